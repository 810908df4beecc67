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

/// How many KKT factorisations block elimination has done in this process.
pub fn block_factorizations_total() -> usize {
    BLOCK_FACTORIZATIONS.load(std::sync::atomic::Ordering::Relaxed)
}

/// How many factorisations of matrices the labels fit went to FERAL in this process.
pub fn feral_fallbacks_total() -> usize {
    FERAL_FALLBACKS.load(std::sync::atomic::Ordering::Relaxed)
}

/// Most refinement steps per solve, and the backward error that stops them.
const REFINE_STEPS: usize = 2;
const REFINE_TOL: f64 = 1e-14;

/// Block label of every KKT index (`< 0`: border), in pounce's KKT order
/// `[x not fixed | slacks | equality duals | inequality duals]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KktLabels(pub Vec<i32>);

impl KktLabels {
    /// The labels of `tr`'s KKT: block `i` is mesh interval `i`. Mirrors pounce's bound
    /// classification (`pounce_nlp::tnlp_adapter`): a variable with equal finite bounds is
    /// fixed and leaves the KKT; a constraint with equal finite bounds is an equality, any
    /// other an inequality with a slack.
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
        let mut labels = Vec::with_capacity(tr.n_vars() + 2 * tr.n_cons());
        for (i, &l) in var.iter().enumerate() {
            let (lo, hi) = (tr.x_lo[i], tr.x_hi[i]);
            if !(present(lo, hi) && lo == hi) {
                labels.push(l);
            }
        }
        let equality: Vec<bool> = (0..tr.n_cons())
            .map(|r| present(tr.g_lo[r], tr.g_hi[r]) && tr.g_lo[r] == tr.g_hi[r])
            .collect();
        let inequalities = || (0..tr.n_cons()).filter(|&r| !equality[r]).map(|r| con[r]);
        labels.extend(inequalities());
        labels.extend((0..tr.n_cons()).filter(|&r| equality[r]).map(|r| con[r]));
        labels.extend(inequalities());
        KktLabels(labels)
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
}

impl Workspace {
    /// The workspace for the pattern `(ia, ja)` (1-based) under `labels`, or `None` when
    /// the labels do not describe it (an entry coupling two blocks that are not
    /// neighbours in label order, a block or border too large).
    fn new(dim: usize, ia: &[Index], ja: &[Index], labels: &[i32]) -> Option<Workspace> {
        if labels.len() != dim || ia.len() != ja.len() {
            return None;
        }
        let max = labels.iter().copied().max().unwrap_or(-1);
        if max < 0 {
            return None;
        }
        // Compact block ids, keeping the label order (the chain's order).
        let mut present = vec![false; max as usize + 1];
        for &l in labels.iter().filter(|&&l| l >= 0) {
            present[l as usize] = true;
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
        let mut local = vec![0usize; dim];
        let mut sizes = vec![0usize; count];
        let mut border = Vec::new();
        for (i, &l) in labels.iter().enumerate() {
            if l < 0 {
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
        // Border columns and links per block, from the pattern.
        let mut touches: Vec<Vec<usize>> = vec![Vec::new(); count];
        let mut linked: Vec<Vec<usize>> = vec![Vec::new(); count];
        for (&r, &c) in ia.iter().zip(ja) {
            let (r, c) = (r as usize, c as usize);
            if r == 0 || c == 0 || r > dim || c > dim {
                return None;
            }
            let (r, c) = (r - 1, c - 1);
            match (block_of[r], block_of[c]) {
                (usize::MAX, usize::MAX) => {}
                (usize::MAX, b) => touches[b].push(local[r]),
                (b, usize::MAX) => touches[b].push(local[c]),
                (br, bc) if br == bc + 1 => linked[br].push(local[c]),
                (br, bc) if bc == br + 1 => linked[bc].push(local[r]),
                (br, bc) if br != bc => return None,
                _ => {}
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
        ws.dense = vec![0.0; ws.s_off + nb * nb];
        ws.y = vec![0.0; w_len];
        ws.z = vec![0.0; z_len];
        ws.piv = vec![0; first + nb];
        ws.g_w = vec![0.0; max_nm];
        let largest = ws.blocks.iter().map(|b| b.n).max().unwrap_or(0).max(nb);
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
        ws.rows = ia.iter().map(|&r| (r - 1) as u32).collect();
        ws.cols = ja.iter().map(|&c| (c - 1) as u32).collect();
        // Where each nonzero goes (lower triangle of each symmetric dense matrix),
        // and which block takes it (its `A`, `C` or `W`; `count`: the border's `S`).
        ws.dest = Vec::with_capacity(ia.len());
        let mut owners = Vec::with_capacity(ia.len());
        for (&r, &c) in ia.iter().zip(ja) {
            let (r, c) = (r as usize - 1, c as usize - 1);
            let (d, owner) = match (block_of[r], block_of[c]) {
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
        Some(ws)
    }

    /// Assembles group `owner` (a block's `A`, `C` and `W`, or with `owner` = the block
    /// count the border's `S`) from `values`; `None` on a non-finite entry.
    fn assemble(&mut self, owner: usize, values: &[f64]) -> Option<()> {
        let nb = self.border.len();
        match self.blocks.get(owner) {
            Some(b) => {
                self.dense[b.a_off..b.a_off + b.n * b.n].fill(0.0);
                let c = self.c_base + b.c_off;
                self.dense[c..c + b.n * b.l].fill(0.0);
                let w = self.w_base + b.w_off;
                self.dense[w..w + b.n * b.m].fill(0.0);
            }
            None => self.dense[self.s_off..self.s_off + nb * nb].fill(0.0),
        }
        let mut finite = true;
        let group = &self.by_owner[self.owner_start[owner]..self.owner_start[owner + 1]];
        for &i in group {
            let v = values[i as usize];
            self.dense[self.dest[i as usize]] += v;
            self.k_max = self.k_max.max(v.abs());
            finite &= v.is_finite();
        }
        finite.then_some(())
    }

    /// Factorises the matrix with nonzeros `values`. `None`: a non-finite entry, a pivot
    /// under `floor` or a zero pivot column; otherwise the number of negative eigenvalues.
    fn factor(&mut self, values: &[f64], floor: f64) -> Option<usize> {
        let count = self.blocks.len();
        self.k_max = 0.0;
        self.assemble(count, values)?;
        if count > 0 {
            self.assemble(0, values)?;
        }
        let nb = self.border.len();
        let mut negative = 0;
        for k in 0..count {
            // The next block is assembled now: this one's elimination updates it.
            if k + 1 < count {
                self.assemble(k + 1, values)?;
            }
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
            let inertia = bunch_kaufman::factor(a, n, piv, &mut self.bk_work)?;
            if inertia.min_pivot < floor {
                return None;
            }
            negative += inertia.negative;
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
            if l == 0 {
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
            let inertia = bunch_kaufman::factor(s, nb, piv, &mut self.bk_work)?;
            if inertia.min_pivot < floor {
                return None;
            }
            negative += inertia.negative;
        }
        Some(negative)
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
            for ((&r, &c), &v) in self.rows.iter().zip(&self.cols).zip(values) {
                let (r, c) = (r as usize, c as usize);
                self.res[r] -= v * b[c];
                if r != c {
                    self.res[c] -= v * b[r];
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
    Feral,
}

/// The structured KKT backend (see the module documentation).
pub struct StructuredKkt {
    labels: Option<KktLabels>,
    feral: FeralSolverInterface,
    /// `None`: every factorisation goes to FERAL (the labels did not fit the pattern).
    ws: Option<Workspace>,
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
}

impl StructuredKkt {
    /// A backend for KKTs labelled `labels` (`None`: FERAL for every matrix), falling back
    /// to FERAL configured with `feral`.
    pub fn new(labels: Option<KktLabels>, feral: FeralConfig) -> StructuredKkt {
        StructuredKkt {
            labels,
            feral: FeralSolverInterface::with_config(feral),
            ws: None,
            values: Vec::new(),
            dim: 0,
            floor: 0.0,
            negevals: 0,
            factored: Factored::None,
            switched: false,
            block_factorizations: 0,
            feral_factorizations: 0,
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

impl SparseSymLinearSolverInterface for StructuredKkt {
    fn initialize_structure(
        &mut self,
        dim: Index,
        nonzeros: Index,
        ia: &[Index],
        ja: &[Index],
    ) -> ESymSolverStatus {
        let status = self.feral.initialize_structure(dim, nonzeros, ia, ja);
        self.dim = dim.max(0) as usize;
        self.values = vec![0.0; nonzeros.max(0) as usize];
        self.floor = self.dim as f64 * f64::EPSILON;
        self.factored = Factored::None;
        self.switched = false;
        self.ws = self
            .labels
            .as_ref()
            .and_then(|l| Workspace::new(self.dim, ia, ja, &l.0));
        if self.ws.is_none() && self.labels.is_some() {
            tracing::debug!(
                dim,
                labels = self.labels.as_ref().map_or(0, |l| l.0.len()),
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
            let Some(neg) = ws.factor(&self.values, self.floor) else {
                FERAL_FALLBACKS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                return self.feral_solve(true, ia, ja, nrhs, rhs_vals, check, expected);
            };
            self.block_factorizations += 1;
            BLOCK_FACTORIZATIONS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            self.factored = Factored::Blocks;
            self.negevals = neg as Index;
            if check && self.negevals != expected {
                return ESymSolverStatus::WrongInertia;
            }
        }
        match self.factored {
            Factored::Feral => self.feral_solve(false, ia, ja, nrhs, rhs_vals, check, expected),
            Factored::None => ESymSolverStatus::FatalError,
            Factored::Blocks => {
                let dim = self.dim;
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
            let mut solver = StructuredKkt::new(Some(KktLabels(labels)), feral_cfg());
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
            let mut solver = StructuredKkt::new(Some(KktLabels(labels)), feral_cfg());
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
        let mut solver = StructuredKkt::new(Some(KktLabels(vec![0, 0, 1, -1])), feral_cfg());
        let status = solve_with(&mut solver, &ia, &ja, &va, &mut x, 1, None);
        assert!(solver.is_structured());
        assert_eq!(
            (solver.block_factorizations, solver.feral_factorizations),
            (0, 1)
        );
        assert_eq!(status, ESymSolverStatus::Singular);
    }
}
