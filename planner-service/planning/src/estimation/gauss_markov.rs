//! The first-order Gauss–Markov acceleration model along the road (eq. 6.3), its exact
//! discretisation (closed forms, or Van Loan's matrix exponential), and the Gaussian
//! estimate of `(d, v, a)` it propagates.

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::{EstimationError, MAX_HORIZON, expm};

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
    pub(super) fn stepped(&self, dis: &Discrete, t: f64) -> Self {
        let cov = dis.phi * self.cov * dis.phi.transpose() + dis.qd;
        Self {
            t,
            mean: dis.phi * self.mean,
            cov: 0.5 * (cov + cov.transpose()),
        }
    }
}
