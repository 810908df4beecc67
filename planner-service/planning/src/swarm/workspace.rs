//! [`SwarmWorkspace`]: every buffer of the swarm, allocated once and reused by every run.

use std::sync::Mutex;

use wingman_interfaces::MAX_PHASES;

use crate::seeding::{Seed, SeedLabel};
use crate::trajectory::Trajectory;

use super::eval::{self, Grid, OutBuffers, Score};
use super::groups::SKETCH;
use super::outcome::PathReport;
use super::settings::SwarmSettings;
use super::workers::{Shard, lock};

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
    pub(super) grid: Grid,
    pub(super) shards: Vec<Mutex<Shard>>,
    pub(super) global: Vec<f64>,
    /// Best position of each group (`groups * dim`) and its score.
    pub(super) group_best: Vec<f64>,
    pub(super) group_score: Vec<Score>,
    pub(super) seeds: Vec<Seed>,
    pub(super) seed_scores: Vec<Score>,
    /// Each seed's path at [`SKETCH`] evenly spaced arc fractions (leader diversity).
    pub(super) sketches: Vec<[f64; 3]>,
    /// Seed of each particle (`usize::MAX`: a perturbed copy of its group's leader) and
    /// each group's leader.
    pub(super) member_seed: Vec<usize>,
    pub(super) leaders: Vec<usize>,
    pub(super) order: Vec<usize>,
    pub(super) seed_u: Vec<f64>,
    pub(super) history: Vec<f64>,
    pub(super) out: OutBuffers,
    pub(super) best: Trajectory,
    /// The last run's seed-tracking look-ahead (for [`SwarmWorkspace::seed_trajectory`]).
    pub(super) lookahead: f64,
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

    pub(super) fn reserve(&mut self, settings: &SwarmSettings) {
        if !self.cap.holds(&Capacity::of(settings)) {
            *self = SwarmWorkspace::new(settings);
        }
    }
}

fn trajectory_with_capacity(n: usize) -> Trajectory {
    Trajectory {
        times: Vec::with_capacity(n),
        states: Vec::with_capacity(n),
        controls: Vec::with_capacity(n),
        phase_ends: Vec::with_capacity(MAX_PHASES),
    }
}
