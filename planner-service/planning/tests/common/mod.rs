//! A bundled scenario's problem and the hybrid planner's plan for it (default settings, a
//! generous deadline): a good guess in the right basin for tests of the collocation layer,
//! and its transcription on a mesh.

use std::time::Duration;

use wingman_planning::clock::{Deadline, MonotonicClock};
use wingman_planning::collocation::{Mesh, Transcription, TranscriptionSettings};
use wingman_planning::hybrid::{Planner, PlannerSettings};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::bundled;
use wingman_planning::trajectory::Trajectory;

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

/// The transcription of `p` on `mesh` around `guess`, with the guess as its scaled initial
/// point and the objective scaled to about 1 there (as the planner scales it).
pub fn transcribed(p: &Problem, mesh: &Mesh, guess: &Trajectory) -> (Transcription, Vec<f64>) {
    let mut tr = Transcription::new(p, mesh, guess, &TranscriptionSettings::default());
    let mut x = vec![0.0; tr.n_vars()];
    tr.initial_point(guess, &mut x);
    tr.obj_scale = 1.0 / tr.objective(&x).abs().max(1e-3);
    (tr, x)
}
