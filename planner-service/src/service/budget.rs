//! The compute gate: when may the next plan start? Two limits keep a burst of triggers
//! from starving the flight computer (issue 6, item 5):
//!
//! - a minimum spacing between the starts of two plans;
//! - a duty-cycle cap: over any sliding window of `window`, planning may use at most
//!   `duty_cycle x window` of core time. A plan is admitted only if the time already used
//!   in the window plus the most it can use fits: its budget (its deadline) times the
//!   threads it plans on (`solver.threads`: the swarm's workers and the NLP starts solved
//!   side by side each keep a core busy).
//!
//! Core time of a finished plan is what it really used: the process's CPU time over the
//! plan (`solver::process_cpu_time`), at least its wall time. Intervals are in the
//! injected clock's time (`Clock::now()`); fixed-capacity and allocation-free.

use std::time::Duration;

use wingman_ipc::config::DUTY_HISTORY;

/// Limits of the gate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GateSettings {
    pub min_spacing: Duration,
    /// Share of one core, in (0, 1].
    pub duty_cycle: f64,
    pub window: Duration,
    /// Threads a plan runs on at once (at least 1): a plan of budget `b` may use up to
    /// `threads x b` of core time.
    pub threads: u32,
}

/// One finished plan: its wall-clock interval and the core time it used.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Spent {
    start: Duration,
    end: Duration,
    core: Duration,
}

impl Spent {
    /// Core time of this plan that falls in `[from, to]`, spread evenly over its interval.
    fn within(&self, from: Duration, to: Duration) -> f64 {
        let a = self.start.max(from);
        let b = self.end.min(to);
        if b <= a {
            return 0.0;
        }
        // `b > a` within `[start, end]`: the span is positive.
        let span = self.end.saturating_sub(self.start).as_secs_f64();
        self.core.as_secs_f64() * (b - a).as_secs_f64() / span
    }
}

/// Admission of plans under the minimum spacing and the duty-cycle cap.
#[derive(Debug, Clone)]
pub struct ComputeGate {
    settings: GateSettings,
    spent: [Spent; DUTY_HISTORY],
    len: usize,
    next: usize,
    last_start: Option<Duration>,
}

impl ComputeGate {
    pub fn new(settings: GateSettings) -> Self {
        ComputeGate {
            settings,
            spent: [Spent::default(); DUTY_HISTORY],
            len: 0,
            next: 0,
            last_start: None,
        }
    }

    /// The settings.
    pub fn settings(&self) -> &GateSettings {
        &self.settings
    }

    /// Core time the window may hold.
    pub fn cap(&self) -> Duration {
        self.settings.window.mul_f64(self.settings.duty_cycle)
    }

    /// Core time used by finished plans in the window ending at `now`.
    pub fn used(&self, now: Duration) -> Duration {
        let from = now.saturating_sub(self.settings.window);
        let s: f64 = self.spent[..self.len]
            .iter()
            .map(|p| p.within(from, now))
            .sum();
        Duration::from_secs_f64(s.max(0.0))
    }

    /// Core time left in the window ending at `now`.
    pub fn remaining(&self, now: Duration) -> Duration {
        self.cap().saturating_sub(self.used(now))
    }

    /// The most core time a plan of `budget` can use.
    pub fn worst_case(&self, budget: Duration) -> Duration {
        budget.saturating_mul(self.settings.threads.max(1))
    }

    /// Whether a plan of `budget` may start at `now`.
    pub fn admits(&self, now: Duration, budget: Duration) -> bool {
        let spaced = self
            .last_start
            .is_none_or(|s| now >= s.saturating_add(self.settings.min_spacing));
        spaced && self.used(now).saturating_add(self.worst_case(budget)) <= self.cap()
    }

    /// The earliest time at or after `now` at which a plan of `budget` may start, if no
    /// other plan starts before; `None` if the budget alone exceeds the cap.
    pub fn earliest_start(&self, now: Duration, budget: Duration) -> Option<Duration> {
        let need = self.worst_case(budget);
        if need > self.cap() {
            return None;
        }
        let spaced = match self.last_start {
            Some(s) => now.max(s.saturating_add(self.settings.min_spacing)),
            None => now,
        };
        let fits = |t: Duration| self.used(t).saturating_add(need) <= self.cap();
        if fits(spaced) {
            return Some(spaced);
        }
        // `used` does not grow after `spaced` (no plan runs meanwhile) and is zero once the
        // window has slid past every recorded plan: bisect to 1 microsecond.
        let latest_end = self.spent[..self.len]
            .iter()
            .map(|p| p.end)
            .max()
            .unwrap_or(spaced);
        let (mut lo, mut hi) = (spaced, latest_end.max(spaced) + self.settings.window);
        while hi.saturating_sub(lo) > Duration::from_micros(1) {
            let mid = lo + (hi - lo) / 2;
            if fits(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Some(hi)
    }

    /// A plan starts now.
    pub fn begin(&mut self, now: Duration) {
        self.last_start = Some(now);
    }

    /// A plan ran from `start` to `end` on the injected clock, using `core` core time.
    pub fn record(&mut self, start: Duration, end: Duration, core: Duration) {
        self.spent[self.next] = Spent {
            start,
            end: end.max(start),
            core,
        };
        self.next = (self.next + 1) % DUTY_HISTORY;
        self.len = (self.len + 1).min(DUTY_HISTORY);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: u64) -> Duration {
        Duration::from_millis(v)
    }

    fn gate() -> ComputeGate {
        ComputeGate::new(GateSettings {
            min_spacing: ms(200),
            duty_cycle: 0.5,
            window: ms(1000),
            threads: 1,
        })
    }

    /// B5: a plan on two threads can use twice its budget of core time: it is admitted
    /// only if twice its budget fits under the cap.
    #[test]
    fn admission_counts_every_thread_of_a_plan() {
        let mut g = ComputeGate::new(GateSettings {
            min_spacing: ms(0),
            duty_cycle: 0.5,
            window: ms(1000),
            threads: 2,
        });
        assert!(g.admits(ms(0), ms(250)), "2 x 250 ms fits the 500 ms cap");
        assert!(!g.admits(ms(0), ms(251)));
        assert_eq!(g.earliest_start(ms(0), ms(300)), None, "600 ms never fits");
        g.record(ms(0), ms(100), ms(200));
        assert!(g.admits(ms(100), ms(150)) && !g.admits(ms(100), ms(151)));
    }

    #[test]
    fn spacing_defers_the_next_start() {
        let mut g = gate();
        assert!(g.admits(ms(0), ms(100)));
        g.begin(ms(0));
        g.record(ms(0), ms(50), ms(50));
        assert!(!g.admits(ms(199), ms(100)));
        assert!(g.admits(ms(200), ms(100)));
        assert_eq!(g.earliest_start(ms(60), ms(100)), Some(ms(200)));
    }

    #[test]
    fn duty_cycle_defers_until_the_window_slides() {
        let mut g = gate();
        // 400 ms of core time in [0, 400]: 100 ms left of the 500 ms cap.
        g.begin(ms(0));
        g.record(ms(0), ms(400), ms(400));
        assert_eq!(g.remaining(ms(400)), ms(100));
        assert!(g.admits(ms(400), ms(100)));
        assert!(!g.admits(ms(400), ms(150)));
        // 150 ms fits once 50 ms of the plan left the window: at t = 1050.
        let t = g.earliest_start(ms(400), ms(150)).unwrap();
        assert!((t.as_secs_f64() - 1.05).abs() < 1e-5, "{t:?}");
        assert!(g.admits(t, ms(150)) && !g.admits(t - ms(1), ms(150)));
        // A budget over the cap never fits.
        assert_eq!(g.earliest_start(ms(400), ms(600)), None);
    }

    #[test]
    fn core_time_counts_parallel_stages() {
        let mut g = gate();
        // 200 ms wall, 300 ms of core time (a swarm stage on two threads).
        g.record(ms(0), ms(200), ms(300));
        assert_eq!(g.used(ms(200)), ms(300));
        // Half of it has left the window at t = 1100.
        let used = g.used(ms(1100)).as_secs_f64();
        assert!((used - 0.15).abs() < 1e-9, "{used}");
    }
}
