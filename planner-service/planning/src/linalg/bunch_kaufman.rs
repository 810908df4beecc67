//! Dense symmetric-indefinite `LDLᵀ` factorisation with Bunch–Kaufman partial pivoting
//! (1×1 and 2×2 pivots), the unblocked LAPACK `dsytf2` / `dsytrs` scheme on the lower
//! triangle of a column-major matrix, for the small dense blocks of the structured KKT
//! solver ([`crate::collocation::kkt`]). It works in place on caller-owned buffers and never
//! allocates.
//!
//! `P A Pᵀ = L D Lᵀ` is stored as LAPACK stores it: the multipliers of `L` below the
//! diagonal, `D`'s 1×1 and 2×2 blocks on and just below the diagonal, and the
//! interchanges interleaved with the columns (`piv`), so a solve applies them step by
//! step. Inertia is read off `D` (Sylvester's law).
//!
//! The factorisation is [`factor`] (`factor.rs`), the solves with its factors
//! [`solve`], [`solve_many`] and their halves (`solve.rs`); both run on the widest vector
//! unit the CPU has (`dispatch.rs`).

#[macro_use]
mod dispatch;
mod factor;
mod solve;
#[cfg(test)]
mod tests;

pub use factor::{factor, factor_portable};
pub use solve::{
    backward_many, backward_many_portable, forward_many, forward_many_portable, scale_by_d_inv,
    solve, solve_many, solve_many_portable,
};

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

/// Columns per panel of the blocked factorisation (LAPACK `dsytrf` / `dlasyf`): up to
/// `PANEL - 1` columns (or `PANEL` with a final 2×2 pivot) are factorised against their
/// delayed updates, then the trailing matrix is updated once for the whole panel, which
/// reads and writes it once per panel instead of once per column.
pub const PANEL: usize = 16;

/// Scratch [`factor`] needs for an `n × n` matrix to run blocked (less: unblocked).
pub fn work_len(n: usize) -> usize {
    n * PANEL
}
