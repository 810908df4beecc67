//! Deadline cuts: where a plan's deadline changed the course of its computation, recorded
//! so that a replay takes the same course.
//!
//! A plan that runs to its end is a function of its inputs and seed. Under a short budget
//! the deadline decides too: the swarm stops after so many rounds, a solve after so many
//! iterations, a start is not solved at all, the floor runs, the global search is skipped.
//! Those choices depend on the machine's speed at the time. Every place where one is taken
//! asks its [`Deadline`](crate::clock::Deadline) through
//! [`Deadline::cuts`](crate::clock::Deadline::cuts), naming the work ([`Site`]) and how far
//! it got (a step): that is a function of the inputs too, so the same site and step come
//! up in a replay.
//!
//! - **Recording** (a flight): the answer is the clock's, and each "yes" is kept as a
//!   [`Cut`]. The service puts a plan's cuts into its `Plan` message.
//! - **Replaying**: the answer is whether the logged plan has that cut; the clock is not
//!   asked (a replay runs with no deadline). A site with no logged cut runs to its end, as
//!   it did in the flight.
//!
//! Only a "yes" is recorded: the course a computation takes with no deadline is the
//! default, so a plan the deadline never touched has no cuts. The cuts of one plan are
//! sorted (they are recorded on several threads, in whatever order they came).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Which path of a plan the work belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Part {
    /// The plan as a whole (which paths run).
    Plan,
    /// A re-plan's warm path.
    Warm,
    /// The global search.
    Global,
    /// Wave `k` (from 1) of a plan from scratch: the next starts, solved with the time
    /// the global search left (`hybrid::waves`).
    Wave(u8),
}

impl Part {
    /// The part's 8-bit code: 0-2, then 2 + k for wave k.
    fn code(self) -> u32 {
        match self {
            Part::Plan => 0,
            Part::Warm => 1,
            Part::Global => 2,
            Part::Wave(k) => 2 + u32::from(k.max(1)),
        }
    }
}

/// A piece of work the deadline may cut, within its [`Part`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Work {
    /// The whole of a path (the plan; the choice to run the global search at all).
    Whole,
    /// Building the seeds (step: specs tried).
    Seeds,
    /// Scoring the seeds on worker thread `t` (step: seeds scored).
    SeedScores(u8),
    /// The swarm's rounds (step: iterations done).
    SwarmRounds,
    /// The choice to run the floor first (step 0).
    Floor,
    /// The floor's solve.
    FloorSolve,
    /// The NLP stage as a whole (cut at step 0: not run).
    NlpStage,
    /// The ranking solve of start `i`.
    Rank(u16),
    /// The final solve of candidate `c`.
    Final(u16),
    /// Refinement round `round` after candidate `c`'s final.
    Round { candidate: u8, round: u8 },
    /// The choice to run the winner's first round (step 0).
    WinnerRound,
    /// The rounds after the first (step: the round about to start).
    Refinement,
}

/// Where a cut is taken: a piece of work of a path. Encoded in 32 bits on the wire
/// (`Plan::cuts`): the part in bits 24–31, the kind of work in 16–23, its index in 0–15.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Site {
    pub part: Part,
    pub work: Work,
}

impl Site {
    /// The plan as a whole.
    pub const PLAN: Site = Site {
        part: Part::Plan,
        work: Work::Whole,
    };

    /// The 32-bit code of this site.
    pub fn code(self) -> u32 {
        let (kind, index): (u32, u32) = match self.work {
            Work::Whole => (0, 0),
            Work::Seeds => (1, 0),
            Work::SeedScores(t) => (2, u32::from(t)),
            Work::SwarmRounds => (3, 0),
            Work::Floor => (4, 0),
            Work::FloorSolve => (5, 0),
            Work::NlpStage => (6, 0),
            Work::Rank(i) => (7, u32::from(i)),
            Work::Final(c) => (8, u32::from(c)),
            Work::Round { candidate, round } => (9, u32::from(candidate) << 8 | u32::from(round)),
            Work::WinnerRound => (10, 0),
            Work::Refinement => (11, 0),
        };
        self.part.code() << 24 | kind << 16 | index
    }

    /// The site of a 32-bit code (`None`: no site has it).
    pub fn from_code(code: u32) -> Option<Site> {
        let part = match code >> 24 {
            0 => Part::Plan,
            1 => Part::Warm,
            2 => Part::Global,
            k @ 3..=255 => Part::Wave((k - 2) as u8),
            _ => return None,
        };
        let index = code & 0xffff;
        let small = u8::try_from(index).ok();
        let work = match (code >> 16) & 0xff {
            0 if index == 0 => Work::Whole,
            1 if index == 0 => Work::Seeds,
            2 => Work::SeedScores(small?),
            3 if index == 0 => Work::SwarmRounds,
            4 if index == 0 => Work::Floor,
            5 if index == 0 => Work::FloorSolve,
            6 if index == 0 => Work::NlpStage,
            7 => Work::Rank(index as u16),
            8 => Work::Final(index as u16),
            9 => Work::Round {
                candidate: (index >> 8) as u8,
                round: (index & 0xff) as u8,
            },
            10 if index == 0 => Work::WinnerRound,
            11 if index == 0 => Work::Refinement,
            _ => return None,
        };
        Some(Site { part, work })
    }

    /// This site's part with another piece of work.
    pub fn with(self, work: Work) -> Site {
        Site { work, ..self }
    }
}

/// The deadline cut the work at `site` at `step` (the site's count of what it had done:
/// iterations, rounds, seeds; 0 for a choice or for work not started).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Cut {
    pub site: Site,
    pub step: u32,
}

impl std::fmt::Display for Cut {
    /// `part/work@step`, as logs show it: `Global/Whole@0`, `Warm/Rank(2)@14`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?}/{:?}@{}", self.site.part, self.site.work, self.step)
    }
}

/// Cuts as logs show them: space-separated (`-` for none).
pub struct CutList<'a>(pub &'a [Cut]);

impl std::fmt::Display for CutList<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.is_empty() {
            return write!(f, "-");
        }
        for (k, c) in self.0.iter().enumerate() {
            if k > 0 {
                write!(f, " ")?;
            }
            write!(f, "{c}")?;
        }
        Ok(())
    }
}

/// What a [`CutLog`] does during one plan.
#[derive(Debug)]
enum Mode {
    /// The clock answers; its cuts are kept.
    Recording,
    /// The logged cuts answer (sorted).
    Replaying(Vec<Cut>),
}

#[derive(Debug)]
struct State {
    mode: Mode,
    taken: Vec<Cut>,
}

/// The cuts of the plan in hand: recorded in a flight, or replayed from a logged plan.
/// One per solve thread; [`CutLog::begin`] starts each plan, [`CutLog::finish`] ends it.
#[derive(Debug)]
pub struct CutLog {
    state: Mutex<State>,
}

/// Cuts a plan takes at most before recording them allocates (a plan has a few dozen
/// sites).
const RESERVED: usize = 128;

impl Default for CutLog {
    fn default() -> Self {
        CutLog {
            state: Mutex::new(State {
                mode: Mode::Recording,
                taken: Vec::with_capacity(RESERVED),
            }),
        }
    }
}

impl CutLog {
    pub fn new() -> Self {
        Self::default()
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Starts a plan: recording its cuts, or (`Some`) replaying these.
    pub fn begin(&self, replay: Option<&[Cut]>) {
        let mut state = self.lock();
        state.taken.clear();
        state.mode = match replay {
            Some(cuts) => {
                let mut cuts = cuts.to_vec();
                cuts.sort_unstable();
                cuts.dedup();
                Mode::Replaying(cuts)
            }
            None => Mode::Recording,
        };
    }

    /// Whether this plan replays logged cuts (then deadlines are not read).
    pub fn replaying(&self) -> bool {
        matches!(self.lock().mode, Mode::Replaying(_))
    }

    /// Ends a plan: its cuts, sorted. (Replaying, the logged cuts the plan took: all of
    /// them when it took the logged course.)
    pub fn finish(&self) -> Vec<Cut> {
        let mut state = self.lock();
        let mut cuts = std::mem::take(&mut state.taken);
        state.taken = Vec::with_capacity(RESERVED);
        cuts.sort_unstable();
        cuts.dedup();
        cuts
    }

    /// Whether the work at `site` is cut at `step`: recording, `live()` (the clock's
    /// answer), kept if yes; replaying, whether the logged plan was cut there.
    pub(crate) fn cuts(&self, site: Site, step: u32, live: impl FnOnce() -> bool) -> bool {
        let cut = Cut { site, step };
        {
            let mut guard = self.lock();
            let state = &mut *guard;
            if let Mode::Replaying(logged) = &state.mode {
                let taken = logged.binary_search(&cut).is_ok();
                if taken {
                    state.taken.push(cut);
                }
                return taken;
            }
        }
        // The clock is read outside the lock: several threads ask at once.
        let taken = live();
        if taken {
            self.lock_taken(cut);
        }
        taken
    }

    /// Records a cut the work took by other means (the solver's own wall-time limit).
    pub(crate) fn note(&self, site: Site, step: u32) {
        let mut state = self.lock();
        if matches!(state.mode, Mode::Recording) {
            state.taken.push(Cut { site, step });
        }
    }

    /// Forgets the cuts taken at `site` (work whose result is not used: a replay need not
    /// run it).
    pub(crate) fn forget(&self, site: Site) {
        self.lock().taken.retain(|c| c.site != site);
    }

    fn lock_taken(&self, cut: Cut) {
        self.lock().taken.push(cut);
    }
}

/// The logged cuts of a flight's plans, by plan id: what a replay hands the planner
/// (`wingman-planner serve --replay-cuts FILE`). A plan with no entry was not cut.
///
/// The file is text, one plan per line: its id, then each cut as `site:step` with the site
/// in hexadecimal (its 32-bit code); `#` starts a comment.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ReplayCuts {
    plans: BTreeMap<u64, Vec<Cut>>,
}

/// A replay-cuts file that cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {problem}")]
pub struct ReplayCutsError {
    pub line: usize,
    pub problem: String,
}

impl ReplayCuts {
    /// Adds plan `plan_id`'s cuts (replacing any it had).
    pub fn insert(&mut self, plan_id: u64, cuts: Vec<Cut>) {
        self.plans.insert(plan_id, cuts);
    }

    /// Plan `plan_id`'s cuts (empty: it was not cut).
    pub fn of(&self, plan_id: u64) -> &[Cut] {
        self.plans.get(&plan_id).map_or(&[], Vec::as_slice)
    }

    /// The file's text.
    pub fn to_text(&self) -> String {
        let mut out = String::from("# wingman deadline cuts: plan id, then site (hex):step\n");
        for (id, cuts) in &self.plans {
            let _ = write!(out, "{id}");
            for c in cuts {
                let _ = write!(out, " {:08x}:{}", c.site.code(), c.step);
            }
            out.push('\n');
        }
        out
    }

    /// Reads the file's text.
    pub fn parse(text: &str) -> Result<ReplayCuts, ReplayCutsError> {
        let mut plans = BTreeMap::new();
        for (k, line) in text.lines().enumerate() {
            let fail = |problem: String| ReplayCutsError {
                line: k + 1,
                problem,
            };
            let line = line.split('#').next().unwrap_or_default();
            let mut words = line.split_whitespace();
            let Some(id) = words.next() else {
                continue;
            };
            let id: u64 = id
                .parse()
                .map_err(|_| fail(format!("`{id}` is not a plan id")))?;
            let mut cuts = Vec::new();
            for w in words {
                let bad = || fail(format!("`{w}` is not a cut (site in hex:step)"));
                let (site, step) = w.split_once(':').ok_or_else(bad)?;
                let code = u32::from_str_radix(site, 16).map_err(|_| bad())?;
                let site = Site::from_code(code)
                    .ok_or_else(|| fail(format!("no site has the code {site}")))?;
                let step = step.parse().map_err(|_| bad())?;
                cuts.push(Cut { site, step });
            }
            if plans.insert(id, cuts).is_some() {
                return Err(fail(format!("plan {id} appears twice")));
            }
        }
        Ok(ReplayCuts { plans })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn every_work() -> Vec<Work> {
        vec![
            Work::Whole,
            Work::Seeds,
            Work::SeedScores(0),
            Work::SeedScores(7),
            Work::SwarmRounds,
            Work::Floor,
            Work::FloorSolve,
            Work::NlpStage,
            Work::Rank(0),
            Work::Rank(513),
            Work::Final(3),
            Work::Round {
                candidate: 2,
                round: 0,
            },
            Work::Round {
                candidate: 9,
                round: 4,
            },
            Work::WinnerRound,
            Work::Refinement,
        ]
    }

    #[test]
    fn every_site_survives_its_code() {
        let mut codes = Vec::new();
        for part in [
            Part::Plan,
            Part::Warm,
            Part::Global,
            Part::Wave(1),
            Part::Wave(253),
        ] {
            for work in every_work() {
                let site = Site { part, work };
                assert_eq!(Site::from_code(site.code()), Some(site), "{site:?}");
                codes.push(site.code());
            }
        }
        let n = codes.len();
        codes.sort_unstable();
        codes.dedup();
        assert_eq!(codes.len(), n, "two sites share a code");
        assert_eq!(
            Site::from_code(0xff << 24).map(|s| s.part),
            Some(Part::Wave(253))
        );
        assert_eq!(Site::from_code(12 << 16), None, "no kind 12");
        assert_eq!(
            Site::from_code(1 << 16 | 1),
            None,
            "the seeds have no index"
        );
    }

    #[test]
    fn recording_keeps_the_yes_answers_sorted() {
        let log = CutLog::new();
        log.begin(None);
        let late = Site::PLAN.with(Work::SwarmRounds);
        let early = Site::PLAN.with(Work::Seeds);
        assert!(!log.cuts(early, 1, || false));
        assert!(log.cuts(late, 40, || true));
        assert!(log.cuts(early, 3, || true));
        assert_eq!(
            log.finish(),
            vec![
                Cut {
                    site: early,
                    step: 3
                },
                Cut {
                    site: late,
                    step: 40
                }
            ]
        );
        assert!(log.finish().is_empty(), "finish starts afresh");
        let shown = CutList(&[Cut {
            site: late,
            step: 40,
        }])
        .to_string();
        assert_eq!(shown, "Plan/SwarmRounds@40");
        assert_eq!(CutList(&[]).to_string(), "-");
    }

    #[test]
    fn replaying_answers_from_the_log_and_never_asks_the_clock() {
        let log = CutLog::new();
        let site = Site {
            part: Part::Global,
            work: Work::Rank(2),
        };
        log.begin(Some(&[Cut { site, step: 5 }]));
        assert!(log.replaying());
        let clock = || panic!("a replay asked the clock");
        assert!(!log.cuts(site, 4, clock));
        assert!(log.cuts(site, 5, clock));
        assert!(!log.cuts(site.with(Work::Rank(3)), 5, clock));
        assert_eq!(log.finish(), vec![Cut { site, step: 5 }]);
        log.begin(None);
        assert!(!log.replaying());
    }

    #[test]
    fn replay_cuts_read_back_what_was_written() {
        let mut r = ReplayCuts::default();
        let site = Site {
            part: Part::Warm,
            work: Work::Round {
                candidate: 1,
                round: 2,
            },
        };
        r.insert(
            7,
            vec![
                Cut { site, step: 12 },
                Cut {
                    site: Site::PLAN,
                    step: 0,
                },
            ],
        );
        r.insert(2, Vec::new());
        let text = r.to_text();
        assert_eq!(ReplayCuts::parse(&text), Ok(r.clone()));
        assert_eq!(r.of(7).len(), 2);
        assert!(r.of(3).is_empty(), "a plan with no entry was not cut");
        let bad = ReplayCuts::parse("1 01000000:2\nx 2").unwrap_err();
        assert_eq!(bad.line, 2);
        let unknown = ReplayCuts::parse("1 020c0000:2").unwrap_err();
        assert!(unknown.problem.contains("no site"), "{unknown}");
        assert!(ReplayCuts::parse("1\n1").is_err(), "a plan twice");
    }
}
