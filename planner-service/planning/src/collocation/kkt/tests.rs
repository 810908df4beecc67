//! Tests of the structured KKT solver against dense solves, eigenvalues and FERAL.

use pounce_feral::FeralConfig;
use pounce_linsol::{ESymSolverStatus, SparseSymLinearSolverInterface};
use pounce_rs::Index;

use std::sync::Arc;

use super::*;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A lower-triangle triplet (1-based), its values, its labels and the dense matrix.
struct Arrowhead {
    ia: Vec<Index>,
    ja: Vec<Index>,
    va: Vec<f64>,
    labels: Vec<i32>,
    k: DMatrix<f64>,
}

/// A random symmetric indefinite arrowhead: blocks of `sizes` (each coupled to a few
/// border indices), a border of `nb`, indices shuffled over the KKT; with `chain`,
/// each block also couples to up to three indices of the block before it (a block
/// tridiagonal arrowhead, as the collocation's interval ends make it).
fn arrowhead(sizes: &[usize], nb: usize, chain: bool, rng: &mut ChaCha8Rng) -> Arrowhead {
    let dim = sizes.iter().sum::<usize>() + nb;
    let mut order: Vec<usize> = (0..dim).collect();
    for i in (1..dim).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let mut labels = vec![-1; dim];
    let mut at = 0;
    let mut members = Vec::new();
    for (b, &n) in sizes.iter().enumerate() {
        members.push(order[at..at + n].to_vec());
        for &i in &order[at..at + n] {
            labels[i] = b as i32;
        }
        at += n;
    }
    let border = order[at..].to_vec();
    let (mut ia, mut ja, mut va) = (Vec::new(), Vec::new(), Vec::new());
    let mut push = |i: usize, j: usize, v: f64| {
        let (r, c) = (i.max(j), i.min(j));
        ia.push(r as Index + 1);
        ja.push(c as Index + 1);
        va.push(v);
    };
    for m in &members {
        for (p, &i) in m.iter().enumerate() {
            // Alternating signs: indefinite blocks, some pivots needing 2x2 steps.
            let sign = if p % 3 == 2 { -1.0 } else { 1.0 };
            push(i, i, sign * rng.random_range(0.0..2.0));
            for &j in &m[..p] {
                push(i, j, rng.random_range(-1.0..1.0));
            }
            for &bj in &border {
                if rng.random_range(0.0..1.0) < 0.3 {
                    push(i, bj, rng.random_range(-1.0..1.0));
                }
            }
        }
    }
    if chain {
        for pair in members.windows(2) {
            let (prev, this) = (&pair[0], &pair[1]);
            for &j in prev.iter().take(3) {
                for &i in this {
                    if rng.random_range(0.0..1.0) < 0.5 {
                        push(i, j, rng.random_range(-1.0..1.0));
                    }
                }
            }
        }
    }
    for (p, &i) in border.iter().enumerate() {
        push(i, i, rng.random_range(-3.0..3.0));
        if p > 0 {
            push(i, border[p - 1], rng.random_range(-1.0..1.0));
        }
    }
    // A duplicate entry: the two values add, as pounce's assembly expects.
    if let Some(&b0) = border.first() {
        push(b0, b0, 0.5);
    }
    let mut k = DMatrix::zeros(dim, dim);
    for ((&r, &c), &v) in ia.iter().zip(&ja).zip(&va) {
        let (r, c) = (r as usize - 1, c as usize - 1);
        k[(r, c)] += v;
        if r != c {
            k[(c, r)] += v;
        }
    }
    Arrowhead {
        ia,
        ja,
        va,
        labels,
        k,
    }
}

/// A cache of its own (no other test's workspaces).
fn fresh_cache() -> Arc<KktCache> {
    Arc::new(KktCache::new())
}

fn feral_cfg() -> FeralConfig {
    FeralConfig::default()
}

/// `a` with `per_block` pivot groups of two indices added to every block after the
/// first (appended to the KKT): each a `[[d, s], [s, e]]` pivot with `|s|` in 1..2 and
/// `scale · d`, coupled to members of its block, to three of the block before it and
/// to the border, as a node's controls and driven defects are. Returns the group
/// labels (`-1` outside the groups).
fn add_groups(a: &mut Arrowhead, per_block: usize, scale: f64, rng: &mut ChaCha8Rng) -> Vec<i32> {
    let dim0 = a.k.nrows();
    let blocks = a.labels.iter().copied().max().unwrap_or(-1) + 1;
    let members =
        |b: i32, labels: &[i32]| -> Vec<usize> { (0..dim0).filter(|&i| labels[i] == b).collect() };
    let border: Vec<usize> = (0..dim0).filter(|&i| a.labels[i] < 0).collect();
    let mut groups = vec![-1; dim0];
    let mut entries = Vec::new();
    let mut id = 0;
    for b in 1..blocks {
        let (this, prev) = (members(b, &a.labels), members(b - 1, &a.labels));
        for _ in 0..per_block {
            let (u, l) = (a.labels.len(), a.labels.len() + 1);
            a.labels.extend([b, b]);
            groups.extend([id, id]);
            id += 1;
            let sign = if rng.random_range(0.0..1.0) < 0.5 {
                -1.0
            } else {
                1.0
            };
            entries.push((u, u, scale * rng.random_range(0.1..1.0)));
            entries.push((l, u, sign * rng.random_range(1.0..2.0)));
            for &i in &this {
                if rng.random_range(0.0..1.0) < 0.4 {
                    entries.push((l, i, rng.random_range(-1.0..1.0)));
                }
            }
            for &i in prev.iter().take(3) {
                entries.push((l, i, rng.random_range(-1.0..1.0)));
            }
            for &i in &border {
                if rng.random_range(0.0..1.0) < 0.5 {
                    entries.push((u, i, rng.random_range(-0.5..0.5)));
                }
            }
        }
    }
    let dim = a.labels.len();
    let mut k = DMatrix::zeros(dim, dim);
    k.view_mut((0, 0), (dim0, dim0)).copy_from(&a.k);
    for (i, j, v) in entries {
        let (r, c) = (i.max(j), i.min(j));
        a.ia.push(r as Index + 1);
        a.ja.push(c as Index + 1);
        a.va.push(v);
        k[(r, c)] += v;
        if r != c {
            k[(c, r)] += v;
        }
    }
    a.k = k;
    groups
}

/// Pivot groups eliminated before the chain (indefinite 2×2 pivots coupled to their
/// block, the block before and the border): three right-hand sides solved as by
/// nalgebra's LU to 1e-9 relative, the inertia equal to `SymmetricEigen`'s, by the
/// grouped workspace. With a tiny pivot scale, so that the groups' multipliers stay
/// bounded, and with a huge one (multipliers past [`GROUP_GROWTH_MAX`]): then the
/// same blocks without the groups factor it, and the answer is as right.
#[test]
fn pivot_groups_match_a_dense_solve_and_the_eigenvalues() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for (sizes, nb, per_block, scale, plain) in [
        (vec![8, 9, 7, 8], 3, 2, 1e-3, false),
        (vec![12; 5], 4, 3, 1.0, false),
        (vec![6, 6, 6], 2, 1, 1e9, true),
    ] {
        let mut a = arrowhead(&sizes, nb, true, &mut rng);
        let groups = add_groups(&mut a, per_block, scale, &mut rng);
        let dim = a.k.nrows();
        let eig = SymmetricEigen::new(a.k.clone()).eigenvalues;
        assert!(eig.iter().all(|l: &f64| l.abs() > 1e-6), "draw is singular");
        let neg = eig.iter().filter(|&&l| l < 0.0).count();
        let nrhs = 3;
        let b: Vec<f64> = (0..dim * nrhs)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let mut x = b.clone();
        let labels = KktLabels {
            blocks: a.labels.clone(),
            groups,
        };
        let mut solver = StructuredKkt::new(Some(labels), feral_cfg(), fresh_cache());
        let status = solve_with(&mut solver, &a.ia, &a.ja, &a.va, &mut x, nrhs, Some(neg));
        assert_eq!(status, ESymSolverStatus::Success);
        let ws = solver.ws.as_ref().expect("the labels fit");
        assert_eq!(ws.groups.len(), per_block * (sizes.len() - 1));
        assert_eq!(
            (solver.block_factorizations, solver.feral_factorizations),
            (1, 0)
        );
        assert_eq!(solver.on_plain, plain, "grouped or plain as expected");
        assert_eq!(solver.number_of_neg_evals() as usize, neg);
        let lu = a.k.clone().lu();
        for r in 0..nrhs {
            let rhs = DVector::from_column_slice(&b[r * dim..(r + 1) * dim]);
            let reference = lu.solve(&rhs).expect("LU solve");
            let got = DVector::from_column_slice(&x[r * dim..(r + 1) * dim]);
            let err = (got - &reference).amax() / reference.amax();
            assert!(err < 1e-9, "differs from LU by {err:e} (relative)");
            // The elimination alone, without refinement, is as exact.
            let mut alone = b[r * dim..(r + 1) * dim].to_vec();
            let ws = match solver.plain.as_mut() {
                Some(p) if solver.on_plain => p,
                _ => solver.ws.as_mut().expect("the labels fit"),
            };
            ws.solve(&mut alone);
            let err = (DVector::from_vec(alone) - &reference).amax() / reference.amax();
            assert!(
                err < 1e-9,
                "unrefined: differs from LU by {err:e} (relative)"
            );
        }
    }
}

/// A workspace that factored one matrix factors the next exactly as a fresh one does
/// (the same solution, bit for bit, and the same inertia): the assembly restores every
/// entry the elimination reads, and nothing above a block's diagonal is ever written
/// nor above the border's (they stay at their allocated zeros, so the assembly clears
/// only the lower triangles).
#[test]
fn a_reused_workspace_factors_as_a_fresh_one() {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let mut a = arrowhead(&[10, 12, 9, 11], 3, true, &mut rng);
    let groups = add_groups(&mut a, 2, 1e-2, &mut rng);
    let dim = a.k.nrows();
    let labels = KktLabels {
        blocks: a.labels.clone(),
        groups,
    };
    // Same pattern, new values: indefinite diagonals (2x2 pivots), new couplings.
    let second: Vec<f64> =
        a.va.iter()
            .map(|v| v * rng.random_range(-1.5..1.5))
            .collect();
    let b: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
    let mut used = StructuredKkt::new(Some(labels.clone()), feral_cfg(), fresh_cache());
    let mut x_used = b.clone();
    let _ = solve_with(&mut used, &a.ia, &a.ja, &a.va, &mut x_used, 1, None);
    let mut x_used = b.clone();
    used.values_array_mut().copy_from_slice(&second);
    let status = used.multi_solve(true, &a.ia, &a.ja, 1, &mut x_used, false, 0);
    let mut fresh = StructuredKkt::new(Some(labels), feral_cfg(), fresh_cache());
    let mut x_fresh = b.clone();
    let status_fresh = solve_with(&mut fresh, &a.ia, &a.ja, &second, &mut x_fresh, 1, None);
    assert_eq!(status, status_fresh);
    assert_eq!(used.block_factorizations, 2, "both by block elimination");
    assert_eq!(used.number_of_neg_evals(), fresh.number_of_neg_evals());
    let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&x_used), bits(&x_fresh), "reused and fresh differ");
    let ws = used.ws.as_ref().expect("the labels fit");
    let nb = ws.border.len();
    assert!(nb > 0, "the draw has a border");
    let squares = ws
        .blocks
        .iter()
        .map(|blk| (blk.a_off, blk.n))
        .chain([(ws.s_off, nb)]);
    for (off, n) in squares {
        let a = &ws.dense[off..off + n * n];
        for j in 0..n {
            assert!(
                a[j * n..j * n + j].iter().all(|&v| v == 0.0),
                "written above the diagonal"
            );
        }
    }
}

/// A solve takes the workspace a finished solve of the same pattern left in the pool,
/// and computes the same bits as a solve on a workspace built for it; a solve of
/// another pattern (one nonzero fewer) does not take it.
#[test]
fn a_pooled_workspace_solves_as_a_new_one() {
    let mut rng = ChaCha8Rng::seed_from_u64(4242);
    // Block sizes no other test draws, so that no other test's workspace fits.
    let mut a = arrowhead(&[13, 7, 16, 5, 11], 4, true, &mut rng);
    let groups = add_groups(&mut a, 2, 1e-2, &mut rng);
    let dim = a.k.nrows();
    let labels = KktLabels {
        blocks: a.labels.clone(),
        groups,
    };
    let values: Vec<f64> =
        a.va.iter()
            .map(|v| v * rng.random_range(-1.5..1.5))
            .collect();
    let b: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
    // One planner's cache, shared by its solves.
    let cache = Arc::new(KktCache::new());
    let mut first = StructuredKkt::new(Some(labels.clone()), feral_cfg(), Arc::clone(&cache));
    let mut x = b.clone();
    let _ = solve_with(&mut first, &a.ia, &a.ja, &a.va, &mut x, 1, None);
    assert!(first.is_structured() && !first.reused);
    drop(first);
    let mut pooled = StructuredKkt::new(Some(labels.clone()), feral_cfg(), Arc::clone(&cache));
    let mut x_pooled = b.clone();
    let status = solve_with(&mut pooled, &a.ia, &a.ja, &values, &mut x_pooled, 1, None);
    assert!(
        pooled.reused,
        "the finished solve's workspace was not taken"
    );
    // The pooled one is in use: this one is built.
    let mut built = StructuredKkt::new(Some(labels.clone()), feral_cfg(), Arc::clone(&cache));
    let mut x_built = b.clone();
    let status_built = solve_with(&mut built, &a.ia, &a.ja, &values, &mut x_built, 1, None);
    assert!(!built.reused);
    assert_eq!(status, status_built);
    assert_eq!(pooled.block_factorizations, 1);
    assert_eq!(pooled.number_of_neg_evals(), built.number_of_neg_evals());
    let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&x_pooled), bits(&x_built), "pooled and built differ");
    drop(pooled);
    drop(built);
    // Another pattern: the last entry dropped.
    let n = a.ia.len() - 1;
    let mut other = StructuredKkt::new(Some(labels.clone()), feral_cfg(), Arc::clone(&cache));
    let mut x_other = b.clone();
    let _ = solve_with(
        &mut other,
        &a.ia[..n],
        &a.ja[..n],
        &values[..n],
        &mut x_other,
        1,
        None,
    );
    assert!(!other.reused, "a workspace of another pattern was taken");
    assert_eq!(
        cache.workspace_reuses(),
        1,
        "the cache counts its one reuse"
    );
    // Another planner's cache holds nothing of this one's.
    drop(other);
    let mut elsewhere = StructuredKkt::new(Some(labels), feral_cfg(), Arc::new(KktCache::new()));
    let mut x_elsewhere = b.clone();
    let _ = solve_with(
        &mut elsewhere,
        &a.ia,
        &a.ja,
        &values,
        &mut x_elsewhere,
        1,
        None,
    );
    assert!(
        !elsewhere.reused,
        "a workspace of another planner's cache was taken"
    );
}

/// Two groups coupled to each other do not fit: FERAL factors that matrix.
#[test]
fn coupled_groups_go_to_feral() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let mut a = arrowhead(&[6, 6, 6], 2, true, &mut rng);
    let groups = add_groups(&mut a, 2, 1.0, &mut rng);
    let g: Vec<usize> = (0..groups.len()).filter(|&i| groups[i] >= 0).collect();
    // The first group's first index and the second group's first index.
    let (i, j) = (g[0], g[2]);
    a.ia.push(i.max(j) as Index + 1);
    a.ja.push(i.min(j) as Index + 1);
    a.va.push(0.3);
    let dim = a.k.nrows();
    let mut x = vec![1.0; dim];
    let labels = KktLabels {
        blocks: a.labels.clone(),
        groups,
    };
    let mut solver = StructuredKkt::new(Some(labels), feral_cfg(), fresh_cache());
    let _ = solve_with(&mut solver, &a.ia, &a.ja, &a.va, &mut x, 1, None);
    assert!(!solver.is_structured());
    assert_eq!(solver.feral_factorizations, 1);
}

/// Factorises and solves `nrhs` random right-hand sides; the solutions and status.
fn solve_with(
    solver: &mut StructuredKkt,
    ia: &[Index],
    ja: &[Index],
    va: &[f64],
    rhs: &mut [f64],
    nrhs: usize,
    expected_neg: Option<usize>,
) -> ESymSolverStatus {
    let dim = rhs.len() / nrhs;
    assert_eq!(
        solver.initialize_structure(dim as Index, ia.len() as Index, ia, ja),
        ESymSolverStatus::Success
    );
    solver.values_array_mut().copy_from_slice(va);
    solver.multi_solve(
        true,
        ia,
        ja,
        nrhs as Index,
        rhs,
        expected_neg.is_some(),
        expected_neg.unwrap_or(0) as Index,
    )
}

/// The early stop on a surplus of negative eigenvalues, on a three-index KKT
/// `[[h, 0, c], [0, 2, 1], [c, 1, 0]]` (primal `x` in block 0; primal `y` and the one
/// multiplier in block 1): with `h = −1` block 0 alone has a negative eigenvalue more
/// than multipliers, but through the link (`c = 1`, `M = 1/h < 0`) the next block makes
/// up for it: the matrix's inertia is right (determinant −1, trace 1: one negative
/// eigenvalue), so the factorisation must not stop. Without the link (`c` not in the
/// pattern) nothing can: it stops, and reports the wrong inertia with more negative
/// eigenvalues than multipliers (the matrix has two).
#[test]
fn a_surplus_stops_only_when_the_rest_cannot_make_up_for_it() {
    for (linked, status, stops) in [
        (true, ESymSolverStatus::Success, 0),
        (false, ESymSolverStatus::WrongInertia, 1),
    ] {
        let (mut ia, mut ja, mut va) = (
            vec![1, 2, 3, 3],
            vec![1, 2, 2, 3],
            vec![-1.0, 2.0, 1.0, 0.0],
        );
        if linked {
            ia.push(3);
            ja.push(1);
            va.push(1.0);
        }
        let mut solver = StructuredKkt::new(
            Some(KktLabels::plain(vec![0, 1, 1])),
            feral_cfg(),
            fresh_cache(),
        );
        let mut x = vec![1.0; 3];
        let got = solve_with(&mut solver, &ia, &ja, &va, &mut x, 1, Some(1));
        assert!(solver.is_structured());
        assert_eq!(
            (got, solver.surplus_stops),
            (status, stops),
            "linked: {linked}"
        );
        assert_eq!(solver.number_of_neg_evals() > 1, !linked);
    }
}

/// Block elimination on random arrowheads, plain and chained (indefinite blocks and
/// border, indices shuffled, a duplicate entry): three right-hand sides solved as by
/// nalgebra's LU to 1e-9 relative, and the inertia equal to the signs of
/// `SymmetricEigen`.
#[test]
fn arrowhead_matches_a_dense_solve_and_the_eigenvalues() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for (sizes, nb, chain) in [
        (vec![5, 7, 6], 4, false),
        (vec![12; 6], 9, false),
        (vec![1, 2, 3], 1, false),
        (vec![30, 25], 20, false),
        (vec![5, 7, 6], 4, true),
        (vec![12; 6], 9, true),
        (vec![1, 2, 3], 1, true),
        (vec![30, 25], 20, true),
        (vec![9; 12], 0, true),
    ] {
        let Arrowhead {
            ia,
            ja,
            va,
            labels,
            k,
        } = arrowhead(&sizes, nb, chain, &mut rng);
        let dim = k.nrows();
        let eig = SymmetricEigen::new(k.clone()).eigenvalues;
        assert!(eig.iter().all(|l: &f64| l.abs() > 1e-6), "draw is singular");
        let neg = eig.iter().filter(|&&l| l < 0.0).count();
        let nrhs = 3;
        let b: Vec<f64> = (0..dim * nrhs)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect();
        let mut x = b.clone();
        let mut solver =
            StructuredKkt::new(Some(KktLabels::plain(labels)), feral_cfg(), fresh_cache());
        let status = solve_with(&mut solver, &ia, &ja, &va, &mut x, nrhs, Some(neg));
        assert_eq!(status, ESymSolverStatus::Success);
        assert!(solver.is_structured());
        assert_eq!(
            (solver.block_factorizations, solver.feral_factorizations),
            (1, 0)
        );
        assert_eq!(solver.number_of_neg_evals() as usize, neg);
        let lu = k.clone().lu();
        for r in 0..nrhs {
            let rhs = DVector::from_column_slice(&b[r * dim..(r + 1) * dim]);
            let reference = lu.solve(&rhs).expect("LU solve");
            let got = DVector::from_column_slice(&x[r * dim..(r + 1) * dim]);
            let err = (got - &reference).amax() / reference.amax();
            assert!(err < 1e-9, "differs from LU by {err:e} (relative)");
        }
        // A wrong expected count is reported as such (the count is trusted).
        let mut y = b.clone();
        let status = solve_with(&mut solver, &ia, &ja, &va, &mut y, nrhs, Some(neg + 1));
        assert_eq!(status, ESymSolverStatus::WrongInertia);
    }
}

/// An entry coupling two blocks that are not neighbours (blocks 0 and 2 of a chain):
/// the labels do not describe the matrix, so FERAL factors it, and the solve is still right (1e-9 relative to LU). A label vector of
/// the wrong length does the same.
#[test]
fn a_pattern_coupling_two_blocks_goes_to_feral() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let Arrowhead {
        mut ia,
        mut ja,
        mut va,
        labels,
        mut k,
    } = arrowhead(&[6, 6, 6], 5, true, &mut rng);
    let i = labels.iter().position(|&l| l == 0).unwrap();
    let j = labels.iter().position(|&l| l == 2).unwrap();
    ia.push(i.max(j) as Index + 1);
    ja.push(i.min(j) as Index + 1);
    va.push(0.25);
    k[(i, j)] += 0.25;
    k[(j, i)] += 0.25;
    let dim = k.nrows();
    let b: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
    let reference = k
        .clone()
        .lu()
        .solve(&DVector::from_column_slice(&b))
        .unwrap();
    for labels in [labels.clone(), labels[1..].to_vec()] {
        let mut x = b.clone();
        let mut solver =
            StructuredKkt::new(Some(KktLabels::plain(labels)), feral_cfg(), fresh_cache());
        let status = solve_with(&mut solver, &ia, &ja, &va, &mut x, 1, None);
        assert_eq!(status, ESymSolverStatus::Success);
        assert!(!solver.is_structured());
        assert_eq!(
            (solver.block_factorizations, solver.feral_factorizations),
            (0, 1)
        );
        let err = (DVector::from_vec(x) - &reference).amax() / reference.amax();
        assert!(err < 1e-9, "differs from LU by {err:e} (relative)");
    }
}

/// A block that is exactly singular (a zero row inside it) cannot be factored on its
/// own, so FERAL factors that matrix and decides: here the whole matrix is singular.
#[test]
fn a_singular_block_goes_to_feral() {
    // Block 0 = {0, 1}, block 1 = {2}, border = {3}; index 1 has no entries at all.
    let ia = [1, 3, 4, 4, 4];
    let ja = [1, 3, 1, 3, 4];
    let va = [2.0, -1.0, 0.5, 0.3, 4.0];
    let mut x = vec![1.0; 4];
    let mut solver = StructuredKkt::new(
        Some(KktLabels::plain(vec![0, 0, 1, -1])),
        feral_cfg(),
        fresh_cache(),
    );
    let status = solve_with(&mut solver, &ia, &ja, &va, &mut x, 1, None);
    assert!(solver.is_structured());
    assert_eq!(
        (solver.block_factorizations, solver.feral_factorizations),
        (0, 1)
    );
    assert_eq!(status, ESymSolverStatus::Singular);
}
