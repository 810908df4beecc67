//! Process fixtures of the multi-process tests: a temporary folder, a child process with a
//! hard watchdog that is killed in `Drop` (and whose iceoryx2 resources are then removed),
//! vehicle ids unique to a test, and the harness and planner started the way a test needs.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

use crate::binary;

/// A folder of its own under the system's temporary folder, removed in `Drop`.
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        let p = std::env::temp_dir().join(format!("wingman-tests-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).expect("create the test folder");
        TempDir(p)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A vehicle id (hence an iceoryx2 service prefix `wingman/<id>/`) unique to this test
/// process and `tag`.
pub fn vehicle(tag: &str) -> String {
    format!("it-{tag}-{}", std::process::id())
}

/// Removes the iceoryx2 resources of every node whose process is gone (a child killed
/// by a test leaves them behind).
pub fn remove_dead_nodes() {
    let _ = wingman_ipc::remove_dead_nodes(Duration::from_secs(1));
}

/// A child process. `Drop` kills it if it still runs, reaps it, and removes the iceoryx2
/// resources of dead nodes.
pub struct Proc {
    child: Option<Child>,
    what: String,
}

impl Proc {
    /// Spawns `cmd` (stdin closed).
    pub fn spawn(mut cmd: Command, what: &str) -> Proc {
        let child = cmd
            .stdin(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("spawn {what}: {e}"));
        Proc {
            child: Some(child),
            what: what.to_string(),
        }
    }

    pub fn id(&self) -> u32 {
        self.child.as_ref().map_or(0, Child::id)
    }

    /// Whether it still runs.
    pub fn is_running(&mut self) -> bool {
        self.child
            .as_mut()
            .is_some_and(|c| matches!(c.try_wait(), Ok(None)))
    }

    /// Waits for the exit and takes its output; the watchdog kills it after `limit` and
    /// fails the test.
    pub fn wait(mut self, limit: Duration) -> Output {
        let mut child = self.child.take().expect("a running child");
        let start = Instant::now();
        loop {
            if matches!(child.try_wait(), Ok(Some(_))) {
                return child.wait_with_output().expect("collect the output");
            }
            if start.elapsed() > limit {
                let _ = child.kill();
                let out = child.wait_with_output();
                remove_dead_nodes();
                panic!(
                    "{} outlived its {limit:?} watchdog: {}",
                    self.what,
                    out.map(|o| text(&o)).unwrap_or_default()
                );
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// SIGKILL: no clean-up in the child, as in a crash.
    pub fn kill9(&mut self) {
        if let Some(c) = self.child.as_mut() {
            let _ = c.kill();
            let _ = c.wait();
        }
        self.child = None;
    }

    /// SIGTERM, then waits up to `limit` for the exit (killed and a panic after that).
    pub fn terminate(mut self, limit: Duration) -> ExitStatus {
        let pid = self.id().to_string();
        let _ = Command::new("kill").args(["-TERM", &pid]).status();
        let start = Instant::now();
        let c = self.child.as_mut().expect("a running child");
        loop {
            if let Ok(Some(s)) = c.try_wait() {
                self.child = None;
                return s;
            }
            assert!(
                start.elapsed() < limit,
                "{} ignored SIGTERM for {limit:?}",
                self.what
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
            remove_dead_nodes();
        }
    }
}

/// stdout and stderr of a finished child, for failure messages.
pub fn text(o: &Output) -> String {
    format!(
        "{}\nstdout:\n{}\nstderr:\n{}",
        o.status,
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// `wingman-harness <args>` with its output captured (`RUST_LOG=warn`, which a spawned
/// planner inherits).
pub fn harness(args: &[&str]) -> Proc {
    harness_logging(args, "warn")
}

/// `wingman-harness <args>` with its output captured, at log level `rust_log`.
pub fn harness_logging(args: &[&str], rust_log: &str) -> Proc {
    let mut c = Command::new(binary("wingman-harness"));
    c.args(args)
        .env("RUST_LOG", rust_log)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    Proc::spawn(c, "wingman-harness")
}

/// `wingman-planner serve --config <config> --vehicle <vehicle>`, its log (at `info`)
/// into `log`.
pub fn planner(config: &Path, vehicle: &str, log: &Path) -> Proc {
    let out = std::fs::File::create(log).expect("create the planner log");
    let err = out.try_clone().expect("open the planner log");
    let mut c = Command::new(binary("wingman-planner"));
    c.arg("serve")
        .arg("--config")
        .arg(config)
        .args(["--vehicle", vehicle])
        .env("RUST_LOG", "info")
        .stdout(out)
        .stderr(err);
    Proc::spawn(c, "wingman-planner serve")
}

/// Writes a planner configuration: the given budgets (for the take-off plan, plans from
/// scratch and re-plans alike), a 100 ms heartbeat, no duty-cycle cap beyond one core over
/// a minute, and `extra` TOML lines.
pub fn planner_config(dir: &Path, plan_2d_ms: u64, plan_3d_ms: u64, extra: &str) -> PathBuf {
    let p = dir.join("planner.toml");
    std::fs::write(
        &p,
        format!(
            "[budget]\ntakeoff_2d_ms = {plan_2d_ms}\ntakeoff_3d_ms = {plan_3d_ms}\n\
             plan_2d_ms = {plan_2d_ms}\nplan_3d_ms = {plan_3d_ms}\n\
             replan_2d_ms = {plan_2d_ms}\nreplan_3d_ms = {plan_3d_ms}\nduty_cycle = 1.0\n\
             duty_window_ms = 60000\n\n[status]\nheartbeat_ms = 100\n{extra}"
        ),
    )
    .expect("write planner.toml");
    p
}

/// The `report.json` in `out`.
pub fn report(out: &Path) -> serde_json::Value {
    let p = out.join("report.json");
    let s = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    serde_json::from_str(&s).expect("report.json is JSON")
}
