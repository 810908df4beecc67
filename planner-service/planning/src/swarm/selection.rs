//! The swarm's result: the groups' bests ranked as starts for the NLP ([`basin_rank`]), the
//! returned path and the candidates of other basins.

use wingman_interfaces::Objective;

use crate::trajectory::Trajectory;

use super::eval::{self, Grid, OutBuffers, Report};
use super::outcome::{Candidate, PathReport};
use super::run::Swarm;
use super::settings::{MAX_GROUPS, SwarmError};
use super::workers::lock;

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

impl Swarm<'_> {
    /// The groups' bests (the global best among them) in the order of [`basin_rank`]
    /// into `order`; none with one group or when no iteration ran. Returns how many.
    fn rank_groups(&self, order: &mut [usize; MAX_GROUPS]) -> usize {
        let (grid, dim, groups) = (self.grid, self.dim, self.groups);
        if !(groups > 1 && self.iterations > 0) {
            return 0;
        }
        let mut keys = [(false, 0.0f64, 0.0f64); MAX_GROUPS];
        let mut sh = lock(&self.shards[0]);
        for k in 0..groups {
            let rep = eval::evaluate(
                grid,
                &self.group_best[k * dim..(k + 1) * dim],
                &mut sh.scratch,
            );
            let (near, rank) = basin_rank(grid, &rep);
            keys[k] = (near, rank, rep.score.cost);
            order[k] = k;
        }
        order[..groups].sort_by(|&a, &b| {
            let (ka, kb) = (keys[a], keys[b]);
            kb.0.cmp(&ka.0)
                .then(ka.1.total_cmp(&kb.1))
                .then(ka.2.total_cmp(&kb.2))
                .then(a.cmp(&b))
        });
        groups
    }

    /// The returned path and the candidates: the groups' bests (the global best among
    /// them) ranked by [`basin_rank`]; with no iteration done, the best seed. Returns the
    /// path's report, trajectory (lifted into `best`, then cloned) and cost, and the
    /// candidates.
    #[allow(clippy::type_complexity)]
    pub(super) fn select(
        &self,
        out: &mut OutBuffers,
        best: &mut Trajectory,
    ) -> Result<(PathReport, Trajectory, f64, Vec<Candidate>), SwarmError> {
        let (grid, dim) = (self.grid, self.dim);
        let mut order_buf = [0usize; MAX_GROUPS];
        let n_ranked = self.rank_groups(&mut order_buf);
        let ranked = &order_buf[..n_ranked];
        let chosen: &[f64] = match ranked.first() {
            Some(&k) => &self.group_best[k * dim..(k + 1) * dim],
            None => self.global,
        };
        let (report, traj, cost) = {
            let mut sh = lock(&self.shards[0]);
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
        let mut candidates = Vec::with_capacity(self.settings.candidates);
        for (i, &k) in ranked.iter().enumerate().skip(1) {
            if candidates.len() == self.settings.candidates {
                break;
            }
            let gb = &self.group_best[k * dim..(k + 1) * dim];
            // The same path as one ranked before it (two groups in one basin): skip it.
            if ranked[..i]
                .iter()
                .any(|&q| &self.group_best[q * dim..(q + 1) * dim] == gb)
            {
                continue;
            }
            let mut sh = lock(&self.shards[0]);
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
        Ok((report, traj, cost, candidates))
    }
}
