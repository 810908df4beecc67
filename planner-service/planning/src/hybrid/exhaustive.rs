//! The yardstick of global optimality: the planner with a far wider global search, run
//! several times from different random streams under a long budget, keeping the best
//! plan. It is what a campaign judges the default take-off plan against
//! (`wingman-planner plan --exhaustive`, `wingman-harness campaign`); it is not for
//! flight.
//!
//! Wider means: every seed family with more bulge ratios (0.15 to 1.2 of a leg), eight
//! times the random seeds, the altitude profiles that descend or climb early and late
//! beside the direct and the high ones, a swarm of 64 particles in 8 groups for 300
//! iterations, 24 NLP starts from distinct basins (with a fixed final time 24 by cost and
//! up to 23 more with the seeds that arrive on time first), 6 finalists within 50 % of the
//! best, two refinement rounds.

use std::time::Duration;

use wingman_interfaces::Quality;

use super::{PlanError, PlanOutcome, Planner, PlannerSettings};
use crate::basins::StartRanking;
use crate::clock::{Clock, Deadline};
use crate::cuts::CutLog;
use crate::problem::Problem;

/// How hard the yardstick searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exhaustive {
    /// Planner runs, each from its own random streams (`seed`, `seed + 1`, ...).
    pub runs: usize,
    /// Budget of each run.
    pub budget: Duration,
    /// Seed of the first run.
    pub seed: u64,
}

impl Default for Exhaustive {
    fn default() -> Self {
        Exhaustive {
            runs: 3,
            budget: Duration::from_secs(60),
            seed: 1,
        }
    }
}

/// The best of the yardstick's runs, and what it took.
#[derive(Debug, Clone)]
pub struct ExhaustiveOutcome {
    pub best: PlanOutcome,
    /// Each run's quality and cost, in run order.
    pub runs: Vec<(Quality, f64)>,
    /// Deadline cuts over all runs (0: no run was cut, so the result does not depend on
    /// the machine's speed).
    pub cuts: usize,
    pub elapsed: Duration,
}

impl PlannerSettings {
    /// The yardstick's settings (see the module documentation) with the swarm seeded by
    /// `seed`.
    pub fn exhaustive(seed: u64) -> PlannerSettings {
        let mut s = PlannerSettings::default();
        s.swarm = s.swarm.with_seed(seed);
        s.swarm.particles = 64;
        s.swarm.groups = 8;
        s.swarm.max_iterations = 300;
        s.swarm.stall_iterations = 60;
        s.swarm.candidates = 8;
        s.swarm.seeds = s
            .swarm
            .seeds
            .clone()
            .with_bulge_ratios(&[0.15, 0.3, 0.5, 0.8, 1.2])
            .with_random_seeds(64)
            .with_random_bulge_max(1.0)
            .with_early_late_profiles(true)
            .with_max_seeds(512)
            .with_scan_minima(5);
        s.starts = 24;
        // Its own search stays as it was measured: no waves after it.
        s.wave_starts = 0;
        s.wave_starts_3d = 0;
        s.start_ranking = StartRanking::Both;
        s.finalists = 6;
        s.finalist_gap_tol = 0.5;
        s.refine_rounds = 2;
        s
    }
}

/// Plans `problem` with the yardstick: `how.runs` runs of [`PlannerSettings::exhaustive`],
/// each seeded anew; the best `Optimal` plan (else the best of any quality).
pub fn plan_exhaustive(
    problem: &Problem,
    how: &Exhaustive,
    clock: &'static dyn Clock,
) -> Result<ExhaustiveOutcome, PlanError> {
    let started = clock.now();
    let mut best: Option<PlanOutcome> = None;
    let mut runs = Vec::with_capacity(how.runs);
    let mut cuts = 0;
    for run in 0..how.runs.max(1) {
        let settings = PlannerSettings::exhaustive(how.seed.wrapping_add(run as u64));
        settings.validate()?;
        let mut planner = Planner::new(&settings);
        // Deadlines need `'static` parts; one small log per run.
        let log: &'static CutLog = Box::leak(Box::new(CutLog::new()));
        log.begin(None);
        let deadline = Deadline::after(clock, how.budget).with_cuts(log);
        let outcome = planner.plan(problem, &settings, deadline)?;
        cuts += log.finish().len();
        runs.push((outcome.quality, outcome.cost));
        if best.as_ref().is_none_or(|b| better(&outcome, b)) {
            best = Some(outcome);
        }
    }
    let best = best.ok_or(PlanError::NonFinite)?;
    Ok(ExhaustiveOutcome {
        best,
        runs,
        cuts,
        elapsed: clock.now().saturating_sub(started),
    })
}

/// Whether `a` beats `b`: `Optimal` beats any other quality, then the lower cost.
fn better(a: &PlanOutcome, b: &PlanOutcome) -> bool {
    let optimal = |o: &PlanOutcome| o.quality == Quality::Optimal;
    match (optimal(a), optimal(b)) {
        (true, false) => true,
        (false, true) => false,
        _ => a.cost < b.cost,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clock::MonotonicClock;
    use crate::scenario::bundled;

    /// On a canonical scenario the yardstick's plan is `Optimal`, uncut, and no worse
    /// than the deployment settings' plan (within the solver's tolerance, 1e-6 relative).
    #[test]
    fn the_yardstick_is_no_worse_than_the_default_plan() {
        let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
        let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
        let problem = Problem::from_scenario(&sc).unwrap();
        let how = Exhaustive {
            runs: 1,
            ..Exhaustive::default()
        };
        let yardstick = plan_exhaustive(&problem, &how, clock).unwrap();
        assert_eq!(yardstick.cuts, 0);
        assert_eq!(yardstick.best.quality, Quality::Optimal);
        assert_eq!(yardstick.runs.len(), 1);

        let settings = PlannerSettings::default();
        let mut planner = Planner::new(&settings);
        let deadline = Deadline::after(clock, Duration::from_secs(60));
        let default = planner.plan(&problem, &settings, deadline).unwrap();
        assert!(
            yardstick.best.cost <= default.cost * (1.0 + 1e-6),
            "yardstick {} against default {}",
            yardstick.best.cost,
            default.cost
        );
        assert!(PlannerSettings::exhaustive(7).validate().is_ok());
    }
}
