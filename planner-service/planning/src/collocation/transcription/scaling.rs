//! Scaling of the variables and constraints (positions in the length scale, controls in
//! their rate limits, times in the time to fly one length scale), and the scaled initial
//! point of a guess.

// Index loops here mirror the equations (rows, nodes, state components) one to one.
#![allow(clippy::needless_range_loop)]

use wingman_interfaces::{Model, Objective};

use super::{Transcription, TranscriptionSettings};
use crate::collocation::mesh::Layout;
use crate::problem::Problem;
use crate::trajectory::Trajectory;

/// Physical value of one NLP unit, per variable.
pub(super) fn variable_scales(
    problem: &Problem,
    layout: &Layout,
    settings: &TranscriptionSettings,
) -> Vec<f64> {
    let (nx, nu, dim) = (problem.nx(), problem.nu(), problem.dim());
    let phases = layout.phases();
    let n_nodes = layout.state_nodes();
    let n_ctrl = layout.control_nodes();
    let n_vars = n_nodes * nx + n_ctrl * nu + phases;
    let v = problem.limits.speed;
    let len = settings.length_scale_m;
    let time_scale = len / v;
    let mut scale = vec![1.0; n_vars];
    let l = &problem.limits;
    for k in 0..n_nodes {
        for c in 0..dim {
            scale[k * nx + c] = len;
        }
    }
    for k in 0..n_ctrl {
        let base = n_nodes * nx + k * nu;
        match problem.model {
            Model::TwoD => scale[base] = l.turn_rate_max,
            Model::ThreeD => {
                scale[base] = l.nz_rate_max;
                scale[base + 1] = l.mu_rate_max;
            }
        }
    }
    for p in 0..phases {
        scale[n_nodes * nx + n_ctrl * nu + p] = time_scale;
    }
    scale
}

/// NLP value of one physical unit, per constraint (`n_cons` of them), from the variables'
/// `scale`.
pub(super) fn constraint_scales(
    problem: &Problem,
    layout: &Layout,
    settings: &TranscriptionSettings,
    scale: &[f64],
    n_cons: usize,
) -> Vec<f64> {
    let (nx, dim) = (problem.nx(), problem.dim());
    let phases = layout.phases();
    let n_ctrl = layout.control_nodes();
    let rendezvous = problem.objective == Objective::MinTimeRendezvous;
    let v = problem.limits.speed;
    let len = settings.length_scale_m;
    let time_scale = len / v;
    let mut cscale = vec![1.0; n_cons];
    for k in 0..n_ctrl {
        for c in 0..nx {
            cscale[k * nx + c] = 1.0 / scale[c];
        }
    }
    for r in 0..phases - 1 {
        cscale[n_ctrl * nx + r] = 1.0 / time_scale;
    }
    if rendezvous {
        for c in 0..dim {
            cscale[n_ctrl * nx + phases - 1 + c] = 1.0 / len;
        }
    }
    cscale
}

impl Transcription {
    /// Scaled variables for the initial guess `guess` (states and controls interpolated at
    /// the node times implied by the guess's phase ends).
    pub fn initial_point(&self, guess: &Trajectory, x: &mut [f64]) {
        let phases = self.layout.phases();
        let t0 = self.problem.t0;
        let mut ends = [0.0; 16];
        for (p, end) in ends.iter_mut().enumerate().take(phases) {
            let fallback = guess.final_time().unwrap_or(t0 + 1.0);
            *end = guess.phase_ends.get(p).copied().unwrap_or(fallback);
        }
        for p in 0..phases {
            x[self.time(p)] = ends[p];
        }
        for k in 0..self.layout.state_nodes() {
            let (p, s) = self.layout.node_phase_fraction(k);
            let ta = if p == 0 { t0 } else { ends[p - 1] };
            let t = ta + (ends[p] - ta) * s;
            let (state, control) = guess.at(t).unwrap_or((self.problem.x0, [0.0; 2]));
            for c in 0..self.nx {
                x[self.state(k, c)] = state[c];
            }
            if k < self.layout.control_nodes() {
                for e in 0..self.nu {
                    x[self.control(k, e)] = control[e];
                }
            }
        }
        for (i, v) in x.iter_mut().enumerate() {
            *v = (*v / self.scale[i]).clamp(self.x_lo[i], self.x_hi[i]);
        }
    }
}
