//! A particle written out as a full-model [`Trajectory`] ([`write_trajectory`]; 3-D states
//! lifted with eqs. 5.13–5.15).

use crate::dynamics::{self, ReducedPath, Spatial};
use crate::trajectory::Trajectory;

use super::Scratch;
use super::cost::Report;
use super::flight::sinc;
use super::grid::Grid;

/// Output buffers of [`write_trajectory`] (3-D lift input).
#[derive(Debug, Clone, Default)]
pub(crate) struct OutBuffers {
    times: Vec<f64>,
    pos: Vec<[f64; 3]>,
    gamma: Vec<f64>,
    chi: Vec<f64>,
    rate: Vec<f64>,
}

/// A state of the output: position, heading, flight-path angle, 2-D turn rate.
pub(super) type OutState = ([f64; 3], f64, f64, f64);

impl OutBuffers {
    fn clear(&mut self) {
        self.times.clear();
        self.pos.clear();
        self.gamma.clear();
        self.chi.clear();
        self.rate.clear();
    }

    fn push(&mut self, t: f64, s: OutState) {
        self.times.push(t);
        self.pos.push(s.0);
        self.chi.push(s.1);
        self.gamma.push(s.2);
        self.rate.push(s.3);
    }

    pub(crate) fn with_capacity(n: usize) -> Self {
        OutBuffers {
            times: Vec::with_capacity(n),
            pos: Vec::with_capacity(n),
            gamma: Vec::with_capacity(n),
            chi: Vec::with_capacity(n),
            rate: Vec::with_capacity(n),
        }
    }
}

/// Writes the path of particle `u` (already evaluated into `sc` with report `rep`) up to
/// its final time into `out`: every sample, plus a sample at each target's pass and at
/// the final time; full 3-D states lifted with eqs. (5.13)–(5.15). Phase ends: the pass
/// times.
pub(crate) fn write_trajectory(
    g: &Grid,
    sc: &Scratch,
    rep: &Report,
    buf: &mut OutBuffers,
    out: &mut Trajectory,
) -> Result<(), dynamics::DynamicsError> {
    buf.clear();
    out.clear();
    let eps = 1e-6 * g.h;
    let fin = rep.passes[rep.n_passes - 1];
    let segs = rep.flown;
    // The state at fraction `f` of segment `j`: one partial step of the same model.
    let partial = |j: usize, f: f64| -> OutState {
        let th = f * g.h;
        let a = sc.pos[j];
        if !g.spatial {
            let ue = sc.ctrl[j.min(segs.saturating_sub(1))];
            let chord = g.speed * th * sinc(0.5 * ue * th);
            let mid = sc.head[j] + 0.5 * ue * th;
            (
                [a[0] + chord * mid.cos(), a[1] + chord * mid.sin(), 0.0],
                sc.head[j] + ue * th,
                0.0,
                ue,
            )
        } else {
            let j1 = (j + 1).min(segs);
            let (g0, g1) = (sc.gam[j], sc.gam[j1]);
            let (c0, c1) = (sc.head[j], sc.head[j1]);
            let gm = g0 + 0.5 * f * (g1 - g0);
            let cm = c0 + 0.5 * f * (c1 - c0);
            let v = g.speed * th;
            (
                [
                    a[0] + v * gm.cos() * cm.cos(),
                    a[1] + v * gm.cos() * cm.sin(),
                    a[2] + v * gm.sin(),
                ],
                c0 + f * (c1 - c0),
                g0 + f * (g1 - g0),
                0.0,
            )
        }
    };
    let sample = |j: usize| -> OutState {
        let r = if g.spatial {
            0.0
        } else {
            sc.ctrl[j.min(segs.saturating_sub(1))]
        };
        (sc.pos[j], sc.head[j], sc.gam[j], r)
    };
    let mut next_pass = 0;
    for j in 0..=fin.seg {
        buf.push(g.time(j), sample(j));
        // Targets passed inside segment j (not at its ends, not after the final time).
        while next_pass + 1 < rep.n_passes && rep.passes[next_pass].seg == j {
            let p = rep.passes[next_pass];
            next_pass += 1;
            let inside = p.frac * g.h > eps && (1.0 - p.frac) * g.h > eps;
            if inside && !(j == fin.seg && p.frac >= fin.frac) {
                buf.push(p.time(g), partial(j, p.frac));
            }
        }
    }
    if fin.frac * g.h > eps {
        if (1.0 - fin.frac) * g.h > eps {
            buf.push(fin.time(g), partial(fin.seg, fin.frac));
        } else {
            let j = (fin.seg + 1).min(segs);
            buf.push(g.time(j), sample(j));
        }
    }
    if buf.times.len() < 2 {
        // A path that ends at once: two samples a sub-step apart.
        let j = 1.min(segs);
        buf.push(g.time(j), sample(j));
    }
    let OutBuffers {
        times,
        pos,
        gamma,
        chi,
        rate,
    } = buf;
    let n = times.len();
    // One allocation per buffer for a fresh trajectory, none for a large enough one.
    out.times.reserve_exact(n);
    out.states.reserve_exact(n);
    out.controls.reserve_exact(n);
    out.phase_ends.reserve_exact(rep.n_passes);
    if !g.spatial {
        for i in 0..n {
            let p = pos[i];
            out.push(
                times[i],
                [p[0], p[1], chi[i], 0.0, 0.0, 0.0, 0.0],
                [rate[i], 0.0],
            );
        }
    } else {
        let model = Spatial::new(g.speed)?;
        out.times.extend_from_slice(times);
        out.states.resize(n, [0.0; 7]);
        out.controls.resize(n, [0.0; 2]);
        dynamics::lift_reduced_path(
            &model,
            &ReducedPath {
                times,
                positions: pos,
                gamma,
                chi,
            },
            &mut out.states,
            &mut out.controls,
        )?;
        // The first sample is the initial state itself (its Nz, mu), the first controls
        // lead from it to the second sample's.
        out.states[0][dynamics::idx3::NZ] = g.nz0;
        out.states[0][dynamics::idx3::MU] = g.mu0;
        let dt0 = times[1] - times[0];
        out.controls[0] = [
            (out.states[1][dynamics::idx3::NZ] - g.nz0) / dt0,
            (out.states[1][dynamics::idx3::MU] - g.mu0) / dt0,
        ];
    }
    // Phase ends: the pass times, non-decreasing and within the trajectory.
    let (t_first, t_last) = (out.times[0], out.times[n - 1]);
    let mut prev = t_first;
    for p in &rep.passes[..rep.n_passes - 1] {
        prev = p.time(g).clamp(prev, t_last);
        out.phase_ends.push(prev);
    }
    out.phase_ends.push(t_last);
    Ok(())
}
