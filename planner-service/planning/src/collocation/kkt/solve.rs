//! Solves with the blocked factors: the pivot groups, then forward through the chain,
//! the border, and back; refined against the assembled matrix.

use crate::linalg::bunch_kaufman;

use super::Workspace;

/// Most refinement steps per solve, and the backward error that stops them.
const REFINE_STEPS: usize = 2;
const REFINE_TOL: f64 = 1e-14;

impl Workspace {
    /// Solves `K x = b` in place (`b` in KKT order, `K` with nonzeros `values`), with up
    /// to [`REFINE_STEPS`] steps of iterative refinement until the backward error
    /// `‖b − K x‖∞ / (‖K‖max ‖x‖∞ + ‖b‖∞)` is below [`REFINE_TOL`] (the blocked elimination
    /// pivots only inside each block, so its first answer can be less accurate than a
    /// globally pivoted one).
    pub(super) fn solve_refined(&mut self, values: &[f64], b: &mut [f64]) {
        self.rhs.copy_from_slice(b);
        self.solve(b);
        let b_max = self.rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for _ in 0..REFINE_STEPS {
            self.res.copy_from_slice(&self.rhs);
            assert!(
                b.len() == self.res.len(),
                "one right-hand side of the KKT's order"
            );
            for ((&r, &c), &v) in self.rows.iter().zip(&self.cols).zip(values) {
                let (r, c) = (r as usize, c as usize);
                // SAFETY: r, c < dim (`new`) = res.len() = b.len().
                unsafe {
                    *self.res.get_unchecked_mut(r) -= v * b.get_unchecked(c);
                    if r != c {
                        *self.res.get_unchecked_mut(c) -= v * b.get_unchecked(r);
                    }
                }
            }
            let r_max = self.res.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let x_max = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if r_max <= REFINE_TOL * (self.k_max * x_max + b_max) {
                break;
            }
            let mut res = std::mem::take(&mut self.res);
            self.solve(&mut res);
            for (x, d) in b.iter_mut().zip(&res) {
                *x += d;
            }
            self.res = res;
        }
    }

    /// Solves in place for one right-hand side `b` (KKT order), without refinement.
    pub(super) fn solve(&mut self, b: &mut [f64]) {
        // The groups first: b_N -= Bᵀ G⁻¹ b_g = Yᵀ b_g on the neighbours, and
        // t_g = G⁻¹ b_g kept.
        for (gi, g) in self.groups.iter().enumerate() {
            let q = g.q;
            let t = &mut self.g_work[g.first..g.first + q];
            for (ti, &i) in t.iter_mut().zip(&self.g_members[g.first..g.first + q]) {
                *ti = b[i];
            }
            let y = &self.g_y[g.y_off..];
            let nbrs = &self.g_nbrs[g.n_first..];
            for &j in &self.g_nz[g.n_first..g.n_first + self.g_nz_len[gi]] {
                let yj = &y[j * q..(j + 1) * q];
                b[nbrs[j]] -= yj.iter().zip(t.iter()).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        self.solve_chain(b);
        // Then x_g = G⁻¹ b_g - Y x_N.
        for (gi, g) in self.groups.iter().enumerate() {
            let q = g.q;
            let bg = &mut self.g_work[g.first..g.first + q];
            let inv = &self.g_inv[g.inv_off..g.inv_off + q * q];
            let y = &self.g_y[g.y_off..];
            let nbrs = &self.g_nbrs[g.n_first..];
            let nz = &self.g_nz[g.n_first..g.n_first + self.g_nz_len[gi]];
            for (r, &i) in self.g_members[g.first..g.first + q].iter().enumerate() {
                let mut x: f64 = (0..q).map(|c| inv[r + c * q] * bg[c]).sum();
                for &j in nz {
                    x -= y[j * q + r] * b[nbrs[j]];
                }
                b[i] = x;
            }
            let _ = bg;
        }
    }

    /// The chain's and the border's part of [`Workspace::solve`] (the indices outside
    /// the groups, with the groups' couplings already taken out of `b`).
    pub(super) fn solve_chain(&mut self, b: &mut [f64]) {
        let nb = self.border.len();
        let c_all = &self.dense[self.c_base..self.w_base];
        let s = &self.dense[self.s_off..];
        for (w, &i) in self.work_b.iter_mut().zip(&self.border) {
            *w = b[i];
        }
        // Forward, with Ã_kk = P L D Lᵀ Pᵀ: t_k = b_k - C_k u_{k-1}[L_k], h = L⁻¹ Pᵀ t_k,
        // b_G -= W_kᵀ Ã_kk⁻¹ t_k = V_kᵀ h, u_k[L_{k+1}] = E_Lᵀ Ã_kk⁻¹ t_k = V_Lᵀ h (in
        // `ctx`, for the next block), and D⁻¹ h kept for the backward pass.
        for k in 0..self.blocks.len() {
            let blk = self.blocks[k];
            let (n, m, l) = (blk.n, blk.m, blk.l);
            let t = &mut self.work[blk.first..blk.first + n];
            for (ti, &i) in t.iter_mut().zip(&self.members[blk.first..blk.first + n]) {
                *ti = b[i];
            }
            if l > 0 {
                let c = &c_all[blk.c_off..blk.c_off + n * l];
                for (cq, &f) in c.chunks_exact(n).zip(&self.ctx[..l]) {
                    if f != 0.0 {
                        for (ti, &cv) in t.iter_mut().zip(cq) {
                            *ti -= cv * f;
                        }
                    }
                }
            }
            let a = &self.dense[blk.a_off..blk.a_off + n * n];
            let piv = &self.piv[blk.first..blk.first + n];
            bunch_kaufman::forward_many(a, n, piv, t, 1);
            let v = &self.y[blk.y_off..blk.y_off + n * m];
            let cols = &self.border_cols[blk.b_first..blk.b_first + m];
            for (vj, &bj) in v.chunks_exact(n).zip(cols) {
                self.work_b[bj] -= bunch_kaufman::dot(vj, t);
            }
            if let Some(&next) = self.blocks.get(k + 1) {
                let vl = &self.z[next.z_off..next.z_off + n * next.l];
                for (o, vq) in self.ctx.iter_mut().zip(vl.chunks_exact(n)) {
                    *o = bunch_kaufman::dot(vq, t);
                }
            }
            bunch_kaufman::scale_by_d_inv(a, n, piv, t, 1);
        }
        if nb > 0 {
            bunch_kaufman::solve(s, nb, &self.piv[self.members.len()..], &mut self.work_b);
        }
        // Backward: x_k = Ã_kk⁻¹ (t_k - W_k x_G - E_L C_{k+1}ᵀ x_{k+1})
        //               = P L⁻ᵀ (D⁻¹ h - V_k x_G - V_L C_{k+1}ᵀ x_{k+1}).
        for k in (0..self.blocks.len()).rev() {
            let blk = self.blocks[k];
            let (n, m) = (blk.n, blk.m);
            let (now, later) = self.work.split_at_mut(blk.first + n);
            let t = &mut now[blk.first..];
            let v = &self.y[blk.y_off..blk.y_off + n * m];
            let cols = &self.border_cols[blk.b_first..blk.b_first + m];
            for (vj, &bj) in v.chunks_exact(n).zip(cols) {
                let f = self.work_b[bj];
                if f != 0.0 {
                    for (ti, &vv) in t.iter_mut().zip(vj) {
                        *ti -= vv * f;
                    }
                }
            }
            if let Some(&next) = self.blocks.get(k + 1) {
                let (nn, l) = (next.n, next.l);
                if l > 0 {
                    let x_next = &later[..nn];
                    let c = &c_all[next.c_off..next.c_off + nn * l];
                    let ctx = &mut self.ctx[..l];
                    for (o, cq) in ctx.iter_mut().zip(c.chunks_exact(nn)) {
                        *o = bunch_kaufman::dot(cq, x_next);
                    }
                    let vl = &self.z[next.z_off..next.z_off + n * l];
                    for (vq, &f) in vl.chunks_exact(n).zip(ctx.iter()) {
                        if f != 0.0 {
                            for (ti, &vv) in t.iter_mut().zip(vq) {
                                *ti -= vv * f;
                            }
                        }
                    }
                }
            }
            let a = &self.dense[blk.a_off..blk.a_off + n * n];
            bunch_kaufman::backward_many(a, n, &self.piv[blk.first..blk.first + n], t, 1);
            for (&ti, &i) in t.iter().zip(&self.members[blk.first..blk.first + n]) {
                b[i] = ti;
            }
        }
        for (&w, &i) in self.work_b.iter().zip(&self.border) {
            b[i] = w;
        }
    }
}
