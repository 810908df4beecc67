//! Flying a particle: the flown [`State`], the exact 2-D arc and the 3-D reduced-model
//! sample steps, pure pursuit and the guidance of the guided parameterisation, and the
//! [`Flyer`] that flies a particle step by step into a [`Scratch`], with the fast
//! trigonometry they use.

use std::f64::consts::FRAC_PI_2;

#[cfg(doc)]
use crate::dynamics;
use crate::dynamics::G0;

use super::Scratch;
use super::grid::{End, Grid};

/// `sin(x) / x`.
#[inline]
pub(super) fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// `(sin x, cos x)` for the small angles of one sample step (a half turn-rate or
/// flight-path increment): Taylor series to `x^10` when `|x| <= 0.6` (error below 1e-10,
/// several times cheaper than `sin_cos`), `sin_cos` otherwise.
#[inline(always)]
pub(super) fn sin_cos_small(x: f64) -> (f64, f64) {
    if x.abs() > 0.6 {
        return x.sin_cos();
    }
    // Horner form with the reciprocal factorial ratios as constants (no division).
    const S3: f64 = 1.0 / 6.0;
    const S5: f64 = 1.0 / 20.0;
    const S7: f64 = 1.0 / 42.0;
    const S9: f64 = 1.0 / 72.0;
    const C2: f64 = 0.5;
    const C4: f64 = 1.0 / 12.0;
    const C6: f64 = 1.0 / 30.0;
    const C8: f64 = 1.0 / 56.0;
    const C10: f64 = 1.0 / 90.0;
    let x2 = x * x;
    let s = x * (1.0 - x2 * S3 * (1.0 - x2 * S5 * (1.0 - x2 * S7 * (1.0 - x2 * S9))));
    let c = 1.0 - x2 * C2 * (1.0 - x2 * C4 * (1.0 - x2 * C6 * (1.0 - x2 * C8 * (1.0 - x2 * C10))));
    (s, c)
}

/// `atan(z)` within 1e-5 rad (minimax polynomial on `[-1, 1]`, `pi/2 - atan(1/z)`
/// beyond): for the guidance's flight-path angle and the effort estimate, not for output.
#[inline(always)]
pub(super) fn atan_fast(z: f64) -> f64 {
    let (a, flip) = if z.abs() > 1.0 {
        (1.0 / z, true)
    } else {
        (z, false)
    };
    let a2 = a * a;
    let r = a
        * (0.999_977_26
            + a2 * (-0.332_623_47
                + a2 * (0.193_543_46
                    + a2 * (-0.116_432_87 + a2 * (0.052_653_32 - 0.011_721_20 * a2)))));
    if flip { FRAC_PI_2.copysign(z) - r } else { r }
}

/// `(sin, cos)` of `a + b` from those of `a` and `b`.
#[inline(always)]
pub(super) fn rotate((sa, ca): (f64, f64), (sb, cb): (f64, f64)) -> (f64, f64) {
    (sa * cb + ca * sb, ca * cb - sa * sb)
}

/// The flown state: position, heading and flight-path angle with their sines and cosines
/// (advanced by exact rotations, so a step needs one or two `sin_cos`, not one per
/// sample).
#[derive(Debug, Clone, Copy)]
pub(super) struct State {
    pub(super) p: [f64; 3],
    pub(super) head: f64,
    pub(super) gam: f64,
    pub(super) sc_head: (f64, f64),
    pub(super) sc_gam: (f64, f64),
}

impl State {
    pub(super) fn initial(g: &Grid) -> Self {
        State {
            p: g.start,
            head: g.heading0,
            gam: g.gamma0,
            sc_head: g.heading0.sin_cos(),
            sc_gam: g.gamma0.sin_cos(),
        }
    }
}

/// Flies one 2-D sample step (length `h`) with turn rate `u` (clamped) as an exact arc.
#[inline(always)]
pub(super) fn step_planar(g: &Grid, s: &mut State, u: f64) {
    let uh = u * g.h;
    let half = sin_cos_small(0.5 * uh);
    let chord = g.speed
        * g.h
        * if uh.abs() < 2e-4 {
            sinc(0.5 * uh)
        } else {
            half.0 / (0.5 * uh)
        };
    let mid = rotate(s.sc_head, half);
    s.p[0] += chord * mid.1;
    s.p[1] += chord * mid.0;
    s.head += uh;
    s.sc_head = rotate(mid, half);
}

/// The 3-D sample step's effective controls from the commanded `gamma` at its end and the
/// heading rate at state `s`: clamped to their bounds, and `gamma` raised so that the step
/// ends above `z_min` (midpoint estimate) when it can.
#[inline(always)]
pub(super) fn spatial_controls(g: &Grid, s: &State, gamma_cmd: f64, rate: f64) -> (f64, f64) {
    let w = rate.clamp(-g.rate_max, g.rate_max);
    let mut ge = gamma_cmd.clamp(-g.gamma_max, g.gamma_max);
    let need = (g.z_min - s.p[2]) / (g.speed * g.h);
    if need > -1.0 {
        let a = need.min(1.0).asin();
        ge = ge.max(2.0 * a - s.gam).min(g.gamma_max);
    }
    (ge, w)
}

/// Flies one 3-D sample step (reduced model, eq. 5.11): `gamma` from its value to `ge` and
/// `chi` at rate `w`, both linear in time, position by the midpoint rule.
#[inline(always)]
pub(super) fn step_spatial(g: &Grid, s: &mut State, ge: f64, w: f64) {
    let dchi = w * g.h;
    let dgam = ge - s.gam;
    let (hc, hg) = (sin_cos_small(0.5 * dchi), sin_cos_small(0.5 * dgam));
    let mc = rotate(s.sc_head, hc);
    let mg = rotate(s.sc_gam, hg);
    let vh = g.speed * g.h;
    s.p[0] += vh * mg.1 * mc.1;
    s.p[1] += vh * mg.1 * mc.0;
    s.p[2] += vh * mg.0;
    s.head += dchi;
    s.gam = ge;
    s.sc_head = rotate(mc, hc);
    s.sc_gam = rotate(mg, hg);
}

/// `Nz`, `mu` of a 3-D sample step (eq. 5.14 as [`dynamics::lift_reduced_path`], in the
/// form `mu = atan(num / den)`, `Nz = sign(den) (V / g) sqrt(num² + den²)`, `atan` within
/// 1e-5 rad: for the swarm's effort term only).
#[inline(always)]
pub(super) fn lift_step(g: &Grid, s: &State, ge: f64, w: f64) -> (f64, f64) {
    let gdot = (ge - s.gam) / g.h;
    let cg = s.sc_gam.1;
    let num = w * cg;
    let den = gdot + G0 * cg / g.speed;
    let r = (num * num + den * den).sqrt();
    if den == 0.0 {
        (0.0, num.signum() * FRAC_PI_2)
    } else {
        (den.signum() * g.speed / G0 * r, atan_fast(num / den))
    }
}

/// Pure pursuit of `aim` from `s`: the heading rate of the arc tangent to the heading
/// through `aim` (`2 V_h sin(e) / d`; the full rate towards it when it is behind) and, in
/// 3-D, the flight-path angle of the straight climb to it, both clamped to their bounds.
/// In 2-D the arc is flown exactly, so a reachable aim point is hit. An aim point inside
/// the tightest turning circle on its side cannot be reached by turning (pursuit would
/// orbit it for ever): the command is then to fly straight until it is outside. `turn`
/// remembers the side of a turn towards a point behind (hysteresis).
#[inline(always)]
pub(super) fn pursuit(g: &Grid, s: &State, aim: &[f64; 3], turn: &mut i8) -> (f64, f64) {
    let (dx, dy) = (aim[0] - s.p[0], aim[1] - s.p[1]);
    let d2 = dx * dx + dy * dy;
    let (sh, ch) = s.sc_head;
    let cross = ch * dy - sh * dx; // d sin(e)
    let dot = ch * dx + sh * dy; // d cos(e)
    let vh = g.speed * s.sc_gam.1;
    // Radius of the tightest turn: the point is inside that circle (centre at `r` along the
    // normal on the point's side) when `d² < 2 r |cross|`.
    let radius = vh / g.rate_max;
    let rate = if d2 < 1.0 || d2 < 2.0 * radius * cross.abs() {
        0.0
    } else if dot < 0.0 {
        // Behind: turn towards it at the full rate; within 30 degrees of straight behind,
        // keep the side chosen before (else the side flips at every sample).
        if *turn == 0 || cross.abs() > 0.5 * d2.sqrt() {
            *turn = if cross >= 0.0 { 1 } else { -1 };
        }
        f64::from(*turn) * g.rate_max
    } else {
        *turn = 0;
        2.0 * vh * cross / d2
    };
    let gamma = if g.spatial {
        atan_fast((aim[2] - s.p[2]) / d2.sqrt().max(1.0))
    } else {
        0.0
    };
    (
        rate.clamp(-g.rate_max, g.rate_max),
        gamma.clamp(-g.gamma_max, g.gamma_max),
    )
}

/// The guidance of the guided parameterisation: pure pursuit of the next target not yet
/// passed, then of the final point or of the lead's intercept point. A target counts as
/// passed once it is within a quarter sample spacing, or behind and within two control
/// steps' flight.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Guide {
    pub(super) gate: usize,
    turn: i8,
}

impl Guide {
    /// The guidance command (heading rate, flight-path angle) at state `s` at sample `j`.
    #[inline(always)]
    pub(super) fn command(&mut self, g: &Grid, s: &State, j: usize) -> (f64, f64) {
        if !g.guided {
            return (0.0, 0.0);
        }
        let (sh, ch) = s.sc_head;
        let reach2 = (2.0 * g.speed * g.dt).powi(2);
        let near2 = (0.25 * g.speed * g.h).powi(2);
        while self.gate < g.n_targets {
            let q = &g.targets[self.gate];
            let (dx, dy) = (q[0] - s.p[0], q[1] - s.p[1]);
            let d2 = dx * dx + dy * dy;
            if d2 < near2 || (dx * ch + dy * sh <= 0.0 && d2 < reach2) {
                self.gate += 1;
            } else {
                break;
            }
        }
        let aim = if self.gate < g.n_targets {
            g.targets[self.gate]
        } else {
            match g.end {
                End::Point { p, .. } => p,
                End::Lead => g.intercept(&s.p, j),
            }
        };
        pursuit(g, s, &aim, &mut self.turn)
    }
}

/// Flies a particle control step by control step into a [`Scratch`].
pub(super) struct Flyer {
    s: State,
    guide: Guide,
    /// Last sample written.
    pub(super) j: usize,
    effort: f64,
    nz: f64,
    mu: f64,
}

impl Flyer {
    pub(super) fn start(g: &Grid, sc: &mut Scratch) -> Self {
        let s = State::initial(g);
        sc.pos[0] = s.p;
        sc.head[0] = s.head;
        sc.gam[0] = s.gam;
        sc.effort[0] = 0.0;
        Flyer {
            s,
            guide: Guide::default(),
            j: 0,
            effort: 0.0,
            nz: g.nz0,
            mu: g.mu0,
        }
    }

    /// Flies control step `k` of particle `u` (its `sub` samples), writing the samples.
    #[inline(always)]
    pub(super) fn step(&mut self, g: &Grid, u: &[f64], k: usize, sc: &mut Scratch) {
        for _ in 0..g.sub {
            let j = self.j;
            let (cr, cg) = self.guide.command(g, &self.s, j);
            if !g.spatial {
                let ue = (cr + u[k]).clamp(-g.rate_max, g.rate_max);
                sc.ctrl[j] = ue;
                step_planar(g, &mut self.s, ue);
                self.effort += ue * ue * g.h;
            } else {
                let (ge, w) = spatial_controls(g, &self.s, cg + u[2 * k], cr + u[2 * k + 1]);
                let (nz1, mu1) = lift_step(g, &self.s, ge, w);
                // (u1² + u2²) h with u = jump / h.
                self.effort += ((nz1 - self.nz).powi(2) + (mu1 - self.mu).powi(2)) / g.h;
                self.nz = nz1;
                self.mu = mu1;
                step_spatial(g, &mut self.s, ge, w);
            }
            self.j += 1;
            let j = self.j;
            sc.pos[j] = self.s.p;
            sc.head[j] = self.s.head;
            sc.gam[j] = self.s.gam;
            sc.effort[j] = self.effort;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast trigonometry against libm: `sin_cos_small` within 1e-10 on `[-1, 1]`
    /// (series below 0.6, libm above), `atan_fast` within 1e-5 rad on `[-1e3, 1e3]`.
    #[test]
    fn fast_trigonometry_is_accurate() {
        for k in -1000..=1000 {
            let x = k as f64 * 1e-3;
            let (s, c) = sin_cos_small(x);
            assert!(
                (s - x.sin()).abs() < 1e-10 && (c - x.cos()).abs() < 1e-10,
                "{x}"
            );
        }
        for k in -20000..=20000 {
            let z = (k as f64 * 5e-4).powi(3);
            assert!((atan_fast(z) - z.atan()).abs() < 1e-5, "{z}");
        }
    }
}
