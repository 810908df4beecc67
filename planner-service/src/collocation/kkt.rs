//! A KKT linear solver for the solver (pounce) that exploits the LGR collocation
//! structure: block elimination over the mesh intervals with dense Bunch–Kaufman
//! factorisations ([`super::bunch_kaufman`]), in place of the general sparse
//! factorisation (FERAL).
//!
//! The KKT indices are split into one block per mesh interval (that interval's interior
//! state points, its controls and its defect multipliers) and a border (the
//! interval-boundary state points shared by neighbouring intervals, the phase end times,
//! the phase-order rows with their slacks, the rendezvous rows): blocks couple to the
//! border only, never to each other. Per factorisation
//!
//! ```text
//!   A_kk = P L D Lᵀ Pᵀ          (dense Bunch–Kaufman, per block)
//!   Y_k  = A_kk⁻¹ A_kb           (its border columns)
//!   S    = A_bb − Σ_k A_bk Y_k   (dense border Schur complement, factored the same way)
//!   inertia(K) = Σ_k inertia(A_kk) + inertia(S)   (Haynsworth)
//! ```
//!
//! and a solve is block elimination (`S Δ_b = b_b − Σ Y_kᵀ b_k`,
//! `x_k = A_kk⁻¹ b_k − Y_k Δ_b`). Nothing allocates after
//! [`SparseSymLinearSolverInterface::initialize_structure`].
//!
//! **Never a silent mislabel.** The labels come from the [`Transcription`] (see
//! [`KktLabels::of`]) and are checked against the assembled pattern: a dimension that
//! differs, or any entry coupling two blocks, sends every factorisation of that matrix to
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
/// cube. Measured on the canonical scenarios (probe, 3 seeds): 2-D borders (74-152) plan
/// 13-37 % faster than with FERAL; 3-D borders (200-430) plan no faster, up to 1.7 times
/// slower on the largest, so 3-D KKTs stay with FERAL.
const MAX_BORDER: usize = 160;

/// Factorisations done by block elimination, over the process (diagnostics and tests).
static BLOCK_FACTORIZATIONS: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

/// How many KKT factorisations block elimination has done in this process.
pub fn block_factorizations_total() -> usize {
    BLOCK_FACTORIZATIONS.load(std::sync::atomic::Ordering::Relaxed)
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
            if node.local != 0 {
                for c in 0..nx {
                    var[tr.state(k, c)] = interval;
                }
            }
            for e in 0..nu {
                var[tr.control(k, e)] = interval;
            }
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
#[derive(Debug, Clone, Copy)]
struct Block {
    /// Order of `A_kk`.
    n: usize,
    /// Its KKT indices are `members[first..first + n]` (also its offset in `work`/`piv`).
    first: usize,
    /// Border columns it touches: `border_cols[b_first..b_first + m]` (border-local,
    /// increasing).
    m: usize,
    b_first: usize,
    /// Offsets of `A_kk` (`n × n`) and of `A_kb` (`n × m`) in `dense`, and of `Y_k` in `y`.
    a_off: usize,
    c_off: usize,
    y_off: usize,
}

/// Every buffer of the structured path, sized in `initialize_structure`.
#[derive(Debug, Default)]
struct Workspace {
    /// Destination in `dense` of each input nonzero.
    dest: Vec<usize>,
    blocks: Vec<Block>,
    members: Vec<usize>,
    border_cols: Vec<usize>,
    /// KKT index of each border position.
    border: Vec<usize>,
    /// All `A_kk`, then all `A_kb`, then `S` (`nb × nb`), column-major.
    dense: Vec<f64>,
    s_off: usize,
    y: Vec<f64>,
    /// Pivots: the blocks' at their `first`, `S`'s after them.
    piv: Vec<i32>,
    /// Solve scratch: block parts and border part of one right-hand side.
    work: Vec<f64>,
    work_b: Vec<f64>,
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
    /// the labels do not describe it.
    fn new(dim: usize, ia: &[Index], ja: &[Index], labels: &[i32]) -> Option<Workspace> {
        if labels.len() != dim || ia.len() != ja.len() {
            return None;
        }
        // Compact block ids in order of first appearance.
        let max = labels.iter().copied().max().unwrap_or(-1);
        if max < 0 {
            return None;
        }
        let mut remap = vec![usize::MAX; max as usize + 1];
        let mut block_of = vec![usize::MAX; dim];
        let mut local = vec![0usize; dim];
        let mut sizes: Vec<usize> = Vec::new();
        let mut border = Vec::new();
        for (i, &l) in labels.iter().enumerate() {
            if l < 0 {
                local[i] = border.len();
                border.push(i);
            } else {
                let slot = &mut remap[l as usize];
                if *slot == usize::MAX {
                    *slot = sizes.len();
                    sizes.push(0);
                }
                block_of[i] = *slot;
                local[i] = sizes[*slot];
                sizes[*slot] += 1;
            }
        }
        let nb = border.len();
        if sizes.is_empty() || nb > MAX_BORDER || sizes.iter().any(|&s| s > MAX_BLOCK) {
            return None;
        }
        // Border columns per block, from the pattern; any block-block coupling refuses.
        let mut touches: Vec<Vec<usize>> = vec![Vec::new(); sizes.len()];
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
                (br, bc) if br != bc => return None,
                _ => {}
            }
        }
        let mut ws = Workspace {
            border,
            ..Workspace::default()
        };
        let mut first = 0;
        let (mut a_len, mut c_len) = (0, 0);
        for (b, t) in touches.iter_mut().enumerate() {
            t.sort_unstable();
            t.dedup();
            let n = sizes[b];
            ws.blocks.push(Block {
                n,
                first,
                m: t.len(),
                b_first: ws.border_cols.len(),
                a_off: a_len,
                c_off: 0,
                y_off: c_len,
            });
            ws.border_cols.extend_from_slice(t);
            first += n;
            a_len += n * n;
            c_len += n * t.len();
        }
        for blk in &mut ws.blocks {
            blk.c_off = a_len + blk.y_off;
        }
        ws.members = vec![0; first];
        let mut fill: Vec<usize> = ws.blocks.iter().map(|b| b.first).collect();
        for (i, &b) in block_of.iter().enumerate() {
            if b != usize::MAX {
                ws.members[fill[b]] = i;
                fill[b] += 1;
            }
        }
        ws.s_off = a_len + c_len;
        ws.dense = vec![0.0; a_len + c_len + nb * nb];
        ws.y = vec![0.0; c_len];
        ws.piv = vec![0; first + nb];
        ws.work = vec![0.0; first];
        ws.work_b = vec![0.0; nb];
        ws.rhs = vec![0.0; dim];
        ws.res = vec![0.0; dim];
        ws.rows = ia.iter().map(|&r| (r - 1) as u32).collect();
        ws.cols = ja.iter().map(|&c| (c - 1) as u32).collect();
        // Where each nonzero goes (lower triangle of each dense matrix).
        ws.dest = Vec::with_capacity(ia.len());
        for (&r, &c) in ia.iter().zip(ja) {
            let (r, c) = (r as usize - 1, c as usize - 1);
            let d = match (block_of[r], block_of[c]) {
                (usize::MAX, usize::MAX) => {
                    let (i, j) = (local[r].max(local[c]), local[r].min(local[c]));
                    ws.s_off + i + j * nb
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
                    blk.c_off + row + j * blk.n
                }
                (b, _) => {
                    let blk = ws.blocks[b];
                    let (i, j) = (local[r].max(local[c]), local[r].min(local[c]));
                    blk.a_off + i + j * blk.n
                }
            };
            ws.dest.push(d);
        }
        Some(ws)
    }

    /// Factorises the matrix with nonzeros `values`. `None`: a pivot under `floor` (or a
    /// zero pivot column); otherwise the number of negative eigenvalues.
    fn factor(&mut self, values: &[f64], floor: f64) -> Option<usize> {
        self.dense.iter_mut().for_each(|v| *v = 0.0);
        self.k_max = 0.0;
        for (&d, &v) in self.dest.iter().zip(values) {
            self.dense[d] += v;
            self.k_max = self.k_max.max(v.abs());
        }
        let nb = self.border.len();
        let (blocks_part, s) = self.dense.split_at_mut(self.s_off);
        let mut negative = 0;
        for blk in &self.blocks {
            let (n, m) = (blk.n, blk.m);
            let (a_all, c_all) = blocks_part.split_at_mut(blk.c_off);
            let a = &mut a_all[blk.a_off..blk.a_off + n * n];
            let piv = &mut self.piv[blk.first..blk.first + n];
            let inertia = bunch_kaufman::factor(a, n, piv)?;
            if inertia.min_pivot < floor {
                return None;
            }
            negative += inertia.negative;
            let c = &c_all[..n * m];
            let y = &mut self.y[blk.y_off..blk.y_off + n * m];
            y.copy_from_slice(c);
            for col in y.chunks_exact_mut(n) {
                bunch_kaufman::solve(a, n, piv, col);
            }
            // S -= A_bk Y_k over the lower triangle (border columns increase).
            let cols = &self.border_cols[blk.b_first..blk.b_first + m];
            for (jj, &bj) in cols.iter().enumerate() {
                let yj = &y[jj * n..(jj + 1) * n];
                for (ii, &bi) in cols.iter().enumerate().skip(jj) {
                    let ci = &c[ii * n..(ii + 1) * n];
                    let dot: f64 = ci.iter().zip(yj).map(|(p, q)| p * q).sum();
                    s[bi + bj * nb] -= dot;
                }
            }
        }
        if nb > 0 {
            let piv = &mut self.piv[self.members.len()..];
            let inertia = bunch_kaufman::factor(s, nb, piv)?;
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
        let s = &self.dense[self.s_off..];
        for (w, &i) in self.work_b.iter_mut().zip(&self.border) {
            *w = b[i];
        }
        for blk in &self.blocks {
            let (n, m) = (blk.n, blk.m);
            let t = &mut self.work[blk.first..blk.first + n];
            for (ti, &i) in t.iter_mut().zip(&self.members[blk.first..blk.first + n]) {
                *ti = b[i];
            }
            let y = &self.y[blk.y_off..blk.y_off + n * m];
            let cols = &self.border_cols[blk.b_first..blk.b_first + m];
            for (yj, &bj) in y.chunks_exact(n).zip(cols) {
                let dot: f64 = yj.iter().zip(t.iter()).map(|(p, q)| p * q).sum();
                self.work_b[bj] -= dot;
            }
            let a = &self.dense[blk.a_off..blk.a_off + n * n];
            bunch_kaufman::solve(a, n, &self.piv[blk.first..blk.first + n], t);
        }
        if nb > 0 {
            bunch_kaufman::solve(s, nb, &self.piv[self.members.len()..], &mut self.work_b);
        }
        for blk in &self.blocks {
            let (n, m) = (blk.n, blk.m);
            let t = &mut self.work[blk.first..blk.first + n];
            let y = &self.y[blk.y_off..blk.y_off + n * m];
            let cols = &self.border_cols[blk.b_first..blk.b_first + m];
            for (yj, &bj) in y.chunks_exact(n).zip(cols) {
                let v = self.work_b[bj];
                if v != 0.0 {
                    for (ti, &yv) in t.iter_mut().zip(yj) {
                        *ti -= yv * v;
                    }
                }
            }
            for (&ti, &i) in t.iter().zip(&self.members[blk.first..blk.first + n]) {
                b[i] = ti;
            }
        }
        for (&w, &i) in self.work_b.iter().zip(&self.border) {
            b[i] = w;
        }
    }
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
            let finite = self.values.iter().all(|v| v.is_finite());
            let neg = if finite {
                ws.factor(&self.values, self.floor)
            } else {
                None
            };
            let Some(neg) = neg else {
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
    /// border indices), a border of `nb`, indices shuffled over the KKT.
    fn arrowhead(sizes: &[usize], nb: usize, rng: &mut ChaCha8Rng) -> Arrowhead {
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
        for (p, &i) in border.iter().enumerate() {
            push(i, i, rng.random_range(-3.0..3.0));
            if p > 0 {
                push(i, border[p - 1], rng.random_range(-1.0..1.0));
            }
        }
        // A duplicate entry: the two values add, as pounce's assembly expects.
        push(border[0], border[0], 0.5);
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

    /// Block elimination on random arrowheads (indefinite blocks and border, indices
    /// shuffled, a duplicate entry): three right-hand sides solved as by nalgebra's LU to
    /// 1e-9 relative, and the inertia equal to the signs of `SymmetricEigen`.
    #[test]
    fn arrowhead_matches_a_dense_solve_and_the_eigenvalues() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for (sizes, nb) in [
            (vec![5, 7, 6], 4),
            (vec![12; 6], 9),
            (vec![1, 2, 3], 1),
            (vec![30, 25], 20),
        ] {
            let Arrowhead {
                ia,
                ja,
                va,
                labels,
                k,
            } = arrowhead(&sizes, nb, &mut rng);
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

    /// An entry coupling two blocks: the labels do not describe the matrix, so FERAL
    /// factors it, and the solve is still right (1e-9 relative to LU). A label vector of
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
        } = arrowhead(&[6, 6, 6], 5, &mut rng);
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
