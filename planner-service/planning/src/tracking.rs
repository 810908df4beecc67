//! A tracking law that flies a planned trajectory with the vehicle model: the plan's
//! controls as feed-forward plus cascaded feedback — position error → heading (and in 3-D
//! flight-path angle) command → turn/climb rate → load factor and bank → their rates.
//!
//! It is the inner loop of the harness's emulated tracker, and the planner uses it to
//! export plans whose controls replay open loop onto the planned path (the 3-D model is
//! unstable in a climb, so open-loop plan controls alone drift away).

use crate::dynamics::{G0, wrap_angle};
use crate::problem::Problem;

/// Gains of the tracking law (rad/s bandwidths of each loop; inner loops faster).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackingGains {
    /// Position loop: cross-track and vertical error to heading / flight-path angle.
    pub position: f64,
    /// Attitude loop: heading and flight-path angle error to their rates.
    pub attitude: f64,
    /// Actuator loop: load factor and bank error to their rates (3-D).
    pub actuator: f64,
}

impl Default for TrackingGains {
    fn default() -> Self {
        TrackingGains {
            position: 0.05,
            attitude: 0.25,
            actuator: 1.5,
        }
    }
}

/// The deviation of a state from the plan's state at the same time, in the plan's frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Deviation {
    /// Along the plan's track (positive ahead).
    pub along_m: f64,
    /// Across the plan's track (positive left).
    pub cross_m: f64,
    /// Above the plan (0 in 2-D).
    pub vertical_m: f64,
}

/// The tracking law for one vehicle.
#[derive(Debug, Clone, Copy)]
pub struct Tracker {
    three_d: bool,
    speed: f64,
    gains: TrackingGains,
    limits: crate::dynamics::Limits,
}

impl Tracker {
    pub fn new(problem: &Problem, gains: TrackingGains) -> Tracker {
        Tracker {
            three_d: problem.dim() == 3,
            speed: problem.limits.speed,
            gains,
            limits: problem.limits,
        }
    }

    /// Deviation of `state` from `reference` (both model order, zero-padded).
    pub fn deviation(&self, state: &[f64; 7], reference: &[f64; 7]) -> Deviation {
        let heading = if self.three_d {
            reference[4]
        } else {
            reference[2]
        };
        let (s, c) = heading.sin_cos();
        let (dx, dy) = (state[0] - reference[0], state[1] - reference[1]);
        Deviation {
            along_m: c * dx + s * dy,
            cross_m: -s * dx + c * dy,
            vertical_m: if self.three_d {
                state[2] - reference[2]
            } else {
                0.0
            },
        }
    }

    /// Control to apply at `state`, given the plan's state and control at the same time,
    /// saturated to the vehicle's limits.
    pub fn control(
        &self,
        state: &[f64; 7],
        reference: &[f64; 7],
        feed_forward: &[f64; 2],
    ) -> [f64; 2] {
        let g = self.gains;
        let v = self.speed;
        let dev = self.deviation(state, reference);
        let l = &self.limits;
        if !self.three_d {
            let psi_cmd = reference[2] - (g.position * dev.cross_m / v).clamp(-0.5, 0.5);
            let u = feed_forward[0] + g.attitude * wrap_angle(psi_cmd - state[2]);
            return [u.clamp(-l.turn_rate_max, l.turn_rate_max), 0.0];
        }
        let (gamma, chi, nz, mu) = (state[3], state[4], state[5], state[6]);
        let (gamma_r, nz_r, mu_r) = (reference[3], reference[5], reference[6]);
        // Reference rates of gamma and chi from the plan's own state.
        let gamma_rate_r = G0 * (nz_r * mu_r.cos() - gamma_r.cos()) / v;
        let chi_rate_r = G0 * nz_r * mu_r.sin() / (v * gamma_r.cos());
        // Position loop.
        let chi_cmd = reference[4] - (g.position * dev.cross_m / v).clamp(-0.5, 0.5);
        let gamma_cmd = (gamma_r - (g.position * dev.vertical_m / v).clamp(-0.3, 0.3))
            .clamp(-l.gamma_max, l.gamma_max);
        // Attitude loop: desired rates.
        let gamma_rate = gamma_rate_r + g.attitude * (gamma_cmd - gamma);
        let chi_rate = chi_rate_r + g.attitude * wrap_angle(chi_cmd - chi);
        // Invert gamma' = g (Nz cos mu - cos gamma) / V, chi' = g Nz sin mu / (V cos gamma).
        let vertical = v * gamma_rate / G0 + gamma.cos();
        let lateral = v * gamma.cos() * chi_rate / G0;
        let nz_cmd = vertical
            .hypot(lateral)
            .copysign(vertical)
            .clamp(l.nz_min, l.nz_max);
        let mu_cmd = if vertical >= 0.0 {
            lateral.atan2(vertical)
        } else {
            (-lateral).atan2(-vertical)
        }
        .clamp(-l.mu_max, l.mu_max);
        // Actuator loop; near the Nz and bank limits only back inside (bound protection:
        // the plan's feed-forward may push past a limit between its nodes).
        let u1 = (feed_forward[0] + g.actuator * (nz_cmd - nz))
            .min(g.actuator * (l.nz_max - nz))
            .max(g.actuator * (l.nz_min - nz));
        let u2 = (feed_forward[1] + g.actuator * wrap_angle(mu_cmd - mu))
            .min(g.actuator * (l.mu_max - mu))
            .max(g.actuator * (-l.mu_max - mu));
        [
            u1.clamp(-l.nz_rate_max, l.nz_rate_max),
            u2.clamp(-l.mu_rate_max, l.mu_rate_max),
        ]
    }
}
