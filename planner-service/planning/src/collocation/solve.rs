//! Solving the transcription with pounce-rs (a pure-Rust port of Ipopt) under a deadline.
//!
//! Designed around the solver's known behaviour:
//! - a bare application has no restoration phase, so [`install_restoration`] wires it;
//! - its fall-back strategies re-solve silently with a fresh time budget, so they are off;
//! - on a time or iteration limit it returns the *last* iterate, so the adapter keeps the
//!   best iterate with the constraints within tolerance itself (checked every iteration in
//!   the intermediate callback, which also enforces the caller's deadline);
//! - a warm start from the previous primal and dual solution re-converges in a few
//!   iterations (`warm_start_init_point`), used by re-plans.

use std::cell::RefCell;
use std::rc::Rc;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pounce_rs::pounce_algorithm::intermediate::with_current;
use pounce_rs::pounce_common::options_list::OptionsList;
use pounce_rs::{
    AlgorithmMode, ApplicationReturnStatus, BoundsInfo, IndexStyle, IpoptApplication, IpoptCq,
    IpoptData, IterStats, NlpInfo, Solution, SparsityRequest, StartingPoint, TNLP,
};

use super::kkt::{KktCache, KktLabels, KktSolver, StructuredKkt};
pub use super::nlp_settings::{
    FeralOrdering, FeralScaling, MuStrategy, NlpSettings, NlpSettingsError, OptionError,
};
use super::transcription::Transcription;
use crate::clock::Deadline;

/// How the NLP ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NlpStatus {
    /// Converged to `tol` (or to the acceptable level).
    Converged,
    /// Stopped by the iteration limit.
    MaxIterations,
    /// Stopped by the deadline.
    MaxTime,
    /// The solver failed (restoration failure, numerical trouble, …).
    NumericalError,
    /// The solver reports the constraints cannot be met.
    Infeasible,
}

/// A primal-dual point, for warm starts.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PrimalDual {
    pub x: Vec<f64>,
    pub z_l: Vec<f64>,
    pub z_u: Vec<f64>,
    pub lambda: Vec<f64>,
}

/// What bounds a solve in time, besides its settings.
#[derive(Clone)]
pub struct SolveBudget {
    /// The solve stops before an iteration would end past it.
    pub deadline: Deadline<'static>,
    /// Set by another thread when the result is no longer wanted: the solve stops at the
    /// end of the iteration (status [`NlpStatus::MaxTime`]).
    pub cancel: Option<Arc<AtomicBool>>,
    /// The expected length of an iteration until one has been measured (the first ones
    /// of a solve are among its longest).
    pub iteration: Duration,
    /// Time kept for the work after the last iteration (the solver's wrap-up, the
    /// results).
    pub wrap_up: Duration,
}

impl SolveBudget {
    /// Bounded by `deadline` alone.
    pub fn until(deadline: Deadline<'static>) -> SolveBudget {
        SolveBudget {
            deadline,
            cancel: None,
            iteration: Duration::ZERO,
            wrap_up: Duration::ZERO,
        }
    }
}

/// The result of one NLP solve.
#[derive(Debug, Clone)]
pub struct NlpOutcome {
    pub status: NlpStatus,
    /// The solver's own return code.
    pub return_status: ApplicationReturnStatus,
    pub iterations: usize,
    /// The scaled variables to use: the solution if converged, else the best feasible
    /// iterate, else the last iterate.
    pub x: Vec<f64>,
    /// Whether `x` satisfies the constraints within `feasibility_tol`.
    pub feasible: bool,
    /// Largest scaled constraint or bound violation at `x`.
    pub violation: f64,
    /// Physical objective at `x`.
    pub objective: f64,
    /// Primal-dual solution for a warm start (when the solver finished normally).
    pub warm: Option<PrimalDual>,
    pub elapsed: Duration,
    /// Time from the start to the end of the first iteration (`None`: none ended).
    pub first_iteration: Option<Duration>,
    /// The longest iteration after the first.
    pub longest_iteration: Duration,
    /// Time from the end of the last iteration to the return.
    pub wrap_up: Duration,
}

/// The TNLP adapter: owns the transcription during the solve.
#[derive(Clone)]
struct Adapter {
    tr: Transcription,
    start: PrimalDual,
    warm: bool,
    budget: SolveBudget,
    feasibility_tol: f64,
    best: Vec<f64>,
    best_objective: f64,
    has_best: bool,
    solution: Option<PrimalDual>,
    iterations: usize,
    /// Calls of the intermediate callback (restoration's included): the step at which
    /// the deadline cuts the solve (`crate::cuts`).
    callbacks: u32,
    /// When the solve began, and when the last iteration ended (deadline clock).
    began: Duration,
    last_iteration_end: Duration,
    /// Time to the first iteration's end (set-up, ordering, initial multipliers).
    first_iteration: Option<Duration>,
    /// The longest iteration so far: a solve that has less time left stops now rather
    /// than one iteration past its deadline.
    longest_iteration: Duration,
}

impl TNLP for Adapter {
    fn get_nlp_info(&mut self) -> Option<NlpInfo> {
        Some(NlpInfo {
            n: self.tr.n_vars() as i32,
            m: self.tr.n_cons() as i32,
            nnz_jac_g: self.tr.jac.len() as i32,
            nnz_h_lag: self.tr.hess.len() as i32,
            index_style: IndexStyle::C,
        })
    }

    fn get_bounds_info(&mut self, b: BoundsInfo<'_>) -> bool {
        b.x_l.copy_from_slice(&self.tr.x_lo);
        b.x_u.copy_from_slice(&self.tr.x_hi);
        b.g_l.copy_from_slice(&self.tr.g_lo);
        b.g_u.copy_from_slice(&self.tr.g_hi);
        true
    }

    fn get_starting_point(&mut self, sp: StartingPoint<'_>) -> bool {
        sp.x.copy_from_slice(&self.start.x);
        if self.warm {
            if sp.init_z && self.start.z_l.len() == sp.z_l.len() {
                sp.z_l.copy_from_slice(&self.start.z_l);
                sp.z_u.copy_from_slice(&self.start.z_u);
            }
            if sp.init_lambda && self.start.lambda.len() == sp.lambda.len() {
                sp.lambda.copy_from_slice(&self.start.lambda);
            }
        }
        true
    }

    fn eval_f(&mut self, x: &[f64], _new_x: bool) -> Option<f64> {
        let f = self.tr.objective(x);
        f.is_finite().then_some(f)
    }

    fn eval_grad_f(&mut self, x: &[f64], _new_x: bool, grad: &mut [f64]) -> bool {
        self.tr.gradient(x, grad);
        grad.iter().all(|g| g.is_finite())
    }

    fn eval_g(&mut self, x: &[f64], _new_x: bool, g: &mut [f64]) -> bool {
        self.tr.constraints(x, g);
        g.iter().all(|v| v.is_finite())
    }

    fn eval_jac_g(&mut self, x: Option<&[f64]>, _new_x: bool, mode: SparsityRequest<'_>) -> bool {
        match mode {
            SparsityRequest::Structure { irow, jcol } => {
                for (k, &(r, c)) in self.tr.jac.iter().enumerate() {
                    irow[k] = r as i32;
                    jcol[k] = c as i32;
                }
                true
            }
            SparsityRequest::Values { values } => {
                let Some(x) = x else { return false };
                self.tr.jacobian(x, values);
                values.iter().all(|v| v.is_finite())
            }
        }
    }

    fn eval_h(
        &mut self,
        x: Option<&[f64]>,
        _new_x: bool,
        obj_factor: f64,
        lambda: Option<&[f64]>,
        _new_lambda: bool,
        mode: SparsityRequest<'_>,
    ) -> bool {
        match mode {
            SparsityRequest::Structure { irow, jcol } => {
                for (k, &(r, c)) in self.tr.hess.iter().enumerate() {
                    irow[k] = r as i32;
                    jcol[k] = c as i32;
                }
                true
            }
            SparsityRequest::Values { values } => {
                let (Some(x), Some(lambda)) = (x, lambda) else {
                    return false;
                };
                self.tr.hessian(x, obj_factor, lambda, values);
                values.iter().all(|v| v.is_finite())
            }
        }
    }

    fn finalize_solution(&mut self, sol: Solution<'_>, _d: &IpoptData, _q: &IpoptCq) {
        self.solution = Some(PrimalDual {
            x: sol.x.to_vec(),
            z_l: sol.z_l.to_vec(),
            z_u: sol.z_u.to_vec(),
            lambda: sol.lambda.to_vec(),
        });
    }

    fn intermediate_callback(&mut self, stats: IterStats, _d: &IpoptData, _q: &IpoptCq) -> bool {
        self.iterations = stats.iter.max(0) as usize;
        if stats.mode == AlgorithmMode::RegularMode
            && stats.inf_pr <= self.feasibility_tol
            && (!self.has_best || stats.obj_value < self.best_objective)
        {
            // Only this iterate's x, read from the algorithm's own state: asking for the
            // whole user iterate at every iteration (`wants_current_iterate`) builds ten
            // vectors per iteration, 3 % of a plan's time.
            let best = &mut self.best;
            let copied = with_current(|ctx| {
                let data = ctx.data.borrow();
                let Some(curr) = data.curr.as_ref() else {
                    return false;
                };
                let x = ctx.nlp.borrow().finalize_solution_x(&*curr.x);
                if x.len() == best.len() {
                    best.copy_from_slice(&x);
                    true
                } else {
                    false
                }
            });
            if copied == Some(true) {
                self.has_best = true;
                self.best_objective = stats.obj_value;
            }
        }
        let now = self.budget.deadline.clock().now();
        if self.first_iteration.is_none() {
            self.first_iteration = Some(now.saturating_sub(self.began));
        } else {
            let took = now.saturating_sub(self.last_iteration_end);
            self.longest_iteration = self.longest_iteration.max(took);
        }
        self.last_iteration_end = now;
        self.callbacks += 1;
        let budget = &self.budget;
        let cancelled = budget
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed));
        if cancelled {
            return false;
        }
        let next = self.longest_iteration.max(budget.iteration);
        !budget
            .deadline
            .cuts(self.callbacks, |d| d.remaining() <= next + budget.wrap_up)
    }
}

/// Wires the restoration phase into `app` (a bare application has none). Call after
/// setting options: the provider copies them.
fn install_restoration(app: &mut IpoptApplication) {
    use pounce_rs::pounce_algorithm::application::{
        Ma57Config, default_backend_factory, feral_config_from_options,
    };
    use pounce_rs::pounce_restoration::resto_alg_builder::RestoAlgorithmBuilder;
    use pounce_rs::pounce_restoration::resto_inner_solver::{
        InnerBackendFactoryFactory, make_default_restoration_factory_provider,
    };
    let feral_cfg = feral_config_from_options(app.options());
    let factory = move || -> InnerBackendFactoryFactory {
        let cfg = feral_cfg.clone();
        Box::new(move || default_backend_factory(cfg.clone(), Ma57Config::default()))
    };
    let provider = make_default_restoration_factory_provider(
        RestoAlgorithmBuilder::new(),
        app.algorithm_builder_from_options(),
        factory,
    );
    app.set_restoration_factory_provider(provider);
}

fn application(
    settings: &NlpSettings,
    warm: bool,
    budget: Duration,
    labels: Option<KktLabels>,
    kkt: &Arc<KktCache>,
) -> Result<IpoptApplication, OptionError> {
    let mut app = IpoptApplication::new();
    let _ = app.initialize();
    let o = app.options_mut();
    let num = |o: &mut OptionsList, name: &'static str, v: f64| {
        o.set_numeric_value(name, v, true, false)
            .map(|_| ())
            .map_err(|e| OptionError {
                name,
                reason: format!("{e:?}"),
            })
    };
    num(o, "tol", settings.tol)?;
    num(o, "acceptable_tol", settings.acceptable_tol)?;
    if let Some(v) = settings.acceptable_constr_viol_tol {
        num(o, "acceptable_constr_viol_tol", v)?;
    }
    if let Some(v) = settings.constr_viol_tol {
        num(o, "constr_viol_tol", v)?;
    }
    // The deadline is kept by the intermediate callback on the injected clock, every
    // iteration (the restoration phase's too). The solver's own wall-time limit reads the
    // OS clock: set to the budget, it made a solve under a clock that stands still (tests)
    // end after the budget in real time, on a loaded host unfinished. It stays as a
    // backstop only, past anything the callback lets through.
    num(o, "max_wall_time", (budget * 2).as_secs_f64() + 1.0)?;
    // Nothing else in the solver may spend a share of that wall time: the adaptive
    // barrier's switch to its monotone endgame would be a choice of the clock that no
    // deadline cut records (`crate::cuts`), so a replay would not take it.
    num(o, "adaptive_mu_budget_pin_fraction", 1.0)?;
    let int = |o: &mut OptionsList, name: &'static str, v: i32| {
        o.set_integer_value(name, v, true, false)
            .map(|_| ())
            .map_err(|e| OptionError {
                name,
                reason: format!("{e:?}"),
            })
    };
    int(o, "max_iter", settings.max_iter)?;
    int(o, "acceptable_iter", settings.acceptable_iter)?;
    int(o, "print_level", settings.print_level)?;
    let text = |o: &mut OptionsList, name: &'static str, v: &str| {
        o.set_string_value(name, v, true, false)
            .map(|_| ())
            .map_err(|e| OptionError {
                name,
                reason: format!("{e:?}"),
            })
    };
    text(o, "hessian_approximation", "exact")?;
    text(o, "mu_strategy", settings.mu_strategy.as_str())?;
    text(o, "linear_solver", "feral")?;
    let flag = |o: &mut OptionsList, name: &'static str, v: bool| {
        o.set_bool_value(name, v, true, false)
            .map(|_| ())
            .map_err(|e| OptionError {
                name,
                reason: format!("{e:?}"),
            })
    };
    flag(o, "mu_strategy_fallback", false)?;
    flag(o, "solve_quality_audit", false)?;
    flag(o, "dual_divergence_retry", false)?;
    flag(o, "honor_original_bounds", true)?;
    flag(o, "feral_refine", settings.feral_refine)?;
    text(o, "feral_ordering", settings.feral_ordering.as_str())?;
    text(o, "feral_scaling", settings.feral_scaling.as_str())?;
    flag(o, "feral_static_pivoting", settings.feral_static_pivoting)?;
    if let Some(p) = settings.feral_pivtol {
        num(o, "feral_pivtol", p)?;
    }
    if settings.print_level > 0 {
        flag(o, "print_timing_statistics", true)?;
    }
    if settings.serial_factorization {
        num(o, "feral_min_par_flops", 1e30)?;
    }
    if !settings.second_order_check {
        int(o, "neg_curv_escapes", 0)?;
    }
    if !settings.second_order_corrections {
        int(o, "max_soc", 0)?;
    }
    if let Some(mu) = settings.mu_init {
        num(o, "mu_init", mu)?;
    }
    if warm {
        flag(o, "warm_start_init_point", true)?;
        for name in [
            "warm_start_bound_push",
            "warm_start_bound_frac",
            "warm_start_slack_bound_push",
            "warm_start_slack_bound_frac",
            "warm_start_mult_bound_push",
        ] {
            num(o, name, settings.warm_start_push)?;
        }
        num(o, "mu_init", settings.warm_start_mu_init)?;
    }
    set_extra_options(o, &settings.extra)?;
    install_restoration(&mut app);
    if settings.kkt == KktSolver::Structured {
        install_structured_kkt(&mut app, labels, Arc::clone(kkt));
    }
    Ok(app)
}

/// Sets `extra` (`name=value`: an integer, a number or a word) on `o`, after the others.
pub(super) fn set_extra_options(
    o: &mut OptionsList,
    extra: &[(String, String)],
) -> Result<(), OptionError> {
    for (name, value) in extra {
        let done = if let Ok(i) = value.parse::<i32>() {
            o.set_integer_value(name, i, true, false).is_ok()
                || o.set_numeric_value(name, f64::from(i), true, false).is_ok()
        } else if let Ok(v) = value.parse::<f64>() {
            o.set_numeric_value(name, v, true, false).is_ok()
        } else {
            o.set_string_value(name, value, true, false).is_ok()
        };
        if !done {
            return Err(OptionError {
                name: "extra",
                reason: format!("{name}={value}: refused"),
            });
        }
    }
    Ok(())
}

/// Plugs the structured KKT backend into `app`'s main algorithm, falling back to FERAL
/// configured exactly as pounce's default backend would be (the same options). Call after
/// setting options.
fn install_structured_kkt(
    app: &mut IpoptApplication,
    labels: Option<KktLabels>,
    cache: Arc<KktCache>,
) {
    use pounce_feral::FeralSolverInterface;
    use pounce_linsol::SparseSymLinearSolverInterface;
    use pounce_rs::pounce_algorithm::alg_builder::LinearSolverChoice;
    use pounce_rs::pounce_algorithm::application::feral_config_from_options;
    let feral_cfg = feral_config_from_options(app.options());
    app.set_linear_backend_factory(Box::new(
        move |choice| -> Box<dyn SparseSymLinearSolverInterface> {
            match choice {
                LinearSolverChoice::Feral => Box::new(StructuredKkt::new(
                    labels.clone(),
                    feral_cfg.clone(),
                    Arc::clone(&cache),
                )),
                // Not asked for by these settings; pounce's own answer without MA57.
                LinearSolverChoice::Ma57 => {
                    Box::new(FeralSolverInterface::with_config(feral_cfg.clone()))
                }
            }
        },
    ));
}

/// Solves `tr` from the scaled start `start` (with its duals when `warm_start`), stopping
/// within `budget`, the structured backend's workspaces pooled in `kkt` (the planner's).
/// Returns the transcription back with the outcome.
pub fn solve(
    tr: Transcription,
    start: PrimalDual,
    warm_start: bool,
    settings: &NlpSettings,
    budget: SolveBudget,
    kkt: &Arc<KktCache>,
) -> Result<(Transcription, NlpOutcome), OptionError> {
    let deadline = budget.deadline;
    let clock = deadline.clock();
    let began = clock.now();
    let n = tr.n_vars();
    let labels = (settings.kkt == KktSolver::Structured).then(|| KktLabels::of(&tr));
    let mut app = application(settings, warm_start, deadline.remaining(), labels, kkt)?;
    let adapter = Rc::new(RefCell::new(Adapter {
        tr,
        start,
        warm: warm_start,
        budget,
        feasibility_tol: settings.feasibility_tol,
        best: vec![0.0; n],
        best_objective: f64::INFINITY,
        has_best: false,
        solution: None,
        iterations: 0,
        callbacks: 0,
        began,
        last_iteration_end: began,
        first_iteration: None,
        longest_iteration: Duration::ZERO,
    }));
    let dyn_adapter: Rc<RefCell<dyn TNLP>> = adapter.clone();
    let return_status = app.optimize_tnlp(dyn_adapter);
    let iterations = app.statistics().iteration_count.max(0) as usize;
    drop(app);
    let mut a = match Rc::try_unwrap(adapter) {
        Ok(cell) => cell.into_inner(),
        // The application let go of the problem when dropped; if it did not, copy it out.
        Err(rc) => rc.borrow().clone(),
    };
    if matches!(
        return_status,
        ApplicationReturnStatus::MaximumWallTimeExceeded
            | ApplicationReturnStatus::MaximumCpuTimeExceeded
    ) {
        // The backstop stopped it after this callback: a replay stops it there (one
        // stopped before its first callback, after a set-up of over a second past its
        // deadline, is replayed as stopped at its first: step 0 means "not started").
        deadline.note_cut(a.callbacks.max(1));
    }
    let status = match return_status {
        ApplicationReturnStatus::SolveSucceeded
        | ApplicationReturnStatus::SolvedToAcceptableLevel => NlpStatus::Converged,
        ApplicationReturnStatus::MaximumIterationsExceeded => NlpStatus::MaxIterations,
        ApplicationReturnStatus::MaximumWallTimeExceeded
        | ApplicationReturnStatus::MaximumCpuTimeExceeded
        | ApplicationReturnStatus::UserRequestedStop => NlpStatus::MaxTime,
        ApplicationReturnStatus::InfeasibleProblemDetected => NlpStatus::Infeasible,
        _ => NlpStatus::NumericalError,
    };
    let mut g = vec![0.0; a.tr.n_cons()];
    let last = a.solution.as_ref().map(|s| s.x.clone());
    // Prefer the converged solution; else the best feasible iterate; else the last.
    let mut x = match (&last, status) {
        (Some(x), NlpStatus::Converged) => x.clone(),
        _ if a.has_best => a.best.clone(),
        (Some(x), _) => x.clone(),
        (None, _) => a.start.x.clone(),
    };
    let mut violation = a.tr.violation(&x, &mut g);
    if status != NlpStatus::Converged
        && a.has_best
        && let Some(last) = &last
    {
        // The last iterate may be feasible and better than the best seen in a callback.
        let v_last = a.tr.violation(last, &mut g);
        if v_last <= settings.feasibility_tol && a.tr.objective(last) < a.tr.objective(&x) {
            x = last.clone();
            violation = v_last;
        }
    }
    let objective = a.tr.objective(&x) / a.tr.obj_scale;
    let warm = match status {
        NlpStatus::Converged => a.solution.take(),
        _ => None,
    };
    let outcome = NlpOutcome {
        status,
        return_status,
        iterations: iterations.max(a.iterations),
        feasible: violation <= settings.feasibility_tol,
        violation,
        objective,
        x,
        warm,
        elapsed: clock.now().saturating_sub(began),
        first_iteration: a.first_iteration,
        longest_iteration: a.longest_iteration,
        wrap_up: match a.first_iteration {
            Some(_) => clock.now().saturating_sub(a.last_iteration_end),
            None => Duration::ZERO,
        },
    };
    Ok((a.tr, outcome))
}
