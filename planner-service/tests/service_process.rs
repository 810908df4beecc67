//! The real `wingman-planner serve` process:
//!
//! - SIGTERM stops it with exit code 0 after it has published its heartbeat, and with a
//!   plan in flight after publishing that plan;
//! - killed with SIGKILL (no clean-up), a new process on the same vehicle id starts (the
//!   dead node's resources are removed at start-up), takes the tasking and threats from
//!   the services' history, plans, and stops cleanly;
//! - `deploy/wingman-planner.service` and `docs/DEPLOYMENT.md` use only flags the binary
//!   has, and the document names every flag of `serve --help`.
//!
//! A watchdog kills a child that outlives its time limit.

mod common;

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use common::*;
use wingman_planning::scenario::bundled;

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
    // No wait for an ownship state before a first plan: `Planning` then means a plan in
    // flight (the restart test sends its ownship state with the history anyway).
    let text = "[budget]\nplan_2d_ms = 20000\nplan_3d_ms = 20000\nreplan_2d_ms = 20000\n\
                replan_3d_ms = 20000\nduty_cycle = 1.0\n\
                duty_window_ms = 60000\n\n[status]\nheartbeat_ms = 100\n\n\
                [triggers]\nfirst_plan_wait_ms = 0\n";
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

/// The kernel's scheduler slice of each thread of process `pid`, by thread name, ns
/// (`se.slice` in `/proc/PID/task/TID/sched`; empty on a kernel that does not show it).
fn thread_slices(pid: u32) -> Vec<(String, u64)> {
    let mut out = Vec::new();
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else {
        return out;
    };
    for t in tasks.flatten() {
        let sched = std::fs::read_to_string(t.path().join("sched")).unwrap_or_default();
        let name = sched.split(' ').next().unwrap_or_default().to_string();
        let slice = sched
            .lines()
            .find(|l| l.starts_with("se.slice"))
            .and_then(|l| l.split(':').nth(1))
            .and_then(|v| v.trim().parse().ok());
        if let Some(slice) = slice {
            out.push((name, slice));
        }
    }
    out
}

/// The message thread runs with planner.toml's 0.1 ms scheduler slice (a message wakes it
/// at once on a busy core); the solve thread keeps the kernel's default. Fails without
/// `service::sched` applied in `run()`, or if it were applied before the solve thread
/// starts (the solve thread would inherit it).
#[test]
fn the_message_thread_runs_with_the_short_scheduler_slice_and_the_solve_thread_without() {
    let kernel = wingman_planner::service::sched::kernel_release();
    let slices = thread_slices(std::process::id());
    if kernel < (6, 12) || slices.is_empty() {
        eprintln!("kernel {kernel:?}: no per-thread slice to check");
        return;
    }
    let default = slices[0].1;
    let v = vehicle("slice");
    let planner = Planner::spawn(&v, &repo().join("planner.toml"));
    let mut h = FakeHarness::new(&v);
    assert!(
        h.wait_until(Duration::from_secs(30), |h| h.status.is_some()),
        "no heartbeat"
    );
    let threads = thread_slices(planner.child.id());
    let of = |name: &str| {
        threads
            .iter()
            .find(|(n, _)| n == name)
            .map(|&(_, s)| s)
            .unwrap_or_else(|| panic!("no thread {name} in {threads:?}"))
    };
    let configured = wingman_ipc::ServiceConfig::load(repo().join("planner.toml"))
        .unwrap()
        .scheduling
        .message_slice_us;
    assert_eq!(of("wingman-planner"), configured * 1000, "{threads:?}");
    assert_eq!(of("wingman-solve"), default, "{threads:?}");
    drop(planner);
}

/// T7: SIGTERM while a plan is in flight: the service finishes that plan, publishes it,
/// then exits 0.
#[test]
fn sigterm_with_a_plan_in_flight_publishes_it_and_exits_0() {
    let v = vehicle("sigterm-busy");
    let config = config_file("sigterm-busy");
    let planner = Planner::spawn(&v, &config);
    let mut h = FakeHarness::new(&v);
    assert!(
        h.wait_until(Duration::from_secs(30), |h| h.status.is_some()),
        "no heartbeat"
    );
    // A 3-D plan takes about a second in a release build.
    let sc = bundled("3d-min-time-avoidable").unwrap().unwrap();
    h.send_tasking(tasking_from(&sc, 1));
    h.wake();
    assert!(
        h.wait_until(Duration::from_secs(30), |h| h
            .status
            .is_some_and(|s| s.state() == Some(PlannerState::Planning))),
        "the plan did not start: {:?}",
        h.status
    );
    planner.signal("-TERM");
    let (status, err) = planner.wait(Duration::from_secs(60));
    assert_eq!(status.code(), Some(0), "stderr:\n{err}");
    let stopping = err
        .find("planner service stopping")
        .expect("stopping logged");
    let published = err
        .find("plan published")
        .unwrap_or_else(|| panic!("the plan in flight was not published; stderr:\n{err}"));
    assert!(
        stopping < published,
        "the plan was published after the signal, on the way out"
    );
    let _ = std::fs::remove_file(config);
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
    // The harness hands its history to the new subscribers, sends the ownship state (it
    // flies plan 1, 5 s into the mission), then wakes the planner.
    h.refresh();
    let flown = h.plans[0].clone();
    h.set_time(5.0);
    let mut own = OwnshipState::zeroed();
    own.time_s = 5.0;
    own.model = Model::TwoD.to_wire();
    own.plan_id = flown.plan_id;
    own.state = wingman_planning::plan_message::state_at(&flown, 5.0).unwrap();
    h.send_ownship(own);
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
        s.messages_received, 6,
        "4 threats and the tasking from history, the ownship state"
    );
    // T7: the mission is under way: a restart, from the ownship, with the next plan id.
    let p = h.plans.last().unwrap();
    assert_eq!(p.trigger(), Some(Trigger::Restart));
    assert_eq!(p.plan_id, flown.plan_id + 1, "plan ids continue");
    assert_eq!(s.current_plan_id, p.plan_id);
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
        .filter(|w| {
            w.starts_with("--") && w.as_bytes().get(2).is_some_and(u8::is_ascii_alphanumeric)
        })
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
        "RestartPreventExitStatus=2",
        "KillSignal=SIGTERM",
    ] {
        assert!(unit.contains(key), "the unit sets {key}");
    }

    // T8: every flag the documents mention is one `serve` has, except on the lines of
    // other commands (cargo, the install steps, systemd's tools, the harness).
    let doc = std::fs::read_to_string(repo().join("docs/DEPLOYMENT.md")).unwrap();
    let toml = std::fs::read_to_string(repo().join("planner.toml")).unwrap();
    let other = [
        "cargo ",
        "sudo ",
        "journalctl",
        "systemctl",
        "useradd",
        "wingman-harness ",
    ];
    let mut commands = 0;
    for (file, text) in [
        ("DEPLOYMENT.md", &doc),
        ("planner.toml", &toml),
        ("the unit", &unit),
    ] {
        for line in text.lines() {
            commands += usize::from(line.contains("wingman-planner serve"));
            if other.iter().any(|o| line.contains(o)) {
                continue;
            }
            for f in flags(line) {
                assert!(known.contains(&f), "{file} mentions {f}: {line}");
            }
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
    // D3: the stop timeout exceeds the largest plan budget of planner.toml + 2 s.
    let stop_s: f64 = unit
        .lines()
        .find_map(|l| l.strip_prefix("TimeoutStopSec="))
        .expect("TimeoutStopSec")
        .trim()
        .parse()
        .unwrap();
    let cfg = wingman_ipc::ServiceConfig::load(repo().join("planner.toml")).unwrap();
    let largest_s = cfg.budget.largest_ms() as f64 / 1e3;
    assert!(
        stop_s > largest_s + 2.0,
        "TimeoutStopSec={stop_s} <= {largest_s} s + 2 s"
    );
}
