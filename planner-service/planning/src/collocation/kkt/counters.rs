//! Counters of the structured factorisations of one planner's solves (diagnostics and
//! tests), kept in its [`super::KktCache`].

use std::sync::atomic::{AtomicUsize, Ordering};

/// The counters, updated by the solves' backends.
#[derive(Debug, Default)]
pub(super) struct KktCounters {
    /// Factorisations done by block elimination.
    pub block: AtomicUsize,
    /// Factorisations of labelled matrices that block elimination handed to FERAL (a
    /// pivot under the floor, a non-finite entry).
    pub feral_fallbacks: AtomicUsize,
    /// Factorisations block elimination stopped early on a certain surplus of negative
    /// eigenvalues (see [`super::Workspace::surplus`]; included in `block`).
    pub surplus_stops: AtomicUsize,
    /// Factorisations by block elimination without the pivot groups (their pivots
    /// refused; included in `block`).
    pub plain: AtomicUsize,
}

/// The counters at one moment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct KktCounts {
    /// Factorisations done by block elimination.
    pub block_factorizations: usize,
    /// Of those, stopped early on a surplus of negative eigenvalues.
    pub surplus_stops: usize,
    /// Of those, done without the pivot groups.
    pub plain_factorizations: usize,
    /// Factorisations of matrices the labels fit that went to FERAL.
    pub feral_fallbacks: usize,
}

impl KktCounters {
    /// Adds one to `counter`.
    pub fn bump(counter: &AtomicUsize) {
        counter.fetch_add(1, Ordering::Relaxed);
    }

    pub fn snapshot(&self) -> KktCounts {
        KktCounts {
            block_factorizations: self.block.load(Ordering::Relaxed),
            surplus_stops: self.surplus_stops.load(Ordering::Relaxed),
            plain_factorizations: self.plain.load(Ordering::Relaxed),
            feral_fallbacks: self.feral_fallbacks.load(Ordering::Relaxed),
        }
    }
}
