//! The Kalman filter of the distance along the road (eqs. 6.4, 6.12).

use nalgebra::{Matrix3, Vector3};

use super::EstimationError;
use super::gauss_markov::{Discrete, Estimate, GaussMarkov};
use super::road::Road;

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
