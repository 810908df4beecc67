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

/// What the planner learns of its NLP stage as a whole. The stage yields a plan only after
/// every start is ranked and a finalist's solve has run (the finalists are chosen on all
/// the ranks), so a budget that cannot hold the ranking is better spent on the swarm: the
/// NLP is not started, and the swarm runs until the fallback must be built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct StageTiming {
    /// How long the ranking step takes (every start, on the planner's threads).
    pub ranking: Duration,
    /// Building the fallback: the swarm's path resampled (and in 3-D flown).
    pub fallback: Duration,
    /// The least the ranking estimate comes down to while no plan tries the stage: half
    /// the prior's, so that a budget far below any ranking never tries a stage it cannot
    /// finish.
    floor: Duration,
}

/// How a plan's ranking step ended, for [`StageTiming::after`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Ranking {
    /// Not started (no time for the stage).
    Skipped,
    /// Every start ranked, in this long.
    Done(Duration),
    /// The stage ran out of time before it had a plan, after this long.
    Cut(Duration),
}

impl StageTiming {
    /// The estimate of a planner that has not planned yet (`three_d`: of the 3-D model):
    /// below the shortest rankings of the canonical scenarios (2-D 25-50 ms on a 2.6 GHz
    /// EPYC, 40-110 ms on a 2.3 GHz Xeon VM; 3-D 55-220 ms and 90-300 ms), so that a
    /// budget that might hold the stage tries it; the fallback about the longest seen
    /// on the Xeon (2-D 0.1-0.3 ms, 3-D 0.5-2 ms).
    pub fn prior(three_d: bool) -> StageTiming {
        let (ranking, fallback) = if three_d {
            (Duration::from_millis(50), Duration::from_millis(2))
        } else {
            (Duration::from_millis(20), Duration::from_micros(500))
        };
        StageTiming {
            ranking,
            fallback,
            floor: ranking / 2,
        }
    }

    /// Whether `remaining` (after the swarm) leaves time for the stage to yield a plan:
    /// the ranking, then one solve's set-up and wrap-up (`solves`).
    pub fn fits_the_stage(&self, solves: &SolveTiming, remaining: Duration) -> bool {
        remaining > self.ranking && solves.fits_a_solve(remaining - self.ranking)
    }

    /// The estimate after a plan whose ranking ended as `ranking` and whose fallback took
    /// `fallback`. A ranking done: its time (not under the floor: a ranking whose solves
    /// failed fast says little). A stage that ran out of time: at least twice what it had
    /// (the next tries wait until the estimate has come down again). None: a tenth lower,
    /// down to the floor, so that a later plan tries again (a host that was slow for a
    /// while is tried again). The fallback: the longer of this one and half the
    /// estimate.
    pub fn after(self, ranking: Ranking, fallback: Duration) -> StageTiming {
        StageTiming {
            ranking: match ranking {
                Ranking::Skipped => self.ranking.mul_f64(0.9).max(self.floor),
                Ranking::Done(d) => d.max(self.floor),
                Ranking::Cut(d) => self.ranking.max(d * 2),
            },
            fallback: fallback.max(self.fallback / 2),
            floor: self.floor,
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

    fn solves(setup_ms: u64, per_var: f64, wrap_up_ms: u64) -> SolveTiming {
        SolveTiming {
            setup: ms(setup_ms),
            per_var,
            wrap_up: ms(wrap_up_ms),
        }
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
        let old = solves(8, 2e-6, 2);
        let seen = solves(3, 3e-6, 0);
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
    fn the_stage_fits_only_past_the_ranking_and_a_solve() {
        let t = solves(5, 1e-6, 2);
        let stage = StageTiming {
            ranking: ms(30),
            fallback: ms(1),
            floor: ms(10),
        };
        assert!(!stage.fits_the_stage(&t, ms(37)));
        assert!(stage.fits_the_stage(&t, ms(37) + Duration::from_nanos(1)));
        // The priors: a 5 ms budget holds no stage, a second does.
        for three_d in [false, true] {
            let p = StageTiming::prior(three_d);
            let s = SolveTiming::prior(three_d);
            assert!(!p.fits_the_stage(&s, ms(5)) && p.fits_the_stage(&s, ms(1000)));
        }
    }

    #[test]
    fn the_ranking_estimate_follows_done_backs_off_when_cut_and_decays_to_its_floor() {
        let stage = StageTiming::prior(false);
        assert_eq!(stage.floor, stage.ranking / 2);
        // Done: what it took, but not under the floor.
        let done = stage.after(Ranking::Done(ms(42)), ms(1));
        assert_eq!(done.ranking, ms(42));
        assert_eq!(
            stage.after(Ranking::Done(ms(3)), ms(1)).ranking,
            stage.floor
        );
        // Cut after 15 ms: at least 30.
        assert_eq!(stage.after(Ranking::Cut(ms(15)), ms(1)).ranking, ms(30));
        assert_eq!(done.after(Ranking::Cut(ms(15)), ms(1)).ranking, ms(42));
        // Skipped: a tenth lower each time, never under the floor.
        let once = done.after(Ranking::Skipped, ms(1));
        assert_eq!(once.ranking, ms(42).mul_f64(0.9));
        let mut s = done;
        for _ in 0..100 {
            s = s.after(Ranking::Skipped, ms(1));
        }
        assert_eq!(s.ranking, stage.floor);
        // The fallback: this one's, or half the estimate if that is longer.
        assert_eq!(stage.after(Ranking::Skipped, ms(2)).fallback, ms(2));
        assert_eq!(
            stage.after(Ranking::Skipped, Duration::ZERO).fallback,
            stage.fallback / 2
        );
    }

    #[test]
    fn a_solve_fits_only_past_its_set_up_and_wrap_up() {
        let t = solves(5, 1e-6, 2);
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
