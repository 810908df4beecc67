//! The wingman planning library: the numerical core (vehicle models, threat exposure,
//! moving-threat estimation, re-plan timing, trajectory metrics), the scenario loader, and
//! (in later modules) the hybrid planner and the planner service.
//!
//! One module per idea (see `../shared/STYLE.md`): every module is named for what it does.

pub mod basins;
pub mod clock;
pub mod collocation;
pub mod dynamics;
pub mod estimation;
pub mod hybrid;
pub mod lead;
pub mod logging;
pub mod metrics;
pub mod offline;
pub mod plot;
pub mod problem;
pub mod replan;
pub mod scenario;
pub mod seeding;
pub mod service;
pub mod swarm;
pub mod threat;
pub mod tracking;
pub mod trajectory;
