//! A KKT linear solver for the solver (pounce) that exploits the LGR collocation
//! structure: block elimination over the mesh intervals with dense Bunch–Kaufman
//! factorisations ([`crate::linalg::bunch_kaufman`]), in place of the general sparse
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
//!
//! Its parts: `labels` (the block labelling), `workspace` (the buffers) and `symbolic`
//! (their layout for a pattern, `Workspace::new`), `factor` (block elimination), `groups`
//! (the pivot groups), `surplus` (the early stop on a surplus of negative eigenvalues),
//! `solve` (solves and refinement), `backend` ([`StructuredKkt`], the pounce interface),
//! `pool` (the planner's [`KktCache`]: workspaces kept across solves) and `counters` (its
//! factorisations counted, for diagnostics).
//!
//! [`Transcription`]: super::transcription::Transcription
//! [`FeralSolverInterface`]: pounce_feral::FeralSolverInterface
//! [`SparseSymLinearSolverInterface::initialize_structure`]: pounce_linsol::SparseSymLinearSolverInterface::initialize_structure
//! [`SparseSymLinearSolverInterface::increase_quality`]: pounce_linsol::SparseSymLinearSolverInterface::increase_quality

mod backend;
mod counters;
mod factor;
mod groups;
mod labels;
mod pool;
mod solve;
mod surplus;
mod symbolic;
#[cfg(test)]
mod tests;
mod workspace;

pub use backend::{KktSolver, StructuredKkt};
pub use counters::KktCounts;
pub use labels::KktLabels;
pub use pool::KktCache;

use workspace::Workspace;
