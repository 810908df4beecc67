//! The NLP stage of one plan: each solve on a mesh (`solve_on_mesh`), and the steps the
//! schedule runs on the planner's threads (rank a start, solve a finalist, refine the
//! winner), as [`schedule::Stage`].

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use wingman_interfaces::Quality;

use super::schedule;
use super::timing::{Seen, SolveTiming};
use super::{
    PlanError, PlanSolution, PlannerSettings, finalists, phase_durations, trajectory_cost,
};
use crate::clock::Deadline;
use crate::collocation::kkt::KktCache;
use crate::collocation::warm;
use crate::collocation::{
    ExportSettings, Mesh, NlpSettings, NlpStatus, PrimalDual, SolveBudget, Transcription, export,
    interval_errors, refine, solve, split_crossings,
};
use crate::cuts::Work;
use crate::problem::Problem;
use crate::trajectory::Trajectory;

/// One NLP solve's accepted result.
pub(super) struct Solved {
    pub(super) tr: Transcription,
    pub(super) x: Vec<f64>,
    pub(super) quality: Quality,
    pub(super) objective: f64,
    pub(super) status: NlpStatus,
    /// The converged primal-dual solution, for a warm start on the next mesh.
    pub(super) warm: Option<PrimalDual>,
}

/// One NLP solve of the plan: which mesh, from where, with which settings.
pub(super) struct MeshSolve<'a> {
    pub(super) problem: &'a Problem,
    pub(super) mesh: &'a Mesh,
    /// The primal starting point (interpolated onto the mesh).
    pub(super) guess: &'a Trajectory,
    pub(super) settings: &'a PlannerSettings,
    pub(super) nlp_settings: &'a NlpSettings,
    /// The guess is a solution on another mesh (a small initial barrier keeps it).
    pub(super) refined: bool,
    /// Largest scaled violation of a result that is accepted.
    pub(super) feasibility_tol: f64,
    /// The previous mesh's transcription and primal-dual solution, to start from.
    pub(super) warm_from: Option<(&'a Transcription, &'a PrimalDual)>,
    /// `warm_from` is the plan in flight (its multipliers are taken at the same mission
    /// time, `warm::transfer_in_time`), not a solution of this problem on another mesh.
    pub(super) warm_in_time: bool,
    /// The first barrier parameter, over `nlp_settings`' (`None`: theirs).
    pub(super) mu_init: Option<f64>,
    /// The primal starting point itself (scaled), when it is a solution on this very mesh
    /// (`guess` then only sets the bounds).
    pub(super) start_x: Option<&'a [f64]>,
    /// Set when the result is no longer wanted: the solve stops (see `collocation::solve`).
    pub(super) cancel: Option<Arc<AtomicBool>>,
}

/// Solves `job.problem` on `job.mesh` from `job.guess`; `None` if the result is not
/// feasible. `timing` is the solves' expected timing: none is started without time for
/// its set-up and wrap-up, and it stops while an iteration and its wrap-up still fit.
pub(super) fn solve_on_mesh(
    job: MeshSolve<'_>,
    deadline: Deadline<'static>,
    timing: SolveTiming,
    kkt: &Arc<KktCache>,
) -> MeshSolveResult {
    let MeshSolve {
        problem,
        mesh,
        guess,
        settings,
        nlp_settings,
        refined,
        feasibility_tol,
        warm_from,
        warm_in_time,
        mu_init,
        start_x,
        cancel,
    } = job;
    if deadline.cuts(0, |d| !timing.fits_a_solve(d.remaining())) {
        // No time for even one iteration (the longest set-up and first iteration of
        // recent solves): do not build the NLP; the caller returns what it has.
        return Ok((None, 0, NlpStatus::MaxTime, SolveTiming::default()));
    }
    let mut tr = Transcription::new(problem, mesh, guess, &settings.transcription);
    let mut x = vec![0.0; tr.n_vars()];
    match start_x {
        Some(x0) if x0.len() == x.len() => {
            for (i, v) in x.iter_mut().enumerate() {
                *v = x0[i].clamp(tr.x_lo[i], tr.x_hi[i]);
            }
        }
        _ => tr.initial_point(guess, &mut x),
    }
    let j0 = tr.objective(&x);
    tr.obj_scale = 1.0 / j0.abs().max(1e-3);
    let mut nlp = nlp_settings.clone();
    if refined {
        // A refined mesh starts from the previous solution: a small barrier keeps it.
        nlp.mu_init = Some(nlp_settings.refine_mu_init);
    }
    if mu_init.is_some() {
        nlp.mu_init = mu_init;
    }
    let mut start = PrimalDual {
        x,
        ..PrimalDual::default()
    };
    let warm = match warm_from {
        Some((from, duals)) if warm_in_time => warm::transfer_in_time(from, duals, &tr, &mut start),
        Some((from, duals)) => warm::transfer(from, duals, &tr, &mut start),
        None => false,
    };
    let vars = tr.n_vars();
    let budget = SolveBudget {
        deadline,
        cancel,
        iteration: timing.iteration(vars),
        wrap_up: timing.wrap_up,
    };
    let (tr, out) = solve(tr, start, warm, &nlp, budget, kkt)?;
    let seen = SolveTiming {
        setup: out.first_iteration.unwrap_or_default(),
        per_var: out.longest_iteration.as_secs_f64() / vars.max(1) as f64,
        wrap_up: out.wrap_up,
    };
    let feasible = out.violation <= feasibility_tol;
    let quality = match (out.status, feasible) {
        (NlpStatus::Converged, true) => Some(Quality::Optimal),
        (_, true) => Some(Quality::Feasible),
        _ => None,
    };
    let solved = quality.map(|quality| Solved {
        tr,
        x: out.x,
        quality,
        objective: out.objective,
        status: out.status,
        warm: out.warm,
    });
    Ok((solved, out.iterations, out.status, seen))
}

/// The floor of a budget that may not hold the NLP stage: one solve of the swarm's best
/// (`swarm_path`, lifted; the fallback flown with the tracking law was a worse start: a 3-D
/// rendezvous floor did not converge from it) on its coarse ranking mesh at
/// `PlannerSettings::floor_nlp` (the finalists' tight constraint tolerance, the ranking's
/// plain line search), accepted only as feasible as a refined solve must be. A plan from
/// it is `Feasible` (a coarse mesh's solution, neither refined nor compared with other
/// basins); it is kept when the stage yields nothing.
pub(super) fn floor(
    problem: &Problem,
    settings: &PlannerSettings,
    swarm_path: &Trajectory,
    deadline: Deadline<'static>,
    timing: SolveTiming,
    kkt: &Arc<KktCache>,
) -> (MeshSolveResult, Mesh) {
    let mesh = super::ranking_meshes(problem, settings, std::slice::from_ref(swarm_path))
        .pop()
        .unwrap_or_else(|| unreachable!("one mesh per start"));
    let job = MeshSolve {
        problem,
        mesh: &mesh,
        guess: swarm_path,
        settings,
        nlp_settings: &settings.floor_nlp,
        refined: false,
        feasibility_tol: settings.nlp.feasibility_tol,
        warm_from: None,
        warm_in_time: false,
        mu_init: ranking_mu_init(problem, settings),
        start_x: None,
        cancel: None,
    };
    let deadline = deadline.at(Work::FloorSolve);
    (solve_on_mesh(job, deadline, timing, kkt), mesh)
}

/// The first barrier parameter of a ranking solve (`None`: the ranking settings').
fn ranking_mu_init(problem: &Problem, settings: &PlannerSettings) -> Option<f64> {
    if problem.dim() == 3 {
        settings.ranking_mu_init_3d
    } else {
        None
    }
}

/// A mesh solve's accepted result (if any), iterations, status and timing.
pub(super) type MeshSolveResult =
    Result<(Option<Solved>, usize, NlpStatus, SolveTiming), PlanError>;

/// The accepted solution of a solve's result, if any.
pub(super) fn accepted_of(r: &MeshSolveResult) -> Option<&Solved> {
    r.as_ref().ok().and_then(|r| r.0.as_ref())
}

/// A start's ranking solve on the coarse mesh and, if it was accepted, the path exported
/// from it with its dense cost.
pub(super) struct Ranked {
    pub(super) result: MeshSolveResult,
    pub(super) path: Option<(f64, Trajectory)>,
}

/// A finalist's solve on the working mesh.
pub(super) struct Finaled {
    pub(super) result: MeshSolveResult,
    pub(super) mesh: Mesh,
    /// When it ended (stage clock).
    pub(super) done_at: Duration,
}

/// A refinement round: its solve, mesh and end (stage clock) (`None`: the mesh needed no
/// refinement and there was nothing to polish).
pub(super) type Rounded = Option<(MeshSolveResult, Mesh, Duration)>;

/// The NLP stage of one plan, as [`schedule`] runs it.
pub(super) struct NlpStage<'a> {
    pub(super) problem: &'a Problem,
    pub(super) settings: &'a PlannerSettings,
    pub(super) starts: &'a [Trajectory],
    /// The ranking mesh of each start.
    pub(super) coarse: &'a [Mesh],
    /// The guess of the candidate solved when no start ranked: the swarm's best, or on
    /// the warm path the plan in flight cut at the start.
    pub(super) fallback_start: &'a Trajectory,
    /// The plan in flight's solution that the fallback candidate's solve takes its
    /// multipliers from (the warm path's plain solve; `warm::transfer_in_time`).
    pub(super) fallback_warm: Option<&'a PlanSolution>,
    /// A wave's bar (`waves`): only starts ranked at or below this dense cost are
    /// finalists, and no fallback is solved when none is (`None`: any start, and the
    /// fallback).
    pub(super) to_beat: Option<f64>,
    /// How ranked solutions are exported: densely, open loop.
    pub(super) reference: ExportSettings,
    /// The solves' timing learned from recent plans.
    pub(super) timing: SolveTiming,
    /// The timing of this plan's solves so far.
    pub(super) seen: Seen,
    pub(super) deadline: Deadline<'static>,
    /// The planner's pool of KKT workspaces and its counters.
    pub(super) kkt: &'a Arc<KktCache>,
}

impl NlpStage<'_> {
    /// Runs `job` (the stage's `work`) with the timing known now (recent plans' and this
    /// one's so far), and records its own.
    fn solve(&self, work: Work, job: MeshSolve<'_>) -> MeshSolveResult {
        let timing = self.timing.max(self.seen.get());
        let result = solve_on_mesh(job, self.deadline.at(work), timing, self.kkt);
        if let Ok((_, _, _, seen)) = &result {
            self.seen.record(*seen);
        }
        result
    }

    /// Whether the finalists stop at a looser tolerance than the working one, so that a
    /// winner whose mesh needs no refinement is solved again on it ("polished").
    pub(super) fn polish(&self) -> bool {
        self.settings.finalist_nlp.tol > self.settings.nlp.tol
    }

    /// Refinement round `round` after `current` (descended from candidate `candidate`'s
    /// final), solved on `mesh`: the refined mesh, or (`polish`) the same mesh from
    /// `current`'s own solution.
    pub(super) fn round_after(
        &self,
        round: usize,
        candidate: usize,
        current: &Solved,
        mesh: &Mesh,
        polish: bool,
        cancel: Option<Arc<AtomicBool>>,
    ) -> Rounded {
        let settings = self.settings;
        let mut errors = Vec::new();
        interval_errors(&current.tr, &current.x, &mut errors);
        let refined = if round < settings.refine_rounds {
            refine(mesh, &errors, &settings.refine)
        } else {
            None
        };
        let (next, same) = match refined {
            Some(next) => (next, false),
            None if polish => (mesh.clone(), true),
            None => return None,
        };
        let mut guess = Trajectory::default();
        export(&current.tr, &current.x, &self.reference, &mut guess);
        let work = Work::Round {
            candidate: candidate as u8,
            round: round as u8,
        };
        let result = self.solve(
            work,
            MeshSolve {
                problem: self.problem,
                mesh: &next,
                guess: &guess,
                settings,
                nlp_settings: &settings.nlp,
                refined: true,
                feasibility_tol: settings.nlp.feasibility_tol,
                warm_from: warm_start_of(Some(current), settings.warm_mesh_changes),
                warm_in_time: false,
                mu_init: None,
                start_x: same.then_some(current.x.as_slice()),
                cancel,
            },
        );
        Some((result, next, self.deadline.clock().now()))
    }
}

impl schedule::Stage for NlpStage<'_> {
    type Rank = Ranked;
    type Final = Finaled;
    type Round = Rounded;

    fn starts(&self) -> usize {
        self.starts.len()
    }

    fn rank(&self, i: usize) -> Ranked {
        let (problem, settings) = (self.problem, self.settings);
        let result = self.solve(
            Work::Rank(i as u16),
            MeshSolve {
                problem,
                mesh: &self.coarse[i],
                guess: &self.starts[i],
                settings,
                nlp_settings: &settings.ranking_nlp,
                refined: false,
                feasibility_tol: settings.ranking_feasibility_tol,
                warm_from: None,
                warm_in_time: false,
                mu_init: ranking_mu_init(problem, settings),
                start_x: None,
                cancel: None,
            },
        );
        let path = accepted_of(&result).map(|s| {
            let mut tr = Trajectory::default();
            export(&s.tr, &s.x, &self.reference, &mut tr);
            // Rank by the path's cost re-evaluated densely: the coarse mesh's own
            // quadrature misjudges sharp exposure transitions by percents.
            (trajectory_cost(problem, &tr), tr)
        });
        Ranked { result, path }
    }

    fn finalists(&self, ranks: &[Option<&Ranked>]) -> Vec<usize> {
        let mut order: Vec<(f64, usize, &Trajectory)> = ranks
            .iter()
            .enumerate()
            .filter_map(|(i, r)| r.and_then(|r| r.path.as_ref()).map(|(c, tr)| (*c, i, tr)))
            .filter(|(c, _, _)| self.to_beat.is_none_or(|bar| *c <= bar))
            .collect();
        // Lowest cost first; ties go to the earlier start (deterministic).
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        finalists(&order, self.settings)
    }

    fn fallback_wanted(&self) -> bool {
        self.to_beat.is_none()
    }

    fn finalist(&self, c: usize, rank: Option<&Ranked>, cancel: Arc<AtomicBool>) -> Finaled {
        let settings = self.settings;
        // A finalist starts from its coarse solution; the fallback from its own start, with
        // the plan in flight's multipliers if it has them.
        let (guess, warm_from, warm_in_time) =
            match rank.and_then(|r| r.path.as_ref().map(|p| (&p.1, r))) {
                Some((path, r)) => (
                    path,
                    warm_start_of(accepted_of(&r.result), settings.warm_mesh_changes),
                    false,
                ),
                None => (
                    self.fallback_start,
                    self.fallback_warm.map(|s| (&s.tr, &s.duals)),
                    true,
                ),
            };
        let mut mesh = Mesh::uniform(
            settings.mesh.points,
            &phase_durations(self.problem.t0, guess),
            settings.mesh.interval_s,
            settings.mesh.min_intervals,
        );
        if let Some(split) = settings
            .crossing_split
            .and_then(|threshold| split_crossings(&mesh, self.problem, guess, threshold))
        {
            mesh = split;
        }
        let result = self.solve(
            Work::Final(c as u16),
            MeshSolve {
                problem: self.problem,
                mesh: &mesh,
                guess,
                settings,
                nlp_settings: &settings.finalist_nlp,
                refined: true,
                feasibility_tol: settings.nlp.feasibility_tol,
                warm_from,
                warm_in_time,
                mu_init: None,
                start_x: None,
                cancel: Some(cancel),
            },
        );
        Finaled {
            result,
            mesh,
            done_at: self.deadline.clock().now(),
        }
    }

    fn judge(&self, f: &Finaled) -> Option<(f64, bool)> {
        let rounds = self.settings.refine_rounds.max(usize::from(self.polish()));
        accepted_of(&f.result).map(|s| (s.objective, s.quality == Quality::Optimal && rounds > 0))
    }

    fn round(&self, c: usize, f: &Finaled, cancel: Arc<AtomicBool>) -> Rounded {
        let current = accepted_of(&f.result)?;
        self.round_after(0, c, current, &f.mesh, self.polish(), Some(cancel))
    }

    fn expired(&self) -> bool {
        self.deadline.expired()
    }

    fn discard(&self, c: usize, round: bool) {
        let work = if round {
            Work::Round {
                candidate: c as u8,
                round: 0,
            }
        } else {
            Work::Final(c as u16)
        };
        self.deadline.at(work).forget_cuts();
    }

    fn round_cut(&self, started: bool) -> bool {
        let deadline = self.deadline.at(Work::WinnerRound);
        deadline.cuts(0, |d| !started && d.expired())
    }

    fn now(&self) -> Duration {
        self.deadline.clock().now()
    }
}

/// The transcription and primal-dual solution of `solved` to warm-start the next mesh from.
fn warm_start_of(solved: Option<&Solved>, enabled: bool) -> Option<(&Transcription, &PrimalDual)> {
    let s = solved.filter(|_| enabled)?;
    s.warm.as_ref().map(|w| (&s.tr, w))
}
