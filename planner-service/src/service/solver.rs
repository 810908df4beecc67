//! The solve thread: it owns the hybrid [`Planner`] (its workspaces are reused plan after
//! plan), takes one request at a time over a crossbeam channel — a problem snapshot with
//! its ticket (plan id, trigger, commit time, budget) — plans it under a deadline of the
//! budget, sends the outcome back with the problem (whose buffers the message thread
//! reuses) and wakes the message thread.
//!
//! At most one request is in flight: the request channel holds one, and the message thread
//! sends the next only after it took the previous result. A panic inside the planner is
//! caught, reported as [`SolveError::Panicked`], and the planner rebuilt.
//!
//! Each plan's deadline cuts (`wingman_planning::cuts`) are recorded and sent back with
//! it; a replay (`replay`: the logged cuts of a flight's plans) plans with no deadline and
//! takes the logged cuts instead.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam::channel::{self, Receiver, RecvTimeoutError, Sender};
use tracing::{error, info, info_span};
use wingman_interfaces::{Quality, Trigger};

use crate::service::triggers::TriggerSet;

use wingman_planning::clock::{Clock, Deadline};
use wingman_planning::cuts::{Cut, CutList, CutLog, ReplayCuts};
use wingman_planning::hybrid::{FlyingPlan, PlanError, PlanOutcome, Planner, PlannerSettings};
use wingman_planning::problem::Problem;

/// What travels with a problem to the solver and back.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ticket {
    pub plan_id: u64,
    pub trigger: Trigger,
    /// Every trigger the plan answers (`trigger` is the first of them).
    pub triggers: TriggerSet,
    /// Mission time of the trigger.
    pub created_at_s: f64,
    /// Compute budget (the deadline).
    pub budget: Duration,
    /// World epoch of the snapshot (threats changed after it are not in the plan).
    pub epoch: u64,
    /// Targets of the tasking left out as passed.
    pub targets_from: usize,
    /// Revision of the tasking the problem was built from.
    pub tasking_revision: u32,
    /// The plan in flight to re-plan from (its id), if any: the solve thread starts from
    /// it when it made that plan and the problem continues its tasking.
    pub warm_from: Option<u64>,
}

/// A plan to make.
#[derive(Debug)]
pub struct SolveRequest {
    pub problem: Box<Problem>,
    pub ticket: Ticket,
}

/// Why the solver returned no plan.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    #[error(transparent)]
    Plan(#[from] PlanError),
    #[error("the planner panicked; it was rebuilt")]
    Panicked,
}

/// A plan made (or not).
#[derive(Debug)]
pub struct SolveResult {
    pub problem: Box<Problem>,
    pub ticket: Ticket,
    pub outcome: Result<PlanOutcome, SolveError>,
    /// Start and end on the injected clock.
    pub started: Duration,
    pub finished: Duration,
    /// Core time used: the process's CPU time over the plan (every thread of the swarm
    /// and of the NLP starts), at least the wall time; `threads x` the wall time if the
    /// CPU clock cannot be read.
    pub core_time: Duration,
    /// Where the deadline cut the plan (sorted).
    pub cuts: Vec<Cut>,
}

/// Builds, on the solve thread, the function that wakes the message thread after each
/// result (an iceoryx2 notifier is not `Send`, so it is made where it is used).
pub type WakerFactory = Box<dyn FnOnce() -> Result<Box<dyn FnMut()>, String> + Send>;

/// The solve thread could not start.
#[derive(Debug, thiserror::Error)]
pub enum SolverStartError {
    #[error("cannot spawn the solve thread: {0}")]
    Spawn(#[from] std::io::Error),
    #[error("the solve thread cannot wake the message thread: {0}")]
    Waker(String),
}

/// Handle of the solve thread.
pub struct Solver {
    requests: Option<Sender<SolveRequest>>,
    results: Receiver<SolveResult>,
    thread: Option<JoinHandle<()>>,
}

impl Solver {
    /// Starts the solve thread with its planner.
    pub fn spawn(
        settings: PlannerSettings,
        clock: &'static dyn Clock,
        replay: Option<ReplayCuts>,
        waker: WakerFactory,
    ) -> Result<Solver, SolverStartError> {
        let (req_tx, req_rx) = channel::bounded::<SolveRequest>(1);
        let (res_tx, res_rx) = channel::bounded::<SolveResult>(1);
        let (ready_tx, ready_rx) = channel::bounded::<Result<(), String>>(1);
        let thread = std::thread::Builder::new()
            .name("wingman-solve".into())
            .spawn(move || {
                let mut wake = match waker() {
                    Ok(w) => {
                        let _ = ready_tx.send(Ok(()));
                        w
                    }
                    Err(e) => {
                        let _ = ready_tx.send(Err(e));
                        return;
                    }
                };
                solve_loop(
                    &settings,
                    clock,
                    replay.as_ref(),
                    &req_rx,
                    &res_tx,
                    &mut *wake,
                );
            })?;
        match ready_rx.recv() {
            Ok(Ok(())) => Ok(Solver {
                requests: Some(req_tx),
                results: res_rx,
                thread: Some(thread),
            }),
            Ok(Err(e)) => {
                let _ = thread.join();
                Err(SolverStartError::Waker(e))
            }
            Err(_) => {
                let _ = thread.join();
                Err(SolverStartError::Waker("the solve thread ended".into()))
            }
        }
    }

    /// Hands a request to the solve thread; gives it back if one is already queued or the
    /// thread is gone.
    pub fn submit(&self, request: SolveRequest) -> Result<(), SolveRequest> {
        match &self.requests {
            Some(tx) => tx.try_send(request).map_err(|e| e.into_inner()),
            None => Err(request),
        }
    }

    /// A finished plan, if one is waiting.
    pub fn try_result(&self) -> Option<SolveResult> {
        self.results.try_recv().ok()
    }

    /// Waits up to `timeout` for a finished plan.
    pub fn wait_result(&self, timeout: Duration) -> Option<SolveResult> {
        self.results.recv_timeout(timeout).ok()
    }

    /// Whether the solve thread is still running.
    pub fn is_alive(&self) -> bool {
        self.thread.as_ref().is_some_and(|t| !t.is_finished())
    }

    /// Stops taking requests and joins the thread once it has finished the plan in hand
    /// (waiting at most `timeout`; past it the thread is left to end with the process).
    pub fn shutdown(mut self, timeout: Duration) {
        self.requests = None;
        let Some(thread) = self.thread.take() else {
            return;
        };
        join_within(thread, &self.results, timeout);
    }
}

/// Joins the solve thread once it has ended, waiting at most `timeout` (wall time) and
/// draining its results meanwhile (so it is never blocked sending one); past it the thread
/// is left to end with the process. Whether it was joined.
///
/// The thread drops its end of `results` as it returns, a moment before it counts as
/// finished (its thread-locals, such as the solver's buffer pool, are freed in between):
/// the wait then sleeps in steps rather than spinning on the closed channel.
fn join_within<T>(thread: JoinHandle<()>, results: &Receiver<T>, timeout: Duration) -> bool {
    let step = Duration::from_millis(5);
    let began = Instant::now();
    while !thread.is_finished() && began.elapsed() < timeout {
        if let Err(RecvTimeoutError::Disconnected) = results.recv_timeout(step) {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    if thread.is_finished() {
        let _ = thread.join();
        true
    } else {
        error!("the solve thread did not end within {timeout:?}; leaving it to the process exit");
        false
    }
}

impl Drop for Solver {
    /// Unblocks a pending send and joins the thread once the plan in hand has ended (by
    /// its deadline), waiting at most [`DROP_WAIT`]; past it the thread is left to end
    /// with the process.
    fn drop(&mut self) {
        self.requests = None;
        if let Some(thread) = self.thread.take() {
            join_within(thread, &self.results, DROP_WAIT);
        }
    }
}

/// Longest wait for the solve thread when a [`Solver`] is dropped without
/// [`Solver::shutdown`] (a plan ends by its deadline; budgets are seconds at most).
pub const DROP_WAIT: Duration = Duration::from_secs(60);

fn solve_loop(
    settings: &PlannerSettings,
    clock: &'static dyn Clock,
    replay: Option<&ReplayCuts>,
    requests: &Receiver<SolveRequest>,
    results: &Sender<SolveResult>,
    wake: &mut dyn FnMut(),
) {
    let mut planner = Planner::new(settings);
    // Deadlines need `'static` parts: one log for the thread's lifetime.
    let cut_log: &'static CutLog = Box::leak(Box::new(CutLog::new()));
    // The last plan made, with its id: the plan in flight once the message thread took it.
    let mut last: Option<Made> = None;
    // The last plan the NLP made (`Optimal` or `Feasible`) since the last plan from
    // scratch: a re-plan of a plan in flight that is the swarm's path starts from it.
    let mut solved: Option<Arc<FlyingPlan>> = None;
    let threads = settings.swarm.threads.max(settings.threads).max(1) as u32;
    for request in requests.iter() {
        let SolveRequest { problem, ticket } = request;
        // The stage durations are recorded on the span when the plan ends (the planner
        // reports them in `PlanOutcome::times`; seeding is part of the swarm stage).
        let span = info_span!(
            "plan",
            id = ticket.plan_id,
            trigger = ticket.trigger.name(),
            budget_ms = ticket.budget.as_millis() as u64,
            t0 = problem.t0,
            swarm_ms = tracing::field::Empty,
            nlp_ms = tracing::field::Empty,
            export_ms = tracing::field::Empty,
            total_ms = tracing::field::Empty,
            cpu_ms = tracing::field::Empty,
        );
        let _entered = span.enter();
        let cpu_before = process_cpu_time();
        let started = clock.now();
        let logged = replay.map(|r| r.of(ticket.plan_id));
        cut_log.begin(logged);
        let deadline = match logged {
            // A replay takes the logged cuts and no others.
            Some(_) => Deadline::never(clock),
            None => Deadline::after(clock, ticket.budget).earlier(handover_margin(ticket.budget)),
        }
        .with_cuts(cut_log);
        if ticket.warm_from.is_none() {
            // A plan from scratch: what the NLP made before is of another tasking or start.
            solved = None;
        }
        let flying = ticket
            .warm_from
            .and_then(|id| warm_start(id, last.as_ref(), solved.as_ref()));
        let outcome = match catch_unwind(AssertUnwindSafe(|| match flying {
            Some(f) => planner.replan(&problem, settings, deadline, f),
            None => planner.plan(&problem, settings, deadline),
        })) {
            Ok(r) => r.map_err(SolveError::from),
            Err(_) => {
                planner = Planner::new(settings);
                Err(SolveError::Panicked)
            }
        };
        let finished = clock.now();
        let cuts = cut_log.finish();
        let wall = finished.saturating_sub(started);
        let core_time = match (cpu_before, process_cpu_time()) {
            (Some(a), Some(b)) => b.saturating_sub(a).max(wall),
            _ => wall * threads,
        };
        span.record("cpu_ms", ms(core_time));
        if let Ok(o) = &outcome {
            span.record("swarm_ms", ms(o.times.swarm));
            span.record("nlp_ms", ms(o.times.nlp));
            span.record("export_ms", ms(o.times.export));
            span.record("total_ms", ms(o.times.total));
        }
        match &outcome {
            Ok(o) => info!(
                quality = o.quality.name(),
                path = o.path.name(),
                cuts = %CutList(&cuts),
                warm_ms = ms(o.times.warm),
                first_optimal_ms = o.first_optimal.map_or(f64::NAN, ms),
                cost = o.cost,
                swarm_ms = ms(o.times.swarm),
                nlp_ms = ms(o.times.nlp),
                export_ms = ms(o.times.export),
                total_ms = ms(o.times.total),
                samples = o.trajectory.len(),
                "plan made"
            ),
            Err(e) => error!(error = %e, "no plan"),
        }
        drop(_entered);
        if let Ok(o) = &outcome {
            // Shared by `last` and `solved`, not copied.
            let made = Arc::new(
                FlyingPlan::new(&problem, o.trajectory.clone()).with_solution(o.solution.clone()),
            );
            let nlp = matches!(o.quality, Quality::Optimal | Quality::Feasible);
            if nlp {
                solved = Some(Arc::clone(&made));
            }
            last = Some(Made {
                plan_id: ticket.plan_id,
                plan: made,
                nlp,
            });
        }
        let result = SolveResult {
            problem,
            ticket,
            outcome,
            started,
            finished,
            core_time,
            cuts,
        };
        if results.send(result).is_err() {
            return;
        }
        wake();
    }
}

/// The last plan the solve thread made.
struct Made {
    plan_id: u64,
    plan: Arc<FlyingPlan>,
    /// Whether the NLP made it (`Optimal` or `Feasible`), or it is the swarm's path.
    nlp: bool,
}

/// The plan a re-plan of plan `id` (the plan in flight) starts from: that plan, or if it
/// is not the NLP's (the swarm's path of a re-plan its deadline cut: a start far from any
/// optimum, and from which a 2-D re-plan of a 3000 s mission did not converge in 500 ms)
/// the last plan the NLP made since the last plan from scratch, cut at the new start as
/// well, with the world it was made for (threats it did not know are new to it). `None`
/// if plan `id` is not the last made.
fn warm_start<'a>(
    id: u64,
    last: Option<&'a Made>,
    solved: Option<&'a Arc<FlyingPlan>>,
) -> Option<&'a FlyingPlan> {
    let made = last.filter(|m| m.plan_id == id)?;
    match solved {
        Some(nlp) if !made.nlp => Some(nlp),
        _ => Some(&made.plan),
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// CPU time of the whole process so far (user + system, every thread), from
/// `/proc/self/stat` (std has no process CPU clock). Resolution: one clock tick (10 ms,
/// `USER_HZ` = 100 on Linux). No heap allocation: the path is short enough for std's
/// stack buffer and the text is read into a stack array. `None` if it cannot be read.
pub fn process_cpu_time() -> Option<Duration> {
    use std::io::Read;
    const USER_HZ: u64 = 100;
    let mut buf = [0u8; 1024];
    let mut f = std::fs::File::open("/proc/self/stat").ok()?;
    let mut n = 0;
    while n < buf.len() {
        match f.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(_) => return None,
        }
    }
    parse_cpu_ticks(&buf[..n]).map(|ticks| Duration::from_millis(ticks * 1000 / USER_HZ))
}

/// `utime + stime` (fields 14 and 15) of a `/proc/<pid>/stat` line. The command name
/// (field 2) is in parentheses and may hold spaces: fields are counted after the last `)`.
fn parse_cpu_ticks(stat: &[u8]) -> Option<u64> {
    let close = stat.iter().rposition(|&b| b == b')')?;
    let mut fields = stat[close + 1..]
        .split(|&b| b == b' ')
        .filter(|f| !f.is_empty());
    // After `)`: field 3 (state) first, so utime (14) is the 12th.
    let utime = fields.nth(11)?;
    let stime = fields.next()?;
    let num = |f: &[u8]| std::str::from_utf8(f).ok()?.trim().parse::<u64>().ok();
    Some(num(utime)? + num(stime)?)
}

/// How much earlier than its budget a plan aims to return: 2 % of the budget, at least
/// 20 ms, at most half the budget. The budget is the time from the trigger to the plan
/// published; the margin covers the hand-over to the message thread and on to the tracker
/// (measured up to 9 ms under a CPU hog on both cores) and an NLP iteration that runs
/// longer than the ones before it on a loaded core (up to 7 ms past the planner's own
/// deadline in 2-D, 35 ms in 3-D without a margin; `docs/decisions/0010-handover-margin.md`).
pub fn handover_margin(budget: std::time::Duration) -> std::time::Duration {
    budget
        .mul_f64(0.02)
        .max(std::time::Duration::from_millis(20))
        .min(budget / 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_ticks_are_read_after_the_command_name() {
        let line = b"4242 (a (b) c) S 1 2 3 4 5 6 7 8 9 10 31 7 0 0 20 0 3 0 100";
        assert_eq!(parse_cpu_ticks(line), Some(38));
        assert_eq!(parse_cpu_ticks(b"4242 (x) S 1 2"), None);
        assert!(process_cpu_time().is_some(), "/proc/self/stat is readable");
    }

    /// A thread that closes its results channel and then takes a while to end (as the
    /// solve thread does while its thread-locals are freed) is waited for, in wall time:
    /// counting 5 ms per `recv` on the closed channel gave up on it at once.
    #[test]
    fn a_thread_that_closed_its_channel_is_still_waited_for() {
        let (tx, rx) = channel::bounded::<u32>(1);
        let thread = std::thread::spawn(move || {
            drop(tx);
            std::thread::sleep(Duration::from_millis(60));
        });
        let began = Instant::now();
        assert!(join_within(thread, &rx, Duration::from_secs(5)), "joined");
        assert!(
            began.elapsed() >= Duration::from_millis(50),
            "it waited for the thread"
        );

        // And one that does not end in time is left, after the timeout.
        let (_tx, rx) = channel::bounded::<u32>(1);
        let (stop_tx, stop_rx) = channel::bounded::<()>(1);
        let thread = std::thread::spawn(move || {
            let _ = stop_rx.recv();
        });
        let began = Instant::now();
        assert!(
            !join_within(thread, &rx, Duration::from_millis(50)),
            "not joined"
        );
        assert!(
            began.elapsed() >= Duration::from_millis(50),
            "the whole timeout"
        );
        let _ = stop_tx.send(());
    }

    #[test]
    fn the_handover_margin_is_a_share_of_the_budget_with_a_floor() {
        use std::time::Duration;
        let m = |ms| super::handover_margin(Duration::from_millis(ms));
        assert_eq!(m(2500), Duration::from_millis(50), "2 %");
        assert_eq!(m(500), Duration::from_millis(20), "the floor");
        assert_eq!(m(30), Duration::from_millis(15), "at most half the budget");
    }
}
