//! The structured KKT backend (`collocation::kkt`) inside real solves: a collocation solve
//! with it reaches the objective of a solve with FERAL, and its factorise-and-solve loop
//! does not allocate.

use std::sync::Arc;
use std::time::Duration;

use wingman_planning::clock::Deadline;
use wingman_planning::collocation::kkt::KktCache;
use wingman_planning::collocation::{
    KktLabels, KktSolver, Mesh, NlpSettings, NlpStatus, PrimalDual, SolveBudget, StructuredKkt,
    Transcription, TranscriptionSettings, solve,
};
use wingman_planning::hybrid::phase_durations;

use pounce_linsol::{ESymSolverStatus, SparseSymLinearSolverInterface};

wingman_testkit::counting_allocator!();
use counting_alloc::allocations_in;
use wingman_testkit::counting_alloc;

mod common;
use common::{clock, planned_globally, transcribed};

/// Cold solves of `name` on a 5-point mesh from the plan of the hybrid planner's global
/// search, with FERAL and with the structured backend: both converge, to the same
/// objective within 1e-5 of it (the solves take different pivots, so their iterates
/// differ by rounding, and both stop at `tol` 1e-7 on the scaled problem), and the
/// structured one used block elimination. (From the waves' slightly better plan of
/// `2d-fixed-time-unavoidable` the two coarse solves, rounding apart, end in two local
/// minima of the coarse problem, 60.48 and 55.59: a fact of the non-convex problem, not
/// of either backend, so the guess is the global search's.)
fn same_objective(name: &str) {
    let (p, guess) = planned_globally(name);
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
        let cache = Arc::new(KktCache::new());
        let (_, out) = solve(
            tr,
            start,
            false,
            &nlp,
            SolveBudget::until(Deadline::after(clock(), Duration::from_secs(60))),
            &cache,
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
                cache.counts().block_factorizations > 0,
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
/// What an entry of a transcription's KKT is, as pounce assembles it.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Entry {
    /// The diagonal of a primal variable or slack.
    PrimalDiagonal,
    /// The diagonal of a multiplier.
    DualDiagonal,
    /// An off-diagonal Hessian entry.
    Hessian,
    /// A Jacobian entry.
    Jacobian,
    /// An inequality row's slack.
    Slack,
}

/// The KKT pattern pounce assembles for `tr` (`[x not fixed | slacks | equality duals |
/// inequality duals]`, Hessian and Jacobian entries, every diagonal): its order, number
/// of multipliers, and entries (0-based, lower triangle).
fn kkt_pattern(tr: &Transcription) -> (usize, usize, Vec<(usize, usize, Entry)>) {
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
    let mut entries = Vec::new();
    let mut push = |i: usize, j: usize, e: Entry| entries.push((i.max(j), i.min(j), e));
    for i in 0..dim {
        let e = if i < n + n_d {
            Entry::PrimalDiagonal
        } else {
            Entry::DualDiagonal
        };
        push(i, i, e);
    }
    for &(r, c) in &tr.hess {
        if xpos[r] != usize::MAX && xpos[c] != usize::MAX && r != c {
            push(xpos[r], xpos[c], Entry::Hessian);
        }
    }
    for &(r, c) in &tr.jac {
        if xpos[c] != usize::MAX {
            let row = if eq(r) { cpos[r] } else { dpos[r] };
            push(row, xpos[c], Entry::Jacobian);
        }
    }
    for (k, r) in (0..tr.n_cons()).filter(|&r| !eq(r)).enumerate() {
        push(dpos[r], n + k, Entry::Slack);
    }
    (dim, n_c + n_d, entries)
}

/// 1-based triplets of `entries`.
fn triplets(entries: &[(usize, usize, Entry)]) -> (Vec<i32>, Vec<i32>) {
    entries
        .iter()
        .map(|&(i, j, _)| (i as i32 + 1, j as i32 + 1))
        .unzip()
}

/// The labels of a real transcription of `name`, on a KKT pattern assembled as pounce
/// assembles it ([`kkt_pattern`]), are accepted, with a border of at most
/// `3 · phases + 3` indices (the phase times, the phase-order rows' slacks and duals, the
/// rendezvous rows); then factorising and solving again and again (two right-hand sides)
/// allocates nothing.
fn labels_fit_and_do_not_allocate(name: &str) {
    let (p, guess) = planned_globally(name);
    let mesh = Mesh::uniform(5, &phase_durations(p.t0, &guess), 35.0, 2);
    let tr = Transcription::new(&p, &mesh, &guess, &TranscriptionSettings::default());
    let labels = KktLabels::of(&tr);
    let border = labels.blocks.iter().filter(|&&l| l < 0).count();
    let phases = mesh.phases.len();
    assert!(
        border <= 3 * phases + 3,
        "{name}: border of {border} with {phases} phases"
    );
    let (dim, m, entries) = kkt_pattern(&tr);
    let (ia, ja) = triplets(&entries);
    // Primal diagonal positive, dual diagonal negative: a quasi-definite KKT.
    let va: Vec<f64> = entries
        .iter()
        .map(|&(i, _, e)| match e {
            Entry::PrimalDiagonal => 4.0 + (i % 5) as f64,
            Entry::DualDiagonal => -1e-2,
            Entry::Hessian => 0.1,
            Entry::Jacobian => 0.3,
            Entry::Slack => -1.0,
        })
        .collect();
    let mut solver =
        StructuredKkt::new(Some(labels), Default::default(), Arc::new(KktCache::new()));
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
        let status = solver.multi_solve(true, &ia, &ja, 2, rhs, true, m as i32);
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
    let (p, guess) = planned_globally(name);
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

/// The early stop on a surplus of negative eigenvalues, on KKTs of a real transcription of
/// `name` with random values: Hessian diagonals drawn below zero with probability `p`
/// (so that many draws have the wrong inertia), the multipliers' diagonal 0 or −1e-8
/// (pounce's `δ_c`). Checked against nalgebra's dense `SymmetricEigen`: the status is
/// `Success` exactly when the matrix has as many negative eigenvalues as multipliers, a
/// wrong inertia is always reported as one, with a count on the right side of the
/// expected one, and some draws stop early.
fn surplus_stops_agree_with_the_eigenvalues(name: &str) {
    use nalgebra::{DMatrix, SymmetricEigen};
    use rand::{RngExt, SeedableRng};
    let (p, guess) = planned_globally(name);
    let mesh = Mesh::uniform(4, &phase_durations(p.t0, &guess), 120.0, 3);
    let tr = Transcription::new(&p, &mesh, &guess, &TranscriptionSettings::default());
    let (dim, m, entries) = kkt_pattern(&tr);
    let (ia, ja) = triplets(&entries);
    let mut solver = StructuredKkt::new(
        Some(KktLabels::of(&tr)),
        Default::default(),
        Arc::new(KktCache::new()),
    );
    assert_eq!(
        solver.initialize_structure(dim as i32, ia.len() as i32, &ia, &ja),
        ESymSolverStatus::Success
    );
    assert!(solver.is_structured());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
    let (mut right, mut wrong, mut judged) = (0, 0, 0);
    for draw in 0..24 {
        let p_negative = [0.0, 0.05, 0.2, 0.5][draw % 4];
        let delta_c = if draw % 8 < 4 { 0.0 } else { 1e-8 };
        let va: Vec<f64> = entries
            .iter()
            .map(|&(_, _, e)| match e {
                Entry::PrimalDiagonal if rng.random_range(0.0..1.0) < p_negative => {
                    rng.random_range(-10.0..-2.0)
                }
                Entry::PrimalDiagonal => rng.random_range(1.0..4.0),
                Entry::DualDiagonal => -delta_c,
                Entry::Hessian => rng.random_range(-0.2..0.2),
                Entry::Jacobian => rng.random_range(-1.0..1.0),
                Entry::Slack => -1.0,
            })
            .collect();
        let mut k = DMatrix::<f64>::zeros(dim, dim);
        for (&(i, j, _), &v) in entries.iter().zip(&va) {
            k[(i, j)] += v;
            if i != j {
                k[(j, i)] += v;
            }
        }
        let eig = SymmetricEigen::new(k).eigenvalues;
        if eig.iter().any(|l| l.abs() < 1e-9) {
            continue;
        }
        let negative = eig.iter().filter(|&&l| l < 0.0).count();
        let feral_before = solver.feral_factorizations;
        solver.values_array_mut().copy_from_slice(&va);
        let mut rhs = vec![1.0; dim];
        let status = solver.multi_solve(true, &ia, &ja, 1, &mut rhs, true, m as i32);
        if solver.feral_factorizations != feral_before {
            continue;
        }
        judged += 1;
        if negative == m {
            right += 1;
            assert_eq!(status, ESymSolverStatus::Success, "{name}, draw {draw}");
        } else {
            wrong += 1;
            assert_eq!(
                status,
                ESymSolverStatus::WrongInertia,
                "{name}, draw {draw}"
            );
            let reported = solver.number_of_neg_evals() as usize;
            assert_eq!(reported < m, negative < m, "{name}, draw {draw}: side");
        }
    }
    assert!(judged >= 16, "{name}: only {judged} draws judged");
    assert!(
        right >= 4 && wrong >= 4,
        "{name}: {right} right, {wrong} wrong"
    );
    assert!(
        solver.surplus_stops > 0 && solver.surplus_stops <= wrong,
        "{name}: {} early stops of {wrong} wrong inertias",
        solver.surplus_stops
    );
}

#[test]
fn surplus_stops_agree_with_the_eigenvalues_2d() {
    surplus_stops_agree_with_the_eigenvalues("2d-min-time-rendezvous-avoidable");
}

#[test]
fn surplus_stops_agree_with_the_eigenvalues_3d() {
    surplus_stops_agree_with_the_eigenvalues("3d-min-time-rendezvous-unavoidable");
}
