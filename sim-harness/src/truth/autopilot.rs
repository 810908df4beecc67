//! The aircraft's response to the tracker's commands: each command is followed with a
//! first-order lag of time constant `response_s` and within the aircraft's own rate
//! limits. In 2-D the command is the turn rate, whose change per second is limited; in
//! 3-D the commands are the rates of the load factor and of the bank, limited to the
//! aircraft's maxima, and the load factor and bank themselves stay within the airframe's
//! limits. The applied control is held over each integration step.

use wingman_interfaces::Model;
use wingman_planning::dynamics::Limits;
use wingman_planning::scenario::AircraftSpec;

/// The response of one aircraft.
#[derive(Debug, Clone, Copy)]
pub struct Autopilot {
    model: Model,
    response_s: f64,
    /// 2-D: the most the turn rate changes per second; 3-D: unused (infinite).
    turn_accel_max: f64,
    /// The most each applied control may be (2-D: the turn rate; 3-D: the rates).
    control_max: [f64; 2],
    limits: Limits,
    applied: [f64; 2],
}

impl Autopilot {
    /// The response of `spec` for a vehicle of `model` within `limits`.
    pub fn new(spec: &AircraftSpec, model: Model, limits: Limits) -> Autopilot {
        let (turn_accel_max, control_max) = match model {
            Model::TwoD => (spec.turn_accel_max, [limits.turn_rate_max, 0.0]),
            Model::ThreeD => (f64::INFINITY, [spec.nz_rate_max, spec.mu_rate_max]),
        };
        Autopilot {
            model,
            response_s: spec.response_s,
            turn_accel_max,
            control_max,
            limits,
            applied: [0.0; 2],
        }
    }

    /// The time constant of the lag, s.
    pub fn response_s(&self) -> f64 {
        self.response_s
    }

    /// The control applied over the next `h` seconds when commanded `command`: the lag's
    /// exact step towards the command, its change limited (2-D), then clamped.
    pub fn respond(&mut self, command: [f64; 2], h: f64) -> [f64; 2] {
        let keep = if self.response_s > 0.0 {
            (-h / self.response_s).exp()
        } else {
            0.0
        };
        let most_change = self.turn_accel_max * h;
        for ((applied, max), command) in self.channels_mut().zip(command) {
            let lagged = command + (*applied - command) * keep;
            let change = (lagged - *applied).clamp(-most_change, most_change);
            *applied = (*applied + change).clamp(-max, max);
        }
        self.applied
    }

    /// The aircraft applying `control` already (clamped to its limits).
    pub fn applying(&mut self, control: [f64; 2]) {
        for ((applied, max), c) in self.channels_mut().zip(control) {
            *applied = c.clamp(-max, max);
        }
    }

    /// Keeps the load factor and the bank of a 3-D state within the airframe's limits.
    pub fn saturate(&self, x: &mut [f64; 7]) {
        if self.model == Model::ThreeD {
            let l = &self.limits;
            x[5] = x[5].clamp(l.nz_min, l.nz_max);
            x[6] = x[6].clamp(-l.mu_max, l.mu_max);
        }
    }

    /// Each commanded channel's applied control and its bound (2-D: the turn rate; 3-D:
    /// the rates of `Nz` and `mu`).
    fn channels_mut(&mut self) -> impl Iterator<Item = (&mut f64, f64)> {
        let channels = match self.model {
            Model::TwoD => 1,
            Model::ThreeD => 2,
        };
        self.applied.iter_mut().zip(self.control_max).take(channels)
    }
}

#[cfg(test)]
mod tests {
    use wingman_planning::scenario::bundled;

    use super::*;

    fn spec(response_s: f64, turn_accel_max: f64) -> AircraftSpec {
        let sc = bundled("2d-fixed-time-avoidable").unwrap().unwrap();
        AircraftSpec {
            response_s,
            turn_accel_max,
            ..AircraftSpec::ideal(&sc.vehicle)
        }
    }

    fn limits_of(name: &str) -> Limits {
        let sc = bundled(name).unwrap().unwrap();
        wingman_planning::problem::Problem::from_scenario(&sc)
            .unwrap()
            .limits
    }

    /// A step command is followed as `c (1 - exp(-t / tau))`, to rounding (1e-12), at
    /// any step length.
    #[test]
    fn a_step_is_followed_with_the_first_order_lag() {
        let limits = limits_of("2d-fixed-time-avoidable");
        let c = 0.5 * limits.turn_rate_max;
        for h in [0.01, 0.05, 0.2] {
            let mut a = Autopilot::new(&spec(0.8, f64::INFINITY), Model::TwoD, limits);
            for k in 1..=40 {
                let u = a.respond([c, 0.0], h)[0];
                let t = k as f64 * h;
                let expected = c * (1.0 - (-t / 0.8).exp());
                assert!(
                    (u - expected).abs() < 1e-12,
                    "h {h}, t {t}: {u} against {expected}"
                );
            }
        }
    }

    /// The turn rate changes at most `turn_accel_max h` per step and stays within the
    /// vehicle's turn-rate limit; with no lag and no limit the command is applied as is.
    #[test]
    fn the_turn_rate_is_rate_limited_and_clamped() {
        let limits = limits_of("2d-fixed-time-avoidable");
        let (accel, h) = (0.01, 0.05);
        let mut a = Autopilot::new(&spec(0.0, accel), Model::TwoD, limits);
        let mut before = 0.0;
        for _ in 0..400 {
            let u = a.respond([10.0, 0.0], h)[0];
            assert!(u - before <= accel * h + 1e-15);
            assert!(u <= limits.turn_rate_max);
            before = u;
        }
        assert_eq!(before, limits.turn_rate_max);
        let mut ideal = Autopilot::new(&spec(0.0, f64::INFINITY), Model::TwoD, limits);
        assert_eq!(ideal.respond([0.01, 0.0], h), [0.01, 0.0]);
    }

    /// 3-D: the rates are clamped to the aircraft's own maxima, the load factor and bank
    /// to the airframe's.
    #[test]
    fn three_d_rates_and_attitude_stay_within_the_aircraft_limits() {
        let sc = bundled("3d-replan-popups").unwrap().unwrap();
        let limits = limits_of("3d-replan-popups");
        let slow = AircraftSpec {
            nz_rate_max: 0.1,
            mu_rate_max: 0.2,
            ..AircraftSpec::ideal(&sc.vehicle)
        };
        let mut a = Autopilot::new(&slow, Model::ThreeD, limits);
        assert_eq!(a.respond([5.0, -5.0], 0.05), [0.1, -0.2]);
        let mut x = [0.0, 0.0, 1000.0, 0.0, 0.0, 99.0, -99.0];
        a.saturate(&mut x);
        assert_eq!((x[5], x[6]), (limits.nz_max, -limits.mu_max));
    }
}
