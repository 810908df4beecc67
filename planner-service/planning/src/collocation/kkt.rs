//! A KKT linear solver for the solver (pounce) that exploits the LGR collocation
//! structure: block elimination over the mesh intervals with dense Bunch–Kaufman
//! factorisations ([`super::bunch_kaufman`]), in place of the general sparse
//! factorisation (FERAL).
//!
//! The KKT indices are split into one block per mesh interval (that interval's states
//! after its first point — so its end point, the next interval's first — its controls and
//! its defect multipliers) and a small border (the phase end times, the phase-order rows
//! with their slacks, the rendezvous rows). Block `k` couples only to the border and to
//! block `k - 1` (its defects read the previous interval's end point): a block-tridiagonal
//! matrix with a border. Per factorisation, in block order (`Ã_00 = A_00`, `W̃_0 = W_0`),
//!
//! ```text
//!   Ã_kk = P L D Lᵀ Pᵀ                       (dense Bunch–Kaufman, per block)
//!   Y_k  = Ã_kk⁻¹ W̃_k                         (its border columns)
//!   S   -= W̃_kᵀ Y_k                           (dense border Schur complement)
//!   Ã_k+1 = A_k+1 − C_k+1 Ã_kk⁻¹ C_k+1ᵀ       (C: block k+1's rows, block k's columns)
//!   W̃_k+1 = W_k+1 − C_k+1 Y_k
//!   inertia(K) = Σ_k inertia(Ã_kk) + inertia(S)   (Haynsworth)
//! ```
//!
//! where `C_k+1` touches only the few columns of block `k`'s end point, so the chain
//! terms are small. A solve runs forward through the blocks, solves the border, and runs
//! back. Nothing allocates after
//! [`SparseSymLinearSolverInterface::initialize_structure`]. A partition without chain
//! couplings (every `C` empty) is the plain arrowhead.
//!
//! **Never a silent mislabel.** The labels come from the [`Transcription`] (see
//! [`KktLabels::of`]) and are checked against the assembled pattern: a dimension that
//! differs, or any entry coupling two blocks that are not neighbours, sends every
//! factorisation of that matrix to
//! an inner [`FeralSolverInterface`] built with the configuration pounce's default backend
//! would use, so the solve behaves as it does without this module. Block elimination is
//! exact for any partition that passes the check; the labels only decide its speed.
//!
//! **Pivot floor.** A factorisation whose smallest pivot (over every block's `D` and
//! `S`'s) is below `dim · ε` — FERAL's own inertia-trust floor
//! (`pounce_feral::inertia_trust_floor`, on the unscaled matrix as the planner runs FERAL)
//! — is redone by FERAL, which then decides between `Success`, `WrongInertia` and
//! `Singular` as it does today. Above the floor the inertia is a measurement, so a
//! mismatch is `WrongInertia`, as FERAL would report it. This module itself never
//! reports `Singular`. A blocked elimination pivots only inside each block, so it is less
//! stable than a global pivot order: each solve is refined against the assembled matrix
//! until its backward error is at rounding level (at most two steps). When pounce's own
//! refinement stalls and it calls
//! [`SparseSymLinearSolverInterface::increase_quality`], the answer is FERAL's (the
//! planner's FERAL declines, and pounce perturbs); if FERAL escalates, it also takes over
//! the rest of the solve.

use pounce_feral::{FeralConfig, FeralSolverInterface};
use pounce_linsol::FactorPattern;
use pounce_linsol::{EMatrixFormat, ESymSolverStatus, SparseSymLinearSolverInterface};
use pounce_rs::{Index, Number};

use super::bunch_kaufman;
use super::transcription::Transcription;

mod pool;
pub use pool::{clear_workspace_pool, workspace_reuses_total};

/// Which linear solver factors the KKT systems of the NLP solves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KktSolver {
    /// FERAL, pounce's general sparse `LDLᵀ`.
    Feral,
    /// Block elimination over the mesh intervals ([`StructuredKkt`]), FERAL where the
    /// structure does not hold.
    Structured,
}

/// Bound magnitude pounce reads as "no bound" (`nlp_lower_bound_inf` / `_upper_`).
const POUNCE_INF: f64 = 1e19;

/// Largest block the dense path takes.
const MAX_BLOCK: usize = 600;

/// Largest border the dense path takes: the dense border factorisation grows as its
/// cube. With the interval ends in the blocks the collocation's borders hold only the
/// phase times and the phase-order and rendezvous rows (at most `3 · phases + 3` indices,
/// `tests/kkt.rs`); when the interval
/// ends were in the border (74-152 in 2-D, 200-430 in 3-D), the 3-D ones planned no
/// faster than FERAL.
const MAX_BORDER: usize = 160;

/// Factorisations done by block elimination, over the process (diagnostics and tests).
static BLOCK_FACTORIZATIONS: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

/// Factorisations of labelled matrices that block elimination handed to FERAL (a pivot
/// under the floor, a non-finite entry), over the process.
static FERAL_FALLBACKS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Factorisations block elimination stopped early on a certain surplus of negative
/// eigenvalues (see [`Workspace::surplus`]), over the process.
static SURPLUS_STOPS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// How many factorisations block elimination stopped early on a surplus of negative
/// eigenvalues in this process (included in [`block_factorizations_total`]).
pub fn surplus_stops_total() -> usize {
    SURPLUS_STOPS.load(std::sync::atomic::Ordering::Relaxed)
}

/// How many KKT factorisations block elimination has done in this process.
pub fn block_factorizations_total() -> usize {
    BLOCK_FACTORIZATIONS.load(std::sync::atomic::Ordering::Relaxed)
}

/// Factorisations by block elimination without the pivot groups (their pivots refused),
/// over the process.
static PLAIN_FACTORIZATIONS: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

/// How many factorisations block elimination did without the pivot groups in this
/// process (included in [`block_factorizations_total`]).
pub fn plain_factorizations_total() -> usize {
    PLAIN_FACTORIZATIONS.load(std::sync::atomic::Ordering::Relaxed)
}

/// How many factorisations of matrices the labels fit went to FERAL in this process.
pub fn feral_fallbacks_total() -> usize {
    FERAL_FALLBACKS.load(std::sync::atomic::Ordering::Relaxed)
}

/// Most refinement steps per solve, and the backward error that stops them.
const REFINE_STEPS: usize = 2;
const REFINE_TOL: f64 = 1e-14;

/// Block label of every KKT index (`< 0`: border), in pounce's KKT order
/// `[x not fixed | slacks | equality duals | inequality duals]`, and the pivot groups.
///
/// A pivot group is eliminated before the chain with its own small dense pivot: one
/// collocation node's controls with the defect rows of the states they drive (the control
/// rates: `psi` in 2-D, `Nz` and `mu` in 3-D). Its pivot `[[H_uu, J_uᵀ], [J_u, 0]]` is
/// nonsingular whenever the controls drive those rates (`J_u` is the interval's half
/// length), and taking the group out of its block shrinks the block's dense factorisation
/// (96 → 72 indices in 3-D, 42 → 30 in 2-D on the working mesh).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KktLabels {
    /// Block of every KKT index (`< 0`: border).
    pub blocks: Vec<i32>,
    /// Pivot group of every KKT index (`< 0`: none); empty: no groups.
    pub groups: Vec<i32>,
}

impl KktLabels {
    /// Labels with blocks only.
    pub fn plain(blocks: Vec<i32>) -> KktLabels {
        KktLabels {
            blocks,
            groups: Vec::new(),
        }
    }

    /// The labels of `tr`'s KKT: block `i` is mesh interval `i`; group `k` collocation node
    /// `k`'s controls and driven defect rows. Mirrors pounce's bound classification
    /// (`pounce_nlp::tnlp_adapter`): a variable with equal finite bounds is fixed and
    /// leaves the KKT; a constraint with equal finite bounds is an equality, any other an
    /// inequality with a slack.
    pub fn of(tr: &Transcription) -> KktLabels {
        let (nx, nu) = (tr.nx, tr.nu);
        let n_pts = tr.layout.lgr.len();
        let n_ctrl = tr.layout.control_nodes();
        let mut var = vec![-1i32; tr.n_vars()];
        for (k, node) in tr.layout.nodes.iter().enumerate() {
            let interval = (k / n_pts) as i32;
            // An interval's first point ends the previous interval (node 0 has none).
            let owner = if node.local == 0 {
                (interval - 1).max(0)
            } else {
                interval
            };
            for c in 0..nx {
                var[tr.state(k, c)] = owner;
            }
            for e in 0..nu {
                var[tr.control(k, e)] = interval;
            }
        }
        // The final node ends the last interval.
        let last = tr.layout.nodes.len();
        for c in 0..nx {
            var[tr.state(last, c)] = (last / n_pts) as i32 - 1;
        }
        let mut con = vec![-1i32; tr.n_cons()];
        for k in 0..n_ctrl {
            for c in 0..nx {
                con[k * nx + c] = (k / n_pts) as i32;
            }
        }
        let present = |lo: f64, hi: f64| lo > -POUNCE_INF && hi < POUNCE_INF;
        let fixed = |i: usize| present(tr.x_lo[i], tr.x_hi[i]) && tr.x_lo[i] == tr.x_hi[i];
        let equality: Vec<bool> = (0..tr.n_cons())
            .map(|r| present(tr.g_lo[r], tr.g_hi[r]) && tr.g_lo[r] == tr.g_hi[r])
            .collect();
        // A node's group: its controls (all free) and its driven defect rows (equalities).
        let driven = tr.vehicle.driven_states();
        let mut var_group = vec![-1i32; tr.n_vars()];
        let mut con_group = vec![-1i32; tr.n_cons()];
        for k in 0..n_ctrl {
            let controls_free = (0..nu).all(|e| !fixed(tr.control(k, e)));
            let rows_equal = driven.iter().all(|&c| equality[k * nx + c]);
            if driven.len() == nu && controls_free && rows_equal {
                for e in 0..nu {
                    var_group[tr.control(k, e)] = k as i32;
                }
                for &c in driven {
                    con_group[k * nx + c] = k as i32;
                }
            }
        }
        let (mut blocks, mut groups) = (Vec::new(), Vec::new());
        for (i, &l) in var.iter().enumerate() {
            if !fixed(i) {
                blocks.push(l);
                groups.push(var_group[i]);
            }
        }
        let inequalities = || (0..tr.n_cons()).filter(|&r| !equality[r]);
        for r in inequalities() {
            blocks.push(con[r]);
            groups.push(-1);
        }
        for r in (0..tr.n_cons()).filter(|&r| equality[r]) {
            blocks.push(con[r]);
            groups.push(con_group[r]);
        }
        for r in inequalities() {
            blocks.push(con[r]);
            groups.push(-1);
        }
        KktLabels { blocks, groups }
    }
}

/// One block's place in the workspace.
#[derive(Debug, Clone, Copy, Default)]
struct Block {
    /// Order of `A_kk`.
    n: usize,
    /// Its KKT indices are `members[first..first + n]` (also its offset in `work`/`piv`).
    first: usize,
    /// Offset of `A_kk` (`n × n`) in `dense`.
    a_off: usize,
    /// Border columns of `W_k` (the original ones and the fill from the previous block):
    /// `border_cols[b_first..b_first + m]` (border-local, increasing); `W_k` (`n × m`) at
    /// `w_off` in the `W` part of `dense`, `V_k = D⁻¹ L⁻¹ Pᵀ W_k` (with `Ã_kk = P L D Lᵀ
    /// Pᵀ`) at `y_off` in `y`.
    m: usize,
    b_first: usize,
    w_off: usize,
    y_off: usize,
    /// Link to the previous block: its local indices `links[l_first..l_first + l]`
    /// (increasing) that this block touches; `C_k` (`n × l`, this block's rows, those
    /// columns) at `c_off` in the `C` part of `dense`, `D⁻¹ L⁻¹ Pᵀ E_L` of block `k - 1`'s
    /// factors (`n_{k-1} × l`) at `z_off` in `z`.
    l: usize,
    l_first: usize,
    c_off: usize,
    z_off: usize,
    /// Its pivot groups `groups[g_first..g_first + g_count]`, whose `G` and `B` fill
    /// `dense[gs_off..gs_off + gs_len]`.
    g_first: usize,
    g_count: usize,
    gs_off: usize,
    gs_len: usize,
}

/// One pivot group's place in the workspace: eliminated before the chain, with its own
/// dense pivot `G` (`q × q`) and its couplings `B` (`q × nn`) to its neighbours (KKT
/// indices outside it, in blocks or the border).
#[derive(Debug, Clone, Copy, Default)]
struct Group {
    /// Its KKT indices are `g_members[first..first + q]` (also its offset in `g_piv` and
    /// `g_work`).
    q: usize,
    first: usize,
    /// Its neighbours `g_nbrs[n_first..n_first + nn]` (increasing).
    nn: usize,
    n_first: usize,
    /// `G` (column-major, lower triangle) at `g_off` in `dense`, `B` (column `j`:
    /// neighbour `j`) right after it.
    g_off: usize,
    /// `Y = G⁻¹ B` at `y_off` in `g_y`; `G⁻¹` at `inv_off` in `g_inv`.
    y_off: usize,
    inv_off: usize,
    /// Where `B_iᵀ Y_j` is subtracted, for neighbours `j ≤ i`, column by column:
    /// `g_fill[f_first..f_first + nn (nn + 1) / 2]`.
    f_first: usize,
}

/// Every buffer of the structured path, sized in `initialize_structure`.
#[derive(Debug, Default)]
struct Workspace {
    /// Destination in `dense` of each input nonzero.
    dest: Vec<usize>,
    /// The input nonzeros grouped by the block whose `A`, `C` or `W` they land in (the
    /// border's `S` last): group `b` is `by_owner[owner_start[b]..owner_start[b + 1]]`.
    by_owner: Vec<u32>,
    owner_start: Vec<usize>,
    blocks: Vec<Block>,
    members: Vec<usize>,
    border_cols: Vec<usize>,
    links: Vec<usize>,
    /// Position in the previous block's `border_cols` of each of a block's border columns
    /// (`usize::MAX`: not there), aligned with `border_cols`.
    prev_col: Vec<usize>,
    /// KKT index of each border position.
    border: Vec<usize>,
    /// All `A_kk`, then all `C_k`, then all `W_k`, then `S` (`nb × nb`), column-major.
    dense: Vec<f64>,
    c_base: usize,
    w_base: usize,
    s_off: usize,
    y: Vec<f64>,
    z: Vec<f64>,
    /// Pivots: the blocks' at their `first`, `S`'s after them.
    piv: Vec<i32>,
    /// Factorisation scratch: `L⁻¹ Pᵀ W_k`, `L⁻¹ Pᵀ E_L`, `M = E_Lᵀ Ã⁻¹ E_L` (`l × l`),
    /// `E_Lᵀ Ã⁻¹ W_k` (`l × m`) and `C M` (`n × l`).
    g_w: Vec<f64>,
    g_l: Vec<f64>,
    /// The blocked Bunch–Kaufman's panel scratch, for the largest block or border.
    bk_work: Vec<f64>,
    m_link: Vec<f64>,
    y_link: Vec<f64>,
    cm: Vec<f64>,
    /// Solve scratch: block parts and border part of one right-hand side, and `Cᵀ x` (the
    /// backward pass) or `E_Lᵀ Ã⁻¹ t` (the forward pass).
    work: Vec<f64>,
    work_b: Vec<f64>,
    ctx: Vec<f64>,
    /// The pattern (0-based) and the largest entry magnitude, for residuals.
    rows: Vec<u32>,
    cols: Vec<u32>,
    k_max: f64,
    /// Refinement scratch: the right-hand side and the residual.
    rhs: Vec<f64>,
    res: Vec<f64>,
    /// The pivot groups (ordered by block), their members, neighbours, pivots, `Y`, fill
    /// destinations, and scratch (`B` while `G` is factored; `G⁻¹ b_g` in a solve).
    groups: Vec<Group>,
    g_members: Vec<usize>,
    g_nbrs: Vec<usize>,
    g_piv: Vec<i32>,
    g_y: Vec<f64>,
    g_fill: Vec<usize>,
    g_b: Vec<f64>,
    g_work: Vec<f64>,
    /// `G⁻¹` of each group (`q × q` at `q · first`... see [`Group::inv_off`]).
    g_inv: Vec<f64>,
    /// Of each group, the positions of its neighbours whose column of `B` has a nonzero
    /// (`g_nz[n_first..n_first + g_nz_len[g]]`): the others add nothing.
    g_nz: Vec<usize>,
    g_nz_len: Vec<usize>,
    /// The surplus test's set-up (see [`Workspace::surplus`]) for the KKT whose
    /// multipliers are the indices from `first_dual` on (`usize::MAX`: none yet): whether
    /// the pattern is a KKT's there (no entry couples two multipliers), each block's
    /// multipliers, its groups' multipliers, the rank its groups' elimination may add to
    /// the multipliers' diagonal block (`fill_rank_any`; `fill_rank_zero` when every
    /// multiplier's diagonal is zero, so that a square group adds none), the border's
    /// multipliers, and where the multipliers' diagonal entries are in the input nonzeros.
    first_dual: usize,
    kkt_shaped: bool,
    block_duals: Vec<usize>,
    group_duals: Vec<usize>,
    fill_rank_any: Vec<usize>,
    fill_rank_zero: Vec<usize>,
    border_duals: usize,
    dual_diag: Vec<usize>,
    /// Scratch for `M`'s inertia: a copy of it and its pivots.
    m_copy: Vec<f64>,
    m_piv: Vec<i32>,
}

/// What a factorisation found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Count {
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
fn clear_lower(a: &mut [f64], n: usize) {
    if n == 0 {
        return;
    }
    for (j, col) in a.chunks_exact_mut(n).enumerate() {
        col[j..].fill(0.0);
    }
}

/// Largest multiplier `|G⁻¹ B|` a pivot group may have: a larger one would amplify
/// rounding beyond what the refinement recovers, so FERAL factors that matrix instead.
const GROUP_GROWTH_MAX: f64 = 1e6;

impl Workspace {
    /// Whether it was built for the pattern `(ia, ja)` (1-based) of order `dim`: the
    /// pattern it keeps for the refinement residual, compared entry by entry.
    fn same_pattern(&self, dim: usize, ia: &[Index], ja: &[Index]) -> bool {
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
    fn bytes(&self) -> usize {
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

    /// The workspace for the pattern `(ia, ja)` (1-based) under the block `labels` and
    /// the pivot `groups` (empty: none), or `None` when they do not describe it (an entry
    /// coupling two blocks that are not neighbours in label order, or two groups; a group
    /// across blocks or in the border; a block or border too large).
    fn new(
        dim: usize,
        ia: &[Index],
        ja: &[Index],
        labels: &[i32],
        groups: &[i32],
    ) -> Option<Workspace> {
        if labels.len() != dim || ia.len() != ja.len() {
            return None;
        }
        if !groups.is_empty() && groups.len() != dim {
            return None;
        }
        let in_group = |i: usize| groups.get(i).is_some_and(|&g| g >= 0);
        // Compact group ids (in label order) and block ids (keeping the label order, the
        // chain's order) of the indices outside the groups.
        let g_max = groups.iter().copied().max().unwrap_or(-1);
        let mut g_remap = vec![usize::MAX; (g_max + 1).max(0) as usize];
        let mut g_count = 0;
        for &g in groups.iter().filter(|&&g| g >= 0) {
            if g_remap[g as usize] == usize::MAX {
                g_remap[g as usize] = g_count;
                g_count += 1;
            }
        }
        let max = labels.iter().copied().max().unwrap_or(-1);
        if max < 0 {
            return None;
        }
        let mut present = vec![false; max as usize + 1];
        for (i, &l) in labels.iter().enumerate() {
            if l >= 0 && !in_group(i) {
                present[l as usize] = true;
            }
        }
        let mut remap = vec![usize::MAX; present.len()];
        let mut count = 0;
        for (slot, &p) in remap.iter_mut().zip(&present) {
            if p {
                *slot = count;
                count += 1;
            }
        }
        let mut block_of = vec![usize::MAX; dim];
        let mut group_of = vec![usize::MAX; dim];
        let mut local = vec![0usize; dim];
        let mut sizes = vec![0usize; count];
        let mut border = Vec::new();
        let mut g_block = vec![usize::MAX; g_count];
        let mut g_members: Vec<Vec<usize>> = vec![Vec::new(); g_count];
        for (i, &l) in labels.iter().enumerate() {
            if in_group(i) {
                // A group lies inside one block (it is eliminated with that block).
                let g = g_remap[groups[i] as usize];
                let b = if l >= 0 {
                    remap[l as usize]
                } else {
                    usize::MAX
                };
                if b == usize::MAX || (g_block[g] != usize::MAX && g_block[g] != b) {
                    return None;
                }
                g_block[g] = b;
                group_of[i] = g;
                local[i] = g_members[g].len();
                g_members[g].push(i);
            } else if l < 0 {
                local[i] = border.len();
                border.push(i);
            } else {
                let b = remap[l as usize];
                block_of[i] = b;
                local[i] = sizes[b];
                sizes[b] += 1;
            }
        }
        let nb = border.len();
        if nb > MAX_BORDER || sizes.iter().any(|&s| s > MAX_BLOCK) {
            return None;
        }
        // Border columns and links per block, from the pattern and from the groups' fill
        // (every pair of a group's neighbours); each group's neighbours.
        let mut touches: Vec<Vec<usize>> = vec![Vec::new(); count];
        let mut linked: Vec<Vec<usize>> = vec![Vec::new(); count];
        let mut nbrs: Vec<Vec<usize>> = vec![Vec::new(); g_count];
        let mut record = |r: usize, c: usize| -> Option<()> {
            match (block_of[r], block_of[c]) {
                (usize::MAX, usize::MAX) => {}
                (usize::MAX, b) => touches[b].push(local[r]),
                (b, usize::MAX) => touches[b].push(local[c]),
                (br, bc) if br == bc + 1 => linked[br].push(local[c]),
                (br, bc) if bc == br + 1 => linked[bc].push(local[r]),
                (br, bc) if br != bc => return None,
                _ => {}
            }
            Some(())
        };
        for (&r, &c) in ia.iter().zip(ja) {
            let (r, c) = (r as usize, c as usize);
            if r == 0 || c == 0 || r > dim || c > dim {
                return None;
            }
            let (r, c) = (r - 1, c - 1);
            match (group_of[r], group_of[c]) {
                (usize::MAX, usize::MAX) => record(r, c)?,
                (gr, gc) if gr == gc => {}
                (usize::MAX, g) => nbrs[g].push(r),
                (g, usize::MAX) => nbrs[g].push(c),
                _ => return None,
            }
        }
        for list in &mut nbrs {
            list.sort_unstable();
            list.dedup();
            for i in 0..list.len() {
                for j in 0..=i {
                    record(list[i], list[j])?;
                }
            }
        }
        // A block linked to its predecessor inherits its border columns (fill).
        for b in 0..count {
            linked[b].sort_unstable();
            linked[b].dedup();
            if b > 0 && !linked[b].is_empty() {
                let inherited = touches[b - 1].clone();
                touches[b].extend(inherited);
            }
            touches[b].sort_unstable();
            touches[b].dedup();
        }
        let mut ws = Workspace {
            border,
            ..Workspace::default()
        };
        // The groups ordered by block (then by id), and each block's share of them.
        let mut g_order: Vec<usize> = (0..g_count).collect();
        g_order.sort_by_key(|&g| (g_block[g], g));
        let mut g_first_of = vec![0usize; count + 1];
        for &g in &g_order {
            g_first_of[g_block[g] + 1] += 1;
        }
        for b in 0..count {
            g_first_of[b + 1] += g_first_of[b];
        }
        let (mut first, mut a_len, mut c_len, mut w_len, mut z_len) = (0, 0, 0, 0, 0);
        let (mut max_l, mut max_nl, mut max_nm, mut max_zl, mut max_m) = (0, 0, 0, 0, 0);
        for b in 0..count {
            let (n, m, l) = (sizes[b], touches[b].len(), linked[b].len());
            ws.blocks.push(Block {
                n,
                first,
                a_off: a_len,
                m,
                b_first: ws.border_cols.len(),
                w_off: w_len,
                y_off: w_len,
                l,
                l_first: ws.links.len(),
                c_off: c_len,
                z_off: z_len,
                g_first: g_first_of[b],
                g_count: g_first_of[b + 1] - g_first_of[b],
                gs_off: 0,
                gs_len: 0,
            });
            for &col in &touches[b] {
                let prev = if b > 0 && l > 0 {
                    touches[b - 1].binary_search(&col).unwrap_or(usize::MAX)
                } else {
                    usize::MAX
                };
                ws.prev_col.push(prev);
            }
            ws.border_cols.extend_from_slice(&touches[b]);
            ws.links.extend_from_slice(&linked[b]);
            first += n;
            a_len += n * n;
            c_len += n * l;
            w_len += n * m;
            if l > 0 {
                z_len += sizes[b - 1] * l;
                max_zl = max_zl.max(sizes[b - 1] * l);
            }
            max_l = max_l.max(l);
            max_m = max_m.max(m);
            max_nl = max_nl.max(n * l);
            max_nm = max_nm.max(n * m);
        }
        ws.c_base = a_len;
        ws.w_base = a_len + c_len;
        ws.members = vec![0; first];
        let mut fill: Vec<usize> = ws.blocks.iter().map(|b| b.first).collect();
        for (i, &b) in block_of.iter().enumerate() {
            if b != usize::MAX {
                ws.members[fill[b]] = i;
                fill[b] += 1;
            }
        }
        ws.s_off = a_len + c_len + w_len;
        // The groups' `G` and `B` after `S`, block by block.
        let mut g_at = ws.s_off + nb * nb;
        let (mut y_len, mut max_qn, mut largest_q, mut inv_len) = (0, 0, 0, 0);
        let mut g_index = vec![0usize; g_count];
        for (b, blk) in ws.blocks.iter_mut().enumerate() {
            blk.gs_off = g_at;
            for &g in &g_order[g_first_of[b]..g_first_of[b + 1]] {
                let (q, nn) = (g_members[g].len(), nbrs[g].len());
                g_index[g] = ws.groups.len();
                ws.groups.push(Group {
                    q,
                    first: ws.g_members.len(),
                    nn,
                    n_first: ws.g_nbrs.len(),
                    g_off: g_at,
                    y_off: y_len,
                    inv_off: inv_len,
                    f_first: 0,
                });
                inv_len += q * q;
                ws.g_members.extend_from_slice(&g_members[g]);
                ws.g_nbrs.extend_from_slice(&nbrs[g]);
                g_at += q * q + q * nn;
                y_len += q * nn;
                max_qn = max_qn.max(q * nn);
                largest_q = largest_q.max(q);
            }
            blk.gs_len = g_at - blk.gs_off;
        }
        ws.dense = vec![0.0; g_at];
        ws.y = vec![0.0; w_len];
        ws.z = vec![0.0; z_len];
        ws.piv = vec![0; first + nb];
        ws.g_w = vec![0.0; max_nm];
        let largest = ws.blocks.iter().map(|b| b.n).max().unwrap_or(0);
        let largest = largest.max(nb).max(largest_q);
        ws.bk_work = vec![0.0; bunch_kaufman::work_len(largest)];
        ws.g_l = vec![0.0; max_zl];
        ws.m_link = vec![0.0; max_l * max_l];
        ws.y_link = vec![0.0; max_l * max_m];
        ws.cm = vec![0.0; max_nl];
        ws.work = vec![0.0; first];
        ws.work_b = vec![0.0; nb];
        ws.ctx = vec![0.0; max_l];
        ws.rhs = vec![0.0; dim];
        ws.res = vec![0.0; dim];
        ws.g_piv = vec![0; ws.g_members.len()];
        ws.g_y = vec![0.0; y_len];
        ws.g_b = vec![0.0; max_qn];
        ws.g_work = vec![0.0; ws.g_members.len()];
        ws.g_inv = vec![0.0; inv_len];
        ws.g_nz = vec![0; ws.g_nbrs.len()];
        ws.g_nz_len = vec![0; ws.groups.len()];
        ws.first_dual = usize::MAX;
        ws.block_duals = vec![0; count];
        ws.group_duals = vec![0; count];
        ws.fill_rank_any = vec![0; count];
        ws.fill_rank_zero = vec![0; count];
        ws.m_copy = vec![0.0; max_l * max_l];
        ws.m_piv = vec![0; max_l];
        ws.rows = ia.iter().map(|&r| (r - 1) as u32).collect();
        ws.cols = ja.iter().map(|&c| (c - 1) as u32).collect();
        // Where an entry (r, c) outside the groups goes (lower triangle of each symmetric
        // dense matrix), and which block takes it (its `A`, `C` or `W`; `count`: `S`).
        let slot = |ws: &Workspace, r: usize, c: usize| -> Option<(usize, usize)> {
            Some(match (block_of[r], block_of[c]) {
                (usize::MAX, usize::MAX) => {
                    let (i, j) = (local[r].max(local[c]), local[r].min(local[c]));
                    (ws.s_off + i + j * nb, count)
                }
                (usize::MAX, b) | (b, usize::MAX) => {
                    let (row, bcol) = if block_of[r] == b {
                        (local[r], local[c])
                    } else {
                        (local[c], local[r])
                    };
                    let blk = ws.blocks[b];
                    let cols = &ws.border_cols[blk.b_first..blk.b_first + blk.m];
                    let j = cols.binary_search(&bcol).ok()?;
                    (ws.w_base + blk.w_off + row + j * blk.n, b)
                }
                (br, bc) if br != bc => {
                    let (hi, row, prev) = if br > bc {
                        (br, local[r], local[c])
                    } else {
                        (bc, local[c], local[r])
                    };
                    let blk = ws.blocks[hi];
                    let links = &ws.links[blk.l_first..blk.l_first + blk.l];
                    let j = links.binary_search(&prev).ok()?;
                    (ws.c_base + blk.c_off + row + j * blk.n, hi)
                }
                (b, _) => {
                    let blk = ws.blocks[b];
                    let (i, j) = (local[r].max(local[c]), local[r].min(local[c]));
                    (blk.a_off + i + j * blk.n, b)
                }
            })
        };
        // The groups' fill destinations.
        for gi in 0..ws.groups.len() {
            let g = ws.groups[gi];
            ws.groups[gi].f_first = ws.g_fill.len();
            for j in 0..g.nn {
                for i in j..g.nn {
                    let (r, c) = (ws.g_nbrs[g.n_first + i], ws.g_nbrs[g.n_first + j]);
                    let (d, _) = slot(&ws, r, c)?;
                    ws.g_fill.push(d);
                }
            }
        }
        ws.dest = Vec::with_capacity(ia.len());
        let mut owners = Vec::with_capacity(ia.len());
        for (&r, &c) in ia.iter().zip(ja) {
            let (r, c) = (r as usize - 1, c as usize - 1);
            let (d, owner) = match (group_of[r], group_of[c]) {
                (usize::MAX, usize::MAX) => slot(&ws, r, c)?,
                (gr, gc) if gr == gc => {
                    let g = ws.groups[g_index[gr]];
                    let (i, j) = (local[r].max(local[c]), local[r].min(local[c]));
                    (g.g_off + i + j * g.q, g_block[gr])
                }
                (usize::MAX, gc) | (gc, usize::MAX) => {
                    let (member, other) = if group_of[r] == gc { (r, c) } else { (c, r) };
                    let g = ws.groups[g_index[gc]];
                    let list = &ws.g_nbrs[g.n_first..g.n_first + g.nn];
                    let j = list.binary_search(&other).ok()?;
                    (g.g_off + g.q * g.q + local[member] + j * g.q, g_block[gc])
                }
                _ => return None,
            };
            ws.dest.push(d);
            owners.push(owner);
        }
        // Group the nonzeros by the block that takes them (the border last), so that each
        // block is assembled just before it is needed, while it is in cache.
        ws.owner_start = vec![0; count + 2];
        for &o in &owners {
            ws.owner_start[o + 1] += 1;
        }
        for b in 0..=count {
            ws.owner_start[b + 1] += ws.owner_start[b];
        }
        ws.by_owner = vec![0; owners.len()];
        let mut fill = ws.owner_start.clone();
        for (i, &o) in owners.iter().enumerate() {
            ws.by_owner[fill[o]] = i as u32;
            fill[o] += 1;
        }
        // What the unchecked loops of `assemble`, `eliminate_groups` and `solve_refined`
        // rely on: every destination (of a nonzero, of a group's fill) inside `dense`,
        // every pattern index (checked above) below `dim`.
        if ws
            .dest
            .iter()
            .chain(&ws.g_fill)
            .any(|&d| d >= ws.dense.len())
            || ws.rows.iter().chain(&ws.cols).any(|&i| i as usize >= dim)
            || ws.res.len() != dim
        {
            return None;
        }
        Some(ws)
    }

    /// Sets the surplus test up for a KKT whose multipliers are the indices from
    /// `first_dual` on (nothing to do when it already is). The test needs the KKT's shape:
    /// no entry of the pattern couples two multipliers (`kkt_shaped`).
    fn prepare_surplus(&mut self, first_dual: usize) {
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
    fn surplus(
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

    /// Assembles group `owner` (a block's `A`, `C` and `W`, or with `owner` = the block
    /// count the border's `S`) from `values`; `None` on a non-finite entry.
    fn assemble(&mut self, owner: usize, values: &[f64]) -> Option<()> {
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

    /// Eliminates block `b`'s pivot groups (assembled): factors each `G`, forms
    /// `Y = G⁻¹ B` and subtracts `Bᵀ Y` from the neighbours' entries. `None`: a pivot under
    /// `floor` or a multiplier above [`GROUP_GROWTH_MAX`]; otherwise the groups' number of
    /// negative eigenvalues.
    fn eliminate_groups(&mut self, b: usize, floor: f64) -> Option<usize> {
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

    /// Factorises the matrix with nonzeros `values`. `None`: a non-finite entry, a pivot
    /// under `floor` or a zero pivot column; otherwise the number of negative eigenvalues,
    /// or with `test` (the surplus test set up by [`Workspace::prepare_surplus`]) possibly
    /// [`Count::Surplus`], before the end.
    fn factor(&mut self, values: &[f64], floor: f64, test: bool) -> Option<Count> {
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
            let (a_all, rest) = self.dense.split_at_mut(self.c_base);
            let (c_all, rest) = rest.split_at_mut(self.w_base - self.c_base);
            let (w_all, s) = rest.split_at_mut(self.s_off - self.w_base);
            let blk = self.blocks[k];
            let next = self.blocks.get(k + 1).copied().unwrap_or_default();
            let (n, m, nn) = (blk.n, blk.m, next.n);
            // Ã_kk (already updated by the previous block) and Ã_{k+1}; W_k and W_{k+1}.
            let (a_lo, a_hi) = a_all.split_at_mut(blk.a_off + n * n);
            let a = &mut a_lo[blk.a_off..];
            let (w_lo, w_hi) = w_all.split_at_mut(blk.w_off + n * m);
            let w = &w_lo[blk.w_off..];
            let piv = &mut self.piv[blk.first..blk.first + n];
            negative += factor_above(&mut *a, n, piv, &mut self.bk_work, floor)?;
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
            // The next block, if linked: with G_L = L⁻¹ Pᵀ E_L and V_L = D⁻¹ G_L,
            // M = E_Lᵀ Ã_kk⁻¹ E_L = G_Lᵀ V_L and E_Lᵀ Ã_kk⁻¹ W_k = G_Lᵀ V;
            // Ã_{k+1} -= C M Cᵀ and W_{k+1} -= C E_Lᵀ Ã_kk⁻¹ W_k.
            let l = next.l;
            m_p += self.block_duals[k];
            if l == 0 {
                let base = m_p + self.border_duals + next_fill;
                if test && negative > base {
                    return Some(Count::Surplus);
                }
                continue;
            }
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
            let base = m_p + self.border_duals + next_fill;
            if test
                && Self::surplus(
                    negative,
                    base,
                    mm,
                    l,
                    &mut self.m_copy,
                    &mut self.m_piv,
                    &mut self.bk_work,
                )
            {
                return Some(Count::Surplus);
            }
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
            let a_next = &mut a_hi[next.a_off - blk.a_off - n * n..][..nn * nn];
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
            let w_next = &mut w_hi[next.w_off - blk.w_off - n * m..][..nn * next.m];
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
        if nb > 0 {
            let s = &mut self.dense[self.s_off..self.s_off + nb * nb];
            let piv = &mut self.piv[self.members.len()..];
            negative += factor_above(&mut *s, nb, piv, &mut self.bk_work, floor)?;
        }
        Some(Count::Negative(negative))
    }

    /// Solves `K x = b` in place (`b` in KKT order, `K` with nonzeros `values`), with up
    /// to [`REFINE_STEPS`] steps of iterative refinement until the backward error
    /// `‖b − K x‖∞ / (‖K‖max ‖x‖∞ + ‖b‖∞)` is below [`REFINE_TOL`] (the blocked elimination
    /// pivots only inside each block, so its first answer can be less accurate than a
    /// globally pivoted one).
    fn solve_refined(&mut self, values: &[f64], b: &mut [f64]) {
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
    fn solve(&mut self, b: &mut [f64]) {
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
    fn solve_chain(&mut self, b: &mut [f64]) {
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

/// Factorises the `n × n` matrix `a` in place ([`bunch_kaufman::factor`]); its number of
/// negative eigenvalues, or `None` when a pivot is under `floor` (or a column is zero).
fn factor_above(
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
fn half_solve(a: &[f64], n: usize, piv: &[i32], g: &mut [f64], v: &mut [f64], ncols: usize) {
    bunch_kaufman::forward_many(a, n, piv, g, ncols);
    v.copy_from_slice(g);
    bunch_kaufman::scale_by_d_inv(a, n, piv, v, ncols);
}

/// Who factored the current matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Factored {
    None,
    Blocks,
    /// Block elimination stopped on a certain surplus ([`Count::Surplus`]).
    Stopped,
    Feral,
}

/// The structured KKT backend (see the module documentation).
pub struct StructuredKkt {
    labels: Option<KktLabels>,
    feral: FeralSolverInterface,
    /// `None`: every factorisation goes to FERAL (the labels did not fit the pattern).
    ws: Option<Workspace>,
    /// The blocks with the groups inside them, for a matrix whose group pivots `ws`
    /// refuses (built when first needed), and whether it factored the current matrix.
    plain: Option<Workspace>,
    on_plain: bool,
    values: Vec<f64>,
    dim: usize,
    floor: f64,
    negevals: Index,
    factored: Factored,
    /// `increase_quality` handed the solve to FERAL; the next solve must refactor.
    switched: bool,
    /// Factorisations by the blocks and by FERAL (for tests and diagnostics).
    pub block_factorizations: usize,
    pub feral_factorizations: usize,
    /// Of `block_factorizations`, those stopped on a surplus of negative eigenvalues.
    pub surplus_stops: usize,
    /// Whether `ws` came from the pool (for tests and diagnostics).
    pub reused: bool,
}

impl StructuredKkt {
    /// A backend for KKTs labelled `labels` (`None`: FERAL for every matrix), falling back
    /// to FERAL configured with `feral`.
    pub fn new(labels: Option<KktLabels>, feral: FeralConfig) -> StructuredKkt {
        StructuredKkt {
            labels,
            feral: FeralSolverInterface::with_config(feral),
            ws: None,
            plain: None,
            on_plain: false,
            values: Vec::new(),
            dim: 0,
            floor: 0.0,
            negevals: 0,
            factored: Factored::None,
            switched: false,
            block_factorizations: 0,
            feral_factorizations: 0,
            surplus_stops: 0,
            reused: false,
        }
    }

    /// Returns the workspaces to the pool, for the next solve with the same pattern.
    fn release(&mut self) {
        let plain = self.plain.take();
        if let (Some(ws), Some(labels)) = (self.ws.take(), self.labels.as_ref()) {
            pool::give_back(pool::Pooled::new(labels.clone(), ws, plain));
        }
    }

    /// Whether the labels fit the pattern (block elimination is in use).
    pub fn is_structured(&self) -> bool {
        self.ws.is_some()
    }

    #[allow(clippy::too_many_arguments)]
    fn feral_solve(
        &mut self,
        new_matrix: bool,
        ia: &[Index],
        ja: &[Index],
        nrhs: Index,
        rhs: &mut [Number],
        check: bool,
        expected: Index,
    ) -> ESymSolverStatus {
        if new_matrix {
            self.feral.values_array_mut().copy_from_slice(&self.values);
            self.feral_factorizations += 1;
            self.factored = Factored::Feral;
        }
        let status = self
            .feral
            .multi_solve(new_matrix, ia, ja, nrhs, rhs, check, expected);
        self.negevals = self.feral.number_of_neg_evals();
        status
    }
}

impl Drop for StructuredKkt {
    fn drop(&mut self) {
        self.release();
    }
}

impl SparseSymLinearSolverInterface for StructuredKkt {
    fn initialize_structure(
        &mut self,
        dim: Index,
        nonzeros: Index,
        ia: &[Index],
        ja: &[Index],
    ) -> ESymSolverStatus {
        let status = self.feral.initialize_structure(dim, nonzeros, ia, ja);
        self.release();
        self.dim = dim.max(0) as usize;
        self.values = vec![0.0; nonzeros.max(0) as usize];
        self.floor = self.dim as f64 * f64::EPSILON;
        self.factored = Factored::None;
        self.switched = false;
        self.on_plain = false;
        self.reused = false;
        if let Some(l) = self.labels.as_ref() {
            // A workspace is a function of the pattern and the labels alone: one built
            // for this very pattern factors as a new one would (see `pool`).
            if let Some(p) = pool::take(self.dim, ia, ja, l) {
                self.ws = Some(p.ws);
                self.plain = p.plain;
                self.reused = true;
            } else {
                self.ws = Workspace::new(self.dim, ia, ja, &l.blocks, &l.groups);
            }
        }
        if self.ws.is_none() && self.labels.is_some() {
            tracing::debug!(
                dim,
                labels = self.labels.as_ref().map_or(0, |l| l.blocks.len()),
                "KKT labels do not fit the matrix; FERAL factors it"
            );
        }
        status
    }

    fn values_array_mut(&mut self) -> &mut [Number] {
        &mut self.values
    }

    fn multi_solve(
        &mut self,
        new_matrix: bool,
        ia: &[Index],
        ja: &[Index],
        nrhs: Index,
        rhs_vals: &mut [Number],
        check_neg_evals: bool,
        number_of_neg_evals: Index,
    ) -> ESymSolverStatus {
        if self.switched {
            self.switched = false;
            if !new_matrix {
                return ESymSolverStatus::CallAgain;
            }
        }
        let (check, expected) = (check_neg_evals, number_of_neg_evals);
        let Some(ws) = self.ws.as_mut() else {
            return self.feral_solve(new_matrix, ia, ja, nrhs, rhs_vals, check, expected);
        };
        if new_matrix {
            // The surplus test needs the multipliers' count: the KKT's last `expected`
            // indices.
            let test = check && (0..=self.dim as Index).contains(&expected);
            if test {
                ws.prepare_surplus(self.dim - expected as usize);
            }
            let mut neg = ws.factor(&self.values, self.floor, test);
            let grouped = !ws.groups.is_empty();
            self.on_plain = false;
            if neg.is_none() && grouped {
                // A group's pivot refused (e.g. a control pinned to its bound by the
                // barrier): the same blocks with their groups inside.
                if self.plain.is_none() {
                    self.plain = self
                        .labels
                        .as_ref()
                        .and_then(|l| Workspace::new(self.dim, ia, ja, &l.blocks, &[]));
                }
                if let Some(plain) = self.plain.as_mut() {
                    if test {
                        plain.prepare_surplus(self.dim - expected as usize);
                    }
                    neg = plain.factor(&self.values, self.floor, test);
                    self.on_plain = neg.is_some();
                    if self.on_plain {
                        PLAIN_FACTORIZATIONS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    }
                }
            }
            let Some(neg) = neg else {
                FERAL_FALLBACKS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                return self.feral_solve(true, ia, ja, nrhs, rhs_vals, check, expected);
            };
            self.block_factorizations += 1;
            BLOCK_FACTORIZATIONS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            match neg {
                Count::Surplus => {
                    SURPLUS_STOPS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    self.surplus_stops += 1;
                    self.factored = Factored::Stopped;
                    // More than expected (pounce reads only which side of it the count
                    // is); the exact count was not taken.
                    self.negevals = expected + 1;
                    return ESymSolverStatus::WrongInertia;
                }
                Count::Negative(neg) => {
                    self.factored = Factored::Blocks;
                    self.negevals = neg as Index;
                    if check && self.negevals != expected {
                        return ESymSolverStatus::WrongInertia;
                    }
                }
            }
        }
        match self.factored {
            Factored::Feral => self.feral_solve(false, ia, ja, nrhs, rhs_vals, check, expected),
            Factored::None => ESymSolverStatus::FatalError,
            // A solve with the matrix whose factorisation stopped (pounce perturbs after a
            // wrong inertia, but should it solve): the whole factorisation, unchecked.
            Factored::Stopped => self.multi_solve(true, ia, ja, nrhs, rhs_vals, false, expected),
            Factored::Blocks => {
                let dim = self.dim;
                let ws = match self.plain.as_mut() {
                    Some(plain) if self.on_plain => plain,
                    _ => ws,
                };
                for b in rhs_vals.chunks_exact_mut(dim).take(nrhs.max(0) as usize) {
                    ws.solve_refined(&self.values, b);
                }
                ESymSolverStatus::Success
            }
        }
    }

    fn number_of_neg_evals(&self) -> Index {
        self.negevals
    }

    fn increase_quality(&mut self) -> bool {
        // FERAL's answer, as without this module (the planner's FERAL declines by default:
        // pounce then perturbs). When FERAL would escalate, it also takes over the solve.
        if !self.feral.increase_quality() {
            return false;
        }
        self.plain = None;
        self.on_plain = false;
        if self.ws.take().is_some() {
            tracing::debug!(dim = self.dim, "KKT quality raised; FERAL takes over");
            self.switched = true;
        }
        true
    }

    fn provides_inertia(&self) -> bool {
        true
    }

    fn singularity_certified(&self) -> bool {
        self.factored == Factored::Feral && self.feral.singularity_certified()
    }

    fn set_reused_scaling_zero_pivot_recheck(&mut self, on: bool) {
        self.feral.set_reused_scaling_zero_pivot_recheck(on);
    }

    fn multi_solve_matches_single_solve(&self, nrhs: usize) -> bool {
        // The blocked solve treats each column on its own, in the same operations.
        self.factored == Factored::Blocks || self.feral.multi_solve_matches_single_solve(nrhs)
    }

    fn matrix_format(&self) -> EMatrixFormat {
        EMatrixFormat::TripletFormat
    }

    fn provides_degeneracy_detection(&self) -> bool {
        self.feral.provides_degeneracy_detection()
    }

    fn determine_dependent_rows(
        &mut self,
        n_rows: Index,
        n_cols: Index,
        irn: &[Index],
        jcn: &[Index],
        vals: &[Number],
        c_deps: &mut Vec<Index>,
    ) -> ESymSolverStatus {
        self.feral
            .determine_dependent_rows(n_rows, n_cols, irn, jcn, vals, c_deps)
    }

    fn factor_pattern(&self, want_values: bool) -> Option<FactorPattern> {
        match self.factored {
            Factored::Feral => self.feral.factor_pattern(want_values),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector, SymmetricEigen};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A lower-triangle triplet (1-based), its values, its labels and the dense matrix.
    struct Arrowhead {
        ia: Vec<Index>,
        ja: Vec<Index>,
        va: Vec<f64>,
        labels: Vec<i32>,
        k: DMatrix<f64>,
    }

    /// A random symmetric indefinite arrowhead: blocks of `sizes` (each coupled to a few
    /// border indices), a border of `nb`, indices shuffled over the KKT; with `chain`,
    /// each block also couples to up to three indices of the block before it (a block
    /// tridiagonal arrowhead, as the collocation's interval ends make it).
    fn arrowhead(sizes: &[usize], nb: usize, chain: bool, rng: &mut ChaCha8Rng) -> Arrowhead {
        let dim = sizes.iter().sum::<usize>() + nb;
        let mut order: Vec<usize> = (0..dim).collect();
        for i in (1..dim).rev() {
            order.swap(i, rng.random_range(0..=i));
        }
        let mut labels = vec![-1; dim];
        let mut at = 0;
        let mut members = Vec::new();
        for (b, &n) in sizes.iter().enumerate() {
            members.push(order[at..at + n].to_vec());
            for &i in &order[at..at + n] {
                labels[i] = b as i32;
            }
            at += n;
        }
        let border = order[at..].to_vec();
        let (mut ia, mut ja, mut va) = (Vec::new(), Vec::new(), Vec::new());
        let mut push = |i: usize, j: usize, v: f64| {
            let (r, c) = (i.max(j), i.min(j));
            ia.push(r as Index + 1);
            ja.push(c as Index + 1);
            va.push(v);
        };
        for m in &members {
            for (p, &i) in m.iter().enumerate() {
                // Alternating signs: indefinite blocks, some pivots needing 2x2 steps.
                let sign = if p % 3 == 2 { -1.0 } else { 1.0 };
                push(i, i, sign * rng.random_range(0.0..2.0));
                for &j in &m[..p] {
                    push(i, j, rng.random_range(-1.0..1.0));
                }
                for &bj in &border {
                    if rng.random_range(0.0..1.0) < 0.3 {
                        push(i, bj, rng.random_range(-1.0..1.0));
                    }
                }
            }
        }
        if chain {
            for pair in members.windows(2) {
                let (prev, this) = (&pair[0], &pair[1]);
                for &j in prev.iter().take(3) {
                    for &i in this {
                        if rng.random_range(0.0..1.0) < 0.5 {
                            push(i, j, rng.random_range(-1.0..1.0));
                        }
                    }
                }
            }
        }
        for (p, &i) in border.iter().enumerate() {
            push(i, i, rng.random_range(-3.0..3.0));
            if p > 0 {
                push(i, border[p - 1], rng.random_range(-1.0..1.0));
            }
        }
        // A duplicate entry: the two values add, as pounce's assembly expects.
        if let Some(&b0) = border.first() {
            push(b0, b0, 0.5);
        }
        let mut k = DMatrix::zeros(dim, dim);
        for ((&r, &c), &v) in ia.iter().zip(&ja).zip(&va) {
            let (r, c) = (r as usize - 1, c as usize - 1);
            k[(r, c)] += v;
            if r != c {
                k[(c, r)] += v;
            }
        }
        Arrowhead {
            ia,
            ja,
            va,
            labels,
            k,
        }
    }

    fn feral_cfg() -> FeralConfig {
        FeralConfig::default()
    }

    /// `a` with `per_block` pivot groups of two indices added to every block after the
    /// first (appended to the KKT): each a `[[d, s], [s, e]]` pivot with `|s|` in 1..2 and
    /// `scale · d`, coupled to members of its block, to three of the block before it and
    /// to the border, as a node's controls and driven defects are. Returns the group
    /// labels (`-1` outside the groups).
    fn add_groups(
        a: &mut Arrowhead,
        per_block: usize,
        scale: f64,
        rng: &mut ChaCha8Rng,
    ) -> Vec<i32> {
        let dim0 = a.k.nrows();
        let blocks = a.labels.iter().copied().max().unwrap_or(-1) + 1;
        let members = |b: i32, labels: &[i32]| -> Vec<usize> {
            (0..dim0).filter(|&i| labels[i] == b).collect()
        };
        let border: Vec<usize> = (0..dim0).filter(|&i| a.labels[i] < 0).collect();
        let mut groups = vec![-1; dim0];
        let mut entries = Vec::new();
        let mut id = 0;
        for b in 1..blocks {
            let (this, prev) = (members(b, &a.labels), members(b - 1, &a.labels));
            for _ in 0..per_block {
                let (u, l) = (a.labels.len(), a.labels.len() + 1);
                a.labels.extend([b, b]);
                groups.extend([id, id]);
                id += 1;
                let sign = if rng.random_range(0.0..1.0) < 0.5 {
                    -1.0
                } else {
                    1.0
                };
                entries.push((u, u, scale * rng.random_range(0.1..1.0)));
                entries.push((l, u, sign * rng.random_range(1.0..2.0)));
                for &i in &this {
                    if rng.random_range(0.0..1.0) < 0.4 {
                        entries.push((l, i, rng.random_range(-1.0..1.0)));
                    }
                }
                for &i in prev.iter().take(3) {
                    entries.push((l, i, rng.random_range(-1.0..1.0)));
                }
                for &i in &border {
                    if rng.random_range(0.0..1.0) < 0.5 {
                        entries.push((u, i, rng.random_range(-0.5..0.5)));
                    }
                }
            }
        }
        let dim = a.labels.len();
        let mut k = DMatrix::zeros(dim, dim);
        k.view_mut((0, 0), (dim0, dim0)).copy_from(&a.k);
        for (i, j, v) in entries {
            let (r, c) = (i.max(j), i.min(j));
            a.ia.push(r as Index + 1);
            a.ja.push(c as Index + 1);
            a.va.push(v);
            k[(r, c)] += v;
            if r != c {
                k[(c, r)] += v;
            }
        }
        a.k = k;
        groups
    }

    /// Pivot groups eliminated before the chain (indefinite 2×2 pivots coupled to their
    /// block, the block before and the border): three right-hand sides solved as by
    /// nalgebra's LU to 1e-9 relative, the inertia equal to `SymmetricEigen`'s, by the
    /// grouped workspace. With a tiny pivot scale, so that the groups' multipliers stay
    /// bounded, and with a huge one (multipliers past [`GROUP_GROWTH_MAX`]): then the
    /// same blocks without the groups factor it, and the answer is as right.
    #[test]
    fn pivot_groups_match_a_dense_solve_and_the_eigenvalues() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for (sizes, nb, per_block, scale, plain) in [
            (vec![8, 9, 7, 8], 3, 2, 1e-3, false),
            (vec![12; 5], 4, 3, 1.0, false),
            (vec![6, 6, 6], 2, 1, 1e9, true),
        ] {
            let mut a = arrowhead(&sizes, nb, true, &mut rng);
            let groups = add_groups(&mut a, per_block, scale, &mut rng);
            let dim = a.k.nrows();
            let eig = SymmetricEigen::new(a.k.clone()).eigenvalues;
            assert!(eig.iter().all(|l: &f64| l.abs() > 1e-6), "draw is singular");
            let neg = eig.iter().filter(|&&l| l < 0.0).count();
            let nrhs = 3;
            let b: Vec<f64> = (0..dim * nrhs)
                .map(|_| rng.random_range(-1.0..1.0))
                .collect();
            let mut x = b.clone();
            let labels = KktLabels {
                blocks: a.labels.clone(),
                groups,
            };
            let mut solver = StructuredKkt::new(Some(labels), feral_cfg());
            let status = solve_with(&mut solver, &a.ia, &a.ja, &a.va, &mut x, nrhs, Some(neg));
            assert_eq!(status, ESymSolverStatus::Success);
            let ws = solver.ws.as_ref().expect("the labels fit");
            assert_eq!(ws.groups.len(), per_block * (sizes.len() - 1));
            assert_eq!(
                (solver.block_factorizations, solver.feral_factorizations),
                (1, 0)
            );
            assert_eq!(solver.on_plain, plain, "grouped or plain as expected");
            assert_eq!(solver.number_of_neg_evals() as usize, neg);
            let lu = a.k.clone().lu();
            for r in 0..nrhs {
                let rhs = DVector::from_column_slice(&b[r * dim..(r + 1) * dim]);
                let reference = lu.solve(&rhs).expect("LU solve");
                let got = DVector::from_column_slice(&x[r * dim..(r + 1) * dim]);
                let err = (got - &reference).amax() / reference.amax();
                assert!(err < 1e-9, "differs from LU by {err:e} (relative)");
                // The elimination alone, without refinement, is as exact.
                let mut alone = b[r * dim..(r + 1) * dim].to_vec();
                let ws = match solver.plain.as_mut() {
                    Some(p) if solver.on_plain => p,
                    _ => solver.ws.as_mut().expect("the labels fit"),
                };
                ws.solve(&mut alone);
                let err = (DVector::from_vec(alone) - &reference).amax() / reference.amax();
                assert!(
                    err < 1e-9,
                    "unrefined: differs from LU by {err:e} (relative)"
                );
            }
        }
    }

    /// A workspace that factored one matrix factors the next exactly as a fresh one does
    /// (the same solution, bit for bit, and the same inertia): the assembly restores every
    /// entry the elimination reads, and nothing above a block's diagonal is ever written
    /// nor above the border's (they stay at their allocated zeros, so the assembly clears
    /// only the lower triangles).
    #[test]
    fn a_reused_workspace_factors_as_a_fresh_one() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        let mut a = arrowhead(&[10, 12, 9, 11], 3, true, &mut rng);
        let groups = add_groups(&mut a, 2, 1e-2, &mut rng);
        let dim = a.k.nrows();
        let labels = KktLabels {
            blocks: a.labels.clone(),
            groups,
        };
        // Same pattern, new values: indefinite diagonals (2x2 pivots), new couplings.
        let second: Vec<f64> =
            a.va.iter()
                .map(|v| v * rng.random_range(-1.5..1.5))
                .collect();
        let b: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut used = StructuredKkt::new(Some(labels.clone()), feral_cfg());
        let mut x_used = b.clone();
        let _ = solve_with(&mut used, &a.ia, &a.ja, &a.va, &mut x_used, 1, None);
        let mut x_used = b.clone();
        used.values_array_mut().copy_from_slice(&second);
        let status = used.multi_solve(true, &a.ia, &a.ja, 1, &mut x_used, false, 0);
        let mut fresh = StructuredKkt::new(Some(labels), feral_cfg());
        let mut x_fresh = b.clone();
        let status_fresh = solve_with(&mut fresh, &a.ia, &a.ja, &second, &mut x_fresh, 1, None);
        assert_eq!(status, status_fresh);
        assert_eq!(used.block_factorizations, 2, "both by block elimination");
        assert_eq!(used.number_of_neg_evals(), fresh.number_of_neg_evals());
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&x_used), bits(&x_fresh), "reused and fresh differ");
        let ws = used.ws.as_ref().expect("the labels fit");
        let nb = ws.border.len();
        assert!(nb > 0, "the draw has a border");
        let squares = ws
            .blocks
            .iter()
            .map(|blk| (blk.a_off, blk.n))
            .chain([(ws.s_off, nb)]);
        for (off, n) in squares {
            let a = &ws.dense[off..off + n * n];
            for j in 0..n {
                assert!(
                    a[j * n..j * n + j].iter().all(|&v| v == 0.0),
                    "written above the diagonal"
                );
            }
        }
    }

    /// A solve takes the workspace a finished solve of the same pattern left in the pool,
    /// and computes the same bits as a solve on a workspace built for it; a solve of
    /// another pattern (one nonzero fewer) does not take it.
    #[test]
    fn a_pooled_workspace_solves_as_a_new_one() {
        let mut rng = ChaCha8Rng::seed_from_u64(4242);
        // Block sizes no other test draws, so that no other test's workspace fits.
        let mut a = arrowhead(&[13, 7, 16, 5, 11], 4, true, &mut rng);
        let groups = add_groups(&mut a, 2, 1e-2, &mut rng);
        let dim = a.k.nrows();
        let labels = KktLabels {
            blocks: a.labels.clone(),
            groups,
        };
        let values: Vec<f64> =
            a.va.iter()
                .map(|v| v * rng.random_range(-1.5..1.5))
                .collect();
        let b: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
        let mut first = StructuredKkt::new(Some(labels.clone()), feral_cfg());
        let mut x = b.clone();
        let _ = solve_with(&mut first, &a.ia, &a.ja, &a.va, &mut x, 1, None);
        assert!(first.is_structured() && !first.reused);
        drop(first);
        let mut pooled = StructuredKkt::new(Some(labels.clone()), feral_cfg());
        let mut x_pooled = b.clone();
        let status = solve_with(&mut pooled, &a.ia, &a.ja, &values, &mut x_pooled, 1, None);
        assert!(
            pooled.reused,
            "the finished solve's workspace was not taken"
        );
        // The pooled one is in use: this one is built.
        let mut built = StructuredKkt::new(Some(labels.clone()), feral_cfg());
        let mut x_built = b.clone();
        let status_built = solve_with(&mut built, &a.ia, &a.ja, &values, &mut x_built, 1, None);
        assert!(!built.reused);
        assert_eq!(status, status_built);
        assert_eq!(pooled.block_factorizations, 1);
        assert_eq!(pooled.number_of_neg_evals(), built.number_of_neg_evals());
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&x_pooled), bits(&x_built), "pooled and built differ");
        drop(pooled);
        drop(built);
        // Another pattern: the last entry dropped.
        let n = a.ia.len() - 1;
        let mut other = StructuredKkt::new(Some(labels), feral_cfg());
        let mut x_other = b.clone();
        let _ = solve_with(
            &mut other,
            &a.ia[..n],
            &a.ja[..n],
            &values[..n],
            &mut x_other,
            1,
            None,
        );
        assert!(!other.reused, "a workspace of another pattern was taken");
    }

    /// Two groups coupled to each other do not fit: FERAL factors that matrix.
    #[test]
    fn coupled_groups_go_to_feral() {
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        let mut a = arrowhead(&[6, 6, 6], 2, true, &mut rng);
        let groups = add_groups(&mut a, 2, 1.0, &mut rng);
        let g: Vec<usize> = (0..groups.len()).filter(|&i| groups[i] >= 0).collect();
        // The first group's first index and the second group's first index.
        let (i, j) = (g[0], g[2]);
        a.ia.push(i.max(j) as Index + 1);
        a.ja.push(i.min(j) as Index + 1);
        a.va.push(0.3);
        let dim = a.k.nrows();
        let mut x = vec![1.0; dim];
        let labels = KktLabels {
            blocks: a.labels.clone(),
            groups,
        };
        let mut solver = StructuredKkt::new(Some(labels), feral_cfg());
        let _ = solve_with(&mut solver, &a.ia, &a.ja, &a.va, &mut x, 1, None);
        assert!(!solver.is_structured());
        assert_eq!(solver.feral_factorizations, 1);
    }

    /// Factorises and solves `nrhs` random right-hand sides; the solutions and status.
    fn solve_with(
        solver: &mut StructuredKkt,
        ia: &[Index],
        ja: &[Index],
        va: &[f64],
        rhs: &mut [f64],
        nrhs: usize,
        expected_neg: Option<usize>,
    ) -> ESymSolverStatus {
        let dim = rhs.len() / nrhs;
        assert_eq!(
            solver.initialize_structure(dim as Index, ia.len() as Index, ia, ja),
            ESymSolverStatus::Success
        );
        solver.values_array_mut().copy_from_slice(va);
        solver.multi_solve(
            true,
            ia,
            ja,
            nrhs as Index,
            rhs,
            expected_neg.is_some(),
            expected_neg.unwrap_or(0) as Index,
        )
    }

    /// The early stop on a surplus of negative eigenvalues, on a three-index KKT
    /// `[[h, 0, c], [0, 2, 1], [c, 1, 0]]` (primal `x` in block 0; primal `y` and the one
    /// multiplier in block 1): with `h = −1` block 0 alone has a negative eigenvalue more
    /// than multipliers, but through the link (`c = 1`, `M = 1/h < 0`) the next block makes
    /// up for it: the matrix's inertia is right (determinant −1, trace 1: one negative
    /// eigenvalue), so the factorisation must not stop. Without the link (`c` not in the
    /// pattern) nothing can: it stops, and reports the wrong inertia with more negative
    /// eigenvalues than multipliers (the matrix has two).
    #[test]
    fn a_surplus_stops_only_when_the_rest_cannot_make_up_for_it() {
        for (linked, status, stops) in [
            (true, ESymSolverStatus::Success, 0),
            (false, ESymSolverStatus::WrongInertia, 1),
        ] {
            let (mut ia, mut ja, mut va) = (
                vec![1, 2, 3, 3],
                vec![1, 2, 2, 3],
                vec![-1.0, 2.0, 1.0, 0.0],
            );
            if linked {
                ia.push(3);
                ja.push(1);
                va.push(1.0);
            }
            let mut solver = StructuredKkt::new(Some(KktLabels::plain(vec![0, 1, 1])), feral_cfg());
            let mut x = vec![1.0; 3];
            let got = solve_with(&mut solver, &ia, &ja, &va, &mut x, 1, Some(1));
            assert!(solver.is_structured());
            assert_eq!(
                (got, solver.surplus_stops),
                (status, stops),
                "linked: {linked}"
            );
            assert_eq!(solver.number_of_neg_evals() > 1, !linked);
        }
    }

    /// Block elimination on random arrowheads, plain and chained (indefinite blocks and
    /// border, indices shuffled, a duplicate entry): three right-hand sides solved as by
    /// nalgebra's LU to 1e-9 relative, and the inertia equal to the signs of
    /// `SymmetricEigen`.
    #[test]
    fn arrowhead_matches_a_dense_solve_and_the_eigenvalues() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for (sizes, nb, chain) in [
            (vec![5, 7, 6], 4, false),
            (vec![12; 6], 9, false),
            (vec![1, 2, 3], 1, false),
            (vec![30, 25], 20, false),
            (vec![5, 7, 6], 4, true),
            (vec![12; 6], 9, true),
            (vec![1, 2, 3], 1, true),
            (vec![30, 25], 20, true),
            (vec![9; 12], 0, true),
        ] {
            let Arrowhead {
                ia,
                ja,
                va,
                labels,
                k,
            } = arrowhead(&sizes, nb, chain, &mut rng);
            let dim = k.nrows();
            let eig = SymmetricEigen::new(k.clone()).eigenvalues;
            assert!(eig.iter().all(|l: &f64| l.abs() > 1e-6), "draw is singular");
            let neg = eig.iter().filter(|&&l| l < 0.0).count();
            let nrhs = 3;
            let b: Vec<f64> = (0..dim * nrhs)
                .map(|_| rng.random_range(-1.0..1.0))
                .collect();
            let mut x = b.clone();
            let mut solver = StructuredKkt::new(Some(KktLabels::plain(labels)), feral_cfg());
            let status = solve_with(&mut solver, &ia, &ja, &va, &mut x, nrhs, Some(neg));
            assert_eq!(status, ESymSolverStatus::Success);
            assert!(solver.is_structured());
            assert_eq!(
                (solver.block_factorizations, solver.feral_factorizations),
                (1, 0)
            );
            assert_eq!(solver.number_of_neg_evals() as usize, neg);
            let lu = k.clone().lu();
            for r in 0..nrhs {
                let rhs = DVector::from_column_slice(&b[r * dim..(r + 1) * dim]);
                let reference = lu.solve(&rhs).expect("LU solve");
                let got = DVector::from_column_slice(&x[r * dim..(r + 1) * dim]);
                let err = (got - &reference).amax() / reference.amax();
                assert!(err < 1e-9, "differs from LU by {err:e} (relative)");
            }
            // A wrong expected count is reported as such (the count is trusted).
            let mut y = b.clone();
            let status = solve_with(&mut solver, &ia, &ja, &va, &mut y, nrhs, Some(neg + 1));
            assert_eq!(status, ESymSolverStatus::WrongInertia);
        }
    }

    /// An entry coupling two blocks that are not neighbours (blocks 0 and 2 of a chain):
    /// the labels do not describe the matrix, so FERAL factors it, and the solve is still right (1e-9 relative to LU). A label vector of
    /// the wrong length does the same.
    #[test]
    fn a_pattern_coupling_two_blocks_goes_to_feral() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let Arrowhead {
            mut ia,
            mut ja,
            mut va,
            labels,
            mut k,
        } = arrowhead(&[6, 6, 6], 5, true, &mut rng);
        let i = labels.iter().position(|&l| l == 0).unwrap();
        let j = labels.iter().position(|&l| l == 2).unwrap();
        ia.push(i.max(j) as Index + 1);
        ja.push(i.min(j) as Index + 1);
        va.push(0.25);
        k[(i, j)] += 0.25;
        k[(j, i)] += 0.25;
        let dim = k.nrows();
        let b: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
        let reference = k
            .clone()
            .lu()
            .solve(&DVector::from_column_slice(&b))
            .unwrap();
        for labels in [labels.clone(), labels[1..].to_vec()] {
            let mut x = b.clone();
            let mut solver = StructuredKkt::new(Some(KktLabels::plain(labels)), feral_cfg());
            let status = solve_with(&mut solver, &ia, &ja, &va, &mut x, 1, None);
            assert_eq!(status, ESymSolverStatus::Success);
            assert!(!solver.is_structured());
            assert_eq!(
                (solver.block_factorizations, solver.feral_factorizations),
                (0, 1)
            );
            let err = (DVector::from_vec(x) - &reference).amax() / reference.amax();
            assert!(err < 1e-9, "differs from LU by {err:e} (relative)");
        }
    }

    /// A block that is exactly singular (a zero row inside it) cannot be factored on its
    /// own, so FERAL factors that matrix and decides: here the whole matrix is singular.
    #[test]
    fn a_singular_block_goes_to_feral() {
        // Block 0 = {0, 1}, block 1 = {2}, border = {3}; index 1 has no entries at all.
        let ia = [1, 3, 4, 4, 4];
        let ja = [1, 3, 1, 3, 4];
        let va = [2.0, -1.0, 0.5, 0.3, 4.0];
        let mut x = vec![1.0; 4];
        let mut solver = StructuredKkt::new(Some(KktLabels::plain(vec![0, 0, 1, -1])), feral_cfg());
        let status = solve_with(&mut solver, &ia, &ja, &va, &mut x, 1, None);
        assert!(solver.is_structured());
        assert_eq!(
            (solver.block_factorizations, solver.feral_factorizations),
            (0, 1)
        );
        assert_eq!(status, ESymSolverStatus::Singular);
    }
}
