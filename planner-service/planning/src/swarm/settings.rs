//! The swarm's settings ([`SwarmSettings`]: defaults, builder, [`SwarmSettings::validate`]),
//! its errors and why it stopped.

use crate::seeding::{SeedError, SeedSettings};

#[cfg(doc)]
use super::outcome::SwarmOutcome;

/// Most particle groups.
pub const MAX_GROUPS: usize = 64;

/// Bad input, or a failure that should not happen.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SwarmError {
    /// A setting is out of range.
    #[error("swarm settings: {0}")]
    Settings(String),
    /// The seeds cannot be built.
    #[error(transparent)]
    Seeds(#[from] SeedError),
    /// The problem is not well posed.
    #[error("swarm problem: {0}")]
    Problem(String),
    /// A worker thread died or the best path could not be lifted (a bug).
    #[error("swarm internal error: {0}")]
    Internal(String),
}

/// Why the swarm stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwarmStatus {
    /// The global best stalled (no relative gain above `stall_tolerance` for
    /// `stall_iterations` iterations).
    Converged,
    /// `max_iterations` done.
    MaxIterations,
    /// The deadline passed.
    MaxTime,
}

/// What a particle's coordinates are (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Parameterisation {
    /// Offsets added to the guidance command (pure pursuit of the next target, then of
    /// the end or the lead's intercept point), each within twice the control's bound.
    Guided,
    /// The controls themselves (the dissertation's particles).
    Direct,
}

/// Settings of the swarm (builder with defaults; [`SwarmSettings::validate`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SwarmSettings {
    /// Number of particles `M`. Default 24.
    pub particles: usize,
    /// Iteration limit `R`. Default 100.
    pub max_iterations: usize,
    /// Control step `dt`, s (raised when the horizon needs more than `max_steps` steps).
    /// Default 20 s.
    pub dt: f64,
    /// Samples per control step (the guidance acts and the cost is sampled at each).
    /// Default 3 (6.7 s samples).
    pub substeps: usize,
    /// Most control steps (sizes the workspace). Default 256.
    pub max_steps: usize,
    /// Horizon beyond the longest seed's duration, as a fraction of it. Default 0.3.
    pub horizon_margin: f64,
    /// `D*`, m: a particle passing a target or the end farther away is infeasible.
    /// Default 5000 m.
    pub d_star: f64,
    /// Seed of the swarm's random numbers (ChaCha8).
    pub seed: u64,
    /// Threads evaluating seeds and particles (the calling one included). Default 2: on
    /// the project's 2-vCPU machine two threads take 25–35 % less time than one while the
    /// host gives both cores; at times it gives one core's throughput (two single-thread
    /// runs together then each take twice as long), and two threads are then up to 30 %
    /// slower than one. The result is bit-identical for any number of threads.
    pub threads: usize,
    /// Constriction factor `K`. Default 0.6417.
    pub constriction: f64,
    /// Local weight `bL`. Default 1.0.
    pub local_weight: f64,
    /// Global weight `bG`. Default 3.2.
    pub global_weight: f64,
    /// Velocity bound per coordinate as a fraction of its range. Default 0.5.
    pub velocity_limit: f64,
    /// Iterations without gain before [`SwarmStatus::Converged`]. Default 30.
    pub stall_iterations: usize,
    /// Relative gain that counts. Default 1e-4.
    pub stall_tolerance: f64,
    /// Miss penalty weight (see the module documentation). Default 4.
    pub miss_weight: f64,
    /// Fixed-time penalty weight. Default 4.
    pub time_weight: f64,
    /// Final heading penalty weight. Default 2.
    pub heading_weight: f64,
    /// Look-ahead of the seed-tracking controller, s of flight. Default 15 s.
    pub lookahead: f64,
    /// Noise (fraction of the range) on copies of seeds when there are more particles than
    /// seeds. Default 0.1.
    pub perturbation: f64,
    /// Groups of particles (niches), each led by a seed far from the other leaders and
    /// attracted to its own best until `merge_fraction` of `max_iterations`; 1 = one
    /// swarm with the global best throughout. Default 4.
    pub groups: usize,
    /// Fraction of `max_iterations` after which every particle follows the global best
    /// (1: never, the groups stay in their basins). Default 1.
    pub merge_fraction: f64,
    /// Most entries of [`SwarmOutcome::candidates`]. Default 3.
    pub candidates: usize,
    /// What the coordinates are. Default [`Parameterisation::Guided`].
    pub parameterisation: Parameterisation,
    /// The seeds.
    pub seeds: SeedSettings,
}

impl Default for SwarmSettings {
    fn default() -> Self {
        SwarmSettings {
            particles: 24,
            max_iterations: 100,
            dt: 20.0,
            substeps: 3,
            max_steps: 256,
            horizon_margin: 0.3,
            d_star: 5000.0,
            seed: 0,
            threads: 2,
            constriction: 0.6417,
            local_weight: 1.0,
            global_weight: 3.2,
            velocity_limit: 0.5,
            stall_iterations: 30,
            stall_tolerance: 1e-4,
            miss_weight: 4.0,
            time_weight: 4.0,
            heading_weight: 2.0,
            lookahead: 15.0,
            perturbation: 0.1,
            groups: 4,
            merge_fraction: 1.0,
            candidates: 3,
            parameterisation: Parameterisation::Guided,
            seeds: SeedSettings::default(),
        }
    }
}

macro_rules! setter {
    ($(#[$m:meta])* $name:ident, $field:ident, $t:ty) => {
        $(#[$m])*
        pub fn $name(mut self, v: $t) -> Self {
            self.$field = v;
            self
        }
    };
}

impl SwarmSettings {
    setter!(
        /// Sets [`SwarmSettings::particles`].
        with_particles, particles, usize
    );
    setter!(
        /// Sets [`SwarmSettings::max_iterations`].
        with_max_iterations, max_iterations, usize
    );
    setter!(
        /// Sets [`SwarmSettings::dt`].
        with_dt, dt, f64
    );
    setter!(
        /// Sets [`SwarmSettings::substeps`].
        with_substeps, substeps, usize
    );
    setter!(
        /// Sets [`SwarmSettings::max_steps`].
        with_max_steps, max_steps, usize
    );
    setter!(
        /// Sets [`SwarmSettings::horizon_margin`].
        with_horizon_margin, horizon_margin, f64
    );
    setter!(
        /// Sets [`SwarmSettings::d_star`].
        with_d_star, d_star, f64
    );
    setter!(
        /// Sets [`SwarmSettings::threads`].
        with_threads, threads, usize
    );
    setter!(
        /// Sets [`SwarmSettings::constriction`].
        with_constriction, constriction, f64
    );
    setter!(
        /// Sets [`SwarmSettings::local_weight`].
        with_local_weight, local_weight, f64
    );
    setter!(
        /// Sets [`SwarmSettings::global_weight`].
        with_global_weight, global_weight, f64
    );
    setter!(
        /// Sets [`SwarmSettings::velocity_limit`].
        with_velocity_limit, velocity_limit, f64
    );
    setter!(
        /// Sets [`SwarmSettings::stall_iterations`].
        with_stall_iterations, stall_iterations, usize
    );
    setter!(
        /// Sets [`SwarmSettings::stall_tolerance`].
        with_stall_tolerance, stall_tolerance, f64
    );
    setter!(
        /// Sets [`SwarmSettings::miss_weight`].
        with_miss_weight, miss_weight, f64
    );
    setter!(
        /// Sets [`SwarmSettings::time_weight`].
        with_time_weight, time_weight, f64
    );
    setter!(
        /// Sets [`SwarmSettings::heading_weight`].
        with_heading_weight, heading_weight, f64
    );
    setter!(
        /// Sets [`SwarmSettings::lookahead`].
        with_lookahead, lookahead, f64
    );
    setter!(
        /// Sets [`SwarmSettings::perturbation`].
        with_perturbation, perturbation, f64
    );
    setter!(
        /// Sets [`SwarmSettings::groups`].
        with_groups, groups, usize
    );
    setter!(
        /// Sets [`SwarmSettings::merge_fraction`].
        with_merge_fraction, merge_fraction, f64
    );
    setter!(
        /// Sets [`SwarmSettings::candidates`].
        with_candidates, candidates, usize
    );
    setter!(
        /// Sets [`SwarmSettings::parameterisation`].
        with_parameterisation, parameterisation, Parameterisation
    );
    setter!(
        /// Sets [`SwarmSettings::seeds`].
        with_seeds, seeds, SeedSettings
    );

    /// Sets the swarm's random seed and derives the random seeds' one from it, so one
    /// number (`--seed N`) drives the whole run.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self.seeds.rng_seed = seed ^ 0x9e37_79b9_7f4a_7c15;
        self
    }

    /// Checks every setting is in range.
    pub fn validate(&self) -> Result<(), SwarmError> {
        let bad = |m: &str| Err(SwarmError::Settings(m.to_string()));
        let pos = |x: f64| x.is_finite() && x > 0.0;
        if !(2..=4096).contains(&self.particles) {
            return bad("particles must be in 2..=4096");
        }
        if self.max_iterations > 1_000_000 {
            return bad("max_iterations must be at most 1e6");
        }
        if !pos(self.dt) {
            return bad("dt must be finite and positive");
        }
        if !(1..=16).contains(&self.substeps) {
            return bad("substeps must be in 1..=16");
        }
        if !(4..=100_000).contains(&self.max_steps) {
            return bad("max_steps must be in 4..=100000");
        }
        if !(self.horizon_margin.is_finite() && (0.0..=10.0).contains(&self.horizon_margin)) {
            return bad("horizon_margin must be in [0, 10]");
        }
        if !pos(self.d_star) {
            return bad("d_star must be finite and positive");
        }
        if !(1..=64).contains(&self.threads) {
            return bad("threads must be in 1..=64");
        }
        if !(pos(self.constriction) && self.constriction <= 1.0) {
            return bad("constriction must be in (0, 1]");
        }
        for (name, w) in [
            ("local_weight", self.local_weight),
            ("global_weight", self.global_weight),
            ("miss_weight", self.miss_weight),
            ("time_weight", self.time_weight),
            ("heading_weight", self.heading_weight),
        ] {
            if !(w.is_finite() && w >= 0.0) {
                return Err(SwarmError::Settings(format!(
                    "{name} must be finite and non-negative"
                )));
            }
        }
        if !(pos(self.velocity_limit) && self.velocity_limit <= 2.0) {
            return bad("velocity_limit must be in (0, 2]");
        }
        if !(self.stall_tolerance.is_finite() && self.stall_tolerance >= 0.0) {
            return bad("stall_tolerance must be finite and non-negative");
        }
        if !(pos(self.lookahead) && self.lookahead <= 600.0) {
            return bad("lookahead must be in (0, 600] s");
        }
        if self.groups == 0 || self.groups > self.particles.min(MAX_GROUPS) {
            return bad("groups must be in 1..=min(particles, 64)");
        }
        if !(self.merge_fraction.is_finite() && (0.0..=1.0).contains(&self.merge_fraction)) {
            return bad("merge_fraction must be in [0, 1]");
        }
        if !(self.perturbation.is_finite() && (0.0..=1.0).contains(&self.perturbation)) {
            return bad("perturbation must be in [0, 1]");
        }
        self.seeds.validate()?;
        Ok(())
    }
}
