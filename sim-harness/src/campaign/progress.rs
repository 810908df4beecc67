//! A campaign's progress on stderr: missions done, how many failed, time so far and an
//! estimate of the time left (the mean wall time per mission so far, times what is left).
//! On a terminal one line redrawn in place; otherwise a line every 5 % or minute.

use std::io::{IsTerminal, Write};
use std::time::{Duration, Instant};

use super::outcome::MissionOutcome;

/// The progress of one run.
pub struct Progress {
    on: bool,
    tty: bool,
    total: usize,
    done: usize,
    failed: usize,
    started: Instant,
    last_line: Instant,
    last_done: usize,
}

impl Progress {
    pub fn new(on: bool, total: usize) -> Progress {
        let now = Instant::now();
        Progress {
            on,
            tty: std::io::stderr().is_terminal(),
            total,
            done: 0,
            failed: 0,
            started: now,
            last_line: now,
            last_done: 0,
        }
    }

    /// Counts a mission and shows the line when it is due; a failed mission also gets a
    /// line of its own.
    pub fn done(&mut self, o: &MissionOutcome) {
        self.done += 1;
        if !o.meets_criteria() {
            self.failed += 1;
        }
        if !self.on {
            return;
        }
        if !o.meets_criteria() {
            self.clear_line();
            eprintln!("{}: {}", o.name, o.misses.join("; "));
        }
        let step = (self.total / 20).max(1);
        let due = self.tty
            || self.done - self.last_done >= step
            || self.last_line.elapsed() >= Duration::from_secs(60)
            || self.done == self.total;
        if due {
            self.show();
        }
    }

    /// Ends the line on a terminal.
    pub fn finish(&self) {
        if self.on && self.tty {
            eprintln!();
        }
    }

    fn show(&mut self) {
        let line = self.line();
        if self.tty {
            eprint!("\r{line}\x1b[K");
            let _ = std::io::stderr().flush();
        } else {
            eprintln!("{line}");
        }
        self.last_line = Instant::now();
        self.last_done = self.done;
    }

    fn clear_line(&self) {
        if self.tty {
            eprint!("\r\x1b[K");
        }
    }

    /// `campaign [#####.....] 37/125  30 %  1 failed  3m12s  ETA 7m40s`.
    fn line(&self) -> String {
        let elapsed = self.started.elapsed();
        let share = self.done as f64 / self.total.max(1) as f64;
        let width = 20;
        let filled = (share * width as f64).round() as usize;
        let eta = if self.done == 0 {
            "?".to_string()
        } else {
            let per = elapsed.as_secs_f64() / self.done as f64;
            clock_time((self.total - self.done) as f64 * per)
        };
        format!(
            "campaign [{}{}] {}/{} {:3.0} %  {} failed  {}  ETA {eta}",
            "#".repeat(filled),
            ".".repeat(width - filled.min(width)),
            self.done,
            self.total,
            100.0 * share,
            self.failed,
            clock_time(elapsed.as_secs_f64())
        )
    }
}

/// `1h02m`, `3m12s` or `42s`.
pub fn clock_time(s: f64) -> String {
    let s = s.max(0.0).round() as u64;
    if s >= 3600 {
        format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
    } else if s >= 60 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{s}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_read_as_clocks() {
        assert_eq!(clock_time(42.4), "42s");
        assert_eq!(clock_time(192.0), "3m12s");
        assert_eq!(clock_time(3720.0), "1h02m");
    }
}
