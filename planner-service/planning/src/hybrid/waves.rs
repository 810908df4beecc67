//! Waves: a plan from scratch that has work and time left after its global search solves
//! the next starts from distinct basins, `starts` at a time, up to `wave_starts` in all
//! (`wave_starts_3d` in 3-D).
//!
//! The global search ranks a few starts (five) and solves the best of them; on missions
//! nobody tuned for, the best basin is sometimes the sixth or the tenth start
//! (`docs/decisions/0040`). Each wave ranks its starts on the coarse mesh, solves on the
//! working mesh only those ranked within `wave_gap_tol` of the best ranked so far, and
//! its winner replaces the plan if it is better (an `Optimal` solution before any other,
//! then the lower objective).
//!
//! Two gates, both asked before each wave:
//! - **Work** (`wave_work`, `wave_work_3d`): the plan's NLP work so far, plus the last
//!   stage's again (the wave's estimate), must stay within the cap. Work is counted (a
//!   solve's iterations times its mesh's intervals), so this gate is the same on any
//!   computer: it decides how many waves a plan runs (`docs/decisions/0048`).
//! - **Time**: the time left must hold a stage as long as the last one took. That choice
//!   is a deadline cut (`Part::Wave(k)`, `Work::Whole`), so a replay runs the same waves;
//!   it guards a slow or loaded computer. With no deadline only the work decides.

use std::time::Duration;

use wingman_interfaces::Quality;

use super::nlp_stage::{NlpStage, Solved};
use super::timing::{Seen, SolveTiming};
use super::{Gathered, PlanError, Planner, PlannerSettings, gather, ranking_meshes};
use super::{reference_export, schedule, trajectory_cost};
use crate::basins;
use crate::clock::Deadline;
use crate::cuts::{Part, Work};
use crate::problem::Problem;
use crate::seeding::{self, SeedSettings};
use crate::swarm::SwarmError;
use crate::trajectory::Trajectory;

/// What the waves start from and work with.
pub(super) struct Waves<'a> {
    problem: &'a Problem,
    settings: &'a PlannerSettings,
    /// The global search's starts: the waves' are distinct from them.
    taken: &'a [Trajectory],
    /// The swarm's best (a wave solves no fallback; the stage wants one to hold).
    swarm_best: &'a Trajectory,
    /// The solves' timing learned from recent plans.
    timing: SolveTiming,
    /// How long the global search's NLP stage took.
    stage_took: Duration,
}

impl<'a> Waves<'a> {
    /// The waves after the global search of `problem`: its starts `taken`, the swarm's
    /// best, the solves' timing, and how long its NLP stage took.
    pub fn new(
        problem: &'a Problem,
        settings: &'a PlannerSettings,
        taken: &'a [Trajectory],
        swarm_best: &'a Trajectory,
        timing: SolveTiming,
        stage_took: Duration,
    ) -> Waves<'a> {
        Waves {
            problem,
            settings,
            taken,
            swarm_best,
            timing,
            stage_took,
        }
    }
}

/// The latest the waves of a plan may run: `wave_share` (2-D) or `wave_share_3d` of the
/// time `deadline` leaves at the plan's start.
pub(super) fn deadline(
    problem: &Problem,
    settings: &PlannerSettings,
    deadline: Deadline<'static>,
) -> Deadline<'static> {
    let share = if problem.dim() == 3 {
        settings.wave_share_3d
    } else {
        settings.wave_share
    };
    deadline.share(share)
}

/// The most starts a plan of `problem` solves in all, its global search's included, and
/// the cap on its NLP work before a wave (`None`: none).
fn limits(problem: &Problem, settings: &PlannerSettings) -> (usize, Option<usize>) {
    if problem.dim() == 3 {
        (settings.wave_starts_3d, settings.wave_work_3d)
    } else {
        (settings.wave_starts, settings.wave_work)
    }
}

impl Planner {
    /// Runs the waves while the deadline holds them; `best` (the global search's result)
    /// comes back with every wave's ranks and iterations appended, its accepted solution
    /// replaced by a wave's better one.
    pub(super) fn waves(
        &self,
        waves: Waves<'_>,
        deadline: Deadline<'static>,
        mut best: Gathered,
    ) -> Result<Gathered, PlanError> {
        let Waves {
            problem,
            settings,
            taken,
            swarm_best,
            timing,
            mut stage_took,
        } = waves;
        // The work of the last stage: the global search's, whose result `best` is.
        let mut stage_work = best.work;
        let (most_starts, work_cap) = limits(problem, settings);
        if most_starts <= settings.starts {
            return Ok(best);
        }
        let clock = deadline.clock();
        let size = settings.starts.max(1);
        let mut later = Vec::new();
        for k in 0.. {
            // Past the first wave its starts are known: no gate is asked for a wave that
            // has none (its cut would mark a plan the clock did not change).
            if k > 0 && later.chunks(size).nth(k).is_none() {
                break;
            }
            let Some(bar) = best_rank(&best) else {
                break;
            };
            if work_cap.is_some_and(|cap| best.work + stage_work > cap) {
                break;
            }
            let part = Part::Wave(u8::try_from(k + 1).unwrap_or(u8::MAX));
            let deadline = deadline.within(part);
            if deadline.cuts(0, |d| d.remaining() < stage_took) {
                break;
            }
            let started = clock.now();
            if k == 0 {
                later = wave_starts(problem, settings, most_starts, taken, swarm_best, deadline)?;
            }
            let Some(wave_starts) = later.chunks(size).nth(k) else {
                break;
            };
            let coarse = ranking_meshes(problem, settings, wave_starts);
            let stage = NlpStage {
                problem,
                settings,
                starts: wave_starts,
                coarse: &coarse,
                fallback_start: swarm_best,
                fallback_warm: None,
                to_beat: Some(bar * (1.0 + settings.wave_gap_tol)),
                reference: reference_export(settings),
                timing,
                seen: Seen::default(),
                deadline,
                kkt: &self.kkt,
            };
            let done = schedule::run(&stage, settings.threads);
            let wave = gather(&stage, done, deadline)?;
            stage_took = clock.now().saturating_sub(started);
            stage_work = wave.work;
            merge(&mut best, wave, taken.len() + k * size);
        }
        Ok(best)
    }
}

/// The waves' starts, in order, up to `most` with the global search's: built by the first
/// wave from the wider seeds (`wave_seeds` with the swarm's random stream, under its
/// deadline), distinct from the global search's.
fn wave_starts(
    problem: &Problem,
    settings: &PlannerSettings,
    most: usize,
    taken: &[Trajectory],
    swarm_best: &Trajectory,
    deadline: Deadline<'static>,
) -> Result<Vec<Trajectory>, PlanError> {
    // The random curves from the swarm's stream: a plan's seed changes them too.
    let seed_settings = SeedSettings {
        rng_seed: settings.swarm.seeds.rng_seed,
        ..settings.wave_seeds.clone()
    };
    let mut seeds = Vec::new();
    let seeds_deadline = deadline.at(Work::Seeds);
    seeding::seeds_until(problem, &seed_settings, &mut seeds, &|tried| {
        seeds_deadline.cuts(tried, Deadline::expired)
    })
    .map_err(SwarmError::from)?;
    let taken = if taken.is_empty() {
        std::slice::from_ref(swarm_best)
    } else {
        taken
    };
    let mut all = basins::more_candidates(
        problem,
        taken,
        &seeds,
        most,
        settings.threads,
        settings.wave_ranking,
        |tr| trajectory_cost(problem, tr),
    );
    Ok(all.split_off(taken.len()))
}

/// The lowest dense cost of a ranked start so far (`None`: none ranked, or no plan to
/// beat).
fn best_rank(best: &Gathered) -> Option<f64> {
    best.accepted.as_ref()?;
    best.report
        .ranking
        .iter()
        .copied()
        .filter(|c| c.is_finite())
        .min_by(f64::total_cmp)
}

/// `wave`'s ranks, iterations and work added to `best`'s; its solution taken if better
/// (its finalists then named by their index among all starts, the wave's first being
/// `offset`).
fn merge(best: &mut Gathered, wave: Gathered, offset: usize) {
    best.report.ranking.extend(&wave.report.ranking);
    best.report.iterations.extend(&wave.report.iterations);
    let wins = match (&wave.accepted, &best.accepted) {
        (Some((w, _)), Some((b, _))) => better(w, b),
        (Some(_), None) => true,
        (None, _) => false,
    };
    if wins {
        best.accepted = wave.accepted;
        best.report.objective = wave.report.objective;
        best.report.status = wave.report.status;
        best.report.intervals = wave.report.intervals;
        best.report.finalists = wave.report.finalists.iter().map(|c| c + offset).collect();
    }
    best.first_optimal = best.first_optimal.or(wave.first_optimal);
    best.work += wave.work;
}

/// Whether `a` beats `b`: `Optimal` before any other quality, then the lower objective
/// (a wave that reaches the plan's basin again may end a little lower in it).
fn better(a: &Solved, b: &Solved) -> bool {
    let optimal = |s: &Solved| s.quality == Quality::Optimal;
    match (optimal(a), optimal(b)) {
        (true, false) => true,
        (false, true) => false,
        _ => a.objective < b.objective,
    }
}
