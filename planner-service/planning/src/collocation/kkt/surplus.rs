//! The surplus test: stopping a factorisation that is certain to find more negative
//! eigenvalues than the KKT has multipliers.

use crate::linalg::bunch_kaufman;

use super::Workspace;

impl Workspace {
    /// Sets the surplus test up for a KKT whose multipliers are the indices from
    /// `first_dual` on (nothing to do when it already is). The test needs the KKT's shape:
    /// no entry of the pattern couples two multipliers (`kkt_shaped`).
    pub(super) fn prepare_surplus(&mut self, first_dual: usize) {
        if self.first_dual == first_dual {
            return;
        }
        self.first_dual = first_dual;
        let dual = |i: &usize| *i >= first_dual;
        for (b, blk) in self.blocks.iter().enumerate() {
            self.block_duals[b] = self.members[blk.first..blk.first + blk.n]
                .iter()
                .filter(|i| dual(i))
                .count();
            let (mut duals, mut any, mut zero) = (0, 0, 0);
            for g in &self.groups[blk.g_first..blk.g_first + blk.g_count] {
                let d = self.g_members[g.first..g.first + g.q]
                    .iter()
                    .filter(|i| dual(i))
                    .count();
                // Its elimination adds to the multipliers' diagonal block `B_Λᵀ (G⁻¹)_uu
                // B_Λ`: of rank at most its primal count, and none when its multiplier
                // block is zero and as large as its primal one (then `(G⁻¹)_uu = 0`).
                duals += d;
                any += g.q - d;
                if 2 * d != g.q {
                    zero += g.q - d;
                }
            }
            self.group_duals[b] = duals;
            self.fill_rank_any[b] = any;
            self.fill_rank_zero[b] = zero;
        }
        self.border_duals = self.border.iter().filter(|i| dual(i)).count();
        self.dual_diag.clear();
        self.kkt_shaped = true;
        for (e, (&r, &c)) in self.rows.iter().zip(&self.cols).enumerate() {
            let (r, c) = (r as usize, c as usize);
            if r >= first_dual && c >= first_dual {
                if r == c {
                    self.dual_diag.push(e);
                } else {
                    self.kkt_shaped = false;
                }
            }
        }
    }

    /// Whether the factorisation, after eliminating block `k` (and every group up to
    /// block `k + 1`), is certain to end with more negative eigenvalues than the KKT has
    /// multipliers, `negative` being the count so far and `m_link` holding
    /// `M = E_Lᵀ Ã_kk⁻¹ E_L` (`l × l`, `l` the next block's links).
    ///
    /// Let `P` be the indices eliminated so far and `R` the rest, `Λ` the multipliers in
    /// `R` outside the border. Cauchy interlacing gives `pos(K) ≤ pos(K_P) + pos(S) ≤
    /// pos(K_P) + pos(S_ΛΛ) + |R| − |Λ|` (`S` the Schur complement on `R`), and `S_ΛΛ` is
    /// the multipliers' own diagonal (`−δ_c ≤ 0`, checked) minus what `P` adds to it: the
    /// next block's groups (nothing when a group's multiplier part is zero and square,
    /// else at most its primal count: `fill_rank_zero` / `fill_rank_any`) and the chain, `−C M Cᵀ`, with at
    /// most `neg(M)` positive eigenvalues. With no zero pivot `pos(K_P) = |P| − negative`,
    /// so `pos(K) < n = dim − m` (the inertia pounce expects) as soon as
    /// `negative > m_P + m_border + group_fill_rank + neg(M)`: then the count cannot come
    /// out right, whatever the rest of the factorisation finds.
    ///
    /// `base` is `m_P + m_border +` the next block's fill rank; `m_copy`, `m_piv` and `work` are
    /// scratch.
    pub(super) fn surplus(
        negative: usize,
        base: usize,
        m_link: &[f64],
        l: usize,
        m_copy: &mut [f64],
        m_piv: &mut [i32],
        work: &mut [f64],
    ) -> bool {
        if negative <= base {
            return false;
        }
        if negative > base + l {
            return true;
        }
        // neg(M) from its own factorisation, when its pivots are clear of zero (else every
        // one of its `l` eigenvalues may be negative).
        let m = &mut m_copy[..l * l];
        m.copy_from_slice(&m_link[..l * l]);
        let scale = m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let neg_m = match bunch_kaufman::factor(m, l, &mut m_piv[..l], work) {
            Some(inertia) if inertia.min_pivot > 1e-10 * scale => inertia.negative,
            _ => l,
        };
        negative > base + neg_m
    }
}
