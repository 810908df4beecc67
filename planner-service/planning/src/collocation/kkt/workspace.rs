//! The structured path's buffers: each block's and pivot group's place in them, and
//! the [`Workspace`] that holds them (built by `symbolic.rs`, factored by `factor.rs`
//! and `groups.rs`, solved with by `solve.rs`).

use pounce_rs::Index;

/// One block's place in the workspace.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Block {
    /// Order of `A_kk`.
    pub(super) n: usize,
    /// Its KKT indices are `members[first..first + n]` (also its offset in `work`/`piv`).
    pub(super) first: usize,
    /// Offset of `A_kk` (`n × n`) in `dense`.
    pub(super) a_off: usize,
    /// Border columns of `W_k` (the original ones and the fill from the previous block):
    /// `border_cols[b_first..b_first + m]` (border-local, increasing); `W_k` (`n × m`) at
    /// `w_off` in the `W` part of `dense`, `V_k = D⁻¹ L⁻¹ Pᵀ W_k` (with `Ã_kk = P L D Lᵀ
    /// Pᵀ`) at `y_off` in `y`.
    pub(super) m: usize,
    pub(super) b_first: usize,
    pub(super) w_off: usize,
    pub(super) y_off: usize,
    /// Link to the previous block: its local indices `links[l_first..l_first + l]`
    /// (increasing) that this block touches; `C_k` (`n × l`, this block's rows, those
    /// columns) at `c_off` in the `C` part of `dense`, `D⁻¹ L⁻¹ Pᵀ E_L` of block `k - 1`'s
    /// factors (`n_{k-1} × l`) at `z_off` in `z`.
    pub(super) l: usize,
    pub(super) l_first: usize,
    pub(super) c_off: usize,
    pub(super) z_off: usize,
    /// Its pivot groups `groups[g_first..g_first + g_count]`, whose `G` and `B` fill
    /// `dense[gs_off..gs_off + gs_len]`.
    pub(super) g_first: usize,
    pub(super) g_count: usize,
    pub(super) gs_off: usize,
    pub(super) gs_len: usize,
}

/// One pivot group's place in the workspace: eliminated before the chain, with its own
/// dense pivot `G` (`q × q`) and its couplings `B` (`q × nn`) to its neighbours (KKT
/// indices outside it, in blocks or the border).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Group {
    /// Its KKT indices are `g_members[first..first + q]` (also its offset in `g_piv` and
    /// `g_work`).
    pub(super) q: usize,
    pub(super) first: usize,
    /// Its neighbours `g_nbrs[n_first..n_first + nn]` (increasing).
    pub(super) nn: usize,
    pub(super) n_first: usize,
    /// `G` (column-major, lower triangle) at `g_off` in `dense`, `B` (column `j`:
    /// neighbour `j`) right after it.
    pub(super) g_off: usize,
    /// `Y = G⁻¹ B` at `y_off` in `g_y`; `G⁻¹` at `inv_off` in `g_inv`.
    pub(super) y_off: usize,
    pub(super) inv_off: usize,
    /// Where `B_iᵀ Y_j` is subtracted, for neighbours `j ≤ i`, column by column:
    /// `g_fill[f_first..f_first + nn (nn + 1) / 2]`.
    pub(super) f_first: usize,
}

/// Every buffer of the structured path, sized in `initialize_structure`.
#[derive(Debug, Default)]
pub(super) struct Workspace {
    /// Destination in `dense` of each input nonzero.
    pub(super) dest: Vec<usize>,
    /// The input nonzeros grouped by the block whose `A`, `C` or `W` they land in (the
    /// border's `S` last): group `b` is `by_owner[owner_start[b]..owner_start[b + 1]]`.
    pub(super) by_owner: Vec<u32>,
    pub(super) owner_start: Vec<usize>,
    pub(super) blocks: Vec<Block>,
    pub(super) members: Vec<usize>,
    pub(super) border_cols: Vec<usize>,
    pub(super) links: Vec<usize>,
    /// Position in the previous block's `border_cols` of each of a block's border columns
    /// (`usize::MAX`: not there), aligned with `border_cols`.
    pub(super) prev_col: Vec<usize>,
    /// KKT index of each border position.
    pub(super) border: Vec<usize>,
    /// All `A_kk`, then all `C_k`, then all `W_k`, then `S` (`nb × nb`), column-major.
    pub(super) dense: Vec<f64>,
    pub(super) c_base: usize,
    pub(super) w_base: usize,
    pub(super) s_off: usize,
    pub(super) y: Vec<f64>,
    pub(super) z: Vec<f64>,
    /// Pivots: the blocks' at their `first`, `S`'s after them.
    pub(super) piv: Vec<i32>,
    /// Factorisation scratch: `L⁻¹ Pᵀ W_k`, `L⁻¹ Pᵀ E_L`, `M = E_Lᵀ Ã⁻¹ E_L` (`l × l`),
    /// `E_Lᵀ Ã⁻¹ W_k` (`l × m`) and `C M` (`n × l`).
    pub(super) g_w: Vec<f64>,
    pub(super) g_l: Vec<f64>,
    /// The blocked Bunch–Kaufman's panel scratch, for the largest block or border.
    pub(super) bk_work: Vec<f64>,
    pub(super) m_link: Vec<f64>,
    pub(super) y_link: Vec<f64>,
    pub(super) cm: Vec<f64>,
    /// Solve scratch: block parts and border part of one right-hand side, and `Cᵀ x` (the
    /// backward pass) or `E_Lᵀ Ã⁻¹ t` (the forward pass).
    pub(super) work: Vec<f64>,
    pub(super) work_b: Vec<f64>,
    pub(super) ctx: Vec<f64>,
    /// The pattern (0-based) and the largest entry magnitude, for residuals.
    pub(super) rows: Vec<u32>,
    pub(super) cols: Vec<u32>,
    pub(super) k_max: f64,
    /// Refinement scratch: the right-hand side and the residual.
    pub(super) rhs: Vec<f64>,
    pub(super) res: Vec<f64>,
    /// The pivot groups (ordered by block), their members, neighbours, pivots, `Y`, fill
    /// destinations, and scratch (`B` while `G` is factored; `G⁻¹ b_g` in a solve).
    pub(super) groups: Vec<Group>,
    pub(super) g_members: Vec<usize>,
    pub(super) g_nbrs: Vec<usize>,
    pub(super) g_piv: Vec<i32>,
    pub(super) g_y: Vec<f64>,
    pub(super) g_fill: Vec<usize>,
    pub(super) g_b: Vec<f64>,
    pub(super) g_work: Vec<f64>,
    /// `G⁻¹` of each group (`q × q` at `q · first`... see [`Group::inv_off`]).
    pub(super) g_inv: Vec<f64>,
    /// Of each group, the positions of its neighbours whose column of `B` has a nonzero
    /// (`g_nz[n_first..n_first + g_nz_len[g]]`): the others add nothing.
    pub(super) g_nz: Vec<usize>,
    pub(super) g_nz_len: Vec<usize>,
    /// The surplus test's set-up (see [`Workspace::surplus`]) for the KKT whose
    /// multipliers are the indices from `first_dual` on (`usize::MAX`: none yet): whether
    /// the pattern is a KKT's there (no entry couples two multipliers), each block's
    /// multipliers, its groups' multipliers, the rank its groups' elimination may add to
    /// the multipliers' diagonal block (`fill_rank_any`; `fill_rank_zero` when every
    /// multiplier's diagonal is zero, so that a square group adds none), the border's
    /// multipliers, and where the multipliers' diagonal entries are in the input nonzeros.
    pub(super) first_dual: usize,
    pub(super) kkt_shaped: bool,
    pub(super) block_duals: Vec<usize>,
    pub(super) group_duals: Vec<usize>,
    pub(super) fill_rank_any: Vec<usize>,
    pub(super) fill_rank_zero: Vec<usize>,
    pub(super) border_duals: usize,
    pub(super) dual_diag: Vec<usize>,
    /// Scratch for `M`'s inertia: a copy of it and its pivots.
    pub(super) m_copy: Vec<f64>,
    pub(super) m_piv: Vec<i32>,
}

impl Workspace {
    /// Whether it was built for the pattern `(ia, ja)` (1-based) of order `dim`: the
    /// pattern it keeps for the refinement residual, compared entry by entry.
    pub(super) fn same_pattern(&self, dim: usize, ia: &[Index], ja: &[Index]) -> bool {
        let same = |kept: &[u32], given: &[Index]| {
            kept.len() == given.len()
                && kept
                    .iter()
                    .zip(given)
                    .all(|(&k, &g)| i64::from(k) + 1 == i64::from(g))
        };
        self.res.len() == dim && same(&self.rows, ia) && same(&self.cols, ja)
    }

    /// About the bytes its buffers hold (the pool's budget).
    pub(super) fn bytes(&self) -> usize {
        let f64s = [
            &self.dense,
            &self.y,
            &self.z,
            &self.g_w,
            &self.g_l,
            &self.bk_work,
            &self.m_link,
            &self.y_link,
            &self.cm,
            &self.work,
            &self.work_b,
            &self.ctx,
            &self.rhs,
            &self.res,
            &self.g_y,
            &self.g_b,
            &self.g_work,
            &self.g_inv,
            &self.m_copy,
        ]
        .iter()
        .map(|v| v.capacity())
        .sum::<usize>();
        let words = [
            &self.dest,
            &self.owner_start,
            &self.members,
            &self.g_fill,
            &self.g_members,
            &self.g_nbrs,
            &self.g_nz,
        ]
        .iter()
        .map(|v| v.capacity())
        .sum::<usize>();
        let halves = self.by_owner.capacity() + self.rows.capacity() + self.cols.capacity();
        8 * (f64s + words) + 4 * halves
    }
}
