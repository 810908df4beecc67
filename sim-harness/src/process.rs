//! The planner as a child process: `wingman-planner serve --config FILE --vehicle ID`,
//! found next to the harness's own executable (or named by `WINGMAN_PLANNER`), its logs in
//! a file. Stopped with SIGTERM (it exits 0 after finishing its plan); killed if it does
//! not stop in time, and in `Drop` if the harness leaves early, so no planner outlives a
//! flight.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// The planner process could not be started or stopped.
#[derive(Debug, thiserror::Error)]
pub enum ProcessError {
    #[error(
        "cannot find the planner binary at {0} (build it with `cargo build --release --workspace`, \
         or name it in WINGMAN_PLANNER)"
    )]
    NotFound(PathBuf),
    #[error("cannot start {binary}: {source}")]
    Spawn {
        binary: PathBuf,
        source: std::io::Error,
    },
    #[error("{what}: {source}")]
    Io {
        what: String,
        source: std::io::Error,
    },
}

/// `wingman-planner` next to the current executable (a test binary lives one folder
/// deeper, in `deps/`), unless `WINGMAN_PLANNER` names one.
pub fn planner_binary() -> Result<PathBuf, ProcessError> {
    if let Some(p) = std::env::var_os("WINGMAN_PLANNER") {
        return Ok(PathBuf::from(p));
    }
    let exe = std::env::current_exe().map_err(|source| ProcessError::Io {
        what: "locate the harness executable".into(),
        source,
    })?;
    let name = format!("wingman-planner{}", std::env::consts::EXE_SUFFIX);
    let dir = exe.parent().map(Path::to_path_buf).unwrap_or_default();
    let candidates = [dir.join(&name), dir.join("..").join(&name)];
    candidates
        .iter()
        .find(|p| p.is_file())
        .cloned()
        .ok_or_else(|| ProcessError::NotFound(candidates[0].clone()))
}

/// A running `wingman-planner serve`.
pub struct PlannerProcess {
    child: Option<Child>,
}

impl PlannerProcess {
    /// Starts `binary serve --config config --vehicle vehicle_id` (and `replay_cuts`:
    /// `--replay-cuts FILE`), stdout and stderr into `log`.
    pub fn spawn(
        binary: &Path,
        config: &Path,
        vehicle_id: &str,
        replay_cuts: Option<&Path>,
        log: &Path,
    ) -> Result<PlannerProcess, ProcessError> {
        if !binary.is_file() {
            return Err(ProcessError::NotFound(binary.to_path_buf()));
        }
        let io = |what: &str| {
            let what = format!("{what} {}", log.display());
            move |source| ProcessError::Io { what, source }
        };
        let out = File::create(log).map_err(io("create"))?;
        let err = out.try_clone().map_err(io("open"))?;
        let child = Command::new(binary)
            .arg("serve")
            .arg("--config")
            .arg(config)
            .args(["--vehicle", vehicle_id])
            .args(
                replay_cuts
                    .iter()
                    .flat_map(|p| [Path::new("--replay-cuts"), p]),
            )
            .env(
                "RUST_LOG",
                std::env::var("RUST_LOG").unwrap_or_else(|_| "info".into()),
            )
            .stdin(Stdio::null())
            .stdout(out)
            .stderr(err)
            .spawn()
            .map_err(|source| ProcessError::Spawn {
                binary: binary.to_path_buf(),
                source,
            })?;
        Ok(PlannerProcess { child: Some(child) })
    }

    /// The process id.
    pub fn id(&self) -> Option<u32> {
        self.child.as_ref().map(Child::id)
    }

    /// Whether the process still runs.
    pub fn is_running(&mut self) -> bool {
        match self.child.as_mut() {
            Some(c) => matches!(c.try_wait(), Ok(None)),
            None => false,
        }
    }

    /// SIGKILL (no clean-up, as a crash), and reaps it.
    pub fn kill(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }

    /// SIGTERM, then waits up to `grace`; kills it if it is still running then.
    pub fn stop(&mut self, grace: Duration) -> Option<ExitStatus> {
        let mut child = self.child.take()?;
        if let Ok(Some(s)) = child.try_wait() {
            return Some(s);
        }
        let _ = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status();
        let start = Instant::now();
        while start.elapsed() < grace {
            if let Ok(Some(s)) = child.try_wait() {
                return Some(s);
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        tracing::warn!(pid = child.id(), "the planner ignored SIGTERM: killed");
        let _ = child.kill();
        child.wait().ok()
    }
}

impl Drop for PlannerProcess {
    fn drop(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}
