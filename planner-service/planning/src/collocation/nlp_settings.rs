//! The NLP solve's settings: a builder with defaults, the solver's option words as enums,
//! and [`NlpSettings::validate`], which refuses a bad setting (or an extra option the
//! solver does not take) before a plan starts.

use pounce_rs::IpoptApplication;

use super::kkt::KktSolver;
use super::solve::set_extra_options;

/// Solver options that spend the solver's own time budget (the OS clock): refused as extra
/// options, since the planner's deadline and its recorded cuts decide when a solve stops.
const CLOCK_OPTIONS: [&str; 5] = [
    "max_wall_time",
    "max_cpu_time",
    "adaptive_mu_budget_pin_fraction",
    "crossover",
    "ipm_sqp_handover",
];

/// Settings of the NLP solve.
#[derive(Debug, Clone, PartialEq)]
pub struct NlpSettings {
    /// Convergence tolerance (Ipopt `tol`, on the scaled problem).
    pub tol: f64,
    /// "Acceptable" tolerance and the number of acceptable iterations that stop the solve.
    pub acceptable_tol: f64,
    pub acceptable_iter: i32,
    /// Largest constraint violation an "acceptable" stop may leave (`None`: the solver's
    /// default, 1e-2).
    pub acceptable_constr_viol_tol: Option<f64>,
    /// Largest constraint violation a converged solve may leave (Ipopt `constr_viol_tol`,
    /// on the scaled problem; `None`: the solver's default, 1e-4).
    pub constr_viol_tol: Option<f64>,
    /// Iteration limit.
    pub max_iter: i32,
    /// Largest scaled constraint violation of an iterate that counts as feasible.
    pub feasibility_tol: f64,
    /// How the barrier parameter is updated.
    pub mu_strategy: MuStrategy,
    /// Warm-start pushes (used with a warm start only).
    pub warm_start_push: f64,
    pub warm_start_mu_init: f64,
    /// Ipopt print level (0: silent).
    pub print_level: i32,
    /// FERAL's own iterative refinement inside each back-solve (pounce already refines
    /// the unreduced Newton system around it).
    pub feral_refine: bool,
    /// FERAL fill-reducing ordering.
    pub feral_ordering: FeralOrdering,
    /// Keep every factorization on the calling thread: the KKT systems of one plan are
    /// small, and rayon's fork/join hand-offs cost more than they save on two cores.
    pub serial_factorization: bool,
    /// FERAL's diagonal scaling.
    pub feral_scaling: FeralScaling,
    /// FERAL static pivoting (force-accept small pivots instead of delaying them).
    pub feral_static_pivoting: bool,
    /// FERAL pivot tolerance (`None`: the solver's default).
    pub feral_pivtol: Option<f64>,
    /// On convergence, the solver's second-order test (pounce's negative-curvature
    /// escape): it re-evaluates the Hessian and factors the KKT once more to check that the
    /// point is a minimum, and leaves along negative curvature if not. 3-25 ms per solve
    /// on the canonical scenarios.
    pub second_order_check: bool,
    /// The line search's second-order corrections (Ipopt `max_soc`: up to 4 per
    /// iteration when a trial step is rejected; `false`: none).
    pub second_order_corrections: bool,
    /// The linear solver of the KKT systems: FERAL, or block elimination along the chain
    /// of mesh intervals ([`super::kkt`]; FERAL where the structure does not hold). The
    /// restoration phase keeps FERAL either way. Structured by default: on the canonical
    /// scenarios (probe, 3 seeds, same window) 38-62 % less plan time, the same costs
    /// (docs/decisions/0015-structured-kkt-backend.md).
    pub kkt: KktSolver,
    /// Initial barrier parameter of a cold start (`None`: the solver's default, 0.1).
    pub mu_init: Option<f64>,
    /// Initial barrier parameter when starting from a previous solution on a refined mesh.
    pub refine_mu_init: f64,
    /// Further solver options by name (`name=value`: a number, an integer or a word), set
    /// after the ones above; for experiments and expert tuning. [`NlpSettings::validate`]
    /// checks that the solver takes each of them.
    pub extra: Vec<(String, String)>,
}

/// Declares a `&'static str`-valued enum of a solver option: its variants, their option
/// words and `as_str`.
macro_rules! option_words {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident => $word:literal,)* }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum $name {
            $($(#[$vdoc])* $variant,)*
        }

        impl $name {
            /// The solver's word for it.
            pub const fn as_str(self) -> &'static str {
                match self {
                    $($name::$variant => $word,)*
                }
            }
        }
    };
}

option_words! {
    /// The barrier parameter's update (Ipopt `mu_strategy`).
    MuStrategy {
        /// Fiacco–McCormick: the barrier falls once each subproblem is solved.
        Monotone => "monotone",
        /// A new barrier every iteration from an oracle.
        Adaptive => "adaptive",
    }
}

option_words! {
    /// FERAL's fill-reducing ordering (`feral_ordering`).
    FeralOrdering {
        /// FERAL picks per matrix.
        Auto => "auto",
        /// Approximate minimum degree.
        Amd => "amd",
        /// Approximate minimum fill.
        Amf => "amf",
        /// Nested dissection (METIS).
        Metis => "metis",
    }
}

option_words! {
    /// FERAL's diagonal scaling (`feral_scaling`).
    FeralScaling {
        /// FERAL picks per matrix.
        Auto => "auto",
        /// Iterative infinity-norm equilibration.
        InfNorm => "infnorm",
        /// Matching-based symmetric scaling.
        Mc64 => "mc64",
        /// No scaling.
        Identity => "identity",
    }
}

/// NLP settings that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NlpSettingsError {
    /// A setting out of its range.
    #[error("NLP setting `{setting}`: {problem}")]
    OutOfRange {
        setting: &'static str,
        problem: &'static str,
    },
    /// An extra option the solver refuses.
    #[error(transparent)]
    Refused(#[from] OptionError),
}

/// A builder method per setting: `with_<name>(value)`.
macro_rules! nlp_setter {
    ($($(#[$doc:meta])* $fn_name:ident, $field:ident, $ty:ty;)*) => {$(
        $(#[$doc])*
        pub fn $fn_name(mut self, value: $ty) -> Self {
            self.$field = value;
            self
        }
    )*};
}

impl NlpSettings {
    nlp_setter! {
        /// Sets [`NlpSettings::tol`].
        with_tol, tol, f64;
        /// Sets [`NlpSettings::acceptable_tol`].
        with_acceptable_tol, acceptable_tol, f64;
        /// Sets [`NlpSettings::acceptable_iter`].
        with_acceptable_iter, acceptable_iter, i32;
        /// Sets [`NlpSettings::acceptable_constr_viol_tol`].
        with_acceptable_constr_viol_tol, acceptable_constr_viol_tol, Option<f64>;
        /// Sets [`NlpSettings::constr_viol_tol`].
        with_constr_viol_tol, constr_viol_tol, Option<f64>;
        /// Sets [`NlpSettings::max_iter`].
        with_max_iter, max_iter, i32;
        /// Sets [`NlpSettings::feasibility_tol`].
        with_feasibility_tol, feasibility_tol, f64;
        /// Sets [`NlpSettings::mu_strategy`].
        with_mu_strategy, mu_strategy, MuStrategy;
        /// Sets [`NlpSettings::feral_ordering`].
        with_feral_ordering, feral_ordering, FeralOrdering;
        /// Sets [`NlpSettings::feral_scaling`].
        with_feral_scaling, feral_scaling, FeralScaling;
        /// Sets [`NlpSettings::feral_static_pivoting`].
        with_feral_static_pivoting, feral_static_pivoting, bool;
        /// Sets [`NlpSettings::second_order_check`].
        with_second_order_check, second_order_check, bool;
        /// Sets [`NlpSettings::second_order_corrections`].
        with_second_order_corrections, second_order_corrections, bool;
        /// Sets [`NlpSettings::kkt`].
        with_kkt, kkt, KktSolver;
        /// Sets [`NlpSettings::mu_init`].
        with_mu_init, mu_init, Option<f64>;
        /// Sets [`NlpSettings::refine_mu_init`].
        with_refine_mu_init, refine_mu_init, f64;
    }

    /// Adds an extra solver option (see [`NlpSettings::extra`]).
    pub fn with_extra(mut self, name: impl Into<String>, value: impl Into<String>) -> Self {
        self.extra.push((name.into(), value.into()));
        self
    }

    /// Checks every setting is in range and the solver takes every extra option, so that
    /// a bad setting is refused when the planner is built, not by the solver mid-plan.
    pub fn validate(&self) -> Result<(), NlpSettingsError> {
        let out = |setting: &'static str, problem: &'static str| {
            Err(NlpSettingsError::OutOfRange { setting, problem })
        };
        let positive = |x: f64| x.is_finite() && x > 0.0;
        for (setting, value) in [
            ("tol", self.tol),
            ("acceptable_tol", self.acceptable_tol),
            ("feasibility_tol", self.feasibility_tol),
            ("warm_start_push", self.warm_start_push),
            ("warm_start_mu_init", self.warm_start_mu_init),
            ("refine_mu_init", self.refine_mu_init),
        ] {
            if !positive(value) {
                return out(setting, "must be finite and positive");
            }
        }
        for (setting, value) in [
            (
                "acceptable_constr_viol_tol",
                self.acceptable_constr_viol_tol,
            ),
            ("constr_viol_tol", self.constr_viol_tol),
            ("feral_pivtol", self.feral_pivtol),
            ("mu_init", self.mu_init),
        ] {
            if value.is_some_and(|v| !positive(v)) {
                return out(setting, "must be finite and positive when set");
            }
        }
        if self.max_iter < 1 {
            return out("max_iter", "must be at least 1");
        }
        if self.acceptable_iter < 0 {
            return out("acceptable_iter", "must not be negative");
        }
        if !(0..=12).contains(&self.print_level) {
            return out("print_level", "must be in 0..=12");
        }
        if self
            .extra
            .iter()
            .any(|(name, _)| CLOCK_OPTIONS.contains(&name.as_str()))
        {
            return out(
                "extra",
                "max_wall_time, max_cpu_time, adaptive_mu_budget_pin_fraction, crossover and \
                 ipm_sqp_handover spend the solver's own time budget: choices of the clock \
                 that no deadline cut records (the deadline is the planner's)",
            );
        }
        if !self.extra.is_empty() {
            let mut app = IpoptApplication::new();
            let _ = app.initialize();
            set_extra_options(app.options_mut(), &self.extra)?;
        }
        Ok(())
    }
}

impl Default for NlpSettings {
    fn default() -> Self {
        NlpSettings {
            tol: 1e-7,
            acceptable_tol: 1e-5,
            acceptable_iter: 5,
            acceptable_constr_viol_tol: None,
            constr_viol_tol: None,
            max_iter: 300,
            feasibility_tol: 1e-6,
            mu_strategy: MuStrategy::Monotone,
            warm_start_push: 1e-6,
            warm_start_mu_init: 1e-6,
            print_level: 0,
            feral_refine: false,
            feral_ordering: FeralOrdering::Amf,
            serial_factorization: true,
            feral_scaling: FeralScaling::Identity,
            feral_static_pivoting: false,
            feral_pivtol: None,
            second_order_check: true,
            second_order_corrections: true,
            kkt: KktSolver::Structured,
            mu_init: None,
            refine_mu_init: 1e-3,
            extra: Vec::new(),
        }
    }
}

/// An option the solver refused: a programming error in the settings.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("NLP option `{name}` refused: {reason}")]
pub struct OptionError {
    pub name: &'static str,
    pub reason: String,
}
