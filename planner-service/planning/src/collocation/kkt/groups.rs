//! The elimination of the pivot groups, before the chain: each group's small dense pivot
//! `G`, its multipliers `Y = G⁻¹ B` and their fill in its neighbours' entries.

use crate::linalg::bunch_kaufman;

use super::Workspace;
use super::factor::factor_above;

/// Largest multiplier `|G⁻¹ B|` a pivot group may have: a larger one would amplify
/// rounding beyond what the refinement recovers, so FERAL factors that matrix instead.
pub(super) const GROUP_GROWTH_MAX: f64 = 1e6;

impl Workspace {
    /// Eliminates block `b`'s pivot groups (assembled): factors each `G`, forms
    /// `Y = G⁻¹ B` and subtracts `Bᵀ Y` from the neighbours' entries. `None`: a pivot under
    /// `floor` or a multiplier above [`GROUP_GROWTH_MAX`]; otherwise the groups' number of
    /// negative eigenvalues.
    pub(super) fn eliminate_groups(&mut self, b: usize, floor: f64) -> Option<usize> {
        let blk = self.blocks[b];
        let mut negative = 0;
        for gi in blk.g_first..blk.g_first + blk.g_count {
            let g = self.groups[gi];
            let (q, nn) = (g.q, g.nn);
            let bm = &mut self.g_b[..q * nn];
            bm.copy_from_slice(&self.dense[g.g_off + q * q..g.g_off + q * q + q * nn]);
            let gm = &mut self.dense[g.g_off..g.g_off + q * q];
            // G⁻¹ explicitly (the solves apply it), then Y = G⁻¹ B.
            let inv = &mut self.g_inv[g.inv_off..g.inv_off + q * q];
            if q == 2 {
                // In closed form: the inertia from the determinant, the smallest pivot the
                // smallest eigenvalue magnitude.
                let (a, b, c) = (gm[0], gm[1], gm[3]);
                let det = a * c - b * b;
                let r = (0.5 * (a - c)).hypot(b);
                let mean = 0.5 * (a + c);
                let min_pivot = (mean - r).abs().min((mean + r).abs());
                if min_pivot.is_nan() || min_pivot < floor || det == 0.0 {
                    return None;
                }
                negative += if det < 0.0 {
                    1
                } else if a < 0.0 {
                    2
                } else {
                    0
                };
                inv.copy_from_slice(&[c / det, -b / det, -b / det, a / det]);
            } else {
                let piv = &mut self.g_piv[g.first..g.first + q];
                negative += factor_above(&mut *gm, q, piv, &mut self.bk_work, floor)?;
                inv.fill(0.0);
                for k in 0..q {
                    inv[k * q + k] = 1.0;
                }
                bunch_kaufman::solve_many(gm, q, piv, inv, q);
            }
            let inv = &*inv;
            let y = &mut self.g_y[g.y_off..g.y_off + q * nn];
            let nz = &mut self.g_nz[g.n_first..g.n_first + nn];
            let mut n_nz = 0;
            // The largest multiplier, NaN if any is.
            let mut largest = 0.0f64;
            for (j, (yj, bj)) in y.chunks_exact_mut(q).zip(bm.chunks_exact(q)).enumerate() {
                if bj.iter().all(|&v| v == 0.0) {
                    yj.fill(0.0);
                    continue;
                }
                nz[n_nz] = j;
                n_nz += 1;
                match q {
                    2 => group_multipliers::<2>(inv, bj, yj),
                    4 => group_multipliers::<4>(inv, bj, yj),
                    _ => {
                        for (r, yr) in yj.iter_mut().enumerate() {
                            *yr = (0..q).map(|c| inv[r + c * q] * bj[c]).sum();
                        }
                    }
                }
                for &yr in yj.iter() {
                    let a = yr.abs();
                    if a > largest || a.is_nan() {
                        largest = a;
                    }
                }
            }
            self.g_nz_len[gi] = n_nz;
            if largest.is_nan() || largest > GROUP_GROWTH_MAX {
                return None;
            }

            let (y, bm, nz) = (&*y, &*bm, &nz[..n_nz]);
            let fill = &self.g_fill[g.f_first..g.f_first + nn * (nn + 1) / 2];
            for (jj, &j) in nz.iter().enumerate() {
                let yj = &y[j * q..(j + 1) * q];
                // Column j of the lower triangle starts at Σ_{c<j} (nn - c).
                let col = j * nn - j * j.saturating_sub(1) / 2;
                let fill = &fill[col - j..];
                let (fill, later) = (&fill[..nn], &nz[jj..]);
                // SAFETY (both unrolled cases): `nz` holds neighbour positions, below `nn`
                // (it is filled from the `nn` columns of `B` above).
                match q {
                    2 => unsafe { subtract_fill::<2>(&mut self.dense, fill, bm, yj, later) },
                    4 => unsafe { subtract_fill::<4>(&mut self.dense, fill, bm, yj, later) },
                    _ => {
                        for &i in later {
                            let bi = &bm[i * q..(i + 1) * q];
                            let v: f64 = bi.iter().zip(yj).map(|(a, b)| a * b).sum();
                            self.dense[fill[i]] -= v;
                        }
                    }
                }
            }
        }
        Some(negative)
    }
}

/// `y = G⁻¹ b` for one neighbour of a pivot group of `Q` indices (`G⁻¹` column-major in
/// `inv`), each entry summed left to right from its first product: the bits of a float
/// `sum` over the same products (which starts from −0.0, adding nothing), unrolled.
#[inline(always)]
fn group_multipliers<const Q: usize>(inv: &[f64], b: &[f64], y: &mut [f64]) {
    let (inv, b) = (&inv[..Q * Q], <&[f64; Q]>::try_from(&b[..Q]).expect("Q"));
    for (r, yr) in y[..Q].iter_mut().enumerate() {
        *yr = (1..Q).fold(inv[r] * b[0], |s, c| s + inv[r + c * Q] * b[c]);
    }
}

/// A pivot group's fill in column `y` (its `Y` for one neighbour): for each later nonzero
/// neighbour `i` in `rows`, `dense[fill[i]] -= B_iᵀ y`, the `Q`-term product summed as
/// [`group_multipliers`] sums. `b` holds `B` (`Q` entries per neighbour).
///
/// # Safety
/// Every entry of `rows` is below `fill.len()`, and every entry of `fill` below
/// `dense.len()` (`Workspace::new` checks the fill destinations).
#[inline(always)]
unsafe fn subtract_fill<const Q: usize>(
    dense: &mut [f64],
    fill: &[usize],
    b: &[f64],
    y: &[f64],
    rows: &[usize],
) {
    let y: &[f64; Q] = y[..Q].try_into().expect("Q");
    assert!(b.len() >= Q * fill.len(), "Q entries of B per neighbour");
    for &i in rows {
        // SAFETY: i < fill.len() (the caller's promise), so Q·i + Q <= b.len();
        // fill[i] < dense.len() (likewise).
        unsafe {
            let bi = &*(b.as_ptr().add(Q * i) as *const [f64; Q]);
            let v = bi
                .iter()
                .zip(y)
                .skip(1)
                .fold(bi[0] * y[0], |s, (a, c)| s + a * c);
            *dense.get_unchecked_mut(*fill.get_unchecked(i)) -= v;
        }
    }
}
