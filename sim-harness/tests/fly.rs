//! Missions flown end to end with the real binaries (`wingman-harness fly`, which spawns
//! `wingman-planner serve`), in the fast clock: a short 2-D canonical scenario completes,
//! its log replays with every plan identical, an external planner works the same, and a
//! planner that dies at start-up or a broken scenario end the harness with an error
//! instead of a hang. (Every canonical scenario, `3d-replan-popups`' re-plans included, is
//! flown by `tests/tests/canonical.rs`.) Every test has its own vehicle id and output folder; a watchdog
//! kills a child that outlives its limit; `Drop` cleans up.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use wingman_testkit::binary;

const LIMIT: Duration = Duration::from_secs(600);

/// A folder of its own, removed in `Drop`.
struct TempDir(PathBuf);

impl TempDir {
    fn new(tag: &str) -> TempDir {
        let p = std::env::temp_dir().join(format!("wingman-harness-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        TempDir(p)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A child process, killed in `Drop` if still running.
struct Guard(Option<Child>);

impl Guard {
    /// Waits for the exit, killing the child after `limit` (then panics).
    fn wait(mut self, limit: Duration) -> Output {
        let mut child = self.0.take().unwrap();
        let start = Instant::now();
        loop {
            if child.try_wait().unwrap().is_some() {
                return child.wait_with_output().unwrap();
            }
            if start.elapsed() > limit {
                let _ = child.kill();
                let _ = child.wait();
                panic!("the child outlived its {limit:?} watchdog");
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Guard {
    fn drop(&mut self) {
        if let Some(c) = self.0.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

fn vehicle(tag: &str) -> String {
    format!("test-{tag}-{}", std::process::id())
}

fn harness(args: &[&str], out: Option<&Path>) -> Guard {
    let mut c = Command::new(binary("wingman-harness"));
    c.args(args).env("RUST_LOG", "warn");
    if let Some(out) = out {
        c.arg("--out").arg(out);
    }
    let child = c
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn wingman-harness");
    Guard(Some(child))
}

fn text(o: &Output) -> String {
    format!(
        "stdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn report(out: &Path) -> serde_json::Value {
    let s = std::fs::read_to_string(out.join("report.json")).unwrap();
    serde_json::from_str(&s).unwrap()
}

fn assert_completed(r: &serde_json::Value) {
    assert_eq!(r["completed"], true, "{r:#}");
    for t in r["targets"].as_array().unwrap() {
        assert!(t["miss_m"].as_f64().unwrap() <= 100.0, "{t}");
    }
    assert!(r["final_error_m"].as_f64().unwrap() <= 100.0);
    assert!(r["min_f_static"].as_f64().unwrap() >= 1.0, "avoidable");
    let plans = r["plans"].as_array().unwrap();
    assert!(!plans.is_empty());
    assert_eq!(plans[0]["trigger"], "Initial");
    for p in plans {
        for key in ["at_s", "compute_ms", "cost"] {
            assert!(p[key].is_number(), "{key} in {p}");
        }
        assert!(["Optimal", "Feasible"].contains(&p["quality"].as_str().unwrap()));
    }
    assert!(r["exposure_integral"].as_f64().unwrap() >= 0.0);
}

#[test]
fn a_2d_mission_flies_end_to_end_and_replays_identically() {
    let dir = TempDir::new("fly");
    let out = dir.0.join("run");
    let v = vehicle("fly");
    let o = harness(
        &["fly", "2d-min-time-avoidable", "--quiet", "--vehicle", &v],
        Some(&out),
    )
    .wait(LIMIT);
    assert!(o.status.success(), "{}", text(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("COMPLETED"));
    let r = report(&out);
    assert_eq!(r["scenario"], "2d-min-time-avoidable");
    assert_eq!(r["vehicle_id"], v.as_str());
    assert_completed(&r);
    for f in ["flight.log", "map.png", "timeline.png", "planner.toml"] {
        let len = std::fs::metadata(out.join(f)).map_or(0, |m| m.len());
        assert!(len > 0, "{f} missing or empty");
    }
    // The planner's own log (empty at RUST_LOG=warn when all goes well).
    assert!(out.join("planner.log").exists());
    assert!(!out.join("side.png").exists(), "no side view in 2-D");

    let o = harness(&["replay", out.join("flight.log").to_str().unwrap()], None).wait(LIMIT);
    assert!(o.status.success(), "{}", text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("every plan identical"), "{stdout}");
}

#[test]
fn an_external_planner_is_flown_against_the_same_way() {
    let dir = TempDir::new("external");
    let v = vehicle("external");
    let config = dir.0.join("planner.toml");
    std::fs::write(
        &config,
        "[budget]\nplan_2d_ms = 2000\nplan_3d_ms = 6000\nreplan_2d_ms = 2000\nreplan_3d_ms = 6000\n\
         duty_cycle = 1.0\nduty_window_ms = 60000\n",
    )
    .unwrap();
    let planner = Command::new(binary("wingman-planner"))
        .args(["serve", "--config"])
        .arg(&config)
        .args(["--vehicle", &v])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut planner = Guard(Some(planner));
    let out = dir.0.join("run");
    let o = harness(
        &[
            "fly",
            "2d-min-time-rendezvous-avoidable",
            "--quiet",
            "--planner",
            "external",
            "--vehicle",
            &v,
        ],
        Some(&out),
    )
    .wait(LIMIT);
    assert!(o.status.success(), "{}", text(&o));
    assert_completed(&report(&out));
    // The harness leaves an external planner running.
    let still = planner.0.as_mut().unwrap().try_wait().unwrap();
    assert!(
        still.is_none(),
        "the external planner was stopped: {still:?}"
    );
    // Stopped cleanly (SIGTERM), so it releases its shared memory.
    let pid = planner.0.as_ref().unwrap().id().to_string();
    let _ = Command::new("kill").args(["-TERM", &pid]).status();
    let o = planner.wait(Duration::from_secs(30));
    assert!(o.status.success(), "the planner's exit: {:?}", o.status);
}

#[test]
fn a_planner_that_dies_at_start_up_or_a_broken_scenario_is_an_error() {
    let dir = TempDir::new("faults");
    let v = vehicle("dies");
    // `false` exits at once: the harness must notice, not wait forever.
    let o = {
        let mut c = Command::new(binary("wingman-harness"));
        c.args(["fly", "2d-min-time-avoidable", "--quiet", "--vehicle", &v])
            .arg("--out")
            .arg(dir.0.join("dies"))
            .env("WINGMAN_PLANNER", "/bin/false")
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        Guard(Some(c.spawn().unwrap())).wait(Duration::from_secs(120))
    };
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("exited"),
        "{}",
        text(&o)
    );

    let bad = dir.0.join("bad.toml");
    let good = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/2d-min-time-avoidable.toml"),
    )
    .unwrap();
    std::fs::write(&bad, good.replace("speed_mps = 200.0", "speed_mps = -5.0")).unwrap();
    let o = harness(&["fly", bad.to_str().unwrap(), "--quiet"], None).wait(Duration::from_secs(60));
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bad.toml") && err.contains("speed_mps"),
        "{err}"
    );
    let o = harness(&["fly", "no-such-scenario", "--quiet"], None).wait(Duration::from_secs(60));
    assert_eq!(o.status.code(), Some(2));
}
