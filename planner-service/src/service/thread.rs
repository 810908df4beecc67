//! The service on a thread of the calling process: what `wingman-planner serve` runs, for
//! an application that embeds the planner, and for tests that drive it in-process.

use std::thread::JoinHandle;

use wingman_ipc::ServiceConfig;
use wingman_planning::clock::MonotonicClock;

use super::run::{RunOptions, RunSummary, Shutdown, run};

/// The service running [`run`] on a thread of this process; stopped in `Drop` if not
/// before.
pub struct ServiceThread {
    shutdown: Shutdown,
    thread: Option<JoinHandle<Result<RunSummary, String>>>,
}

impl ServiceThread {
    /// Starts the service with `config` (its own monotonic clock, no signal handling). Its
    /// log events go to whatever `tracing` subscriber the caller installed (none: they
    /// are dropped; `wingman_ipc::logging::init` installs the binaries' one).
    pub fn start(config: ServiceConfig) -> std::io::Result<ServiceThread> {
        let shutdown = Shutdown::new();
        let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
        let options = RunOptions {
            config,
            clock,
            handle_signals: false,
            shutdown: shutdown.clone(),
            replay_cuts: None,
        };
        let thread = std::thread::Builder::new()
            .name("planner-service".into())
            .spawn(move || {
                let r = run(options).map_err(|e| e.to_string());
                if let Err(e) = &r {
                    tracing::error!("the service failed: {e}");
                }
                r
            })?;
        Ok(ServiceThread {
            shutdown,
            thread: Some(thread),
        })
    }

    /// Stops the service and returns its summary, or its error. `wake` wakes the message
    /// loop (a notification on `wake/planner`) so that it sees the request at once rather
    /// than at its next heartbeat.
    pub fn stop(mut self, wake: impl FnOnce()) -> Result<RunSummary, String> {
        self.shutdown.request();
        wake();
        match self.thread.take() {
            Some(t) => t
                .join()
                .unwrap_or_else(|_| Err("the service thread panicked".into())),
            None => Err("the service was stopped before".into()),
        }
    }
}

impl Drop for ServiceThread {
    fn drop(&mut self) {
        if let Some(t) = self.thread.take() {
            self.shutdown.request();
            // The heartbeat wakes the loop at the latest.
            let _ = t.join();
        }
    }
}
