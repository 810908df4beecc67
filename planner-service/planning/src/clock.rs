//! Injected time for compute deadlines. Planning logic never reads the OS clock itself: it
//! asks a [`Clock`], so tests can use a [`ManualClock`] and stay deterministic.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use crate::cuts::{CutLog, Part, Site, Work};

/// A monotonic clock.
pub trait Clock: Send + Sync {
    /// Time since an arbitrary fixed origin.
    fn now(&self) -> Duration;
}

/// The OS monotonic clock.
#[derive(Debug, Clone, Copy)]
pub struct MonotonicClock {
    origin: Instant,
}

impl MonotonicClock {
    pub fn new() -> Self {
        MonotonicClock {
            origin: Instant::now(),
        }
    }
}

impl Default for MonotonicClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for MonotonicClock {
    fn now(&self) -> Duration {
        self.origin.elapsed()
    }
}

/// A clock that moves only when told to (tests).
#[derive(Debug, Default)]
pub struct ManualClock {
    nanos: AtomicU64,
}

impl ManualClock {
    pub fn new() -> Self {
        Self::default()
    }

    /// Moves the clock forward.
    pub fn advance(&self, by: Duration) {
        self.nanos.fetch_add(by.as_nanos() as u64, Ordering::SeqCst);
    }
}

impl Clock for ManualClock {
    fn now(&self) -> Duration {
        Duration::from_nanos(self.nanos.load(Ordering::SeqCst))
    }
}

/// A clock that moves 1 ms every time it is read (tests): time then counts the clock's
/// readings, the same on every machine, so a deadline cuts a computation at the same step
/// everywhere.
#[derive(Debug, Default)]
pub struct TickingClock(AtomicU64);

impl Clock for TickingClock {
    fn now(&self) -> Duration {
        Duration::from_millis(self.0.fetch_add(1, Ordering::SeqCst))
    }
}

/// A point in a clock's time by which work must be done, and the work it is for: where
/// the deadline changes the course of a computation it is asked through [`Deadline::cuts`],
/// which records the choice (or replays a logged one, `crate::cuts`).
#[derive(Clone, Copy)]
pub struct Deadline<'c> {
    clock: &'c dyn Clock,
    at: Duration,
    log: Option<&'c CutLog>,
    site: Site,
}

impl<'c> Deadline<'c> {
    /// `budget` from now on `clock`.
    pub fn after(clock: &'c dyn Clock, budget: Duration) -> Self {
        Deadline {
            clock,
            at: clock.now().saturating_add(budget),
            log: None,
            site: Site::PLAN,
        }
    }

    /// No deadline (a budget of about a century).
    pub fn never(clock: &'c dyn Clock) -> Self {
        Self::after(clock, Duration::from_secs(3_000_000_000))
    }

    /// This deadline with its cuts recorded in (or replayed from) `log`.
    pub fn with_cuts(self, log: &'c CutLog) -> Self {
        Deadline {
            log: Some(log),
            ..self
        }
    }

    /// This deadline for the whole of path `part`.
    pub fn within(self, part: Part) -> Self {
        Deadline {
            site: Site {
                part,
                work: Work::Whole,
            },
            ..self
        }
    }

    /// This deadline for `work` of the same path.
    pub fn at(self, work: Work) -> Self {
        Deadline {
            site: self.site.with(work),
            ..self
        }
    }

    /// The work this deadline is for.
    pub fn site(&self) -> Site {
        self.site
    }

    /// Whether the deadline cuts this work at `step` (iterations, rounds or seeds done;
    /// 0 for a choice or for work not started): `live(self)`, the clock's answer, or in a
    /// replay the logged one (see `crate::cuts`).
    pub fn cuts(&self, step: u32, live: impl FnOnce(&Self) -> bool) -> bool {
        match self.log {
            Some(log) => log.cuts(self.site, step, || live(self)),
            None => live(self),
        }
    }

    /// Records that this work was cut at `step` by other means (the solver's own
    /// wall-time limit).
    pub fn note_cut(&self, step: u32) {
        if let Some(log) = self.log {
            log.note(self.site, step);
        }
    }

    /// Forgets the cuts this work took (its result is not used).
    pub fn forget_cuts(&self) {
        if let Some(log) = self.log {
            log.forget(self.site);
        }
    }

    /// Time left (zero once passed).
    pub fn remaining(&self) -> Duration {
        self.at.saturating_sub(self.clock.now())
    }

    /// Whether the deadline has passed.
    pub fn expired(&self) -> bool {
        self.clock.now() >= self.at
    }

    /// A deadline `share` (0–1) of the remaining time from now, never later than this one.
    pub fn share(&self, share: f64) -> Deadline<'c> {
        let part = self.remaining().mul_f64(share.clamp(0.0, 1.0));
        Deadline {
            at: self.clock.now().saturating_add(part),
            ..*self
        }
    }

    /// This deadline moved `by` earlier (time kept in reserve for the work after it).
    pub fn earlier(&self, by: Duration) -> Deadline<'c> {
        Deadline {
            at: self.at.saturating_sub(by),
            ..*self
        }
    }

    /// This deadline, or `other`'s time if that comes first.
    pub fn no_later_than(&self, other: &Deadline<'_>) -> Deadline<'c> {
        Deadline {
            at: self.at.min(other.at),
            ..*self
        }
    }

    /// The clock this deadline runs on.
    pub fn clock(&self) -> &'c dyn Clock {
        self.clock
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manual_deadline_expires_when_advanced() {
        let clock = ManualClock::new();
        let d = Deadline::after(&clock, Duration::from_millis(10));
        assert!(!d.expired());
        assert_eq!(d.remaining(), Duration::from_millis(10));
        let half = d.share(0.5);
        clock.advance(Duration::from_millis(6));
        assert!(half.expired() && !d.expired());
        clock.advance(Duration::from_millis(4));
        assert!(d.expired());
        assert_eq!(d.remaining(), Duration::ZERO);
    }

    #[test]
    fn an_earlier_deadline_expires_first() {
        let clock = ManualClock::new();
        let d = Deadline::after(&clock, Duration::from_millis(10));
        let e = d.earlier(Duration::from_millis(3));
        assert_eq!(e.remaining(), Duration::from_millis(7));
        clock.advance(Duration::from_millis(7));
        assert!(e.expired() && !d.expired());
        assert!(
            d.earlier(Duration::from_secs(1)).expired(),
            "saturates at zero"
        );
    }
}
