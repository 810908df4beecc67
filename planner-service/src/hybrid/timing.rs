//! What the planner learns of its NLP solves' timing, to keep its deadline: a solve is
//! not started without time for its set-up, and stops while an iteration and its
//! wrap-up still fit. Iterations are the longest on the largest meshes (the refined one
//! has three times the ranking mesh's variables), so they are learned per variable.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Timing of the NLP solves (the longest seen).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct SolveTiming {
    /// From the start of a solve to the end of its first iteration (the transcription,
    /// the solver's set-up, the first factorisation).
    pub setup: Duration,
    /// An iteration (after the first), per variable of the NLP, in seconds.
    pub per_var: f64,
    /// From the end of the last iteration to the solve's return.
    pub wrap_up: Duration,
}

impl SolveTiming {
    /// The estimate of a planner that has not solved yet (`three_d`: of the 3-D model):
    /// about the longest set-up, iteration and wrap-up of the canonical scenarios' solves
    /// on the slower of the hosts measured (a 2.3 GHz Xeon VM, 2026-12-03: 2-D set-up
    /// 2.2-5.2 ms, 3.4-16 us per variable, wrap-up 0.8-1.5 ms; 3-D 5.5-14 ms, 5-15 us,
    /// 3.8-10 ms). Without it the first plan starts its solves blind: under a 5 ms budget
    /// a fresh 2-D planner returned after 10.7 ms. A faster host replaces it after the
    /// first plan that solves (see [`SolveTiming::after`]); a plan that may start no solve
    /// lowers it by a tenth.
    pub fn prior(three_d: bool) -> SolveTiming {
        if three_d {
            SolveTiming {
                setup: Duration::from_millis(12),
                per_var: 12e-6,
                wrap_up: Duration::from_millis(6),
            }
        } else {
            SolveTiming {
                setup: Duration::from_millis(5),
                per_var: 8e-6,
                wrap_up: Duration::from_micros(1500),
            }
        }
    }

    /// Whether `remaining` leaves time for one solve: its set-up and its wrap-up.
    pub fn fits_a_solve(&self, remaining: Duration) -> bool {
        remaining > self.setup + self.wrap_up
    }

    /// The longer of each.
    pub fn max(self, other: SolveTiming) -> SolveTiming {
        SolveTiming {
            setup: self.setup.max(other.setup),
            per_var: self.per_var.max(other.per_var),
            wrap_up: self.wrap_up.max(other.wrap_up),
        }
    }

    /// The expected iteration of an NLP of `vars` variables.
    pub fn iteration(&self, vars: usize) -> Duration {
        Duration::from_secs_f64(self.per_var * vars as f64)
    }

    /// The estimate after a plan that saw `seen`: what it saw, forgetting older, slower
    /// plans slowly (halved each plan); after a plan that started no solve (no time),
    /// lowered by a tenth, so that a later plan tries again.
    pub fn after(self, seen: SolveTiming) -> SolveTiming {
        if seen.setup > Duration::ZERO {
            seen.max(SolveTiming {
                setup: self.setup / 2,
                per_var: self.per_var / 2.0,
                wrap_up: self.wrap_up / 2,
            })
        } else {
            SolveTiming {
                setup: self.setup.mul_f64(0.9),
                per_var: self.per_var * 0.9,
                wrap_up: self.wrap_up.mul_f64(0.9),
            }
        }
    }
}

/// The timing seen in one plan, raised by its solves as they end (from any thread).
#[derive(Debug, Default)]
pub(super) struct Seen {
    setup_ns: AtomicU64,
    /// `f64` bits: for non-negative values their order is the numbers' order.
    per_var_bits: AtomicU64,
    wrap_up_ns: AtomicU64,
}

impl Seen {
    /// Records one solve's timing.
    pub fn record(&self, t: SolveTiming) {
        let ns = |d: Duration| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX);
        self.setup_ns.fetch_max(ns(t.setup), Ordering::Relaxed);
        if t.per_var.is_finite() && t.per_var > 0.0 {
            self.per_var_bits
                .fetch_max(t.per_var.to_bits(), Ordering::Relaxed);
        }
        self.wrap_up_ns.fetch_max(ns(t.wrap_up), Ordering::Relaxed);
    }

    /// The longest of each seen so far.
    pub fn get(&self) -> SolveTiming {
        SolveTiming {
            setup: Duration::from_nanos(self.setup_ns.load(Ordering::Relaxed)),
            per_var: f64::from_bits(self.per_var_bits.load(Ordering::Relaxed)),
            wrap_up: Duration::from_nanos(self.wrap_up_ns.load(Ordering::Relaxed)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: u64) -> Duration {
        Duration::from_millis(v)
    }

    #[test]
    fn seen_keeps_the_longest_of_each_from_any_thread() {
        let seen = Seen::default();
        assert_eq!(seen.get(), SolveTiming::default());
        std::thread::scope(|s| {
            for k in 1..=4u64 {
                let seen = &seen;
                s.spawn(move || {
                    seen.record(SolveTiming {
                        setup: ms(k),
                        per_var: 1e-6 * (5 - k) as f64,
                        wrap_up: ms(10 * (k % 2)),
                    })
                });
            }
        });
        let got = seen.get();
        assert_eq!(got.setup, ms(4));
        assert_eq!(got.per_var, 4e-6);
        assert_eq!(got.wrap_up, ms(10));
        // An iteration of 1000 variables at 4 us each: 4 ms.
        assert_eq!(got.iteration(1000), ms(4));
        // A non-finite or negative rate is not recorded.
        seen.record(SolveTiming {
            per_var: f64::INFINITY,
            ..SolveTiming::default()
        });
        seen.record(SolveTiming {
            per_var: -1.0,
            ..SolveTiming::default()
        });
        assert_eq!(seen.get().per_var, 4e-6);
    }

    #[test]
    fn the_estimate_forgets_slow_plans_by_halves_and_retries_after_none() {
        let old = SolveTiming {
            setup: ms(8),
            per_var: 2e-6,
            wrap_up: ms(2),
        };
        let seen = SolveTiming {
            setup: ms(3),
            per_var: 3e-6,
            wrap_up: ms(0),
        };
        let next = old.after(seen);
        assert_eq!(next.setup, ms(4));
        assert_eq!(next.per_var, 3e-6);
        assert_eq!(next.wrap_up, ms(1));
        // No solve started: every part a tenth lower.
        let idle = old.after(SolveTiming::default());
        assert_eq!(idle.setup, ms(8).mul_f64(0.9));
        assert!((idle.per_var - 1.8e-6).abs() < 1e-18);
        assert_eq!(idle.wrap_up, ms(2).mul_f64(0.9));
    }

    #[test]
    fn a_solve_fits_only_past_its_set_up_and_wrap_up() {
        let t = SolveTiming {
            setup: ms(5),
            per_var: 1e-6,
            wrap_up: ms(2),
        };
        assert!(
            !t.fits_a_solve(Duration::ZERO),
            "an expired deadline fits none"
        );
        assert!(!t.fits_a_solve(ms(7)));
        assert!(t.fits_a_solve(ms(7) + Duration::from_nanos(1)));
        // Each prior leaves a short budget without a solve, a long one with.
        for three_d in [false, true] {
            let p = SolveTiming::prior(three_d);
            assert!(!p.fits_a_solve(ms(2)) && p.fits_a_solve(ms(100)));
        }
    }
}
