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
//! `dt = 20 s` with 3 samples, 24 particles in 4 groups, at most 100 iterations, a stall
//! stop after 30 without a 1e-4 gain, `D* = 5 km` (dissertation), two threads: why, with
//! the measurements, in `docs/decisions/0004-swarm-size-and-iterations.md`.

#[cfg(doc)]
use crate::problem::Problem;

mod eval;
mod groups;
mod outcome;
mod run;
mod selection;
mod settings;
mod sync;
mod update;
mod workers;
mod workspace;

pub use outcome::{Candidate, PathReport, SwarmOutcome};
pub use run::run;
pub use settings::{MAX_GROUPS, Parameterisation, SwarmError, SwarmSettings, SwarmStatus};
pub use workspace::SwarmWorkspace;
