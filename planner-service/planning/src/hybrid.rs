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

mod schedule;
mod timing;

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use wingman_interfaces::Quality;

use crate::basins;
use crate::clock::Deadline;
use crate::collocation::kkt::KktCache;
use crate::collocation::{
    ExportSettings, Mesh, NlpSettings, NlpStatus, PrimalDual, RefineSettings, SolveBudget,
    Transcription, TranscriptionSettings, export, fly_reference, interval_errors, refine, solve,
    split_crossings,
};
use crate::problem::Problem;
use crate::swarm::{self, SwarmOutcome, SwarmSettings, SwarmWorkspace};
use crate::trajectory::Trajectory;
use timing::{Ranking, Seen, SolveTiming, StageTiming};

/// How each phase's first mesh is cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSettings {
    /// LGR points per interval.
    pub points: usize,
    /// Target length of an interval of the first mesh.
    pub interval_s: f64,
    /// Fewest intervals in a phase.
    pub min_intervals: usize,
}

impl Default for MeshSettings {
    fn default() -> Self {
        MeshSettings {
            points: 6,
            interval_s: 25.0,
            min_intervals: 2,
        }
    }
}

/// Settings of the whole planner.
#[derive(Debug, Clone)]
pub struct PlannerSettings {
    pub swarm: SwarmSettings,
    pub mesh: MeshSettings,
    pub transcription: TranscriptionSettings,
    pub nlp: NlpSettings,
    /// The NLP settings of the ranking solves on the coarse mesh (they only have to tell
    /// the basins apart: looser tolerances).
    pub ranking_nlp: NlpSettings,
    /// The NLP settings of the finalists' solves on the working mesh.
    pub finalist_nlp: NlpSettings,
    pub refine: RefineSettings,
    /// Refinement rounds after the first NLP solve.
    pub refine_rounds: usize,
    pub export: ExportSettings,
    /// Largest share of the deadline the swarm may use.
    pub swarm_share: f64,
    /// NLP starts from distinct basins: the swarm's best and the best seeds that pass some
    /// threat on another side (see `basins`).
    pub starts: usize,
    /// Threads solving the starts' NLPs side by side.
    pub threads: usize,
    /// The coarser mesh on which all starts are first ranked (2-D).
    pub ranking_mesh: MeshSettings,
    /// The ranking mesh of 3-D plans.
    pub ranking_mesh_3d: MeshSettings,
    /// The first barrier parameter of the 3-D ranking solves (`None`: `ranking_nlp`'s).
    pub ranking_mu_init_3d: Option<f64>,
    /// Largest scaled constraint violation of a ranking solve that still ranks.
    pub ranking_feasibility_tol: f64,
    /// How many of the best-ranked starts are solved again on the working mesh (at most).
    pub finalists: usize,
    /// A ranked start whose dense cost is within this of a finalist's (relative), on a path
    /// not distinct from it ([`basins::separation`] under [`basins::MIN_SEPARATION_M`]),
    /// reached the same basin: it is not solved again.
    pub finalist_duplicate_tol: f64,
    /// A ranked start whose dense cost is above the best's by more than this (relative)
    /// is out of the race: it is not solved again.
    pub finalist_gap_tol: f64,
    /// Start the solves on the working and the refined meshes primal-dual from the
    /// previous mesh's solution (multipliers carried over, see `collocation::warm`).
    pub warm_mesh_changes: bool,
    /// Split a finalist's working-mesh intervals where its ranked path crosses a threat's
    /// edge (the exposure along an interval varying by more than this; phases before the
    /// last; see [`split_crossings`]); `None`: no split.
    pub crossing_split: Option<f64>,
}

/// The deployment defaults. Why each is what it is, with what was measured, is in
/// `docs/decisions/` (the record named beside it).
impl Default for PlannerSettings {
    fn default() -> Self {
        PlannerSettings {
            swarm: SwarmSettings::default(),
            mesh: MeshSettings::default(),
            transcription: TranscriptionSettings::default(),
            // The winner's refined solve: tol 1e-6 (0026), no second-order test (0013).
            nlp: NlpSettings::default()
                .with_feral_static_pivoting(true)
                .with_tol(1e-6)
                .with_second_order_check(false),
            // Ranking only tells basins apart: stop at the first acceptable iterate
            // (0008), no second-order test (0013) or corrections (0027).
            ranking_nlp: NlpSettings::default()
                .with_feral_static_pivoting(true)
                .with_tol(1e-4)
                .with_acceptable_tol(1e-3)
                .with_acceptable_iter(1)
                .with_acceptable_constr_viol_tol(Some(1e-3))
                .with_second_order_check(false)
                .with_second_order_corrections(false),
            // A refined solve or a polish follows; feasible as the refined ones (0022).
            finalist_nlp: NlpSettings::default()
                .with_feral_static_pivoting(true)
                .with_tol(1e-5)
                .with_acceptable_tol(1e-4)
                .with_acceptable_constr_viol_tol(Some(1e-7))
                .with_constr_viol_tol(Some(1e-7)),
            refine: RefineSettings::default(),
            refine_rounds: 1, // more moved no cost, took 20-30 % of the plan (0011)
            export: ExportSettings::default(),
            swarm_share: 0.3,
            starts: 5,  // six's worst cost, a 16 % shorter ranking; four lose basins (0021)
            threads: 2, // the NLP tasks on two threads (0023)
            // Coarser meshes lose basins; four points only in 3-D (0012).
            ranking_mesh: MeshSettings {
                points: 5,
                interval_s: 35.0,
                min_intervals: 2,
            },
            ranking_mesh_3d: MeshSettings {
                points: 4,
                interval_s: 35.0,
                min_intervals: 2,
            },
            ranking_mu_init_3d: Some(1e-3), // 3-D starts are whole paths (0018)
            ranking_feasibility_tol: 1e-3,  // as loose as the ranking's stop (0008)
            // Two distinct finalists within 10 % of the best (0020).
            finalists: 2,
            finalist_duplicate_tol: 1e-3,
            finalist_gap_tol: 0.1,
            warm_mesh_changes: true, // 9-28 -> 3-11 iterations per mesh change (0006)
            crossing_split: Some(0.3), // a crossing steps the exposure by ~1 (0029)
        }
    }
}

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

/// Planner settings that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlannerSettingsError {
    #[error("swarm: {0}")]
    Swarm(#[from] swarm::SwarmError),
    #[error("`{stage}`: {source}")]
    Nlp {
        stage: &'static str,
        source: crate::collocation::NlpSettingsError,
    },
    #[error("`{setting}`: {problem}")]
    OutOfRange {
        setting: &'static str,
        problem: &'static str,
    },
}

impl PlannerSettings {
    /// Checks every stage's settings (the swarm's, the three NLP settings) and the
    /// planner's own, so that a bad setting is refused before a plan starts.
    pub fn validate(&self) -> Result<(), PlannerSettingsError> {
        self.swarm.validate()?;
        for (stage, nlp) in [
            ("nlp", &self.nlp),
            ("ranking_nlp", &self.ranking_nlp),
            ("finalist_nlp", &self.finalist_nlp),
        ] {
            nlp.validate()
                .map_err(|source| PlannerSettingsError::Nlp { stage, source })?;
        }
        let out = |setting: &'static str, problem: &'static str| {
            Err(PlannerSettingsError::OutOfRange { setting, problem })
        };
        let fraction = |x: f64| x.is_finite() && x > 0.0 && x <= 1.0;
        let non_negative = |x: f64| x.is_finite() && x >= 0.0;
        if !fraction(self.swarm_share) {
            return out("swarm_share", "must be in (0, 1]");
        }
        if self.starts == 0 {
            return out("starts", "must be at least 1");
        }
        if !(1..=64).contains(&self.threads) {
            return out("threads", "must be in 1..=64");
        }
        if self.finalists == 0 {
            return out("finalists", "must be at least 1");
        }
        if self.refine_rounds > 16 {
            return out("refine_rounds", "must be at most 16");
        }
        for (setting, value) in [
            ("ranking_feasibility_tol", self.ranking_feasibility_tol),
            ("finalist_duplicate_tol", self.finalist_duplicate_tol),
            ("finalist_gap_tol", self.finalist_gap_tol),
        ] {
            if !non_negative(value) {
                return out(setting, "must be finite and non-negative");
            }
        }
        if self
            .ranking_mu_init_3d
            .is_some_and(|v| !(v.is_finite() && v > 0.0))
        {
            return out("ranking_mu_init_3d", "must be finite and positive when set");
        }
        if self
            .crossing_split
            .is_some_and(|v| !(v.is_finite() && v > 0.0))
        {
            return out("crossing_split", "must be finite and positive when set");
        }
        Ok(())
    }
}

/// Time spent in each stage.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StageTimes {
    pub swarm: Duration,
    pub nlp: Duration,
    /// The part of `nlp` spent ranking the starts on the coarse mesh.
    pub ranking: Duration,
    pub export: Duration,
    pub total: Duration,
}

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
}

/// One NLP solve's accepted result.
struct Solved {
    tr: Transcription,
    x: Vec<f64>,
    quality: Quality,
    objective: f64,
    iterations: usize,
    status: NlpStatus,
    /// The converged primal-dual solution, for a warm start on the next mesh.
    warm: Option<PrimalDual>,
}

/// One NLP solve of the plan: which mesh, from where, with which settings.
struct MeshSolve<'a> {
    problem: &'a Problem,
    mesh: &'a Mesh,
    /// The primal starting point (interpolated onto the mesh).
    guess: &'a Trajectory,
    settings: &'a PlannerSettings,
    nlp_settings: &'a NlpSettings,
    /// The guess is a solution on another mesh (a small initial barrier keeps it).
    refined: bool,
    /// Largest scaled violation of a result that is accepted.
    feasibility_tol: f64,
    /// The previous mesh's transcription and primal-dual solution, to start from.
    warm_from: Option<(&'a Transcription, &'a PrimalDual)>,
    /// The first barrier parameter, over `nlp_settings`' (`None`: theirs).
    mu_init: Option<f64>,
    /// The primal starting point itself (scaled), when it is a solution on this very mesh
    /// (`guess` then only sets the bounds).
    start_x: Option<&'a [f64]>,
    /// Set when the result is no longer wanted: the solve stops (see `collocation::solve`).
    cancel: Option<Arc<AtomicBool>>,
}

/// Solves `job.problem` on `job.mesh` from `job.guess`; `None` if the result is not
/// feasible. `timing` is the solves' expected timing: none is started without time for
/// its set-up and wrap-up, and it stops while an iteration and its wrap-up still fit.
fn solve_on_mesh(
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
        mu_init,
        start_x,
        cancel,
    } = job;
    if !timing.fits_a_solve(deadline.remaining()) {
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
    let mut start = PrimalDual::default();
    let warm = match warm_from {
        Some((from, duals)) => crate::collocation::warm::transfer(from, duals, &tr, &mut start),
        None => false,
    };
    start.x = x;
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
        iterations: out.iterations,
        status: out.status,
        warm: out.warm,
    });
    Ok((solved, out.iterations, out.status, seen))
}

/// A mesh solve's accepted result (if any), iterations, status and timing.
type MeshSolveResult = Result<(Option<Solved>, usize, NlpStatus, SolveTiming), PlanError>;

/// The accepted solution of a solve's result, if any.
fn accepted_of(r: &MeshSolveResult) -> Option<&Solved> {
    r.as_ref().ok().and_then(|r| r.0.as_ref())
}

/// A start's ranking solve on the coarse mesh and, if it was accepted, the path exported
/// from it with its dense cost.
struct Ranked {
    result: MeshSolveResult,
    path: Option<(f64, Trajectory)>,
}

/// A finalist's solve on the working mesh.
struct Finaled {
    result: MeshSolveResult,
    mesh: Mesh,
}

/// A refinement round: its solve and mesh (`None`: the mesh needed no refinement and
/// there was nothing to polish).
type Rounded = Option<(MeshSolveResult, Mesh)>;

/// The NLP stage of one plan, as [`schedule`] runs it.
struct NlpStage<'a> {
    problem: &'a Problem,
    settings: &'a PlannerSettings,
    starts: &'a [Trajectory],
    /// The ranking mesh of each start.
    coarse: &'a [Mesh],
    /// The swarm's best (the fallback candidate's guess).
    swarm_best: &'a Trajectory,
    /// How ranked solutions are exported: densely, open loop.
    reference: ExportSettings,
    /// The solves' timing learned from recent plans.
    timing: SolveTiming,
    /// The timing of this plan's solves so far.
    seen: Seen,
    deadline: Deadline<'static>,
    /// The planner's pool of KKT workspaces and its counters.
    kkt: &'a Arc<KktCache>,
}

impl NlpStage<'_> {
    /// Runs `job` with the timing known now (recent plans' and this one's so far), and
    /// records its own.
    fn solve(&self, job: MeshSolve<'_>) -> MeshSolveResult {
        let timing = self.timing.max(self.seen.get());
        let result = solve_on_mesh(job, self.deadline, timing, self.kkt);
        if let Ok((_, _, _, seen)) = &result {
            self.seen.record(*seen);
        }
        result
    }

    /// Whether the finalists stop at a looser tolerance than the working one, so that a
    /// winner whose mesh needs no refinement is solved again on it ("polished").
    fn polish(&self) -> bool {
        self.settings.finalist_nlp.tol > self.settings.nlp.tol
    }

    /// Refinement round `round` after `current`, solved on `mesh`: the refined mesh, or
    /// (`polish`) the same mesh from `current`'s own solution.
    fn round_after(
        &self,
        round: usize,
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
        let result = self.solve(MeshSolve {
            problem: self.problem,
            mesh: &next,
            guess: &guess,
            settings,
            nlp_settings: &settings.nlp,
            refined: true,
            feasibility_tol: settings.nlp.feasibility_tol,
            warm_from: warm_start_of(Some(current), settings.warm_mesh_changes),
            mu_init: None,
            start_x: same.then_some(current.x.as_slice()),
            cancel,
        });
        Some((result, next))
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
        let result = self.solve(MeshSolve {
            problem,
            mesh: &self.coarse[i],
            guess: &self.starts[i],
            settings,
            nlp_settings: &settings.ranking_nlp,
            refined: false,
            feasibility_tol: settings.ranking_feasibility_tol,
            warm_from: None,
            mu_init: if problem.dim() == 3 {
                settings.ranking_mu_init_3d
            } else {
                None
            },
            start_x: None,
            cancel: None,
        });
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
            .collect();
        // Lowest cost first; ties go to the earlier start (deterministic).
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        finalists(&order, self.settings)
    }

    fn finalist(&self, _c: usize, rank: Option<&Ranked>, cancel: Arc<AtomicBool>) -> Finaled {
        let settings = self.settings;
        // A finalist starts from its coarse solution; the fallback from the swarm's best.
        let (guess, coarse) = match rank.and_then(|r| r.path.as_ref().map(|p| (&p.1, r))) {
            Some((path, r)) => (path, accepted_of(&r.result)),
            None => (self.swarm_best, None),
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
        let result = self.solve(MeshSolve {
            problem: self.problem,
            mesh: &mesh,
            guess,
            settings,
            nlp_settings: &settings.finalist_nlp,
            refined: true,
            feasibility_tol: settings.nlp.feasibility_tol,
            warm_from: warm_start_of(coarse, settings.warm_mesh_changes),
            mu_init: None,
            start_x: None,
            cancel: Some(cancel),
        });
        Finaled { result, mesh }
    }

    fn judge(&self, f: &Finaled) -> Option<(f64, bool)> {
        let rounds = self.settings.refine_rounds.max(usize::from(self.polish()));
        accepted_of(&f.result).map(|s| (s.objective, s.quality == Quality::Optimal && rounds > 0))
    }

    fn round(&self, _c: usize, f: &Finaled, cancel: Arc<AtomicBool>) -> Rounded {
        let current = accepted_of(&f.result)?;
        self.round_after(0, current, &f.mesh, self.polish(), Some(cancel))
    }

    fn expired(&self) -> bool {
        self.deadline.expired()
    }

    fn now(&self) -> Duration {
        self.deadline.clock().now()
    }
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
        }
    }

    /// The planner's pool of KKT workspaces and its factorisations' counters.
    pub fn kkt_cache(&self) -> &Arc<KktCache> {
        &self.kkt
    }

    /// The seeds of the last plan (for plots).
    pub fn swarm_workspace(&self) -> &SwarmWorkspace {
        &self.swarm
    }

    /// Plans `problem` by `deadline`. Never fails on a valid problem: at worst the swarm's
    /// path comes back flagged `SwarmOnly`.
    pub fn plan(
        &mut self,
        problem: &Problem,
        settings: &PlannerSettings,
        deadline: Deadline<'static>,
    ) -> Result<PlanOutcome, PlanError> {
        problem.validate()?;
        settings.validate()?;
        let clock = deadline.clock();
        let started = clock.now();
        let mut times = StageTimes::default();

        let model = usize::from(problem.dim() == 3);
        let (timing, stage_timing) = (self.timing[model], self.stage[model]);
        // The NLP stage only when the budget left after the swarm's share (and the
        // fallback's reserve) can hold it, as recent plans took it: it yields nothing before
        // its ranking is done. Otherwise the swarm has all of the budget but the reserve
        // (twice the fallback's cost, at most half the budget).
        let share = settings.swarm_share.clamp(0.0, 1.0);
        let reserve = (stage_timing.fallback * 2).min(deadline.remaining() / 2);
        let after_swarm = deadline.remaining().mul_f64(1.0 - share);
        let nlp_possible =
            stage_timing.fits_the_stage(&timing, after_swarm.saturating_sub(reserve));
        let swarm_deadline = if nlp_possible {
            deadline.share(share)
        } else {
            deadline.earlier(reserve)
        };
        let sw: SwarmOutcome =
            swarm::run(problem, &settings.swarm, &mut self.swarm, swarm_deadline)?;
        times.swarm = sw.elapsed;
        if !sw.best.is_valid() {
            return Err(PlanError::NonFinite);
        }
        let swarm_cost = trajectory_cost(problem, &sw.best);

        // The swarm's lifted path, flown with the tracking law so that its controls replay
        // onto it (in 3-D the lifted controls alone drift away): the answer if the NLP
        // does not finish. It is built now, so that at the deadline nothing is left to do
        // but return it, and timed: exporting the NLP's plan costs about as much, so the
        // NLP stops twice that long before the deadline.
        let fallback_started = clock.now();
        let mut fallback = sw.best.resampled(settings.export.max_step_s);
        if problem.dim() == 3 {
            fly_reference(problem, &settings.export, &mut fallback);
        }
        let fallback_cost = clock.now().saturating_sub(fallback_started);
        let deadline = deadline.earlier(fallback_cost * 2);

        let nlp_started = clock.now();
        let mut report = NlpReport {
            status: None,
            iterations: Vec::new(),
            intervals: Vec::new(),
            objective: f64::NAN,
            ranking: Vec::new(),
            finalists: Vec::new(),
        };
        // No time left for the ranking and one solve's set-up and wrap-up after it (as
        // recent plans measured them): no NLP stage at all, not even its starts (2-3 ms of
        // dense costs). (An expired deadline is one of these.) Asked again now: a swarm
        // that converged early may have left the time for it.
        let no_time = !stage_timing.fits_the_stage(&timing, deadline.remaining());
        // Starts from distinct basins, solved side by side on the first mesh.
        // The swarm's workspace holds this problem's seeds: no need to build them again.
        let starts = if no_time {
            Vec::new()
        } else {
            let count = settings.starts.max(1);
            basins::candidates(
                problem,
                &sw.best,
                self.swarm.seeds(),
                count,
                settings.threads,
                |tr| trajectory_cost(problem, tr),
            )
        };
        // Rank every start on the coarse mesh, solve the best distinct ones on the working
        // mesh, refine the best of those: scheduled on the planner's threads (`schedule`).
        let rank = if problem.dim() == 3 {
            &settings.ranking_mesh_3d
        } else {
            &settings.ranking_mesh
        };
        let coarse: Vec<Mesh> = starts
            .iter()
            .map(|g| {
                Mesh::uniform(
                    rank.points,
                    &phase_durations(problem.t0, g),
                    rank.interval_s,
                    rank.min_intervals,
                )
            })
            .collect();
        let stage = NlpStage {
            problem,
            settings,
            starts: &starts,
            coarse: &coarse,
            swarm_best: &sw.best,
            reference: ExportSettings {
                closed_loop: false,
                max_step_s: settings.export.max_step_s / 2.0,
                ..settings.export
            },
            timing,
            seen: Seen::default(),
            deadline,
            kkt: &self.kkt,
        };
        let done = if no_time {
            schedule::Schedule::none()
        } else {
            schedule::run(&stage, settings.threads)
        };
        times.ranking = done.ranked_at.saturating_sub(nlp_started);
        report.finalists = done.chosen;
        // The report and any error in the step-by-step order: ranks, finals, rounds. A
        // task that failed (panicked) counts as a failed solve.
        let failed = || Ok((None, 0, NlpStatus::NumericalError, SolveTiming::default()));
        // A rank the deadline stopped: the ranking was cut short.
        let mut cut = false;
        for r in done.ranks {
            let (path, result) = match r {
                Some(Ranked { result, path }) => (path, result),
                None => (None, failed()),
            };
            let (_, iterations, status, _) = result?;
            cut |= status == NlpStatus::MaxTime;
            report.iterations.push(iterations);
            report.status = Some(status);
            report.ranking.push(path.map_or(f64::NAN, |p| p.0));
        }
        let mut accepted: Option<(Solved, Mesh)> = None;
        for (k, f) in done.finals.into_iter().enumerate() {
            let (result, fine) = match f {
                Some(Finaled { result, mesh }) => (result, Some(mesh)),
                None => (failed(), None),
            };
            let (solved, iterations, status, _) = result?;
            report.iterations.push(iterations);
            report.status = Some(status);
            if done.winner == Some(k)
                && let (Some(s), Some(fine)) = (solved, fine)
            {
                accepted = Some((s, fine));
            }
        }
        // The first round ran in the schedule; the others (if any) follow it here.
        let mut round_result = done.round.flatten();
        for round in 0..settings.refine_rounds.max(usize::from(stage.polish())) {
            let Some((current, mesh)) = accepted.as_ref() else {
                break;
            };
            let next = if round == 0 {
                round_result.take()
            } else if current.quality != Quality::Optimal || deadline.expired() {
                break;
            } else {
                stage.round_after(round, current, mesh, false, None)
            };
            let Some((result, next)) = next else {
                break;
            };
            let (solved, iterations, status, _) = result?;
            report.iterations.push(iterations);
            report.status = Some(status);
            match solved {
                Some(s) => accepted = Some((s, next)),
                None => break,
            }
        }
        if let Some((a, mesh)) = &accepted {
            report.objective = a.objective;
            report.status = Some(a.status);
            report.intervals = mesh.phases.iter().map(Vec::len).collect();
            let _ = a.iterations;
        }
        times.nlp = clock.now().saturating_sub(nlp_started);
        self.timing[model] = self.timing[model].after(stage.seen.get());
        // The stage ran out of time before it had a plan (a rank or every final stopped by
        // the deadline): it needs more than it had. Else its ranking took what it took.
        let ranking = if no_time {
            Ranking::Skipped
        } else if accepted.is_none() && (cut || deadline.expired()) {
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
                (a.quality, flown)
            }
            None => (Quality::SwarmOnly, fallback),
        };
        if !trajectory.is_valid() {
            return Err(PlanError::NonFinite);
        }
        times.export = clock.now().saturating_sub(export_started) + fallback_cost;
        times.total = clock.now().saturating_sub(started);
        Ok(PlanOutcome {
            quality,
            cost: trajectory_cost(problem, &trajectory),
            trajectory,
            swarm_best: sw.best,
            swarm_cost,
            swarm_iterations: sw.iterations,
            nlp: report,
            times,
        })
    }
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

/// The transcription and primal-dual solution of `solved` to warm-start the next mesh from.
fn warm_start_of(solved: Option<&Solved>, enabled: bool) -> Option<(&Transcription, &PrimalDual)> {
    let s = solved.filter(|_| enabled)?;
    s.warm.as_ref().map(|w| (&s.tr, w))
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
