//! The particle groups (niches): each led by a seed far from the other leaders, joined by
//! the seeds nearest to its leader, filled up with perturbed copies of the leader.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::seeding::Seed;

use super::eval;
use super::run::Swarm;
use super::settings::MAX_GROUPS;

/// Points of a seed's sketch (leader diversity).
pub(super) const SKETCH: usize = 24;

/// Appends `seed`'s path at [`SKETCH`] evenly spaced arc fractions to `sketches`.
pub(super) fn push_sketch(sketches: &mut Vec<[f64; 3]>, seed: &Seed) {
    let total = seed.arc_lengths().last().copied().unwrap_or(0.0);
    for k in 0..SKETCH {
        sketches.push(seed.point_at_arc(total * (k as f64 + 0.5) / SKETCH as f64));
    }
}

/// Mean distance between the paths of seeds `a` and `b` at equal arc fractions.
fn distance(sketches: &[[f64; 3]], a: usize, b: usize) -> f64 {
    let pa = &sketches[a * SKETCH..(a + 1) * SKETCH];
    let pb = &sketches[b * SKETCH..(b + 1) * SKETCH];
    pa.iter()
        .zip(pb)
        .map(|(p, q)| {
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        })
        .sum::<f64>()
        / SKETCH as f64
}

impl Swarm<'_> {
    /// Groups: the best seed leads the first; each next leader is the seed farthest from
    /// the leaders so far (mean distance between the paths at equal arc fractions) among
    /// the better half of the seeds, so that the groups refine different basins. Every
    /// other seed, best first, joins the group of its nearest leader while it has room;
    /// the rest of a group are perturbed copies of its leader. One group: the best seeds
    /// in order.
    pub(super) fn form_groups(&mut self) {
        self.pick_leaders();
        self.assign_members();
        self.start_group_bests();
    }

    /// The leaders, best seed first, each next one the farthest from those so far.
    fn pick_leaders(&mut self) {
        let (sketches, order, leaders) = (&*self.sketches, &*self.order, &mut *self.leaders);
        let groups = self.groups;
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
                    .map(|&l| distance(sketches, i, l))
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
    }

    /// Each particle's seed: its group's leader first, then the nearest seeds while the
    /// group has room (`usize::MAX` for the rest: perturbed copies of the leader).
    fn assign_members(&mut self) {
        let (sketches, order, leaders) = (&*self.sketches, &*self.order, &*self.leaders);
        let (groups, per_group, particles) = (self.groups, self.per_group, self.settings.particles);
        let member_seed = &mut *self.member_seed;
        let n_leaders = leaders.len();
        member_seed[..particles].fill(usize::MAX);
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
                    .min_by(|&a, &b| {
                        distance(sketches, i, leaders[a])
                            .total_cmp(&distance(sketches, i, leaders[b]))
                    })
                    .unwrap_or(0)
            };
            let room = per_group.min(particles - k * per_group);
            if filled[k] < room {
                member_seed[k * per_group + filled[k]] = i;
                filled[k] += 1;
            }
        }
    }

    /// Each group's best starts as its leader (groups without a leader: the first's).
    fn start_group_bests(&mut self) {
        let dim = self.dim;
        let n_leaders = self.leaders.len();
        for (k, &leader) in self.leaders.iter().enumerate() {
            eval::track(
                self.grid,
                &self.seeds[leader],
                self.settings.lookahead,
                &mut self.group_best[k * dim..(k + 1) * dim],
            );
            self.group_score[k] = self.seed_scores[leader];
        }
        for k in n_leaders..self.groups {
            self.group_best.copy_within(0..dim, k * dim);
            self.group_score[k] = self.group_score[0];
        }
    }

    /// The particles: each tracks its seed (copies: its group's leader, perturbed with
    /// random numbers drawn particle by particle, coordinate by coordinate); velocities
    /// zero.
    pub(super) fn init_particles(&mut self, rng: &mut ChaCha8Rng) {
        let (grid, dim, per_group) = (self.grid, self.dim, self.per_group);
        let settings = self.settings;
        let n_leaders = self.leaders.len();
        let mut j = 0;
        for m in self.shards {
            let mut sh = super::workers::lock(m);
            let sh = &mut *sh;
            for l in 0..sh.count {
                let x = &mut sh.x[l * dim..(l + 1) * dim];
                let k = j / per_group;
                let seed = self.member_seed[j];
                let copy = seed == usize::MAX;
                let source = if copy {
                    self.leaders[k.min(n_leaders - 1)]
                } else {
                    seed
                };
                eval::track(grid, &self.seeds[source], settings.lookahead, x);
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
    }
}
