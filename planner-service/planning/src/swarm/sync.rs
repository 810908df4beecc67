//! A reusable barrier for the swarm's persistent worker threads: no allocation, a short
//! spin (no system call when the parties arrive together, as on two free cores), then
//! `yield` (so that threads sharing one core do not take cycles from each other), and an
//! abort flag so that a party that dies cannot leave the others waiting for ever.

use std::hint::spin_loop;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Spins before yielding the core: few, because when the threads share one physical
/// core (as on the project's VM) a spinning waiter takes cycles from the thread it waits
/// for (with 2 000 spins two threads were 35 % slower than one on a 2-D scenario there;
/// with 50, as fast).
const SPINS_BEFORE_YIELD: u32 = 50;

/// A barrier for `parties` threads, reusable round after round.
#[derive(Debug)]
pub(crate) struct SpinBarrier {
    parties: usize,
    arrived: AtomicUsize,
    generation: AtomicUsize,
    aborted: AtomicBool,
}

impl SpinBarrier {
    pub(crate) fn new(parties: usize) -> Self {
        SpinBarrier {
            parties: parties.max(1),
            arrived: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            aborted: AtomicBool::new(false),
        }
    }

    /// Waits until every party has arrived; false when the barrier was aborted.
    pub(crate) fn wait(&self) -> bool {
        let gen_now = self.generation.load(Ordering::Acquire);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.parties {
            self.arrived.store(0, Ordering::Relaxed);
            self.generation.fetch_add(1, Ordering::Release);
            return !self.aborted.load(Ordering::Acquire);
        }
        let mut spins = 0u32;
        while self.generation.load(Ordering::Acquire) == gen_now {
            if self.aborted.load(Ordering::Acquire) {
                return false;
            }
            if spins < SPINS_BEFORE_YIELD {
                spin_loop();
                spins += 1;
            } else {
                std::thread::yield_now();
            }
        }
        !self.aborted.load(Ordering::Acquire)
    }

    /// Releases every waiting party with `false`, now and in every later round.
    pub(crate) fn abort(&self) {
        self.aborted.store(true, Ordering::Release);
    }
}

/// Aborts the barrier when dropped during a panic (a worker that dies releases the others).
pub(crate) struct AbortOnUnwind<'a>(pub(crate) &'a SpinBarrier);

impl Drop for AbortOnUnwind<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.abort();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two threads pass 10 000 rounds in lock step: a shared counter seen by both after
    /// each round equals the round number.
    #[test]
    fn rounds_stay_in_lock_step() {
        let b = SpinBarrier::new(2);
        let counter = AtomicUsize::new(0);
        std::thread::scope(|s| {
            s.spawn(|| {
                for r in 0..10_000 {
                    assert!(b.wait());
                    assert_eq!(counter.load(Ordering::SeqCst), r + 1);
                    assert!(b.wait());
                }
            });
            for _ in 0..10_000 {
                counter.fetch_add(1, Ordering::SeqCst);
                assert!(b.wait());
                assert!(b.wait());
            }
        });
    }

    #[test]
    fn abort_releases_a_waiter() {
        let b = SpinBarrier::new(2);
        std::thread::scope(|s| {
            let h = s.spawn(|| b.wait());
            std::thread::sleep(std::time::Duration::from_millis(5));
            b.abort();
            assert!(!h.join().unwrap_or(true));
        });
    }
}
