//! A threat moving on a known road: its inflated keep-out region at a time (eqs. 6.5,
//! 6.6, 6.10) with `F`, its derivatives in position and its time derivative, and the
//! exposure over a static layout and moving threats.

use super::EstimationError;
use super::gauss_markov::{Estimate, GaussMarkov};
use super::road::Road;
use crate::threat::{Eval, ExposureAcc, Superquadric, pow_abs};

/// The keep-out region of a moving threat at one time, eqs. (6.5), (6.6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region<const D: usize> {
    /// The superquadric: centre on the road at the mean distance, x-axis along the road,
    /// `ax = ax0 + sigma_d`, `px = 2 + sigma_d/ax0`, other axes as given with exponent 2.
    pub shape: Superquadric<D>,
    /// Mean distance along the road.
    pub distance: f64,
    /// `sigma_d = sqrt(P_11)`.
    pub sigma_d: f64,
    /// Velocity of the centre (`d'` times the road tangent).
    pub center_velocity: [f64; D],
    /// `d sigma_d / dt`.
    pub sigma_rate: f64,
}

/// `F` of a moving threat at `(w, t)` with derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingEval<const D: usize> {
    /// `F`, its gradient and Hessian in `w`.
    pub f: Eval<D>,
    /// `dF/dt` at fixed `w`.
    pub df_dt: f64,
    /// `d(grad_w F)/dt` at fixed `w` (the mixed second derivative).
    pub dgrad_dt: [f64; D],
}

/// A threat moving on a known road (FORMULATION.md §5): the road, its keep-out axes when
/// its position is certain (along the road, across, up), the motion model and the current
/// estimate of `(d, v, a)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingThreat<const D: usize> {
    road: Road<D>,
    axes0: [f64; D],
    model: GaussMarkov,
    estimate: Estimate,
    appears_at: f64,
}

impl<const D: usize> MovingThreat<D> {
    /// A moving threat, known from the start (`appears_at = -inf`); `axes0` finite,
    /// positive.
    pub fn new(
        road: Road<D>,
        axes0: [f64; D],
        model: GaussMarkov,
        estimate: Estimate,
    ) -> Result<Self, EstimationError> {
        for &a in &axes0 {
            if !(a.is_finite() && a > 0.0) {
                return Err(EstimationError::NotPositive {
                    field: "axes0",
                    value: a,
                });
            }
        }
        Ok(Self {
            road,
            axes0,
            model,
            estimate,
            appears_at: f64::NEG_INFINITY,
        })
    }

    /// The same threat, present only from `t` on (scenario `appears_at_s`).
    pub fn with_appears_at(mut self, t: f64) -> Self {
        self.appears_at = t;
        self
    }

    /// Time from which the threat exists (exposure before it is zero).
    pub fn appears_at(&self) -> f64 {
        self.appears_at
    }

    /// True when the threat exists at `t`.
    pub fn is_active(&self, t: f64) -> bool {
        t >= self.appears_at
    }

    /// The road.
    pub fn road(&self) -> &Road<D> {
        &self.road
    }

    /// Keep-out semi-axes when the position is certain.
    pub fn axes0(&self) -> &[f64; D] {
        &self.axes0
    }

    /// The motion model.
    pub fn model(&self) -> &GaussMarkov {
        &self.model
    }

    /// The estimate the regions are propagated from.
    pub fn estimate(&self) -> &Estimate {
        &self.estimate
    }

    /// Replaces the estimate (after a filter update or a new report).
    pub fn set_estimate(&mut self, est: Estimate) {
        self.estimate = est;
    }

    /// The keep-out region at time `t` (for `t` before the estimate, the estimate's).
    #[inline]
    pub fn region_at(&self, t: f64) -> Region<D> {
        let st = self.model.distance_at(&self.estimate, t);
        let sigma = st.var.max(0.0).sqrt();
        let sigma_rate = if sigma > 0.0 {
            st.var_rate / (2.0 * sigma)
        } else {
            0.0
        };
        let rp = self.road.point_at(st.mean);
        let ax0 = self.axes0[0];
        let mut axes = self.axes0;
        axes[0] = ax0 + sigma;
        let mut exps = [2.0; D];
        exps[0] = 2.0 + sigma / ax0;
        Region {
            shape: Superquadric::new_unchecked(rp.point, axes, exps, rp.yaw),
            distance: st.mean,
            sigma_d: sigma,
            center_velocity: rp.direction.map(|u| u * st.rate),
            sigma_rate,
        }
    }

    /// `F` of the region at time `t` at `w` (eq. 6.10).
    #[inline]
    pub fn f(&self, w: &[f64; D], t: f64) -> f64 {
        self.region_at(t).shape.f(w)
    }

    /// `F` at `(w, t)` with gradient and Hessian in `w`, `dF/dt` and `d grad F/dt`.
    ///
    /// With `r = d_x/ax` and the x-term `T = |r|^px`: the centre moves at `c'`, so
    /// `dF/dt = -grad F · c' + (dT/dax) sigma' + (dT/dpx) sigma'/ax0`, with
    /// `dT/dax = -T'(r) r/ax` and `dT/dpx = T ln|r|`; the mixed derivative is
    /// `-H c' + R e_x (dg_x/dax sigma' + dg_x/dpx sigma'/ax0)` with `g_x = T'(r)/ax`,
    /// `dg_x/dax = -(T''(r) r + T'(r))/ax²`, `dg_x/dpx = T'(r)(1/px + ln|r|)/ax`.
    /// The road's yaw is constant along a segment, so it contributes nothing.
    pub fn eval(&self, w: &[f64; D], t: f64) -> MovingEval<D> {
        let reg = self.region_at(t);
        let f = reg.shape.f_grad_hess(w);
        let ax = reg.shape.axes()[0];
        let px = reg.shape.exponents()[0];
        let r = reg.shape.local(w)[0] / ax;
        let (tx, d1, d2) = pow_abs(r, px);
        let ln_r = if r != 0.0 && d1 != 0.0 {
            r.abs().ln()
        } else {
            0.0
        };
        let sdot = reg.sigma_rate;
        let a_rate = sdot;
        let p_rate = sdot / self.axes0[0];
        let cdot = &reg.center_velocity;
        let grad_dot_c: f64 = (0..D).map(|k| f.grad[k] * cdot[k]).sum();
        let df_dt = -grad_dot_c + (-d1 * r / ax) * a_rate + tx * ln_r * p_rate;
        let dgx = -(d2 * r + d1) / (ax * ax) * a_rate + d1 * (1.0 / px + ln_r) / ax * p_rate;
        let mut local = [0.0; D];
        local[0] = dgx;
        let rot = reg.shape.rotate_to_world(local);
        let dgrad_dt: [f64; D] = std::array::from_fn(|i| {
            let hc: f64 = (0..D).map(|j| f.hess[(i, j)] * cdot[j]).sum();
            rot[i] - hc
        });
        MovingEval { f, df_dt, dgrad_dt }
    }
}

impl<const D: usize> MovingThreat<D> {
    /// The region at `t` unless it is skipped at `w` by the cut-off of stiffness `s`
    /// (`None` also before the threat appears): skipped when `w` lies outside the
    /// region's box for `F >= cutoff_f(s)` (conservative box, see
    /// [`Superquadric::cutoff_half_extents`]), where `1 - eps <= CUTOFF_DELTA`.
    #[inline]
    pub fn region_if_near(&self, w: &[f64; D], t: f64, stiffness: f64) -> Option<Region<D>> {
        if !self.is_active(t) {
            return None;
        }
        let reg = self.region_at(t);
        let half = reg
            .shape
            .cutoff_half_extents(crate::threat::cutoff_f(stiffness), true);
        (!reg.shape.outside_box(w, &half)).then_some(reg)
    }
}

/// A moving threat's region at one time with its cut-off box and whether the threat is
/// active then: what an evaluator that tables the regions over time keeps (the swarm's
/// grid, the seeds' table), so that a point's exposure needs no propagation.
#[derive(Debug, Clone, Copy)]
pub struct TabledRegion<const D: usize> {
    shape: Superquadric<D>,
    half: [f64; D],
    active: bool,
}

impl<const D: usize> TabledRegion<D> {
    /// Folds the region's `F` at `w` into `acc` (with `stiffness`), as the exposure does:
    /// only while the threat is active and `w` is inside its cut-off box.
    #[inline]
    pub fn fold_value_into(&self, w: &[f64; D], acc: &mut ExposureAcc<D>, stiffness: f64) {
        if self.active && !self.shape.outside_box(w, &self.half) {
            acc.fold_value(self.shape.f(w), stiffness);
        }
    }
}

/// Appends to `out`, for each time of `times` in turn, the region of every threat of
/// `moving` with its cut-off box at `f_cut` (conservative, as the exposure's).
pub fn tabulate<const D: usize>(
    moving: &[MovingThreat<D>],
    times: impl Iterator<Item = f64>,
    f_cut: f64,
    out: &mut Vec<TabledRegion<D>>,
) {
    for t in times {
        for m in moving {
            let r = m.region_at(t);
            out.push(TabledRegion {
                shape: r.shape,
                half: r.shape.cutoff_half_extents(f_cut, true),
                active: m.is_active(t),
            });
        }
    }
}

/// Exposure `E(w, t) = 1 - prod eps_i` over a static layout and moving threats, each
/// moving threat at its region at `t` (absent before it appears), all with the layout's
/// stiffness and cut-off.
pub fn exposure_at<const D: usize>(
    layout: &crate::threat::ThreatLayout<D>,
    moving: &[MovingThreat<D>],
    w: &[f64; D],
    t: f64,
) -> f64 {
    let s = layout.stiffness();
    let mut acc = crate::threat::ExposureAcc::new();
    layout.fold_value_into(w, &mut acc);
    for m in moving {
        if let Some(reg) = m.region_if_near(w, t, s) {
            acc.fold_value(reg.shape.f(w), s);
        }
    }
    acc.e.value
}

/// [`exposure_at`] with gradient and Hessian in `w`.
pub fn exposure_eval_at<const D: usize>(
    layout: &crate::threat::ThreatLayout<D>,
    moving: &[MovingThreat<D>],
    w: &[f64; D],
    t: f64,
) -> Eval<D> {
    let s = layout.stiffness();
    let mut acc = crate::threat::ExposureAcc::new();
    layout.fold_into(w, &mut acc);
    for m in moving {
        if let Some(reg) = m.region_if_near(w, t, s) {
            acc.fold(&reg.shape.f_grad_hess(w), s);
        }
    }
    acc.e
}
