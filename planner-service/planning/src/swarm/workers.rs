//! The worker threads: the particles split into contiguous [`Shard`]s, one per thread, and
//! [`Workers`], the persistent scoped threads that evaluate them (or the seeds) round by
//! round between two waits at a spinning barrier.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

use crate::clock::Deadline;
use crate::cuts::Work;
use crate::seeding::Seed;

use super::eval::{self, Grid, Score, Scratch};
use super::sync::{AbortOnUnwind, SpinBarrier};

/// Jobs of the worker threads.
pub(super) const JOB_STOP: usize = 0;
pub(super) const JOB_SEEDS: usize = 1;
pub(super) const JOB_PARTICLES: usize = 2;

/// A contiguous group of particles evaluated by one thread.
#[derive(Debug)]
pub(super) struct Shard {
    pub(super) count: usize,
    pub(super) x: Vec<f64>,
    pub(super) v: Vec<f64>,
    pub(super) best: Vec<f64>,
    pub(super) score: Vec<Score>,
    pub(super) best_score: Vec<Score>,
    pub(super) scratch: Scratch,
    /// A seed's particle while the seeds are evaluated.
    pub(super) seed_u: Vec<f64>,
    /// `(seed, score)` of the seeds this shard evaluated.
    pub(super) seed_scores: Vec<(usize, Score)>,
}

impl Shard {
    pub(super) fn new(count: usize, dim: usize, samples: usize, seeds: usize) -> Self {
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
        let deadline = deadline.at(Work::SeedScores(first as u8));
        for i in (first..seeds.len()).step_by(stride) {
            let scored = self.seed_scores.len() as u32;
            if scored > 0 && deadline.cuts(scored, Deadline::expired) {
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

pub(super) fn lock(m: &Mutex<Shard>) -> MutexGuard<'_, Shard> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The worker threads' shared view of a run: shard `t` evaluates its particles, or the
/// seeds `t, t + threads, ...`; the calling thread does shard 0.
#[derive(Clone, Copy)]
pub(super) struct Workers<'a> {
    pub(super) barrier: &'a SpinBarrier,
    pub(super) job: &'a AtomicUsize,
    pub(super) shards: &'a [Mutex<Shard>],
    pub(super) grid: &'a Grid,
    pub(super) seeds: &'a [Seed],
    pub(super) lookahead: f64,
    /// Coordinates per particle.
    pub(super) dim: usize,
    pub(super) threads: usize,
    pub(super) deadline: Deadline<'a>,
}

impl<'a> Workers<'a> {
    /// Starts a thread for every shard but the first, in `scope`.
    pub(super) fn spawn(&self, scope: &crossbeam::thread::Scope<'a>) {
        for (t, shard) in self.shards.iter().enumerate().skip(1) {
            let w = *self;
            scope.spawn(move |_| w.work(t, shard));
        }
    }

    /// A worker's loop: waits for a job, does it on `shard`, waits for the others, until
    /// [`JOB_STOP`] or an aborted barrier.
    fn work(&self, t: usize, shard: &Mutex<Shard>) {
        let _guard = AbortOnUnwind(self.barrier);
        loop {
            if !self.barrier.wait() {
                break;
            }
            match self.job.load(Ordering::Acquire) {
                JOB_SEEDS => lock(shard).evaluate_seeds(
                    self.grid,
                    self.seeds,
                    self.lookahead,
                    (t, self.threads),
                    &self.deadline,
                ),
                JOB_PARTICLES => lock(shard).evaluate(self.grid, self.dim),
                _ => break,
            }
            if !self.barrier.wait() {
                break;
            }
        }
    }

    /// One round of `what` on every shard (the calling thread does shard 0); false when
    /// a worker died.
    pub(super) fn run_job(&self, what: usize) -> bool {
        let threads = self.threads;
        self.job.store(what, Ordering::Release);
        if threads > 1 && !self.barrier.wait() {
            return false;
        }
        {
            let mut sh = lock(&self.shards[0]);
            if what == JOB_SEEDS {
                sh.evaluate_seeds(
                    self.grid,
                    self.seeds,
                    self.lookahead,
                    (0, threads),
                    &self.deadline,
                );
            } else {
                sh.evaluate(self.grid, self.dim);
            }
        }
        threads == 1 || self.barrier.wait()
    }

    /// Ends the workers' loops.
    pub(super) fn stop(&self) {
        self.job.store(JOB_STOP, Ordering::Release);
        if self.threads > 1 {
            self.barrier.wait();
        }
    }
}
