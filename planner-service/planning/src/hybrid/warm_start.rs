//! The warm re-plan: the plan the aircraft flies is, cut at the new plan's start, a start
//! already in the right basin and close to the new optimum (what is left of an optimal
//! path is optimal for what is left of the mission, until the world changes). A re-plan
//! of the same tasking solves from it first; the global search follows with the time left
//! (see [`super::Planner::replan`]).

use std::sync::Arc;
use std::time::Duration;

use wingman_interfaces::{Model, Objective, Quality};

use super::deflect;
use super::nlp_stage::{NlpStage, Solved};
use super::timing::Seen;
use super::{
    Gathered, NlpReport, PlanError, PlanOutcome, PlanPath, Planner, PlannerSettings, StageTimes,
    exported_quality, gather, ranking_meshes, reference_export, schedule, trajectory_cost,
};
use crate::basins::{self, StartRanking};
use crate::clock::Deadline;
use crate::collocation::transcription::nearest_turn;
use crate::collocation::{PrimalDual, Transcription, export};
use crate::cuts::Work;
use crate::lead::distance;
use crate::problem::{Problem, Threats};
use crate::seeding;
use crate::swarm::SwarmError;
use crate::trajectory::Trajectory;

/// What a re-plan's warm path did.
#[derive(Debug, Clone, PartialEq)]
pub struct WarmReport {
    /// The quality of its solution (`None`: no solve was accepted, or none could start).
    pub quality: Option<Quality>,
    /// The dense cost of its plan (infinite without one).
    pub cost: f64,
    /// Its solves.
    pub nlp: NlpReport,
    /// From its start to its first `Optimal` solution.
    pub first_optimal: Option<Duration>,
    /// How long it took.
    pub elapsed: Duration,
}

/// The warm path's plan, offered to the plan's outcome against the global search's.
pub(super) struct WarmPlan {
    report: WarmReport,
    trajectory: Option<Trajectory>,
    solution: Option<Arc<PlanSolution>>,
}

/// A plan's NLP solution on its last mesh, primal and dual (a converged solve's): the
/// multipliers a re-plan of the rest of its mission starts from.
#[derive(Debug)]
pub struct PlanSolution {
    pub(super) tr: Transcription,
    pub(super) duals: PrimalDual,
}

impl PlanSolution {
    /// The solution of an accepted solve, if it converged (its multipliers are known).
    pub(super) fn of(solved: Solved) -> Option<Arc<PlanSolution>> {
        let Solved { tr, warm, .. } = solved;
        warm.map(|duals| Arc::new(PlanSolution { tr, duals }))
    }
}

/// A new threat whose `F` along the plan in flight falls below this (about 1.4 of an
/// ellipsoid's half-extents) is near the plan: its multipliers are not carried over.
const NEAR_NEW_F: f64 = 2.0;

impl Planner {
    /// The warm path: `guess` (the plan in flight cut at the start) solved on the working
    /// mesh and refined, as a finalist is, on the calling thread. When `guess` crosses
    /// threats the plan in flight did not know, its bends around them (`deflect`) and, in
    /// 2-D, seeds of other basins are the starts of an NLP stage as the global search's,
    /// on the planner's threads; `guess` itself is solved only if none of them ranks.
    /// Ranked, it only came back to a bend's basin (it is pushed out of the threat on
    /// whichever side the gradient points, a side a bend starts on): in the re-plan
    /// bench of 2026-12-06 it never ranked better than the best bend or seed by 0.1 % but
    /// where the deadline had cut the others, and leaving it out made the 3-D pop-ups'
    /// time to `Optimal` 51 -> 36 ms (median) and the 2-D ones' 27 -> 26 ms (0035).
    pub(super) fn warm(
        &mut self,
        problem: &Problem,
        settings: &PlannerSettings,
        deadline: Deadline<'static>,
        flying: &FlyingPlan,
        guess: Trajectory,
    ) -> Result<WarmPlan, PlanError> {
        let clock = deadline.clock();
        let started = clock.now();
        let model = usize::from(problem.dim() == 3);
        let bends = deflect::deflected(problem, &flying.threats, &guess);
        let starts: Vec<Trajectory> = if bends.is_empty() {
            Vec::new()
        } else {
            let seeds = seed_starts(problem, settings, &guess, deadline)?;
            bends.into_iter().chain(seeds).collect()
        };
        let coarse = ranking_meshes(problem, settings, &starts);
        // The export of its plan is kept time for, as the global search keeps it.
        let nlp_deadline = deadline.earlier(self.stage[model].fallback * 2);
        let stage = NlpStage {
            problem,
            settings,
            starts: &starts,
            coarse: &coarse,
            fallback_start: &guess,
            // The plain solve of the plan in flight takes its multipliers too, unless a new
            // threat has come near it (they are the costates of the old world: from them a
            // 3-D solve past a new threat did not converge in 100 ms, from the path alone
            // it did).
            fallback_warm: flying.solution.as_deref().filter(|_| {
                settings.warm_mesh_changes
                    && starts.is_empty()
                    && !deflect::near_new_threat(problem, &flying.threats, &guess, NEAR_NEW_F)
            }),
            to_beat: None,
            reference: reference_export(settings),
            timing: self.timing[model],
            seen: Seen::default(),
            deadline: nlp_deadline,
            kkt: &self.kkt,
        };
        let threads = if starts.is_empty() {
            1
        } else {
            settings.threads
        };
        let done = schedule::run(&stage, threads);
        let Gathered {
            report,
            accepted,
            first_optimal,
            ..
        } = gather(&stage, done, nlp_deadline)?;
        self.timing[model] = self.timing[model].after(stage.seen.get());
        let trajectory = accepted.as_ref().map(|(a, _)| {
            let mut flown = Trajectory::default();
            export(&a.tr, &a.x, &settings.export, &mut flown);
            flown
        });
        let trajectory = trajectory.filter(Trajectory::is_valid);
        let cost = trajectory
            .as_ref()
            .map_or(f64::INFINITY, |t| trajectory_cost(problem, t));
        let quality = trajectory
            .as_ref()
            .zip(accepted.as_ref())
            .map(|(t, (a, _))| exported_quality(problem, t, a.quality));
        Ok(WarmPlan {
            solution: accepted.and_then(|(a, _)| PlanSolution::of(a)),
            report: WarmReport {
                quality,
                cost,
                nlp: report,
                first_optimal: first_optimal.map(|t| t.saturating_sub(started)),
                elapsed: clock.now().saturating_sub(started),
            },
            trajectory,
        })
    }
}

/// The starts from the global search's seeds that a warm path with bends adds (2-D:
/// `warm_seed_starts`, 3-D: `warm_seed_starts_3d`): the cheapest seeds of the re-plan's
/// problem that pass some threat on another side than `guess` and than each other
/// (`basins::candidates`). A pop-up across the plan often makes the best route another
/// way around other threats too, which a bend around the pop-up alone does not reach.
fn seed_starts(
    problem: &Problem,
    settings: &PlannerSettings,
    guess: &Trajectory,
    deadline: Deadline<'static>,
) -> Result<Vec<Trajectory>, PlanError> {
    let count = if problem.dim() == 3 {
        settings.warm_seed_starts_3d
    } else {
        settings.warm_seed_starts
    };
    if count == 0 {
        return Ok(Vec::new());
    }
    let mut seeds = Vec::new();
    let deadline = deadline.at(Work::Seeds);
    seeding::seeds_until(problem, &settings.swarm.seeds, &mut seeds, &|tried| {
        deadline.cuts(tried, Deadline::expired)
    })
    .map_err(SwarmError::from)?;
    let cost = |tr: &Trajectory| trajectory_cost(problem, tr);
    let mut starts = basins::candidates(
        problem,
        guess,
        &seeds,
        1 + count,
        settings.threads,
        // A warm re-plan's few seed starts, ranked as a plan's (the yardstick's wider
        // ranking would double them).
        StartRanking::OnTimeFirst,
        cost,
    );
    // The first is `guess` itself.
    starts.remove(0);
    Ok(starts)
}

impl WarmPlan {
    /// Whether the warm path has a plan (an accepted NLP solution).
    pub(super) fn has_plan(&self) -> bool {
        self.report.quality.is_some() && self.trajectory.is_some()
    }
}

impl PlanOutcome {
    /// The warm path's plan alone (no global search ran: no swarm path, no swarm time).
    pub(super) fn of_warm(warm: WarmPlan) -> PlanOutcome {
        let WarmPlan {
            report,
            trajectory,
            solution,
        } = warm;
        PlanOutcome {
            quality: report.quality.unwrap_or(Quality::SwarmOnly),
            trajectory: trajectory.unwrap_or_default(),
            cost: report.cost,
            swarm_best: Trajectory::default(),
            swarm_cost: f64::NAN,
            swarm_iterations: 0,
            nlp: report.nlp.clone(),
            times: StageTimes {
                warm: report.elapsed,
                ..StageTimes::default()
            },
            path: PlanPath::Warm,
            first_optimal: report.first_optimal,
            warm: Some(report),
            solution,
        }
    }

    /// Takes the warm path's plan if it is better than this (the global search's, which
    /// followed it): a solution of the NLP against the swarm's path, else the lower cost
    /// (a tie to the warm path). The warm path's report is kept either way.
    pub(super) fn offer(&mut self, warm: WarmPlan) {
        let WarmPlan {
            report,
            trajectory,
            solution,
        } = warm;
        self.times.warm = report.elapsed;
        // The global search started after the warm path.
        self.first_optimal = self.first_optimal.map(|t| t + report.elapsed);
        if report.first_optimal.is_some() {
            self.first_optimal = report.first_optimal;
        }
        let warm_wins = match (report.quality, trajectory) {
            (Some(quality), Some(trajectory))
                if self.quality == Quality::SwarmOnly || report.cost <= self.cost =>
            {
                self.quality = quality;
                self.cost = report.cost;
                self.trajectory = trajectory;
                self.nlp = report.nlp.clone();
                self.solution = solution;
                true
            }
            _ => false,
        };
        if warm_wins {
            self.path = PlanPath::Warm;
        }
        self.warm = Some(report);
    }
}

/// The plan in flight, as a re-plan starts from it: its path and the tasking it was made
/// for (to tell whether a new problem continues it).
#[derive(Debug, Clone)]
pub struct FlyingPlan {
    pub model: Model,
    pub objective: Objective,
    /// The targets the plan still had to pass when it was made, in order.
    pub targets: Vec<[f64; 3]>,
    pub final_state: Option<[f64; 7]>,
    pub final_time: Option<f64>,
    /// The threats the plan was made for (a threat not among them that the plan crosses
    /// is deflected around, see `deflect`).
    pub threats: Threats,
    /// The plan's samples; its `phase_ends` are those of `targets` and the final time.
    pub path: Trajectory,
    /// The NLP solution the plan was exported from, if kept: a re-plan's plain solve of
    /// the plan takes its multipliers (at the same mission time) when no target was passed
    /// in between (the same phases).
    pub solution: Option<Arc<PlanSolution>>,
}

impl FlyingPlan {
    /// The plan `path` made for `problem`.
    pub fn new(problem: &Problem, path: Trajectory) -> FlyingPlan {
        FlyingPlan {
            model: problem.model,
            objective: problem.objective,
            targets: problem.targets.clone(),
            final_state: problem.final_state,
            final_time: problem.final_time,
            threats: problem.threats.clone(),
            path,
            solution: None,
        }
    }

    /// This plan with the NLP solution it was exported from (`PlanOutcome::solution`).
    pub fn with_solution(self, solution: Option<Arc<PlanSolution>>) -> FlyingPlan {
        FlyingPlan { solution, ..self }
    }

    /// How many of this plan's targets `problem` leaves out as passed, if `problem`
    /// continues its tasking: the same model, objective and end, and the plan's targets
    /// but for the first ones, which the plan passes by `problem`'s start.
    pub fn passed_targets(&self, problem: &Problem) -> Option<usize> {
        let same_task = self.model == problem.model
            && self.objective == problem.objective
            && self.final_state == problem.final_state
            && self.final_time == problem.final_time;
        let dropped = self.targets.len().checked_sub(problem.targets.len())?;
        let same_targets = self.targets[dropped..] == problem.targets[..];
        let phases_fit = self.path.phase_ends.len() == self.targets.len() + 1;
        // The plan passes the dropped targets by the start (a second of slack: the
        // service drops what the plan passes by the commit time).
        let passed = self.path.phase_ends[..dropped]
            .iter()
            .all(|&e| e <= problem.t0 + 1.0);
        let left = self.path.final_time().is_some_and(|tf| tf > problem.t0);
        (same_task && same_targets && phases_fit && passed && left).then_some(dropped)
    }

    /// The start of a re-plan of `problem` from this plan: its samples after `problem`'s
    /// start, behind `problem`'s start state, the passed targets' phases dropped, the
    /// heading turned by whole turns to continue the start state's. `None` if `problem`
    /// does not continue this plan's tasking, or if it is a 2-D rendezvous whose lead is
    /// no longer near the plan's end ([`FAR_LEAD_SHARE`]).
    pub fn guess_for(&self, problem: &Problem) -> Option<Trajectory> {
        let dropped = self.passed_targets(problem)?;
        let t0 = problem.t0;
        let (at_start, u0) = self.path.at(t0)?;
        let h = problem.heading_index();
        let turns = nearest_turn(at_start[h], problem.x0[h]) - at_start[h];
        let mut guess = Trajectory {
            phase_ends: self.path.phase_ends[dropped..].to_vec(),
            ..Trajectory::default()
        };
        guess.push(t0, problem.x0, u0);
        // Samples closer than a millisecond to the start add nothing but a stiff step.
        let first = self.path.times.partition_point(|&t| t <= t0 + 1e-3);
        for k in first..self.path.len() {
            let mut x = self.path.states[k];
            x[h] += turns;
            guess.push(self.path.times[k], x, self.path.controls[k]);
        }
        // A phase that ends at the start (a target passed right at the commit time) is
        // given a moment, so that the phases stay in order.
        let mut prev = t0;
        for e in &mut guess.phase_ends {
            *e = e.max(prev + 1e-3);
            prev = *e;
        }
        (guess.len() >= 2 && guess.is_valid() && ends_near_the_lead(problem, &guess))
            .then_some(guess)
    }
}

/// A 2-D rendezvous guess whose end is farther than this share of its length from where
/// the lead is at the guess's final time does not continue its plan.
const FAR_LEAD_SHARE: f64 = 0.1;

/// Whether `guess` (the plan in flight cut at `problem`'s start) ends near the lead of a
/// rendezvous `problem` at the guess's final time (any other problem keeps the end its
/// plan was made for: a continued tasking has the same final point). A new route, or a
/// lead off its route, may move the meeting far: a plan made for another meeting is no
/// start for the new one. Dragged to it, it converged across a static threat the plan went
/// around (c1-0061: the meeting moved 85 km on the 282 km left; docs/decisions/0045).
/// In 2-D only: a 3-D plan from scratch does not fit a refinement's 1.2 s on a slow
/// computer (take-off plans 0.9 s p50, 1.4 s p90 there), and 7 of 19 such refinements
/// came out `SwarmOnly` or `Feasible` in the campaign that tried it in 3-D too.
fn ends_near_the_lead(problem: &Problem, guess: &Trajectory) -> bool {
    let Some(lead) = &problem.lead else {
        return true;
    };
    if problem.dim() == 3 {
        return true;
    }
    let (Some(tf), Some(end)) = (guess.final_time(), guess.states.last()) else {
        return false;
    };
    let length: f64 = guess
        .states
        .windows(2)
        .map(|w| distance(&problem.position(&w[0]), &problem.position(&w[1])))
        .sum();
    distance(&problem.position(end), &lead.at(tf).position) <= FAR_LEAD_SHARE * length
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::bundled;
    use std::f64::consts::TAU;

    /// A 2-D problem and a straight plan for it east at 200 m/s through its first target
    /// at t = 50 and on to t = 100.
    fn flying(problem: &Problem) -> FlyingPlan {
        let mut path = Trajectory::default();
        for k in 0..=100 {
            let t = k as f64;
            path.push(t, [200.0 * t, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0; 2]);
        }
        let mut phase_ends: Vec<f64> = (0..problem.targets.len())
            .map(|i| 50.0 + i as f64)
            .collect();
        phase_ends.push(100.0);
        path.phase_ends = phase_ends;
        FlyingPlan::new(problem, path)
    }

    /// A bundled 2-D fixed-time problem given a second target.
    fn problem_with_targets() -> Problem {
        let sc = bundled("2d-fixed-time-avoidable")
            .expect("bundled")
            .expect("valid");
        let mut problem = Problem::from_scenario(&sc).expect("a valid scenario");
        let first = problem.targets[0];
        problem
            .targets
            .push([first[0] + 1000.0, first[1], first[2]]);
        problem
    }

    #[test]
    fn a_re_plan_of_the_same_tasking_starts_from_the_plan_cut_at_its_start() {
        let problem = problem_with_targets();
        let plan = flying(&problem);
        let mut replan = problem.clone();
        replan.t0 = 50.5;
        replan.targets.remove(0);
        // Two whole turns off: the guess's heading continues the start state's.
        replan.x0 = [200.0 * 50.5 + 3.0, 1.0, 2.0 * TAU, 0.0, 0.0, 0.0, 0.0];
        let guess = plan.guess_for(&replan).expect("it continues the plan");
        assert_eq!(guess.times[0], 50.5);
        assert_eq!(guess.states[0], replan.x0);
        assert_eq!(guess.times[1], 51.0);
        assert_eq!(guess.states[1][2], 2.0 * TAU);
        assert_eq!(guess.final_time(), Some(100.0));
        assert_eq!(guess.phase_ends, plan.path.phase_ends[1..]);
        assert_eq!(plan.passed_targets(&replan), Some(1));
    }

    /// The 2-D problem with the straight plan's rendezvous: the lead flies east at
    /// 200 m/s, `offset_m` north of the plan's line: the plan ends at t = 100 `offset_m`
    /// from where the lead is then.
    fn rendezvous(offset_m: f64) -> Problem {
        let mut problem = problem_with_targets();
        problem.objective = Objective::MinTimeRendezvous;
        problem.final_state = None;
        problem.final_time = None;
        problem.lead = Some(
            crate::lead::LeadPath::new(
                &[[0.0, offset_m, 0.0], [40_000.0, offset_m, 0.0]],
                200.0,
                0.0,
            )
            .expect("a valid lead"),
        );
        problem
    }

    #[test]
    fn a_rendezvous_whose_lead_moved_far_from_the_plans_end_gives_no_warm_start() {
        let plan = flying(&rendezvous(0.0));
        let replan_for = |offset_m: f64| {
            let mut replan = rendezvous(offset_m);
            replan.t0 = 50.5;
            replan.targets.remove(0);
            replan.x0 = [200.0 * 50.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
            replan
        };
        // The plan left: 9 900 m. Its end 0 m and 900 m from the lead (a tenth of it:
        // 990 m) continues it; 1 100 m does not.
        assert!(plan.guess_for(&replan_for(0.0)).is_some());
        assert!(plan.guess_for(&replan_for(900.0)).is_some());
        assert_eq!(plan.guess_for(&replan_for(1_100.0)), None);
        // The same lead behind or ahead: its position at the plan's end is what counts.
        let mut late = replan_for(0.0);
        late.lead = Some(
            crate::lead::LeadPath::new(&[[0.0, 0.0, 0.0], [40_000.0, 0.0, 0.0]], 200.0, 6.0)
                .expect("a valid lead"),
        );
        assert_eq!(plan.guess_for(&late), None, "1 200 m behind");
    }

    #[test]
    fn another_tasking_or_a_target_not_passed_gives_no_warm_start() {
        let problem = problem_with_targets();
        let plan = flying(&problem);
        // The first target is left out but the plan passes it only at t = 50.
        let mut early = problem.clone();
        early.t0 = 20.0;
        early.targets.remove(0);
        assert_eq!(plan.guess_for(&early), None);
        // Another target list.
        let mut moved = problem.clone();
        moved.t0 = 20.0;
        moved.targets[1][0] += 1.0;
        assert_eq!(plan.guess_for(&moved), None);
        // Another final time.
        let mut later = problem.clone();
        later.t0 = 20.0;
        later.final_time = Some(later.final_time.unwrap_or(0.0) + 5.0);
        assert_eq!(plan.guess_for(&later), None);
        // Past the plan's end.
        let mut over = problem.clone();
        over.t0 = 150.0;
        over.targets.clear();
        assert_eq!(plan.guess_for(&over), None);
    }
}
