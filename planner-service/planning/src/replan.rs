//! When to re-plan (FORMULATION.md §6, chapter VII, appendix E): the scheduled re-plan time
//! `t_r` for a moving threat (eqs. 7.1–7.6) and the pop-up test (`F < F*` at a remaining
//! sample of the plan, moving threats at their propagated region).
//!
//! Pure functions of a plan given as samples and a threat; no allocation, no clock.

use crate::dynamics::{OdeModel, Planar, Spatial, State2, State3};
use crate::estimation::{MovingThreat, Region};
use crate::threat::Superquadric;

/// One sample of a plan: time, position and inertial velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanPoint<const D: usize> {
    /// Mission time, s.
    pub t: f64,
    /// Position.
    pub position: [f64; D],
    /// Inertial velocity.
    pub velocity: [f64; D],
}

impl PlanPoint<2> {
    /// The sample of a 2-D state: its velocity over the ground (the model's wind added).
    pub fn from_state2(model: &Planar, t: f64, x: &State2) -> Self {
        let f = model.rhs(x, &[0.0]);
        Self {
            t,
            position: [x[0], x[1]],
            velocity: [f[0], f[1]],
        }
    }
}

impl PlanPoint<3> {
    /// The sample of a 3-D state.
    pub fn from_state3(model: &Spatial, t: f64, x: &State3) -> Self {
        Self {
            t,
            position: [x[0], x[1], x[2]],
            velocity: model.velocity(x),
        }
    }
}

/// Which condition fixed `t_r`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReplanCause {
    /// `H(i) <= rho(i)`, eq. (7.3).
    CriticalDistance,
    /// The sample lies in the propagated keep-out region (`F <= 1`) while still outside
    /// `rho` (see [`replan_time`]).
    InsideRegion,
}

/// The scheduled re-plan: the first sample that triggers it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplanTime {
    /// Index of the sample in the plan.
    pub index: usize,
    /// `t_r`, the sample's time.
    pub t: f64,
    /// Why.
    pub cause: ReplanCause,
    /// `H(i)`, distance from the wingman to the estimated threat centre (eq. 7.1).
    pub h: f64,
    /// `rho(i)`, the critical distance (eq. 7.4); infinite when `H(i) = 0`.
    pub rho: f64,
}

/// The terms of eqs. (7.1)–(7.6) at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CriticalDistance {
    /// `H(i) = |w(i) - c(i)|`, eq. (7.1).
    pub h: f64,
    /// `|cos alpha(i)|`, eq. (7.6) (0 when either velocity is zero).
    pub abs_cos_alpha: f64,
    /// `|c(i) - c(0)|`, the distance the threat has moved since the plan's start.
    pub travelled: f64,
    /// `sigma_d(i)`.
    pub sigma_d: f64,
    /// `rho(i) = ax(0) + sigma_d(i) (1 + xi(i))`, eqs. (7.4), (7.5); infinite at `H = 0`.
    pub rho: f64,
    /// `H(i) <= rho(i)`, evaluated as `H² <= (ax0 + sigma) H + sigma |c - c0| |cos alpha|`
    /// (no division, so exact at `H = 0`).
    pub triggers: bool,
}

/// Eqs. (7.1)–(7.6) at sample `p` with `c0` the threat's estimated centre at the plan's
/// first sample.
pub fn critical_distance<const D: usize>(
    threat: &MovingThreat<D>,
    c0: &[f64; D],
    p: &PlanPoint<D>,
) -> CriticalDistance {
    critical_distance_in(&threat.region_at(p.t), threat.axes0()[0], c0, p)
}

/// Eqs. (7.1)–(7.6) against a region already propagated to the sample's time.
fn critical_distance_in<const D: usize>(
    reg: &Region<D>,
    ax0: f64,
    c0: &[f64; D],
    p: &PlanPoint<D>,
) -> CriticalDistance {
    let c = reg.shape.center();
    let h = norm(&sub(&p.position, c));
    let travelled = norm(&sub(c, c0));
    let tv = &reg.center_velocity;
    let nw = norm(&p.velocity);
    let nt = norm(tv);
    let abs_cos_alpha = if nw > 0.0 && nt > 0.0 {
        (dot(&p.velocity, tv) / (nw * nt)).abs().min(1.0)
    } else {
        0.0
    };
    let sigma = reg.sigma_d;
    let rho = if h > 0.0 {
        ax0 + sigma * (1.0 + travelled / h * abs_cos_alpha)
    } else {
        f64::INFINITY
    };
    CriticalDistance {
        h,
        abs_cos_alpha,
        travelled,
        sigma_d: sigma,
        rho,
        triggers: h * h <= (ax0 + sigma) * h + sigma * travelled * abs_cos_alpha,
    }
}

/// `t_r` of eqs. (7.1)–(7.6) for a plan and a moving threat: the first sample `i` with
/// `H(i) <= rho(i)`, where `c(i)` is the threat centre propagated to `t_i`, `c(0)` the
/// centre at the plan's first sample (the last re-plan), and `alpha(i)` the angle between
/// the wingman's and the centre's velocities. `None` when no sample triggers.
///
/// Deviation from eq. (7.3), stated: a sample that lies in the propagated keep-out
/// region (`F(w_i, t_i) <= 1`) also triggers. `rho >= ax(0) + sigma_d = ax(i)` covers the
/// region only when no point of it lies farther than `ax(i)` from its centre, which fails
/// for `ay, az > ax(i)` and for `px > 2` (box-like corners); with this guard `t_r` never
/// lies after the plan enters the region. Samples before the threat appears are skipped.
pub fn replan_time<const D: usize>(
    plan: &[PlanPoint<D>],
    threat: &MovingThreat<D>,
) -> Option<ReplanTime> {
    let first = plan.first()?;
    let c0 = *threat.region_at(first.t).shape.center();
    for (index, p) in plan.iter().enumerate() {
        if !threat.is_active(p.t) {
            continue;
        }
        let reg = threat.region_at(p.t);
        let cd = critical_distance_in(&reg, threat.axes0()[0], &c0, p);
        let cause = if cd.triggers {
            ReplanCause::CriticalDistance
        } else if reg.shape.f(&p.position) <= 1.0 {
            ReplanCause::InsideRegion
        } else {
            continue;
        };
        return Some(ReplanTime {
            index,
            t: p.t,
            cause,
            h: cd.h,
            rho: cd.rho,
        });
    }
    None
}

/// A sample of the plan where a threat gives `F < F*`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PopupHit {
    /// Index of the sample in the given slice.
    pub index: usize,
    /// Its time.
    pub t: f64,
    /// `F` there.
    pub f: f64,
}

/// Pop-up test for a static threat (§6 trigger 1, chapter VII box 12): the first sample
/// of `remaining` with `F < f_star` (`f_star = 1` by default in the spec). `None`: the
/// threat does not touch the plan and causes no re-plan.
pub fn static_popup_hit<const D: usize>(
    remaining: &[PlanPoint<D>],
    threat: &Superquadric<D>,
    f_star: f64,
) -> Option<PopupHit> {
    remaining.iter().enumerate().find_map(|(index, p)| {
        let f = threat.f(&p.position);
        (f < f_star).then_some(PopupHit { index, t: p.t, f })
    })
}

/// Pop-up test for a moving threat: the first sample of `remaining` with
/// `F(w_i, t_i) < f_star`, the region propagated to each sample's time (eqs. 6.5, 6.6,
/// 6.10). Samples before the threat appears are skipped.
pub fn moving_popup_hit<const D: usize>(
    remaining: &[PlanPoint<D>],
    threat: &MovingThreat<D>,
    f_star: f64,
) -> Option<PopupHit> {
    remaining.iter().enumerate().find_map(|(index, p)| {
        if !threat.is_active(p.t) {
            return None;
        }
        let f = threat.f(&p.position, p.t);
        (f < f_star).then_some(PopupHit { index, t: p.t, f })
    })
}

#[inline]
fn sub<const D: usize>(a: &[f64; D], b: &[f64; D]) -> [f64; D] {
    std::array::from_fn(|i| a[i] - b[i])
}

#[inline]
fn dot<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[inline]
fn norm<const D: usize>(a: &[f64; D]) -> f64 {
    dot(a, a).sqrt()
}
