//! Every canonical scenario (`scenarios/*.toml`) flown end to end with the real binaries
//! — `wingman-harness fly-all`, a `wingman-planner serve` child per flight on a fresh
//! vehicle id, the fast lock-step clock, the deployment defaults of `planner.toml` — with each
//! flight's outcome asserted from its `report.json`: targets and the end within 100 m,
//! min F ≥ 1 on avoidable layouts, no hold, every scheduled `t_r` followed by its
//! re-plan, every log replayed byte-identical, and `3d-replan-popups` re-planning for
//! exactly the events it should (none for the far pop-up at 300 s).

use std::time::Duration;

use wingman_testkit::process::{TempDir, harness, report, text};
use wingman_testkit::scenarios_dir;
use wingman_tests::outcome::{
    assert_every_tr_followed, assert_mission_succeeded, assert_replan_popups,
};

#[test]
fn every_canonical_scenario_flies_to_a_successful_end() {
    let dir = TempDir::new("canonical");
    let scenarios = scenarios_dir();
    let out = dir.path().join("runs");
    let o = harness(&[
        "fly-all",
        "--quiet",
        "--scenarios",
        scenarios.to_str().unwrap(),
        "--out-root",
        out.to_str().unwrap(),
    ])
    .wait(Duration::from_secs(1800));
    assert!(o.status.success(), "{}", text(&o));
    let table = String::from_utf8_lossy(&o.stdout);

    let mut names: Vec<String> = std::fs::read_dir(&scenarios)
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            let stem = p.file_stem()?.to_string_lossy().into_owned();
            (p.extension()? == "toml").then_some(stem)
        })
        .collect();
    names.sort();
    assert_eq!(names.len(), 15, "the canonical scenarios: {names:?}");
    for name in &names {
        let r = report(&out.join(name));
        assert_eq!(r["scenario"], name.as_str());
        assert_mission_succeeded(&r);
        let trs = assert_every_tr_followed(&r);
        if name.contains("moving-threat") {
            assert!(
                trs >= 1,
                "{name}: the moving threat's t_r was not re-planned"
            );
        }
        let row = table
            .lines()
            .find(|l| l.starts_with(&format!("| {name} |")))
            .unwrap_or_else(|| panic!("{name} missing from the table:\n{table}"));
        assert!(row.contains("| yes |"), "{row}");
        assert!(row.trim_end().ends_with("identical |"), "replay: {row}");
    }

    // The closed-loop mission in detail (issue 7's "must show").
    let popups = out.join("3d-replan-popups");
    let r = report(&popups);
    assert_replan_popups(&r);
    // Re-plans are charged their compute time in the lock-step clock: available from the
    // trigger time plus the compute time on.
    for p in &r["plans"].as_array().unwrap()[1..] {
        let charged = p["at_s"].as_f64().unwrap() + p["compute_ms"].as_f64().unwrap() / 1e3;
        let available = p["available_at_s"].as_f64().unwrap();
        assert!((available - charged).abs() < 1e-6, "{p}");
    }
    assert!(popups.join("side.png").exists());
}
