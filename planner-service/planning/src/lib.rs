//! The wingman planning algorithms: the vehicle models, threat exposure, moving-threat
//! estimation, re-plan timing and trajectory metrics (the numerical core), the scenario
//! loader, and the hybrid planner (spline seeds, particle swarm, Legendre–Gauss–Radau
//! collocation). It knows no IPC, no command line and no plots: the service
//! (`wingman-planner`), the plots (`wingman-plot`) and the harness build on it.
//!
//! One module per idea, named for it. The mathematics each module implements is
//! `docs/FORMULATION.md`, cited by section number (§N).

pub mod basins;
pub mod clock;
pub mod collocation;
pub mod cuts;
pub mod dynamics;
pub mod estimation;
pub mod hybrid;
pub mod lead;
pub mod linalg;
pub mod metrics;
pub mod plan_message;
pub mod problem;
pub mod replan;
pub mod scenario;
pub mod seeding;
pub mod swarm;
pub mod threat;
pub mod tracking;
pub mod trajectory;
