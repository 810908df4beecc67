//! Trajectory metrics shared by the optimizer, the harness and the reports, defined as the
//! judge (`tools/judge/evaluate.py`) defines them: the exposure integral, the minimum
//! `F` per threat, final-condition errors, target miss distances and bound violations.
//!
//! All functions work on samples the caller owns and never allocate.

use crate::dynamics::{Control2, Control3, Limits, State2, State3, idx2, idx3, wrap_angle};
use crate::estimation::{MovingThreat, exposure_at};
use crate::threat::{Superquadric, ThreatLayout};

/// Composite Simpson rule on samples `(times[i], f(i))` with any spacing: each pair of
/// steps `h0, h1` gets the non-uniform rule
/// `(h0+h1)/6 [(2 - h1/h0) f0 + (h0+h1)²/(h0 h1) f1 + (2 - h0/h1) f2]` (the classic
/// `h/3 (f0 + 4 f1 + f2)` when `h0 = h1`); with an even number of samples the last step
/// is a trapezoid, exactly as `evaluate.py`'s `simpson`. `f` is called once per sample.
/// Fewer than two samples give 0.
pub fn simpson_by(times: &[f64], mut f: impl FnMut(usize) -> f64) -> f64 {
    let n = times.len();
    if n < 2 {
        return 0.0;
    }
    let simpson_end = if n % 2 == 1 { n - 1 } else { n - 2 };
    let mut sum = 0.0;
    let mut f0 = f(0);
    let mut i = 0;
    while i + 2 <= simpson_end {
        let f1 = f(i + 1);
        let f2 = f(i + 2);
        let h0 = times[i + 1] - times[i];
        let h1 = times[i + 2] - times[i + 1];
        let hs = h0 + h1;
        sum += hs / 6.0 * ((2.0 - h1 / h0) * f0 + hs * hs / (h0 * h1) * f1 + (2.0 - h0 / h1) * f2);
        f0 = f2;
        i += 2;
    }
    if simpson_end < n - 1 {
        let f1 = f(n - 1);
        sum += 0.5 * (times[n - 1] - times[n - 2]) * (f0 + f1);
    }
    sum
}

/// [`simpson_by`] on a slice of values (same length as `times`; the shorter decides).
pub fn simpson(times: &[f64], values: &[f64]) -> f64 {
    let n = times.len().min(values.len());
    simpson_by(&times[..n], |i| values[i])
}

/// `int E(w(t), t) dt` by composite Simpson ([`simpson_by`]) on the given samples, `E`
/// over the static layout and the moving threats (each at its region at the sample's
/// time, absent before it appears).
pub fn exposure_integral<const D: usize>(
    times: &[f64],
    positions: &[[f64; D]],
    layout: &ThreatLayout<D>,
    moving: &[MovingThreat<D>],
) -> f64 {
    let n = times.len().min(positions.len());
    simpson_by(&times[..n], |i| {
        exposure_at(layout, moving, &positions[i], times[i])
    })
}

/// The smallest `F` along a path and where it occurs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MinF {
    /// Smallest `F`.
    pub f: f64,
    /// Index of its sample.
    pub index: usize,
    /// Time of its sample.
    pub t: f64,
}

/// Smallest `F` of a static threat over the samples (`None` for no samples).
pub fn min_f_static<const D: usize>(
    times: &[f64],
    positions: &[[f64; D]],
    threat: &Superquadric<D>,
) -> Option<MinF> {
    min_by(times, positions, |_, w| Some(threat.f(w)))
}

/// Smallest `F` of a moving threat over the samples where it exists, each sample against
/// the region at its time (`None` if it never exists along the samples).
pub fn min_f_moving<const D: usize>(
    times: &[f64],
    positions: &[[f64; D]],
    threat: &MovingThreat<D>,
) -> Option<MinF> {
    min_by(times, positions, |t, w| {
        threat.is_active(t).then(|| threat.f(w, t))
    })
}

fn min_by<const D: usize>(
    times: &[f64],
    positions: &[[f64; D]],
    mut f: impl FnMut(f64, &[f64; D]) -> Option<f64>,
) -> Option<MinF> {
    let mut best: Option<MinF> = None;
    for (index, (t, w)) in times.iter().zip(positions).enumerate() {
        if let Some(v) = f(*t, w)
            && best.is_none_or(|b| v < b.f)
        {
            best = Some(MinF { f: v, index, t: *t });
        }
    }
    best
}

/// Time spent inside (`F < 1`) any of the static threats or moving threats, counting
/// `times[i+1] - times[i]` for each sample `i` inside (on a uniform grid, `evaluate.py`'s
/// `time_inside_*` with `h` per sample; the last sample counts nothing).
pub fn time_inside<const D: usize>(
    times: &[f64],
    positions: &[[f64; D]],
    threats: &[Superquadric<D>],
    moving: &[MovingThreat<D>],
) -> f64 {
    let n = times.len().min(positions.len());
    let mut total = 0.0;
    for i in 0..n.saturating_sub(1) {
        let (t, w) = (times[i], &positions[i]);
        let inside = threats.iter().any(|th| th.f(w) < 1.0)
            || moving.iter().any(|m| m.is_active(t) && m.f(w, t) < 1.0);
        if inside {
            total += times[i + 1] - t;
        }
    }
    total
}

/// Final-condition errors (absolute values; angles in radians, heading wrapped).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FinalErrors {
    /// Position error (Euclidean), m.
    pub position: f64,
    /// Heading error, wrapped to `[0, π]`, rad.
    pub heading: f64,
    /// 3-D: flight-path angle error, rad (0 in 2-D).
    pub gamma: f64,
    /// 3-D: `Nz` error (0 in 2-D).
    pub nz: f64,
    /// 3-D: bank error, rad (0 in 2-D).
    pub mu: f64,
}

/// Final-condition errors of a 2-D state against the required one.
pub fn final_errors_2d(x: &State2, reference: &State2) -> FinalErrors {
    FinalErrors {
        position: (x[idx2::X] - reference[idx2::X]).hypot(x[idx2::Y] - reference[idx2::Y]),
        heading: wrap_angle(x[idx2::PSI] - reference[idx2::PSI]).abs(),
        ..FinalErrors::default()
    }
}

/// Final-condition errors of a 3-D state against the required one (the fixed final state,
/// or the lead's position, heading, `gamma` with `Nz = 1`, `mu = 0` for a rendezvous).
pub fn final_errors_3d(x: &State3, reference: &State3) -> FinalErrors {
    let dp: f64 = (0..3).map(|i| (x[i] - reference[i]).powi(2)).sum();
    FinalErrors {
        position: dp.sqrt(),
        heading: wrap_angle(x[idx3::CHI] - reference[idx3::CHI]).abs(),
        gamma: (x[idx3::GAMMA] - reference[idx3::GAMMA]).abs(),
        nz: (x[idx3::NZ] - reference[idx3::NZ]).abs(),
        mu: (x[idx3::MU] - reference[idx3::MU]).abs(),
    }
}

/// Closest approach of the path to one target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TargetMiss {
    /// Smallest distance, m.
    pub distance: f64,
    /// Sample where it occurs.
    pub index: usize,
}

/// Sequential closest approach to each target, as `evaluate.py`'s `target_errors` on
/// samples: target `g` is searched from the sample of target `g - 1`'s closest approach
/// on. Writes `min(targets.len(), out.len())` entries and returns that count.
pub fn target_misses<const D: usize>(
    positions: &[[f64; D]],
    targets: &[[f64; D]],
    out: &mut [TargetMiss],
) -> usize {
    let mut k0 = 0;
    let mut written = 0;
    for (tgt, slot) in targets.iter().zip(out.iter_mut()) {
        let mut best = TargetMiss {
            distance: f64::INFINITY,
            index: k0,
        };
        for (k, w) in positions.iter().enumerate().skip(k0) {
            let d = w
                .iter()
                .zip(tgt)
                .map(|(a, b)| (a - b) * (a - b))
                .sum::<f64>()
                .sqrt();
            if d < best.distance {
                best = TargetMiss {
                    distance: d,
                    index: k,
                };
            }
        }
        *slot = best;
        k0 = best.index;
        written += 1;
    }
    written
}

/// By how much each box bound is exceeded at worst (0: respected), SI units and radians,
/// as `evaluate.py`'s `bound_violations`. Bounds a model does not have stay 0.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BoundViolations {
    /// 2-D: `max |u| - u_max`, rad/s.
    pub u: f64,
    /// 3-D: `z_min - min z`, m.
    pub z_min: f64,
    /// 3-D: `max |gamma| - gamma_max`, rad.
    pub gamma: f64,
    /// 3-D: `max(max Nz - nz_max, nz_min - min Nz)`.
    pub nz: f64,
    /// 3-D: `max |mu| - mu_max`, rad.
    pub mu: f64,
    /// 3-D: `max |u1| - nz_rate_max`, 1/s.
    pub u1: f64,
    /// 3-D: `max |u2| - mu_rate_max`, rad/s.
    pub u2: f64,
}

impl BoundViolations {
    /// The largest entry (0 when every bound holds).
    pub fn max(&self) -> f64 {
        [
            self.u, self.z_min, self.gamma, self.nz, self.mu, self.u1, self.u2,
        ]
        .into_iter()
        .fold(0.0, f64::max)
    }
}

#[inline]
fn excess(v: f64, bound: f64) -> f64 {
    (v - bound).max(0.0)
}

/// Bound violations of 2-D controls.
pub fn bound_violations_2d(controls: &[Control2], limits: &Limits) -> BoundViolations {
    let umax = controls.iter().map(|u| u[0].abs()).fold(0.0, f64::max);
    BoundViolations {
        u: excess(umax, limits.turn_rate_max),
        ..BoundViolations::default()
    }
}

/// Bound violations of 3-D states and controls.
pub fn bound_violations_3d(
    states: &[State3],
    controls: &[Control3],
    limits: &Limits,
) -> BoundViolations {
    let mut v = BoundViolations::default();
    for x in states {
        v.z_min = v.z_min.max(excess(limits.z_min, x[idx3::Z]));
        v.gamma = v.gamma.max(excess(x[idx3::GAMMA].abs(), limits.gamma_max));
        v.nz =
            v.nz.max(excess(x[idx3::NZ], limits.nz_max))
                .max(excess(limits.nz_min, x[idx3::NZ]));
        v.mu = v.mu.max(excess(x[idx3::MU].abs(), limits.mu_max));
    }
    for u in controls {
        v.u1 = v.u1.max(excess(u[idx3::U1].abs(), limits.nz_rate_max));
        v.u2 = v.u2.max(excess(u[idx3::U2].abs(), limits.mu_rate_max));
    }
    v
}
