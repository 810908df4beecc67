//! Dense symmetric-indefinite `LDLᵀ` factorisation with Bunch–Kaufman partial pivoting
//! (1×1 and 2×2 pivots), the unblocked LAPACK `dsytf2` / `dsytrs` scheme on the lower
//! triangle of a column-major matrix, for the small dense blocks of the structured KKT
//! solver ([`super::kkt`]). It works in place on caller-owned buffers and never
//! allocates.
//!
//! `P A Pᵀ = L D Lᵀ` is stored as LAPACK stores it: the multipliers of `L` below the
//! diagonal, `D`'s 1×1 and 2×2 blocks on and just below the diagonal, and the
//! interchanges interleaved with the columns (`piv`), so a solve applies them step by
//! step. Inertia is read off `D` (Sylvester's law).

/// Bunch–Kaufman's growth-balancing constant `(1 + √17) / 8`.
const ALPHA: f64 = 0.640_388_203_202_208_4;

/// The inertia of a factorised matrix, with the smallest eigenvalue magnitude of `D`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Inertia {
    pub positive: usize,
    pub negative: usize,
    /// Smallest `|λ|` over `D`'s 1×1 pivots and the eigenvalues of its 2×2 pivots.
    pub min_pivot: f64,
}

/// How one step of the factorisation pivoted (`piv[k]`).
///
/// Encoding: `piv[k] = p` (≥ 0) for a 1×1 pivot at `k` after interchanging `k` and `p`;
/// for a 2×2 pivot at `(k, k+1)` after interchanging `k+1` and `p`,
/// `piv[k] = piv[k+1] = -(p + 1)`.
fn decode(p: i32) -> (bool, usize) {
    if p >= 0 {
        (false, p as usize)
    } else {
        (true, (-p - 1) as usize)
    }
}

/// `Σ a_i b_i` over the common length, in four interleaved partial sums (a fixed order,
/// so the result is deterministic; the independent sums let the loop vectorise).
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for q in 0..4 {
            acc[q] += x[q] * y[q];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    (acc[0] + acc[2]) + (acc[1] + acc[3]) + tail
}

/// `(Σ a_i c_i, Σ b_i c_i)` over the common length, as [`dot`] does each.
#[inline]
fn dot2(a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64) {
    let n = a.len().min(b.len()).min(c.len());
    let (a, b, c) = (&a[..n], &b[..n], &c[..n]);
    let (mut sa, mut sb) = ([0.0f64; 4], [0.0f64; 4]);
    let m = n - n % 4;
    for i in (0..m).step_by(4) {
        for q in 0..4 {
            sa[q] += a[i + q] * c[i + q];
            sb[q] += b[i + q] * c[i + q];
        }
    }
    let (mut ta, mut tb) = (0.0, 0.0);
    for i in m..n {
        ta += a[i] * c[i];
        tb += b[i] * c[i];
    }
    (
        (sa[0] + sa[2]) + (sa[1] + sa[3]) + ta,
        (sb[0] + sb[2]) + (sb[1] + sb[3]) + tb,
    )
}

#[inline]
fn at(n: usize, i: usize, j: usize) -> usize {
    i + j * n
}

/// Swaps rows and columns `r < q` of the trailing lower triangle `A[r.., r..]`.
fn swap_symmetric(a: &mut [f64], n: usize, r: usize, q: usize) {
    debug_assert!(r < q);
    for i in q + 1..n {
        a.swap(at(n, i, r), at(n, i, q));
    }
    for j in r + 1..q {
        a.swap(at(n, j, r), at(n, q, j));
    }
    a.swap(at(n, r, r), at(n, q, q));
}

/// Eigenvalues of the symmetric 2×2 `[[a, b], [b, c]]`.
fn eig2(a: f64, b: f64, c: f64) -> (f64, f64) {
    let mean = 0.5 * (a + c);
    let r = (0.5 * (a - c)).hypot(b);
    (mean - r, mean + r)
}

/// Factorises the `n × n` symmetric matrix whose lower triangle is in `a` (column-major,
/// leading dimension `n`; the strict upper triangle is neither read nor written), in
/// place. `piv` needs `n` entries.
///
/// Returns `None` when a whole pivot column is zero (the matrix is singular: no pivot to
/// take); otherwise the inertia. A nonsingular but ill-conditioned matrix factorises:
/// the caller judges [`Inertia::min_pivot`] against its own floor.
pub fn factor(a: &mut [f64], n: usize, piv: &mut [i32]) -> Option<Inertia> {
    debug_assert!(a.len() >= n * n && piv.len() >= n);
    let mut inertia = Inertia {
        positive: 0,
        negative: 0,
        min_pivot: f64::INFINITY,
    };
    let mut k = 0;
    while k < n {
        let absakk = a[at(n, k, k)].abs();
        let (mut imax, mut colmax) = (k, 0.0);
        for i in k + 1..n {
            let v = a[at(n, i, k)].abs();
            if v > colmax {
                (imax, colmax) = (i, v);
            }
        }
        if absakk.max(colmax) == 0.0 || !absakk.max(colmax).is_finite() {
            return None;
        }
        let (two, kp) = if absakk >= ALPHA * colmax {
            (false, k)
        } else {
            // The largest off-diagonal magnitude in row/column `imax` of the trailing part.
            let mut rowmax: f64 = 0.0;
            for j in k..imax {
                rowmax = rowmax.max(a[at(n, imax, j)].abs());
            }
            for i in imax + 1..n {
                rowmax = rowmax.max(a[at(n, i, imax)].abs());
            }
            if absakk >= ALPHA * colmax * (colmax / rowmax) {
                (false, k)
            } else if a[at(n, imax, imax)].abs() >= ALPHA * rowmax {
                (false, imax)
            } else {
                (true, imax)
            }
        };
        let kk = if two { k + 1 } else { k };
        if kp != kk {
            swap_symmetric(a, n, kk, kp);
            if two {
                a.swap(at(n, k + 1, k), at(n, kp, k));
            }
        }
        if !two {
            let d = a[at(n, k, k)];
            inertia.min_pivot = inertia.min_pivot.min(d.abs());
            if d > 0.0 {
                inertia.positive += 1;
            } else {
                inertia.negative += 1;
            }
            let r = 1.0 / d;
            // A22 -= x xᵀ / d over the lower triangle, column by column.
            for j in k + 1..n {
                let t = a[at(n, j, k)] * r;
                if t != 0.0 {
                    let (head, tail) = a.split_at_mut(at(n, 0, j));
                    let col_k = &head[at(n, j, k)..at(n, n, k)];
                    let col_j = &mut tail[j..n];
                    for (cj, &ck) in col_j.iter_mut().zip(col_k) {
                        *cj -= ck * t;
                    }
                }
            }
            for i in k + 1..n {
                a[at(n, i, k)] *= r;
            }
            piv[k] = kp as i32;
            k += 1;
        } else {
            let (d11, d21, d22) = (a[at(n, k, k)], a[at(n, k + 1, k)], a[at(n, k + 1, k + 1)]);
            let (lo, hi) = eig2(d11, d21, d22);
            inertia.min_pivot = inertia.min_pivot.min(lo.abs()).min(hi.abs());
            for l in [lo, hi] {
                if l > 0.0 {
                    inertia.positive += 1;
                } else {
                    inertia.negative += 1;
                }
            }
            if k + 2 < n {
                // dsytf2's scaled inverse of the 2×2 pivot.
                let e11 = d22 / d21;
                let e22 = d11 / d21;
                let t = 1.0 / (e11 * e22 - 1.0);
                let s = t / d21;
                for j in k + 2..n {
                    let wk = s * (e11 * a[at(n, j, k)] - a[at(n, j, k + 1)]);
                    let wk1 = s * (e22 * a[at(n, j, k + 1)] - a[at(n, j, k)]);
                    let (head, tail) = a.split_at_mut(at(n, 0, j));
                    let col_k = &head[at(n, j, k)..at(n, n, k)];
                    let col_k1 = &head[at(n, j, k + 1)..at(n, n, k + 1)];
                    for ((cj, &ck), &ck1) in tail[j..n].iter_mut().zip(col_k).zip(col_k1) {
                        *cj -= ck * wk + ck1 * wk1;
                    }
                    a[at(n, j, k)] = wk;
                    a[at(n, j, k + 1)] = wk1;
                }
            }
            let code = -(kp as i32) - 1;
            piv[k] = code;
            piv[k + 1] = code;
            k += 2;
        }
    }
    Some(inertia)
}

/// Solves `A x = b` in place with the factors from [`factor`] (`b` has `n` entries).
pub fn solve(a: &[f64], n: usize, piv: &[i32], b: &mut [f64]) {
    solve_many(a, n, piv, &mut b[..n], 1);
}

/// Solves `A X = B` in place for the `ncols` columns of `b` (column-major, `n × ncols`),
/// each column in exactly the operations of [`solve`]; the factor is read once per step
/// for all columns.
pub fn solve_many(a: &[f64], n: usize, piv: &[i32], b: &mut [f64], ncols: usize) {
    debug_assert!(b.len() >= n * ncols);
    let b = &mut b[..n * ncols];
    // L D y = P b, interchanges interleaved.
    let mut k = 0;
    while k < n {
        let (two, p) = decode(piv[k]);
        if !two {
            let lk = &a[at(n, k + 1, k)..at(n, n, k)];
            let dkk = a[at(n, k, k)];
            for col in b.chunks_exact_mut(n) {
                col.swap(k, p);
                let bk = col[k];
                if bk != 0.0 {
                    for (bi, &l) in col[k + 1..].iter_mut().zip(lk) {
                        *bi -= l * bk;
                    }
                }
                col[k] = bk / dkk;
            }
            k += 1;
        } else {
            let d21 = a[at(n, k + 1, k)];
            let e11 = a[at(n, k, k)] / d21;
            let e22 = a[at(n, k + 1, k + 1)] / d21;
            let denom = e11 * e22 - 1.0;
            for col in b.chunks_exact_mut(n) {
                col.swap(k + 1, p);
                let (bk, bk1) = (col[k], col[k + 1]);
                if k + 2 < n {
                    let lk = &a[at(n, k + 2, k)..at(n, n, k)];
                    let lk1 = &a[at(n, k + 2, k + 1)..at(n, n, k + 1)];
                    for ((bi, &l0), &l1) in col[k + 2..].iter_mut().zip(lk).zip(lk1) {
                        *bi -= l0 * bk + l1 * bk1;
                    }
                }
                let (c0, c1) = (bk / d21, bk1 / d21);
                col[k] = (e22 * c0 - c1) / denom;
                col[k + 1] = (e11 * c1 - c0) / denom;
            }
            k += 2;
        }
    }
    // Lᵀ x = y, then the interchanges in reverse.
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

#[cfg(test)]
mod tests {
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

    fn check(m: &DMatrix<f64>, rng: &mut ChaCha8Rng) -> (usize, bool) {
        let n = m.nrows();
        let mut a = lower_of(m);
        let mut piv = vec![0; n];
        let inertia = factor(&mut a, n, &mut piv).expect("nonsingular");
        let eig = SymmetricEigen::new(m.clone()).eigenvalues;
        let neg = eig.iter().filter(|&&l| l < 0.0).count();
        assert_eq!(inertia.negative, neg, "negative eigenvalues");
        assert_eq!(inertia.positive, n - neg, "positive eigenvalues");
        let b = DVector::from_fn(n, |_, _| rng.random_range(-1.0..1.0));
        let reference = m.clone().lu().solve(&b).expect("LU solve");
        let mut x = b.as_slice().to_vec();
        solve(&a, n, &piv, &mut x);
        let err = (DVector::from_vec(x) - &reference).amax() / reference.amax();
        // Condition numbers here stay below ~1e4: 1e-10 leaves a wide margin over
        // eps · κ · n.
        assert!(err < 1e-10, "solve differs from LU by {err:e} (relative)");
        // Three columns at once: each bit for bit as solved alone.
        let cols: Vec<f64> = (0..3 * n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut many = cols.clone();
        solve_many(&a, n, &piv, &mut many, 3);
        for (c, got) in cols.chunks_exact(n).zip(many.chunks_exact(n)) {
            let mut one = c.to_vec();
            solve(&a, n, &piv, &mut one);
            assert_eq!(one, got, "a column of solve_many differs from solve");
        }
        (neg, piv.iter().any(|&p| p < 0))
    }

    /// Random symmetric indefinite matrices: the inertia equals the signs of nalgebra's
    /// `SymmetricEigen` eigenvalues, and the solve equals nalgebra's LU solve to 1e-10
    /// relative.
    #[test]
    fn inertia_and_solve_match_eigen_and_lu_on_random_indefinite_matrices() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut saw_two_by_two = false;
        for trial in 0..200 {
            let n = 1 + trial % 23;
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
        for (nx, m) in [(3, 2), (6, 3), (10, 7), (13, 12)] {
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
        assert!(factor(&mut a, 3, &mut piv).is_none());
        // [[1, 0, 0], [0, 0, 0], [0, 0, 2]]: the middle column is zero.
        let mut a = vec![1.0, 0.0, 0.0, f64::NAN, 0.0, 0.0, f64::NAN, f64::NAN, 2.0];
        assert!(factor(&mut a, 3, &mut piv).is_none());
    }
}
