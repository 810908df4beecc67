//! The multi-phase LGR transcription of the optimal control problem (FORMULATION.md §4) as
//! a sparse NLP: variables, bounds, objective, constraints, and exact sparse first and
//! second derivatives. Pure functions of the (scaled) variable vector; they do not
//! allocate, so the solver's callbacks do not either.
//!
//! Variables, in this order (physical value = `scale[i] ·` NLP value):
//! - states `X[k][c]` at every node `k = 0..=K` (`K` collocation nodes + the final node);
//! - controls `U[k][e]` at the collocation nodes `k = 0..K`;
//! - phase end times `T_1 … T_P` (`T_0 = t0` is a constant; `T_P` is the final time).
//!
//! Constraints, in this order:
//! - defects `Σ_j D_ij X_j - half · Δ_p · f(X_i, U_i) = 0` at every collocation node, one
//!   row per state (`Δ_p = T_{p+1} - T_p`);
//! - phase order `T_{p+1} - T_p ≥ min_phase_s` for `p ≥ 1`;
//! - rendezvous (`MinTimeRendezvous` only): final position = lead position at `T_P`, final
//!   heading = lead heading (+ 2πk), and in 3-D final gamma = lead gamma.
//!
//! The start state is fixed by bounds, each target fixes the position of its phase's last
//! node, and a fixed final state fixes the final node (heading modulo 2π: the multiple of
//! 2π nearest the initial guess). Threats are only in the cost, never constraints.

// Index loops here mirror the equations (rows, nodes, state components) one to one.
#![allow(clippy::needless_range_loop)]

use wingman_interfaces::{Model, Objective};

use super::mesh::{Layout, Mesh};
use crate::dynamics::{OdeModel, Planar, Spatial};
use crate::problem::Problem;
use crate::trajectory::Trajectory;

/// Bound magnitude meaning "no bound" (pounce's default `nlp_*_bound_inf` is 1e19).
pub const INF: f64 = 1e20;

/// Settings of the transcription.
#[derive(Debug, Clone, PartialEq)]
pub struct TranscriptionSettings {
    /// Shortest phase allowed.
    pub min_phase_s: f64,
    /// Longest mission allowed, as a multiple of the initial guess's duration.
    pub max_duration_factor: f64,
    /// Length scale of positions in the NLP.
    pub length_scale_m: f64,
    /// Share of each bounded range kept free at the nodes (gamma, Nz, mu, controls), so
    /// that the path between nodes and the tracker's corrections stay inside the vehicle's
    /// true limits.
    pub bound_margin: f64,
    /// Height kept above the minimum altitude at the nodes, for the same reason.
    pub altitude_margin_m: f64,
}

impl Default for TranscriptionSettings {
    fn default() -> Self {
        TranscriptionSettings {
            min_phase_s: 1.0,
            max_duration_factor: 4.0,
            length_scale_m: 10_000.0,
            bound_margin: 0.02,
            altitude_margin_m: 20.0,
        }
    }
}

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
        match problem.model {
            Model::TwoD => Vehicle::Planar(Planar::new(v).unwrap_or_else(|_| unreachable_speed(v))),
            Model::ThreeD => {
                Vehicle::Spatial(Spatial::new(v).unwrap_or_else(|_| unreachable_speed(v)))
            }
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

/// The NLP of one problem on one mesh.
#[derive(Debug, Clone)]
pub struct Transcription {
    pub problem: Problem,
    pub vehicle: Vehicle,
    pub layout: Layout,
    pub nx: usize,
    pub nu: usize,
    /// Position coordinates (2 or 3).
    pub dim: usize,
    /// Physical value of one NLP unit, per variable.
    pub scale: Vec<f64>,
    /// NLP value of one physical unit, per constraint.
    pub cscale: Vec<f64>,
    /// NLP objective per unit of physical objective.
    pub obj_scale: f64,
    /// Scaled variable bounds.
    pub x_lo: Vec<f64>,
    pub x_hi: Vec<f64>,
    /// Scaled constraint bounds.
    pub g_lo: Vec<f64>,
    pub g_hi: Vec<f64>,
    /// Jacobian structure (row, column).
    pub jac: Vec<(usize, usize)>,
    /// Hessian structure (row, column), lower triangle, duplicates summed.
    pub hess: Vec<(usize, usize)>,
    /// Weight of the running cost in the objective (`1 - alpha` or 1).
    run_weight: f64,
    /// Weight of `T_P` in the objective (`alpha` or 0).
    time_weight: f64,
    /// Physical values of the current variables.
    phys: Vec<f64>,
}

impl Transcription {
    /// The transcription of `problem` on `mesh`, with bounds, scaling and the final
    /// heading's multiple of 2π taken from the initial guess `guess`.
    pub fn new(
        problem: &Problem,
        mesh: &Mesh,
        guess: &Trajectory,
        settings: &TranscriptionSettings,
    ) -> Transcription {
        let layout = Layout::new(mesh);
        let (nx, nu, dim) = (problem.nx(), problem.nu(), problem.dim());
        let phases = layout.phases();
        let n_nodes = layout.state_nodes();
        let n_ctrl = layout.control_nodes();
        let n_vars = n_nodes * nx + n_ctrl * nu + phases;
        let rendezvous = problem.objective == Objective::MinTimeRendezvous;
        let n_rdv = if rendezvous {
            dim + 1 + usize::from(dim == 3)
        } else {
            0
        };
        let n_cons = n_ctrl * nx + (phases - 1) + n_rdv;

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

        let mut t = Transcription {
            problem: problem.clone(),
            vehicle: Vehicle::new(problem),
            layout,
            nx,
            nu,
            dim,
            scale,
            cscale,
            obj_scale: 1.0,
            x_lo: vec![-INF; n_vars],
            x_hi: vec![INF; n_vars],
            g_lo: vec![0.0; n_cons],
            g_hi: vec![0.0; n_cons],
            jac: Vec::new(),
            hess: Vec::new(),
            run_weight: if problem.objective == Objective::FixedTime {
                1.0
            } else {
                1.0 - problem.weights.alpha
            },
            time_weight: if problem.objective == Objective::FixedTime {
                0.0
            } else {
                problem.weights.alpha
            },
            phys: vec![0.0; n_vars],
        };
        t.set_bounds(guess, settings);
        t.build_structure();
        t
    }

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

    fn phase_times(&self, x: &[f64], p: usize) -> (f64, f64) {
        let start = if p == 0 {
            self.problem.t0
        } else {
            x[self.time(p - 1)]
        };
        (start, x[self.time(p)])
    }

    fn set_bounds(&mut self, guess: &Trajectory, settings: &TranscriptionSettings) {
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

    fn build_structure(&mut self) {
        let (nx, nu) = (self.nx, self.nu);
        let n_pts = self.layout.lgr.len();
        let mut jac = Vec::new();
        let mut hess = Vec::new();
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
            let vars = self.node_vars(k);
            for i in 0..vars.len {
                for j in 0..=i {
                    hess.push((vars.idx[i], vars.idx[j]));
                }
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
        self.jac = jac;
        self.hess = hess;
    }

    /// The variables one collocation node's terms depend on, in increasing index order:
    /// its states, its controls, the phase's start time (if a variable) and end time.
    fn node_vars(&self, k: usize) -> NodeVars {
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
    fn unscale(&mut self, x: &[f64]) {
        for ((p, &v), &s) in self.phys.iter_mut().zip(x).zip(&self.scale) {
            *p = v * s;
        }
    }

    fn node_state(&self, k: usize) -> [f64; 7] {
        let mut s = [0.0; 7];
        s[..self.nx].copy_from_slice(&self.phys[k * self.nx..(k + 1) * self.nx]);
        s
    }

    fn node_control(&self, k: usize) -> [f64; 2] {
        let mut u = [0.0; 2];
        let base = self.control(k, 0);
        u[..self.nu].copy_from_slice(&self.phys[base..base + self.nu]);
        u
    }

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

/// `target + 2πk` for the integer `k` that brings it nearest to `reference`.
pub fn nearest_turn(target: f64, reference: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    target + tau * ((reference - target) / tau).round()
}

/// Up to 11 variable indices of one node, in increasing order.
#[derive(Debug, Clone, Copy)]
struct NodeVars {
    idx: [usize; 11],
    len: usize,
}

impl NodeVars {
    fn push(&mut self, i: usize) {
        self.idx[self.len] = i;
        self.len += 1;
    }
}
