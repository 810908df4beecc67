//! Bounds of the variables (path limits with their margins, the fixed start, targets and
//! final state, the phase end times) and of the constraints (phase order, rendezvous
//! heading), scaled.

// Index loops here mirror the equations (rows, nodes, state components) one to one.
#![allow(clippy::needless_range_loop)]

use wingman_interfaces::Model;

use super::{INF, Transcription, TranscriptionSettings};
use crate::trajectory::Trajectory;

impl Transcription {
    pub(super) fn set_bounds(&mut self, guess: &Trajectory, settings: &TranscriptionSettings) {
        let pr = &self.problem;
        let (nx, dim) = (self.nx, self.dim);
        let n_nodes = self.layout.state_nodes();
        let phases = self.layout.phases();
        let mut l = pr.limits;
        let keep = 1.0 - settings.bound_margin;
        l.turn_rate_max *= keep;
        l.gamma_max *= keep;
        l.mu_max *= keep;
        l.nz_rate_max *= keep;
        l.mu_rate_max *= keep;
        let nz_span = (l.nz_max - l.nz_min) * settings.bound_margin / 2.0;
        (l.nz_min, l.nz_max) = (l.nz_min + nz_span, l.nz_max - nz_span);
        l.z_min += settings.altitude_margin_m;
        let mut lo = vec![-INF; self.n_vars()];
        let mut hi = vec![INF; self.n_vars()];
        // Path bounds on states and controls.
        for k in 0..n_nodes {
            if pr.model == Model::ThreeD {
                lo[self.state(k, 2)] = l.z_min;
                (lo[self.state(k, 3)], hi[self.state(k, 3)]) = (-l.gamma_max, l.gamma_max);
                (lo[self.state(k, 5)], hi[self.state(k, 5)]) = (l.nz_min, l.nz_max);
                (lo[self.state(k, 6)], hi[self.state(k, 6)]) = (-l.mu_max, l.mu_max);
            }
        }
        for k in 0..self.layout.control_nodes() {
            match pr.model {
                Model::TwoD => {
                    (lo[self.control(k, 0)], hi[self.control(k, 0)]) =
                        (-l.turn_rate_max, l.turn_rate_max)
                }
                Model::ThreeD => {
                    (lo[self.control(k, 0)], hi[self.control(k, 0)]) =
                        (-l.nz_rate_max, l.nz_rate_max);
                    (lo[self.control(k, 1)], hi[self.control(k, 1)]) =
                        (-l.mu_rate_max, l.mu_rate_max);
                }
            }
        }
        // The start state.
        for c in 0..nx {
            let i = self.state(0, c);
            (lo[i], hi[i]) = (pr.x0[c], pr.x0[c]);
        }
        // Targets fix the position of each phase's last node.
        for (p, target) in pr.targets.iter().enumerate() {
            let k = self.layout.phase_start[p + 1];
            for c in 0..dim {
                let i = self.state(k, c);
                (lo[i], hi[i]) = (target[c], target[c]);
            }
        }
        let h = pr.heading_index();
        let guess_final_heading = guess.states.last().map_or(pr.x0[h], |s| s[h]);
        let last = n_nodes - 1;
        if let Some(f) = &pr.final_state {
            for c in 0..nx {
                let i = self.state(last, c);
                let value = if c == h {
                    nearest_turn(f[h], guess_final_heading)
                } else {
                    f[c]
                };
                (lo[i], hi[i]) = (value, value);
            }
        }
        // Times.
        let t0 = pr.t0;
        let guess_tf = guess.final_time().unwrap_or(t0 + 1.0);
        let t_max = t0
            + settings.max_duration_factor
                * (guess_tf - t0).max(settings.min_phase_s * phases as f64);
        for p in 0..phases {
            let i = self.time(p);
            (lo[i], hi[i]) = (t0 + settings.min_phase_s * (p + 1) as f64, t_max);
        }
        if let Some(tf) = pr.final_time {
            let i = self.time(phases - 1);
            (lo[i], hi[i]) = (tf, tf);
        }
        // Rendezvous: the final node is in level flight; constraint bounds below.
        let base = self.layout.control_nodes() * nx;
        for r in 0..phases - 1 {
            self.g_lo[base + r] = settings.min_phase_s;
            self.g_hi[base + r] = INF;
        }
        if let Some(lead) = &pr.lead {
            if pr.model == Model::ThreeD {
                for (c, value) in [(5, 1.0), (6, 0.0)] {
                    let i = self.state(last, c);
                    (lo[i], hi[i]) = (value, value);
                }
            }
            let lead_heading = lead.at(guess_tf).heading;
            let turn = nearest_turn(lead_heading, guess_final_heading) - lead_heading;
            let r = base + phases - 1 + dim;
            (self.g_lo[r], self.g_hi[r]) = (turn, turn);
        }
        for i in 0..self.n_vars() {
            let s = self.scale[i];
            self.x_lo[i] = if lo[i] <= -INF { -INF } else { lo[i] / s };
            self.x_hi[i] = if hi[i] >= INF { INF } else { hi[i] / s };
        }
        for r in 0..self.n_cons() {
            let s = self.cscale[r];
            if self.g_lo[r] > -INF {
                self.g_lo[r] *= s;
            }
            if self.g_hi[r] < INF {
                self.g_hi[r] *= s;
            }
        }
    }
}

/// `target + 2πk` for the integer `k` that brings it nearest to `reference`.
pub fn nearest_turn(target: f64, reference: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    target + tau * ((reference - target) / tau).round()
}
