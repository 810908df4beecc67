//! The truth model: how the flown aircraft and its air differ from the planner's model.
//! The wind moves the air mass (a steady mean plus gusts), the aircraft answers the
//! tracker's commands with a lag and within its own rate limits, and the tracker sees the
//! state only through a navigation solution with correlated errors. Each part draws from
//! its own seeded stream, once per integration step: a flight's disturbances are a
//! function of the scenario alone, so a replay sees the same flight.
//!
//! A scenario with neither `[wind]` nor `[aircraft]` has no truth model: the tracker
//! flies the planner's model in still air exactly as before.

mod autopilot;
mod gauss_markov;
mod navigation;
mod wind;

pub use autopilot::Autopilot;
pub use gauss_markov::GaussMarkov;
pub use navigation::Navigation;
pub use wind::Wind;

use wingman_planning::problem::Problem;
use wingman_planning::scenario::{AircraftSpec, Scenario, WindSpec};

/// The ChaCha8 streams of the gusts and of the navigation errors: two parts given the
/// same seed (both default to 0) still draw independent numbers.
const WIND_STREAM: u64 = 1;
const NAVIGATION_STREAM: u64 = 2;

/// The disturbances of one flight.
#[derive(Debug, Clone)]
pub struct Truth {
    model: wingman_interfaces::Model,
    wind: Wind,
    autopilot: Autopilot,
    navigation: Navigation,
}

impl Truth {
    /// The truth model of `sc` (`None` when it has neither `[wind]` nor `[aircraft]`).
    pub fn of(sc: &Scenario, problem: &Problem) -> Option<Truth> {
        if sc.wind.is_none() && sc.aircraft.is_none() {
            return None;
        }
        let still = WindSpec::still();
        let wind = sc.wind.as_ref().unwrap_or(&still);
        let ideal = AircraftSpec::ideal(&sc.vehicle);
        let aircraft = sc.aircraft.as_ref().unwrap_or(&ideal);
        Some(Truth {
            model: problem.model,
            wind: Wind::new(wind, problem.model, problem.limits.speed),
            autopilot: Autopilot::new(aircraft, problem.model, problem.limits),
            navigation: Navigation::new(aircraft, problem.model),
        })
    }

    /// The wind now, m/s.
    pub fn wind(&self) -> [f64; 3] {
        self.wind.now()
    }

    /// What the navigation solution says of the true state `x`.
    pub fn sense(&self, x: &[f64; 7]) -> [f64; 7] {
        self.navigation.sense(x)
    }

    /// The aircraft flying `control` already (a resumed flight taking over in the air).
    pub fn applying(&mut self, control: [f64; 2]) {
        self.autopilot.applying(control);
    }

    /// The time constant of the aircraft's lag behind its commands, s.
    pub fn response_s(&self) -> f64 {
        self.autopilot.response_s()
    }

    /// The control the aircraft applies over the next `h` seconds when commanded
    /// `command`.
    pub fn respond(&mut self, command: [f64; 2], h: f64) -> [f64; 2] {
        self.autopilot.respond(command, h)
    }

    /// The wind and the navigation errors `h` seconds on.
    pub fn advance(&mut self, h: f64) {
        self.wind.advance(h);
        self.navigation.advance(h);
    }

    /// The state after `h` seconds of flight: `x` moved by the wind over the ground,
    /// its load factor and bank kept within the airframe's limits (3-D).
    pub fn drift(&self, x: &mut [f64; 7], wind: [f64; 3], h: f64) {
        for (p, w) in x.iter_mut().zip(wind).take(self.model.position_dim()) {
            *p += w * h;
        }
        self.autopilot.saturate(x);
    }
}

#[cfg(test)]
mod tests {
    use wingman_planning::scenario::bundled;
    use wingman_planning::tracking::TrackingGains;

    use super::*;
    use crate::tracker::InnerLoop;

    /// The 2-D tracker with no plan flies its hold, a constant turn rate wherever it is:
    /// a steady wind `w` then moves it by exactly `w t` against still air (to 1e-6 m
    /// over 120 s), and still air with the ideal aircraft flies as no truth model does,
    /// bit for bit.
    #[test]
    fn a_steady_wind_carries_the_aircraft_by_w_t() {
        let mut sc = bundled("2d-fixed-time-avoidable").unwrap().unwrap();
        let problem = Problem::from_scenario(&sc).unwrap();
        let fly = |truth: Option<Truth>| {
            let mut tracker = InnerLoop::new(&problem, TrackingGains::default())
                .unwrap()
                .with_truth(truth);
            tracker.advance_to(120.0);
            *tracker.state()
        };
        let plain = fly(None);
        sc.aircraft = Some(AircraftSpec::ideal(&sc.vehicle));
        assert_eq!(fly(Truth::of(&sc, &problem)), plain);
        let w = [12.0, -7.0, 0.0];
        sc.wind = Some(WindSpec {
            mean_mps: w,
            ..WindSpec::still()
        });
        let windy = fly(Truth::of(&sc, &problem));
        for i in 0..2 {
            assert!((windy[i] - plain[i] - w[i] * 120.0).abs() < 1e-6, "{i}");
        }
        assert_eq!(windy[2], plain[2]);
    }

    /// `OwnshipState` carries the navigation solution; the samples keep the true state
    /// and the wind.
    #[test]
    fn ownship_reports_the_navigation_solution() {
        let mut sc = bundled("2d-fixed-time-avoidable").unwrap().unwrap();
        let problem = Problem::from_scenario(&sc).unwrap();
        sc.aircraft = Some(AircraftSpec {
            nav_sigma_m: 50.0,
            ..AircraftSpec::ideal(&sc.vehicle)
        });
        sc.wind = Some(WindSpec {
            mean_mps: [5.0, 0.0, 0.0],
            ..WindSpec::still()
        });
        let truth = Truth::of(&sc, &problem).unwrap();
        let mut tracker = InnerLoop::new(&problem, TrackingGains::default())
            .unwrap()
            .with_truth(Some(truth));
        tracker.advance_to(10.0);
        let sample = tracker.sample();
        let reported = tracker.ownship().state;
        assert_ne!(reported[..2], sample.state[..2]);
        assert_eq!(reported[2], sample.state[2]);
        assert_eq!(sample.wind, [5.0, 0.0, 0.0]);
        assert!(
            Truth::of(
                &bundled("2d-min-time-avoidable").unwrap().unwrap(),
                &problem
            )
            .is_none()
        );
    }
}
