//! The planner service (issue 6): the planner as the customer deploys it — its own
//! process, talking only through the fixed-layout messages of `wingman-interfaces` over
//! iceoryx2, planning **only when triggered**, under a compute budget, never without a
//! valid plan to fly.
//!
//! - [`config`]: `planner.toml` (every setting documented and defaulted);
//! - [`ipc`]: the quality of service of every service and the port helpers, shared with
//!   the harness; the dead-node clean-up;
//! - [`world`]: the world model (tasking, lead, threats with their Kalman filters,
//!   ownship, mission clock) and the [`crate::problem::Problem`] of each plan;
//! - [`triggers`]: when to re-plan, as pure functions;
//! - [`budget`]: the compute gate (minimum spacing, duty-cycle cap);
//! - [`solver`]: the solve thread that owns the hybrid planner;
//! - [`export`]: the `Plan` message from a planned trajectory, and back to trigger points;
//! - [`sched`]: the message thread's short scheduler slice (a message wakes it at once);
//! - [`run`]: the message thread and [`run()`](run::run), which `wingman-planner serve`
//!   calls and a test can drive in-process.

pub mod budget;
pub mod config;
pub mod export;
pub mod ipc;
pub mod run;
pub mod sched;
pub mod solver;
pub mod triggers;
pub mod world;

pub use config::ServiceConfig;
pub use run::{ExitReason, MessageLoop, RunOptions, RunSummary, ServiceError, Shutdown, run};
