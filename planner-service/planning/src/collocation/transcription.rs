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

mod bounds;
mod constraints;
mod hessian;
mod layout;
mod objective;
mod scaling;
mod vehicle;

pub use bounds::nearest_turn;
pub use vehicle::{NodeDynamics, Vehicle};

use wingman_interfaces::Objective;

use super::mesh::{Layout, Mesh};
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

        let scale = scaling::variable_scales(problem, &layout, settings);
        let cscale = scaling::constraint_scales(problem, &layout, settings, &scale, n_cons);

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
        t.jac = t.jacobian_structure();
        t.hess = t.hessian_structure();
        t
    }
}
