//! The structured KKT backend (`collocation::kkt`) inside real solves: a collocation solve
//! with it reaches the objective of a solve with FERAL, and its factorise-and-solve loop
//! does not allocate.

use std::time::Duration;

use wingman_planner::clock::Deadline;
use wingman_planner::collocation::kkt::block_factorizations_total;
use wingman_planner::collocation::{
    KktLabels, KktSolver, Mesh, NlpSettings, NlpStatus, PrimalDual, SolveBudget, StructuredKkt,
    Transcription, TranscriptionSettings, solve,
};
use wingman_planner::hybrid::phase_durations;

use pounce_linsol::{ESymSolverStatus, SparseSymLinearSolverInterface};

#[path = "support/counting_alloc.rs"]
mod counting_alloc;
use counting_alloc::allocations_in;

#[path = "support/planned.rs"]
mod planned;
use planned::{clock, planned, transcribed};

/// Cold solves of `name` on a 5-point mesh from the hybrid planner's plan, with FERAL and
/// with the structured backend: both converge, to the same objective within 1e-5 of it
/// (the solves take different pivots, so their iterates differ by rounding, and both stop
/// at `tol` 1e-7 on the scaled problem), and the structured one used block elimination.
fn same_objective(name: &str) {
    let (p, guess) = planned(name);
    let mesh = Mesh::uniform(5, &phase_durations(p.t0, &guess), 35.0, 2);
    let mut objective = [0.0; 2];
    for (slot, kkt) in [KktSolver::Feral, KktSolver::Structured]
        .into_iter()
        .enumerate()
    {
        let (tr, x) = transcribed(&p, &mesh, &guess);
        let start = PrimalDual {
            x,
            ..PrimalDual::default()
        };
        let nlp = NlpSettings {
            kkt,
            mu_init: Some(1e-3),
            ..NlpSettings::default()
        };
        let before = block_factorizations_total();
        let (_, out) = solve(
            tr,
            start,
            false,
            &nlp,
            SolveBudget::until(Deadline::after(clock(), Duration::from_secs(60))),
        )
        .unwrap();
        assert_eq!(
            out.status,
            NlpStatus::Converged,
            "{kkt:?}: {:?}",
            out.return_status
        );
        if kkt == KktSolver::Structured {
            assert!(
                block_factorizations_total() > before,
                "no block factorisation"
            );
        }
        objective[slot] = out.objective;
    }
    let rel = (objective[1] - objective[0]).abs() / objective[0].abs();
    assert!(
        rel < 1e-5,
        "{name}: objectives {objective:?} differ by {rel:e}"
    );
}

#[test]
fn structured_solve_reaches_ferals_objective_2d_rendezvous() {
    same_objective("2d-min-time-rendezvous-avoidable");
}

#[test]
fn structured_solve_reaches_ferals_objective_2d_fixed_time() {
    same_objective("2d-fixed-time-unavoidable");
}

#[test]
fn structured_solve_reaches_ferals_objective_3d_rendezvous() {
    same_objective("3d-min-time-rendezvous-avoidable");
}

/// The labels of a real transcription of `name`, on a KKT pattern assembled as pounce
/// assembles it (`[x not fixed | slacks | equality duals | inequality duals]`, Hessian
/// and Jacobian entries, every diagonal), are accepted, with a border of at most
/// `3 · phases + 3` indices (the phase times, the phase-order rows' slacks and duals, the
/// rendezvous rows); then factorising and solving again and again (two right-hand sides)
/// allocates nothing.
fn labels_fit_and_do_not_allocate(name: &str) {
    let (p, guess) = planned(name);
    let mesh = Mesh::uniform(5, &phase_durations(p.t0, &guess), 35.0, 2);
    let tr = Transcription::new(&p, &mesh, &guess, &TranscriptionSettings::default());
    let labels = KktLabels::of(&tr);
    let border = labels.blocks.iter().filter(|&&l| l < 0).count();
    let phases = mesh.phases.len();
    assert!(
        border <= 3 * phases + 3,
        "{name}: border of {border} with {phases} phases"
    );
    // KKT positions, as pounce numbers them.
    let fixed = |i: usize| tr.x_lo[i] == tr.x_hi[i];
    let mut xpos = vec![usize::MAX; tr.n_vars()];
    let mut n = 0;
    for (i, slot) in xpos.iter_mut().enumerate() {
        if !fixed(i) {
            *slot = n;
            n += 1;
        }
    }
    let eq = |r: usize| tr.g_lo[r] == tr.g_hi[r];
    let n_d = (0..tr.n_cons()).filter(|&r| !eq(r)).count();
    let n_c = tr.n_cons() - n_d;
    let (mut cpos, mut dpos) = (vec![usize::MAX; tr.n_cons()], vec![usize::MAX; tr.n_cons()]);
    let (mut c, mut d) = (0, 0);
    for r in 0..tr.n_cons() {
        if eq(r) {
            cpos[r] = n + n_d + c;
            c += 1;
        } else {
            dpos[r] = n + n_d + n_c + d;
            d += 1;
        }
    }
    let dim = n + 2 * n_d + n_c;
    let (mut ia, mut ja, mut va) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |i: usize, j: usize, v: f64| {
        ia.push(i.max(j) as i32 + 1);
        ja.push(i.min(j) as i32 + 1);
        va.push(v);
    };
    for i in 0..dim {
        // Primal diagonal positive, dual diagonal negative: a quasi-definite KKT.
        push(
            i,
            i,
            if i < n + n_d {
                4.0 + (i % 5) as f64
            } else {
                -1e-2
            },
        );
    }
    for &(r, c) in &tr.hess {
        if xpos[r] != usize::MAX && xpos[c] != usize::MAX && r != c {
            push(xpos[r], xpos[c], 0.1);
        }
    }
    for &(r, c) in &tr.jac {
        if xpos[c] != usize::MAX {
            let row = if eq(r) { cpos[r] } else { dpos[r] };
            push(row, xpos[c], 0.3);
        }
    }
    for (k, r) in (0..tr.n_cons()).filter(|&r| !eq(r)).enumerate() {
        push(dpos[r], n + k, -1.0);
    }
    let mut solver = StructuredKkt::new(Some(labels), Default::default());
    let nnz = ia.len() as i32;
    assert_eq!(
        solver.initialize_structure(dim as i32, nnz, &ia, &ja),
        ESymSolverStatus::Success
    );
    assert!(
        solver.is_structured(),
        "the transcription's labels fit its KKT"
    );
    let mut rhs = vec![1.0; 2 * dim];
    let round = |solver: &mut StructuredKkt, rhs: &mut [f64]| {
        solver.values_array_mut().copy_from_slice(&va);
        let status = solver.multi_solve(true, &ia, &ja, 2, rhs, true, (n_c + n_d) as i32);
        assert_eq!(status, ESymSolverStatus::Success);
        let status = solver.multi_solve(false, &ia, &ja, 2, rhs, false, 0);
        assert_eq!(status, ESymSolverStatus::Success);
    };
    round(&mut solver, &mut rhs);
    let allocations = allocations_in(|| {
        for _ in 0..10 {
            round(&mut solver, &mut rhs);
        }
    });
    assert_eq!(allocations, 0);
    assert_eq!(solver.feral_factorizations, 0);
}

#[test]
fn factorise_and_solve_do_not_allocate_2d() {
    labels_fit_and_do_not_allocate("2d-min-time-rendezvous-avoidable");
}

#[test]
fn factorise_and_solve_do_not_allocate_3d() {
    labels_fit_and_do_not_allocate("3d-min-time-rendezvous-unavoidable");
}

/// The pivot groups of a real transcription: one per collocation node, each its controls
/// and the defect rows of the states they drive (`2 · nu` KKT indices); and the model's
/// controls drive exactly those states (`df_c/du_e` is zero for every other state and
/// nonzero for the driven one, at random states and controls).
fn groups_are_the_nodes_controls_and_driven_rows(name: &str) {
    use rand::{RngExt, SeedableRng};
    let (p, guess) = planned(name);
    let mesh = Mesh::uniform(5, &phase_durations(p.t0, &guess), 35.0, 2);
    let (tr, _) = transcribed(&p, &mesh, &guess);
    let labels = KktLabels::of(&tr);
    assert_eq!(labels.groups.len(), labels.blocks.len());
    let mut sizes = std::collections::BTreeMap::new();
    for (&g, &b) in labels.groups.iter().zip(&labels.blocks) {
        if g >= 0 {
            let entry = sizes.entry(g).or_insert((0, b));
            entry.0 += 1;
            assert_eq!(entry.1, b, "a group lies inside one block");
        }
    }
    assert_eq!(sizes.len(), tr.layout.control_nodes());
    assert!(sizes.values().all(|&(n, _)| n == 2 * tr.nu));
    let driven = tr.vehicle.driven_states();
    assert_eq!(driven.len(), tr.nu);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    for _ in 0..50 {
        let x: [f64; 7] = std::array::from_fn(|c| match c {
            3 => rng.random_range(-0.3..0.3),
            5 => rng.random_range(0.5..2.5),
            6 => rng.random_range(-1.0..1.0),
            _ => rng.random_range(-5.0..5.0),
        });
        let u: [f64; 2] = std::array::from_fn(|_| rng.random_range(-0.1..0.1));
        let d = tr.vehicle.eval(&x, &u);
        for (e, &drives) in driven.iter().enumerate() {
            for c in 0..tr.nx {
                if c == drives {
                    assert!(d.ju[c][e] != 0.0, "control {e} drives state {c}");
                } else {
                    assert_eq!(d.ju[c][e], 0.0, "control {e} does not drive state {c}");
                }
            }
        }
    }
}

#[test]
fn pivot_groups_2d() {
    groups_are_the_nodes_controls_and_driven_rows("2d-min-time-rendezvous-avoidable");
}

#[test]
fn pivot_groups_3d() {
    groups_are_the_nodes_controls_and_driven_rows("3d-min-time-rendezvous-unavoidable");
}
