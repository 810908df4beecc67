//! The moving, stochastic threat of FORMULATION.md §5 (chapter VI, appendix D): the road
//! polyline, the first-order Gauss–Markov acceleration model along it (eq. 6.3), its
//! discretisation by Van Loan's matrix exponential, the Kalman filter (eqs. 6.4, 6.11,
//! 6.12), the propagated mean and covariance, and the inflated keep-out region
//! (eqs. 6.5, 6.6, 6.10) with `F`, its derivatives in position and its time derivative.
//!
//! Everything after construction is allocation-free. Operations whose input can be bad
//! (a negative time step, a non-finite fix) return `Result`; pure evaluations do not.

mod expm;
mod gauss_markov;
mod kalman;
mod moving_threat;
mod road;

pub use expm::expm;
pub use gauss_markov::{Discrete, DistanceStats, Estimate, GaussMarkov};
pub use kalman::{Innovation, KalmanFilter};
pub use moving_threat::{
    MovingEval, MovingThreat, Region, TabledRegion, exposure_at, exposure_eval_at, tabulate,
};
pub use road::{Road, RoadPoint};

use thiserror::Error;

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
