//! The NLP stage's schedule on the planner's threads: the ranking solves, the finalists'
//! solves and the first refinement round, with no core idle while work that may be
//! needed is left.
//!
//! The stage has three steps, each waiting for a decision taken on the whole of the step
//! before: every start is *ranked* on the coarse mesh; the best distinct ranked starts
//! are the *finalists*, solved on the working mesh; the best finalist is the *winner*,
//! refined (or polished) in a *round*. Run step by step, one core idles while the last
//! solve of a step ends (the solves differ in length by a factor of three). Here an idle
//! thread runs, speculatively, the solve the decision will most likely ask for: the
//! final of the best start ranked so far, the round of the best finalist solved so far
//! (while the last ranks run too).
//! A decision is still taken only once its step is complete, every task's result is a
//! function of its own inputs alone, and a speculative task that the decision did not
//! ask for is cancelled and its result dropped: the plan is the same, byte for byte, as
//! the step-by-step one (which this is with one thread).

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, OnceLock};
use std::time::Duration;

/// The NLP stage's work, as the schedule sees it. Candidates of the final step are the
/// starts `0..starts()` and [`Stage::fallback`]`()`, the swarm's own path (solved when no
/// start ranked).
pub(super) trait Stage: Sync {
    type Rank: Send + Sync;
    type Final: Send + Sync;
    type Round: Send + Sync;
    /// How many starts are ranked.
    fn starts(&self) -> usize;
    /// The candidate solved when no start ranked.
    fn fallback(&self) -> usize {
        self.starts()
    }
    /// Whether the fallback is solved when no start ranked (a wave, whose plan only
    /// competes with one already made, wants none).
    fn fallback_wanted(&self) -> bool {
        true
    }
    /// Ranks start `i`.
    fn rank(&self, i: usize) -> Self::Rank;
    /// The finalists, best first, among the ranks done so far (`ranks[i]` is `None` while
    /// start `i` is not done, or if its task failed); indices of starts.
    fn finalists(&self, ranks: &[Option<&Self::Rank>]) -> Vec<usize>;
    /// Solves candidate `c` on the working mesh from its rank (`None` for the fallback).
    fn finalist(&self, c: usize, rank: Option<&Self::Rank>, cancel: Arc<AtomicBool>)
    -> Self::Final;
    /// An accepted final's objective, and whether a round follows it if it wins; `None`:
    /// not accepted.
    fn judge(&self, f: &Self::Final) -> Option<(f64, bool)>;
    /// The first round after candidate `c`'s final `f`.
    fn round(&self, c: usize, f: &Self::Final, cancel: Arc<AtomicBool>) -> Self::Round;
    /// The plan's deadline has passed (no speculative task is started).
    fn expired(&self) -> bool;
    /// Whether the deadline cuts the winner's first round (`started`: it is already
    /// running, speculatively), recorded as a deadline cut (`crate::cuts`).
    fn round_cut(&self, started: bool) -> bool;
    /// Candidate `c`'s final (`round`: its first round) ran speculatively, or not at all,
    /// and its result is not used: the deadline cuts it took are forgotten, since a replay
    /// need not run it.
    fn discard(&self, c: usize, round: bool);
    /// The stage clock's time.
    fn now(&self) -> Duration;
}

/// What the schedule did: every result the decisions used, in the step-by-step order.
pub(super) struct Schedule<S: Stage> {
    /// Each start's rank (`None`: its task failed).
    pub ranks: Vec<Option<S::Rank>>,
    /// The finalists decided on all the ranks (the fallback if none ranked).
    pub chosen: Vec<usize>,
    /// The final of each of `chosen`, in its order (`None`: its task failed).
    pub finals: Vec<Option<S::Final>>,
    /// The winner, as a position in `chosen` (`None`: no final was accepted).
    pub winner: Option<usize>,
    /// The winner's first round (`None`: none was needed, or its task failed).
    pub round: Option<S::Round>,
    /// When the last rank was done (stage clock).
    pub ranked_at: Duration,
}

impl<S: Stage> Schedule<S> {
    /// The schedule that ran nothing (no time for it): no rank, no final, no winner.
    pub fn none() -> Schedule<S> {
        Schedule {
            ranks: Vec::new(),
            chosen: Vec::new(),
            finals: Vec::new(),
            winner: None,
            round: None,
            ranked_at: Duration::ZERO,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Idle,
    Running,
    Done,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Task {
    Rank(usize),
    Final(usize),
    Round(usize),
}

/// The tasks' states and the decisions, under one lock.
struct Board {
    rank: Vec<State>,
    finals: Vec<State>,
    rounds: Vec<State>,
    chosen: Option<Vec<usize>>,
    /// `Some(w)` once decided; `w` as in [`Schedule::winner`].
    winner: Option<Option<usize>>,
    /// The candidate whose round is wanted (decided with the winner).
    wanted_round: Option<usize>,
    ranked_at: Duration,
}

impl Board {
    /// The winner is decided and its round, if wanted, done.
    fn finished(&self) -> bool {
        self.winner.is_some()
            && self
                .wanted_round
                .is_none_or(|c| self.rounds[c] == State::Done)
    }
}

/// The results, written once by the task that computes them, read without the lock.
struct Shared<S: Stage> {
    board: Mutex<Board>,
    changed: Condvar,
    ranks: Vec<OnceLock<S::Rank>>,
    finals: Vec<OnceLock<S::Final>>,
    rounds: Vec<OnceLock<S::Round>>,
    cancel_final: Vec<Arc<AtomicBool>>,
    cancel_round: Vec<Arc<AtomicBool>>,
}

impl<S: Stage> Shared<S> {
    fn lock(&self) -> MutexGuard<'_, Board> {
        // A panic never happens under the lock (tasks run outside it); recover anyway.
        self.board.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The done ranks, as [`Stage::finalists`] takes them.
    fn done_ranks(&self, board: &Board) -> Vec<Option<&S::Rank>> {
        self.ranks
            .iter()
            .zip(&board.rank)
            .map(|(r, s)| if *s == State::Done { r.get() } else { None })
            .collect()
    }

    /// The best accepted final among `chosen` that are done, as (position, wants a round);
    /// ties go to the earlier.
    fn best_final(&self, board: &Board, chosen: &[usize], stage: &S) -> Option<(usize, bool)> {
        let mut best: Option<(usize, f64, bool)> = None;
        for (k, &c) in chosen.iter().enumerate() {
            if board.finals[c] != State::Done {
                continue;
            }
            let Some((objective, round)) = self.finals[c].get().and_then(|f| stage.judge(f)) else {
                continue;
            };
            if best.is_none_or(|b| objective < b.1) {
                best = Some((k, objective, round));
            }
        }
        best.map(|(k, _, round)| (k, round))
    }

    /// Takes the decisions that have become possible and picks this thread's next task
    /// (`None`: nothing to do now).
    fn next(&self, stage: &S, board: &mut Board) -> Option<Task> {
        // 1. The ranks, in order.
        if let Some(i) = board.rank.iter().position(|s| *s == State::Idle) {
            return Some(Task::Rank(i));
        }
        let ranked = board.rank.iter().all(|s| *s == State::Done);
        if ranked && board.chosen.is_none() {
            // 2. The finalists, on all the ranks.
            let mut chosen = stage.finalists(&self.done_ranks(board));
            if chosen.is_empty() && stage.fallback_wanted() {
                chosen.push(stage.fallback());
            }
            for (c, (cancel_final, cancel_round)) in
                self.cancel_final.iter().zip(&self.cancel_round).enumerate()
            {
                if !chosen.contains(&c) {
                    cancel_final.store(true, Ordering::Relaxed);
                    cancel_round.store(true, Ordering::Relaxed);
                }
            }
            board.chosen = Some(chosen);
        }
        if let Some(chosen) = board.chosen.clone() {
            // 3. The finalists' solves, in order.
            if let Some(&c) = chosen.iter().find(|&&c| board.finals[c] == State::Idle) {
                return Some(Task::Final(c));
            }
            let finished = chosen.iter().all(|&c| board.finals[c] == State::Done);
            if finished && board.winner.is_none() {
                // 4. The winner, on all the finals.
                let best = self.best_final(board, &chosen, stage);
                board.wanted_round = best
                    .filter(|&(k, round)| {
                        round && !stage.round_cut(board.rounds[chosen[k]] != State::Idle)
                    })
                    .map(|(k, _)| chosen[k]);
                for (c, cancel) in self.cancel_round.iter().enumerate() {
                    if Some(c) != board.wanted_round {
                        cancel.store(true, Ordering::Relaxed);
                    }
                }
                board.winner = Some(best.map(|(k, _)| k));
            }
            if board.winner.is_some() {
                // 5. The winner's round.
                return board
                    .wanted_round
                    .filter(|&c| board.rounds[c] == State::Idle)
                    .map(Task::Round);
            }
            // 6. Speculative: the round of the best final so far.
            if stage.expired() {
                return None;
            }
            return self.speculative_round(board, &chosen, stage);
        }
        if stage.expired() {
            return None;
        }
        let so_far = stage.finalists(&self.done_ranks(board));
        // 7. Speculative: the final of the best start ranked so far.
        if let Some(&c) = so_far.iter().find(|&&c| board.finals[c] == State::Idle) {
            return Some(Task::Final(c));
        }
        // 8. Speculative: the round of the best final so far among them (a long last
        //    rank would otherwise leave this thread idle).
        self.speculative_round(board, &so_far, stage)
    }

    /// The round of the best accepted final among `candidates` that are done, if it
    /// wants one and it is not started.
    fn speculative_round(&self, board: &Board, candidates: &[usize], stage: &S) -> Option<Task> {
        self.best_final(board, candidates, stage)
            .filter(|&(k, round)| round && board.rounds[candidates[k]] == State::Idle)
            .map(|(k, _)| Task::Round(candidates[k]))
    }

    fn run(&self, stage: &S, task: Task) {
        // A task that panics (a solver bug) leaves no result: it counts as failed, and
        // the plan goes on with the others.
        let _ = catch_unwind(AssertUnwindSafe(|| match task {
            Task::Rank(i) => {
                let _ = self.ranks[i].set(stage.rank(i));
            }
            Task::Final(c) => {
                let rank = self.ranks.get(c).and_then(OnceLock::get);
                let cancel = self.cancel_final[c].clone();
                let _ = self.finals[c].set(stage.finalist(c, rank, cancel));
            }
            Task::Round(c) => {
                if let Some(f) = self.finals[c].get() {
                    let cancel = self.cancel_round[c].clone();
                    let _ = self.rounds[c].set(stage.round(c, f, cancel));
                }
            }
        }));
    }

    /// One thread's loop: take a task, run it, until the stage is finished.
    fn work(&self, stage: &S) {
        let mut board = self.lock();
        loop {
            if board.finished() {
                self.changed.notify_all();
                return;
            }
            let Some(task) = self.next(stage, &mut board) else {
                if !board.finished() {
                    board = self.changed.wait(board).unwrap_or_else(|e| e.into_inner());
                }
                continue;
            };
            set(&mut board, task, State::Running);
            drop(board);
            self.run(stage, task);
            board = self.lock();
            set(&mut board, task, State::Done);
            if matches!(task, Task::Rank(_)) && board.rank.iter().all(|s| *s == State::Done) {
                board.ranked_at = stage.now();
            }
            self.changed.notify_all();
        }
    }
}

/// `k` empty result slots.
fn slots<T>(k: usize) -> Vec<OnceLock<T>> {
    (0..k).map(|_| OnceLock::new()).collect()
}

fn set(board: &mut Board, task: Task, state: State) {
    match task {
        Task::Rank(i) => board.rank[i] = state,
        Task::Final(c) => board.finals[c] = state,
        Task::Round(c) => board.rounds[c] = state,
    }
}

/// Runs `stage` on the calling thread and `threads - 1` more.
pub(super) fn run<S: Stage>(stage: &S, threads: usize) -> Schedule<S> {
    let n = stage.starts();
    let candidates = n.max(stage.fallback()) + 1;
    let flags = |k: usize| (0..k).map(|_| Arc::new(AtomicBool::new(false))).collect();
    let shared = Shared::<S> {
        board: Mutex::new(Board {
            rank: vec![State::Idle; n],
            finals: vec![State::Idle; candidates],
            rounds: vec![State::Idle; candidates],
            chosen: None,
            winner: None,
            wanted_round: None,
            ranked_at: stage.now(),
        }),
        changed: Condvar::new(),
        ranks: slots(n),
        finals: slots(candidates),
        rounds: slots(candidates),
        cancel_final: flags(candidates),
        cancel_round: flags(candidates),
    };
    let threads = threads.clamp(1, n.max(1) + 1);
    std::thread::scope(|scope| {
        for _ in 1..threads {
            scope.spawn(|| shared.work(stage));
        }
        shared.work(stage);
    });
    let Shared {
        board,
        ranks,
        finals,
        rounds,
        ..
    } = shared;
    let board = board.into_inner().unwrap_or_else(|e| e.into_inner());
    let chosen = board.chosen.unwrap_or_default();
    for c in 0..candidates {
        if !chosen.contains(&c) {
            stage.discard(c, false);
        }
        if board.wanted_round != Some(c) {
            stage.discard(c, true);
        }
    }
    let mut finals: Vec<Option<S::Final>> = finals.into_iter().map(OnceLock::into_inner).collect();
    let mut rounds: Vec<Option<S::Round>> = rounds.into_iter().map(OnceLock::into_inner).collect();
    Schedule {
        ranks: ranks.into_iter().map(OnceLock::into_inner).collect(),
        finals: chosen.iter().map(|&c| finals[c].take()).collect(),
        chosen,
        winner: board.winner.flatten(),
        round: board.wanted_round.and_then(|c| rounds[c].take()),
        ranked_at: board.ranked_at,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicUsize;

    /// A stage whose solves take `len` steps of a spin (cancellable at each step); ranks'
    /// costs and finals' objectives are given; `panics` names tasks that panic.
    struct Fake {
        rank_cost: Vec<f64>,
        rank_len: Vec<u64>,
        final_objective: Vec<Option<f64>>,
        final_len: Vec<u64>,
        rounds: bool,
        fallback_wanted: bool,
        panic_rank: Option<usize>,
        panic_final: Option<usize>,
        /// Solves started (speculative ones included) and cancelled.
        started: AtomicUsize,
        cancelled: AtomicUsize,
        /// When each final and each round started (fake clock).
        final_started: Mutex<Vec<(usize, Duration)>>,
        round_started: Mutex<Vec<(usize, Duration)>>,
        round_len: u64,
        clock: std::time::Instant,
    }

    impl Fake {
        fn new(rank_cost: &[f64], rank_len: &[u64], final_objective: &[Option<f64>]) -> Fake {
            Fake {
                rank_cost: rank_cost.to_vec(),
                rank_len: rank_len.to_vec(),
                final_objective: final_objective.to_vec(),
                final_len: vec![3; final_objective.len()],
                rounds: true,
                fallback_wanted: true,
                panic_rank: None,
                panic_final: None,
                started: AtomicUsize::new(0),
                cancelled: AtomicUsize::new(0),
                final_started: Mutex::new(Vec::new()),
                round_started: Mutex::new(Vec::new()),
                round_len: 4,
                clock: std::time::Instant::now(),
            }
        }

        /// Spins `steps` milliseconds; false if cancelled on the way.
        fn spin(&self, steps: u64, cancel: Option<&AtomicBool>) -> bool {
            self.started.fetch_add(1, Ordering::Relaxed);
            for _ in 0..steps {
                if cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                    self.cancelled.fetch_add(1, Ordering::Relaxed);
                    return false;
                }
                std::thread::sleep(Duration::from_millis(1));
            }
            true
        }
    }

    impl Stage for Fake {
        type Rank = f64;
        /// (candidate, objective) or not accepted.
        type Final = (usize, Option<f64>);
        type Round = (usize, bool);

        fn starts(&self) -> usize {
            self.rank_cost.len()
        }

        fn rank(&self, i: usize) -> f64 {
            assert_ne!(self.panic_rank, Some(i), "rank {i} fails");
            self.spin(self.rank_len[i], None);
            self.rank_cost[i]
        }

        /// The two lowest costs, best first, skipping NaN (not ranked).
        fn finalists(&self, ranks: &[Option<&f64>]) -> Vec<usize> {
            let mut ranked: Vec<(f64, usize)> = ranks
                .iter()
                .enumerate()
                .filter_map(|(i, r)| r.filter(|c| c.is_finite()).map(|&c| (c, i)))
                .collect();
            ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            ranked.into_iter().take(2).map(|r| r.1).collect()
        }

        fn fallback_wanted(&self) -> bool {
            self.fallback_wanted
        }

        fn finalist(&self, c: usize, rank: Option<&f64>, cancel: Arc<AtomicBool>) -> Self::Final {
            assert_ne!(self.panic_final, Some(c), "final {c} fails");
            assert_eq!(rank.is_none(), c == self.starts());
            self.final_started.lock().unwrap().push((c, self.now()));
            let done = self.spin(self.final_len[c], Some(&cancel));
            (c, self.final_objective[c].filter(|_| done))
        }

        fn judge(&self, f: &Self::Final) -> Option<(f64, bool)> {
            f.1.map(|o| (o, self.rounds))
        }

        fn round(&self, c: usize, f: &Self::Final, cancel: Arc<AtomicBool>) -> Self::Round {
            assert_eq!(c, f.0);
            self.round_started.lock().unwrap().push((c, self.now()));
            (c, self.spin(self.round_len, Some(&cancel)))
        }

        fn expired(&self) -> bool {
            false
        }

        fn round_cut(&self, started: bool) -> bool {
            !started && self.expired()
        }

        fn discard(&self, _c: usize, _round: bool) {}

        fn now(&self) -> Duration {
            self.clock.elapsed()
        }
    }

    /// The decisions of a schedule, to compare across thread counts.
    fn decisions(s: &Schedule<Fake>) -> String {
        format!(
            "{:?} {:?} {:?} {:?} {:?}",
            s.ranks, s.chosen, s.finals, s.winner, s.round
        )
    }

    /// The stage `fake()` run on one thread and on two, which decide alike.
    fn one_and_two_threads(
        fake: impl Fn() -> Fake,
    ) -> (Fake, Schedule<Fake>, Fake, Schedule<Fake>) {
        let one = fake();
        let sequential = run(&one, 1);
        let two = fake();
        let parallel = run(&two, 2);
        assert_eq!(decisions(&sequential), decisions(&parallel));
        (one, sequential, two, parallel)
    }

    #[test]
    fn two_threads_decide_as_one_and_speculate_into_idle_time() {
        // Start 3 is long: while it runs, the other thread is idle on a step-by-step
        // schedule; here it solves the final of the best start ranked so far (0), which
        // the decision takes. Start 2 ranks best but its final is not accepted.
        let fake = || {
            Fake::new(
                &[5.0, 7.0, 4.0, 9.0, 6.0],
                &[2, 2, 2, 20, 2],
                &[Some(3.0), Some(2.5), None, Some(1.0), Some(2.0), Some(9.0)],
            )
        };
        let (one, sequential, two, parallel) = one_and_two_threads(fake);
        // Ranked 2 (4.0) then 0 (5.0): 2's final is refused, 0 wins and is refined.
        assert_eq!(parallel.chosen, [2, 0]);
        assert_eq!(parallel.winner, Some(1));
        assert_eq!(parallel.round, Some((0, true)));
        // One thread never speculates: 5 ranks, 2 finals, 1 round.
        assert_eq!(one.started.load(Ordering::Relaxed), 8);
        assert_eq!(one.cancelled.load(Ordering::Relaxed), 0);
        // Two speculate: start 2's final began while start 3 was still ranking (18 ms
        // of it left), and was used.
        let started = two.final_started.lock().unwrap().clone();
        assert_eq!(started.first().map(|s| s.0), Some(2), "{started:?}");
        assert!(started[0].1 < parallel.ranked_at, "{started:?}");
        assert!(one.final_started.lock().unwrap()[0].1 >= sequential.ranked_at);
    }

    #[test]
    fn speculation_not_chosen_is_cancelled_and_dropped() {
        // Start 4 is long; meanwhile the best ranked so far is 1 (3.0), whose final is
        // started; start 4 ranks better (1.0) and start 0 second: 1 is not a finalist.
        let fake = Fake::new(
            &[2.0, 3.0, 8.0, 8.0, 1.0],
            &[1, 1, 1, 1, 40],
            &[Some(5.0), Some(0.1), Some(5.0), Some(5.0), Some(4.0), None],
        );
        let mut slow = fake;
        slow.final_len[1] = 200;
        let s = run(&slow, 2);
        assert_eq!(s.chosen, [4, 0]);
        // 1's objective (0.1) would have won: its result must not leak in.
        assert_eq!(s.winner, Some(0));
        assert_eq!(s.finals, [Some((4, Some(4.0))), Some((0, Some(5.0)))]);
        assert!(slow.cancelled.load(Ordering::Relaxed) >= 1);
    }

    #[test]
    fn a_long_last_rank_leaves_time_for_the_round_of_the_best_final() {
        // Start 3 ranks for 60 ms. Meanwhile the other thread solves the finals of the
        // two best ranked so far (2, then 0) and then, speculatively, the round of the
        // better of them (2), which the decision takes: no thread waits for the rank.
        let fake = || {
            Fake::new(
                &[5.0, 7.0, 4.0, 9.0, 6.0],
                &[2, 2, 2, 60, 2],
                &[
                    Some(3.0),
                    Some(2.5),
                    Some(1.0),
                    Some(1.5),
                    Some(2.0),
                    Some(9.0),
                ],
            )
        };
        let (one, sequential, two, parallel) = one_and_two_threads(fake);
        assert_eq!(parallel.chosen, [2, 0]);
        assert_eq!(parallel.winner, Some(0));
        assert_eq!(parallel.round, Some((2, true)));
        let rounds = two.round_started.lock().unwrap().clone();
        assert_eq!(rounds.len(), 1, "{rounds:?}");
        assert_eq!(rounds[0].0, 2);
        assert!(rounds[0].1 < parallel.ranked_at, "{rounds:?}");
        // One thread refines only after the ranking.
        assert!(one.round_started.lock().unwrap()[0].1 >= sequential.ranked_at);
    }

    #[test]
    fn a_speculative_round_of_a_start_not_chosen_is_cancelled() {
        // While start 4 ranks (40 ms), start 1 is the best ranked so far: its final is
        // solved and its (long) round started. Start 4 then ranks best and 0 second, so
        // 1 is no finalist: its round is cancelled, and the round taken is the winner's.
        let mut fake = Fake::new(
            &[2.0, 3.0, 8.0, 8.0, 1.0],
            &[1, 1, 1, 1, 40],
            &[Some(5.0), Some(0.1), Some(5.0), Some(5.0), Some(4.0), None],
        );
        fake.round_len = 400;
        let s = run(&fake, 2);
        assert_eq!(s.chosen, [4, 0]);
        assert_eq!(s.winner, Some(0));
        let rounds = fake.round_started.lock().unwrap().clone();
        assert!(rounds.iter().any(|r| r.0 == 1), "{rounds:?}");
        assert!(fake.cancelled.load(Ordering::Relaxed) >= 1);
        assert_eq!(s.round, Some((4, true)));
    }

    #[test]
    fn failed_tasks_count_as_failed_solves_and_no_ranks_fall_back() {
        let mut fake = Fake::new(&[1.0, 2.0], &[1, 1], &[Some(1.0), Some(2.0), Some(3.0)]);
        fake.panic_rank = Some(0);
        fake.panic_final = Some(1);
        let s = run(&fake, 2);
        assert!(s.ranks[0].is_none());
        assert_eq!(s.chosen, [1]);
        assert_eq!(s.finals, [None]);
        assert_eq!(s.winner, None);
        assert_eq!(s.round, None);
        // Nothing ranked (NaN costs): the fallback is solved, and wins.
        let mut none = Fake::new(&[f64::NAN, f64::NAN], &[1, 1], &[None, None, Some(7.0)]);
        none.rounds = false;
        let s = run(&none, 2);
        assert_eq!(s.chosen, [2]);
        assert_eq!(s.finals, [Some((2, Some(7.0)))]);
        assert_eq!(s.winner, Some(0));
        assert_eq!(s.round, None);
    }

    /// A stage that wants no fallback (a wave) ends when nothing ranked: no final, no
    /// winner, on one thread and on two.
    #[test]
    fn a_stage_without_a_fallback_ends_with_no_final_when_nothing_ranked() {
        let fake = || {
            let mut f = Fake::new(&[f64::NAN, f64::NAN], &[1, 1], &[None, None, Some(7.0)]);
            f.fallback_wanted = false;
            f
        };
        let (one, _, _, s) = one_and_two_threads(fake);
        assert!(s.chosen.is_empty());
        assert!(s.finals.is_empty());
        assert_eq!(s.winner, None);
        assert_eq!(s.round, None);
        assert!(one.final_started.lock().unwrap().is_empty());
    }
}
