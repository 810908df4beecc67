//! The real `wingman-planner serve` process:
//!
//! - SIGTERM stops it with exit code 0 after it has published its heartbeat;
//! - killed with SIGKILL (no clean-up), a new process on the same vehicle id starts (the
//!   dead node's resources are removed at start-up), takes the tasking and threats from
//!   the services' history, plans, and stops cleanly;
//! - `deploy/wingman-planner.service` and `docs/DEPLOYMENT.md` use only flags the binary
//!   has, and the document names every flag of `serve --help`.
//!
//! A watchdog kills a child that outlives its time limit.

mod service_support;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use service_support::*;
use wingman_interfaces::*;
use wingman_planner::scenario::bundled;

const BIN: &str = env!("CARGO_BIN_EXE_wingman-planner");

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A `serve` child, killed if the test drops it still running.
struct Planner {
    child: Child,
}

impl Planner {
    fn spawn(vehicle: &str, config: &Path) -> Planner {
        let child = Command::new(BIN)
            .args(["serve", "--config"])
            .arg(config)
            .args(["--vehicle", vehicle])
            .env("RUST_LOG", "info")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn wingman-planner serve");
        Planner { child }
    }

    fn signal(&self, signal: &str) {
        let ok = Command::new("kill")
            .args([signal, &self.child.id().to_string()])
            .status()
            .expect("run kill")
            .success();
        assert!(ok, "kill {signal} failed");
    }

    /// Waits for the exit (the watchdog kills it after `limit`); returns its status and
    /// its stderr.
    fn wait(mut self, limit: Duration) -> (ExitStatus, String) {
        let start = Instant::now();
        let status = loop {
            if let Some(s) = self.child.try_wait().unwrap() {
                break s;
            }
            if start.elapsed() > limit {
                let _ = self.child.kill();
                let _ = self.child.wait();
                panic!("the planner did not exit within {limit:?}");
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let mut err = String::new();
        if let Some(mut e) = self.child.stderr.take() {
            let _ = e.read_to_string(&mut err);
        }
        (status, err)
    }
}

impl Drop for Planner {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// A configuration file for the child: fast heartbeat, generous budgets (debug builds).
fn config_file(tag: &str) -> PathBuf {
    let path = std::env::temp_dir().join(format!("wingman-{}-{tag}.toml", std::process::id()));
    let text = "[budget]\nplan_2d_ms = 20000\nplan_3d_ms = 20000\nduty_cycle = 1.0\n\
                duty_window_ms = 60000\n\n[status]\nheartbeat_ms = 100\n";
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn sigterm_stops_the_service_with_exit_code_0() {
    let v = vehicle("sigterm");
    let planner = Planner::spawn(&v, &repo().join("planner.toml"));
    let mut h = FakeHarness::new(&v);
    // The status heartbeat (1 s with planner.toml) shows the service is up.
    assert!(
        h.wait_until(Duration::from_secs(30), |h| h.status.is_some()),
        "no heartbeat"
    );
    planner.signal("-TERM");
    let (status, err) = planner.wait(Duration::from_secs(30));
    assert_eq!(
        status.code(),
        Some(0),
        "exit status {status:?}; stderr:\n{err}"
    );
    assert!(err.contains("planner service stopping"), "stderr:\n{err}");
}

#[test]
fn a_restart_after_a_crash_cleans_up_and_takes_the_world_from_history() {
    let v = vehicle("restart");
    let config = config_file("restart");
    let first = Planner::spawn(&v, &config);
    let mut h = FakeHarness::new(&v);
    assert!(
        h.wait_until(Duration::from_secs(30), |h| h.status.is_some()),
        "no heartbeat"
    );
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    for t in scenario_threats(&sc) {
        h.send_threat(t);
    }
    h.send_tasking(tasking_from(&sc, 1));
    h.wake();
    assert!(
        h.wait_until(Duration::from_secs(120), |h| h
            .status
            .is_some_and(|s| s.plans_made == 1)),
        "no plan from the first process: {:?}",
        h.status
    );
    // Crash: no clean-up at all.
    first.signal("-KILL");
    let (status, _) = first.wait(Duration::from_secs(10));
    assert_eq!(status.code(), None, "killed by a signal");

    h.status = None;
    let second = Planner::spawn(&v, &config);
    // The new process's first heartbeat (its status sequence starts again).
    assert!(
        h.wait_until(Duration::from_secs(30), |h| h
            .status
            .is_some_and(|s| s.plans_made == 0)),
        "no heartbeat from the restarted planner: {:?}",
        h.status
    );
    // The harness hands its history to the new subscribers, then wakes the planner.
    h.refresh();
    h.wake();
    assert!(
        h.wait_until(Duration::from_secs(120), |h| h
            .status
            .is_some_and(
                |s| s.plans_made == 1 && s.state() != Some(PlannerState::Planning)
            )),
        "the restarted planner did not plan from the history: {:?}",
        h.status
    );
    let s = h.last_status();
    assert_eq!(
        s.messages_received, 5,
        "4 threats and the tasking from history"
    );
    assert_eq!(s.messages_rejected, 0);
    second.signal("-TERM");
    let (status, err) = second.wait(Duration::from_secs(30));
    assert_eq!(status.code(), Some(0), "stderr:\n{err}");
    // (Whichever process runs next removes the dead node's resources: this one, or a
    // parallel test's service.)
    let _ = std::fs::remove_file(config);
}

/// The `--flags` of a line of text (a command line, help text or prose).
fn flags(line: &str) -> Vec<String> {
    line.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
        .filter(|w| w.starts_with("--") && w.len() > 2)
        .map(str::to_string)
        .collect()
}

#[test]
fn the_unit_file_and_the_deployment_doc_match_the_binary() {
    let help = Command::new(BIN)
        .args(["serve", "--help"])
        .output()
        .expect("serve --help");
    assert!(help.status.success());
    let help = String::from_utf8(help.stdout).unwrap();
    let known = flags(&help);
    assert!(known.contains(&"--config".to_string()) && known.contains(&"--vehicle".to_string()));

    let unit = std::fs::read_to_string(repo().join("deploy/wingman-planner.service")).unwrap();
    let exec = unit
        .lines()
        .find(|l| l.starts_with("ExecStart="))
        .expect("an ExecStart line");
    assert!(exec.contains("wingman-planner serve"), "{exec}");
    for f in flags(exec) {
        assert!(
            known.contains(&f),
            "the unit uses {f}, which serve does not have"
        );
    }
    for key in [
        "CPUAffinity=",
        "CPUQuota=",
        "MemoryMax=",
        "Restart=on-failure",
        "KillSignal=SIGTERM",
    ] {
        assert!(unit.contains(key), "the unit sets {key}");
    }

    let doc = std::fs::read_to_string(repo().join("docs/DEPLOYMENT.md")).unwrap();
    let mut commands = 0;
    for line in doc.lines().filter(|l| l.contains("wingman-planner serve")) {
        commands += 1;
        for f in flags(line) {
            assert!(known.contains(&f), "DEPLOYMENT.md uses {f}: {line}");
        }
    }
    assert!(commands > 0, "DEPLOYMENT.md shows how to run serve");
    for f in &known {
        assert!(
            doc.contains(f.as_str()),
            "DEPLOYMENT.md does not explain {f}"
        );
    }
    assert!(doc.contains("deploy/wingman-planner.service"));
}
