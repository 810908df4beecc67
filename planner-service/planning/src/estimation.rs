//! The moving, stochastic threat of FORMULATION.md §5 (chapter VI, appendix D): the road
//! polyline, the first-order Gauss–Markov acceleration model along it (eq. 6.3), its
//! discretisation by Van Loan's matrix exponential, the Kalman filter (eqs. 6.4, 6.11,
//! 6.12), the propagated mean and covariance, and the inflated keep-out region
//! (eqs. 6.5, 6.6, 6.10) with `F`, its derivatives in position and its time derivative.
//!
//! Everything after construction is allocation-free. Operations whose input can be bad
//! (a negative time step, a non-finite fix) return `Result`; pure evaluations do not.

mod expm;

pub use expm::expm;

use nalgebra::{Matrix3, SMatrix, Vector3};
use thiserror::Error;

use crate::threat::{Eval, Superquadric, pow_abs};

/// Most points of a road polyline (the interface's capacity).
pub const MAX_ROAD_POINTS: usize = wingman_interfaces::MAX_ROAD_POINTS;

/// Longest propagation of an estimate, s (about 31 years): beyond it the closed-form
/// statistics are held, so they stay finite for every finite time.
pub const MAX_HORIZON: f64 = 1e9;

/// Bad input to the estimation code.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum EstimationError {
    /// A road needs at least two points.
    #[error("a road needs at least 2 points, got {got}")]
    RoadTooShort {
        /// Given count.
        got: usize,
    },
    /// A road holds more points than [`MAX_ROAD_POINTS`].
    #[error("a road holds at most {max} points, got {got}")]
    RoadTooLong {
        /// Given count.
        got: usize,
        /// Capacity.
        max: usize,
    },
    /// Two consecutive road points do not differ horizontally (the road's yaw is undefined).
    #[error("road points {index} and {next} do not differ horizontally", next = index + 1)]
    DegenerateSegment {
        /// Index of the segment's first point.
        index: usize,
    },
    /// A value that must be finite is not.
    #[error("{field} must be finite")]
    NotFinite {
        /// Name of the value.
        field: &'static str,
    },
    /// A value that must be finite and positive is not.
    #[error("{field} must be finite and positive, got {value}")]
    NotPositive {
        /// Name of the value.
        field: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A covariance with a negative diagonal entry.
    #[error("covariance has a negative variance on its diagonal")]
    NegativeVariance,
    /// A time step that is negative or not finite.
    #[error("time step must be finite and non-negative, got {dt}")]
    BadTimeStep {
        /// The rejected step.
        dt: f64,
    },
    /// A result that is not finite (e.g. a step so long the covariance overflows).
    #[error("numerical failure: {what}")]
    Numerical {
        /// What failed.
        what: &'static str,
    },
}

// -------------------------------------------------------------------------------------------
// Road
// -------------------------------------------------------------------------------------------

/// A point on the road with the road's direction there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoadPoint<const D: usize> {
    /// Position.
    pub point: [f64; D],
    /// Yaw of the segment (horizontal direction, counter-clockwise from +x), rad.
    pub yaw: f64,
    /// Unit tangent of the segment (with its vertical part in 3-D).
    pub direction: [f64; D],
}

/// A road polyline of 2 to [`MAX_ROAD_POINTS`] points (fixed capacity, `Copy`).
///
/// Distance runs along the polyline (eq. 6.2, in all `D` coordinates) from its first
/// point; before the start and past the end the first and last segments are extended, as
/// `scenario.py` does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Road<const D: usize> {
    points: [[f64; D]; MAX_ROAD_POINTS],
    /// Distance at each point; `cum[0] = 0`.
    cum: [f64; MAX_ROAD_POINTS],
    len: usize,
}

impl<const D: usize> Road<D> {
    /// A road through `points`: 2 to [`MAX_ROAD_POINTS`] finite points, consecutive ones
    /// differing horizontally.
    pub fn new(points: &[[f64; D]]) -> Result<Self, EstimationError> {
        const { assert!(D == 2 || D == 3, "roads are 2-D or 3-D") };
        if points.len() < 2 {
            return Err(EstimationError::RoadTooShort { got: points.len() });
        }
        if points.len() > MAX_ROAD_POINTS {
            return Err(EstimationError::RoadTooLong {
                got: points.len(),
                max: MAX_ROAD_POINTS,
            });
        }
        if points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(EstimationError::NotFinite {
                field: "road point",
            });
        }
        let mut road = Self {
            points: [[0.0; D]; MAX_ROAD_POINTS],
            cum: [0.0; MAX_ROAD_POINTS],
            len: points.len(),
        };
        road.points[..points.len()].copy_from_slice(points);
        for k in 1..points.len() {
            let (a, b) = (&points[k - 1], &points[k]);
            if (b[0] - a[0]).hypot(b[1] - a[1]) <= 0.0 {
                return Err(EstimationError::DegenerateSegment { index: k - 1 });
            }
            road.cum[k] = road.cum[k - 1] + dist(a, b);
        }
        Ok(road)
    }

    /// The road's points.
    pub fn points(&self) -> &[[f64; D]] {
        &self.points[..self.len]
    }

    /// Length of the polyline.
    pub fn length(&self) -> f64 {
        self.cum[self.len - 1]
    }

    /// Segment holding distance `d`: the last `k` with `cum[k] <= d`, clamped to the
    /// segments (`searchsorted(..., side="right") - 1` clipped, as in `scenario.py`).
    #[inline]
    pub fn segment_at(&self, d: f64) -> usize {
        let nseg = self.len - 1;
        let mut k = 0;
        while k + 1 < nseg && self.cum[k + 1] <= d {
            k += 1;
        }
        k
    }

    /// The point at distance `d` along the road (extrapolated past the ends) with the yaw
    /// and unit tangent of its segment.
    #[inline]
    pub fn point_at(&self, d: f64) -> RoadPoint<D> {
        let k = self.segment_at(d);
        let (a, b) = (&self.points[k], &self.points[k + 1]);
        let l = self.cum[k + 1] - self.cum[k];
        let frac = (d - self.cum[k]) / l;
        RoadPoint {
            point: std::array::from_fn(|i| a[i] + frac * (b[i] - a[i])),
            yaw: (b[1] - a[1]).atan2(b[0] - a[0]),
            direction: std::array::from_fn(|i| (b[i] - a[i]) / l),
        }
    }

    /// Distance along the road of the road point nearest to `w` (the first and last
    /// segments extended past the ends): the table look-up of a sensor fix (dissertation
    /// §6.3.2; docs/FORMULATION.md §5).
    pub fn project(&self, w: &[f64; D]) -> f64 {
        let nseg = self.len - 1;
        let mut best = (f64::INFINITY, 0.0);
        for k in 0..nseg {
            let (a, b) = (&self.points[k], &self.points[k + 1]);
            let seg: [f64; D] = std::array::from_fn(|i| b[i] - a[i]);
            let rel: [f64; D] = std::array::from_fn(|i| w[i] - a[i]);
            let l2: f64 = seg.iter().map(|v| v * v).sum();
            let mut t = seg.iter().zip(&rel).map(|(s, r)| s * r).sum::<f64>() / l2;
            if k > 0 {
                t = t.max(0.0);
            }
            if k + 1 < nseg {
                t = t.min(1.0);
            }
            let d2: f64 = (0..D).map(|i| (rel[i] - t * seg[i]).powi(2)).sum();
            if d2 < best.0 {
                best = (d2, self.cum[k] + t * (self.cum[k + 1] - self.cum[k]));
            }
        }
        best.1
    }
}

fn dist<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (y - x) * (y - x))
        .sum::<f64>()
        .sqrt()
}

// -------------------------------------------------------------------------------------------
// Gauss–Markov model
// -------------------------------------------------------------------------------------------

/// `(1 - e^-x)/x`, accurate for small `x` (1 at 0).
#[inline]
fn e1(x: f64) -> f64 {
    if x == 0.0 { 1.0 } else { -(-x).exp_m1() / x }
}

/// `(x - 1 + e^-x)/x²`, accurate for small `x` (series below 0.5, 1/2 at 0).
#[inline]
fn e2(x: f64) -> f64 {
    if x.abs() < 0.5 {
        // sum_k (-x)^k / (k+2)!
        let mut term = 0.5;
        let mut sum = 0.5;
        for k in 1..20 {
            term *= -x / (k as f64 + 2.0);
            sum += term;
        }
        sum
    } else {
        (x + (-x).exp_m1()) / (x * x)
    }
}

/// Coefficients `c_n = sum_{k=0..n} 1/((k+2)! (n-k+2)!)` of `e2(y)^2 = sum_n c_n (-y)^n`.
const E2SQ: [f64; 24] = e2sq_coeffs();

const fn e2sq_coeffs() -> [f64; 24] {
    let mut inv_fact = [0.0; 28];
    inv_fact[0] = 1.0;
    let mut i = 1;
    while i < 28 {
        inv_fact[i] = inv_fact[i - 1] / i as f64;
        i += 1;
    }
    let mut c = [0.0; 24];
    let mut n = 0;
    while n < 24 {
        let mut k = 0;
        while k <= n {
            c[n] += inv_fact[k + 2] * inv_fact[n - k + 2];
            k += 1;
        }
        n += 1;
    }
    c
}

/// `Qd_11(s) / (q s^5)` as a function of `x = beta s`:
/// `int_0^1 u^4 e2(x u)^2 du`, by its series below `x = 1` and by the closed form of
/// `scenario.py` (`h(x)/x^5`) above.
#[inline]
fn qd11_scaled(x: f64) -> f64 {
    if x < 1.0 {
        let mut sum = 0.0;
        let mut pow = 1.0;
        for (n, c) in E2SQ.iter().enumerate() {
            sum += c * pow / (n as f64 + 5.0);
            pow *= -x;
        }
        sum
    } else {
        let h =
            ((x - 1.0).powi(3) + 1.0) / 3.0 - 2.0 * x * (-x).exp() + 0.5 * (1.0 - (-2.0 * x).exp());
        h / x.powi(5)
    }
}

/// The first-order Gauss–Markov acceleration model of the distance along the road,
/// state `(d, v, a)`, `a' = -a/tau + w`, white-noise strength `q = 2 sigma_a^2 / tau`
/// (FORMULATION.md §5, eq. 6.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussMarkov {
    tau: f64,
    sigma_a: f64,
}

/// Transition and process-noise covariance of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Discrete {
    /// `Phi(dt)`.
    pub phi: Matrix3<f64>,
    /// `Qd(dt) = int_0^dt Phi(s) G q G^T Phi(s)^T ds`.
    pub qd: Matrix3<f64>,
}

impl GaussMarkov {
    /// A model with correlation time `tau > 0` and acceleration standard deviation
    /// `sigma_a >= 0` (both finite).
    pub fn new(tau: f64, sigma_a: f64) -> Result<Self, EstimationError> {
        if !(tau.is_finite() && tau > 0.0) {
            return Err(EstimationError::NotPositive {
                field: "tau",
                value: tau,
            });
        }
        if !(sigma_a.is_finite() && sigma_a >= 0.0) {
            return Err(EstimationError::NotFinite { field: "sigma_a" });
        }
        Ok(Self { tau, sigma_a })
    }

    /// Correlation time `tau`.
    pub fn tau(&self) -> f64 {
        self.tau
    }

    /// `beta = 1/tau`.
    pub fn beta(&self) -> f64 {
        1.0 / self.tau
    }

    /// Standard deviation of the acceleration.
    pub fn sigma_a(&self) -> f64 {
        self.sigma_a
    }

    /// Continuous white-noise strength `q = 2 sigma_a^2 / tau`.
    pub fn q(&self) -> f64 {
        2.0 * self.sigma_a * self.sigma_a / self.tau
    }

    /// The continuous system matrix `A = [[0,1,0],[0,0,1],[0,0,-beta]]`.
    pub fn a_matrix(&self) -> Matrix3<f64> {
        Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -self.beta())
    }

    /// `Phi(dt)` in closed form (FORMULATION.md §5), evaluated without cancellation for
    /// small `beta dt`. Meant for `dt >= 0`.
    #[inline]
    pub fn phi(&self, dt: f64) -> Matrix3<f64> {
        let x = self.beta() * dt;
        Matrix3::new(
            1.0,
            dt,
            dt * dt * e2(x),
            0.0,
            1.0,
            dt * e1(x),
            0.0,
            0.0,
            (-x).exp(),
        )
    }

    /// `Phi(dt)` and `Qd(dt)` for a step `dt >= 0`.
    ///
    /// `Qd` comes from Van Loan's exponential of `[[-A, G q G^T], [0, A^T]] dt`
    /// (`Qd = Phi · E_12`), computed on the state scaled by `diag(dt², dt, 1)` so that every
    /// block is of order one (the entries of `Qd` span `dt^5 ... dt`; unscaled, the small
    /// ones would lose all their digits). For `beta dt > 1` the step is split into `2^k`
    /// steps with `beta h <= 1` and recombined exactly with
    /// `Qd(2h) = Phi(h) Qd(h) Phi(h)^T + Qd(h)`, which avoids the `e^(beta dt)` growth
    /// of the `-A` block. `Phi` is the closed form.
    pub fn discretize(&self, dt: f64) -> Result<Discrete, EstimationError> {
        if !(dt.is_finite() && dt >= 0.0) {
            return Err(EstimationError::BadTimeStep { dt });
        }
        if dt == 0.0 {
            return Ok(Discrete {
                phi: Matrix3::identity(),
                qd: Matrix3::zeros(),
            });
        }
        let beta = self.beta();
        let x = beta * dt;
        let halvings = if x > 1.0 { x.log2().ceil() as i32 } else { 0 };
        let mut h = dt * 2f64.powi(-halvings);
        let mut qd = self.van_loan_scaled(h)?;
        for _ in 0..halvings {
            let phi = self.phi(h);
            qd = phi * qd * phi.transpose() + qd;
            h *= 2.0;
        }
        let qd = 0.5 * (qd + qd.transpose());
        if qd.iter().any(|v| !v.is_finite()) {
            return Err(EstimationError::Numerical {
                what: "process noise overflows for this step",
            });
        }
        Ok(Discrete {
            phi: self.phi(dt),
            qd,
        })
    }

    /// Van Loan for one step `h` with `beta h <= 1`, on the scaled state.
    fn van_loan_scaled(&self, h: f64) -> Result<Matrix3<f64>, EstimationError> {
        let x = self.beta() * h;
        // Scaled system: A_hat = S^-1 A S h with S = diag(h², h, 1), noise e3 e3^T.
        let mut m = SMatrix::<f64, 6, 6>::zeros();
        // -A_hat
        m[(0, 1)] = -1.0;
        m[(1, 2)] = -1.0;
        m[(2, 2)] = x;
        // noise block
        m[(2, 5)] = 1.0;
        // A_hat^T
        m[(4, 3)] = 1.0;
        m[(5, 4)] = 1.0;
        m[(5, 5)] = -x;
        let e = expm(&m).ok_or(EstimationError::Numerical {
            what: "matrix exponential",
        })?;
        let phi_hat: Matrix3<f64> = e.fixed_view::<3, 3>(3, 3).transpose();
        let e12: Matrix3<f64> = e.fixed_view::<3, 3>(0, 3).into_owned();
        let q_hat = phi_hat * e12;
        let s = Vector3::new(h * h, h, 1.0);
        let scale = self.q() * h;
        Ok(Matrix3::from_fn(|i, j| scale * s[i] * s[j] * q_hat[(i, j)]))
    }

    /// Mean, variance and their rates of the distance `d` at time `t` propagated from
    /// `est` without measurements, in closed form (any `t`; before `est.t` the estimate
    /// itself, with zero rates):
    ///
    /// ```text
    /// d(s)   = [Phi(s) x]_1,             d'(s)  = [Phi(s) x]_2
    /// P11(s) = r0^T P r0 + Qd_11(s),     P11'(s) = 2 r1^T P r0 + q Phi_13(s)^2
    /// ```
    ///
    /// with `s = t - est.t`, `r0, r1` the first two rows of `Phi(s)` and `Qd_11` the closed
    /// form of `scenario.py`'s `var_d` (its series for `beta s < 1`).
    ///
    /// The horizon is capped at [`MAX_HORIZON`] (a NaN time counts as `est.t`), so every
    /// finite input gives finite statistics.
    #[inline]
    pub fn distance_at(&self, est: &Estimate, t: f64) -> DistanceStats {
        let ds = t - est.t;
        let s = if ds > 0.0 { ds.min(MAX_HORIZON) } else { 0.0 };
        let beta = self.beta();
        let x = beta * s;
        let phi13 = s * s * e2(x);
        let phi23 = s * e1(x);
        let m = &est.mean;
        let r0 = Vector3::new(1.0, s, phi13);
        let r1 = Vector3::new(0.0, 1.0, phi23);
        let p = &est.cov;
        let pr0 = p * r0;
        let q = self.q();
        let s5 = s * s * s * s * s;
        let moving = t > est.t && t - est.t < MAX_HORIZON;
        DistanceStats {
            mean: m[0] + s * m[1] + phi13 * m[2],
            rate: m[1] + phi23 * m[2],
            var: r0.dot(&pr0) + q * s5 * qd11_scaled(x),
            var_rate: if moving {
                2.0 * r1.dot(&pr0) + q * phi13 * phi13
            } else {
                0.0
            },
        }
    }

    /// The estimate propagated to `t >= est.t` by `Phi`, `Qd` (eq. 6.4, one step).
    pub fn propagate(&self, est: &Estimate, t: f64) -> Result<Estimate, EstimationError> {
        let dt = t - est.t;
        let dis = self.discretize(dt)?;
        Ok(est.stepped(&dis, t))
    }

    /// Fills `out` with the estimate at `est.t + k dt` (`out[0] = *est`), propagated in
    /// steps of `dt` without measurements (`scenario.py`'s `kf_propagate`).
    pub fn propagate_horizon(
        &self,
        est: &Estimate,
        dt: f64,
        out: &mut [Estimate],
    ) -> Result<(), EstimationError> {
        let dis = self.discretize(dt)?;
        let mut cur = *est;
        for (k, slot) in out.iter_mut().enumerate() {
            if k > 0 {
                cur = cur.stepped(&dis, est.t + k as f64 * dt);
            }
            *slot = cur;
        }
        Ok(())
    }
}

/// Distance statistics of a propagated estimate ([`GaussMarkov::distance_at`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceStats {
    /// Mean distance along the road.
    pub mean: f64,
    /// Its time derivative (the propagated speed).
    pub rate: f64,
    /// Variance `P_11`.
    pub var: f64,
    /// Time derivative of `P_11`.
    pub var_rate: f64,
}

/// A Gaussian estimate of `(d, v, a)` at time `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Time of the estimate.
    pub t: f64,
    /// Mean `(d, v, a)`.
    pub mean: Vector3<f64>,
    /// Covariance (symmetric, positive semi-definite).
    pub cov: Matrix3<f64>,
}

impl Estimate {
    /// An estimate, checked (finite, non-negative variances) and symmetrised.
    pub fn new(t: f64, mean: Vector3<f64>, cov: Matrix3<f64>) -> Result<Self, EstimationError> {
        if !t.is_finite() {
            return Err(EstimationError::NotFinite {
                field: "estimate time",
            });
        }
        if mean.iter().any(|v| !v.is_finite()) {
            return Err(EstimationError::NotFinite {
                field: "estimate mean",
            });
        }
        if cov.iter().any(|v| !v.is_finite()) {
            return Err(EstimationError::NotFinite {
                field: "estimate covariance",
            });
        }
        if (0..3).any(|i| cov[(i, i)] < 0.0) {
            return Err(EstimationError::NegativeVariance);
        }
        Ok(Self {
            t,
            mean,
            cov: 0.5 * (cov + cov.transpose()),
        })
    }

    /// An estimate with diagonal covariance `diag(sigma²)` (the scenario's
    /// `initial_sigma`).
    pub fn with_sigmas(t: f64, mean: [f64; 3], sigma: [f64; 3]) -> Result<Self, EstimationError> {
        Self::new(
            t,
            Vector3::from(mean),
            Matrix3::from_diagonal(&Vector3::from(sigma.map(|s| s * s))),
        )
    }

    #[inline]
    fn stepped(&self, dis: &Discrete, t: f64) -> Self {
        let cov = dis.phi * self.cov * dis.phi.transpose() + dis.qd;
        Self {
            t,
            mean: dis.phi * self.mean,
            cov: 0.5 * (cov + cov.transpose()),
        }
    }
}

// -------------------------------------------------------------------------------------------
// Kalman filter
// -------------------------------------------------------------------------------------------

/// Innovation of one measurement update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Innovation {
    /// `z - H x^-`.
    pub residual: f64,
    /// `H P^- H^T + R`.
    pub variance: f64,
}

/// Kalman filter of the distance along the road (eqs. 6.4, 6.12): predict with `Phi`,
/// `Qd`, update with a distance measurement (`H = [1, 0, 0]`, `R = sigma_meas²`).
/// Holds the last step's discretisation, so steps of a fixed sensor period cost no matrix
/// exponential. Allocation-free.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanFilter {
    model: GaussMarkov,
    meas_var: f64,
    est: Estimate,
    cache: Option<(f64, Discrete)>,
}

impl KalmanFilter {
    /// A filter starting from `initial`, with measurement standard deviation
    /// `meas_sigma > 0`.
    pub fn new(
        model: GaussMarkov,
        meas_sigma: f64,
        initial: Estimate,
    ) -> Result<Self, EstimationError> {
        if !(meas_sigma.is_finite() && meas_sigma > 0.0) {
            return Err(EstimationError::NotPositive {
                field: "meas_sigma",
                value: meas_sigma,
            });
        }
        Ok(Self {
            model,
            meas_var: meas_sigma * meas_sigma,
            est: initial,
            cache: None,
        })
    }

    /// The current estimate.
    pub fn estimate(&self) -> &Estimate {
        &self.est
    }

    /// The motion model.
    pub fn model(&self) -> &GaussMarkov {
        &self.model
    }

    /// Replaces the estimate (e.g. a new report of the threat).
    pub fn reset(&mut self, est: Estimate) {
        self.est = est;
    }

    /// Time update by `dt >= 0`, eq. (6.4): `x = Phi x`, `P = Phi P Phi^T + Qd`.
    pub fn predict(&mut self, dt: f64) -> Result<(), EstimationError> {
        let dis = match self.cache {
            Some((cdt, dis)) if cdt == dt => dis,
            _ => {
                let dis = self.model.discretize(dt)?;
                self.cache = Some((dt, dis));
                dis
            }
        };
        self.est = self.est.stepped(&dis, self.est.t + dt);
        Ok(())
    }

    /// Time update to the absolute time `t >= estimate().t`.
    pub fn predict_to(&mut self, t: f64) -> Result<(), EstimationError> {
        let dt = t - self.est.t;
        self.predict(dt)?;
        self.est.t = t;
        Ok(())
    }

    /// Measurement update with a distance `z` along the road, eq. (6.12), in Joseph form
    /// `P = (I - K H) P (I - K H)^T + K R K^T` (stays symmetric positive semi-definite).
    pub fn update(&mut self, z: f64) -> Result<Innovation, EstimationError> {
        if !z.is_finite() {
            return Err(EstimationError::NotFinite {
                field: "measurement",
            });
        }
        let p = self.est.cov;
        let s = p[(0, 0)] + self.meas_var;
        let k: Vector3<f64> = p.column(0) / s;
        let nu = z - self.est.mean[0];
        let mut ikh = Matrix3::<f64>::identity();
        for i in 0..3 {
            ikh[(i, 0)] -= k[i];
        }
        let cov: Matrix3<f64> = ikh * p * ikh.transpose() + k * k.transpose() * self.meas_var;
        self.est.mean += k * nu;
        self.est.cov = 0.5 * (cov + cov.transpose());
        Ok(Innovation {
            residual: nu,
            variance: s,
        })
    }

    /// Measurement update with a position fix `w`, projected on the road (dissertation §6.3.2;
    /// docs/FORMULATION.md §5).
    pub fn update_position<const D: usize>(
        &mut self,
        road: &Road<D>,
        w: &[f64; D],
    ) -> Result<Innovation, EstimationError> {
        if w.iter().any(|v| !v.is_finite()) {
            return Err(EstimationError::NotFinite {
                field: "position fix",
            });
        }
        self.update(road.project(w))
    }
}

// -------------------------------------------------------------------------------------------
// Moving threat
// -------------------------------------------------------------------------------------------

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

// -------------------------------------------------------------------------------------------
// Exposure with moving threats
// -------------------------------------------------------------------------------------------

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
