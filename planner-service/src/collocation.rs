//! Direct orthogonal collocation at Legendre–Gauss–Radau points (FORMULATION.md §4).

pub mod lgr;

pub use lgr::Lgr;
