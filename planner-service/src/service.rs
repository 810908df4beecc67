//! The planner service: the planner as the customer deploys it — its own process,
//! talking only through the fixed-layout messages of `wingman-interfaces` over iceoryx2,
//! planning **only when triggered**, under a compute budget, never without a valid plan to
//! fly. Its configuration (`planner.toml`) and the services' settings are in `wingman-ipc`,
//! which the harness shares.
//!
//! - [`world`]: the world model (tasking, lead, threats with their Kalman filters,
//!   ownship, mission clock) and the [`wingman_planning::problem::Problem`] of each plan;
//! - [`triggers`]: when to re-plan, as pure functions;
//! - [`budget`]: the compute gate (minimum spacing, duty-cycle cap);
//! - [`solver`]: the solve thread that owns the hybrid planner;
//! - [`sched`]: the message thread's short scheduler slice (a message wakes it at once);
//! - [`thread`]: the service on a thread of the calling process;
//! - [`message_loop`]: the message thread's [`MessageLoop`] and its pass, one submodule per
//!   idea: `inputs` (draining and validating the subscribers, updating the world, event
//!   triggers), `planning` (the time triggers, the gate, the commit time, starting a
//!   plan), `splice` (the start state of a re-plan), `results` (taking a finished plan and
//!   publishing it), `status` (`PlannerStatus` and the heartbeat), and `lifecycle` (the
//!   plan lifecycle as explicit states: `PlanLifecycle` and, before the first plan,
//!   `FirstPlan`);
//! - [`run`]: [`run()`](run::run), which `wingman-planner serve` calls and a test can drive
//!   in-process: the WaitSet around the message loop, [`RunOptions`], [`Shutdown`], the
//!   service's errors.

pub mod budget;
pub mod message_loop;
pub mod run;
pub mod sched;
pub mod sequence_gaps;
pub mod solver;
pub mod thread;
pub mod triggers;
pub mod world;

pub use message_loop::MessageLoop;
pub use run::{ExitReason, RunOptions, RunSummary, ServiceError, Shutdown, run};
pub use thread::ServiceThread;
pub use wingman_ipc::ServiceConfig;
