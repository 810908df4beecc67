//! The objective `time_weight · T_P + run_weight · ∫ L dt` (LGR quadrature of the running
//! cost) and its gradient.

// Index loops here mirror the equations (rows, nodes, state components) one to one.
#![allow(clippy::needless_range_loop)]

use super::Transcription;

impl Transcription {
    /// Running cost `L = (1 - beta)|u|² + beta E(position, t)`.
    fn running(&self, x: &[f64; 7], u: &[f64; 2], t: f64) -> f64 {
        let w = &self.problem.weights;
        let uu: f64 = u[..self.nu].iter().map(|v| v * v).sum();
        let p = [x[0], x[1], if self.dim == 3 { x[2] } else { 0.0 }];
        (1.0 - w.beta) * uu + w.beta * self.problem.exposure(&p, t)
    }

    /// The physical objective.
    pub fn objective(&mut self, x: &[f64]) -> f64 {
        self.unscale(x);
        self.objective_phys() * self.obj_scale
    }

    fn objective_phys(&self) -> f64 {
        let mut run = 0.0;
        for (k, node) in self.layout.nodes.iter().enumerate() {
            let (ta, tb) = self.phase_times(&self.phys, node.phase);
            let dt = tb - ta;
            let t = ta + dt * node.s;
            run += node.quad * dt * self.running(&self.node_state(k), &self.node_control(k), t);
        }
        let tf = self.phys[self.time(self.layout.phases() - 1)];
        self.time_weight * tf + self.run_weight * run
    }

    /// The physical objective at physical variables (for reports and tests).
    pub fn objective_of_physical(&mut self, phys: &[f64]) -> f64 {
        self.phys.copy_from_slice(phys);
        self.objective_phys()
    }

    /// Gradient of the scaled objective.
    pub fn gradient(&mut self, x: &[f64], grad: &mut [f64]) {
        self.unscale(x);
        grad.iter_mut().for_each(|g| *g = 0.0);
        let beta = self.problem.weights.beta;
        for k in 0..self.layout.control_nodes() {
            let node = self.layout.nodes[k];
            let (ta, tb) = self.phase_times(&self.phys, node.phase);
            let dt = tb - ta;
            let t = ta + dt * node.s;
            let (xs, u) = (self.node_state(k), self.node_control(k));
            let e = self
                .problem
                .exposure_wt(&[xs[0], xs[1], if self.dim == 3 { xs[2] } else { 0.0 }], t);
            let uu: f64 = u[..self.nu].iter().map(|v| v * v).sum();
            let l = (1.0 - beta) * uu + beta * e.value;
            let lt = beta * e.grad[3];
            let w = self.run_weight * node.quad;
            for c in 0..self.dim {
                grad[self.state(k, c)] += w * dt * beta * e.grad[c];
            }
            for i in 0..self.nu {
                grad[self.control(k, i)] += w * dt * 2.0 * (1.0 - beta) * u[i];
            }
            if node.phase > 0 {
                grad[self.time(node.phase - 1)] += w * (-l + dt * (1.0 - node.s) * lt);
            }
            grad[self.time(node.phase)] += w * (l + dt * node.s * lt);
        }
        let tf = self.time(self.layout.phases() - 1);
        grad[tf] += self.time_weight;
        for (g, s) in grad.iter_mut().zip(&self.scale) {
            *g *= s * self.obj_scale;
        }
    }
}
