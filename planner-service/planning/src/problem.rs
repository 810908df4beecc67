//! The planning problem: everything one plan needs, in SI units and radians — the model,
//! objective, vehicle limits, weights, initial state, targets, final state or lead, and the
//! threat world (static layout plus moving threats with their current estimates). The
//! offline `plan` command builds it from a scenario ([`Problem::from_scenario`]); the
//! planner service builds it from its world model. Building it allocates; evaluating it
//! ([`Problem::exposure`], …) does not.

// Index loops here mirror the product rule over the four variables (x, y, z, t).
#![allow(clippy::needless_range_loop)]

use wingman_interfaces::{MAX_TARGETS, Model, Objective};

use crate::dynamics::{self, Limits, SpatialLimits};
use crate::estimation::{self, Estimate, GaussMarkov, MovingThreat, Road};
use crate::lead::{LeadError, LeadPath};
use crate::scenario::{MovingThreatSpec, Scenario, StaticThreatSpec};
use crate::threat::{self, Eval, Superquadric, ThreatLayout};

/// A problem that cannot be planned: bad or inconsistent input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProblemError {
    #[error("vehicle: {0}")]
    Vehicle(#[from] dynamics::DynamicsError),
    #[error("threat `{name}`: {source}")]
    Threat {
        name: String,
        source: threat::ThreatError,
    },
    #[error("moving threat `{name}`: {source}")]
    Moving {
        name: String,
        source: estimation::EstimationError,
    },
    #[error("lead: {0}")]
    Lead(#[from] LeadError),
    #[error("{0}")]
    Invalid(String),
}

/// Cost weights (FORMULATION.md §3–4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostWeights {
    /// Time against running cost, in [0, 1].
    pub alpha: f64,
    /// Exposure against control effort, in [0, 1].
    pub beta: f64,
    /// Stiffness `s` of the exposure sigmoid.
    pub stiffness: f64,
}

/// The threat world in the model's dimension. (The variants hold fixed-capacity layouts of
/// different sizes; a problem holds one, so boxing would only add an indirection.)
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum Threats {
    /// 2-D: positions `[x, y]`.
    Planar {
        layout: ThreatLayout<2>,
        moving: Vec<MovingThreat<2>>,
    },
    /// 3-D: positions `[x, y, z]`.
    Spatial {
        layout: ThreatLayout<3>,
        moving: Vec<MovingThreat<3>>,
    },
}

/// One plan's problem.
#[derive(Debug, Clone)]
pub struct Problem {
    pub model: Model,
    pub objective: Objective,
    pub limits: Limits,
    pub weights: CostWeights,
    /// Start time.
    pub t0: f64,
    /// Start state in model order, zero-padded to 7 (2-D: `x, y, psi`).
    pub x0: [f64; 7],
    /// Intermediate targets `[x, y, z]` (z = 0 in 2-D), in order.
    pub targets: Vec<[f64; 3]>,
    /// Final state (model order, zero-padded) for `FixedTime` and `MinTime`.
    pub final_state: Option<[f64; 7]>,
    /// Fixed final time for `FixedTime`.
    pub final_time: Option<f64>,
    /// The lead for `MinTimeRendezvous`.
    pub lead: Option<LeadPath>,
    pub threats: Threats,
    /// The steady wind the plan is made in, m/s `[x, y, z]` (`z` 0 in 2-D; all 0: still
    /// air): the models fly through the air and drift with it over the ground.
    pub wind: [f64; 3],
}

impl Problem {
    /// Number of states (3 or 7).
    pub fn nx(&self) -> usize {
        self.model.state_dim()
    }

    /// Number of controls (1 or 2).
    pub fn nu(&self) -> usize {
        self.model.control_dim()
    }

    /// Number of position coordinates (2 or 3).
    pub fn dim(&self) -> usize {
        self.model.position_dim()
    }

    /// Number of phases (one per leg: targets + 1).
    pub fn phases(&self) -> usize {
        self.targets.len() + 1
    }

    /// Index of the heading in the state vector.
    pub fn heading_index(&self) -> usize {
        match self.model {
            Model::TwoD => 2,
            Model::ThreeD => 4,
        }
    }

    /// Exposure `E` at position `p` (`[x, y, z]`, z ignored in 2-D) and time `t`.
    pub fn exposure(&self, p: &[f64; 3], t: f64) -> f64 {
        match &self.threats {
            Threats::Planar { layout, moving } => {
                estimation::exposure_at(layout, moving, &[p[0], p[1]], t)
            }
            Threats::Spatial { layout, moving } => estimation::exposure_at(layout, moving, p, t),
        }
    }

    /// Exposure with its gradient and Hessian in position (padded to 3; zeros for z in 2-D).
    pub fn exposure_eval(&self, p: &[f64; 3], t: f64) -> Eval<3> {
        match &self.threats {
            Threats::Planar { layout, moving } => {
                let e = estimation::exposure_eval_at(layout, moving, &[p[0], p[1]], t);
                let mut out = Eval::<3>::zero();
                out.value = e.value;
                for i in 0..2 {
                    out.grad[i] = e.grad[i];
                    for j in 0..2 {
                        out.hess[(i, j)] = e.hess[(i, j)];
                    }
                }
                out
            }
            Threats::Spatial { layout, moving } => {
                estimation::exposure_eval_at(layout, moving, p, t)
            }
        }
    }

    /// Exposure with derivatives in position *and* time, `z = (x, y, z, t)` (positions
    /// padded to 3; the z entries are zero in 2-D). Static threats do not depend on time;
    /// a moving threat's region does (its centre moves and its axis and exponent grow with
    /// `sigma_d`). `d²F/dt²` of a moving threat is a central difference of its analytic
    /// `dF/dt` (step 1e-3 s): it only enters the NLP's Hessian.
    pub fn exposure_wt(&self, p: &[f64; 3], t: f64) -> ExposureWt {
        match &self.threats {
            Threats::Planar { layout, moving } => exposure_wt_in(layout, moving, &[p[0], p[1]], t),
            Threats::Spatial { layout, moving } => exposure_wt_in(layout, moving, p, t),
        }
    }

    /// Whether any moving threat is in the world (exposure then depends on time).
    pub fn has_moving_threats(&self) -> bool {
        match &self.threats {
            Threats::Planar { moving, .. } => !moving.is_empty(),
            Threats::Spatial { moving, .. } => !moving.is_empty(),
        }
    }

    /// The position `[x, y, z]` of a state in model order (z = 0 in 2-D, where the third
    /// entry is the heading).
    pub fn position(&self, state: &[f64; 7]) -> [f64; 3] {
        let z = if self.dim() == 3 { state[2] } else { 0.0 };
        [state[0], state[1], z]
    }

    /// The final position the plan must reach at time `t` (the final point, or the lead).
    pub fn final_position_at(&self, t: f64) -> [f64; 3] {
        match (&self.final_state, &self.lead) {
            (Some(f), _) => self.position(f),
            (None, Some(lead)) => lead.at(t).position,
            (None, None) => [self.x0[0], self.x0[1], 0.0],
        }
    }

    /// The take-off problem of a scenario: threats known at `start.time_s`, moving threats
    /// from their initial estimate (no fixes), no events.
    pub fn from_scenario(sc: &Scenario) -> Result<Problem, ProblemError> {
        let limits = vehicle_limits(sc.model, &sc.vehicle)?;
        let s = &sc.start;
        let x0 = s.state(sc.model);
        let final_state = sc.final_point.as_ref().map(|f| f.state(sc.model));
        let lead = match &sc.lead {
            Some(l) => Some(LeadPath::new(&l.route_m, l.speed_mps, s.time_s)?),
            None => None,
        };
        let statics: Vec<&StaticThreatSpec> = sc.known_static_threats().collect();
        let movings: Vec<&MovingThreatSpec> = sc.known_moving_threats().collect();
        let stiffness = sc.weights.stiffness;
        let threats = match sc.model {
            Model::TwoD => Threats::Planar {
                layout: layout::<2>(&statics, stiffness)?,
                moving: movings
                    .iter()
                    .map(|m| moving::<2>(m, s.time_s))
                    .collect::<Result<_, _>>()?,
            },
            Model::ThreeD => Threats::Spatial {
                layout: layout::<3>(&statics, stiffness)?,
                moving: movings
                    .iter()
                    .map(|m| moving::<3>(m, s.time_s))
                    .collect::<Result<_, _>>()?,
            },
        };
        let problem = Problem {
            model: sc.model,
            objective: sc.objective,
            limits,
            weights: CostWeights {
                alpha: sc.weights.alpha,
                beta: sc.weights.beta,
                stiffness,
            },
            t0: s.time_s,
            x0,
            targets: sc.targets.clone(),
            final_state,
            final_time: sc.final_point.as_ref().and_then(|f| f.time_s),
            lead,
            threats,
            wind: sc.wind.as_ref().map_or([0.0; 3], |w| w.mean_mps),
        };
        problem.validate()?;
        Ok(problem)
    }

    /// Checks the problem is well posed: finite numbers, consistent objective, bounds that
    /// admit the start and the end.
    pub fn validate(&self) -> Result<(), ProblemError> {
        let bad = |m: String| Err(ProblemError::Invalid(m));
        if !self.t0.is_finite() || self.x0.iter().any(|v| !v.is_finite()) {
            return bad("the start time and state must be finite".into());
        }
        let wind_speed = self.wind.iter().map(|w| w * w).sum::<f64>().sqrt();
        if !wind_speed.is_finite() || wind_speed >= self.limits.speed {
            return bad(format!(
                "the wind ({wind_speed} m/s) must be finite and slower than the airspeed ({} m/s)",
                self.limits.speed
            ));
        }
        if self.targets.len() > MAX_TARGETS {
            return bad(format!(
                "at most {MAX_TARGETS} targets, got {}",
                self.targets.len()
            ));
        }
        if self.targets.iter().flatten().any(|v| !v.is_finite()) {
            return bad("targets must be finite".into());
        }
        let w = &self.weights;
        let weights_ok =
            (0.0..=1.0).contains(&w.alpha) && (0.0..=1.0).contains(&w.beta) && w.stiffness > 0.0;
        if !weights_ok {
            return bad("weights: alpha and beta must be in [0, 1], stiffness positive".into());
        }
        match self.objective {
            Objective::FixedTime | Objective::MinTime => {
                let Some(f) = &self.final_state else {
                    return bad("a fixed-point objective needs a final state".into());
                };
                if f.iter().any(|v| !v.is_finite()) {
                    return bad("the final state must be finite".into());
                }
                if self.objective == Objective::FixedTime {
                    match self.final_time {
                        Some(tf) if tf.is_finite() && tf > self.t0 => {}
                        _ => {
                            return bad(
                                "a fixed-time objective needs a final time after the start".into(),
                            );
                        }
                    }
                }
            }
            Objective::MinTimeRendezvous => {
                if self.lead.is_none() {
                    return bad("a rendezvous needs the lead's route".into());
                }
            }
        }
        if self.model == Model::ThreeD {
            let l = &self.limits;
            let x = &self.x0;
            if x[2] < l.z_min
                || x[3].abs() > l.gamma_max
                || x[5] < l.nz_min
                || x[5] > l.nz_max
                || x[6].abs() > l.mu_max
            {
                return bad("the start state is outside the vehicle's bounds".into());
            }
            if self.targets.iter().any(|t| t[2] < l.z_min) {
                return bad("a target is under the minimum altitude".into());
            }
        }
        Ok(())
    }
}

/// The model's limits from the wire (and scenario) form, checked.
pub fn vehicle_limits(
    model: Model,
    v: &wingman_interfaces::VehicleLimits,
) -> Result<Limits, dynamics::DynamicsError> {
    match model {
        Model::TwoD => Limits::planar(v.speed_mps, v.turn_rate_max_rps),
        Model::ThreeD => Limits::spatial(SpatialLimits {
            speed: v.speed_mps,
            gamma_max: v.gamma_max_rad,
            nz_min: v.nz_min,
            nz_max: v.nz_max,
            mu_max: v.bank_max_rad,
            nz_rate_max: v.nz_rate_max_per_s,
            mu_rate_max: v.bank_rate_max_rps,
            z_min: v.altitude_min_m,
        }),
    }
}

fn layout<const D: usize>(
    specs: &[&StaticThreatSpec],
    stiffness: f64,
) -> Result<ThreatLayout<D>, ProblemError> {
    let mut layout = ThreatLayout::<D>::new(stiffness).map_err(|source| ProblemError::Threat {
        name: "(layout)".into(),
        source,
    })?;
    for t in specs {
        let err = |source| ProblemError::Threat {
            name: t.name.clone(),
            source,
        };
        let q = Superquadric::<D>::new(
            std::array::from_fn(|i| t.center_m[i]),
            std::array::from_fn(|i| t.axes_m[i]),
            std::array::from_fn(|i| t.exponents[i]),
            t.yaw_rad,
        )
        .map_err(err)?;
        layout.push(q).map_err(err)?;
    }
    Ok(layout)
}

fn moving<const D: usize>(m: &MovingThreatSpec, t0: f64) -> Result<MovingThreat<D>, ProblemError> {
    let err = |source| ProblemError::Moving {
        name: m.name.clone(),
        source,
    };
    let road: Vec<[f64; D]> = m
        .road_m
        .iter()
        .map(|p| std::array::from_fn(|i| p[i]))
        .collect();
    let road = Road::<D>::new(&road).map_err(err)?;
    let model = GaussMarkov::new(m.accel_tau_s, m.accel_sigma_mps2).map_err(err)?;
    let estimate = Estimate::with_sigmas(
        t0,
        [m.initial_distance_m, m.initial_speed_mps, 0.0],
        m.initial_sigma,
    )
    .map_err(err)?;
    Ok(
        MovingThreat::new(road, std::array::from_fn(|i| m.axes_m[i]), model, estimate)
            .map_err(err)?
            .with_appears_at(m.appears_at_s),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::BUNDLED;

    #[test]
    fn every_bundled_scenario_makes_a_problem() {
        for (name, _) in BUNDLED {
            let sc = crate::scenario::bundled(name).unwrap().unwrap();
            let p = Problem::from_scenario(&sc).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(p.phases(), sc.targets.len() + 1);
            assert!(p.exposure(&[p.x0[0], p.x0[1], p.x0[2]], p.t0).is_finite());
        }
    }

    /// `exposure_wt` matches `exposure` and central differences of itself in (x, y, z, t)
    /// on the moving-threat scenario (gradient 1e-5 relative to its scale, Hessian 1e-4).
    #[test]
    fn exposure_with_time_derivatives_matches_differences() {
        let sc = crate::scenario::bundled("3d-min-time-moving-threat")
            .unwrap()
            .unwrap();
        let p = Problem::from_scenario(&sc).unwrap();
        let m = &sc.moving_threats[0];
        // Near the moving threat's initial region, on its edge, where E varies fastest.
        let (d0, road) = (m.initial_distance_m, &m.road_m);
        let dir = [road[1][0] - road[0][0], road[1][1] - road[0][1]];
        let len = dir[0].hypot(dir[1]);
        let c = [
            road[0][0] + d0 * dir[0] / len,
            road[0][1] + d0 * dir[1] / len,
        ];
        for (k, t) in [10.0, 200.0, 500.0].into_iter().enumerate() {
            let z = [c[0] + 9000.0 + 300.0 * k as f64, c[1] + 2000.0, 3000.0, t];
            let e = p.exposure_wt(&[z[0], z[1], z[2]], z[3]);
            assert!((e.value - p.exposure(&[z[0], z[1], z[2]], z[3])).abs() < 1e-15);
            let steps = [1.0, 1.0, 1.0, 1e-2];
            for i in 0..4 {
                let shifted = |d: f64| {
                    let mut y = z;
                    y[i] += d;
                    p.exposure_wt(&[y[0], y[1], y[2]], y[3])
                };
                let (a, b) = (shifted(steps[i]), shifted(-steps[i]));
                let fd = (a.value - b.value) / (2.0 * steps[i]);
                let scale = e.grad.iter().fold(1e-12f64, |m, v| m.max(v.abs()));
                assert!(
                    (fd - e.grad[i]).abs() < 1e-5 * scale,
                    "t={t} grad[{i}]: {fd} vs {}",
                    e.grad[i]
                );
                for j in 0..4 {
                    let fd = (a.grad[j] - b.grad[j]) / (2.0 * steps[i]);
                    let scale = e
                        .hess
                        .iter()
                        .flatten()
                        .fold(1e-12f64, |m, v| m.max(v.abs()));
                    assert!(
                        (fd - e.hess[i][j]).abs() < 1e-4 * scale,
                        "t={t} hess[{i}][{j}]: {fd} vs {}",
                        e.hess[i][j]
                    );
                }
            }
        }
    }

    /// The exposure at the centre of a scenario threat is ~1 and far away ~0 (1e-9).
    #[test]
    fn exposure_dispatches_by_dimension() {
        let sc = crate::scenario::bundled("2d-min-time-avoidable")
            .unwrap()
            .unwrap();
        let p = Problem::from_scenario(&sc).unwrap();
        let c = sc.threats[0].center_m;
        assert!((p.exposure(&c, 0.0) - 1.0).abs() < 1e-9);
        assert!(p.exposure(&[1e7, 1e7, 0.0], 0.0) < 1e-9);
        let e = p.exposure_eval(&[c[0] + 100.0, c[1], 0.0], 0.0);
        assert!(e.grad[2] == 0.0 && e.hess[(2, 2)] == 0.0);
    }
}

/// Exposure `E` and its first and second derivatives in `z = (x, y, z, t)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExposureWt {
    pub value: f64,
    pub grad: [f64; 4],
    pub hess: [[f64; 4]; 4],
}

/// Folds one threat's `F` (value, gradient and Hessian in `z`) into `E`, `P = prod eps`
/// (the product rule of `threat::ExposureAcc`, in four variables).
fn fold4(acc: &mut ExposureWt, prod: &mut f64, f: f64, df: &[f64; 4], d2f: &[[f64; 4]; 4], s: f64) {
    let ed = threat::eps_derivs(f, s);
    let de: [f64; 4] = std::array::from_fn(|k| ed.d1 * df[k]);
    for i in 0..4 {
        for j in 0..4 {
            let d2eps = ed.d2 * df[i] * df[j] + ed.d1 * d2f[i][j];
            acc.hess[i][j] =
                ed.eps * acc.hess[i][j] + acc.grad[i] * de[j] + de[i] * acc.grad[j] - *prod * d2eps;
        }
    }
    for k in 0..4 {
        acc.grad[k] = ed.eps * acc.grad[k] - *prod * de[k];
    }
    acc.value += ed.one_minus * *prod;
    *prod *= ed.eps;
}

fn exposure_wt_in<const D: usize>(
    layout: &ThreatLayout<D>,
    moving: &[MovingThreat<D>],
    w: &[f64; D],
    t: f64,
) -> ExposureWt {
    let s = layout.stiffness();
    let mut acc = threat::ExposureAcc::<D>::new();
    layout.fold_into(w, &mut acc);
    let mut out = ExposureWt {
        value: acc.e.value,
        grad: [0.0; 4],
        hess: [[0.0; 4]; 4],
    };
    for i in 0..D {
        out.grad[i] = acc.e.grad[i];
        for j in 0..D {
            out.hess[i][j] = acc.e.hess[(i, j)];
        }
    }
    let mut prod = acc.prod;
    const STEP: f64 = 1e-3;
    for m in moving {
        if m.region_if_near(w, t, s).is_none() {
            continue;
        }
        let e = m.eval(w, t);
        let mut df = [0.0; 4];
        let mut d2f = [[0.0; 4]; 4];
        for i in 0..D {
            df[i] = e.f.grad[i];
            d2f[i][3] = e.dgrad_dt[i];
            d2f[3][i] = e.dgrad_dt[i];
            for j in 0..D {
                d2f[i][j] = e.f.hess[(i, j)];
            }
        }
        df[3] = e.df_dt;
        d2f[3][3] = (m.eval(w, t + STEP).df_dt - m.eval(w, t - STEP).df_dt) / (2.0 * STEP);
        fold4(&mut out, &mut prod, e.f.value, &df, &d2f, s);
    }
    out
}
