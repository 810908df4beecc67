//! The price of a particle ([`evaluate`]): fly it, find its passes, integrate exposure and
//! control effort up to the final time, add the penalties.

use wingman_interfaces::{MAX_PHASES, Objective};

use crate::dynamics::wrap_angle;

use super::Scratch;
use super::flight::Flyer;
use super::grid::{End, Grid};
use super::passes::{Pass, Passes};

/// A particle's swarm cost; infeasible (a pass beyond `D*`) ranks after every feasible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Score {
    pub cost: f64,
    pub feasible: bool,
}

impl Default for Score {
    fn default() -> Self {
        Score {
            cost: f64::INFINITY,
            feasible: false,
        }
    }
}

impl Score {
    /// Strictly better: feasible first, then lower cost (NaN never better).
    #[inline]
    pub(crate) fn better_than(&self, other: &Score) -> bool {
        match (self.feasible, other.feasible) {
            (true, false) => !self.cost.is_nan(),
            (false, true) => false,
            _ => self.cost < other.cost || (other.cost.is_nan() && !self.cost.is_nan()),
        }
    }
}

/// Everything [`evaluate`] found about one path.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Report {
    pub score: Score,
    pub passes: [Pass; MAX_PHASES],
    pub n_passes: usize,
    pub tf: f64,
    pub objective: f64,
    pub exposure: f64,
    pub effort: f64,
    pub penalty: f64,
    pub heading_error: f64,
    pub gamma_error: f64,
    pub floor_violation: f64,
    /// Samples flown after the first (the horizon may be cut short at the final pass).
    pub flown: usize,
}

/// Flies and prices the particle `u`: the cost of FORMULATION.md §4 up to the final pass
/// plus the swarm's penalties (eqs. 4.5–4.8 in additive form, see the `swarm` module).
pub(crate) fn evaluate(g: &Grid, u: &[f64], sc: &mut Scratch) -> Report {
    let mut fly = Flyer::start(g, sc);
    let mut tr = Passes::new();
    let mut fed = 0;
    let mut done = false;
    'steps: for k in 0..g.steps {
        fly.step(g, u, k, sc);
        while fed < fly.j {
            fed += 1;
            if tr.feed(g, &sc.pos, fed - 1) {
                done = true;
                break 'steps;
            }
        }
    }
    if !done {
        tr.finish(g, &sc.pos, fed);
    }
    let flown = fly.j;
    let mut rep = Report {
        n_passes: g.n_targets + 1,
        flown,
        ..Report::default()
    };
    let mut feasible = true;
    let mut penalty = 0.0;
    for i in 0..rep.n_passes {
        rep.passes[i] = tr.passes[i];
        feasible &= tr.ok[i];
        penalty += g.w_dist * tr.passes[i].dist;
    }
    let fin = rep.passes[g.n_targets];
    let (kf, f) = (fin.seg, fin.frac);
    let tf = fin.time(g);
    // Exposure (trapezoid on the samples) and control effort up to tf.
    let last = (kf + 1).min(flown);
    let mut zlow = f64::INFINITY;
    for j in 0..=last {
        sc.expo[j] = g.exposure(j, &sc.pos[j]);
        zlow = zlow.min(sc.pos[j][2]);
    }
    let mut e_int = 0.0;
    for j in 0..kf {
        e_int += sc.expo[j] + sc.expo[j + 1];
    }
    e_int *= 0.5 * g.h;
    let e_f = sc.expo[kf] + f * (sc.expo[last] - sc.expo[kf]);
    e_int += 0.5 * f * g.h * (sc.expo[kf] + e_f);
    let effort = sc.effort[kf] + f * (sc.effort[last] - sc.effort[kf]);
    let j_run = g.beta * e_int + (1.0 - g.beta) * effort;
    let objective = match g.objective {
        Objective::FixedTime => j_run,
        _ => g.alpha * tf + (1.0 - g.alpha) * j_run,
    };
    // Final heading (and flight-path angle) against the end's or the lead's.
    let head_f = sc.head[kf] + f * (sc.head[last] - sc.head[kf]);
    let gam_f = sc.gam[kf] + f * (sc.gam[last] - sc.gam[kf]);
    let (want_head, want_gam) = match (g.end, &g.lead) {
        (End::Point { heading, gamma, .. }, _) => (heading, gamma),
        (End::Lead, Some(lead)) => {
            let lp = lead.at(tf);
            (lp.heading, if g.spatial { lp.gamma } else { 0.0 })
        }
        (End::Lead, None) => (head_f, gam_f),
    };
    let he = wrap_angle(head_f - want_head);
    let ge = gam_f - want_gam;
    penalty += g.w_head * ((1.0 - he.cos()) + (1.0 - ge.cos()));
    if g.objective == Objective::FixedTime {
        penalty += g.w_time * (tf - g.fixed_time).abs();
    }
    let floor = if g.spatial {
        (g.z_min - zlow).max(0.0)
    } else {
        0.0
    };
    penalty += g.w_dist * floor;
    let cost = objective + penalty;
    rep.score = Score {
        cost: if cost.is_nan() { f64::INFINITY } else { cost },
        feasible: feasible && cost.is_finite(),
    };
    rep.tf = tf;
    rep.objective = objective;
    rep.exposure = e_int;
    rep.effort = effort;
    rep.penalty = penalty;
    rep.heading_error = he;
    rep.gamma_error = ge;
    rep.floor_violation = floor;
    rep
}
