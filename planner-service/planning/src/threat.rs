//! Static threats of FORMULATION.md §3: superquadrics with yaw and one exponent per axis,
//! their inside–outside function `F` (eqs. 2.8, 3.14, 5.2, 6.10) with gradient and Hessian,
//! the smooth exposure `eps(F)` (eq. 5.4) and the layout exposure
//! `E(w) = 1 - prod_i eps_i(F_i(w))` with gradient and Hessian.
//!
//! `D` is the dimension: 2 (the z term is dropped) or 3. Every evaluation is
//! allocation-free and returns finite numbers for every finite point:
//!
//! - each term `|d_k/a_k|^p_k` saturates at [`TERM_MAX`] (its derivatives are then 0, the
//!   derivatives of the saturated function), so `F <= 3 TERM_MAX`;
//! - at `d_k = 0` the first derivative is 0 (for `p_k <= 1` the cusp's subgradient 0); for
//!   `p_k < 2`, where `|r|^p` has an unbounded second derivative (and for `p_k < 1` an
//!   unbounded first one) at `r = 0`, the derivatives use `max(|r|, R_FLOOR)`, so they are
//!   those of the exact function everywhere except within `1e-30` semi-axes of the
//!   threat's mid-planes;
//! - `eps` is evaluated in the overflow-free logistic form with `1 - eps` computed
//!   directly, so its derivatives are exact deep inside and far outside.

use nalgebra::SMatrix;
use thiserror::Error;

/// Most static threats a [`ThreatLayout`] holds.
pub const MAX_THREATS: usize = 16;

/// Largest value of one term `|d_k/a_k|^p_k` (saturation keeps `F` finite).
pub const TERM_MAX: f64 = 1e300;

/// Below this `|d_k/a_k|`, the derivatives of a term with exponent `< 2` are evaluated at
/// the floor (see the module documentation).
pub const R_FLOOR: f64 = 1e-30;

/// Bound on `1 - eps` of a threat skipped by the bounding-box cut-off. Skipping a threat
/// whose `1 - eps <= CUTOFF_DELTA` changes `E` by at most `CUTOFF_DELTA` (the product of
/// the other `eps` is at most 1), so a layout of up to 100 threats (16 static plus the
/// moving ones) changes by less than `1e-12`.
pub const CUTOFF_DELTA: f64 = 1e-14;

/// Bad threat or layout parameters.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ThreatError {
    /// A parameter that must be finite is not.
    #[error("threat {field} must be finite, got {value}")]
    NotFinite {
        /// Parameter name.
        field: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A parameter that must be finite and positive is not.
    #[error("threat {field} must be finite and positive, got {value}")]
    NotPositive {
        /// Parameter name.
        field: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// The layout already holds [`MAX_THREATS`] threats.
    #[error("threat layout is full ({capacity} threats)")]
    LayoutFull {
        /// Capacity of the layout.
        capacity: usize,
    },
}

/// A value with its gradient and Hessian with respect to position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eval<const D: usize> {
    /// The value.
    pub value: f64,
    /// Gradient with respect to the position `w`.
    pub grad: [f64; D],
    /// Hessian with respect to `w` (symmetric).
    pub hess: SMatrix<f64, D, D>,
}

impl<const D: usize> Eval<D> {
    /// Zero value, gradient and Hessian.
    pub fn zero() -> Self {
        Self {
            value: 0.0,
            grad: [0.0; D],
            hess: SMatrix::zeros(),
        }
    }
}

/// `|r|^p` and its first and second derivatives with respect to `r`, finite for every
/// finite `r` and `p > 0` (see the module documentation for the floor and saturation).
#[inline]
pub(crate) fn pow_abs(r: f64, p: f64) -> (f64, f64, f64) {
    if p == 2.0 {
        let t = r * r;
        return if t <= TERM_MAX {
            (t, 2.0 * r, 2.0)
        } else {
            (TERM_MAX, 0.0, 0.0)
        };
    }
    let a = r.abs();
    let floored = p < 2.0 && a < R_FLOOR;
    let ad = if floored { R_FLOOR } else { a };
    let q = ad.powf(p - 2.0);
    let t = if floored { a.powf(p) } else { q * a * a };
    if t.is_nan() || t > TERM_MAX {
        return (TERM_MAX, 0.0, 0.0);
    }
    let sgn = if r > 0.0 {
        1.0
    } else if r < 0.0 {
        -1.0
    } else {
        0.0
    };
    (t, sgn * p * q * ad, p * (p - 1.0) * q)
}

/// Exposure of one threat, eq. (5.4) with `eps_max = 1`:
/// `eps(F) = 1 / (1 + exp(-s (F - 1)))` (0 deep inside, 1 far outside).
#[inline]
pub fn eps(f: f64, stiffness: f64) -> f64 {
    eps_derivs(f, stiffness).eps
}

/// `eps(F)` with `1 - eps` (computed directly, not by subtraction) and the derivatives
/// with respect to `F`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpsDerivs {
    /// `eps(F)`.
    pub eps: f64,
    /// `1 - eps(F)`, accurate when `eps` is close to 1.
    pub one_minus: f64,
    /// `d eps / dF = s eps (1 - eps)`.
    pub d1: f64,
    /// `d² eps / dF² = s² eps (1 - eps)(1 - 2 eps)`.
    pub d2: f64,
}

/// `eps(F)`, `1 - eps(F)` and the first two derivatives with respect to `F`. Finite for
/// every `F` and `s` whose product is not NaN.
#[inline]
pub fn eps_derivs(f: f64, stiffness: f64) -> EpsDerivs {
    let x = stiffness * (f - 1.0);
    let (eps, one_minus) = if x >= 0.0 {
        let e = (-x).exp();
        (1.0 / (1.0 + e), e / (1.0 + e))
    } else {
        let e = x.exp();
        (e / (1.0 + e), 1.0 / (1.0 + e))
    };
    let d1 = stiffness * eps * one_minus;
    EpsDerivs {
        eps,
        one_minus,
        d1,
        d2: stiffness * d1 * (one_minus - eps),
    }
}

/// `F` above which `1 - eps(F) <= CUTOFF_DELTA`: `1 + ln(1/CUTOFF_DELTA)/s`
/// (`1 - eps = e^-x/(1+e^-x) < e^-x` with `x = s(F-1)`).
#[inline]
pub fn cutoff_f(stiffness: f64) -> f64 {
    1.0 + (1.0 / CUTOFF_DELTA).ln() / stiffness
}

/// A superquadric threat: centre `c`, yaw `theta` of its local x-axis (counter-clockwise
/// from +x), semi-axes `a` and exponents `p`, one per axis (FORMULATION.md §3):
/// `F(w) = sum_k |d_k / a_k|^p_k`, `d = R(theta)^T (w - c)` (the yaw turns x and y only).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Superquadric<const D: usize> {
    center: [f64; D],
    axes: [f64; D],
    exponents: [f64; D],
    yaw: f64,
    cos_yaw: f64,
    sin_yaw: f64,
    inv_axes: [f64; D],
}

/// A 2-D threat (the z term dropped).
pub type Threat2 = Superquadric<2>;
/// A 3-D threat.
pub type Threat3 = Superquadric<3>;

impl<const D: usize> Superquadric<D> {
    /// A threat, checked: finite centre and yaw, finite positive axes and exponents.
    pub fn new(
        center: [f64; D],
        axes: [f64; D],
        exponents: [f64; D],
        yaw: f64,
    ) -> Result<Self, ThreatError> {
        for &v in &center {
            if !v.is_finite() {
                return Err(ThreatError::NotFinite {
                    field: "center",
                    value: v,
                });
            }
        }
        if !yaw.is_finite() {
            return Err(ThreatError::NotFinite {
                field: "yaw",
                value: yaw,
            });
        }
        for (field, vals) in [("axes", &axes), ("exponents", &exponents)] {
            for &v in vals {
                if !(v.is_finite() && v > 0.0) {
                    return Err(ThreatError::NotPositive { field, value: v });
                }
            }
        }
        Ok(Self::new_unchecked(center, axes, exponents, yaw))
    }

    /// An ellipsoid (all exponents 2) without yaw.
    pub fn ellipsoid(center: [f64; D], axes: [f64; D]) -> Result<Self, ThreatError> {
        Self::new(center, axes, [2.0; D], 0.0)
    }

    /// Builds without checks (the caller guarantees what [`Superquadric::new`] checks).
    #[inline]
    pub(crate) fn new_unchecked(
        center: [f64; D],
        axes: [f64; D],
        exponents: [f64; D],
        yaw: f64,
    ) -> Self {
        const { assert!(D == 2 || D == 3, "threats are 2-D or 3-D") };
        let (sin_yaw, cos_yaw) = yaw.sin_cos();
        Self {
            center,
            axes,
            exponents,
            yaw,
            cos_yaw,
            sin_yaw,
            inv_axes: axes.map(|a| 1.0 / a),
        }
    }

    /// Centre `c`.
    pub fn center(&self) -> &[f64; D] {
        &self.center
    }
    /// Semi-axes `a`.
    pub fn axes(&self) -> &[f64; D] {
        &self.axes
    }
    /// Exponents `p`.
    pub fn exponents(&self) -> &[f64; D] {
        &self.exponents
    }
    /// Yaw `theta`, rad.
    pub fn yaw(&self) -> f64 {
        self.yaw
    }

    /// The point in the threat's frame, `d = R(theta)^T (w - c)`.
    #[inline]
    pub fn local(&self, w: &[f64; D]) -> [f64; D] {
        let mut d: [f64; D] = std::array::from_fn(|k| w[k] - self.center[k]);
        let (dx, dy) = (d[0], d[1]);
        d[0] = self.cos_yaw * dx + self.sin_yaw * dy;
        d[1] = -self.sin_yaw * dx + self.cos_yaw * dy;
        d
    }

    /// The inside–outside function `F(w)` (< 1 inside, 1 on the surface, > 1 outside).
    #[inline]
    pub fn f(&self, w: &[f64; D]) -> f64 {
        let d = self.local(w);
        let mut f = 0.0;
        for ((dk, ia), &p) in d.iter().zip(&self.inv_axes).zip(&self.exponents) {
            let r = dk * ia;
            f += if p == 2.0 {
                (r * r).min(TERM_MAX)
            } else {
                pow_abs(r, p).0
            };
        }
        f
    }

    /// `F(w)` and its gradient with respect to `w`.
    #[inline]
    pub fn f_grad(&self, w: &[f64; D]) -> (f64, [f64; D]) {
        let d = self.local(w);
        let mut f = 0.0;
        let mut gl = [0.0; D];
        for k in 0..D {
            let (t, d1, _) = pow_abs(d[k] * self.inv_axes[k], self.exponents[k]);
            f += t;
            gl[k] = d1 * self.inv_axes[k];
        }
        (f, self.rotate_to_world(gl))
    }

    /// `F(w)` with gradient and Hessian with respect to `w`.
    #[inline]
    pub fn f_grad_hess(&self, w: &[f64; D]) -> Eval<D> {
        let d = self.local(w);
        let mut f = 0.0;
        let mut gl = [0.0; D];
        let mut hl = [0.0; D];
        for k in 0..D {
            let ia = self.inv_axes[k];
            let (t, d1, d2) = pow_abs(d[k] * ia, self.exponents[k]);
            f += t;
            gl[k] = d1 * ia;
            hl[k] = d2 * ia * ia;
        }
        let (c, s) = (self.cos_yaw, self.sin_yaw);
        let mut hess = SMatrix::<f64, D, D>::zeros();
        hess[(0, 0)] = c * c * hl[0] + s * s * hl[1];
        hess[(1, 1)] = s * s * hl[0] + c * c * hl[1];
        let hxy = c * s * (hl[0] - hl[1]);
        hess[(0, 1)] = hxy;
        hess[(1, 0)] = hxy;
        for k in 2..D {
            hess[(k, k)] = hl[k];
        }
        Eval {
            value: f,
            grad: self.rotate_to_world(gl),
            hess,
        }
    }

    /// Rotates a local-frame vector to the world frame (`R(theta) v`).
    #[inline]
    pub(crate) fn rotate_to_world(&self, mut v: [f64; D]) -> [f64; D] {
        let (x, y) = (v[0], v[1]);
        v[0] = self.cos_yaw * x - self.sin_yaw * y;
        v[1] = self.sin_yaw * x + self.cos_yaw * y;
        v
    }

    /// Half-extents of an axis-aligned box around the centre outside which `F >= f_cut`
    /// (`f_cut >= 1`): the local box `|d_k| < a_k f_cut^(1/p_k)` contains `{F < f_cut}`
    /// because each term alone reaches `f_cut` on its faces, and the yawed box lies in the
    /// world box with half-extents `|cos| h_x + |sin| h_y`, `|sin| h_x + |cos| h_y`, `h_z`.
    /// With `conservative`, exponents `>= 2` use `sqrt(f_cut) >= f_cut^(1/p)` (no `powf`).
    #[inline]
    pub fn cutoff_half_extents(&self, f_cut: f64, conservative: bool) -> [f64; D] {
        let root = |p: f64| {
            if p == 2.0 || (conservative && p > 2.0) {
                f_cut.sqrt()
            } else {
                f_cut.powf(1.0 / p)
            }
        };
        let h: [f64; D] = std::array::from_fn(|k| self.axes[k] * root(self.exponents[k]));
        let (c, s) = (self.cos_yaw.abs(), self.sin_yaw.abs());
        let mut out = h;
        out[0] = c * h[0] + s * h[1];
        out[1] = s * h[0] + c * h[1];
        out
    }

    /// True when `w` lies outside the box of [`Superquadric::cutoff_half_extents`].
    #[inline]
    pub(crate) fn outside_box(&self, w: &[f64; D], half: &[f64; D]) -> bool {
        (0..D).any(|k| (w[k] - self.center[k]).abs() >= half[k])
    }
}

/// Running product `P = prod eps_i` and `E = 1 - P` with derivatives, folded one threat at
/// a time by the product rule (no division, so `eps_i = 0` is harmless):
///
/// ```text
/// E' = E + (1 - eps) P         P' = eps P
/// dE' = eps dE - P d eps
/// d²E' = eps d²E + dE d epsᵀ + d eps dEᵀ - P d²eps
/// d eps = eps'(F) dF,   d²eps = eps''(F) dF dFᵀ + eps'(F) d²F
/// ```
///
/// `E` is kept directly (not as `1 - P`), so it stays accurate when it is tiny.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExposureAcc<const D: usize> {
    /// `E`, its gradient and Hessian so far.
    pub e: Eval<D>,
    /// `P = 1 - E` so far.
    pub prod: f64,
}

impl<const D: usize> Default for ExposureAcc<D> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const D: usize> ExposureAcc<D> {
    /// No threat yet: `E = 0`, `P = 1`.
    pub fn new() -> Self {
        Self {
            e: Eval::zero(),
            prod: 1.0,
        }
    }

    /// Folds a threat given only its `F` (value only; the derivatives are left untouched,
    /// so do not mix with the other `fold_*` on one accumulator).
    #[inline]
    pub fn fold_value(&mut self, f: f64, stiffness: f64) {
        let ed = eps_derivs(f, stiffness);
        self.e.value += ed.one_minus * self.prod;
        self.prod *= ed.eps;
    }

    /// Folds a threat given `F` and its gradient (Hessian untouched).
    #[inline]
    pub fn fold_grad(&mut self, f: f64, grad_f: &[f64; D], stiffness: f64) {
        let ed = eps_derivs(f, stiffness);
        for (g, gf) in self.e.grad.iter_mut().zip(grad_f) {
            *g = ed.eps * *g - self.prod * ed.d1 * gf;
        }
        self.e.value += ed.one_minus * self.prod;
        self.prod *= ed.eps;
    }

    /// Folds a threat given `F` with gradient and Hessian.
    #[inline]
    pub fn fold(&mut self, f: &Eval<D>, stiffness: f64) {
        let ed = eps_derivs(f.value, stiffness);
        let de: [f64; D] = std::array::from_fn(|k| ed.d1 * f.grad[k]);
        for i in 0..D {
            for j in 0..D {
                let d2eps = ed.d2 * f.grad[i] * f.grad[j] + ed.d1 * f.hess[(i, j)];
                self.e.hess[(i, j)] =
                    ed.eps * self.e.hess[(i, j)] + self.e.grad[i] * de[j] + de[i] * self.e.grad[j]
                        - self.prod * d2eps;
            }
        }
        for (g, dek) in self.e.grad.iter_mut().zip(&de) {
            *g = ed.eps * *g - self.prod * dek;
        }
        self.e.value += ed.one_minus * self.prod;
        self.prod *= ed.eps;
    }
}

/// A layout of up to [`MAX_THREATS`] static threats with the exposure stiffness `s`, in
/// fixed-capacity storage (`Copy`, no heap), with each threat's cut-off box precomputed.
///
/// Evaluations skip a threat when the point lies outside its box, where
/// `F >= cutoff_f(s)` and so `1 - eps <= CUTOFF_DELTA`: `E` changes by at most
/// `CUTOFF_DELTA` per skipped threat (< 1e-12 in total), its gradient by at most
/// `s · CUTOFF_DELTA · |grad F|` per skipped threat.
#[derive(Debug, Clone, Copy)]
pub struct ThreatLayout<const D: usize> {
    threats: [Superquadric<D>; MAX_THREATS],
    boxes: [[f64; D]; MAX_THREATS],
    len: usize,
    stiffness: f64,
    f_cut: f64,
}

impl<const D: usize> ThreatLayout<D> {
    /// An empty layout with stiffness `s` (finite, positive).
    pub fn new(stiffness: f64) -> Result<Self, ThreatError> {
        if !(stiffness.is_finite() && stiffness > 0.0) {
            return Err(ThreatError::NotPositive {
                field: "stiffness",
                value: stiffness,
            });
        }
        let placeholder = Superquadric::new_unchecked([0.0; D], [1.0; D], [2.0; D], 0.0);
        Ok(Self {
            threats: [placeholder; MAX_THREATS],
            boxes: [[0.0; D]; MAX_THREATS],
            len: 0,
            stiffness,
            f_cut: cutoff_f(stiffness),
        })
    }

    /// A layout holding `threats` (at most [`MAX_THREATS`]).
    pub fn with_threats(stiffness: f64, threats: &[Superquadric<D>]) -> Result<Self, ThreatError> {
        let mut layout = Self::new(stiffness)?;
        for t in threats {
            layout.push(*t)?;
        }
        Ok(layout)
    }

    /// Adds a threat; fails when the layout is full.
    pub fn push(&mut self, threat: Superquadric<D>) -> Result<(), ThreatError> {
        if self.len == MAX_THREATS {
            return Err(ThreatError::LayoutFull {
                capacity: MAX_THREATS,
            });
        }
        self.threats[self.len] = threat;
        self.boxes[self.len] = threat.cutoff_half_extents(self.f_cut, false);
        self.len += 1;
        Ok(())
    }

    /// Removes every threat.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// The threats.
    pub fn threats(&self) -> &[Superquadric<D>] {
        &self.threats[..self.len]
    }

    /// Number of threats.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when the layout holds no threat.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The stiffness `s`.
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// `F` beyond which a threat is skipped ([`cutoff_f`] of the stiffness).
    pub fn cutoff_f(&self) -> f64 {
        self.f_cut
    }

    /// True when threat `i` is skipped at `w` by the cut-off (false for a bad index).
    pub fn is_cut_off(&self, i: usize, w: &[f64; D]) -> bool {
        i < self.len && self.threats[i].outside_box(w, &self.boxes[i])
    }

    #[inline]
    fn near<'a>(&'a self, w: &'a [f64; D]) -> impl Iterator<Item = &'a Superquadric<D>> + 'a {
        self.threats[..self.len]
            .iter()
            .zip(&self.boxes[..self.len])
            .filter(move |(t, b)| !t.outside_box(w, b))
            .map(|(t, _)| t)
    }

    /// Folds the near threats' exposure at `w` into `acc` (value only).
    #[inline]
    pub fn fold_value_into(&self, w: &[f64; D], acc: &mut ExposureAcc<D>) {
        for t in self.near(w) {
            acc.fold_value(t.f(w), self.stiffness);
        }
    }

    /// Folds the near threats' exposure at `w` into `acc` (value and gradient).
    #[inline]
    pub fn fold_grad_into(&self, w: &[f64; D], acc: &mut ExposureAcc<D>) {
        for t in self.near(w) {
            let (f, g) = t.f_grad(w);
            acc.fold_grad(f, &g, self.stiffness);
        }
    }

    /// Folds the near threats' exposure at `w` into `acc` (value, gradient, Hessian).
    #[inline]
    pub fn fold_into(&self, w: &[f64; D], acc: &mut ExposureAcc<D>) {
        for t in self.near(w) {
            acc.fold(&t.f_grad_hess(w), self.stiffness);
        }
    }

    /// Layout exposure `E(w) = 1 - prod_i eps_i(F_i(w))` (FORMULATION.md §3).
    #[inline]
    pub fn exposure(&self, w: &[f64; D]) -> f64 {
        let mut acc = ExposureAcc::new();
        self.fold_value_into(w, &mut acc);
        acc.e.value
    }

    /// `E(w)` and its gradient.
    #[inline]
    pub fn exposure_grad(&self, w: &[f64; D]) -> (f64, [f64; D]) {
        let mut acc = ExposureAcc::new();
        self.fold_grad_into(w, &mut acc);
        (acc.e.value, acc.e.grad)
    }

    /// `E(w)` with gradient and Hessian.
    #[inline]
    pub fn exposure_hess(&self, w: &[f64; D]) -> Eval<D> {
        let mut acc = ExposureAcc::new();
        self.fold_into(w, &mut acc);
        acc.e
    }
}
