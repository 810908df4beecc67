//! Seeds into particles ([`track`]): the seed flown by the swarm's own model under pure
//! pursuit.

use crate::seeding::Seed;

#[cfg(doc)]
use super::flight::Flyer;
use super::flight::{Guide, State, pursuit, spatial_controls, step_planar, step_spatial};
use super::grid::Grid;

/// Turns a seed into a particle: flies the swarm's own model along the seed with a pure
/// pursuit controller. For each control step, a trial flight of its samples under pursuit
/// gives the commands, whose mean (guided: mean offset from the guidance command) is the
/// particle's coordinate for the step; the step is then flown again exactly as the
/// particle will fly it, and pursuit goes on from there, so the particle reproduces the
/// tracked path (clamps and altitude guard included). The aim point is `lookahead * V`
/// ahead along the seed (`lookahead` in seconds), but never past the next target or the
/// end until that is passed (pursuit then flies the arc through it).
pub(crate) fn track(g: &Grid, seed: &Seed, lookahead: f64, u: &mut [f64]) {
    let pts = seed.points();
    let arc = seed.arc_lengths();
    let gates = seed.gates();
    let n = pts.len();
    if n < 2 {
        u[..g.dim()].fill(0.0);
        return;
    }
    let mut s = State::initial(g);
    let step_len = g.speed * g.dt;
    let la = lookahead * g.speed;
    let mut i = 0;
    let mut gi = 0;
    let mut guide = Guide::default();
    let mut turn = 0i8;
    let dist = |a: &[f64; 3], p: &[f64; 3]| ((a[0] - p[0]).powi(2) + (a[1] - p[1]).powi(2)).sqrt();
    // The pursuit command at `st` (advancing the progress along the seed and its gates).
    let mut command = |st: &State| -> (f64, f64) {
        let mut best = i;
        let mut bd = dist(&pts[i], &st.p);
        let reach = arc[i] + 2.0 * la + step_len;
        let mut m = i + 1;
        while m < n && arc[m] <= reach {
            let d = dist(&pts[m], &st.p);
            if d < bd {
                bd = d;
                best = m;
            }
            m += 1;
        }
        i = best;
        // A gate is passed as the guidance passes a target (within a quarter sample, or
        // behind and within two steps), so that near a target both aim at it.
        let (sh, ch) = st.sc_head;
        while gi < gates.len() {
            let gp = pts[gates[gi]];
            let (dx, dy) = (gp[0] - st.p[0], gp[1] - st.p[1]);
            let d = (dx * dx + dy * dy).sqrt();
            let behind = dx * ch + dy * sh <= 0.0;
            if d < 0.25 * g.speed * g.h || (behind && d < 2.0 * step_len) {
                gi += 1;
                i = i.max(gates[gi - 1]);
            } else {
                break;
            }
        }
        let sq = arc[i] + la;
        let q = if gi < gates.len() && sq >= arc[gates[gi]] {
            pts[gates[gi]]
        } else {
            seed.point_at_arc(sq)
        };
        pursuit(g, st, &q, &mut turn)
    };
    for k in 0..g.steps {
        let j0 = k * g.sub;
        // Trial: pursuit over the step's samples; the mean offset is the coordinate.
        let (mut trial, mut tguide) = (s, guide);
        let (mut sum_r, mut sum_g) = (0.0, 0.0);
        let mut counted = 0;
        let mut passed = false;
        for q in 0..g.sub {
            let (rate, gamma_cmd) = command(&trial);
            let gate_before = tguide.gate;
            let (cr, cg) = tguide.command(g, &trial, j0 + q);
            if tguide.gate != gate_before && q > 0 {
                // The guidance passed a target: up to here both aimed at it, so the
                // offsets so far fly through it; the rest of the step would pull the
                // approach away.
                passed = true;
                break;
            }
            sum_r += rate - cr;
            sum_g += gamma_cmd - cg;
            counted += 1;
            if !g.spatial {
                step_planar(g, &mut trial, rate);
            } else {
                let (ge, w) = spatial_controls(g, &trial, gamma_cmd, rate);
                step_spatial(g, &mut trial, ge, w);
            }
        }
        let inv = 1.0 / counted.max(1) as f64;
        let (mut o_r, mut o_g) = (sum_r * inv, sum_g * inv);
        // The guidance varies within the step, so the mean offset does not reproduce the
        // trial: correct it (three passes) until the step ends with the trial's heading
        // (and flight-path angle).
        let clamp_r = |o: f64| o.clamp(g.lo[g.nu - 1], g.hi[g.nu - 1]);
        let clamp_g = |o: f64| o.clamp(g.lo[0], g.hi[0]);
        (o_r, o_g) = (clamp_r(o_r), clamp_g(o_g));
        for _ in 0..if passed { 0 } else { TRACK_PASSES } {
            let (mut probe, mut pguide) = (s, guide);
            fly_step(g, &mut probe, &mut pguide, j0, o_r, o_g);
            o_r = clamp_r(o_r + (trial.head - probe.head) / g.dt);
            o_g = clamp_g(o_g + (trial.gam - probe.gam));
        }
        if !g.spatial {
            u[k] = o_r;
        } else {
            u[2 * k] = o_g;
            u[2 * k + 1] = o_r;
        }
        // The step as the particle flies it.
        fly_step(g, &mut s, &mut guide, j0, o_r, o_g);
    }
}

/// Flies the `sub` samples of a control step from sample `j0` with constant offsets
/// (turn or heading rate `o_r`, flight-path angle `o_g`) to the guidance, as
/// [`Flyer::step`] does.
pub(super) fn fly_step(g: &Grid, s: &mut State, guide: &mut Guide, j0: usize, o_r: f64, o_g: f64) {
    for q in 0..g.sub {
        let (cr, cg) = guide.command(g, s, j0 + q);
        if !g.spatial {
            step_planar(g, s, (cr + o_r).clamp(-g.rate_max, g.rate_max));
        } else {
            let (ge, w) = spatial_controls(g, s, cg + o_g, cr + o_r);
            step_spatial(g, s, ge, w);
        }
    }
}

/// Correction passes of the seed tracker's offsets (see [`track`]).
pub(super) const TRACK_PASSES: usize = 1;
