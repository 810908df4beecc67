//! The harness's mission clock: how mission time advances against the wall clock, and
//! periodic schedules on mission time.
//!
//! - [`ClockMode::Fast`]: lock-step. Mission time advances in fixed steps as fast as the
//!   planner allows: after each step's inputs the harness waits until the planner's status
//!   echoes the step's last input sequence and the planner is idle. A plan's measured
//!   compute time is charged to mission time: the tracker may fly a re-plan only from
//!   `created_at + compute` on, as it could in a real-time flight.
//! - [`ClockMode::Realtime`] and [`ClockMode::Scaled`]: mission time follows the wall
//!   clock (K times faster); the harness never waits for the planner.

use std::fmt;
use std::str::FromStr;
use std::time::{Duration, Instant};

/// How mission time advances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClockMode {
    /// Lock-step, as fast as possible, compute time charged to mission time.
    Fast,
    /// One mission second per wall second.
    Realtime,
    /// K mission seconds per wall second (`x<K>` on the command line, K > 0).
    Scaled(f64),
}

/// A `--clock` value that is not `fast`, `realtime` or `x<K>`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("clock `{0}`: expected `fast`, `realtime` or `x<K>` with K > 0 (e.g. `x10`)")]
pub struct ClockParseError(pub String);

impl FromStr for ClockMode {
    type Err = ClockParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "fast" => Ok(ClockMode::Fast),
            "realtime" => Ok(ClockMode::Realtime),
            _ => {
                let k = s
                    .strip_prefix('x')
                    .and_then(|k| k.parse::<f64>().ok())
                    .filter(|k| k.is_finite() && *k > 0.0)
                    .ok_or_else(|| ClockParseError(s.to_string()))?;
                Ok(ClockMode::Scaled(k))
            }
        }
    }
}

impl fmt::Display for ClockMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ClockMode::Fast => write!(f, "fast"),
            ClockMode::Realtime => write!(f, "realtime"),
            ClockMode::Scaled(k) => write!(f, "x{k}"),
        }
    }
}

impl ClockMode {
    /// Whether the harness waits for the planner after each step.
    pub fn is_lock_step(&self) -> bool {
        matches!(self, ClockMode::Fast)
    }

    /// Mission seconds per wall second (`None` for the lock-step clock).
    pub fn rate(&self) -> Option<f64> {
        match self {
            ClockMode::Fast => None,
            ClockMode::Realtime => Some(1.0),
            ClockMode::Scaled(k) => Some(*k),
        }
    }
}

/// Paces mission time against the wall clock (a no-op for the lock-step clock).
#[derive(Debug, Clone, Copy)]
pub struct Pacer {
    mode: ClockMode,
    wall_start: Instant,
    mission_start: f64,
}

impl Pacer {
    /// Mission time `mission_start` is now.
    pub fn new(mode: ClockMode, mission_start: f64) -> Pacer {
        Pacer {
            mode,
            wall_start: Instant::now(),
            mission_start,
        }
    }

    /// How long to wait from `elapsed` wall time since the start until mission time `t`
    /// is due (zero when it is due already or the clock is lock-step).
    pub fn wait_for(&self, t: f64, elapsed: Duration) -> Duration {
        match self.mode.rate() {
            None => Duration::ZERO,
            Some(k) => {
                let due = ((t - self.mission_start) / k).max(0.0);
                Duration::from_secs_f64(due).saturating_sub(elapsed)
            }
        }
    }

    /// Sleeps until mission time `t` is due.
    pub fn sleep_until(&self, t: f64) {
        let wait = self.wait_for(t, self.wall_start.elapsed());
        if !wait.is_zero() {
            std::thread::sleep(wait);
        }
    }
}

/// A periodic schedule on mission time: due at `first`, `first + period`, ….
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Periodic {
    period: f64,
    next: f64,
}

impl Periodic {
    /// Due first at `first`, then every `period > 0` seconds.
    pub fn new(first: f64, period: f64) -> Periodic {
        Periodic {
            period,
            next: first,
        }
    }

    /// The schedule `first + k period` taken up at `from` (a resumed flight): its next tick
    /// is the first one at or after `from` (within 1 µs).
    pub fn resumed(first: f64, period: f64, from: f64) -> Periodic {
        let k = ((from - first - 1e-6) / period).ceil().max(0.0);
        Periodic {
            period,
            next: first + k * period,
        }
    }

    /// Whether a tick falls at or before `t` (within 1 µs); takes at most one tick per call,
    /// so a step longer than the period yields one tick per step and keeps the rest for
    /// later steps.
    pub fn due(&mut self, t: f64) -> Option<f64> {
        if t + 1e-6 >= self.next {
            let at = self.next;
            self.next += self.period;
            Some(at)
        } else {
            None
        }
    }

    /// The next tick.
    pub fn next(&self) -> f64 {
        self.next
    }
}

/// Mission time of step `k` of length `dt` from `t0` (no drift from summing steps).
pub fn step_time(t0: f64, dt: f64, k: u64) -> f64 {
    t0 + dt * k as f64
}
