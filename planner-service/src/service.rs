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
//! - [`run`]: the message thread and [`run()`](run::run), which `wingman-planner serve`
//!   calls and a test can drive in-process.

pub mod budget;
pub mod run;
pub mod sched;
pub mod solver;
pub mod thread;
pub mod triggers;
pub mod world;

pub use run::{ExitReason, MessageLoop, RunOptions, RunSummary, ServiceError, Shutdown, run};
pub use thread::ServiceThread;
pub use wingman_ipc::ServiceConfig;
