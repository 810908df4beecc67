//! Process-wide counters of the structured factorisations (diagnostics and tests).

/// Factorisations done by block elimination, over the process (diagnostics and tests).
pub(super) static BLOCK_FACTORIZATIONS: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

/// Factorisations of labelled matrices that block elimination handed to FERAL (a pivot
/// under the floor, a non-finite entry), over the process.
pub(super) static FERAL_FALLBACKS: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

/// Factorisations block elimination stopped early on a certain surplus of negative
/// eigenvalues (see [`super::Workspace::surplus`]), over the process.
pub(super) static SURPLUS_STOPS: std::sync::atomic::AtomicUsize =
    std::sync::atomic::AtomicUsize::new(0);

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
pub(super) static PLAIN_FACTORIZATIONS: std::sync::atomic::AtomicUsize =
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
