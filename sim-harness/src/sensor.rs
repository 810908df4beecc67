//! The onboard threat sensor: static threats known before take-off, pop-ups at their
//! `appears_at_s`, and moving threats driven along their road by a seeded Gauss–Markov
//! *truth* (the same model the planner's Kalman filter assumes): reported when they appear
//! with the propagated initial estimate (scenarios/FORMAT.md), then measured at `rate_hz`
//! with `sigma_m` Gaussian noise per axis. Pure and seeded: the same scenario gives the
//! same reports and fixes.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wingman_interfaces::{MAX_ROAD_POINTS, ThreatKind, ThreatReport, TrackFix, Wire};
use wingman_planning::estimation::{Estimate, EstimationError, GaussMarkov, Road};
use wingman_planning::scenario::{MovingThreatSpec, Scenario, StaticThreatSpec, messages};

/// A scenario's threat that the sensor cannot emulate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SensorError {
    #[error("moving threat `{name}`: {source}")]
    Estimation {
        name: String,
        source: EstimationError,
    },
    #[error("moving threat `{0}`: its road has more than {MAX_ROAD_POINTS} points")]
    Road(String),
}

/// What the sensor reports at one step. (A report is 656 bytes and a fix 72: the enum is
/// as large as a report, which costs nothing for the few outputs of a step.)
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum SensorOutput {
    Report(ThreatReport),
    Fix(TrackFix),
}

/// A standard normal sample (Box–Muller on two uniforms in (0, 1]).
pub fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// The true motion `(d, v, a)` of a moving threat along its road: the exact discrete
/// Gauss–Markov model on a fixed grid of `step` seconds, `x_{k+1} = Phi x_k + L z`,
/// `L L^T = Qd`, `z` standard normal from a seeded ChaCha8 stream.
#[derive(Debug, Clone)]
pub struct Truth {
    t: f64,
    x: Vector3<f64>,
    step: f64,
    phi: Matrix3<f64>,
    noise: Matrix3<f64>,
    rng: ChaCha8Rng,
}

impl Truth {
    /// The truth at `(d0, v0, 0)` at `t0`, advanced in steps of `step > 0`.
    pub fn new(
        model: &GaussMarkov,
        t0: f64,
        d0: f64,
        v0: f64,
        step: f64,
        seed: u64,
    ) -> Result<Truth, EstimationError> {
        let dis = model.discretize(step)?;
        // A square root of the process noise that survives its wide range of scales.
        let eig = SymmetricEigen::new(dis.qd);
        let sqrt_l = Matrix3::from_diagonal(&eig.eigenvalues.map(|l| l.max(0.0).sqrt()));
        Ok(Truth {
            t: t0,
            x: Vector3::new(d0, v0, 0.0),
            step,
            phi: dis.phi,
            noise: eig.eigenvectors * sqrt_l,
            rng: ChaCha8Rng::seed_from_u64(seed),
        })
    }

    /// Advances the truth over every grid step that ends by `t` (within half a step).
    pub fn advance_to(&mut self, t: f64) {
        while self.t + 0.5 * self.step <= t {
            let z = Vector3::new(
                standard_normal(&mut self.rng),
                standard_normal(&mut self.rng),
                standard_normal(&mut self.rng),
            );
            self.x = self.phi * self.x + self.noise * z;
            self.t += self.step;
        }
    }

    /// Time of the current truth state.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// The current `(d, v, a)`.
    pub fn state(&self) -> [f64; 3] {
        [self.x[0], self.x[1], self.x[2]]
    }
}

/// One moving threat as the sensor sees it.
#[derive(Debug, Clone)]
pub struct MovingSensor {
    pub id: u32,
    pub spec: MovingThreatSpec,
    pub road: Road<3>,
    pub truth: Truth,
    /// The report sent when the threat appears.
    pub report: ThreatReport,
    noise: ChaCha8Rng,
    reported: bool,
    next_fix: f64,
}

impl MovingSensor {
    /// True position on the road now.
    pub fn true_position(&self) -> [f64; 3] {
        self.road.point_at(self.truth.state()[0]).point
    }
}

/// The threat sensor of one mission.
#[derive(Debug, Clone)]
pub struct ThreatSensor {
    statics: Vec<(Option<f64>, ThreatReport, bool)>,
    movings: Vec<MovingSensor>,
    three_d: bool,
}

/// Truth grid step of the moving threats, s.
pub const TRUTH_STEP_S: f64 = 0.1;

impl ThreatSensor {
    /// The sensor of `sc`: threat ids 1.. for the static threats in file order, then the
    /// moving threats.
    pub fn new(sc: &Scenario) -> Result<ThreatSensor, SensorError> {
        let three_d = sc.dim() == 3;
        let t0 = sc.start.time_s;
        let statics = sc
            .threats
            .iter()
            .enumerate()
            .map(|(k, s)| (s.appears_at_s, static_report(k as u32 + 1, s), false))
            .collect::<Vec<_>>();
        let base = statics.len() as u32 + 1;
        let mut movings = Vec::new();
        for (k, m) in sc.moving_threats.iter().enumerate() {
            let err = |source| SensorError::Estimation {
                name: m.name.clone(),
                source,
            };
            if m.road_m.len() > MAX_ROAD_POINTS {
                return Err(SensorError::Road(m.name.clone()));
            }
            let road = Road::<3>::new(&m.road_m).map_err(err)?;
            let model = GaussMarkov::new(m.accel_tau_s, m.accel_sigma_mps2).map_err(err)?;
            let truth = Truth::new(
                &model,
                t0,
                m.initial_distance_m,
                m.initial_speed_mps,
                TRUTH_STEP_S,
                m.truth_seed,
            )
            .map_err(err)?;
            let initial = Estimate::with_sigmas(
                t0,
                [m.initial_distance_m, m.initial_speed_mps, 0.0],
                m.initial_sigma,
            )
            .map_err(err)?;
            let at = m.appears_at_s.max(t0);
            let estimate = model.propagate(&initial, at).map_err(err)?;
            let id = base + k as u32;
            let mut noise = ChaCha8Rng::seed_from_u64(m.truth_seed);
            // The sensor's noise is a stream of its own, apart from the truth's.
            noise.set_stream(1);
            movings.push(MovingSensor {
                id,
                report: moving_report(id, m, &estimate),
                spec: m.clone(),
                road,
                truth,
                noise,
                reported: false,
                next_fix: at + 1.0 / m.sensor.rate_hz,
            });
        }
        Ok(ThreatSensor {
            statics,
            movings,
            three_d,
        })
    }

    /// Advances the moving threats' truth to `t` and returns what the sensor reports at
    /// `t`: static threats known before take-off and pop-ups whose time has come (once),
    /// moving threats when they appear, and their fixes due by `t`.
    pub fn poll(&mut self, t: f64) -> Vec<SensorOutput> {
        let mut out = Vec::new();
        for (appears, report, sent) in &mut self.statics {
            if !*sent && appears.is_none_or(|a| a <= t + 1e-9) {
                *sent = true;
                let mut r = *report;
                r.appeared_at_s = appears.unwrap_or(0.0);
                out.push(SensorOutput::Report(r));
            }
        }
        for m in &mut self.movings {
            m.truth.advance_to(t);
            if !m.reported && m.spec.appears_at_s <= t + 1e-9 {
                m.reported = true;
                out.push(SensorOutput::Report(m.report));
            }
            while m.reported && m.next_fix <= t + 1e-9 {
                let at = m.next_fix;
                m.next_fix += 1.0 / m.spec.sensor.rate_hz;
                let p = m.road.point_at(m.truth.state()[0]).point;
                let s = m.spec.sensor.sigma_m;
                let mut fix = TrackFix::zeroed();
                fix.threat_id = m.id;
                fix.time_s = at;
                fix.sigma_m = s;
                for (i, v) in fix.position_m.iter_mut().enumerate() {
                    *v = if i == 2 && !self.three_d {
                        0.0
                    } else {
                        p[i] + s * standard_normal(&mut m.noise)
                    };
                }
                out.push(SensorOutput::Fix(fix));
            }
        }
        out
    }

    /// The moving threats.
    pub fn movings(&self) -> &[MovingSensor] {
        &self.movings
    }

    /// Number of static threats (their ids are 1..=n).
    pub fn static_count(&self) -> usize {
        self.statics.len()
    }
}

fn static_report(id: u32, s: &StaticThreatSpec) -> ThreatReport {
    messages::static_threat_report(id, s)
}

fn moving_report(id: u32, m: &MovingThreatSpec, est: &Estimate) -> ThreatReport {
    let mut r = messages::threat_report(id, ThreatKind::Moving, &m.name);
    r.appeared_at_s = m.appears_at_s;
    r.axes_m = m.axes_m;
    r.road_point_count = m.road_m.len() as u32;
    r.road_m[..m.road_m.len()].copy_from_slice(&m.road_m);
    r.estimate_time_s = est.t;
    r.estimate_mean = [est.mean[0], est.mean[1], est.mean[2]];
    for i in 0..3 {
        for j in 0..3 {
            r.estimate_covariance[3 * i + j] = est.cov[(i, j)];
        }
    }
    r.accel_sigma_mps2 = m.accel_sigma_mps2;
    r.accel_tau_s = m.accel_tau_s;
    r
}
