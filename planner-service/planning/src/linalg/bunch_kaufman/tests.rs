//! Tests of the Bunch–Kaufman kernels against nalgebra's eigenvalues and LU.

use super::*;
use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn lower_of(m: &DMatrix<f64>) -> Vec<f64> {
    let n = m.nrows();
    let mut a = vec![f64::NAN; n * n];
    for j in 0..n {
        for i in j..n {
            a[i + j * n] = m[(i, j)];
        }
    }
    a
}

/// Factorises `m` unblocked (no scratch) and blocked and checks both: the inertia
/// against nalgebra's eigenvalues, the solve against its LU. Returns the number of
/// negative eigenvalues and whether either took a 2×2 pivot.
fn check(m: &DMatrix<f64>, rng: &mut ChaCha8Rng) -> (usize, bool) {
    let n = m.nrows();
    let eig = SymmetricEigen::new(m.clone()).eigenvalues;
    let neg = eig.iter().filter(|&&l| l < 0.0).count();
    let mut two = false;
    for work_len in [0, work_len(n)] {
        let mut a = lower_of(m);
        let mut piv = vec![0; n];
        let mut work = vec![0.0; work_len];
        let inertia = factor(&mut a, n, &mut piv, &mut work).expect("nonsingular");
        assert_eq!(
            inertia.negative, neg,
            "negative eigenvalues (scratch {work_len})"
        );
        assert_eq!(
            inertia.positive,
            n - neg,
            "positive eigenvalues (scratch {work_len})"
        );
        let b = DVector::from_fn(n, |_, _| rng.random_range(-1.0..1.0));
        let reference = m.clone().lu().solve(&b).expect("LU solve");
        let mut x = b.as_slice().to_vec();
        solve(&a, n, &piv, &mut x);
        let err = (DVector::from_vec(x) - &reference).amax() / reference.amax();
        // Condition numbers here stay below ~1e4: 1e-10 leaves a wide margin over
        // eps · κ · n.
        assert!(
            err < 1e-10,
            "solve differs from LU by {err:e} (relative, scratch {work_len})"
        );
        // Three columns at once: each bit for bit as solved alone.
        let cols: Vec<f64> = (0..3 * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut many = cols.clone();
        solve_many(&a, n, &piv, &mut many, 3);
        for (c, got) in cols.chunks_exact(n).zip(many.chunks_exact(n)) {
            let mut one = c.to_vec();
            solve(&a, n, &piv, &mut one);
            assert_eq!(one, got, "a column of solve_many differs from solve");
        }
        two |= piv.iter().any(|&p| p < 0);
    }
    (neg, two)
}

/// Random symmetric indefinite matrices: the inertia equals the signs of nalgebra's
/// `SymmetricEigen` eigenvalues, and the solve equals nalgebra's LU solve to 1e-10
/// relative.
#[test]
fn inertia_and_solve_match_eigen_and_lu_on_random_indefinite_matrices() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut saw_two_by_two = false;
    for trial in 0..240 {
        // Up to 23 (unblocked only) and up to 111 (several panels, ragged ends).
        let n = if trial % 2 == 0 {
            1 + trial % 23
        } else {
            17 + trial % 95
        };
        let mut m: DMatrix<f64> = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
        m = &m + m.transpose();
        // Keep clear of near-singular draws (their LU reference is not a reference).
        let eig = SymmetricEigen::new(m.clone()).eigenvalues;
        if eig.iter().any(|l: &f64| l.abs() < 1e-3) {
            continue;
        }
        let (_, two) = check(&m, &mut rng);
        saw_two_by_two |= two;
    }
    assert!(saw_two_by_two, "no random matrix took a 2x2 pivot");
}

/// Saddle-point matrices `[[H, Jᵀ], [J, 0]]` (zero diagonal in the dual block) have
/// `m` negative eigenvalues; a zero leading 2×2 `[[0, 1], [1, 0]]` takes a 2×2 pivot.
#[test]
fn saddle_point_matrices_take_two_by_two_pivots() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for (nx, m) in [(3, 2), (6, 3), (10, 7), (13, 12), (36, 28), (50, 46)] {
        let n = nx + m;
        let mut k = DMatrix::zeros(n, n);
        for i in 0..nx {
            k[(i, i)] = rng.random_range(0.5..2.0);
        }
        for r in 0..m {
            for c in 0..nx {
                let v = rng.random_range(-1.0..1.0);
                k[(nx + r, c)] = v;
                k[(c, nx + r)] = v;
            }
        }
        let (neg, _) = check(&k, &mut rng);
        assert_eq!(neg, m);
    }
    // Duals first: the first column has a zero diagonal and its largest entry's
    // diagonal is zero too, so the first pivot must be 2x2.
    let k = DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.1, 1.0, 0.0, 0.2, 0.1, 0.2, 3.0]);
    let (neg, two) = check(&k, &mut rng);
    assert_eq!(neg, 1);
    assert!(two, "[[0, 1], [1, 0]] needs a 2x2 pivot");
}

/// On x86-64 with AVX2 the dispatched kernels run the wide code path: its results are
/// bit-identical to the baseline path's (same operations, same order, no fused
/// multiply-add), so a plan does not depend on the CPU it ran on.
#[test]
fn dispatched_and_portable_paths_agree_bit_for_bit() {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    for n in [1usize, 2, 3, 7, 16, 42, 64, 97] {
        let mut m: DMatrix<f64> = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
        m = &m + m.transpose();
        let lower = lower_of(&m);
        let (mut a, mut b) = (lower.clone(), lower);
        let (mut pa, mut pb) = (vec![0; n], vec![0; n]);
        let mut work = vec![0.0; work_len(n)];
        let ia = factor(&mut a, n, &mut pa, &mut work);
        let ib = factor_portable(&mut b, n, &mut pb, &mut work);
        assert_eq!(ia, ib, "inertia, n = {n}");
        assert_eq!(pa, pb, "pivots, n = {n}");
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b), "factors, n = {n}");
        let rhs: Vec<f64> = (0..4 * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        type Kernel = fn(&[f64], usize, &[i32], &mut [f64], usize);
        let pairs: [(Kernel, Kernel); 3] = [
            (solve_many, solve_many_portable),
            (forward_many, forward_many_portable),
            (backward_many, backward_many_portable),
        ];
        for (fast, portable) in pairs {
            let (mut x, mut y) = (rhs.clone(), rhs.clone());
            fast(&a, n, &pa, &mut x, 4);
            portable(&a, n, &pa, &mut y, 4);
            assert_eq!(bits(&x), bits(&y), "solve kernels, n = {n}");
        }
    }
}

/// The half solves: `forward_many` then `scale_by_d_inv` then `backward_many` is
/// `solve_many` bit for bit, and `uᵀ A⁻¹ v = (L⁻¹Pᵀu)ᵀ D⁻¹ (L⁻¹Pᵀv)` matches nalgebra's
/// inverse to 1e-10 relative (condition numbers below ~1e4 here).
#[test]
fn half_solves_compose_to_the_inverse() {
    let mut rng = ChaCha8Rng::seed_from_u64(19);
    let mut tested = 0;
    for trial in 0..60 {
        let n = 2 + trial % 30;
        let mut m: DMatrix<f64> = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
        m = &m + m.transpose();
        let eig = SymmetricEigen::new(m.clone()).eigenvalues;
        if eig.iter().any(|l: &f64| l.abs() < 1e-3) {
            continue;
        }
        tested += 1;
        let mut a = lower_of(&m);
        let mut piv = vec![0; n];
        factor(&mut a, n, &mut piv, &mut vec![0.0; work_len(n)]).expect("nonsingular");
        let u: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let v: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut whole = v.clone();
        solve_many(&a, n, &piv, &mut whole, 1);
        let mut halves = v.clone();
        forward_many(&a, n, &piv, &mut halves, 1);
        let mut hv = halves.clone();
        scale_by_d_inv(&a, n, &piv, &mut halves, 1);
        backward_many(&a, n, &piv, &mut halves, 1);
        assert_eq!(
            whole, halves,
            "forward, D⁻¹, backward differs from solve_many"
        );
        let mut hu = u.clone();
        forward_many(&a, n, &piv, &mut hu, 1);
        scale_by_d_inv(&a, n, &piv, &mut hv, 1);
        let got = dot(&hu, &hv);
        let inv = m.clone().try_inverse().expect("invertible");
        let (du, dv) = (DVector::from_vec(u), DVector::from_vec(v));
        let want = du.dot(&(&inv * &dv));
        let scale = inv.abs().max() * du.amax() * dv.amax() * n as f64;
        assert!(
            (got - want).abs() <= 1e-10 * scale,
            "uᵀA⁻¹v: {got} vs {want}"
        );
    }
    assert!(tested > 30, "too few well-conditioned draws ({tested})");
}

/// `dot` and `dot2` (four partial sums) agree with a plain left-to-right sum to
/// 1e-14 relative to `Σ |a_i b_i|`, for every length up to 40 (remainders 0-3).
#[test]
fn dot_products_match_a_plain_sum() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    for n in 0..40 {
        let draw = |rng: &mut ChaCha8Rng| -> Vec<f64> {
            (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
        };
        let (a, b, c) = (draw(&mut rng), draw(&mut rng), draw(&mut rng));
        let plain = |x: &[f64], y: &[f64]| -> (f64, f64) {
            let mut s = 0.0;
            let mut scale = 0.0;
            for (p, q) in x.iter().zip(y) {
                s += p * q;
                scale += (p * q).abs();
            }
            (s, scale.max(1e-300))
        };
        let (s, scale) = plain(&a, &b);
        assert!((dot(&a, &b) - s).abs() <= 1e-14 * scale, "dot, n = {n}");
        let (s0, c0) = plain(&a, &c);
        let (s1, c1) = plain(&b, &c);
        let (d0, d1) = dot2(&a, &b, &c);
        assert!((d0 - s0).abs() <= 1e-14 * c0, "dot2 first, n = {n}");
        assert!((d1 - s1).abs() <= 1e-14 * c1, "dot2 second, n = {n}");
    }
}

/// A zero matrix and a matrix with a zero row/column are singular.
#[test]
fn singular_matrices_are_refused() {
    let mut a = vec![0.0; 9];
    let mut piv = vec![0; 3];
    assert!(factor(&mut a, 3, &mut piv, &mut []).is_none());
    // [[1, 0, 0], [0, 0, 0], [0, 0, 2]]: the middle column is zero.
    let mut a = vec![1.0, 0.0, 0.0, f64::NAN, 0.0, 0.0, f64::NAN, f64::NAN, 2.0];
    assert!(factor(&mut a, 3, &mut piv, &mut []).is_none());
}
