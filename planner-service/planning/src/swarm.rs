//! The particle swarm of the hybrid planner (dissertation chapter IV, FORMULATION.md §7):
//! it flies the spline seeds ([`crate::seeding`]) as particles, improves them with Clerc's
//! constriction PSO and hands its global best, lifted to the full model, to the
//! collocation NLP as the initial guess — with the best paths of other basins as
//! [`SwarmOutcome::candidates`] for a multi-start.
//!
//! # Particles
//!
//! A particle is a vector of discrete controls on a fixed grid of `steps` control steps of
//! length `dt`, flown with the model from the initial state in `substeps` samples of `h =
//! dt / substeps` per step:
//!
//! - **2-D**: a turn rate per step, flown as exact circular arcs (eq. 3.8 integrated in
//!   closed form, not eq. 4.3's Euler step), clamped to `±u_max`;
//! - **3-D**: the reduced model of eq. (5.11), two coordinates per step: the flight-path
//!   angle, clamped to `±gamma_max`, and the heading *rate*, clamped to the fastest
//!   coordinated turn `g tan(mu_max) / V` (or `g sqrt(Nz_max² - 1) / V` when the load factor
//!   binds first). Within a sample `gamma` and `chi` vary linearly, so the lift of eqs.
//!   (5.13)–(5.15) gives `|mu| <= mu_max` in level turns. The dissertation's heading as a
//!   coordinate lets neighbouring coordinates jump independently, which the lift turns
//!   into bank reversals at every step. A sample that would end under `z_min` has its
//!   final `gamma` raised so that it does not.
//!
//! **Guided coordinates** ([`Parameterisation::Guided`], the default). Each coordinate is
//! an *offset*, within twice the control's bound, added at every sample to a guidance
//! command: pure pursuit of the next target not yet passed, then of the final point or
//! of the lead's intercept point (the arc tangent to the heading through the aim point;
//! in 3-D also the flight-path angle of the line of sight). The control flown is the
//! clamped sum. With the dissertation's *direct* coordinates
//! ([`Parameterisation::Direct`], kept as a setting), a change of an early turn rate
//! moves every later position by kilometres: measured on the canonical 2-D scenarios,
//! particles pulled towards the global best missed the targets by kilometres (median cost
//! ten times the best), and in 30 iterations no particle ever improved on the best seed.
//! With guided coordinates every particle homes onto the targets, the offsets shape the
//! route between them, and the swarm improves the seeds by 3–30 %.
//!
//! Seeds become particles by flying them with the model under pure pursuit of the seed:
//! per control step, a trial flight gives the offsets, corrected until the step flown as
//! the particle flies it ends with the trial's heading ([`SwarmWorkspace::seed_trajectory`]
//! returns a seed as flown).
//!
//! # Cost (eqs. 4.5–4.8)
//!
//! The path passes target `g` where it comes closest to it (closest point of the polyline
//! of samples) within its first approach inside `D*` after the previous target's pass; the
//! final time `tf` is the same pass of the final point (min-time), of the lead's position
//! at the same time (rendezvous: eq. 4.8's `D_Rend`, closest approach of the relative
//! motion), or, for a fixed final time, the approach within `D*` whose `|tf - t_fixed|` and
//! miss distance cost least. Flying stops once the final pass is known. A particle none of
//! whose approaches comes within `D*` of a target or of the end is *infeasible*: its
//! velocity is set to zero for the step and it ranks after every feasible particle (among
//! themselves the infeasible ones still rank by cost, so the swarm always has a best).
//!
//! The swarm cost is the objective of FORMULATION.md §4 up to `tf` — `J_run` (fixed-time)
//! or `alpha tf + (1 - alpha) J_run`, `J_run = ∫ (1 - beta)|u|² + beta E(w, t) dt` with the
//! exposure of [`Problem::exposure`] at each sample's *time* (moving threats at their
//! propagated regions, cached per sample time) by the trapezoid rule, `|u|²` of the 2-D
//! turn rate or, in 3-D, of `(Nz', mu')` from the lift — plus the penalties of eqs.
//! 4.6–4.8 in additive form:
//!
//! ```text
//! P = w_d (sum of target misses + end miss or D_Rend + altitude-floor violation)
//!   + w_t |tf - t_fixed|                                     (fixed-time only)
//!   + w_h (1 - cos(heading error at tf)) + w_h (1 - cos(gamma error at tf))
//! ```
//!
//! with `c = alpha' + (1 - alpha')(beta + (1 - beta) u_max²)` the cost of one second in a
//! threat turning at the bound (`alpha' = alpha`, 0 for fixed-time), `w_d = miss_weight c /
//! V`, `w_t = time_weight c`, `w_h = heading_weight c / u_max`. A miss of `m` metres costs
//! as much as `miss_weight m / V` seconds in a threat — more than cutting the corner could
//! save — so the best path passes the targets and the end; a heading error of 180° costs
//! `2 heading_weight / u_max` seconds, about the time of the turn the NLP would add.
//!
//! # Update (eq. 4.1 with the sign fixed) and groups
//!
//! `v <- K [v + bL r1 ∘ (L - u) + bG r2 ∘ (G - u)]`, `u <- u + v`, `K = 0.6417`,
//! `bL = 1.0`, `bG = 3.2` (appendix C), `r1`, `r2` uniform in `[0, 1]` per coordinate;
//! velocities bounded by `velocity_limit` times the coordinate's range, positions clamped
//! to the bounds (the velocity component is zeroed at a wall).
//!
//! The particles form `groups` groups (niches), each with its own `G`: the best seed leads
//! the first group, each next leader is the seed farthest (mean distance between the
//! paths) from the leaders so far among the better half of the seeds, and every other seed
//! joins its nearest leader's group. One swarm with one `G` collapses on the best seed's
//! basin at once, and the best seed is often not in the best basin: measured with a local
//! NLP started from each seed, seeds whose raw cost was 1.5–6 times the best seed's led to
//! optima 3–9 % better (a path through a narrow gap between two threats, a longer path
//! crossing overlapping threats at their waist). Refined separately, the basins compete
//! fairly; the groups stay separate to the end (`merge_fraction = 1`), so the other
//! groups' bests are distinct basins for a multi-start NLP. The returned path is the
//! group best that is nearly feasible (misses within 1 km, heading within 30°, fixed
//! time within 10 s) with the lowest objective (plus `2 alpha miss / V` in min-time):
//! the penalised cost would rank basins by their residual misses (a 50 m miss weighs
//! ~3 % of a min-time cost, more than the gap between neighbouring basins).
//!
//! # Determinism and threads
//!
//! Every random number is drawn on the calling thread in a fixed order (particle by
//! particle, coordinate by coordinate) from a ChaCha8 generator seeded by
//! [`SwarmSettings::seed`]; evaluations of seeds and particles (pure functions of them)
//! are split into contiguous shards evaluated in parallel by persistent `crossbeam` scoped
//! threads that meet at a spinning barrier; reductions run in particle order on the
//! calling thread. The result is bit-identical for any thread count and timing.
//!
//! # Time and memory
//!
//! The deadline is checked before every round of the particles: one starts only while it
//! still fits (as long as the longest round so far; the first as long as scoring as many
//! seeds), else the best so far is returned with [`SwarmStatus::MaxTime`] (with a deadline
//! already passed: the best seed). So only a run that ends within a round of its deadline
//! depends on the clock; any other gives the same bits for the same seed. Every buffer is
//! allocated in [`SwarmWorkspace::new`]; a run allocates only to build the seeds, to start
//! its worker threads and for the returned trajectories, never in the iteration loop
//! (`tests/swarm_no_alloc.rs`).
//!
//! # Defaults
//!
//! Measured on the canonical scenarios (`docs/BENCHMARKS.md`, "Swarm (issue 5)"):
//! `dt = 20 s` with 3 samples of 6.7 s (1.3–1.7 km: fine against threats of 6–25 km
//! semi-axes; the guidance acts at every sample, so a coarser `dt` only lowers the
//! dimension: 20 s halves it against 10 s at the same basin rate), 24 particles in 4
//! groups, at most 100 iterations and a stall stop after 30 iterations without a 1e-4
//! relative gain of any group; `D* = 5 km` (dissertation); two threads (see
//! [`SwarmSettings::threads`]). That is a median of 12–19 ms on the 2-D scenarios and
//! 27–47 ms on the 3-D ones (one thread: 17–26 ms and 39–62 ms); 32 particles, 150
//! iterations and 5 s samples cost 2.3 times as much for a basin rate no better.

mod eval;
mod sync;

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wingman_interfaces::{MAX_PHASES, Objective};

use crate::clock::Deadline;
use crate::problem::Problem;
use crate::seeding::{self, Seed, SeedError, SeedLabel, SeedSettings};
use crate::trajectory::Trajectory;
use eval::{Grid, GridParams, OutBuffers, Report, Score, Scratch};
use sync::{AbortOnUnwind, SpinBarrier};

/// Jobs of the worker threads.
const JOB_STOP: usize = 0;
const JOB_SEEDS: usize = 1;
const JOB_PARTICLES: usize = 2;

/// Points of a seed's sketch (leader diversity).
const SKETCH: usize = 24;

/// Most particle groups.
pub const MAX_GROUPS: usize = 64;

/// `2^-32`: scales a 32-bit integer to a uniform number in `[0, 1)`.
const TWO_POW_M32: f64 = 1.0 / 4_294_967_296.0;

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

/// What the swarm knows about its best path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathReport {
    /// Number of phases (targets + 1).
    pub phases: usize,
    /// Time of each pass (targets, then the end): the phase end times.
    pub pass_times: [f64; MAX_PHASES],
    /// Distance of each pass, m (the last: to the final point or the lead).
    pub pass_distances: [f64; MAX_PHASES],
    /// Final time.
    pub final_time: f64,
    /// The objective of FORMULATION.md §4 on the swarm's samples (no penalty).
    pub objective: f64,
    /// `∫ E dt` up to the final time.
    pub exposure_integral: f64,
    /// `∫ |u|² dt` up to the final time.
    pub effort_integral: f64,
    /// The swarm's penalties.
    pub penalty: f64,
    /// Heading error at the final time (wrapped), rad.
    pub final_heading_error: f64,
    /// Flight-path angle error at the final time (3-D), rad.
    pub final_gamma_error: f64,
    /// Every pass within `D*`.
    pub feasible: bool,
}

impl PathReport {
    fn from_report(r: &Report, g: &Grid) -> Self {
        let mut pass_times = [f64::NAN; MAX_PHASES];
        let mut pass_distances = [f64::NAN; MAX_PHASES];
        for (i, p) in r.passes[..r.n_passes].iter().enumerate() {
            pass_times[i] = p.time(g);
            pass_distances[i] = p.dist;
        }
        PathReport {
            phases: r.n_passes,
            pass_times,
            pass_distances,
            final_time: r.tf,
            objective: r.objective,
            exposure_integral: r.exposure,
            effort_integral: r.effort,
            penalty: r.penalty,
            final_heading_error: r.heading_error,
            final_gamma_error: r.gamma_error,
            feasible: r.score.feasible,
        }
    }
}

/// Another group's best: a path in a different basin (see [`SwarmOutcome::candidates`]).
#[derive(Debug, Clone)]
pub struct Candidate {
    /// Its swarm cost.
    pub cost: f64,
    pub report: PathReport,
    /// As [`SwarmOutcome::best`].
    pub trajectory: Trajectory,
}

/// The swarm's result.
#[derive(Debug, Clone)]
pub struct SwarmOutcome {
    pub status: SwarmStatus,
    /// Iterations done.
    pub iterations: usize,
    /// The returned path's swarm cost (objective + penalties).
    pub cost: f64,
    /// The returned path: of the groups' bests, the first by basin rank (nearly feasible,
    /// then lowest objective; see the module documentation); the global best with one
    /// group; the best seed when no iteration ran. Full-model states and controls up to
    /// its final time (3-D lifted with eqs. 5.13–5.15), phase ends at the passes.
    pub best: Trajectory,
    /// Details of the returned path.
    pub report: PathReport,
    /// The other groups' bests in rank order, other basins than `best` (the groups
    /// started from distant seeds), for a multi-start NLP; at most
    /// [`SwarmSettings::candidates`]. Empty with one group.
    pub candidates: Vec<Candidate>,
    /// The best seed's swarm cost.
    pub seeds_best_cost: f64,
    /// The best seed's name.
    pub seeds_best: SeedLabel,
    /// Number of seeds built.
    pub seeds: usize,
    /// Control step used (`dt`, or more for a long horizon).
    pub dt: f64,
    /// Particle evaluations done (seeds included).
    pub evaluations: usize,
    /// Time from the call to the return on the deadline's clock.
    pub elapsed: Duration,
}

/// A contiguous group of particles evaluated by one thread.
#[derive(Debug)]
struct Shard {
    count: usize,
    x: Vec<f64>,
    v: Vec<f64>,
    best: Vec<f64>,
    score: Vec<Score>,
    best_score: Vec<Score>,
    scratch: Scratch,
    /// A seed's particle while the seeds are evaluated.
    seed_u: Vec<f64>,
    /// `(seed, score)` of the seeds this shard evaluated.
    seed_scores: Vec<(usize, Score)>,
}

impl Shard {
    fn new(count: usize, dim: usize, samples: usize, seeds: usize) -> Self {
        Shard {
            count,
            x: vec![0.0; count * dim],
            v: vec![0.0; count * dim],
            best: vec![0.0; count * dim],
            score: vec![Score::default(); count],
            best_score: vec![Score::default(); count],
            scratch: Scratch::new(samples),
            seed_u: vec![0.0; dim],
            seed_scores: Vec::with_capacity(seeds),
        }
    }

    /// Flies and prices seeds `first, first + stride, ...`, the first of them at least and
    /// the others until `deadline` (the seeds left out are not scored: they rank last).
    fn evaluate_seeds(
        &mut self,
        g: &Grid,
        seeds: &[Seed],
        lookahead: f64,
        (first, stride): (usize, usize),
        deadline: &Deadline<'_>,
    ) {
        let dim = g.dim();
        self.seed_scores.clear();
        for i in (first..seeds.len()).step_by(stride) {
            if !self.seed_scores.is_empty() && deadline.expired() {
                break;
            }
            let u = &mut self.seed_u[..dim];
            eval::track(g, &seeds[i], lookahead, u);
            let score = eval::evaluate(g, u, &mut self.scratch).score;
            self.seed_scores.push((i, score));
        }
    }

    /// Evaluates every particle of the shard (`dim` coordinates each).
    fn evaluate(&mut self, g: &Grid, dim: usize) {
        let Shard {
            count,
            x,
            score,
            scratch,
            ..
        } = self;
        for j in 0..*count {
            score[j] = eval::evaluate(g, &x[j * dim..(j + 1) * dim], scratch).score;
        }
    }
}

fn lock(m: &Mutex<Shard>) -> MutexGuard<'_, Shard> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Sizes a workspace holds.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Capacity {
    particles: usize,
    groups: usize,
    threads: usize,
    /// Coordinates per particle.
    dim: usize,
    samples: usize,
    iterations: usize,
}

impl Capacity {
    fn of(s: &SwarmSettings) -> Self {
        Capacity {
            particles: s.particles,
            groups: s.groups.clamp(1, s.particles),
            threads: s.threads.min(s.particles),
            dim: 2 * s.max_steps,
            samples: s.max_steps * s.substeps + 1,
            iterations: s.max_iterations + 1,
        }
    }

    fn holds(&self, other: &Capacity) -> bool {
        self.particles == other.particles
            && self.groups >= other.groups
            && self.threads == other.threads
            && self.dim >= other.dim
            && self.samples >= other.samples
            && self.iterations >= other.iterations
    }
}

/// Every buffer of the swarm, allocated once; a re-plan reuses it.
#[derive(Debug)]
pub struct SwarmWorkspace {
    cap: Capacity,
    grid: Grid,
    shards: Vec<Mutex<Shard>>,
    global: Vec<f64>,
    /// Best position of each group (`groups * dim`) and its score.
    group_best: Vec<f64>,
    group_score: Vec<Score>,
    seeds: Vec<Seed>,
    seed_scores: Vec<Score>,
    /// Each seed's path at [`SKETCH`] evenly spaced arc fractions (leader diversity).
    sketches: Vec<[f64; 3]>,
    /// Seed of each particle (`usize::MAX`: a perturbed copy of its group's leader) and
    /// each group's leader.
    member_seed: Vec<usize>,
    leaders: Vec<usize>,
    order: Vec<usize>,
    seed_u: Vec<f64>,
    history: Vec<f64>,
    out: OutBuffers,
    best: Trajectory,
    /// The last run's seed-tracking look-ahead (for [`SwarmWorkspace::seed_trajectory`]).
    lookahead: f64,
}

impl SwarmWorkspace {
    /// A workspace for runs with `settings` (a later run with larger sizes reallocates
    /// once, before its loop).
    pub fn new(settings: &SwarmSettings) -> Self {
        let cap = Capacity::of(settings);
        let threads = cap.threads.max(1);
        let per = settings.particles.div_ceil(threads);
        let shards = (0..threads)
            .map(|t| {
                let count = per.min(settings.particles.saturating_sub(t * per));
                Mutex::new(Shard::new(
                    count,
                    cap.dim,
                    cap.samples,
                    settings.seeds.max_seeds,
                ))
            })
            .collect();
        let seeds_cap = settings.seeds.max_seeds;
        SwarmWorkspace {
            cap,
            grid: Grid::new(cap.samples, 2),
            shards,
            global: vec![0.0; cap.dim],
            group_best: vec![0.0; cap.groups * cap.dim],
            group_score: vec![Score::default(); cap.groups],
            seeds: Vec::with_capacity(seeds_cap),
            seed_scores: Vec::with_capacity(seeds_cap),
            sketches: Vec::with_capacity(seeds_cap * SKETCH),
            member_seed: vec![0; cap.particles],
            leaders: Vec::with_capacity(cap.groups),
            order: Vec::with_capacity(seeds_cap),
            seed_u: vec![0.0; cap.dim],
            history: Vec::with_capacity(cap.iterations + 1),
            out: OutBuffers::with_capacity(cap.samples + MAX_PHASES + 2),
            best: trajectory_with_capacity(cap.samples + MAX_PHASES + 2),
            lookahead: settings.lookahead,
        }
    }

    /// The seeds of the last run.
    pub fn seeds(&self) -> &[Seed] {
        &self.seeds
    }

    /// Each seed's name and path points (for plots).
    pub fn seed_paths(&self) -> impl Iterator<Item = (&SeedLabel, &[[f64; 3]])> {
        self.seeds.iter().map(|s| (s.label(), s.points()))
    }

    /// The global best's swarm cost (the least of any particle so far) after the seeds,
    /// after the initial particles and after each iteration of the last run
    /// (non-increasing).
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    /// Seed `index` of the last run as the swarm flies it (its particle before any swarm
    /// iteration), with its swarm cost and report; `None` for a bad index or before any
    /// run. Allocates the returned trajectory.
    pub fn seed_trajectory(&mut self, index: usize) -> Option<(f64, PathReport, Trajectory)> {
        let lookahead = self.lookahead;
        let seed = self.seeds.get(index)?;
        if self.grid.steps == 0 {
            return None;
        }
        let dim = self.grid.dim();
        let u = &mut self.seed_u[..dim];
        eval::track(&self.grid, seed, lookahead, u);
        let mut sh = lock(&self.shards[0]);
        let rep = eval::evaluate(&self.grid, u, &mut sh.scratch);
        let mut out = Trajectory::default();
        eval::write_trajectory(&self.grid, &sh.scratch, &rep, &mut self.out, &mut out).ok()?;
        Some((
            rep.score.cost,
            PathReport::from_report(&rep, &self.grid),
            out,
        ))
    }

    fn reserve(&mut self, settings: &SwarmSettings) {
        if !self.cap.holds(&Capacity::of(settings)) {
            *self = SwarmWorkspace::new(settings);
        }
    }
}

/// Tolerances within which a group's best counts as nearly feasible for the final choice:
/// misses the NLP closes easily.
const NEAR_MISS_M: f64 = 1000.0;
const NEAR_ANGLE_RAD: f64 = 30.0 * std::f64::consts::PI / 180.0;
const NEAR_TIME_S: f64 = 10.0;

/// How a group's best ranks as the NLP's start: nearly feasible paths first (misses
/// within 1 km, heading and flight-path angle errors within 30 degrees, fixed final time
/// within 10 s, altitude floor within 100 m), then by the objective plus, for min-time
/// objectives, the time a miss costs to fix (`2 alpha miss / V`). The penalised swarm
/// cost ranks basins by the noise of their residual misses — in min-time scenarios a 50 m
/// miss weighs ~3 % of the cost, more than the 0.3–1 % between neighbouring basins — so
/// the choice between basins uses the objective.
fn basin_rank(g: &Grid, rep: &Report) -> (bool, f64) {
    let misses: f64 = rep.passes[..rep.n_passes].iter().map(|p| p.dist).sum();
    let worst = rep.passes[..rep.n_passes]
        .iter()
        .map(|p| p.dist)
        .fold(0.0, f64::max);
    let fixed = g.objective == Objective::FixedTime;
    let near = rep.score.feasible
        && worst <= NEAR_MISS_M
        && rep.heading_error.abs() <= NEAR_ANGLE_RAD
        && rep.gamma_error.abs() <= NEAR_ANGLE_RAD
        && rep.floor_violation <= 100.0
        && (!fixed || (rep.tf - g.fixed_time).abs() <= NEAR_TIME_S);
    let alpha = if fixed { 0.0 } else { g.alpha };
    (near, rep.objective + 2.0 * alpha * misses / g.speed)
}

fn trajectory_with_capacity(n: usize) -> Trajectory {
    Trajectory {
        times: Vec::with_capacity(n),
        states: Vec::with_capacity(n),
        controls: Vec::with_capacity(n),
        phase_ends: Vec::with_capacity(MAX_PHASES),
    }
}

/// Runs the swarm on `problem` until it converges, reaches `max_iterations` or the
/// deadline. `Err` only for bad settings or an ill-posed problem.
pub fn run(
    problem: &Problem,
    settings: &SwarmSettings,
    ws: &mut SwarmWorkspace,
    deadline: Deadline<'_>,
) -> Result<SwarmOutcome, SwarmError> {
    let clock = deadline.clock();
    let started = clock.now();
    settings.validate()?;
    problem
        .validate()
        .map_err(|e| SwarmError::Problem(e.to_string()))?;
    ws.reserve(settings);
    ws.lookahead = settings.lookahead;
    // Under a deadline too short for them all, the most promising seeds only.
    seeding::seeds_until(problem, &settings.seeds, &mut ws.seeds, &|| {
        deadline.expired()
    })?;

    // Horizon and grid: long enough for every seed within 1.5 times the shortest seed's
    // duration (and for a fixed final time), plus the margin. Longer seeds may not reach
    // the end inside it and rank last; sizing by the longest seed would waste most
    // coordinates of every particle on paths no min-time optimum flies.
    let speed = problem.limits.speed;
    let shortest = ws
        .seeds
        .iter()
        .map(|s| s.length() / speed)
        .fold(f64::INFINITY, f64::min);
    let mut horizon = ws
        .seeds
        .iter()
        .map(|s| s.length() / speed)
        .filter(|&d| d <= 1.5 * shortest)
        .fold(0.0, f64::max);
    if problem.objective == Objective::FixedTime
        && let Some(tf) = problem.final_time
    {
        horizon = horizon.max(tf - problem.t0);
    }
    horizon *= 1.0 + settings.horizon_margin;
    if !(horizon.is_finite() && horizon > 0.0) {
        return Err(SwarmError::Problem(format!(
            "cannot size the horizon ({horizon} s)"
        )));
    }
    let dt = settings.dt.max(horizon / settings.max_steps as f64);
    let steps = ((horizon / dt).ceil() as usize).clamp(1, settings.max_steps);
    ws.grid.prepare(
        problem,
        &GridParams {
            dt,
            substeps: settings.substeps,
            steps,
            d_star: settings.d_star,
            miss_weight: settings.miss_weight,
            time_weight: settings.time_weight,
            heading_weight: settings.heading_weight,
            velocity_limit: settings.velocity_limit,
            guided: settings.parameterisation == Parameterisation::Guided,
        },
    );
    let dim = ws.grid.dim();

    let SwarmWorkspace {
        grid,
        shards,
        global,
        group_best,
        group_score,
        seeds,
        seed_scores,
        sketches,
        member_seed,
        leaders,
        order,
        history,
        out,
        best,
        ..
    } = ws;
    let grid: &Grid = grid;
    let shards: &[Mutex<Shard>] = shards;
    let seeds: &[Seed] = seeds;
    let global = &mut global[..dim];
    let groups = settings.groups;
    let per_group = settings.particles.div_ceil(groups);
    let group_best = &mut group_best[..groups * dim];
    let group_score = &mut group_score[..groups];
    history.clear();
    seed_scores.clear();
    seed_scores.resize(seeds.len(), Score::default());
    sketches.clear();
    order.clear();

    let threads = shards.len();
    let barrier = SpinBarrier::new(threads);
    let job = AtomicUsize::new(JOB_STOP);
    let mut status = SwarmStatus::MaxIterations;
    let mut iterations = 0;
    let mut evaluations = 0;
    let mut gscore = Score::default();
    let mut seeds_best = 0;
    let lookahead = settings.lookahead;
    let result = crossbeam::scope(|scope| {
        // Workers: shard t evaluates its particles, or the seeds t, t + threads, ...
        for (t, shard) in shards.iter().enumerate().skip(1) {
            let (barrier, job) = (&barrier, &job);
            scope.spawn(move |_| {
                let _guard = AbortOnUnwind(barrier);
                loop {
                    if !barrier.wait() {
                        break;
                    }
                    match job.load(Ordering::Acquire) {
                        JOB_SEEDS => lock(shard).evaluate_seeds(
                            grid,
                            seeds,
                            lookahead,
                            (t, threads),
                            &deadline,
                        ),
                        JOB_PARTICLES => lock(shard).evaluate(grid, dim),
                        _ => break,
                    }
                    if !barrier.wait() {
                        break;
                    }
                }
            });
        }
        let _guard = AbortOnUnwind(&barrier);
        // One round of `what` on every shard (the calling thread does shard 0).
        let run_job = |what: usize| -> bool {
            job.store(what, Ordering::Release);
            if threads > 1 && !barrier.wait() {
                return false;
            }
            {
                let mut sh = lock(&shards[0]);
                if what == JOB_SEEDS {
                    sh.evaluate_seeds(grid, seeds, lookahead, (0, threads), &deadline);
                } else {
                    sh.evaluate(grid, dim);
                }
            }
            threads == 1 || barrier.wait()
        };
        let stop = || {
            job.store(JOB_STOP, Ordering::Release);
            if threads > 1 {
                barrier.wait();
            }
        };

        // Seeds: fly each, price it, rank them.
        let seeds_started = clock.now();
        if !run_job(JOB_SEEDS) {
            return false;
        }
        let mut scored = 0;
        for m in shards {
            let sh = lock(m);
            scored += sh.seed_scores.len();
            for &(i, s) in &sh.seed_scores {
                seed_scores[i] = s;
            }
        }
        // A round of the particles takes about as long as scoring as many seeds (tracking
        // the seeds onto the particles first takes less): the estimate of the first round,
        // until one is measured.
        let mut round = clock
            .now()
            .saturating_sub(seeds_started)
            .mul_f64(settings.particles as f64 / scored.max(1) as f64);
        for (i, seed) in seeds.iter().enumerate() {
            order.push(i);
            let total = seed.arc_lengths().last().copied().unwrap_or(0.0);
            for k in 0..SKETCH {
                sketches.push(seed.point_at_arc(total * (k as f64 + 0.5) / SKETCH as f64));
            }
        }
        evaluations = seeds.len();
        order.sort_unstable_by(|&a, &b| {
            let (sa, sb) = (&seed_scores[a], &seed_scores[b]);
            if sa.better_than(sb) {
                std::cmp::Ordering::Less
            } else if sb.better_than(sa) {
                std::cmp::Ordering::Greater
            } else {
                a.cmp(&b)
            }
        });
        seeds_best = order[0];
        eval::track(grid, &seeds[seeds_best], lookahead, global);
        gscore = seed_scores[seeds_best];
        history.push(gscore.cost);
        // No time for the particles' first round: the best seed.
        if deadline.remaining() <= round {
            status = SwarmStatus::MaxTime;
            stop();
            return true;
        }

        // Groups: the best seed leads the first; each next leader is the seed farthest
        // from the leaders so far (mean distance between the paths at equal arc
        // fractions) among the better half of the seeds, so that the groups refine
        // different basins. Every other seed, best first, joins the group of its nearest
        // leader while it has room; the rest of a group are perturbed copies of its
        // leader. One group: the best seeds in order.
        let distance = |a: usize, b: usize| -> f64 {
            let pa = &sketches[a * SKETCH..(a + 1) * SKETCH];
            let pb = &sketches[b * SKETCH..(b + 1) * SKETCH];
            pa.iter()
                .zip(pb)
                .map(|(p, q)| {
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
                })
                .sum::<f64>()
                / SKETCH as f64
        };
        leaders.clear();
        leaders.push(order[0]);
        let pool = &order[..order.len().div_ceil(2).max(groups.min(order.len()))];
        while leaders.len() < groups.min(order.len()) {
            let mut pick = None;
            let mut far = -1.0;
            for &i in pool.iter() {
                if leaders.contains(&i) {
                    continue;
                }
                let d = leaders
                    .iter()
                    .map(|&l| distance(i, l))
                    .fold(f64::INFINITY, f64::min);
                if d > far {
                    far = d;
                    pick = Some(i);
                }
            }
            match pick {
                Some(i) => leaders.push(i),
                None => break,
            }
        }
        let n_leaders = leaders.len();
        member_seed[..settings.particles].fill(usize::MAX);
        let mut filled = [0usize; MAX_GROUPS];
        for (k, &leader) in leaders.iter().enumerate() {
            member_seed[k * per_group] = leader;
            filled[k] = 1;
        }
        for &i in order.iter() {
            if leaders.contains(&i) {
                continue;
            }
            let k = if groups == 1 {
                0
            } else {
                (0..n_leaders)
                    .min_by(|&a, &b| distance(i, leaders[a]).total_cmp(&distance(i, leaders[b])))
                    .unwrap_or(0)
            };
            let room = per_group.min(settings.particles - k * per_group);
            if filled[k] < room {
                member_seed[k * per_group + filled[k]] = i;
                filled[k] += 1;
            }
        }
        for (k, &leader) in leaders.iter().enumerate() {
            eval::track(
                grid,
                &seeds[leader],
                lookahead,
                &mut group_best[k * dim..(k + 1) * dim],
            );
            group_score[k] = seed_scores[leader];
        }
        for k in n_leaders..groups {
            group_best.copy_within(0..dim, k * dim);
            group_score[k] = group_score[0];
        }
        // Particles.
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        let mut j = 0;
        for m in shards {
            let mut sh = lock(m);
            let sh = &mut *sh;
            for l in 0..sh.count {
                let x = &mut sh.x[l * dim..(l + 1) * dim];
                let k = j / per_group;
                let seed = member_seed[j];
                let copy = seed == usize::MAX;
                let source = if copy {
                    leaders[k.min(n_leaders - 1)]
                } else {
                    seed
                };
                eval::track(grid, &seeds[source], lookahead, x);
                if copy {
                    for (d, xi) in x.iter_mut().enumerate() {
                        let c = d % grid.nu;
                        let r: f64 = rng.random();
                        let range = grid.hi[c] - grid.lo[c];
                        *xi = (*xi + settings.perturbation * range * (2.0 * r - 1.0))
                            .clamp(grid.lo[c], grid.hi[c]);
                    }
                }
                sh.v[l * dim..(l + 1) * dim].fill(0.0);
                j += 1;
            }
        }
        let first_round = clock.now();
        let mut alive = run_job(JOB_PARTICLES);
        round = clock.now().saturating_sub(first_round);
        // Local bests are the particles themselves; group bests (from their leaders)
        // and the global best (from the best seed) improve with them.
        let mut j = 0;
        for m in shards {
            let mut sh = lock(m);
            let sh = &mut *sh;
            for l in 0..sh.count {
                let r = l * dim..(l + 1) * dim;
                let k = j / per_group;
                sh.best[r.clone()].copy_from_slice(&sh.x[r.clone()]);
                sh.best_score[l] = sh.score[l];
                if sh.score[l].better_than(&group_score[k]) {
                    group_best[k * dim..(k + 1) * dim].copy_from_slice(&sh.x[r.clone()]);
                    group_score[k] = sh.score[l];
                }
                if sh.score[l].better_than(&gscore) {
                    global.copy_from_slice(&sh.x[r]);
                    gscore = sh.score[l];
                }
                j += 1;
            }
        }
        evaluations += settings.particles;
        history.push(gscore.cost);
        let (k, bl, bg) = (
            settings.constriction,
            settings.local_weight,
            settings.global_weight,
        );
        let mut reference = gscore;
        let mut group_reference = [Score::default(); MAX_GROUPS];
        group_reference[..groups].copy_from_slice(group_score);
        let group_reference = &mut group_reference[..groups];
        let mut last_gain = 0;
        let mut last_left: Option<Duration> = None;
        while alive {
            if iterations >= settings.max_iterations {
                status = SwarmStatus::MaxIterations;
                break;
            }
            // Stop while the next iteration still fits: as long as the longest so far, each
            // measured from one of these checks to the next.
            let left = deadline.remaining();
            if let Some(before) = last_left {
                round = round.max(before.saturating_sub(left));
            }
            if left <= round {
                status = SwarmStatus::MaxTime;
                break;
            }
            last_left = Some(left);
            iterations += 1;
            // Update (eq. 4.1), random numbers in particle order; the attractor `G` is the
            // particle's group best until the merge, then the global best.
            let merged = groups == 1
                || iterations as f64 > settings.merge_fraction * settings.max_iterations as f64;
            let mut j = 0;
            for m in shards {
                let mut sh = lock(m);
                let Shard {
                    count, x, v, best, ..
                } = &mut *sh;
                for l in 0..*count {
                    let o = l * dim;
                    let grp = j / per_group;
                    j += 1;
                    let attractor: &[f64] = if merged {
                        global
                    } else {
                        &group_best[grp * dim..(grp + 1) * dim]
                    };
                    for d in 0..dim {
                        let c = d % grid.nu;
                        // Two 32-bit uniforms in [0, 1) from one 64-bit draw.
                        let bits: u64 = rng.random();
                        let r1 = (bits >> 32) as f64 * TWO_POW_M32;
                        let r2 = (bits & 0xffff_ffff) as f64 * TWO_POW_M32;
                        let xi = x[o + d];
                        let mut vi = k
                            * (v[o + d]
                                + bl * r1 * (best[o + d] - xi)
                                + bg * r2 * (attractor[d] - xi));
                        vi = vi.clamp(-grid.vmax[c], grid.vmax[c]);
                        let mut xn = xi + vi;
                        if xn < grid.lo[c] {
                            xn = grid.lo[c];
                            vi = 0.0;
                        } else if xn > grid.hi[c] {
                            xn = grid.hi[c];
                            vi = 0.0;
                        }
                        x[o + d] = xn;
                        v[o + d] = vi;
                    }
                }
            }
            alive = run_job(JOB_PARTICLES);
            // Reduce in particle order.
            let mut j = 0;
            for m in shards {
                let mut sh = lock(m);
                let Shard {
                    count,
                    x,
                    v,
                    best,
                    score,
                    best_score,
                    ..
                } = &mut *sh;
                for l in 0..*count {
                    let r = l * dim..(l + 1) * dim;
                    if !score[l].feasible {
                        v[r.clone()].fill(0.0);
                    }
                    let grp = j / per_group;
                    j += 1;
                    if score[l].better_than(&best_score[l]) {
                        best[r.clone()].copy_from_slice(&x[r.clone()]);
                        best_score[l] = score[l];
                        if best_score[l].better_than(&group_score[grp]) {
                            group_best[grp * dim..(grp + 1) * dim]
                                .copy_from_slice(&best[r.clone()]);
                            group_score[grp] = best_score[l];
                        }
                        if best_score[l].better_than(&gscore) {
                            global.copy_from_slice(&best[r]);
                            gscore = best_score[l];
                        }
                    }
                }
            }
            evaluations += settings.particles;
            history.push(gscore.cost);
            // A gain: the global best improved, or (before the merge) any group's best.
            let tol = settings.stall_tolerance;
            let better = |now: &Score, was: &Score| {
                (now.feasible && !was.feasible)
                    || now.cost < was.cost - tol * was.cost.abs().max(1e-12)
            };
            let mut gain = better(&gscore, &reference);
            if gain {
                reference = gscore;
            }
            if !merged {
                for (now, was) in group_score.iter().zip(group_reference.iter_mut()) {
                    if better(now, was) {
                        gain = true;
                        *was = *now;
                    }
                }
            }
            if gain {
                last_gain = iterations;
            } else if iterations - last_gain >= settings.stall_iterations {
                status = SwarmStatus::Converged;
                break;
            }
        }
        stop();
        alive
    });
    match result {
        Ok(true) => {}
        Ok(false) | Err(_) => {
            tracing::error!("swarm: a worker thread died");
            return Err(SwarmError::Internal("a worker thread died".into()));
        }
    }
    let seeds_best_cost = seed_scores[seeds_best].cost;
    let seeds_best_label = *seeds[seeds_best].label();

    // The returned path and the candidates: the groups' bests (the global best among
    // them) ranked by `basin_rank`; with no iteration done, the best seed.
    let mut order_buf = [0usize; MAX_GROUPS];
    let mut keys = [(false, 0.0f64, 0.0f64); MAX_GROUPS];
    let ranked = if groups > 1 && iterations > 0 {
        let mut sh = lock(&shards[0]);
        for k in 0..groups {
            let rep = eval::evaluate(grid, &group_best[k * dim..(k + 1) * dim], &mut sh.scratch);
            let (near, rank) = basin_rank(grid, &rep);
            keys[k] = (near, rank, rep.score.cost);
            order_buf[k] = k;
        }
        let order = &mut order_buf[..groups];
        order.sort_by(|&a, &b| {
            let (ka, kb) = (keys[a], keys[b]);
            kb.0.cmp(&ka.0)
                .then(ka.1.total_cmp(&kb.1))
                .then(ka.2.total_cmp(&kb.2))
                .then(a.cmp(&b))
        });
        &order_buf[..groups]
    } else {
        &order_buf[..0]
    };
    let chosen: &[f64] = match ranked.first() {
        Some(&k) => &group_best[k * dim..(k + 1) * dim],
        None => global,
    };
    let (report, traj, cost) = {
        let mut sh = lock(&shards[0]);
        let rep = eval::evaluate(grid, chosen, &mut sh.scratch);
        eval::write_trajectory(grid, &sh.scratch, &rep, out, best).map_err(|e| {
            tracing::error!("swarm: lifting the best path failed: {e}");
            SwarmError::Internal(format!("lifting the best path: {e}"))
        })?;
        (
            PathReport::from_report(&rep, grid),
            best.clone(),
            rep.score.cost,
        )
    };
    let mut candidates = Vec::with_capacity(settings.candidates);
    for (i, &k) in ranked.iter().enumerate().skip(1) {
        if candidates.len() == settings.candidates {
            break;
        }
        let gb = &group_best[k * dim..(k + 1) * dim];
        // The same path as one ranked before it (two groups in one basin): skip it.
        if ranked[..i]
            .iter()
            .any(|&q| &group_best[q * dim..(q + 1) * dim] == gb)
        {
            continue;
        }
        let mut sh = lock(&shards[0]);
        let rep = eval::evaluate(grid, gb, &mut sh.scratch);
        let mut t = Trajectory::default();
        if eval::write_trajectory(grid, &sh.scratch, &rep, out, &mut t).is_ok() {
            candidates.push(Candidate {
                cost: rep.score.cost,
                report: PathReport::from_report(&rep, grid),
                trajectory: t,
            });
        }
    }
    Ok(SwarmOutcome {
        status,
        iterations,
        cost,
        best: traj,
        report,
        candidates,
        seeds_best_cost,
        seeds_best: seeds_best_label,
        seeds: seeds.len(),
        dt,
        evaluations,
        elapsed: clock.now().saturating_sub(started),
    })
}
