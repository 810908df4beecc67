//! The hybrid planner (FORMULATION.md §7, dissertation chapter IV): deterministic spline
//! seeds and a particle swarm find the basin; the swarm's best, lifted to the full model,
//! starts the LGR collocation NLP, which makes it locally optimal and dynamically
//! feasible; h-refinement rounds make the mesh fine where the plan needs it; the result is
//! flown with the tracking law and exported densely.
//!
//! It is *anytime* under one deadline: the time left flows from the swarm to the NLP and
//! its refinement rounds. At the deadline it returns the best it has, flagged:
//! `Optimal` (the NLP converged), `Feasible` (the NLP stopped early with its constraints
//! within tolerance), `SwarmOnly` (the swarm's lifted path).

mod deflect;
mod exhaustive;
mod global;
mod nlp_stage;
mod schedule;
mod settings;
mod timing;
mod warm_start;
mod waves;

pub use exhaustive::{Exhaustive, ExhaustiveOutcome, plan_exhaustive};
use nlp_stage::{Finaled, NlpStage, Ranked, Solved};
pub use settings::{MeshSettings, PlannerSettings, PlannerSettingsError};
pub use warm_start::{FlyingPlan, PlanSolution, WarmReport};

use std::sync::Arc;
use std::time::Duration;

use wingman_interfaces::Quality;

use crate::basins;
use crate::clock::Deadline;
use crate::collocation::kkt::KktCache;
use crate::collocation::{ExportSettings, Mesh, NlpStatus};
use crate::cuts::{Part, Work};
use crate::problem::Problem;
use crate::swarm::{self, SwarmWorkspace};
use crate::trajectory::Trajectory;
use timing::{SolveTiming, StageTiming};

/// Bad input: the planner cannot start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    #[error("invalid problem: {0}")]
    Problem(#[from] crate::problem::ProblemError),
    #[error("swarm: {0}")]
    Swarm(#[from] swarm::SwarmError),
    #[error("NLP settings: {0}")]
    Nlp(#[from] crate::collocation::solve::OptionError),
    #[error("planner settings: {0}")]
    Settings(#[from] PlannerSettingsError),
    #[error("the planner produced a non-finite trajectory")]
    NonFinite,
}

/// Time spent in each stage.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StageTimes {
    pub swarm: Duration,
    pub nlp: Duration,
    /// The part of `nlp` spent ranking the starts on the coarse mesh.
    pub ranking: Duration,
    pub export: Duration,
    /// A re-plan's warm path (solving from the plan in flight), before the global search.
    pub warm: Duration,
    pub total: Duration,
}

/// Which path made the plan (the `Plan` message's `path`).
pub use wingman_interfaces::PlanPath;

/// What the NLP stage did.
#[derive(Debug, Clone, PartialEq)]
pub struct NlpReport {
    /// Status of the last solve.
    pub status: Option<NlpStatus>,
    /// Iterations of each solve (first mesh, then each refinement round).
    pub iterations: Vec<usize>,
    /// Intervals per phase of the final mesh.
    pub intervals: Vec<usize>,
    /// Objective of the last accepted solve (its own quadrature).
    pub objective: f64,
    /// Dense cost of each start after its ranking solve (`NaN`: no feasible result).
    pub ranking: Vec<f64>,
    /// The starts solved on the working mesh, best ranked first (`ranking.len()`: the
    /// swarm's best, when no start ranked).
    pub finalists: Vec<usize>,
}

/// The planner's answer.
#[derive(Debug, Clone)]
pub struct PlanOutcome {
    pub quality: Quality,
    /// The plan: dense samples of the flown path with its controls and phase end times.
    pub trajectory: Trajectory,
    /// The objective of `trajectory` re-evaluated on its samples (Simpson).
    pub cost: f64,
    /// The swarm's best path (lifted), for reports and plots.
    pub swarm_best: Trajectory,
    pub swarm_cost: f64,
    pub swarm_iterations: usize,
    pub nlp: NlpReport,
    pub times: StageTimes,
    /// Which path made the plan.
    pub path: PlanPath,
    /// A re-plan's warm path, when the problem continued the plan in flight.
    pub warm: Option<WarmReport>,
    /// From the plan's start to its first `Optimal` solution (`None`: it has none).
    pub first_optimal: Option<Duration>,
    /// The NLP solution the plan was exported from, primal and dual, when its solve
    /// converged: a re-plan of the rest of its mission starts from it
    /// ([`FlyingPlan::with_solution`]).
    pub solution: Option<Arc<PlanSolution>>,
}

/// The planner with its reusable workspace.
pub struct Planner {
    swarm: SwarmWorkspace,
    /// Per model (2-D, 3-D): about the longest set-up, iteration and wrap-up of the NLP
    /// solves of recent plans, to keep the deadline.
    timing: [SolveTiming; 2],
    /// Per model: how long recent plans' ranking and fallback took, to decide whether a
    /// budget can hold the NLP stage at all.
    stage: [StageTiming; 2],
    /// The KKT workspaces of recent solves, kept for solves of the same pattern, and the
    /// factorisations' counters: the planner's own, shared by its threads.
    kkt: Arc<KktCache>,
    /// The settings last validated: a service plans with the same ones every time, and
    /// their check (extra solver options are tried on a solver) is not repeated.
    validated: Option<PlannerSettings>,
}

impl Planner {
    /// A planner with its own pool of KKT workspaces.
    pub fn new(settings: &PlannerSettings) -> Planner {
        Planner::with_kkt_cache(settings, Arc::new(KktCache::new()))
    }

    /// A planner whose solves pool their KKT workspaces in `kkt`, which other planners may
    /// share (a benchmark that plans each time with a fresh planner, as a service keeps
    /// one).
    pub fn with_kkt_cache(settings: &PlannerSettings, kkt: Arc<KktCache>) -> Planner {
        Planner {
            swarm: SwarmWorkspace::new(&settings.swarm),
            timing: [SolveTiming::prior(false), SolveTiming::prior(true)],
            stage: [StageTiming::prior(false), StageTiming::prior(true)],
            kkt,
            validated: None,
        }
    }

    /// Validates `settings` unless they are the ones validated last.
    fn check(&mut self, settings: &PlannerSettings) -> Result<(), PlannerSettingsError> {
        if self.validated.as_ref() != Some(settings) {
            settings.validate()?;
            self.validated = Some(settings.clone());
        }
        Ok(())
    }

    /// The planner's pool of KKT workspaces and its factorisations' counters.
    pub fn kkt_cache(&self) -> &Arc<KktCache> {
        &self.kkt
    }

    /// The seeds of the last plan (for plots).
    pub fn swarm_workspace(&self) -> &SwarmWorkspace {
        &self.swarm
    }

    /// Plans `problem` by `deadline` from scratch (the global search alone). Never fails
    /// on a valid problem: at worst the swarm's path comes back flagged `SwarmOnly`.
    pub fn plan(
        &mut self,
        problem: &Problem,
        settings: &PlannerSettings,
        deadline: Deadline<'static>,
    ) -> Result<PlanOutcome, PlanError> {
        self.plan_from(problem, settings, deadline, None)
    }

    /// Re-plans `problem` by `deadline`, anytime: when `problem` continues the tasking of
    /// `flying` (the plan in flight), first from that plan cut at `problem`'s start (the
    /// warm path), then, with the time left, by the global search; the better of the two
    /// by the deadline is returned. A problem of another tasking is planned as by
    /// [`Planner::plan`].
    pub fn replan(
        &mut self,
        problem: &Problem,
        settings: &PlannerSettings,
        deadline: Deadline<'static>,
        flying: &FlyingPlan,
    ) -> Result<PlanOutcome, PlanError> {
        self.plan_from(problem, settings, deadline, Some(flying))
    }

    /// The warm path if `flying` is given and continued, then the global search; the
    /// better plan.
    fn plan_from(
        &mut self,
        problem: &Problem,
        settings: &PlannerSettings,
        deadline: Deadline<'static>,
        flying: Option<&FlyingPlan>,
    ) -> Result<PlanOutcome, PlanError> {
        problem.validate()?;
        self.check(settings)?;
        let clock = deadline.clock();
        let started = clock.now();
        let warm_deadline = deadline.within(Part::Warm);
        let global_deadline = deadline.within(Part::Global);
        let warm = match flying.and_then(|f| f.guess_for(problem).map(|g| (f, g))) {
            Some((flying, guess)) => {
                Some(self.warm(problem, settings, warm_deadline, flying, guess)?)
            }
            None => None,
        };
        let mut outcome = match warm {
            // The global search could only return the swarm's path, which an NLP plan
            // beats: it is not run (both cores are left idle instead).
            Some(warm)
                if warm.has_plan()
                    && global_deadline
                        .cuts(0, |d| !self.global_nlp_fits(problem, settings, *d)) =>
            {
                PlanOutcome::of_warm(warm)
            }
            Some(warm) => {
                // A warm plan is a better floor than the coarse one.
                let floor_wanted = !warm.has_plan();
                let mut outcome =
                    self.global(problem, settings, global_deadline, floor_wanted, false)?;
                outcome.offer(warm);
                outcome
            }
            // A plan from scratch: waves of further starts with the time it leaves.
            None => self.global(problem, settings, global_deadline, true, true)?,
        };
        outcome.times.total = clock.now().saturating_sub(started);
        Ok(outcome)
    }
}

/// How solutions on the way are exported (to rank them, to start the next mesh from):
/// densely, open loop.
fn reference_export(settings: &PlannerSettings) -> ExportSettings {
    ExportSettings {
        closed_loop: false,
        max_step_s: settings.export.max_step_s / 2.0,
        ..settings.export
    }
}

/// The coarse ranking mesh of each start.
fn ranking_meshes(
    problem: &Problem,
    settings: &PlannerSettings,
    starts: &[Trajectory],
) -> Vec<Mesh> {
    let rank = if problem.dim() == 3 {
        &settings.ranking_mesh_3d
    } else {
        &settings.ranking_mesh
    };
    starts
        .iter()
        .map(|g| {
            Mesh::uniform(
                rank.points,
                &phase_durations(problem.t0, g),
                rank.interval_s,
                rank.min_intervals,
            )
        })
        .collect()
}

/// What the NLP stage's schedule left: the report, the accepted solution on its mesh, and
/// whether a rank was stopped by the deadline.
struct Gathered {
    report: NlpReport,
    accepted: Option<(Solved, Mesh)>,
    cut: bool,
    /// When (stage clock) the first `Optimal` solution of a final or a round was there.
    first_optimal: Option<Duration>,
    /// The NLP work done: each solve's iterations times its mesh's intervals, summed.
    /// Counted, not timed, so the same on any computer (the waves' gate, `waves`).
    work: usize,
}

/// The schedule's results in the step-by-step order (ranks, finals, rounds) into the
/// report, any error among them returned as it would have been met; the rounds after the
/// first (which ran in the schedule) follow here. A task that failed (panicked) counts as
/// a failed solve.
fn gather<'a>(
    stage: &NlpStage<'a>,
    done: schedule::Schedule<NlpStage<'a>>,
    deadline: Deadline<'static>,
) -> Result<Gathered, PlanError> {
    // The candidate whose final won: the rounds descend from it.
    let winner = done.winner.map_or(0, |k| done.chosen[k]);
    let mut report = NlpReport {
        status: None,
        iterations: Vec::new(),
        intervals: Vec::new(),
        objective: f64::NAN,
        ranking: Vec::new(),
        finalists: done.chosen,
    };
    let failed = || Ok((None, 0, NlpStatus::NumericalError, SolveTiming::default()));
    // A rank the deadline stopped: the ranking was cut short.
    let mut cut = false;
    let mut work = 0;
    for (r, coarse) in done.ranks.into_iter().zip(stage.coarse) {
        let (path, result) = match r {
            Some(Ranked { result, path }) => (path, result),
            None => (None, failed()),
        };
        let (_, iterations, status, _) = result?;
        work += iterations * coarse.intervals();
        cut |= status == NlpStatus::MaxTime;
        report.iterations.push(iterations);
        report.status = Some(status);
        report.ranking.push(path.map_or(f64::NAN, |p| p.0));
    }
    let mut accepted: Option<(Solved, Mesh)> = None;
    // When the first `Optimal` solution (of a final or a round) was there.
    let mut first_optimal: Option<Duration> = None;
    let mut optimal_at = |solved: Option<&Solved>, at: Duration| {
        if solved.is_some_and(|s| s.quality == Quality::Optimal) {
            first_optimal = Some(first_optimal.map_or(at, |f| f.min(at)));
        }
    };
    for (k, f) in done.finals.into_iter().enumerate() {
        let (result, fine, done_at) = match f {
            Some(Finaled {
                result,
                mesh,
                done_at,
            }) => (result, Some(mesh), done_at),
            None => (failed(), None, Duration::ZERO),
        };
        let (solved, iterations, status, _) = result?;
        work += iterations * fine.as_ref().map_or(0, Mesh::intervals);
        report.iterations.push(iterations);
        report.status = Some(status);
        optimal_at(solved.as_ref(), done_at);
        if done.winner == Some(k)
            && let (Some(s), Some(fine)) = (solved, fine)
        {
            accepted = Some((s, fine));
        }
    }
    let mut round_result = done.round.flatten();
    for round in 0..stage
        .settings
        .refine_rounds
        .max(usize::from(stage.polish()))
    {
        let Some((current, mesh)) = accepted.as_ref() else {
            break;
        };
        let current_optimal = current.quality == Quality::Optimal;
        let next = if round == 0 {
            round_result.take()
        } else if !current_optimal
            || deadline
                .at(Work::Refinement)
                .cuts(round as u32, Deadline::expired)
        {
            break;
        } else {
            stage.round_after(round, winner, current, mesh, false, None)
        };
        let Some((result, next, done_at)) = next else {
            break;
        };
        let (solved, iterations, status, _) = result?;
        work += iterations * next.intervals();
        report.iterations.push(iterations);
        report.status = Some(status);
        optimal_at(solved.as_ref(), done_at);
        match solved {
            // A round the deadline stopped short of converging does not refine an
            // `Optimal` plan: its iterate may be anywhere on the way (c3-0013: cost 55.6
            // through a threat, after 0.0038 on the mesh before). The plan stays there.
            Some(s) if s.quality == Quality::Optimal || !current_optimal => {
                accepted = Some((s, next));
            }
            _ => break,
        }
    }
    if let Some((a, mesh)) = &accepted {
        report.objective = a.objective;
        report.status = Some(a.status);
        report.intervals = mesh.phases.iter().map(Vec::len).collect();
    }
    Ok(Gathered {
        report,
        accepted,
        cut,
        first_optimal,
        work,
    })
}

/// The ranked starts (lowest dense cost first) that go on to the working mesh: the best,
/// then up to `finalists - 1` more that are neither a duplicate of one already taken (a
/// ranked cost within `finalist_duplicate_tol` of it, relative, on a path not distinct
/// from it: the same basin reached twice) nor out of the race (above the best by more
/// than `finalist_gap_tol`).
fn finalists(ranked: &[(f64, usize, &Trajectory)], settings: &PlannerSettings) -> Vec<usize> {
    let mut taken: Vec<(f64, usize, &Trajectory)> = Vec::with_capacity(settings.finalists);
    for &r in ranked {
        let Some(best) = taken.first().map(|t| t.0) else {
            taken.push(r);
            continue;
        };
        if taken.len() >= settings.finalists.max(1)
            || r.0 > best + settings.finalist_gap_tol * best.abs()
        {
            break;
        }
        let duplicate = taken.iter().any(|t| {
            (r.0 - t.0).abs() <= settings.finalist_duplicate_tol * t.0.abs()
                && basins::separation(r.2, t.2) <= basins::MIN_SEPARATION_M
        });
        if !duplicate {
            taken.push(r);
        }
    }
    taken.into_iter().map(|t| t.1).collect()
}

/// Phase durations of a trajectory (at least one second each).
pub fn phase_durations(t0: f64, tr: &Trajectory) -> Vec<f64> {
    let mut prev = t0;
    tr.phase_ends
        .iter()
        .map(|&e| {
            let d = (e - prev).max(1.0);
            prev = e;
            d
        })
        .collect()
}

/// Farthest the exported plan's end may lie from where its problem wants it (the final
/// point, or the lead at the plan's final time), and farthest it may pass from a target,
/// for the plan to keep its NLP solution's `Optimal`, m. The NLP meets its end to its
/// tolerance, but a 3-D plan is exported as its path flown by the tracking law, and a path the working mesh resolves too coarsely (its
/// refinement round cut by the deadline) can be flown hundreds of metres off: a 3-D
/// rendezvous re-planned for a lead's new route ended 743 m from the lead. Exports of
/// converged plans end within a few metres.
pub const EXPORT_END_TOL_M: f64 = 50.0;

/// How far the end of `tr` lies from where `problem` wants it, m.
pub fn end_miss_m(problem: &Problem, tr: &Trajectory) -> f64 {
    let (Some(&t), Some(state)) = (tr.times.last(), tr.states.last()) else {
        return f64::INFINITY;
    };
    let (at, wanted) = (problem.position(state), problem.final_position_at(t));
    distance(&at, &wanted, problem.dim())
}

/// How far `tr` passes from the target of `problem` it passes farthest from, m (0 with no
/// target): for each target the closest approach of the path, taken as straight between
/// its samples (0.5 s apart, up to 130 m at 3-D speeds), in the horizontal plane in 2-D.
pub fn target_miss_m(problem: &Problem, tr: &Trajectory) -> f64 {
    let (dims, at) = (problem.dim(), |s: &[f64; 7]| problem.position(s));
    let closest = |target: &[f64; 3]| {
        if let [only] = tr.states.as_slice() {
            return distance(&at(only), target, dims);
        }
        tr.states
            .windows(2)
            .map(|ab| segment_distance(&at(&ab[0]), &at(&ab[1]), target, dims))
            .fold(f64::INFINITY, f64::min)
    };
    problem.targets.iter().map(closest).fold(0.0, f64::max)
}

/// The distance from `p` to the segment from `a` to `b`, in the first `dims` coordinates.
fn segment_distance(a: &[f64; 3], b: &[f64; 3], p: &[f64; 3], dims: usize) -> f64 {
    let along: f64 = (0..dims).map(|i| (p[i] - a[i]) * (b[i] - a[i])).sum();
    let length2: f64 = (0..dims).map(|i| (b[i] - a[i]) * (b[i] - a[i])).sum();
    let s = if length2 > 0.0 {
        (along / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let on = [0, 1, 2].map(|i| a[i] + s * (b[i] - a[i]));
    distance(&on, p, dims)
}

/// The distance between `a` and `b` in their first `dims` coordinates.
fn distance(a: &[f64; 3], b: &[f64; 3], dims: usize) -> f64 {
    (0..dims)
        .map(|i| (a[i] - b[i]) * (a[i] - b[i]))
        .sum::<f64>()
        .sqrt()
}

/// The quality of `tr`, exported from an NLP solution of `quality`: an `Optimal` solution
/// whose export misses its end, or passes a target, farther than [`EXPORT_END_TOL_M`] is
/// only `Feasible` (and the service refines it at once).
pub(super) fn exported_quality(problem: &Problem, tr: &Trajectory, quality: Quality) -> Quality {
    if quality == Quality::Optimal
        && (end_miss_m(problem, tr) > EXPORT_END_TOL_M
            || target_miss_m(problem, tr) > EXPORT_END_TOL_M)
    {
        Quality::Feasible
    } else {
        quality
    }
}

/// The objective (FORMULATION.md §4) of a sampled trajectory: `|u|²` integrated exactly
/// for controls linear between samples, `E` by composite Simpson on the samples.
pub fn trajectory_cost(problem: &Problem, tr: &Trajectory) -> f64 {
    use wingman_interfaces::Objective;
    let n = tr.len();
    if n < 2 {
        return f64::INFINITY;
    }
    let nu = problem.nu();
    let mut effort = 0.0;
    for k in 0..n - 1 {
        let dt = tr.times[k + 1] - tr.times[k];
        for e in 0..nu {
            let (a, b) = (tr.controls[k][e], tr.controls[k + 1][e]);
            effort += dt * (a * a + a * b + b * b) / 3.0;
        }
    }
    let exposure = crate::metrics::simpson_by(&tr.times, |k| {
        problem.exposure(&problem.position(&tr.states[k]), tr.times[k])
    });
    let w = &problem.weights;
    let run = (1.0 - w.beta) * effort + w.beta * exposure;
    match problem.objective {
        Objective::FixedTime => run,
        _ => w.alpha * tr.times[n - 1] + (1.0 - w.alpha) * run,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The problem of the bundled `2d-min-time-avoidable` (one target).
    fn min_time_avoidable() -> Problem {
        let sc = crate::scenario::bundled("2d-min-time-avoidable")
            .unwrap()
            .unwrap();
        Problem::from_scenario(&sc).unwrap()
    }

    /// A straight 2-D path from `(0, y)` east at 200 m/s for 100 s.
    fn line(y: f64) -> Trajectory {
        let mut tr = Trajectory::default();
        for k in 0..=10 {
            let t = 10.0 * k as f64;
            tr.push(t, [200.0 * t, y, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0; 2]);
        }
        tr.phase_ends = vec![100.0];
        tr
    }

    /// An `Optimal` solution whose export ends more than 50 m from the final point is only
    /// `Feasible`; the miss is the horizontal distance in 2-D (the third state entry is
    /// the heading), checked against the 3-4-5 triangle. (The path passes through the
    /// target on a middle sample.)
    #[test]
    fn an_export_that_misses_its_end_is_not_optimal() {
        let problem = min_time_avoidable();
        let (target, end) = (problem.targets[0], problem.final_position_at(0.0));
        let ending_at = |dx: f64, dy: f64| {
            let mut tr = line(0.0);
            tr.states[5][0] = target[0];
            tr.states[5][1] = target[1];
            let last = tr.states.len() - 1;
            tr.states[last][0] = end[0] + dx;
            tr.states[last][1] = end[1] + dy;
            tr.states[last][2] = 2.5;
            tr
        };
        assert!(end_miss_m(&problem, &ending_at(0.0, 0.0)) < 1e-9);
        assert!((end_miss_m(&problem, &ending_at(30.0, 40.0)) - 50.0).abs() < 1e-9);
        let q = |tr: &Trajectory, q| exported_quality(&problem, tr, q);
        assert_eq!(
            q(&ending_at(27.0, 36.0), Quality::Optimal),
            Quality::Optimal
        );
        assert_eq!(
            q(&ending_at(33.0, 44.0), Quality::Optimal),
            Quality::Feasible
        );
        assert_eq!(
            q(&ending_at(33.0, 44.0), Quality::Feasible),
            Quality::Feasible
        );
        assert_eq!(end_miss_m(&problem, &Trajectory::default()), f64::INFINITY);
    }

    /// An `Optimal` solution whose export passes a target farther than 50 m is only
    /// `Feasible`. The pass is the path's closest approach taken straight between its
    /// samples: here midway between two samples 2 km apart and `d` abeam of the target, so
    /// the miss is `d` (no sample comes nearer than 1 km); the path ends on the final point.
    #[test]
    fn an_export_that_passes_a_target_wide_is_not_optimal() {
        let problem = min_time_avoidable();
        let (target, end) = (problem.targets[0], problem.final_position_at(0.0));
        let passing = |d: f64| {
            let mut tr = Trajectory::default();
            for (t, x, y) in [
                (0.0, target[0] - 1000.0, target[1] + d),
                (10.0, target[0] + 1000.0, target[1] + d),
                (20.0, end[0], end[1]),
            ] {
                tr.push(t, [x, y, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0; 2]);
            }
            tr.phase_ends = vec![5.0, 20.0];
            tr
        };
        assert!((target_miss_m(&problem, &passing(40.0)) - 40.0).abs() < 1e-9);
        assert!(end_miss_m(&problem, &passing(40.0)) < 1e-9);
        let q = |tr: &Trajectory, q| exported_quality(&problem, tr, q);
        assert_eq!(q(&passing(49.0), Quality::Optimal), Quality::Optimal);
        assert_eq!(q(&passing(-51.0), Quality::Optimal), Quality::Feasible);
        assert_eq!(
            target_miss_m(&problem, &Trajectory::default()),
            f64::INFINITY
        );
    }

    #[test]
    fn separation_is_the_mean_horizontal_gap_at_equal_fractions_of_the_paths() {
        // Exact: parallel lines 300 m apart; the heading (index 2) is not a position.
        assert_eq!(basins::separation(&line(0.0), &line(300.0)), 300.0);
        let mut turned = line(0.0);
        turned.states[10][2] = 1.0;
        assert_eq!(basins::separation(&line(0.0), &turned), 0.0);
        // The same path flown slower (twice the duration) is the same path.
        let mut slow = line(0.0);
        slow.times.iter_mut().for_each(|t| *t *= 2.0);
        assert!(basins::separation(&line(0.0), &slow) < 1e-9);
        assert_eq!(
            basins::separation(&line(0.0), &Trajectory::default()),
            f64::INFINITY
        );
    }

    #[test]
    fn finalists_skip_duplicates_and_starts_out_of_the_race() {
        let settings = PlannerSettings::default();
        let picked = |entries: &[(f64, f64)]| -> Vec<usize> {
            let paths: Vec<Trajectory> = entries.iter().map(|e| line(e.1)).collect();
            let ranked: Vec<(f64, usize, &Trajectory)> = entries
                .iter()
                .zip(&paths)
                .enumerate()
                .map(|(i, (&(cost, _), tr))| (cost, i, tr))
                .collect();
            finalists(&ranked, &settings)
        };
        // A close cost on a path 100 m away is the same basin: the next distinct one goes.
        assert_eq!(picked(&[(10.0, 0.0), (10.005, 100.0), (10.2, 9e3)]), [0, 2]);
        // A close cost on a path 9 km away is another basin (2d-min-time-unavoidable,
        // seeds 17-18: 0.07 % apart, 43 km apart, and the second won on the working mesh).
        assert_eq!(picked(&[(10.0, 0.0), (10.007, 9e3), (10.2, 1e3)]), [0, 1]);
        // More than 10 % above the best: out of the race, and so is everything after it.
        assert_eq!(picked(&[(10.0, 0.0), (11.5, 9e3), (11.6, -9e3)]), [0]);
        // At most `finalists`.
        assert_eq!(
            picked(&[(10.0, 0.0), (10.1, 9e3), (10.2, -9e3), (10.3, 2e4)]),
            [0, 1]
        );
        assert!(finalists(&[], &settings).is_empty());
    }
}
