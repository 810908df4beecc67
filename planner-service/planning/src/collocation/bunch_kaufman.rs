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
#[inline(always)]
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
#[inline(always)]
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

/// Declares `pub fn $name` running `$body` on the widest vector unit the CPU has: AVX2
/// where present (detected at run time; the build targets baseline x86-64), else the
/// baseline (SSE2) code, also public as `$portable`. Both paths execute the same
/// floating-point operations in the same order — no fused multiply-add, partial sums in
/// the same lanes — so they give the same bits (`tests::dispatched_and_portable_paths_agree_bit_for_bit`).
macro_rules! dispatched {
    ($(#[$doc:meta])* $name:ident, $avx2:ident, $portable:ident, $body:ident,
     ($($arg:ident: $ty:ty),*) $(-> $ret:ty)?) => {
        $(#[$doc])*
        pub fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has AVX2 (checked just above).
                return unsafe { $avx2($($arg),*) };
            }
            $body($($arg),*)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        fn $avx2($($arg: $ty),*) $(-> $ret)? {
            $body($($arg),*)
        }

        #[doc = concat!("[`", stringify!($name), "`] on the baseline (SSE2) code path.")]
        pub fn $portable($($arg: $ty),*) $(-> $ret)? {
            $body($($arg),*)
        }
    };
}

/// Columns per panel of the blocked factorisation (LAPACK `dsytrf` / `dlasyf`): up to
/// `PANEL - 1` columns (or `PANEL` with a final 2×2 pivot) are factorised against their
/// delayed updates, then the trailing matrix is updated once for the whole panel, which
/// reads and writes it once per panel instead of once per column.
pub const PANEL: usize = 16;

/// Scratch [`factor`] needs for an `n × n` matrix to run blocked (less: unblocked).
pub fn work_len(n: usize) -> usize {
    n * PANEL
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
}
