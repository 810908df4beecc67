//! Workspaces of recently factorised KKT patterns, kept for the next solve with the same
//! pattern.
//!
//! Building a [`Workspace`] (placing every nonzero, finding the pivot groups, their fill
//! and the surplus test's ranks) costs about as much as three factorisations of a 2-D
//! plan's KKT, and every NLP solve builds one. The patterns repeat: a re-plan of the
//! same mission solves on meshes of the same shapes (five plans of
//! 2d-min-time-unavoidable, seeds 1-5, met 16 distinct patterns in 44 solves, the fifth
//! plan only patterns the first four had). A workspace is a pure
//! function of its pattern and labels, and every factorisation overwrites what it reads
//! (`a_reused_workspace_factors_as_a_fresh_one`), so a solve that takes one from here
//! computes the same bits as with a new one.
//!
//! The pool belongs to the planner that owns its [`KktCache`] (the solves of its plans
//! share it across their threads and across plans) and is bounded by [`POOL_BYTES`]: the
//! least recently returned workspace goes first.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use pounce_rs::Index;

use super::counters::KktCounters;
use super::{KktLabels, Workspace};

/// Most bytes of buffers the pool keeps: about one 3-D plan's workspaces (25-30 MB over
/// its solves), or four 2-D plans' (about 7 MB each).
pub(super) const POOL_BYTES: usize = 32 << 20;

/// A workspace with the labels it was built under (its pattern it keeps itself).
pub(super) struct Pooled {
    pub labels: KktLabels,
    pub ws: Workspace,
    /// The same blocks without the pivot groups, if that solve needed it.
    pub plain: Option<Workspace>,
    bytes: usize,
}

impl Pooled {
    pub fn new(labels: KktLabels, ws: Workspace, plain: Option<Workspace>) -> Pooled {
        let bytes = ws.bytes() + plain.as_ref().map_or(0, Workspace::bytes);
        Pooled {
            labels,
            ws,
            plain,
            bytes,
        }
    }

    fn fits(&self, dim: usize, ia: &[Index], ja: &[Index], labels: &KktLabels) -> bool {
        self.labels == *labels && self.ws.same_pattern(dim, ia, ja)
    }
}

/// What the structured backend keeps across the solves of one planner: the pool of KKT
/// workspaces, and the counters of its factorisations. A planner owns one and hands it to
/// every solve (`collocation::solve`); a solve without a planner makes its own.
#[derive(Default)]
pub struct KktCache {
    /// Least recently returned first.
    pool: Mutex<Vec<Pooled>>,
    /// Workspaces taken from the pool instead of built.
    reuses: AtomicUsize,
    /// The factorisations' counters.
    pub(super) counters: KktCounters,
}

impl KktCache {
    /// An empty cache.
    pub fn new() -> KktCache {
        KktCache::default()
    }

    /// How many solves took their KKT workspace from the pool.
    pub fn workspace_reuses(&self) -> usize {
        self.reuses.load(Ordering::Relaxed)
    }

    /// Drops every pooled workspace (benchmarks count the heap from an empty pool).
    pub fn clear_workspace_pool(&self) {
        self.pool().clear();
    }

    /// The factorisations counted so far.
    pub fn counts(&self) -> super::KktCounts {
        self.counters.snapshot()
    }

    fn pool(&self) -> std::sync::MutexGuard<'_, Vec<Pooled>> {
        // Nothing panics under the lock; recover anyway (the pool is only a cache).
        self.pool.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The pooled workspace built for exactly this pattern and these labels, if any.
    pub(super) fn take(
        &self,
        dim: usize,
        ia: &[Index],
        ja: &[Index],
        labels: &KktLabels,
    ) -> Option<Pooled> {
        let mut pool = self.pool();
        let i = pool.iter().rposition(|p| p.fits(dim, ia, ja, labels))?;
        self.reuses.fetch_add(1, Ordering::Relaxed);
        Some(pool.remove(i))
    }

    /// Keeps `p` for a later solve, dropping the least recently returned workspaces beyond
    /// [`POOL_BYTES`].
    pub(super) fn give_back(&self, p: Pooled) {
        let mut pool = self.pool();
        pool.push(p);
        let mut total: usize = pool.iter().map(|p| p.bytes).sum();
        while total > POOL_BYTES && !pool.is_empty() {
            total -= pool.remove(0).bytes;
        }
    }
}
