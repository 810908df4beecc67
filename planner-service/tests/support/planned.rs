//! A bundled scenario's problem and the hybrid planner's plan for it (default settings, a
//! generous deadline): a good guess in the right basin for tests of the collocation layer.

use std::time::Duration;

use wingman_planner::clock::{Deadline, MonotonicClock};
use wingman_planner::hybrid::{Planner, PlannerSettings};
use wingman_planner::problem::Problem;
use wingman_planner::scenario::bundled;
use wingman_planner::trajectory::Trajectory;

/// A clock that lives as long as the test process.
pub fn clock() -> &'static MonotonicClock {
    Box::leak(Box::new(MonotonicClock::new()))
}

/// The problem of bundled scenario `name` and the planner's trajectory for it.
pub fn planned(name: &str) -> (Problem, Trajectory) {
    let p = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
    let settings = PlannerSettings::default();
    let plan = Planner::new(&settings)
        .plan(
            &p,
            &settings,
            Deadline::after(clock(), Duration::from_secs(60)),
        )
        .unwrap();
    (p, plan.trajectory)
}
