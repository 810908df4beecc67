//! A bundled scenario's problem and the hybrid planner's plan for it (default settings, a
//! generous deadline): a good guess in the right basin for tests of the collocation layer,
//! and its transcription on a mesh.

#![allow(dead_code)]

use std::time::Duration;

use wingman_planning::clock::{Deadline, MonotonicClock};
use wingman_planning::collocation::{Mesh, Transcription, TranscriptionSettings};
use wingman_planning::estimation::{Estimate, GaussMarkov, MovingThreat, Road};
use wingman_planning::hybrid::{PlanOutcome, Planner, PlannerSettings};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::bundled;
use wingman_planning::threat::{Superquadric, ThreatLayout};
use wingman_planning::trajectory::Trajectory;

/// A clock that lives as long as the test process.
pub fn clock() -> &'static MonotonicClock {
    Box::leak(Box::new(MonotonicClock::new()))
}

/// The problem of bundled scenario `name` and the planner's trajectory for it.
pub fn planned(name: &str) -> (Problem, Trajectory) {
    let (p, plan) = planned_outcome(name);
    (p, plan.trajectory)
}

/// The problem of bundled scenario `name` and the planner's plan for it.
pub fn planned_outcome(name: &str) -> (Problem, PlanOutcome) {
    planned_with(name, &PlannerSettings::default())
}

/// The problem of bundled scenario `name` and the plan of its global search alone (no
/// waves of further starts): the guess the collocation tests were written on.
pub fn planned_globally(name: &str) -> (Problem, Trajectory) {
    let settings = PlannerSettings {
        wave_starts: 0,
        wave_starts_3d: 0,
        ..PlannerSettings::default()
    };
    let (p, plan) = planned_with(name, &settings);
    (p, plan.trajectory)
}

/// The problem of bundled scenario `name` and the plan `settings` make for it.
fn planned_with(name: &str, settings: &PlannerSettings) -> (Problem, PlanOutcome) {
    let p = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
    let plan = Planner::new(settings)
        .plan(
            &p,
            settings,
            Deadline::after(clock(), Duration::from_secs(60)),
        )
        .unwrap();
    (p, plan)
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

/// The five static threats of `scenarios/3d-replan-popups.toml` known at take-off
/// ("popup-far" appears at 300 s and is left out), stiffness 30.
pub fn popups_layout() -> ThreatLayout<3> {
    let t = |c: [f64; 3], a: [f64; 3], p: [f64; 3]| Superquadric::new(c, a, p, 0.0).unwrap();
    ThreatLayout::with_threats(
        30.0,
        &[
            t(
                [30000.0, 40000.0, 0.0],
                [25000.0, 25000.0, 25000.0],
                [2.0; 3],
            ),
            t(
                [95000.0, 95000.0, 0.0],
                [18000.0, 18000.0, 15000.0],
                [2.0; 3],
            ),
            t([125000.0, 45000.0, 0.0], [6000.0, 6000.0, 3000.0], [2.0; 3]),
            t(
                [60000.0, 125000.0, 0.0],
                [25000.0, 25000.0, 15000.0],
                [2.0; 3],
            ),
            t(
                [140000.0, 75000.0, 0.0],
                [20000.0, 20000.0, 15000.0],
                [2.0, 2.0, 8.0],
            ),
        ],
    )
    .unwrap()
}

/// Its moving threat "mobile-sam", estimate at t = 0.
pub fn mobile_sam() -> MovingThreat<3> {
    let road = Road::new(&[[70000.0, 0.0, 0.0], [100000.0, 150000.0, 0.0]]).unwrap();
    let est = Estimate::with_sigmas(0.0, [58000.0, 15.0, 0.0], [500.0, 3.0, 0.3]).unwrap();
    MovingThreat::new(
        road,
        [10000.0, 10000.0, 12000.0],
        GaussMarkov::new(60.0, 0.3).unwrap(),
        est,
    )
    .unwrap()
}
