//! The numeric factorisation by block elimination: assembling each block from the
//! nonzeros, factoring it and its border columns, updating the next block and the
//! border's Schur complement, and the border last.

use crate::linalg::bunch_kaufman;

use super::Workspace;

/// What a factorisation found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Count {
    /// It ran to the end: the number of negative eigenvalues.
    Negative(usize),
    /// It stopped where the matrix was certain to have more negative eigenvalues than its
    /// multipliers (see [`Workspace::surplus`]).
    Surplus,
}

/// Zeroes the lower triangle (with the diagonal) of the column-major `n × n` matrix `a`.
/// The symmetric matrices the blocked elimination factors (each block's `A`, the border's
/// `S`) are assembled, updated and factorised below their diagonal only, so what lies above
/// it keeps the zeros it was allocated with and needs no clearing.
pub(super) fn clear_lower(a: &mut [f64], n: usize) {
    if n == 0 {
        return;
    }
    for (j, col) in a.chunks_exact_mut(n).enumerate() {
        col[j..].fill(0.0);
    }
}

impl Workspace {
    /// Assembles group `owner` (a block's `A`, `C` and `W`, or with `owner` = the block
    /// count the border's `S`) from `values`; `None` on a non-finite entry.
    pub(super) fn assemble(&mut self, owner: usize, values: &[f64]) -> Option<()> {
        let nb = self.border.len();
        match self.blocks.get(owner) {
            Some(b) => {
                clear_lower(&mut self.dense[b.a_off..b.a_off + b.n * b.n], b.n);
                let c = self.c_base + b.c_off;
                self.dense[c..c + b.n * b.l].fill(0.0);
                let w = self.w_base + b.w_off;
                self.dense[w..w + b.n * b.m].fill(0.0);
                self.dense[b.gs_off..b.gs_off + b.gs_len].fill(0.0);
            }
            None => clear_lower(&mut self.dense[self.s_off..self.s_off + nb * nb], nb),
        }
        let mut finite = true;
        let group = &self.by_owner[self.owner_start[owner]..self.owner_start[owner + 1]];
        // `by_owner` holds each nonzero's index once (< dest.len()), and `new` checked
        // every `dest` inside `dense`.
        assert!(values.len() >= self.dest.len(), "one value per nonzero");
        for &i in group {
            // SAFETY: i < dest.len() <= values.len(); dest[i] < dense.len() (`new`).
            unsafe {
                let v = *values.get_unchecked(i as usize);
                *self
                    .dense
                    .get_unchecked_mut(*self.dest.get_unchecked(i as usize)) += v;
                self.k_max = self.k_max.max(v.abs());
                finite &= v.is_finite();
            }
        }
        finite.then_some(())
    }

    /// Factorises the matrix with nonzeros `values`. `None`: a non-finite entry, a pivot
    /// under `floor` or a zero pivot column; otherwise the number of negative eigenvalues,
    /// or with `test` (the surplus test set up by [`Workspace::prepare_surplus`]) possibly
    /// [`Count::Surplus`], before the end.
    pub(super) fn factor(&mut self, values: &[f64], floor: f64, test: bool) -> Option<Count> {
        let count = self.blocks.len();
        self.k_max = 0.0;
        self.assemble(count, values)?;
        let nb = self.border.len();
        let mut negative = 0;
        // The test holds for a KKT's shape, with the multipliers' diagonal `−δ_c ≤ 0`; the
        // groups' fill rank depends on whether that diagonal is zero.
        let (mut test, mut zero_diag) = (
            test && self.first_dual != usize::MAX && self.kkt_shaped,
            true,
        );
        if test {
            for &e in &self.dual_diag {
                test &= values[e] <= 0.0;
                zero_diag &= values[e] == 0.0;
            }
        }
        // The fill rank block `b`'s groups may add to the multipliers' diagonal block.
        let fill_rank = |ws: &Workspace, b: usize| match ws.blocks.get(b) {
            None => 0,
            Some(_) if zero_diag => ws.fill_rank_zero[b],
            Some(_) => ws.fill_rank_any[b],
        };
        // Multipliers eliminated so far.
        let mut m_p = 0;
        if count > 0 {
            self.assemble(0, values)?;
            negative += self.eliminate_groups(0, floor)?;
            m_p += self.group_duals[0];
        }
        for k in 0..count {
            // The next block is assembled now, and its groups eliminated (they update this
            // block too): this one's elimination updates it.
            if k + 1 < count {
                self.assemble(k + 1, values)?;
                negative += self.eliminate_groups(k + 1, floor)?;
                m_p += self.group_duals[k + 1];
            }
            let next_fill = fill_rank(self, k + 1);
            negative += self.eliminate_block(k, floor)?;
            // The next block, if linked: with G_L = L⁻¹ Pᵀ E_L and V_L = D⁻¹ G_L,
            // M = E_Lᵀ Ã_kk⁻¹ E_L = G_Lᵀ V_L and E_Lᵀ Ã_kk⁻¹ W_k = G_Lᵀ V;
            // Ã_{k+1} -= C M Cᵀ and W_{k+1} -= C E_Lᵀ Ã_kk⁻¹ W_k.
            let l = self.blocks.get(k + 1).map_or(0, |next| next.l);
            m_p += self.block_duals[k];
            if l == 0 {
                let base = m_p + self.border_duals + next_fill;
                if test && negative > base {
                    return Some(Count::Surplus);
                }
                continue;
            }
            self.link_next(k);
            let base = m_p + self.border_duals + next_fill;
            if test
                && Self::surplus(
                    negative,
                    base,
                    &self.m_link[..l * l],
                    l,
                    &mut self.m_copy,
                    &mut self.m_piv,
                    &mut self.bk_work,
                )
            {
                return Some(Count::Surplus);
            }
            self.update_next(k);
        }
        if nb > 0 {
            let s = &mut self.dense[self.s_off..self.s_off + nb * nb];
            let piv = &mut self.piv[self.members.len()..];
            negative += factor_above(&mut *s, nb, piv, &mut self.bk_work, floor)?;
        }
        Some(Count::Negative(negative))
    }

    /// Factors block `k`'s `Ã_kk` (already updated by the previous block and by its
    /// groups), forms `V_k` and subtracts `W_kᵀ Ã_kk⁻¹ W_k` from `S`. `None`: a pivot
    /// under `floor` (or a zero column); otherwise its number of negative eigenvalues.
    fn eliminate_block(&mut self, k: usize, floor: f64) -> Option<usize> {
        let nb = self.border.len();
        let (a_all, rest) = self.dense.split_at_mut(self.c_base);
        let (_, rest) = rest.split_at_mut(self.w_base - self.c_base);
        let (w_all, s) = rest.split_at_mut(self.s_off - self.w_base);
        let blk = self.blocks[k];
        let (n, m) = (blk.n, blk.m);
        let a = &mut a_all[blk.a_off..blk.a_off + n * n];
        let w = &w_all[blk.w_off..blk.w_off + n * m];
        let piv = &mut self.piv[blk.first..blk.first + n];
        let negative = factor_above(&mut *a, n, piv, &mut self.bk_work, floor)?;
        let (a, piv) = (&*a, &*piv);
        // G = L⁻¹ Pᵀ W_k and V_k = D⁻¹ G, so that uᵀ Ã_kk⁻¹ W_k = (L⁻¹ Pᵀ u)ᵀ V_k: half
        // a solve per column (the solves do the other half).
        let g = &mut self.g_w[..n * m];
        g.copy_from_slice(w);
        let v = &mut self.y[blk.y_off..blk.y_off + n * m];
        half_solve(a, n, piv, g, v, m);
        let (g, v) = (&*g, &*v);
        // S -= W_kᵀ Ã_kk⁻¹ W_k = Gᵀ V over the lower triangle (border columns increase).
        let cols = &self.border_cols[blk.b_first..blk.b_first + m];
        for (jj, &bj) in cols.iter().enumerate() {
            let vj = &v[jj * n..(jj + 1) * n];
            for (ii, &bi) in cols.iter().enumerate().skip(jj) {
                let gi = &g[ii * n..(ii + 1) * n];
                s[bi + bj * nb] -= bunch_kaufman::dot(gi, vj);
            }
        }
        Some(negative)
    }

    /// With block `k` factored and the next block linked to it: `G_L = L⁻¹ Pᵀ E_L` (in
    /// `g_l`), `V_L = D⁻¹ G_L` (the next block's `Z`) and `M = G_Lᵀ V_L` (in `m_link`).
    fn link_next(&mut self, k: usize) {
        let blk = self.blocks[k];
        let next = self.blocks[k + 1];
        let (n, l) = (blk.n, next.l);
        let a = &self.dense[blk.a_off..blk.a_off + n * n];
        let piv = &self.piv[blk.first..blk.first + n];
        let links = &self.links[next.l_first..next.l_first + l];
        let gl = &mut self.g_l[..n * l];
        gl.fill(0.0);
        for (col, &li) in gl.chunks_exact_mut(n).zip(links) {
            col[li] = 1.0;
        }
        let vl = &mut self.z[next.z_off..next.z_off + n * l];
        half_solve(a, n, piv, gl, vl, l);
        let (gl, vl) = (&*gl, &*vl);
        let mm = &mut self.m_link[..l * l];
        for (j, vj) in vl.chunks_exact(n).enumerate() {
            for (i, gi) in gl.chunks_exact(n).enumerate() {
                mm[i + j * l] = bunch_kaufman::dot(gi, vj);
            }
        }
    }

    /// With [`Workspace::link_next`] done for block `k`: `E_Lᵀ Ã_kk⁻¹ W_k = G_Lᵀ V` (in
    /// `y_link`), then `Ã_{k+1} -= C M Cᵀ` and `W_{k+1} -= C E_Lᵀ Ã_kk⁻¹ W_k`.
    fn update_next(&mut self, k: usize) {
        let (a_all, rest) = self.dense.split_at_mut(self.c_base);
        let (c_all, rest) = rest.split_at_mut(self.w_base - self.c_base);
        let (w_all, _) = rest.split_at_mut(self.s_off - self.w_base);
        let blk = self.blocks[k];
        let next = self.blocks[k + 1];
        let (n, m, nn, l) = (blk.n, blk.m, next.n, next.l);
        let v = &self.y[blk.y_off..blk.y_off + n * m];
        let gl = &self.g_l[..n * l];
        let mm = &self.m_link[..l * l];
        let yl = &mut self.y_link[..l * m];
        for (j, vj) in v.chunks_exact(n).enumerate() {
            for (q, gq) in gl.chunks_exact(n).enumerate() {
                yl[q + j * l] = bunch_kaufman::dot(gq, vj);
            }
        }
        let c = &c_all[next.c_off..next.c_off + nn * l];
        let cm = &mut self.cm[..nn * l];
        cm.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..l {
            let out = &mut cm[j * nn..(j + 1) * nn];
            for q in 0..l {
                let f = mm[q + j * l];
                if f != 0.0 {
                    for (o, &cv) in out.iter_mut().zip(&c[q * nn..(q + 1) * nn]) {
                        *o += cv * f;
                    }
                }
            }
        }
        // Lower triangle of Ã_{k+1} -= (C M) Cᵀ.
        let a_next = &mut a_all[next.a_off..][..nn * nn];
        for q in 0..l {
            let cmq = &cm[q * nn..(q + 1) * nn];
            let cq = &c[q * nn..(q + 1) * nn];
            for (j, &f) in cq.iter().enumerate() {
                if f != 0.0 {
                    let col = &mut a_next[j * nn + j..(j + 1) * nn];
                    for (av, &v) in col.iter_mut().zip(&cmq[j..]) {
                        *av -= v * f;
                    }
                }
            }
        }
        let w_next = &mut w_all[next.w_off..][..nn * next.m];
        let prev = &self.prev_col[next.b_first..next.b_first + next.m];
        for (jj, &pj) in prev.iter().enumerate() {
            if pj == usize::MAX {
                continue;
            }
            let ylj = &yl[pj * l..(pj + 1) * l];
            let out = &mut w_next[jj * nn..(jj + 1) * nn];
            for (q, &f) in ylj.iter().enumerate() {
                if f != 0.0 {
                    for (o, &cv) in out.iter_mut().zip(&c[q * nn..(q + 1) * nn]) {
                        *o -= cv * f;
                    }
                }
            }
        }
    }
}

/// Factorises the `n × n` matrix `a` in place ([`bunch_kaufman::factor`]); its number of
/// negative eigenvalues, or `None` when a pivot is under `floor` (or a column is zero).
pub(super) fn factor_above(
    a: &mut [f64],
    n: usize,
    piv: &mut [i32],
    work: &mut [f64],
    floor: f64,
) -> Option<usize> {
    let inertia = bunch_kaufman::factor(a, n, piv, work)?;
    (inertia.min_pivot >= floor).then_some(inertia.negative)
}

/// With the factors `Ã = P L D Lᵀ Pᵀ` of `a`: `g ← L⁻¹ Pᵀ g` and `v ← D⁻¹ g` for the
/// `ncols` columns of `g` (then `uᵀ Ã⁻¹ g₀ = (L⁻¹ Pᵀ u)ᵀ v`).
pub(super) fn half_solve(
    a: &[f64],
    n: usize,
    piv: &[i32],
    g: &mut [f64],
    v: &mut [f64],
    ncols: usize,
) {
    bunch_kaufman::forward_many(a, n, piv, g, ncols);
    v.copy_from_slice(g);
    bunch_kaufman::scale_by_d_inv(a, n, piv, v, ncols);
}
