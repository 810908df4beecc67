//! The particles' moves and memories: the velocity and position update (eq. 4.1 with the
//! sign fixed), the reduction of local, group and global bests in particle order, and the
//! stall test.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::eval::Score;
use super::run::Swarm;
use super::settings::{MAX_GROUPS, SwarmSettings};
use super::workers::{Shard, lock};

/// `2^-32`: scales a 32-bit integer to a uniform number in `[0, 1)`.
const TWO_POW_M32: f64 = 1.0 / 4_294_967_296.0;

impl Swarm<'_> {
    /// After the particles' first round: local bests are the particles themselves; group
    /// bests (from their leaders) and the global best (from the best seed) improve with
    /// them.
    pub(super) fn init_bests(&mut self) {
        let (dim, per_group) = (self.dim, self.per_group);
        let mut j = 0;
        for m in self.shards {
            let mut sh = lock(m);
            let sh = &mut *sh;
            for l in 0..sh.count {
                let r = l * dim..(l + 1) * dim;
                let k = j / per_group;
                sh.best[r.clone()].copy_from_slice(&sh.x[r.clone()]);
                sh.best_score[l] = sh.score[l];
                if sh.score[l].better_than(&self.group_score[k]) {
                    self.group_best[k * dim..(k + 1) * dim].copy_from_slice(&sh.x[r.clone()]);
                    self.group_score[k] = sh.score[l];
                }
                if sh.score[l].better_than(&self.gscore) {
                    self.global.copy_from_slice(&sh.x[r]);
                    self.gscore = sh.score[l];
                }
                j += 1;
            }
        }
        self.evaluations += self.settings.particles;
        self.history.push(self.gscore.cost);
    }

    /// Moves every particle (eq. 4.1): `v <- K [v + bL r1 (L - u) + bG r2 (G - u)]`
    /// bounded, `u <- u + v` clamped to the bounds (the velocity zeroed at a wall), with
    /// random numbers drawn particle by particle, coordinate by coordinate. `G` is the
    /// particle's group best, or the global best once `merged`.
    pub(super) fn update(&mut self, rng: &mut ChaCha8Rng, merged: bool) {
        let (grid, dim, per_group) = (self.grid, self.dim, self.per_group);
        let (k, bl, bg) = (
            self.settings.constriction,
            self.settings.local_weight,
            self.settings.global_weight,
        );
        let mut j = 0;
        for m in self.shards {
            let mut sh = lock(m);
            let Shard {
                count, x, v, best, ..
            } = &mut *sh;
            for l in 0..*count {
                let o = l * dim;
                let grp = j / per_group;
                j += 1;
                let attractor: &[f64] = if merged {
                    self.global
                } else {
                    &self.group_best[grp * dim..(grp + 1) * dim]
                };
                for d in 0..dim {
                    let c = d % grid.nu;
                    // Two 32-bit uniforms in [0, 1) from one 64-bit draw.
                    let bits: u64 = rng.random();
                    let r1 = (bits >> 32) as f64 * TWO_POW_M32;
                    let r2 = (bits & 0xffff_ffff) as f64 * TWO_POW_M32;
                    let xi = x[o + d];
                    let mut vi = k
                        * (v[o + d] + bl * r1 * (best[o + d] - xi) + bg * r2 * (attractor[d] - xi));
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
    }

    /// Reduce in particle order: infeasible particles stop for the step; local, group and
    /// global bests take the particles that improve on them.
    pub(super) fn reduce(&mut self) {
        let (dim, per_group) = (self.dim, self.per_group);
        let mut j = 0;
        for m in self.shards {
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
                    if best_score[l].better_than(&self.group_score[grp]) {
                        self.group_best[grp * dim..(grp + 1) * dim]
                            .copy_from_slice(&best[r.clone()]);
                        self.group_score[grp] = best_score[l];
                    }
                    if best_score[l].better_than(&self.gscore) {
                        self.global.copy_from_slice(&best[r]);
                        self.gscore = best_score[l];
                    }
                }
            }
        }
    }
}

/// The stall test: the scores of the last gain, and when it was.
pub(super) struct Stall {
    reference: Score,
    group_reference: [Score; MAX_GROUPS],
    last_gain: usize,
}

impl Stall {
    /// From the scores after the particles' first round.
    pub(super) fn new(gscore: Score, group_score: &[Score]) -> Self {
        let mut group_reference = [Score::default(); MAX_GROUPS];
        group_reference[..group_score.len()].copy_from_slice(group_score);
        Stall {
            reference: gscore,
            group_reference,
            last_gain: 0,
        }
    }

    /// True when `stall_iterations` iterations have passed without a gain. A gain: the
    /// global best improved, or (before the merge) any group's best, by more than
    /// `stall_tolerance` relative (or became feasible).
    pub(super) fn stalled(
        &mut self,
        gscore: &Score,
        group_score: &[Score],
        merged: bool,
        iterations: usize,
        settings: &SwarmSettings,
    ) -> bool {
        let tol = settings.stall_tolerance;
        let better = |now: &Score, was: &Score| {
            (now.feasible && !was.feasible) || now.cost < was.cost - tol * was.cost.abs().max(1e-12)
        };
        let mut gain = better(gscore, &self.reference);
        if gain {
            self.reference = *gscore;
        }
        if !merged {
            let group_reference = &mut self.group_reference[..group_score.len()];
            for (now, was) in group_score.iter().zip(group_reference.iter_mut()) {
                if better(now, was) {
                    gain = true;
                    *was = *now;
                }
            }
        }
        if gain {
            self.last_gain = iterations;
            false
        } else {
            iterations - self.last_gain >= settings.stall_iterations
        }
    }
}
