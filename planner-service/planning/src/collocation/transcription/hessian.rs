//! The Hessian of the Lagrangian: its values (dense per collocation node over the node's
//! variables, then scaled) and its structure.

// Index loops here mirror the equations (rows, nodes, state components) one to one.
#![allow(clippy::needless_range_loop)]

use super::Transcription;

impl Transcription {
    /// Values of the scaled Hessian of the Lagrangian `obj_factor · f + Σ λ_r g_r`, in the
    /// order of [`Transcription::hess`].
    pub fn hessian(&mut self, x: &[f64], obj_factor: f64, lambda: &[f64], values: &mut [f64]) {
        self.unscale(x);
        let (nx, nu, dim) = (self.nx, self.nu, self.dim);
        let beta = self.problem.weights.beta;
        let sigma = obj_factor * self.obj_scale * self.run_weight;
        let mut at = 0;
        for k in 0..self.layout.control_nodes() {
            let node = self.layout.nodes[k];
            let (ta, tb) = self.phase_times(&self.phys, node.phase);
            let dt = tb - ta;
            let t = ta + dt * node.s;
            let (xs, u) = (self.node_state(k), self.node_control(k));
            let vars = self.node_vars(k);
            let m = vars.len;
            let has_a = node.phase > 0;
            let (ia, ib) = (nx + nu, nx + nu + usize::from(has_a));
            // Local dense Hessian over the node's variables (physical units).
            let mut h = [[0.0; 11]; 11];

            // Running cost: J = sigma · quad · dt · L(x, u, t).
            let e = self
                .problem
                .exposure_wt(&[xs[0], xs[1], if dim == 3 { xs[2] } else { 0.0 }], t);
            let lt = beta * e.grad[3];
            let ltt = beta * e.hess[3][3];
            let w = sigma * node.quad;
            // Gradient of L over the node's (states, controls) and its time derivative.
            let mut lz = [0.0; 9];
            let mut lzt = [0.0; 9];
            for c in 0..dim {
                lz[c] = beta * e.grad[c];
                lzt[c] = beta * e.hess[c][3];
                for d in 0..dim {
                    h[c][d] += w * dt * beta * e.hess[c][d];
                }
            }
            for i in 0..nu {
                lz[nx + i] = 2.0 * (1.0 - beta) * u[i];
                h[nx + i][nx + i] += w * dt * 2.0 * (1.0 - beta);
            }
            let s = node.s;
            for z in 0..nx + nu {
                h[ib][z] += w * (lz[z] + dt * s * lzt[z]);
                if has_a {
                    h[ia][z] += w * (-lz[z] + dt * (1.0 - s) * lzt[z]);
                }
            }
            h[ib][ib] += w * (2.0 * s * lt + dt * s * s * ltt);
            if has_a {
                h[ia][ia] += w * (-2.0 * (1.0 - s) * lt + dt * (1.0 - s) * (1.0 - s) * ltt);
                h[ib][ia] += w * ((1.0 - 2.0 * s) * lt + dt * s * (1.0 - s) * ltt);
            }

            // Defects: Σ_c λ_c (-half · dt · f_c).
            let mut lam = [0.0; 7];
            for c in 0..nx {
                lam[c] = lambda[k * nx + c] * self.cscale[k * nx + c];
            }
            let hw = self.vehicle.hessian_weighted(&xs, &u, &lam);
            let dyn_ = self.vehicle.eval(&xs, &u);
            for i in 0..nx + nu {
                for j in 0..=i {
                    h[i][j] -= node.half * dt * hw[i][j];
                }
                // Σ_c λ_c ∂f_c/∂z_i.
                let mut lf = 0.0;
                for c in 0..nx {
                    lf += lam[c]
                        * if i < nx {
                            dyn_.jx[c][i]
                        } else {
                            dyn_.ju[c][i - nx]
                        };
                }
                h[ib][i] -= node.half * lf;
                if has_a {
                    h[ia][i] += node.half * lf;
                }
            }
            for i in 0..m {
                for j in 0..=i {
                    values[at] = h[i][j] * self.scale[vars.idx[i]] * self.scale[vars.idx[j]];
                    at += 1;
                }
            }
        }
        debug_assert_eq!(at, values.len());
    }

    /// The structure of the Hessian of the Lagrangian (row, column), lower triangle: per
    /// collocation node, every pair of the variables its terms depend on.
    pub(super) fn hessian_structure(&self) -> Vec<(usize, usize)> {
        let mut hess = Vec::new();
        for k in 0..self.layout.nodes.len() {
            let vars = self.node_vars(k);
            for i in 0..vars.len {
                for j in 0..=i {
                    hess.push((vars.idx[i], vars.idx[j]));
                }
            }
        }
        hess
    }
}
