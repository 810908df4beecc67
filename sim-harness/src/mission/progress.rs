//! The progress line of a flight on stderr.

use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

use wingman_planning::scenario::Scenario;

use crate::tracker::InnerLoop;

/// The progress line: mission time, phase, plan flown, re-plans so far.
pub(super) struct Progress {
    on: bool,
    tty: bool,
    last: Option<Instant>,
    last_t: f64,
}

impl Progress {
    pub(super) fn new(on: bool) -> Progress {
        Progress {
            on,
            tty: std::io::stderr().is_terminal(),
            last: None,
            last_t: f64::NEG_INFINITY,
        }
    }

    pub(super) fn show(&mut self, sc: &Scenario, t: f64, tracker: &InnerLoop, last: bool) {
        if !self.on {
            return;
        }
        let due = if self.tty {
            self.last
                .is_none_or(|l| l.elapsed() > Duration::from_millis(200))
        } else {
            t - self.last_t >= 60.0
        };
        if !due && !last {
            return;
        }
        self.last = Some(Instant::now());
        self.last_t = t;
        let phase = match tracker.flying() {
            None => "waiting for the first plan".to_string(),
            Some(p) => {
                let ends = p.plan.phase_ends();
                let left = ends.iter().filter(|&&e| e > t).count();
                let goal = match sc.objective {
                    wingman_interfaces::Objective::MinTimeRendezvous => "rendezvous",
                    _ => "final point",
                };
                if left > 1 {
                    format!("{} target(s) left, then the {goal}", left - 1)
                } else {
                    format!("last leg, to the {goal}")
                }
            }
        };
        let plans = tracker.plans().len();
        let flying = tracker.flying().map_or(0, |p| p.plan.plan_id);
        let hold = if tracker.holding() { "  HOLD" } else { "" };
        let line = format!(
            "{}  t = {t:7.1} s  {phase:<34}  plan {flying} ({} re-plans){hold}",
            sc.name,
            plans.saturating_sub(1)
        );
        let mut err = std::io::stderr();
        if self.tty {
            let _ = write!(err, "\r{line:<110}");
            if last {
                let _ = writeln!(err);
            }
        } else {
            let _ = writeln!(err, "{line}");
        }
    }
}
