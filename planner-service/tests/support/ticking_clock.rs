//! A clock that moves 1 ms every time it is read: time in a test then counts the clock's
//! readings, the same on every machine. Include with
//! `#[path = "support/ticking_clock.rs"] mod ticking_clock;`.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use wingman_planner::clock::Clock;

/// A clock that moves 1 ms every time it is read.
#[derive(Default)]
pub struct TickingClock(AtomicU64);

impl Clock for TickingClock {
    fn now(&self) -> Duration {
        Duration::from_millis(self.0.fetch_add(1, Ordering::SeqCst))
    }
}
