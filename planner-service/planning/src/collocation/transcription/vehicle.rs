//! The vehicle model of the transcription: the 2-D or 3-D model behind one enum, with its
//! right-hand side, Jacobians and weighted Hessian padded to the 3-D sizes, allocation-free.

// Index loops here mirror the equations (rows, nodes, state components) one to one.
#![allow(clippy::needless_range_loop)]

use wingman_interfaces::Model;

use crate::dynamics::{OdeModel, Planar, Spatial};
use crate::problem::Problem;

/// The vehicle model with padded, allocation-free derivatives.
#[derive(Debug, Clone, Copy)]
pub enum Vehicle {
    Planar(Planar),
    Spatial(Spatial),
}

/// Right-hand side and Jacobians at one node, padded to the 3-D sizes.
#[derive(Debug, Clone, Copy)]
pub struct NodeDynamics {
    pub f: [f64; 7],
    /// `df_c/dx_d` at `[c][d]`.
    pub jx: [[f64; 7]; 7],
    /// `df_c/du_e` at `[c][e]`.
    pub ju: [[f64; 2]; 7],
}

impl Vehicle {
    /// The states whose rates the controls drive, one per control (`f_c` of any other
    /// state does not depend on the controls): `psi` in 2-D, `Nz` and `mu` in 3-D.
    pub fn driven_states(&self) -> &'static [usize] {
        use crate::dynamics::{idx2, idx3};
        match self {
            Vehicle::Planar(_) => &[idx2::PSI],
            Vehicle::Spatial(_) => &[idx3::NZ, idx3::MU],
        }
    }

    pub fn new(problem: &Problem) -> Vehicle {
        // The limits were checked when the problem was built, so the speed is positive.
        let v = problem.limits.speed;
        let wind = problem.wind;
        match problem.model {
            Model::TwoD => Vehicle::Planar(
                Planar::new(v)
                    .unwrap_or_else(|_| unreachable_speed(v))
                    .with_wind(wind),
            ),
            Model::ThreeD => Vehicle::Spatial(
                Spatial::new(v)
                    .unwrap_or_else(|_| unreachable_speed(v))
                    .with_wind(wind),
            ),
        }
    }

    /// The right-hand side `f` alone (padded).
    pub fn rhs(&self, x: &[f64; 7], u: &[f64; 2]) -> [f64; 7] {
        match self {
            Vehicle::Planar(m) => {
                let f = m.rhs(&[x[0], x[1], x[2]], &[u[0]]);
                [f[0], f[1], f[2], 0.0, 0.0, 0.0, 0.0]
            }
            Vehicle::Spatial(m) => m.rhs(x, u),
        }
    }

    /// RK4 over `dt` in `steps` equal steps, with the control linear from `ua` to `ub`
    /// (how a judge or the tracker interpolates sampled controls).
    pub fn integrate_linear(
        &self,
        x0: &[f64; 7],
        ua: &[f64; 2],
        ub: &[f64; 2],
        dt: f64,
        steps: usize,
    ) -> [f64; 7] {
        let steps = steps.max(1);
        let h = dt / steps as f64;
        let control = |s: f64| -> [f64; 2] {
            let f = if dt > 0.0 { s / dt } else { 0.0 };
            [ua[0] + f * (ub[0] - ua[0]), ua[1] + f * (ub[1] - ua[1])]
        };
        let mut x = *x0;
        for i in 0..steps {
            let s = i as f64 * h;
            let k1 = self.rhs(&x, &control(s));
            let x2: [f64; 7] = std::array::from_fn(|c| x[c] + 0.5 * h * k1[c]);
            let k2 = self.rhs(&x2, &control(s + 0.5 * h));
            let x3: [f64; 7] = std::array::from_fn(|c| x[c] + 0.5 * h * k2[c]);
            let k3 = self.rhs(&x3, &control(s + 0.5 * h));
            let x4: [f64; 7] = std::array::from_fn(|c| x[c] + h * k3[c]);
            let k4 = self.rhs(&x4, &control(s + h));
            for c in 0..7 {
                x[c] += h / 6.0 * (k1[c] + 2.0 * k2[c] + 2.0 * k3[c] + k4[c]);
            }
        }
        x
    }

    /// `f`, `df/dx`, `df/du`.
    pub fn eval(&self, x: &[f64; 7], u: &[f64; 2]) -> NodeDynamics {
        let mut out = NodeDynamics {
            f: [0.0; 7],
            jx: [[0.0; 7]; 7],
            ju: [[0.0; 2]; 7],
        };
        match self {
            Vehicle::Planar(m) => {
                let (xs, us) = ([x[0], x[1], x[2]], [u[0]]);
                let f = m.rhs(&xs, &us);
                let (jx, ju) = (m.jac_x(&xs, &us), m.jac_u(&xs, &us));
                for c in 0..3 {
                    out.f[c] = f[c];
                    out.ju[c][0] = ju[(c, 0)];
                    for d in 0..3 {
                        out.jx[c][d] = jx[(c, d)];
                    }
                }
            }
            Vehicle::Spatial(m) => {
                out.f = m.rhs(x, u);
                let (jx, ju) = (m.jac_x(x, u), m.jac_u(x, u));
                for c in 0..7 {
                    for d in 0..7 {
                        out.jx[c][d] = jx[(c, d)];
                    }
                    for e in 0..2 {
                        out.ju[c][e] = ju[(c, e)];
                    }
                }
            }
        }
        out
    }

    /// `Σ_c λ_c ∇²f_c` over `z = (states, controls)` (`nx + nu` used, padded to 9).
    pub fn hessian_weighted(&self, x: &[f64; 7], u: &[f64; 2], lambda: &[f64; 7]) -> [[f64; 9]; 9] {
        let mut out = [[0.0; 9]; 9];
        match self {
            Vehicle::Planar(m) => {
                let h = m.hessian_weighted(
                    &[x[0], x[1], x[2]],
                    &[u[0]],
                    &[lambda[0], lambda[1], lambda[2]],
                );
                for i in 0..4 {
                    for j in 0..4 {
                        out[i][j] = h[(i, j)];
                    }
                }
            }
            Vehicle::Spatial(m) => {
                let h = m.hessian_weighted(x, u, lambda);
                for i in 0..9 {
                    for j in 0..9 {
                        out[i][j] = h[(i, j)];
                    }
                }
            }
        }
        out
    }
}

fn unreachable_speed(v: f64) -> ! {
    panic!("vehicle speed {v} was accepted by Problem::validate but refused by the model")
}
