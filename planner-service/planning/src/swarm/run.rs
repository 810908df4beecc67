//! [`run`]: the swarm's steps in order — build the seeds, size the grid, score and rank the
//! seeds, form the groups, start the particles, iterate, choose the result — with the
//! state they share ([`Swarm`]).

use std::sync::Mutex;
use std::sync::atomic::AtomicUsize;
use std::time::Duration;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use wingman_interfaces::Objective;

use crate::clock::Deadline;
use crate::cuts::Work;
use crate::problem::Problem;
use crate::seeding::{self, Seed};

use super::eval::{self, Grid, GridParams, Score};
use super::groups::push_sketch;
use super::outcome::SwarmOutcome;
use super::settings::{Parameterisation, SwarmError, SwarmSettings, SwarmStatus};
use super::sync::{AbortOnUnwind, SpinBarrier};
use super::update::Stall;
use super::workers::{JOB_PARTICLES, JOB_SEEDS, JOB_STOP, Shard, Workers, lock};
use super::workspace::SwarmWorkspace;

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
    let seeds_deadline = deadline.at(Work::Seeds);
    seeding::seeds_until(problem, &settings.seeds, &mut ws.seeds, &|tried| {
        seeds_deadline.cuts(tried, Deadline::expired)
    })?;
    let dt = prepare_grid(problem, settings, &ws.seeds, &mut ws.grid)?;
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
    let groups = settings.groups;
    history.clear();
    seed_scores.clear();
    seed_scores.resize(seeds.len(), Score::default());
    sketches.clear();
    order.clear();
    let mut sw = Swarm {
        settings,
        grid,
        shards,
        seeds,
        deadline,
        dim,
        groups,
        per_group: settings.particles.div_ceil(groups),
        global: &mut global[..dim],
        group_best: &mut group_best[..groups * dim],
        group_score: &mut group_score[..groups],
        seed_scores,
        sketches,
        member_seed,
        leaders,
        order,
        history,
        status: SwarmStatus::MaxIterations,
        iterations: 0,
        evaluations: 0,
        gscore: Score::default(),
        seeds_best: 0,
    };

    let threads = sw.shards.len();
    let barrier = SpinBarrier::new(threads);
    let job = AtomicUsize::new(JOB_STOP);
    let workers = Workers {
        barrier: &barrier,
        job: &job,
        shards: sw.shards,
        grid: sw.grid,
        seeds: sw.seeds,
        lookahead: settings.lookahead,
        dim,
        threads,
        deadline,
    };
    let result = crossbeam::scope(|scope| {
        workers.spawn(scope);
        let _guard = AbortOnUnwind(&barrier);
        sw.fly_rounds(&workers)
    });
    match result {
        Ok(true) => {}
        Ok(false) | Err(_) => {
            tracing::error!("swarm: a worker thread died");
            return Err(SwarmError::Internal("a worker thread died".into()));
        }
    }
    let seeds_best_cost = sw.seed_scores[sw.seeds_best].cost;
    let seeds_best_label = *sw.seeds[sw.seeds_best].label();
    let (report, traj, cost, candidates) = sw.select(out, best)?;
    Ok(SwarmOutcome {
        status: sw.status,
        iterations: sw.iterations,
        cost,
        best: traj,
        report,
        candidates,
        seeds_best_cost,
        seeds_best: seeds_best_label,
        seeds: sw.seeds.len(),
        dt,
        evaluations: sw.evaluations,
        elapsed: clock.now().saturating_sub(started),
    })
}

/// Horizon and grid: long enough for every seed within 1.5 times the shortest seed's
/// duration (and for a fixed final time), plus the margin. Longer seeds may not reach
/// the end inside it and rank last; sizing by the longest seed would waste most
/// coordinates of every particle on paths no min-time optimum flies. Returns the control
/// step `dt`.
fn prepare_grid(
    problem: &Problem,
    settings: &SwarmSettings,
    seeds: &[Seed],
    grid: &mut Grid,
) -> Result<f64, SwarmError> {
    let speed = problem.limits.speed;
    let shortest = seeds
        .iter()
        .map(|s| s.length() / speed)
        .fold(f64::INFINITY, f64::min);
    let mut horizon = seeds
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
    grid.prepare(
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
    Ok(dt)
}

/// One run's state on the calling thread: the workspace's buffers cut to this run's sizes,
/// the global best and the counters. Every reduction runs here, in particle order.
pub(super) struct Swarm<'a> {
    pub(super) settings: &'a SwarmSettings,
    pub(super) grid: &'a Grid,
    pub(super) shards: &'a [Mutex<Shard>],
    pub(super) seeds: &'a [Seed],
    pub(super) deadline: Deadline<'a>,
    /// Coordinates per particle.
    pub(super) dim: usize,
    pub(super) groups: usize,
    /// Particles per group (the last group may have fewer).
    pub(super) per_group: usize,
    pub(super) global: &'a mut [f64],
    pub(super) group_best: &'a mut [f64],
    pub(super) group_score: &'a mut [Score],
    pub(super) seed_scores: &'a mut Vec<Score>,
    pub(super) sketches: &'a mut Vec<[f64; 3]>,
    pub(super) member_seed: &'a mut Vec<usize>,
    pub(super) leaders: &'a mut Vec<usize>,
    pub(super) order: &'a mut Vec<usize>,
    pub(super) history: &'a mut Vec<f64>,
    pub(super) status: SwarmStatus,
    pub(super) iterations: usize,
    pub(super) evaluations: usize,
    /// The global best's score.
    pub(super) gscore: Score,
    /// Index of the best seed.
    pub(super) seeds_best: usize,
}

impl Swarm<'_> {
    /// Every round on the worker threads, from the seeds to the last iteration; stops the
    /// workers. False when a worker died.
    fn fly_rounds(&mut self, workers: &Workers<'_>) -> bool {
        let Some(round) = self.score_seeds(workers) else {
            return false;
        };
        self.rank_seeds();
        // No time for the particles' first round: the best seed.
        let rounds = self.deadline.at(Work::SwarmRounds);
        if rounds.cuts(0, |d| d.remaining() <= round) {
            self.status = SwarmStatus::MaxTime;
            workers.stop();
            return true;
        }
        self.form_groups();
        // Particles.
        let mut rng = ChaCha8Rng::seed_from_u64(self.settings.seed);
        self.init_particles(&mut rng);
        let clock = self.deadline.clock();
        let first_round = clock.now();
        let alive = workers.run_job(JOB_PARTICLES);
        let round = clock.now().saturating_sub(first_round);
        self.init_bests();
        let alive = self.iterate(workers, &mut rng, round, alive);
        workers.stop();
        alive
    }

    /// Seeds: fly each and price it (on every thread). `None` when a worker died, else the
    /// estimate of the particles' first round.
    fn score_seeds(&mut self, workers: &Workers<'_>) -> Option<Duration> {
        let clock = self.deadline.clock();
        let seeds_started = clock.now();
        if !workers.run_job(JOB_SEEDS) {
            return None;
        }
        let mut scored = 0;
        for m in self.shards {
            let sh = lock(m);
            scored += sh.seed_scores.len();
            for &(i, s) in &sh.seed_scores {
                self.seed_scores[i] = s;
            }
        }
        // A round of the particles takes about as long as scoring as many seeds (tracking
        // the seeds onto the particles first takes less): the estimate of the first round,
        // until one is measured.
        Some(
            clock
                .now()
                .saturating_sub(seeds_started)
                .mul_f64(self.settings.particles as f64 / scored.max(1) as f64),
        )
    }

    /// Ranks the seeds (and sketches their paths for the groups); the best one is the
    /// first global best.
    fn rank_seeds(&mut self) {
        for (i, seed) in self.seeds.iter().enumerate() {
            self.order.push(i);
            push_sketch(self.sketches, seed);
        }
        self.evaluations = self.seeds.len();
        let seed_scores = &*self.seed_scores;
        self.order.sort_unstable_by(|&a, &b| {
            let (sa, sb) = (&seed_scores[a], &seed_scores[b]);
            if sa.better_than(sb) {
                std::cmp::Ordering::Less
            } else if sb.better_than(sa) {
                std::cmp::Ordering::Greater
            } else {
                a.cmp(&b)
            }
        });
        self.seeds_best = self.order[0];
        eval::track(
            self.grid,
            &self.seeds[self.seeds_best],
            self.settings.lookahead,
            self.global,
        );
        self.gscore = self.seed_scores[self.seeds_best];
        self.history.push(self.gscore.cost);
    }

    /// The iterations until `max_iterations`, the deadline or a stall; false when a worker
    /// died. `round` is the first round's duration.
    fn iterate(
        &mut self,
        workers: &Workers<'_>,
        rng: &mut ChaCha8Rng,
        mut round: Duration,
        mut alive: bool,
    ) -> bool {
        let settings = self.settings;
        let mut stall = Stall::new(self.gscore, self.group_score);
        let mut last_left: Option<Duration> = None;
        let rounds = self.deadline.at(Work::SwarmRounds);
        while alive {
            if self.iterations >= settings.max_iterations {
                self.status = SwarmStatus::MaxIterations;
                break;
            }
            // Stop while the next iteration still fits: as long as the longest so far, each
            // measured from one of these checks to the next.
            let left = self.deadline.remaining();
            if let Some(before) = last_left {
                round = round.max(before.saturating_sub(left));
            }
            // Step 0 is before the particles' first round (above), k + 1 after k rounds.
            if rounds.cuts(self.iterations as u32 + 1, |_| left <= round) {
                self.status = SwarmStatus::MaxTime;
                break;
            }
            last_left = Some(left);
            self.iterations += 1;
            // Update (eq. 4.1), random numbers in particle order; the attractor `G` is the
            // particle's group best until the merge, then the global best.
            let merged = self.groups == 1
                || self.iterations as f64
                    > settings.merge_fraction * settings.max_iterations as f64;
            self.update(rng, merged);
            alive = workers.run_job(JOB_PARTICLES);
            self.reduce();
            self.evaluations += settings.particles;
            self.history.push(self.gscore.cost);
            if stall.stalled(
                &self.gscore,
                self.group_score,
                merged,
                self.iterations,
                settings,
            ) {
                self.status = SwarmStatus::Converged;
                break;
            }
        }
        alive
    }
}
