//! Solves with the Bunch–Kaufman factors (LAPACK `dsytrs`): whole, or its halves
//! `L⁻¹ Pᵀ`, `D⁻¹` and `P L⁻ᵀ`, for one or several right-hand sides.

use super::{at, decode, dot, dot2};

/// Solves `A x = b` in place with the factors from [`factor`] (`b` has `n` entries).
pub fn solve(a: &[f64], n: usize, piv: &[i32], b: &mut [f64]) {
    solve_many(a, n, piv, &mut b[..n], 1);
}

dispatched!(
    /// Solves `A X = B` in place for the `ncols` columns of `b` (column-major, `n × ncols`),
    /// each column in exactly the operations of [`solve`]; the factor is read once per step
    /// for all columns. The same as [`forward_many`], [`scale_by_d_inv`] and
    /// [`backward_many`] in turn.
    solve_many, solve_many_avx2, solve_many_portable, solve_many_body,
    (a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize)
);

#[inline(always)]
fn solve_many_body(a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize) {
    forward_body(a, n, piv, b, ncols);
    d_inv_body(a, n, piv, b, ncols);
    backward_body(a, n, piv, b, ncols);
}

dispatched!(
    /// The first half of a solve, `B ← L⁻¹ Pᵀ B` (interchanges interleaved), for the
    /// `ncols` columns of `b`. A column whose leading entries are zero costs only the
    /// steps after its first nonzero: the unit vectors of the structured KKT's links are
    /// cheap. With the factors `A = P L D Lᵀ Pᵀ`, `uᵀ A⁻¹ v = (L⁻¹Pᵀu)ᵀ D⁻¹ (L⁻¹Pᵀv)`.
    forward_many, forward_many_avx2, forward_many_portable, forward_body,
    (a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize)
);

#[inline(always)]
fn forward_body(a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize) {
    debug_assert!(b.len() >= n * ncols);
    let b = &mut b[..n * ncols];
    let mut k = 0;
    while k < n {
        let (two, p) = decode(piv[k]);
        if !two {
            let lk = &a[at(n, k + 1, k)..at(n, n, k)];
            for col in b.chunks_exact_mut(n) {
                col.swap(k, p);
                let bk = col[k];
                if bk != 0.0 {
                    for (bi, &l) in col[k + 1..].iter_mut().zip(lk) {
                        *bi -= l * bk;
                    }
                }
            }
            k += 1;
        } else {
            for col in b.chunks_exact_mut(n) {
                col.swap(k + 1, p);
                let (bk, bk1) = (col[k], col[k + 1]);
                if k + 2 < n && (bk != 0.0 || bk1 != 0.0) {
                    let lk = &a[at(n, k + 2, k)..at(n, n, k)];
                    let lk1 = &a[at(n, k + 2, k + 1)..at(n, n, k + 1)];
                    for ((bi, &l0), &l1) in col[k + 2..].iter_mut().zip(lk).zip(lk1) {
                        *bi -= l0 * bk + l1 * bk1;
                    }
                }
            }
            k += 2;
        }
    }
}

/// `B ← D⁻¹ B` for the `ncols` columns of `b` (`D`'s 1×1 and 2×2 blocks as the
/// factorisation left them).
pub fn scale_by_d_inv(a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize) {
    d_inv_body(a, n, piv, b, ncols);
}

#[inline(always)]
fn d_inv_body(a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize) {
    debug_assert!(b.len() >= n * ncols);
    let b = &mut b[..n * ncols];
    let mut k = 0;
    while k < n {
        let (two, _) = decode(piv[k]);
        if !two {
            let dkk = a[at(n, k, k)];
            for col in b.chunks_exact_mut(n) {
                col[k] /= dkk;
            }
            k += 1;
        } else {
            let d21 = a[at(n, k + 1, k)];
            let e11 = a[at(n, k, k)] / d21;
            let e22 = a[at(n, k + 1, k + 1)] / d21;
            let denom = e11 * e22 - 1.0;
            for col in b.chunks_exact_mut(n) {
                let (c0, c1) = (col[k] / d21, col[k + 1] / d21);
                col[k] = (e22 * c0 - c1) / denom;
                col[k + 1] = (e11 * c1 - c0) / denom;
            }
            k += 2;
        }
    }
}

dispatched!(
    /// The second half of a solve, `B ← P L⁻ᵀ B` (interchanges in reverse), for the
    /// `ncols` columns of `b`.
    backward_many, backward_many_avx2, backward_many_portable, backward_body,
    (a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize)
);

#[inline(always)]
fn backward_body(a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize) {
    debug_assert!(b.len() >= n * ncols);
    let b = &mut b[..n * ncols];
    let mut k = n;
    while k > 0 {
        let j = k - 1;
        let (two, p) = decode(piv[j]);
        if !two {
            let lj = &a[at(n, j + 1, j)..at(n, n, j)];
            for col in b.chunks_exact_mut(n) {
                let s = dot(&col[j + 1..], lj);
                col[j] -= s;
                col.swap(j, p);
            }
            k -= 1;
        } else {
            // The pair is (j - 1, j).
            let i = j - 1;
            let li = &a[at(n, j + 1, i)..at(n, n, i)];
            let lj = &a[at(n, j + 1, j)..at(n, n, j)];
            for col in b.chunks_exact_mut(n) {
                let (s0, s1) = dot2(li, lj, &col[j + 1..]);
                col[i] -= s0;
                col[j] -= s1;
                col.swap(j, p);
            }
            k -= 2;
        }
    }
}
