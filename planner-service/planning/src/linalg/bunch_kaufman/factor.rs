//! The Bunch–Kaufman factorisation: LAPACK's blocked `dsytrf` (panels by `dlasyf`) and
//! unblocked `dsytf2`, on the lower triangle, with the inertia read off `D`.

use super::{Inertia, PANEL, at, decode, work_len};

/// Bunch–Kaufman's growth-balancing constant `(1 + √17) / 8`.
const ALPHA: f64 = 0.640_388_203_202_208_4;

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

dispatched!(
    /// Factorises the `n × n` symmetric matrix whose lower triangle is in `a` (column-major,
    /// leading dimension `n`; the strict upper triangle is neither read nor written), in
    /// place. `piv` needs `n` entries; `work` [`work_len`]`(n)` for the blocked algorithm
    /// (LAPACK `dsytrf`: panels by `dlasyf`, the last `PANEL` columns by `dsytf2`),
    /// fewer runs it unblocked (`dsytf2` throughout). Both leave the factors in the same
    /// form (`dsytrs` solves with either) and take the same pivots in exact arithmetic.
    ///
    /// Returns `None` when a whole pivot column is zero (the matrix is singular: no pivot to
    /// take); otherwise the inertia. A nonsingular but ill-conditioned matrix factorises:
    /// the caller judges [`Inertia::min_pivot`] against its own floor.
    factor, factor_avx2, factor_portable, factor_body,
    (a: &mut [f64], n: usize, piv: &mut [i32], work: &mut [f64]) -> Option<Inertia>
);

#[inline(always)]
fn factor_body(a: &mut [f64], n: usize, piv: &mut [i32], work: &mut [f64]) -> Option<Inertia> {
    debug_assert!(a.len() >= n * n && piv.len() >= n);
    let mut inertia = Inertia {
        positive: 0,
        negative: 0,
        min_pivot: f64::INFINITY,
    };
    let mut k = 0;
    if work.len() >= work_len(n) {
        while n - k > PANEL {
            k = panel(a, n, k, piv, work, &mut inertia)?;
        }
    }
    unblocked(a, n, piv, k, &mut inertia)?;
    Some(inertia)
}

/// The largest `|v_i|` (NaN ignored), in four lanes so that it vectorises.
#[inline(always)]
fn abs_max(v: &[f64]) -> f64 {
    let mut lanes = [0.0f64; 4];
    let chunks = v.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for q in 0..4 {
            lanes[q] = lanes[q].max(c[q].abs());
        }
    }
    let mut m = lanes[0].max(lanes[1]).max(lanes[2].max(lanes[3]));
    for x in rest {
        m = m.max(x.abs());
    }
    m
}

/// The first index (plus `offset`) of the largest `|v_i|` and that magnitude; `(offset -
/// 1, 0)` when every entry is zero (or `v` is empty).
#[inline(always)]
fn abs_argmax(v: &[f64], offset: usize) -> (usize, f64) {
    let m = abs_max(v);
    if m == 0.0 {
        return (offset - 1, 0.0);
    }
    let i = v.iter().position(|x| x.abs() == m).unwrap_or(0);
    (offset + i, m)
}

/// `dsytf2`'s scaled inverse of the 2×2 pivot `[[d11, d21], [d21, d22]]`.
struct ScaledInverse {
    e11: f64,
    e22: f64,
    s: f64,
}

impl ScaledInverse {
    #[inline(always)]
    fn of(d11: f64, d21: f64, d22: f64) -> ScaledInverse {
        let e11 = d22 / d21;
        let e22 = d11 / d21;
        let t = 1.0 / (e11 * e22 - 1.0);
        ScaledInverse {
            e11,
            e22,
            s: t / d21,
        }
    }

    /// The multipliers of a row `(x, y)` of the pivot's two columns: `(x, y) D⁻¹`.
    #[inline(always)]
    fn multipliers(&self, x: f64, y: f64) -> (f64, f64) {
        (self.s * (self.e11 * x - y), self.s * (self.e22 * y - x))
    }
}

/// Records a 2×2 pivot at `(k, k + 1)` taken after interchanging `k + 1` and `kp`.
#[inline(always)]
fn mark_2x2(piv: &mut [i32], k: usize, kp: usize) {
    let code = -(kp as i32) - 1;
    piv[k] = code;
    piv[k + 1] = code;
}

/// Counts a 1×1 pivot `d` in `inertia`.
#[inline(always)]
fn take_1x1(inertia: &mut Inertia, d: f64) {
    inertia.min_pivot = inertia.min_pivot.min(d.abs());
    if d > 0.0 {
        inertia.positive += 1;
    } else {
        inertia.negative += 1;
    }
}

/// Counts the 2×2 pivot `[[d11, d21], [d21, d22]]` in `inertia`.
#[inline(always)]
fn take_2x2(inertia: &mut Inertia, d11: f64, d21: f64, d22: f64) {
    let (lo, hi) = eig2(d11, d21, d22);
    inertia.min_pivot = inertia.min_pivot.min(lo.abs()).min(hi.abs());
    for l in [lo, hi] {
        if l > 0.0 {
            inertia.positive += 1;
        } else {
            inertia.negative += 1;
        }
    }
}

/// `out[i] -= Σ_p a[base + p·n + i] · coef[p]`: a column of `out.len()` rows minus the
/// columns `p` (stride `n` in `a`, from `base`) weighted by `coef`, summed over `p` first
/// in strips of 16, then 4 rows (independent partial sums per row, each strip of `out`
/// read and written once), the last rows one by one.
#[inline(always)]
fn sub_weighted_columns(a: &[f64], n: usize, base: usize, coef: &[f64], out: &mut [f64]) {
    #[inline(always)]
    fn strip<const R: usize>(a: &[f64], n: usize, from: usize, coef: &[f64], out: &mut [f64]) {
        let mut acc = [0.0f64; R];
        if coef.is_empty() {
            return;
        }
        // Every column read lies inside `a`: checked once for the last (the furthest).
        assert!(
            from + (coef.len() - 1) * n + R <= a.len(),
            "R rows of every column"
        );
        let base = a[from..].as_ptr();
        for (p, &c) in coef.iter().enumerate() {
            // SAFETY: from + p·n + R <= from + (coef.len() − 1)·n + R <= a.len() (above).
            let col = unsafe { &*(base.add(p * n) as *const [f64; R]) };
            for q in 0..R {
                acc[q] += col[q] * c;
            }
        }
        for (o, v) in out.iter_mut().zip(acc) {
            *o -= v;
        }
    }
    let len = out.len();
    let mut i = 0;
    while i + 16 <= len {
        strip::<16>(a, n, base + i, coef, &mut out[i..i + 16]);
        i += 16;
    }
    while i + 4 <= len {
        strip::<4>(a, n, base + i, coef, &mut out[i..i + 4]);
        i += 4;
    }
    while i < len {
        strip::<1>(a, n, base + i, coef, &mut out[i..i + 1]);
        i += 1;
    }
}

/// One panel of LAPACK's `dlasyf` (lower) on the trailing matrix from column `k0`:
/// factorises up to `PANEL - 1` columns (`PANEL` with a closing 2×2 pivot), each updated
/// only when reached (`W` holds the updated columns, `W = L D`), then updates the trailing
/// matrix with `A22 -= L21 W21ᵀ` and puts the panel's `L` in `dsytf2`'s form. Returns the
/// first column not factorised.
#[inline(always)]
fn panel(
    a: &mut [f64],
    n: usize,
    k0: usize,
    piv: &mut [i32],
    w: &mut [f64],
    inertia: &mut Inertia,
) -> Option<usize> {
    let mut coef = [0.0f64; PANEL];
    let mut k = k0;
    while k < n && k - k0 + 1 < PANEL {
        let kw = k - k0;
        // W[k.., kw] = A[k.., k] - L[k.., panel] W[k, panel]ᵀ.
        for (p, c) in coef.iter_mut().enumerate().take(kw) {
            *c = w[k + p * n];
        }
        {
            let (col, _) = w[kw * n..].split_at_mut(n);
            col[k..n].copy_from_slice(&a[at(n, k, k)..at(n, n, k)]);
            sub_weighted_columns(a, n, at(n, k, k0), &coef[..kw], &mut col[k..n]);
        }
        let absakk = w[k + kw * n].abs();
        let (imax, colmax) = abs_argmax(&w[k + 1 + kw * n..(kw + 1) * n], k + 1);
        if absakk.max(colmax) == 0.0 || !absakk.max(colmax).is_finite() {
            return None;
        }
        let (two, kp) = if absakk >= ALPHA * colmax {
            (false, k)
        } else {
            // W[k.., kw + 1] = column `imax` of the trailing matrix, updated.
            for (p, c) in coef.iter_mut().enumerate().take(kw) {
                *c = w[imax + p * n];
            }
            let next = &mut w[(kw + 1) * n..(kw + 2) * n];
            for j in k..imax {
                next[j] = a[at(n, imax, j)];
            }
            next[imax..n].copy_from_slice(&a[at(n, imax, imax)..at(n, n, imax)]);
            sub_weighted_columns(a, n, at(n, k, k0), &coef[..kw], &mut next[k..n]);
            let rowmax = abs_max(&next[k..imax]).max(abs_max(&next[imax + 1..n]));
            if absakk >= ALPHA * colmax * (colmax / rowmax) {
                (false, k)
            } else if next[imax].abs() >= ALPHA * rowmax {
                let (cur, next) = w[kw * n..(kw + 2) * n].split_at_mut(n);
                cur[k..n].copy_from_slice(&next[k..n]);
                (false, imax)
            } else {
                (true, imax)
            }
        };
        let kk = if two { k + 1 } else { k };
        if kp != kk {
            // The not yet updated column kk of A moves to column kp (column kk itself is
            // overwritten below); rows kk and kp swap in the panel's columns before k
            // and in W's columns so far.
            a[at(n, kp, kp)] = a[at(n, kk, kk)];
            for j in kk + 1..kp {
                a[at(n, kp, j)] = a[at(n, j, kk)];
            }
            for i in kp + 1..n {
                a[at(n, i, kp)] = a[at(n, i, kk)];
            }
            for j in k0..k {
                a.swap(at(n, kk, j), at(n, kp, j));
            }
            for c in 0..=kk - k0 {
                w.swap(kk + c * n, kp + c * n);
            }
        }
        if !two {
            let d = w[k + kw * n];
            take_1x1(inertia, d);
            a[at(n, k, k)] = d;
            let r = 1.0 / d;
            for i in k + 1..n {
                a[at(n, i, k)] = w[i + kw * n] * r;
            }
            piv[k] = kp as i32;
            k += 1;
        } else {
            let (d11, d21, d22) = (w[k + kw * n], w[k + 1 + kw * n], w[k + 1 + (kw + 1) * n]);
            take_2x2(inertia, d11, d21, d22);
            if k + 2 < n {
                let inv = ScaledInverse::of(d11, d21, d22);
                for j in k + 2..n {
                    let (wk, wk1) = inv.multipliers(w[j + kw * n], w[j + (kw + 1) * n]);
                    a[at(n, j, k)] = wk;
                    a[at(n, j, k + 1)] = wk1;
                }
            }
            a[at(n, k, k)] = d11;
            a[at(n, k + 1, k)] = d21;
            a[at(n, k + 1, k + 1)] = d22;
            mark_2x2(piv, k, kp);
            k += 2;
        }
    }
    // A[k.., k..] -= L[k.., panel] W[k.., panel]ᵀ over the lower triangle, column by column.
    let kw = k - k0;
    {
        let (done, trailing) = a.split_at_mut(k * n);
        for j in k..n {
            for (p, c) in coef.iter_mut().enumerate().take(kw) {
                *c = w[j + p * n];
            }
            let col = &mut trailing[(j - k) * n + j..(j - k) * n + n];
            sub_weighted_columns(done, n, at(n, j, k0), &coef[..kw], col);
        }
    }
    // dsytf2's form: undo, in the panel's columns before each pivot, the row interchanges
    // of the pivots after them.
    let mut j = k;
    while j > k0 {
        let jj = j - 1;
        let (two, jp) = decode(piv[jj]);
        let first = if two { jj - 1 } else { jj };
        if jp != jj {
            for c in k0..first {
                a.swap(at(n, jj, c), at(n, jp, c));
            }
        }
        j = first;
    }
    Some(k)
}

/// LAPACK's `dsytf2` (lower) from column `k0` to the end.
#[inline(always)]
fn unblocked(
    a: &mut [f64],
    n: usize,
    piv: &mut [i32],
    k0: usize,
    inertia: &mut Inertia,
) -> Option<()> {
    let mut k = k0;
    while k < n {
        let absakk = a[at(n, k, k)].abs();
        let (imax, colmax) = abs_argmax(&a[at(n, k + 1, k)..at(n, n, k)], k + 1);
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
            rowmax = rowmax.max(abs_max(&a[at(n, imax + 1, imax)..at(n, n, imax)]));
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
            take_1x1(inertia, d);
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
            take_2x2(inertia, d11, d21, d22);
            if k + 2 < n {
                let inv = ScaledInverse::of(d11, d21, d22);
                for j in k + 2..n {
                    let (wk, wk1) = inv.multipliers(a[at(n, j, k)], a[at(n, j, k + 1)]);
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
            mark_2x2(piv, k, kp);
            k += 2;
        }
    }
    Some(())
}
