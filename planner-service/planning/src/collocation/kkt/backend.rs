//! The solver-backend adapter: [`StructuredKkt`], pounce's
//! [`SparseSymLinearSolverInterface`] over the blocked factorisation, with FERAL where the
//! labels do not fit or a factorisation is refused.

use pounce_feral::{FeralConfig, FeralSolverInterface};
use pounce_linsol::FactorPattern;
use pounce_linsol::{EMatrixFormat, ESymSolverStatus, SparseSymLinearSolverInterface};
use pounce_rs::{Index, Number};
use std::sync::Arc;

use super::counters::KktCounters;
use super::factor::Count;
use super::{KktCache, KktLabels, Workspace, pool};

/// Which linear solver factors the KKT systems of the NLP solves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KktSolver {
    /// FERAL, pounce's general sparse `LDLᵀ`.
    Feral,
    /// Block elimination over the mesh intervals ([`StructuredKkt`]), FERAL where the
    /// structure does not hold.
    Structured,
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
    /// The planner's pool of workspaces and its counters.
    cache: Arc<KktCache>,
    feral: FeralSolverInterface,
    /// `None`: every factorisation goes to FERAL (the labels did not fit the pattern).
    pub(super) ws: Option<Workspace>,
    /// The blocks with the groups inside them, for a matrix whose group pivots `ws`
    /// refuses (built when first needed), and whether it factored the current matrix.
    pub(super) plain: Option<Workspace>,
    pub(super) on_plain: bool,
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
    /// to FERAL configured with `feral`, its workspaces pooled and its factorisations
    /// counted in `cache`.
    pub fn new(
        labels: Option<KktLabels>,
        feral: FeralConfig,
        cache: Arc<KktCache>,
    ) -> StructuredKkt {
        StructuredKkt {
            labels,
            cache,
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
            self.cache
                .give_back(pool::Pooled::new(labels.clone(), ws, plain));
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
            if let Some(p) = self.cache.take(self.dim, ia, ja, l) {
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
                        KktCounters::bump(&self.cache.counters.plain);
                    }
                }
            }
            let Some(neg) = neg else {
                KktCounters::bump(&self.cache.counters.feral_fallbacks);
                return self.feral_solve(true, ia, ja, nrhs, rhs_vals, check, expected);
            };
            self.block_factorizations += 1;
            KktCounters::bump(&self.cache.counters.block);
            match neg {
                Count::Surplus => {
                    KktCounters::bump(&self.cache.counters.surplus_stops);
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
