//! The layout of the NLP's variables: the index of each state, control and phase end time,
//! the variables one node's terms depend on, and the physical values of the current
//! (scaled) variables.

use super::Transcription;

impl Transcription {
    /// Number of variables.
    pub fn n_vars(&self) -> usize {
        self.scale.len()
    }

    /// Number of constraints.
    pub fn n_cons(&self) -> usize {
        self.cscale.len()
    }

    /// Index of state `c` of node `k`.
    pub fn state(&self, k: usize, c: usize) -> usize {
        k * self.nx + c
    }

    /// Index of control `e` of collocation node `k`.
    pub fn control(&self, k: usize, e: usize) -> usize {
        self.layout.state_nodes() * self.nx + k * self.nu + e
    }

    /// Index of `T_{p+1}` (the end time of phase `p`).
    pub fn time(&self, p: usize) -> usize {
        self.layout.state_nodes() * self.nx + self.layout.control_nodes() * self.nu + p
    }

    pub(super) fn phase_times(&self, x: &[f64], p: usize) -> (f64, f64) {
        let start = if p == 0 {
            self.problem.t0
        } else {
            x[self.time(p - 1)]
        };
        (start, x[self.time(p)])
    }

    /// The variables one collocation node's terms depend on, in increasing index order:
    /// its states, its controls, the phase's start time (if a variable) and end time.
    pub(super) fn node_vars(&self, k: usize) -> NodeVars {
        let p = self.layout.nodes[k].phase;
        let mut v = NodeVars {
            idx: [0; 11],
            len: 0,
        };
        for c in 0..self.nx {
            v.push(self.state(k, c));
        }
        for e in 0..self.nu {
            v.push(self.control(k, e));
        }
        if p > 0 {
            v.push(self.time(p - 1));
        }
        v.push(self.time(p));
        v
    }

    /// Physical values of the scaled variables `x` into the internal buffer.
    pub(super) fn unscale(&mut self, x: &[f64]) {
        for ((p, &v), &s) in self.phys.iter_mut().zip(x).zip(&self.scale) {
            *p = v * s;
        }
    }

    pub(super) fn node_state(&self, k: usize) -> [f64; 7] {
        let mut s = [0.0; 7];
        s[..self.nx].copy_from_slice(&self.phys[k * self.nx..(k + 1) * self.nx]);
        s
    }

    pub(super) fn node_control(&self, k: usize) -> [f64; 2] {
        let mut u = [0.0; 2];
        let base = self.control(k, 0);
        u[..self.nu].copy_from_slice(&self.phys[base..base + self.nu]);
        u
    }

    /// Node times (physical) at the scaled variables `x`.
    pub fn node_times(&self, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        let t0 = self.problem.t0;
        for k in 0..self.layout.state_nodes() {
            let (p, s) = self.layout.node_phase_fraction(k);
            let ta = if p == 0 {
                t0
            } else {
                x[self.time(p - 1)] * self.scale[self.time(p - 1)]
            };
            let tb = x[self.time(p)] * self.scale[self.time(p)];
            out.push(ta + (tb - ta) * s);
        }
    }
}

/// Up to 11 variable indices of one node, in increasing order.
#[derive(Debug, Clone, Copy)]
pub(super) struct NodeVars {
    pub(super) idx: [usize; 11],
    pub(super) len: usize,
}

impl NodeVars {
    fn push(&mut self, i: usize) {
        self.idx[self.len] = i;
        self.len += 1;
    }
}
