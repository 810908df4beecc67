//! Dense linear algebra: the Bunch–Kaufman `LDLᵀ` kernels the structured KKT solver
//! ([`crate::collocation::kkt`]) factors and solves its small dense blocks with.

pub mod bunch_kaufman;
