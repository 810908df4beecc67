//! The binaries as a user runs them: separate processes, real files, exit codes.

use std::process::Command;
use wingman_testkit::{binary, scenarios_dir};

#[test]
fn harness_lists_every_bundled_scenario_canonical_and_disturbed() {
    let out = Command::new(binary("wingman-harness"))
        .arg("list")
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let tomls = |dir: std::path::PathBuf| {
        std::fs::read_dir(dir)
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .path()
                    .extension()
                    .is_some_and(|x| x == "toml")
            })
            .count()
    };
    let files = tomls(scenarios_dir()) + tomls(scenarios_dir().join("disturbed"));
    assert_eq!(text.lines().count(), files);
    assert!(text.lines().any(|l| l.starts_with("3d-replan-popups ")));
    assert!(text.lines().any(|l| l.starts_with("2d-fixed-time-windy ")));
}

#[test]
fn planner_checks_a_scenario_and_refuses_a_broken_one() {
    let good = scenarios_dir().join("2d-min-time-avoidable.toml");
    let out = Command::new(binary("wingman-planner"))
        .arg("check")
        .arg(&good)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        String::from_utf8(out.stdout)
            .unwrap()
            .starts_with("2d-min-time-avoidable (2d, min-time)")
    );

    let text = std::fs::read_to_string(&good)
        .unwrap()
        .replace("stiffness = 30.0", "stiffness = -1");
    let bad = std::env::temp_dir().join(format!("wingman-cli-{}.toml", std::process::id()));
    std::fs::write(&bad, text).unwrap();
    let out = Command::new(binary("wingman-planner"))
        .arg("check")
        .arg(&bad)
        .output()
        .unwrap();
    std::fs::remove_file(&bad).unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("weights.stiffness") && err.contains("must be positive"),
        "{err}"
    );
}

#[test]
fn harness_refuses_to_resume_without_an_external_planner() {
    let out = Command::new(binary("wingman-harness"))
        .args(["fly", "2d-min-time-avoidable", "--resume"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("it needs --planner external"), "{err}");
}
