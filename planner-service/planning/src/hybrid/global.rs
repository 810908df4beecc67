//! The global search of one plan: seeds and swarm, the starts from distinct basins, the
//! NLP stage over them (ranked, finalists, refinement) with the floor under a short
//! budget, and the swarm's path as the answer if the NLP yields nothing.

use std::time::Duration;

use wingman_interfaces::Quality;

use super::nlp_stage::{self, NlpStage};
use super::timing::{Ranking, Seen, SolveTiming, StageTiming};
use super::waves::{self, Waves};
use super::{
    Gathered, PlanError, PlanOutcome, PlanPath, PlanSolution, Planner, PlannerSettings, StageTimes,
    exported_quality, gather, ranking_meshes, reference_export, schedule, trajectory_cost,
};
use crate::basins;
use crate::clock::Deadline;
use crate::collocation::Mesh;
use crate::collocation::{export, fly_reference};
use crate::cuts::Work;
use crate::problem::Problem;
use crate::swarm::{self, SwarmOutcome};
use crate::trajectory::Trajectory;

impl Planner {
    /// Whether the global search's NLP stage fits in what `deadline` leaves, as recent plans
    /// of `problem`'s model took it.
    pub(super) fn global_nlp_fits(
        &self,
        problem: &Problem,
        settings: &PlannerSettings,
        deadline: Deadline<'static>,
    ) -> bool {
        let model = usize::from(problem.dim() == 3);
        nlp_possible(settings, deadline, self.timing[model], self.stage[model])
    }

    /// The global search: seeds and swarm, the NLP stage over distinct starts, the
    /// refinement of the winner; with `floor_wanted`, under a budget that may not hold the
    /// stage, first the floor (`nlp_stage::floor`); with `widen` (a plan from scratch),
    /// then the waves of further starts the time left holds (`waves`).
    pub(super) fn global(
        &mut self,
        problem: &Problem,
        settings: &PlannerSettings,
        deadline: Deadline<'static>,
        floor_wanted: bool,
        widen: bool,
    ) -> Result<PlanOutcome, PlanError> {
        let clock = deadline.clock();
        let started = clock.now();
        let waves_deadline = waves::deadline(problem, settings, deadline);
        let mut times = StageTimes::default();
        let model = usize::from(problem.dim() == 3);
        let (timing, stage_timing) = (self.timing[model], self.stage[model]);

        let swarm_deadline = swarm_deadline(settings, deadline, timing, stage_timing, floor_wanted);
        let sw: SwarmOutcome =
            swarm::run(problem, &settings.swarm, &mut self.swarm, swarm_deadline)?;
        times.swarm = sw.elapsed;
        if !sw.best.is_valid() {
            return Err(PlanError::NonFinite);
        }
        let swarm_cost = trajectory_cost(problem, &sw.best);

        let fallback_started = clock.now();
        let fallback = fallback_path(problem, settings, &sw.best);
        let fallback_cost = clock.now().saturating_sub(fallback_started);
        // Exporting the NLP's plan costs about as much as the fallback: the NLP stops
        // twice that long before the deadline.
        let deadline = deadline.earlier(fallback_cost * 2);

        let nlp_started = clock.now();
        let floor = self.floor_first(problem, settings, &sw.best, deadline, floor_wanted);
        // No time for the ranking and one solve's set-up and wrap-up (as recent plans took
        // them; an expired deadline too): no NLP stage, not even its starts. Asked again
        // now: a swarm that converged early may have left the time.
        let no_time = deadline
            .at(Work::NlpStage)
            .cuts(0, |d| !stage_timing.fits_the_stage(&timing, d.remaining()));
        let starts = if no_time {
            Vec::new()
        } else {
            self.starts(problem, settings, &sw.best)
        };
        let coarse = ranking_meshes(problem, settings, &starts);
        let stage = NlpStage {
            problem,
            settings,
            starts: &starts,
            coarse: &coarse,
            fallback_start: &sw.best,
            reference: reference_export(settings),
            fallback_warm: None,
            to_beat: None,
            timing,
            seen: Seen::default(),
            deadline,
            kkt: &self.kkt,
        };
        // Rank every start on the coarse mesh, solve the best distinct ones on the working
        // mesh, refine the best of those: scheduled on the planner's threads (`schedule`).
        let done = if no_time {
            schedule::Schedule::none()
        } else {
            schedule::run(&stage, settings.threads)
        };
        times.ranking = done.ranked_at.saturating_sub(nlp_started);
        let gathered = gather(&stage, done, deadline)?;
        let Gathered {
            mut report,
            accepted,
            cut,
            first_optimal,
            ..
        } = if widen && !no_time {
            let took = clock.now().saturating_sub(nlp_started);
            let waves = Waves::new(problem, settings, &starts, &sw.best, timing, took);
            self.waves(waves, deadline.no_later_than(&waves_deadline), gathered)?
        } else {
            gathered
        };
        let stage_yields = accepted.is_some();
        let (accepted, quality_of_floor) = match (accepted, floor) {
            (Some(a), _) => (Some(a), None),
            (None, Some((result, mesh))) => {
                let (solved, iterations, status, seen) = result?;
                stage.seen.record(seen);
                report.iterations.push(iterations);
                report.status = Some(status);
                let floor = solved.map(|s| (s, mesh));
                if let Some((s, mesh)) = &floor {
                    report.objective = s.objective;
                    report.intervals = mesh.phases.iter().map(Vec::len).collect();
                }
                (floor, Some(Quality::Feasible))
            }
            (None, None) => (None, None),
        };
        times.nlp = clock.now().saturating_sub(nlp_started);

        // What this plan teaches about the next ones' timing. The stage ran out of time
        // before it had a plan (a rank or every final stopped by the deadline): it needs
        // more than it had. Else its ranking took what it took.
        self.timing[model] = self.timing[model].after(stage.seen.get());
        let ranking = if no_time {
            Ranking::Skipped
        } else if !stage_yields && (cut || deadline.expired()) {
            Ranking::Cut(times.nlp)
        } else {
            Ranking::Done(times.ranking)
        };
        self.stage[model] = stage_timing.after(ranking, fallback_cost);

        let export_started = clock.now();
        let (quality, trajectory) = match &accepted {
            Some((a, _)) => {
                let mut flown = Trajectory::default();
                export(&a.tr, &a.x, &settings.export, &mut flown);
                let quality = quality_of_floor.unwrap_or(a.quality);
                (exported_quality(problem, &flown, quality), flown)
            }
            None => (Quality::SwarmOnly, fallback),
        };
        if !trajectory.is_valid() {
            return Err(PlanError::NonFinite);
        }
        times.export = clock.now().saturating_sub(export_started) + fallback_cost;
        times.total = clock.now().saturating_sub(started);
        Ok(PlanOutcome {
            first_optimal: first_optimal.map(|t| t.saturating_sub(started)),
            path: PlanPath::Global,
            warm: None,
            quality,
            cost: trajectory_cost(problem, &trajectory),
            trajectory,
            swarm_best: sw.best,
            swarm_cost,
            swarm_iterations: sw.iterations,
            nlp: report,
            times,
            solution: accepted.and_then(|(a, _)| PlanSolution::of(a)),
        })
    }

    /// With `wanted`, under a budget that may not hold the NLP stage (its ranking and a
    /// solve in a third of what is left, as recent plans took them: a stage that yields
    /// needs the finals and a round after its ranking, and the ranking's estimate decays
    /// while no plan tries it): first the floor, one coarse solve of the swarm's path,
    /// kept if the stage yields nothing.
    fn floor_first(
        &self,
        problem: &Problem,
        settings: &PlannerSettings,
        swarm_best: &Trajectory,
        deadline: Deadline<'static>,
        wanted: bool,
    ) -> Option<(nlp_stage::MeshSolveResult, Mesh)> {
        let model = usize::from(problem.dim() == 3);
        let (timing, stage_timing) = (self.timing[model], self.stage[model]);
        let short = !stage_timing.fits_the_stage(&timing, deadline.remaining() / 3);
        let floor_runs = |d: &Deadline<'static>| short && timing.fits_a_solve(d.remaining());
        let runs = wanted && deadline.at(Work::Floor).cuts(0, floor_runs);
        runs.then(|| nlp_stage::floor(problem, settings, swarm_best, deadline, timing, &self.kkt))
    }

    /// Starts from distinct basins, solved side by side on the first mesh. The swarm's
    /// workspace holds this problem's seeds: no need to build them again.
    fn starts(
        &self,
        problem: &Problem,
        settings: &PlannerSettings,
        swarm_best: &Trajectory,
    ) -> Vec<Trajectory> {
        basins::candidates(
            problem,
            swarm_best,
            self.swarm.seeds(),
            settings.starts.max(1),
            settings.threads,
            settings.start_ranking,
            |tr| trajectory_cost(problem, tr),
        )
    }
}

/// The swarm's deadline. The NLP stage runs only when the budget left after the swarm's
/// share (and the fallback's reserve) can hold it, as recent plans took it: it yields
/// nothing before its ranking is done. With `floor_wanted`, a budget that holds the floor
/// (one solve) gives the swarm half its share and the floor the rest (with the full share
/// the floor's solve was cut unfinished on 1 in 10 plans of the unavoidable 2-D missions
/// at 50 ms). Otherwise the swarm has all of the budget but
/// the reserve (twice the fallback's cost, at most half the budget).
fn swarm_deadline(
    settings: &PlannerSettings,
    deadline: Deadline<'static>,
    timing: SolveTiming,
    stage_timing: StageTiming,
    floor_wanted: bool,
) -> Deadline<'static> {
    let share = settings.swarm_share.clamp(0.0, 1.0);
    let after_share = deadline
        .remaining()
        .mul_f64(1.0 - share)
        .saturating_sub(fallback_reserve(deadline, stage_timing));
    if nlp_possible(settings, deadline, timing, stage_timing) {
        deadline.share(share)
    } else if floor_wanted && timing.fits_a_solve(after_share) {
        deadline.share(share / 2.0)
    } else {
        deadline.earlier(fallback_reserve(deadline, stage_timing))
    }
}

/// Whether the NLP stage fits in what `deadline` leaves after the swarm's share and the
/// fallback's reserve, as recent plans took it.
fn nlp_possible(
    settings: &PlannerSettings,
    deadline: Deadline<'static>,
    timing: SolveTiming,
    stage_timing: StageTiming,
) -> bool {
    let share = settings.swarm_share.clamp(0.0, 1.0);
    let after_swarm = deadline.remaining().mul_f64(1.0 - share);
    let reserve = fallback_reserve(deadline, stage_timing);
    stage_timing.fits_the_stage(&timing, after_swarm.saturating_sub(reserve))
}

/// The time kept for the fallback: twice its cost, at most half of what is left.
fn fallback_reserve(deadline: Deadline<'static>, stage_timing: StageTiming) -> Duration {
    (stage_timing.fallback * 2).min(deadline.remaining() / 2)
}

/// The swarm's lifted path, flown with the tracking law so that its controls replay onto
/// it (in 3-D the lifted controls alone drift away): the answer if the NLP does not
/// finish. It is built before the NLP stage, so that at the deadline nothing is left to do
/// but return it.
fn fallback_path(problem: &Problem, settings: &PlannerSettings, best: &Trajectory) -> Trajectory {
    let mut fallback = best.resampled(settings.export.max_step_s);
    if problem.dim() == 3 {
        fly_reference(problem, &settings.export, &mut fallback);
    }
    fallback
}
