//! Warm start on a new mesh: the multipliers of a solution on one mesh carried to another
//! (a finer uniform mesh, or a refined one), so that the solve there starts primal-dual
//! and re-converges in a few iterations instead of re-learning its multipliers from zero.
//! The same carries a plan's multipliers into a re-plan of what is left of its mission
//! ([`transfer_in_time`]): the costates are those of the rest of the mission (Bellman), so
//! they are taken at the same mission time instead of the same phase fraction.
//!
//! On an LGR mesh the multiplier of a node's defect is the costate at the node times the
//! node's quadrature weight `w_i` (on `[-1, 1]`): with the defect `D X - half · Δ · f` and the
//! running cost `quad · Δ · L`, `quad = w_i · half`, stationarity in the node's control reads
//! `w_i · L_u = λ_i · f_u`. So `λ_i / w_i` is a smooth function of time (the costate) and is
//! what is interpolated, linearly in the phase fraction between the old mesh's collocation
//! nodes; a new node's multiplier is that density times its own weight. Bound multipliers
//! of node variables scale the same way. Phase-time variables, phase-order rows and
//! rendezvous rows do not depend on the mesh and are copied. Scaling is undone and redone:
//! a scaled multiplier is the physical one times `obj_scale / cscale` (constraints) or
//! `obj_scale · scale` (bounds).

use super::solve::PrimalDual;
use super::transcription::{INF, Transcription};

/// Where a phase fraction `s` falls among the old mesh's collocation nodes of phase `p`:
/// the two nodes around it and the weight of the second (0 at the first, 1 at the second).
fn bracket(from: &Transcription, p: usize, s: f64) -> (usize, usize, f64) {
    let start = from.layout.phase_start[p];
    let end = from.layout.phase_start[p + 1];
    let nodes = &from.layout.nodes[start..end];
    // Nodes of a phase are in increasing `s`.
    let after = nodes.partition_point(|n| n.s <= s);
    if after == 0 {
        return (start, start, 0.0);
    }
    if after == nodes.len() {
        return (end - 1, end - 1, 0.0);
    }
    let (a, b) = (&nodes[after - 1], &nodes[after]);
    let f = ((s - a.s) / (b.s - a.s).max(1e-300)).clamp(0.0, 1.0);
    (start + after - 1, start + after, f)
}

/// The LGR weight (on `[-1, 1]`) of collocation node `k`.
fn weight(tr: &Transcription, k: usize) -> f64 {
    tr.layout.lgr.weights[tr.layout.nodes[k].local]
}

/// The multipliers for a warm start of `to` (whose `obj_scale` is already set) from the
/// solution `duals` of `from`, written into `out` (`out.x` is left alone). `false` when
/// the two transcriptions are not of the same problem shape (then `out` is unspecified).
pub fn transfer(
    from: &Transcription,
    duals: &PrimalDual,
    to: &Transcription,
    out: &mut PrimalDual,
) -> bool {
    transfer_mapped(from, duals, to, out, |_, s| s)
}

/// The multipliers for a warm start of `to`, a re-plan from a later start, from the
/// solution `duals` of the plan `from` it continues, with the same phases: a node of `to`
/// takes `from`'s multiplier densities at its mission time (by the phase times of `to`'s
/// starting point `out.x` and of `from`'s solution), clamped to `from`'s phase. As
/// [`transfer`] otherwise; `false` also when the phase counts differ (a target passed).
pub fn transfer_in_time(
    from: &Transcription,
    duals: &PrimalDual,
    to: &Transcription,
    out: &mut PrimalDual,
) -> bool {
    let phases = to.layout.phases();
    if from.layout.phases() != phases
        || out.x.len() != to.n_vars()
        || duals.x.len() != from.n_vars()
    {
        return false;
    }
    let times = |tr: &Transcription, x: &[f64]| -> Vec<(f64, f64)> {
        let end = |p: usize| x[tr.time(p)] * tr.scale[tr.time(p)];
        (0..phases)
            .map(|p| (if p == 0 { tr.problem.t0 } else { end(p - 1) }, end(p)))
            .collect()
    };
    let (old, new) = (times(from, &duals.x), times(to, &out.x));
    let to_old = |p: usize, s: f64| {
        let t = new[p].0 + s * (new[p].1 - new[p].0);
        ((t - old[p].0) / (old[p].1 - old[p].0).max(1e-9)).clamp(0.0, 1.0)
    };
    transfer_mapped(from, duals, to, out, to_old)
}

/// [`transfer`] with `to`'s node at phase fraction `s` of phase `p` taking `from`'s
/// densities at phase fraction `map(p, s)` of the same phase.
fn transfer_mapped(
    from: &Transcription,
    duals: &PrimalDual,
    to: &Transcription,
    out: &mut PrimalDual,
    map: impl Fn(usize, f64) -> f64,
) -> bool {
    let (nx, nu) = (from.nx, from.nu);
    let (n_from, n_to) = (from.n_vars(), to.n_vars());
    let (m_from, m_to) = (from.n_cons(), to.n_cons());
    let (k_from, k_to) = (from.layout.control_nodes(), to.layout.control_nodes());
    let fixed_rows = m_from - k_from * nx;
    if to.nx != nx
        || to.nu != nu
        || to.layout.phases() != from.layout.phases()
        || m_to - k_to * nx != fixed_rows
        || duals.lambda.len() != m_from
        || duals.z_l.len() != n_from
        || duals.z_u.len() != n_from
        || k_from == 0
    {
        return false;
    }
    let obj_ratio = to.obj_scale / from.obj_scale;
    out.lambda.clear();
    out.lambda.resize(m_to, 0.0);
    out.z_l.clear();
    out.z_l.resize(n_to, 0.0);
    out.z_u.clear();
    out.z_u.resize(n_to, 0.0);

    // A multiplier density of the old mesh at node `k`: `value · unscale / w_k`.
    let lambda_density = |k: usize, c: usize| -> f64 {
        let r = k * nx + c;
        duals.lambda[r] * from.cscale[r] / weight(from, k)
    };
    let bound_density = |z: &[f64], i: usize, k: usize| -> f64 {
        // A fixed variable's multiplier is its reduced gradient, not a bound's: none.
        if from.x_lo[i] >= from.x_hi[i] {
            return 0.0;
        }
        z[i] / from.scale[i] / weight(from, k)
    };

    // Defect rows and control bounds at the new collocation nodes.
    for k in 0..k_to {
        let node = to.layout.nodes[k];
        let (a, b, f) = bracket(from, node.phase, map(node.phase, node.s));
        let w = weight(to, k);
        for c in 0..nx {
            let d = (1.0 - f) * lambda_density(a, c) + f * lambda_density(b, c);
            let r = k * nx + c;
            out.lambda[r] = d * w * obj_ratio / to.cscale[r];
        }
        for e in 0..nu {
            let (ia, ib, i) = (from.control(a, e), from.control(b, e), to.control(k, e));
            for (z_from, z_to) in [(&duals.z_l, &mut out.z_l), (&duals.z_u, &mut out.z_u)] {
                let d = (1.0 - f) * bound_density(z_from, ia, a) + f * bound_density(z_from, ib, b);
                z_to[i] = d * w * obj_ratio * to.scale[i];
            }
        }
    }
    // State bounds at every new state node (the final node takes the old final node's).
    let (last_from, last_to) = (from.layout.state_nodes() - 1, to.layout.state_nodes() - 1);
    for k in 0..=last_to {
        for c in 0..nx {
            let i = to.state(k, c);
            for (z_from, z_to) in [(&duals.z_l, &mut out.z_l), (&duals.z_u, &mut out.z_u)] {
                z_to[i] = if k == last_to {
                    let j = from.state(last_from, c);
                    let free = from.x_lo[j] < from.x_hi[j];
                    f64::from(u8::from(free)) * z_from[j] / from.scale[j] * obj_ratio * to.scale[i]
                } else {
                    let node = to.layout.nodes[k];
                    let (a, b, f) = bracket(from, node.phase, map(node.phase, node.s));
                    let (ia, ib) = (from.state(a, c), from.state(b, c));
                    let d =
                        (1.0 - f) * bound_density(z_from, ia, a) + f * bound_density(z_from, ib, b);
                    d * weight(to, k) * obj_ratio * to.scale[i]
                };
            }
        }
    }
    // Phase end times, phase-order and rendezvous rows: the same on every mesh.
    for p in 0..to.layout.phases() {
        let (i, j) = (to.time(p), from.time(p));
        out.z_l[i] = duals.z_l[j] / from.scale[j] * obj_ratio * to.scale[i];
        out.z_u[i] = duals.z_u[j] / from.scale[j] * obj_ratio * to.scale[i];
    }
    // Only bounds the new problem has, on variables it leaves free, carry a multiplier.
    for i in 0..n_to {
        let free = to.x_lo[i] < to.x_hi[i];
        if !free || to.x_lo[i] <= -INF {
            out.z_l[i] = 0.0;
        }
        if !free || to.x_hi[i] >= INF {
            out.z_u[i] = 0.0;
        }
    }
    for r in 0..fixed_rows {
        let (rf, rt) = (k_from * nx + r, k_to * nx + r);
        out.lambda[rt] = duals.lambda[rf] * from.cscale[rf] * obj_ratio / to.cscale[rt];
    }
    out.lambda
        .iter()
        .chain(&out.z_l)
        .chain(&out.z_u)
        .all(|v| v.is_finite())
}
