//! What the swarm returns: [`SwarmOutcome`], its paths' [`PathReport`]s and the other
//! basins' [`Candidate`]s.

use std::time::Duration;

use wingman_interfaces::MAX_PHASES;

use crate::seeding::SeedLabel;
use crate::trajectory::Trajectory;

use super::eval::{Grid, Report};
#[cfg(doc)]
use super::settings::SwarmSettings;
use super::settings::SwarmStatus;

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
    pub(super) fn from_report(r: &Report, g: &Grid) -> Self {
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
