//! The constraints (defects, phase order, rendezvous), their Jacobian's structure and
//! values, and the largest violation at a point.

// Index loops here mirror the equations (rows, nodes, state components) one to one.
#![allow(clippy::needless_range_loop)]

use super::Transcription;

impl Transcription {
    /// Scaled constraints.
    pub fn constraints(&mut self, x: &[f64], g: &mut [f64]) {
        self.unscale(x);
        let (nx, n_pts) = (self.nx, self.layout.lgr.len());
        for k in 0..self.layout.control_nodes() {
            let node = self.layout.nodes[k];
            let (ta, tb) = self.phase_times(&self.phys, node.phase);
            let dyn_ = self
                .vehicle
                .eval(&self.node_state(k), &self.node_control(k));
            for c in 0..nx {
                let mut d = 0.0;
                for j in 0..=n_pts {
                    d += self.layout.lgr.d(node.local, j)
                        * self.phys[self.state(node.interval_start + j, c)];
                }
                g[k * nx + c] = d - node.half * (tb - ta) * dyn_.f[c];
            }
        }
        let base = self.layout.control_nodes() * nx;
        let phases = self.layout.phases();
        for r in 0..phases - 1 {
            g[base + r] = self.phys[self.time(r + 1)] - self.phys[self.time(r)];
        }
        if let Some(lead) = &self.problem.lead {
            let last = self.layout.state_nodes() - 1;
            let tf = self.phys[self.time(phases - 1)];
            let lp = lead.at(tf);
            let rows = base + phases - 1;
            for c in 0..self.dim {
                g[rows + c] = self.phys[self.state(last, c)] - lp.position[c];
            }
            let h = self.problem.heading_index();
            g[rows + self.dim] = self.phys[self.state(last, h)] - lp.heading;
            if self.dim == 3 {
                g[rows + 4] = self.phys[self.state(last, 3)] - lp.gamma;
            }
        }
        for (v, s) in g.iter_mut().zip(&self.cscale) {
            *v *= s;
        }
    }

    /// Values of the scaled Jacobian, in the order of [`Transcription::jac`].
    pub fn jacobian(&mut self, x: &[f64], values: &mut [f64]) {
        self.unscale(x);
        let (nx, nu, n_pts) = (self.nx, self.nu, self.layout.lgr.len());
        let mut at = 0;
        for k in 0..self.layout.control_nodes() {
            let node = self.layout.nodes[k];
            let (ta, tb) = self.phase_times(&self.phys, node.phase);
            let hd = node.half * (tb - ta);
            let dyn_ = self
                .vehicle
                .eval(&self.node_state(k), &self.node_control(k));
            for c in 0..nx {
                for j in 0..=n_pts {
                    if j != node.local {
                        values[at] = self.layout.lgr.d(node.local, j);
                        at += 1;
                    }
                }
                for d in 0..nx {
                    let diag = if d == c {
                        self.layout.lgr.d(node.local, node.local)
                    } else {
                        0.0
                    };
                    values[at] = diag - hd * dyn_.jx[c][d];
                    at += 1;
                }
                for e in 0..nu {
                    values[at] = -hd * dyn_.ju[c][e];
                    at += 1;
                }
                if node.phase > 0 {
                    values[at] = node.half * dyn_.f[c];
                    at += 1;
                }
                values[at] = -node.half * dyn_.f[c];
                at += 1;
            }
        }
        let phases = self.layout.phases();
        for _ in 0..phases - 1 {
            values[at] = -1.0;
            values[at + 1] = 1.0;
            at += 2;
        }
        if let Some(lead) = &self.problem.lead {
            let tf = self.phys[self.time(phases - 1)];
            let lp = lead.at(tf);
            for c in 0..self.dim {
                values[at] = 1.0;
                values[at + 1] = -lp.velocity[c];
                at += 2;
            }
            let angles = if self.dim == 3 { 2 } else { 1 };
            for _ in 0..angles {
                values[at] = 1.0;
                values[at + 1] = 0.0;
                at += 2;
            }
        }
        debug_assert_eq!(at, values.len());
        for (v, &(r, c)) in values.iter_mut().zip(&self.jac) {
            *v *= self.cscale[r] * self.scale[c];
        }
    }

    /// The structure of the constraint Jacobian (row, column): per collocation node and
    /// state, the defect's states, controls and phase times; then the phase order rows
    /// and the rendezvous rows.
    pub(super) fn jacobian_structure(&self) -> Vec<(usize, usize)> {
        let (nx, nu) = (self.nx, self.nu);
        let n_pts = self.layout.lgr.len();
        let mut jac = Vec::new();
        for (k, node) in self.layout.nodes.iter().enumerate() {
            let p = node.phase;
            for c in 0..nx {
                let row = k * nx + c;
                for j in 0..=n_pts {
                    if j != node.local {
                        jac.push((row, self.state(node.interval_start + j, c)));
                    }
                }
                for d in 0..nx {
                    jac.push((row, self.state(k, d)));
                }
                for e in 0..nu {
                    jac.push((row, self.control(k, e)));
                }
                if p > 0 {
                    jac.push((row, self.time(p - 1)));
                }
                jac.push((row, self.time(p)));
            }
        }
        let base = self.layout.control_nodes() * nx;
        let phases = self.layout.phases();
        for r in 0..phases - 1 {
            jac.push((base + r, self.time(r)));
            jac.push((base + r, self.time(r + 1)));
        }
        if self.problem.lead.is_some() {
            let last = self.layout.state_nodes() - 1;
            let tf = self.time(phases - 1);
            let rows = base + phases - 1;
            let h = self.problem.heading_index();
            let mut comps: Vec<usize> = (0..self.dim).collect();
            comps.push(h);
            if self.dim == 3 {
                comps.push(3);
            }
            for (r, c) in comps.into_iter().enumerate() {
                jac.push((rows + r, self.state(last, c)));
                jac.push((rows + r, tf));
            }
        }
        jac
    }

    /// Largest violation of the scaled constraints and bounds at `x` (with `g` evaluated
    /// into `g_buf`).
    pub fn violation(&mut self, x: &[f64], g_buf: &mut [f64]) -> f64 {
        self.constraints(x, g_buf);
        let mut worst: f64 = 0.0;
        for r in 0..g_buf.len() {
            worst = worst
                .max(self.g_lo[r] - g_buf[r])
                .max(g_buf[r] - self.g_hi[r]);
        }
        for i in 0..x.len() {
            worst = worst.max(self.x_lo[i] - x[i]).max(x[i] - self.x_hi[i]);
        }
        worst
    }
}
