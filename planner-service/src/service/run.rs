//! [`run()`]: the service's entry point, which `wingman-planner serve` calls and a test can
//! drive in-process. It removes dead iceoryx2 nodes' resources, builds the
//! [`MessageLoop`](super::message_loop::MessageLoop) (which opens the ports and starts the
//! solve thread), and sleeps in an iceoryx2 WaitSet — the `wake/planner` listener, the
//! heartbeat interval, and the loop's own timeout while a plan is deferred or a first plan
//! waits for an ownship state — making one pass of the loop on each wake-up, until a signal
//! or a [`Shutdown`] request.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use iceoryx2::prelude::{CallbackProgression, SignalHandlingMode, WaitSetBuilder};
use iceoryx2::waitset::WaitSetRunResult;
use tracing::{info, warn};
use wingman_interfaces::PlannerStatus;

use super::message_loop::MessageLoop;
use super::sched::{self, SliceOutcome};
use super::solver::SolverStartError;
use wingman_ipc::config::{ConfigError, ServiceConfig};
use wingman_ipc::{self as ipc, Ipc, IpcError};
use wingman_planning::clock::Clock;
use wingman_planning::cuts::ReplayCuts;

/// A request to stop the service, from another thread (tests; `main` uses signals).
#[derive(Debug, Clone, Default)]
pub struct Shutdown(Arc<AtomicBool>);

impl Shutdown {
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks the loop to stop. It notices on its next wake-up: an input, a finished plan,
    /// or the heartbeat at the latest.
    pub fn request(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    pub fn is_requested(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// What [`run`] needs.
pub struct RunOptions {
    pub config: ServiceConfig,
    /// Monotonic clock for compute deadlines, the compute gate and staleness (never for
    /// mission time, which comes from message headers).
    pub clock: &'static dyn Clock,
    /// Stop on SIGINT/SIGTERM (iceoryx2's signal handling). Off in in-process tests.
    pub handle_signals: bool,
    pub shutdown: Shutdown,
    /// A replay: plan with no deadline, taking these logged deadline cuts
    /// (`wingman_planning::cuts`).
    pub replay_cuts: Option<ReplayCuts>,
}

/// Why [`run`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitReason {
    /// SIGINT or SIGTERM.
    Signal,
    /// [`Shutdown::request`].
    Requested,
}

/// The end of a run.
#[derive(Debug, Clone)]
pub struct RunSummary {
    pub exit: ExitReason,
    /// The last status published.
    pub status: PlannerStatus,
    /// Dead iceoryx2 nodes whose resources were removed at start-up.
    pub dead_nodes_removed: u32,
}

/// The service could not start or its event loop failed.
#[derive(Debug, thiserror::Error)]
pub enum ServiceError {
    #[error("configuration: {0}")]
    Config(#[from] ConfigError),
    #[error("iceoryx2: {0}")]
    Ipc(#[from] IpcError),
    #[error("{0}")]
    Solver(#[from] SolverStartError),
    #[error("waitset: {0}")]
    WaitSet(String),
}

/// Gives the calling (message) thread a fair-scheduler slice of `us` µs (0: the kernel's
/// default), and says in the log what the kernel made of it.
fn message_thread_slice(us: u64) {
    if us == 0 {
        return;
    }
    match sched::set_thread_slice(Duration::from_micros(us)) {
        Ok(SliceOutcome::Applied(d)) => {
            info!(
                slice_us = d.as_micros() as u64,
                "message thread scheduler slice set"
            )
        }
        Ok(SliceOutcome::NotSupported) => warn!(
            slice_us = us,
            "this kernel has no per-thread scheduler slice (6.12 or later has): the message \
             thread keeps the default"
        ),
        Ok(SliceOutcome::NotFair(policy)) => info!(
            policy,
            "the message thread runs under a real-time policy: its slice is left alone"
        ),
        Err(e) => warn!(error = %e, "cannot set the message thread's scheduler slice"),
    }
}

/// Runs the planner service until a signal (with `handle_signals`) or a shutdown request:
/// removes dead iceoryx2 nodes' resources, opens the services of
/// `config.vehicle_id`, starts the solve thread and waits for events. On the way out it
/// finishes the plan in flight (publishing it), publishes a last status and releases
/// every resource.
pub fn run(options: RunOptions) -> Result<RunSummary, ServiceError> {
    options.config.validate()?;
    let cleanup = ipc::remove_dead_nodes(Duration::from_secs(1))?;
    if cleanup.removed + cleanup.failed > 0 {
        info!(
            removed = cleanup.removed,
            failed = cleanup.failed,
            "removed the resources of dead iceoryx2 nodes"
        );
    }
    let mut ml = MessageLoop::new(&options)?;
    // After the solve thread is started: only this thread gets the short slice.
    message_thread_slice(options.config.scheduling.message_slice_us);
    let listener = ml.listener()?;
    let mode = if options.handle_signals {
        SignalHandlingMode::HandleTerminationRequests
    } else {
        SignalHandlingMode::Disabled
    };
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(mode)
        .create::<Ipc>()
        .map_err(|e| ServiceError::WaitSet(format!("{e:?}")))?;
    let wake = waitset
        .attach_notification(&listener)
        .map_err(|e| ServiceError::WaitSet(format!("{e:?}")))?;
    let beat = waitset
        .attach_interval(options.config.heartbeat())
        .map_err(|e| ServiceError::WaitSet(format!("{e:?}")))?;
    info!(
        vehicle = %options.config.vehicle_id,
        heartbeat_ms = options.config.status.heartbeat_ms,
        "planner service running"
    );
    ml.process(true);
    let exit = loop {
        let mut heartbeat = false;
        let result = waitset.wait_and_process_once_with_timeout(
            |id| {
                if id.has_event_from(&wake) {
                    // Consume the notifications, or the WaitSet wakes at once again.
                    let _ = listener.try_wait(|_| {});
                } else if id.has_event_from(&beat) {
                    heartbeat = true;
                }
                CallbackProgression::Continue
            },
            ml.next_timeout(),
        );
        match result {
            Ok(WaitSetRunResult::TerminationRequest) => break ExitReason::Signal,
            // EINTR: the next call reports a termination request if that is what it was.
            Ok(WaitSetRunResult::Interrupt) => {}
            Ok(_) => {}
            Err(e) => return Err(ServiceError::WaitSet(format!("{e:?}"))),
        }
        if options.shutdown.is_requested() {
            break ExitReason::Requested;
        }
        ml.process(heartbeat);
    };
    info!(reason = ?exit, "planner service stopping");
    drop(beat);
    drop(wake);
    drop(waitset);
    drop(listener);
    let status = ml.finish();
    Ok(RunSummary {
        exit,
        status,
        dead_nodes_removed: cleanup.removed,
    })
}
