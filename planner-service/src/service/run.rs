//! The message thread: it sleeps in an iceoryx2 WaitSet (the `wake/planner` listener, the
//! heartbeat interval, and a timeout while a plan is deferred), and on each wake-up makes
//! one pass ([`MessageLoop::process`]):
//!
//! 1. takes the solve thread's finished plan, if any, and publishes it as a `Plan`;
//! 2. drains every input subscriber: each sample is `validate()`d first (an invalid one is
//!    dropped, counted, and logged once per input and kind), then updates the world model
//!    and raises the event triggers (pop-ups, tasking and route changes);
//! 3. evaluates the time triggers (scheduled `t_r`, deviation, expiry) and, when a trigger
//!    is pending and no plan is in flight, starts a plan if the compute gate admits it;
//! 4. publishes `PlannerStatus` (echoing the highest input sequence, after all of the
//!    above is visible) and notifies `wake/harness`.
//!
//! It never plans itself. A pass allocates nothing of its own after start-up
//! (`tests/service_no_alloc.rs`, with a tracing subscriber installed and `info` events
//! filtered out), with these exceptions:
//! - iceoryx2 0.10 allocates a small block per loaned sample it publishes, freed on send;
//! - the first plan of a model after a plan of the other model: `World::fill_problem`
//!   builds the other model's threat layout once (a `Vec` of moving threats);
//! - log events that are enabled: `info!` on a trigger, a plan start or a plan published
//!   (and `warn!`/`error!` on the paths that log) go through the installed subscriber,
//!   and tracing-subscriber's formatter allocates while formatting a line. At
//!   `RUST_LOG=warn` a steady pass logs nothing.
//!
//! Time. Mission time is the newest input header's `mission_time_ns`; the scheduled `t_r`,
//! the expiry and the commit times are mission times, so they are evaluated whenever
//! mission time advances, i.e. on every input (the ownship state arrives periodically):
//! no wall-clock timer could stand for them, since mission time does not advance between
//! messages (and runs faster than the wall in a lock-step run). The WaitSet's timers are
//! wall-clock: the heartbeat interval, and a timeout while a triggered plan waits for the
//! compute gate. The injected clock bounds compute (deadlines, gate, staleness) only.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::{CallbackProgression, SignalHandlingMode, WaitSetBuilder};
use iceoryx2::waitset::WaitSetRunResult;
use tracing::{error, info, warn};
use wingman_interfaces::{
    Header, LeadRoute, LeadState, Message, Model, Objective, OwnshipState, Plan, PlannerState,
    PlannerStatus, SENDER_PLANNER, Service, Tasking, ThreatReport, TrackFix, Trigger,
    ValidationError, Wire,
};

use super::budget::{ComputeGate, GateSettings};
use super::sched::{self, SliceOutcome};
use super::solver::{SolveRequest, SolveResult, Solver, SolverStartError, Ticket};
use super::triggers::{
    self, DeviationBounds, PlanWindow, PopupAssessment, RouteDecision, TaskingDecision, TriggerSet,
};
use super::world::{FixOutcome, Input, Splice, ThreatChange, ThreatSlot, World};
use wingman_ipc::config::{ConfigError, ServiceConfig};
use wingman_ipc::{self as ipc, Ipc, IpcError};
use wingman_planning::clock::Clock;
use wingman_planning::dynamics::{VehicleLimits, idx3};
use wingman_planning::hybrid::{PlanOutcome, PlannerSettings};
use wingman_planning::plan_message::{self as export, PlanInfo, PlanPoints};
use wingman_planning::problem::Problem;

/// Largest plan id (exclusive) a restarted planner continues from: far above any real
/// mission's count, far below `u64::MAX`, so plan ids never wrap to 0 ("no plan").
pub const MAX_CONTINUED_PLAN_ID: u64 = 1 << 48;

/// Wall-clock wait before a failed first plan is tried again with the same inputs (the
/// planner is deterministic: an immediate retry would fail the same way; the mission
/// time, and with it a restart's start, moves on meanwhile).
pub const FIRST_PLAN_RETRY: Duration = Duration::from_secs(2);

/// A request to stop the service, from another thread (tests; `main` uses signals).
#[derive(Debug, Clone, Default)]
pub struct Shutdown(Arc<AtomicBool>);

impl Shutdown {
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks the loop to stop. It notices on its next wake-up: an input, a finished plan,
    /// or the heartbeat at the latest.
    pub fn request(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    pub fn is_requested(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// What [`run`] needs.
pub struct RunOptions {
    pub config: ServiceConfig,
    /// Monotonic clock for compute deadlines, the compute gate and staleness (never for
    /// mission time, which comes from message headers).
    pub clock: &'static dyn Clock,
    /// Stop on SIGINT/SIGTERM (iceoryx2's signal handling). Off in in-process tests.
    pub handle_signals: bool,
    pub shutdown: Shutdown,
}

/// Why [`run`] returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitReason {
    /// SIGINT or SIGTERM.
    Signal,
    /// [`Shutdown::request`].
    Requested,
}

/// The end of a run.
#[derive(Debug, Clone)]
pub struct RunSummary {
    pub exit: ExitReason,
    /// The last status published.
    pub status: PlannerStatus,
    /// Dead iceoryx2 nodes whose resources were removed at start-up.
    pub dead_nodes_removed: u32,
}

/// The service could not start or its event loop failed.
#[derive(Debug, thiserror::Error)]
pub enum ServiceError {
    #[error("configuration: {0}")]
    Config(#[from] ConfigError),
    #[error("iceoryx2: {0}")]
    Ipc(#[from] IpcError),
    #[error("{0}")]
    Solver(#[from] SolverStartError),
    #[error("waitset: {0}")]
    WaitSet(String),
}

/// Gives the calling (message) thread a fair-scheduler slice of `us` µs (0: the kernel's
/// default), and says in the log what the kernel made of it.
fn message_thread_slice(us: u64) {
    if us == 0 {
        return;
    }
    match sched::set_thread_slice(Duration::from_micros(us)) {
        Ok(SliceOutcome::Applied(d)) => {
            info!(
                slice_us = d.as_micros() as u64,
                "message thread scheduler slice set"
            )
        }
        Ok(SliceOutcome::NotSupported) => warn!(
            slice_us = us,
            "this kernel has no per-thread scheduler slice (6.12 or later has): the message \
             thread keeps the default"
        ),
        Ok(SliceOutcome::NotFair(policy)) => info!(
            policy,
            "the message thread runs under a real-time policy: its slice is left alone"
        ),
        Err(e) => warn!(error = %e, "cannot set the message thread's scheduler slice"),
    }
}

/// Runs the planner service until a signal (with `handle_signals`) or a shutdown request:
/// removes dead iceoryx2 nodes' resources, opens the services of
/// `config.vehicle_id`, starts the solve thread and waits for events. On the way out it
/// finishes the plan in flight (publishing it), publishes a last status and releases
/// every resource.
pub fn run(options: RunOptions) -> Result<RunSummary, ServiceError> {
    options.config.validate()?;
    let cleanup = ipc::remove_dead_nodes(Duration::from_secs(1))?;
    if cleanup.removed + cleanup.failed > 0 {
        info!(
            removed = cleanup.removed,
            failed = cleanup.failed,
            "removed the resources of dead iceoryx2 nodes"
        );
    }
    let mut ml = MessageLoop::new(&options)?;
    // After the solve thread is started: only this thread gets the short slice.
    message_thread_slice(options.config.scheduling.message_slice_us);
    let listener = ml.listener()?;
    let mode = if options.handle_signals {
        SignalHandlingMode::HandleTerminationRequests
    } else {
        SignalHandlingMode::Disabled
    };
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(mode)
        .create::<Ipc>()
        .map_err(|e| ServiceError::WaitSet(format!("{e:?}")))?;
    let wake = waitset
        .attach_notification(&listener)
        .map_err(|e| ServiceError::WaitSet(format!("{e:?}")))?;
    let beat = waitset
        .attach_interval(options.config.heartbeat())
        .map_err(|e| ServiceError::WaitSet(format!("{e:?}")))?;
    info!(
        vehicle = %options.config.vehicle_id,
        heartbeat_ms = options.config.status.heartbeat_ms,
        "planner service running"
    );
    ml.process(true);
    let exit = loop {
        let mut heartbeat = false;
        let result = waitset.wait_and_process_once_with_timeout(
            |id| {
                if id.has_event_from(&wake) {
                    // Consume the notifications, or the WaitSet wakes at once again.
                    let _ = listener.try_wait(|_| {});
                } else if id.has_event_from(&beat) {
                    heartbeat = true;
                }
                CallbackProgression::Continue
            },
            ml.next_timeout(),
        );
        match result {
            Ok(WaitSetRunResult::TerminationRequest) => break ExitReason::Signal,
            // EINTR: the next call reports a termination request if that is what it was.
            Ok(WaitSetRunResult::Interrupt) => {}
            Ok(_) => {}
            Err(e) => return Err(ServiceError::WaitSet(format!("{e:?}"))),
        }
        if options.shutdown.is_requested() {
            break ExitReason::Requested;
        }
        ml.process(heartbeat);
    };
    info!(reason = ?exit, "planner service stopping");
    drop(beat);
    drop(wake);
    drop(waitset);
    drop(listener);
    let status = ml.finish();
    Ok(RunSummary {
        exit,
        status,
        dead_nodes_removed: cleanup.removed,
    })
}

/// The ports of the message thread.
struct Ports {
    tasking: Subscriber<Ipc, Tasking, ()>,
    route: Subscriber<Ipc, LeadRoute, ()>,
    lead_state: Subscriber<Ipc, LeadState, ()>,
    threats: Subscriber<Ipc, ThreatReport, ()>,
    tracks: Subscriber<Ipc, TrackFix, ()>,
    ownship: Subscriber<Ipc, OwnshipState, ()>,
    plan: Publisher<Ipc, Plan, ()>,
    status: Publisher<Ipc, PlannerStatus, ()>,
    harness: Notifier<Ipc>,
    wake: ipc::Event,
}

/// Counters of the status message.
#[derive(Debug, Clone, Copy, Default)]
struct Counters {
    received: u64,
    rejected: u64,
    plans: u64,
    coalesced: u64,
    deferred: u64,
    popups_clear: u64,
    /// Track fixes the Kalman filter refused (logged once, reported at exit).
    fixes_refused: u64,
    last_compute_ms: f64,
}

/// Triggers waiting for a plan.
#[derive(Debug, Clone, Copy, Default)]
struct Pending {
    set: TriggerSet,
    /// Mission time of the newest trigger folded in.
    created_at_s: f64,
    /// Counted in `triggers_deferred` already.
    deferred: bool,
    /// Wall-clock time at which the gate admits it.
    wake_at: Option<Duration>,
}

/// Why a plan cannot start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum NoSplice {
    /// The plan ends before the commit time: nothing to re-plan.
    MissionOver,
    /// No state to start from (no fresh ownship state of the tasking's model where the
    /// plan cannot say).
    NoStart,
}

/// A plan being computed.
#[derive(Debug, Clone, Copy)]
struct InFlight {
    ticket: Ticket,
}

/// The message loop: ports, world, triggers, the compute gate and the solve thread. `run`
/// drives it from a WaitSet; a test can drive [`MessageLoop::process`] directly.
pub struct MessageLoop {
    cfg: ServiceConfig,
    clock: &'static dyn Clock,
    ports: Ports,
    solver: Solver,
    world: Box<World>,
    /// The newest published plan, and a second buffer the next one is written into.
    current: Box<Plan>,
    scratch: Box<Plan>,
    has_plan: bool,
    /// Tasking revision and passed targets the current plan was made with.
    plan_revision: u32,
    plan_targets_from: usize,
    /// The first revision with the held tasking's content (later ones only repeat it).
    content_revision: u32,
    points: PlanPoints,
    /// The problem buffers, lent to the solver while a plan is in flight.
    problem: Option<Box<Problem>>,
    in_flight: Option<InFlight>,
    pending: Pending,
    batch: TriggerSet,
    batch_count: u64,
    /// A first tasking (or one after a failed first plan) waits for its plan.
    awaiting_first: bool,
    /// Until when (wall clock) a first plan waits for an ownship state, to tell a restart
    /// mid-mission from a take-off (`triggers.first_plan_wait_ms`).
    first_wait_until: Option<Duration>,
    /// Triggers whose plan had no state to start from (no fresh ownship state where the
    /// plan cannot say): raised again by the next ownship state of the tasking's model.
    awaiting_start: Option<TriggerSet>,
    /// After a failed first plan: wall-clock time of the next attempt with the same
    /// inputs (a new tasking or route tries at once).
    retry_first_at: Option<Duration>,
    gate: ComputeGate,
    counters: Counters,
    next_plan_id: u64,
    plan_sequence: u64,
    status_sequence: u64,
    deviation_fired_for: u64,
    expiry_fired_for: u64,
    scheduled_fired_for: u64,
    logged_rejections: [[bool; REJECTION_KINDS]; Input::COUNT],
    logged_receive_errors: [bool; Input::COUNT],
    logged_plan_id: bool,
    logged_fix_refused: bool,
    last_status: PlannerStatus,
    // Declared last: dropped after every port.
    node: Node<Ipc>,
}

impl MessageLoop {
    /// Opens the services and ports of `config.vehicle_id` and starts the solve thread.
    pub fn new(options: &RunOptions) -> Result<MessageLoop, ServiceError> {
        let cfg = options.config.clone();
        cfg.validate()?;
        let id = cfg.vehicle_id.as_str();
        let node = ipc::node(&format!("wingman-planner-{id}"), options.handle_signals)?;
        if options.handle_signals {
            // Installs iceoryx2's SIGINT/SIGTERM handler now (it is otherwise installed on
            // the first wait) and honours a request that came during start-up.
            if node.wait(Duration::ZERO).is_err() {
                warn!("termination requested during start-up");
                options.shutdown.request();
            }
        }
        let wake = ipc::open_event(&node, id, Service::PlannerWake)?;
        let harness_wake = ipc::open_event(&node, id, Service::HarnessWake)?;
        let plan_f = ipc::open_publish_subscribe::<Plan>(&node, id)?;
        let status_f = ipc::open_publish_subscribe::<PlannerStatus>(&node, id)?;
        let ports = Ports {
            tasking: ipc::subscriber(&ipc::open_publish_subscribe::<Tasking>(&node, id)?)?,
            route: ipc::subscriber(&ipc::open_publish_subscribe::<LeadRoute>(&node, id)?)?,
            lead_state: ipc::subscriber(&ipc::open_publish_subscribe::<LeadState>(&node, id)?)?,
            threats: ipc::subscriber(&ipc::open_publish_subscribe::<ThreatReport>(&node, id)?)?,
            tracks: ipc::subscriber(&ipc::open_publish_subscribe::<TrackFix>(&node, id)?)?,
            ownship: ipc::subscriber(&ipc::open_publish_subscribe::<OwnshipState>(&node, id)?)?,
            plan: ipc::publisher(&plan_f)?,
            status: ipc::publisher(&status_f)?,
            harness: ipc::notifier(&harness_wake, ipc::WAKE_HARNESS)?,
            wake,
        };
        let mut settings = PlannerSettings::default();
        settings.swarm = settings.swarm.with_seed(cfg.solver.seed);
        // One setting for both parallel stages: the swarm's workers and the NLP starts.
        settings.swarm.threads = cfg.solver.threads;
        settings.threads = cfg.solver.threads;
        let vehicle = cfg.vehicle_id.clone();
        let solver = Solver::spawn(
            settings,
            options.clock,
            Box::new(move || solver_waker(&vehicle)),
        )?;
        let gate = ComputeGate::new(GateSettings {
            min_spacing: Duration::from_millis(cfg.budget.min_spacing_ms),
            duty_cycle: cfg.budget.duty_cycle,
            window: Duration::from_millis(cfg.budget.duty_window_ms),
            threads: cfg.solver.threads.try_into().unwrap_or(u32::MAX),
        });
        let mut ml = MessageLoop {
            clock: options.clock,
            ports,
            solver,
            world: Box::default(),
            current: zeroed_plan(),
            scratch: zeroed_plan(),
            has_plan: false,
            plan_revision: 0,
            plan_targets_from: 0,
            content_revision: 0,
            points: PlanPoints::with_capacity(),
            problem: Some(Box::new(super::world::reusable_problem())),
            in_flight: None,
            pending: Pending::default(),
            batch: TriggerSet::EMPTY,
            batch_count: 0,
            awaiting_first: false,
            retry_first_at: None,
            awaiting_start: None,
            first_wait_until: None,
            gate,
            counters: Counters::default(),
            next_plan_id: 1,
            plan_sequence: 0,
            status_sequence: 0,
            deviation_fired_for: 0,
            expiry_fired_for: 0,
            scheduled_fired_for: 0,
            logged_rejections: [[false; REJECTION_KINDS]; Input::COUNT],
            logged_receive_errors: [false; Input::COUNT],
            logged_plan_id: false,
            logged_fix_refused: false,
            last_status: PlannerStatus::zeroed(),
            node,
            cfg,
        };
        ml.last_status = ml.status_message();
        Ok(ml)
    }

    /// A listener of `wake/planner` for the WaitSet.
    pub fn listener(&self) -> Result<Listener<Ipc>, IpcError> {
        ipc::listener(&self.ports.wake)
    }

    /// The node (for tests that open more ports on it).
    pub fn node(&self) -> &Node<Ipc> {
        &self.node
    }

    /// How long the WaitSet may sleep before a deferred plan is due, or a first plan's
    /// wait for an ownship state ends (`Duration::MAX`: until an event or the heartbeat).
    pub fn next_timeout(&self) -> Duration {
        let deferred = match (self.in_flight, self.pending.wake_at) {
            (None, Some(at)) if !self.pending.set.is_empty() => Some(at),
            _ => None,
        };
        let first = self.first_wait_until.filter(|_| self.waiting_for_ownship());
        match deferred.into_iter().chain(first).min() {
            Some(at) => at
                .saturating_sub(self.clock.now())
                .max(Duration::from_micros(100)),
            None => Duration::MAX,
        }
    }

    /// A first plan is due: the tasking (and a rendezvous's route) is here and no failed
    /// first plan waits for its retry. It starts at the next pass once no longer
    /// [waiting for an ownship state](Self::waiting_for_ownship).
    fn first_plan_due(&self) -> bool {
        let Some(t) = &self.world.tasking else {
            return false;
        };
        let needs_route = t.objective() == Some(Objective::MinTimeRendezvous);
        self.awaiting_first
            && self.retry_first_at.is_none_or(|at| self.clock.now() >= at)
            && (!needs_route || self.world.route.is_some())
    }

    /// A first plan waits for an ownship state (see `first_wait_until`).
    fn waiting_for_ownship(&self) -> bool {
        self.awaiting_first
            && self.world.ownship.is_none()
            && self
                .first_wait_until
                .is_some_and(|at| self.clock.now() < at)
    }

    /// The last status published.
    pub fn status(&self) -> &PlannerStatus {
        &self.last_status
    }

    /// One pass of the loop (see the module documentation). `heartbeat`: the heartbeat
    /// interval fired, so the status goes out even if nothing changed.
    pub fn process(&mut self, heartbeat: bool) {
        if self.update() || heartbeat {
            self.publish_status();
        }
        if heartbeat {
            // Deliver the history (newest plan, newest status) to late subscribers.
            let _ = self.ports.plan.update_connections();
            let _ = self.ports.status.update_connections();
        }
    }

    /// The pass without the status: takes the finished plan (publishing it), drains and
    /// handles every input, evaluates the triggers and starts a plan. Returns whether
    /// anything changed (then a status is due).
    pub fn update(&mut self) -> bool {
        let mut changed = false;
        while let Some(result) = self.solver.try_result() {
            self.on_result(result);
            changed = true;
        }
        changed |= self.drain() > 0;
        changed |= self.evaluate();
        changed
    }

    /// Publishes the status and notifies `wake/harness`. (iceoryx2 0.10 allocates a small
    /// shared-state `Arc` for every loaned sample, freed when it is sent: the one
    /// allocation of a pass that is not ours.)
    pub fn publish_status(&mut self) {
        let s = self.status_message();
        match self.ports.status.loan_uninit() {
            Ok(sample) => {
                if let Err(e) = sample.write_payload(s).send() {
                    error!(error = ?e, "cannot send the status");
                }
            }
            Err(e) => error!(error = ?e, "cannot loan a status sample"),
        }
        self.status_sequence += 1;
        self.last_status = s;
        let _ = self.ports.harness.notify();
    }

    /// Ends the run: waits for the plan in flight (it ends by its deadline) and publishes
    /// it, publishes a last status, stops the solve thread. Returns the last status.
    pub fn finish(mut self) -> PlannerStatus {
        if let Some(f) = self.in_flight {
            let wait = f.ticket.budget + Duration::from_secs(2);
            if let Some(result) = self.solver.wait_result(wait) {
                self.on_result(result);
            }
        }
        self.pending = Pending::default();
        self.publish_status();
        let status = self.last_status;
        info!(
            fixes_refused = self.counters.fixes_refused,
            threats_dropped = self.world.threats_dropped,
            "inputs the world model could not take"
        );
        let MessageLoop { solver, .. } = self;
        solver.shutdown(Duration::from_secs(2));
        status
    }

    // ---------------------------------------------------------------------------------
    // Inputs
    // ---------------------------------------------------------------------------------

    /// Drains every input subscriber; returns the number of samples taken.
    fn drain(&mut self) -> u64 {
        let before = self.counters.received;
        macro_rules! drain {
            ($port:ident, $input:expr, $handle:ident) => {
                loop {
                    match self.ports.$port.receive() {
                        Ok(Some(sample)) => {
                            let msg = *sample.payload();
                            drop(sample);
                            if self.admit($input, &msg) {
                                self.$handle(&msg);
                            }
                        }
                        Ok(None) => break,
                        Err(e) => {
                            let k = $input as usize;
                            if !self.logged_receive_errors[k] {
                                self.logged_receive_errors[k] = true;
                                error!(input = $input.name(), error = ?e, "receive failed");
                            }
                            break;
                        }
                    }
                }
            };
        }
        drain!(tasking, Input::Tasking, on_tasking);
        drain!(route, Input::LeadRoute, on_route);
        drain!(threats, Input::Threats, on_threat);
        drain!(tracks, Input::Tracks, on_fix);
        drain!(lead_state, Input::LeadState, on_lead_state);
        drain!(ownship, Input::Ownship, on_ownship);
        self.counters.received - before
    }

    /// Counts a sample and validates it; an invalid one is counted, logged once per input
    /// and kind, and changes nothing.
    fn admit<M: Message>(&mut self, input: Input, msg: &M) -> bool {
        self.counters.received += 1;
        self.world.note_sequence(msg.header());
        let wall = self.clock.now();
        let checked = msg
            .validate()
            .and_then(|()| self.world.accept_header(input, msg.header(), wall));
        match checked {
            Ok(()) => true,
            Err(e) => {
                self.counters.rejected += 1;
                let kind = rejection_index(&e);
                let logged = &mut self.logged_rejections[input as usize][kind];
                if !*logged {
                    *logged = true;
                    warn!(
                        input = input.name(),
                        error = %e,
                        "dropped an invalid message (further ones of this kind are only counted)"
                    );
                }
                false
            }
        }
    }

    fn on_tasking(&mut self, t: &Tasking) {
        let decision = self.world.apply_tasking(t);
        if matches!(decision, TaskingDecision::First | TaskingDecision::Changed) {
            self.content_revision = t.revision;
        }
        match decision {
            TaskingDecision::First => {
                self.awaiting_first = true;
                if self.world.ownship.is_none() {
                    let wait = Duration::from_millis(self.cfg.triggers.first_plan_wait_ms);
                    self.first_wait_until = Some(self.clock.now() + wait);
                }
            }
            TaskingDecision::Changed if !self.has_plan && self.in_flight.is_none() => {
                info!(revision = t.revision, "tasking changed before a first plan");
                self.awaiting_first = true;
                self.retry_first_at = None;
            }
            TaskingDecision::Changed => {
                info!(revision = t.revision, "tasking changed");
                if self.has_plan || self.in_flight.is_some() {
                    self.raise(Trigger::Tasking);
                } else {
                    self.awaiting_first = true;
                }
            }
            // Only the start may differ (it is not compared): a waiting first plan uses it
            // at once.
            TaskingDecision::Unchanged if !self.has_plan => self.retry_first_at = None,
            TaskingDecision::Unchanged | TaskingDecision::Stale => {}
        }
    }

    fn on_route(&mut self, r: &LeadRoute) {
        let decision = self.world.apply_route(r);
        let rendezvous = self
            .world
            .tasking
            .as_ref()
            .is_some_and(|t| t.objective() == Some(Objective::MinTimeRendezvous));
        if decision == RouteDecision::Changed
            && rendezvous
            && (self.has_plan || self.in_flight.is_some())
        {
            info!(revision = r.revision, "lead route changed");
            self.raise(Trigger::LeadRoute);
        } else if matches!(decision, RouteDecision::First | RouteDecision::Changed)
            && !self.has_plan
            && self.in_flight.is_none()
            && self.world.tasking.is_some()
        {
            // No plan yet (none made, or the first one failed): try with this route.
            self.awaiting_first = true;
            self.retry_first_at = None;
        }
    }

    fn on_lead_state(&mut self, s: &LeadState) {
        self.world.apply_lead_state(s);
    }

    fn on_ownship(&mut self, s: &OwnshipState) {
        self.world.apply_ownship(s);
        let model = self.world.tasking.as_ref().and_then(Tasking::model);
        if s.model() == model
            && let Some(set) = self.awaiting_start.take()
        {
            info!("an ownship state to start from: the waiting plan starts");
            self.batch = self.batch.union(set);
            self.batch_count += 1;
        }
        // Plan ids keep growing across a restart of the planner: before its first plan,
        // the planner continues above the id the tracker flies. Once it has a plan, the
        // ids are its own. An id too large to continue from is refused (logged once).
        if !self.has_plan && s.plan_id >= self.next_plan_id {
            if s.plan_id < MAX_CONTINUED_PLAN_ID {
                self.next_plan_id = s.plan_id + 1;
            } else if !self.logged_plan_id {
                self.logged_plan_id = true;
                error!(
                    plan_id = s.plan_id,
                    limit = MAX_CONTINUED_PLAN_ID,
                    "the ownship reports a plan id too large to continue from; ignored"
                );
            }
        }
    }

    fn on_threat(&mut self, r: &ThreatReport) {
        let wall = self.clock.now();
        let slot = match self.world.apply_threat(r, wall) {
            ThreatChange::New(s) | ThreatChange::Changed(s) => s,
            ThreatChange::Unchanged => return,
            ThreatChange::Full => {
                // Logged once; the status says `Degraded` from now on.
                if self.world.threats_dropped == 1 {
                    error!(
                        threat = r.threat_id,
                        static_capacity = super::world::MAX_STATIC_THREATS,
                        moving_capacity = super::world::MAX_MOVING_THREATS,
                        "no room for another threat: report ignored, the planner is Degraded \
                         (further ones are only counted)"
                    );
                }
                return;
            }
            ThreatChange::Refused(e) => {
                warn!(threat = r.threat_id, error = %e, "moving threat refused");
                return;
            }
        };
        if !self.has_plan {
            // No plan to assess: a plan in flight does not know it, so it is pending.
            if self.in_flight.is_some() {
                self.raise(Trigger::PopUp);
            }
            return;
        }
        match self.assess_popup(slot) {
            Some(PopupAssessment::Touches(hit)) => {
                info!(
                    threat = r.threat_id,
                    at_s = hit.t,
                    f = hit.f,
                    "pop-up reaches the plan: re-plan"
                );
                self.raise(Trigger::PopUp);
            }
            Some(PopupAssessment::Clear) => {
                self.counters.popups_clear += 1;
                info!(threat = r.threat_id, "pop-up clear of the plan: no re-plan");
                if let ThreatSlot::Moving(i) = slot {
                    self.schedule(i);
                }
            }
            None => warn!(threat = r.threat_id, "pop-up does not fit the plan's model"),
        }
    }

    fn on_fix(&mut self, f: &TrackFix) {
        let wall = self.clock.now();
        match self.world.apply_fix(f, wall) {
            FixOutcome::Applied(i) => {
                if self.has_plan {
                    self.schedule(i);
                }
            }
            FixOutcome::Refused(e) => {
                self.counters.fixes_refused += 1;
                if !self.logged_fix_refused {
                    self.logged_fix_refused = true;
                    warn!(
                        threat = f.threat_id,
                        error = %e,
                        "a track fix was refused by the filter (further ones are only counted)"
                    );
                }
            }
            FixOutcome::UnknownThreat => {}
        }
    }

    // ---------------------------------------------------------------------------------
    // Triggers
    // ---------------------------------------------------------------------------------

    fn raise(&mut self, t: Trigger) {
        self.batch.insert(t);
        self.batch_count += 1;
    }

    /// Pop-up test of one threat against the plan from now on.
    fn assess_popup(&self, slot: ThreatSlot) -> Option<PopupAssessment> {
        let now = self.world.now_s();
        let f_star = self.cfg.triggers.f_star;
        match (slot, self.current.model()) {
            (ThreatSlot::Static(i), Some(Model::TwoD)) => {
                let shape = self.world.static_threat(i)?.shape::<2>().ok()?;
                let rest = triggers::remaining(&self.points.planar, now);
                Some(triggers::static_popup(rest, &shape, f_star))
            }
            (ThreatSlot::Static(i), Some(Model::ThreeD)) => {
                let shape = self.world.static_threat(i)?.shape::<3>().ok()?;
                let rest = triggers::remaining(&self.points.spatial, now);
                Some(triggers::static_popup(rest, &shape, f_star))
            }
            (ThreatSlot::Moving(i), Some(Model::TwoD)) => {
                let threat = self.world.moving(i)?.threat::<2>().ok()?;
                let rest = triggers::remaining(&self.points.planar, now);
                Some(triggers::moving_popup(rest, &threat, f_star))
            }
            (ThreatSlot::Moving(i), Some(Model::ThreeD)) => {
                let threat = self.world.moving(i)?.threat::<3>().ok()?;
                let rest = triggers::remaining(&self.points.spatial, now);
                Some(triggers::moving_popup(rest, &threat, f_star))
            }
            (_, None) => None,
        }
    }

    /// Recomputes `t_r` of moving threat `i` over the current plan.
    fn schedule(&mut self, i: usize) {
        // From the plan's start plus the least lead, and never in the past: a threat that
        // was critical only before now (by the newest estimate) needs no re-plan.
        let not_before = (self.current.start_time_s + self.cfg.triggers.replan_min_lead_s)
            .max(self.world.now_s());
        let t_r = match self.current.model() {
            Some(Model::TwoD) => self
                .world
                .moving(i)
                .and_then(|m| m.threat::<2>().ok())
                .and_then(|t| triggers::scheduled_replan(&self.points.planar, &t, not_before)),
            Some(Model::ThreeD) => self
                .world
                .moving(i)
                .and_then(|m| m.threat::<3>().ok())
                .and_then(|t| triggers::scheduled_replan(&self.points.spatial, &t, not_before)),
            None => None,
        };
        if let Some(m) = self.world.moving_mut(i) {
            m.t_r = t_r.map(|r| r.t);
        }
    }

    /// Budget of a plan of the current tasking's model.
    fn budget(&self) -> Duration {
        let model = self
            .world
            .tasking
            .as_ref()
            .and_then(Tasking::model)
            .unwrap_or(Model::ThreeD);
        self.cfg.plan_budget(model)
    }

    /// Time triggers, folding the batch into the pending set, and starting a plan.
    /// Returns whether anything changed.
    fn evaluate(&mut self) -> bool {
        let now = self.world.now_s();
        let lead = self.budget().as_secs_f64();
        if self.first_plan_due()
            && !self.waiting_for_ownship()
            && let Some(t) = &self.world.tasking
        {
            let trigger = triggers::first_plan_trigger(t, self.world.ownship.as_ref());
            self.awaiting_first = false;
            self.retry_first_at = None;
            self.raise(trigger);
        }
        let quiet = self.in_flight.is_none() && self.pending.set.is_empty();
        if self.has_plan && quiet && self.batch.is_empty() {
            let id = self.current.plan_id;
            // The plan promised its re-plan time (its `valid_until`): newer estimates may
            // bring it forward, never push it back.
            let promised = (self.scheduled_fired_for != id)
                .then(|| self.current.next_replan())
                .flatten();
            let scheduled = match (self.world.next_replan(), promised) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
            if let Some(t_r) = scheduled
                && triggers::scheduled_due(now, t_r, lead)
            {
                info!(t_r, "scheduled re-plan of a moving threat");
                self.world.clear_schedules();
                self.scheduled_fired_for = id;
                self.raise(Trigger::ScheduledReplan);
            }
            let holding = self
                .world
                .ownship
                .as_ref()
                .is_some_and(|o| o.holding() && o.plan_id <= id);
            let window = PlanWindow {
                start_s: self.current.start_time_s,
                valid_until_s: self.current.valid_until_s,
                final_time_s: self.current.final_time_s,
            };
            // A plan cut short by its scheduled re-plan expires only if that re-plan has
            // fired and brought no successor (the schedule is then cleared).
            if self.expiry_fired_for != id
                && (scheduled.is_none() || holding)
                && self.batch.is_empty()
                && triggers::expiry_due(now, &window, lead, holding)
            {
                self.expiry_fired_for = id;
                info!(holding, "plan expires");
                self.raise(Trigger::Expiry);
            }
            let bounds = DeviationBounds {
                cross_m: self.cfg.triggers.deviation_cross_m,
                vertical_m: self.cfg.triggers.deviation_vertical_m,
            };
            if self.deviation_fired_for != id
                && let Some(o) = &self.world.ownship
                && triggers::deviation_exceeded(o, id, &bounds)
            {
                self.deviation_fired_for = id;
                info!(
                    cross_m = o.cross_track_m,
                    vertical_m = o.vertical_m,
                    "deviation from the plan"
                );
                self.raise(Trigger::Deviation);
            }
        }
        let mut changed = false;
        if self.batch_count > 0 {
            let busy = self.in_flight.is_some() || !self.pending.set.is_empty();
            self.counters.coalesced += if busy {
                self.batch_count
            } else {
                self.batch_count - 1
            };
            self.pending.set = self.pending.set.union(self.batch);
            self.pending.created_at_s = if now.is_finite() { now } else { 0.0 };
            self.batch = TriggerSet::EMPTY;
            self.batch_count = 0;
            changed = true;
        }
        if self.in_flight.is_none() && !self.pending.set.is_empty() {
            changed |= self.try_start();
        }
        changed
    }

    /// Starts the pending plan if the gate admits it, else defers it.
    fn try_start(&mut self) -> bool {
        let budget = self.budget();
        let wall = self.clock.now();
        if !self.gate.admits(wall, budget) {
            if !self.pending.deferred {
                self.pending.deferred = true;
                self.counters.deferred += 1;
            }
            self.pending.wake_at = self.gate.earliest_start(wall, budget);
            return false;
        }
        let set = self.pending.set;
        let Some(trigger) = set.primary() else {
            return false;
        };
        let created_at_s = self.pending.created_at_s;
        self.pending = Pending::default();
        let splice = match self.splice(set, budget) {
            Ok(s) => s,
            Err(NoSplice::MissionOver) => return true,
            Err(NoSplice::NoStart) => {
                // Tried again when the next ownship state of the tasking's model arrives.
                self.awaiting_start = Some(self.awaiting_start.unwrap_or_default().union(set));
                return true;
            }
        };
        let Some(tasking) = self.world.tasking else {
            return true;
        };
        let Some(mut problem) = self.problem.take() else {
            error!("the problem buffers are missing; no plan");
            return true;
        };
        match self.world.fill_problem(&splice, &mut problem) {
            Ok(0) => {}
            Ok(skipped) => warn!(skipped, "threats that do not fit the model were left out"),
            Err(e) => {
                error!(error = %e, trigger = trigger.name(), "cannot build the problem; no plan");
                self.problem = Some(problem);
                return true;
            }
        }
        let ticket = Ticket {
            plan_id: self.next_plan_id,
            trigger,
            created_at_s,
            budget,
            epoch: self.world.epoch,
            targets_from: splice.targets_from,
            tasking_revision: tasking.revision,
        };
        match self.solver.submit(SolveRequest { problem, ticket }) {
            Ok(()) => {
                self.gate.begin(wall);
                self.in_flight = Some(InFlight { ticket });
                info!(
                    trigger = trigger.name(),
                    commit_s = splice.t0,
                    targets = tasking.targets().len().saturating_sub(splice.targets_from),
                    "plan started"
                );
            }
            Err(request) => {
                error!("the solve thread is not taking requests; no plan");
                self.problem = Some(request.problem);
            }
        }
        true
    }

    /// Where a plan for the pending triggers `set` starts: the tasking's start for the
    /// first plan; else the commit time `now + budget` and the state the current plan
    /// predicts there (the state the tracker will be in), or the ownship's state
    /// dead-reckoned to it when the plan cannot say (a deviation or a restart among the
    /// pending triggers, whichever names the plan; a safe hold; past the plan's end; a
    /// tasking of another model). Only a fresh ownship state (mission time within
    /// `staleness.ownship_ms` of now) of the tasking's model is dead-reckoned; without one
    /// the plan's own state is used if it can be, else there is no plan for now. Targets
    /// the current plan passes before the commit time are left out.
    fn splice(&self, set: TriggerSet, budget: Duration) -> Result<Splice, NoSplice> {
        let t = self.world.tasking.as_ref().ok_or(NoSplice::NoStart)?;
        let trigger = set.primary().ok_or(NoSplice::NoStart)?;
        if trigger == Trigger::Initial {
            return Ok(Splice {
                t0: t.start_time_s,
                x0: t.start_state,
                targets_from: 0,
            });
        }
        let now = self.world.now_s();
        let t_c = if now.is_finite() {
            now + budget.as_secs_f64()
        } else {
            t.start_time_s
        };
        // The current plan, if its states are in the tasking's layout.
        let plan = self
            .has_plan
            .then_some(&*self.current)
            .filter(|p| p.model() == t.model());
        let targets_from = match plan {
            // The plan was made from this tasking's content (a later revision that only
            // repeats it keeps the passed targets).
            Some(p) if (self.content_revision..=t.revision).contains(&self.plan_revision) => {
                let phases = p.phase_ends();
                let passed = phases[..phases.len().saturating_sub(1)]
                    .iter()
                    .filter(|&&e| e <= t_c)
                    .count();
                self.plan_targets_from + passed
            }
            _ => 0,
        };
        let own = self.world.ownship.as_ref();
        let holding = own.is_some_and(OwnshipState::holding);
        let from_ownship = triggers::splice_from_ownship(set, holding);
        let mission_over =
            plan.is_some_and(|p| p.valid_until_s >= p.final_time_s && t_c >= p.final_time_s);
        if mission_over && set.only_of(&[Trigger::PopUp, Trigger::ScheduledReplan]) {
            info!(
                trigger = trigger.name(),
                "the plan ends before the commit time: no re-plan"
            );
            return Err(NoSplice::MissionOver);
        }
        let beyond = plan.is_none_or(|p| t_c > p.final_time_s);
        let max_age_s = self.cfg.staleness.ownship_ms as f64 * 1e-3;
        let reckoned = own.and_then(|o| {
            let fresh = now - o.time_s <= max_age_s;
            fresh.then(|| dead_reckon(o, t, t_c)).flatten()
        });
        let from_plan = |p: &Plan| {
            let t0 = t_c.max(p.start_time_s);
            export::state_at(p, t0).map(|x0| Splice {
                t0,
                x0,
                targets_from,
            })
        };
        if from_ownship || beyond {
            if let Some(x0) = reckoned {
                return Ok(Splice {
                    t0: t_c,
                    x0,
                    targets_from,
                });
            }
            if own.is_some() || plan.is_some() {
                warn!(
                    trigger = trigger.name(),
                    "no fresh ownship state of the tasking's model to start from"
                );
            }
        }
        match plan {
            Some(p) if !beyond => from_plan(p).ok_or(NoSplice::NoStart),
            Some(_) => Err(NoSplice::NoStart),
            None if own.is_none() && !self.has_plan => Ok(Splice {
                t0: t.start_time_s.max(t_c),
                x0: t.start_state,
                targets_from: 0,
            }),
            None => {
                if self.has_plan && reckoned.is_none() {
                    error!(
                        "the tasking changed model and no ownship state of the new model is \
                         fresh: no plan until one arrives"
                    );
                }
                Err(NoSplice::NoStart)
            }
        }
    }

    // ---------------------------------------------------------------------------------
    // Results
    // ---------------------------------------------------------------------------------

    fn on_result(&mut self, result: SolveResult) {
        let SolveResult {
            problem,
            ticket,
            outcome,
            started,
            finished,
            core_time,
        } = result;
        self.in_flight = None;
        self.problem = Some(problem);
        self.gate.record(started, finished, core_time);
        let compute_ms = finished.saturating_sub(started).as_secs_f64() * 1e3;
        self.counters.last_compute_ms = compute_ms;
        match outcome {
            Ok(o) => self.accept(&o, &ticket, compute_ms),
            Err(e) => {
                warn!(trigger = ticket.trigger.name(), error = %e, "no plan made");
                // Without a plan the status says `Degraded`; the first plan is tried again
                // (the compute gate spaces the attempts), and a new tasking or route is
                // taken into the next attempt.
                if !self.has_plan {
                    self.awaiting_first = true;
                    self.retry_first_at = Some(self.clock.now() + FIRST_PLAN_RETRY);
                }
            }
        }
        // Threats that changed while the plan was computed are not in it: check each
        // against the plan now current (a pop-up clear of the old plan may lie on the new
        // one). Pending pop-ups that the new plan already avoids need no follow-up.
        if self.has_plan && self.world.epoch > ticket.epoch {
            let touch = self.popups_touch(ticket.epoch);
            if self.pending.set.only_popups() && !touch {
                info!("pop-ups during the plan are clear of it: no follow-up");
                self.pending = Pending::default();
            } else if touch && self.pending.set.is_empty() {
                info!("a threat reported during the plan reaches it: re-plan");
                self.raise(Trigger::PopUp);
            }
        }
    }

    /// Whether any threat changed after `epoch` reaches the current plan.
    fn popups_touch(&self, epoch: u64) -> bool {
        let mut touches = false;
        for i in 0..super::world::MAX_STATIC_THREATS {
            if let Some(s) = self.world.static_threat(i)
                && s.epoch > epoch
            {
                touches |= self
                    .assess_popup(ThreatSlot::Static(i))
                    .is_none_or(|a| a.touches());
            }
        }
        for (i, m) in self.world.movings() {
            if m.epoch > epoch {
                touches |= self
                    .assess_popup(ThreatSlot::Moving(i))
                    .is_none_or(|a| a.touches());
            }
        }
        touches
    }

    /// Publishes a plan made by the solver and makes it current.
    fn accept(&mut self, o: &PlanOutcome, ticket: &Ticket, compute_ms: f64) {
        // The model and speed of the problem planned (the tasking may have changed since).
        let Some((model, speed)) = self.problem.as_ref().map(|p| (p.model, p.limits.speed)) else {
            error!(
                trigger = ticket.trigger.name(),
                "the problem buffers are missing: the plan made is dropped"
            );
            return;
        };
        let info = PlanInfo {
            plan_id: self.next_plan_id,
            trigger: ticket.trigger,
            quality: o.quality,
            model,
            created_at_s: ticket.created_at_s,
            cost: o.cost,
            compute_ms,
        };
        let header = Header::new(
            SENDER_PLANNER,
            self.plan_sequence + 1,
            self.world.now_ns.max(0),
        );
        if let Err(e) = export::write_plan(&mut self.scratch, header, &info, &o.trajectory) {
            error!(error = %e, "the plan cannot be exported; it is dropped");
            return;
        }
        // Scheduled re-plans of the moving threats over the new plan.
        self.points.fill(&self.scratch, speed);
        std::mem::swap(&mut self.current, &mut self.scratch);
        self.has_plan = true;
        let slots: [Option<usize>; super::world::MAX_MOVING_THREATS] = {
            let mut s = [None; super::world::MAX_MOVING_THREATS];
            for (k, (i, _)) in self.world.movings().enumerate() {
                s[k] = Some(i);
            }
            s
        };
        for i in slots.into_iter().flatten() {
            self.schedule(i);
        }
        export::set_next_replan(&mut self.current, self.world.next_replan());
        self.awaiting_start = None;
        self.plan_revision = ticket.tasking_revision;
        self.plan_targets_from = ticket.targets_from;
        self.publish_plan();
        self.plan_sequence += 1;
        match self.next_plan_id.checked_add(1) {
            Some(n) => self.next_plan_id = n,
            None => error!("plan ids exhausted: the next plan repeats the id"),
        }
        self.counters.plans += 1;
        info!(
            plan_id = self.current.plan_id,
            trigger = ticket.trigger.name(),
            quality = o.quality.name(),
            start_s = self.current.start_time_s,
            valid_until_s = self.current.valid_until_s,
            samples = self.current.sample_count,
            next_replan_s = self.current.next_replan(),
            "plan published"
        );
    }

    fn publish_plan(&mut self) {
        match self.ports.plan.loan_uninit() {
            Ok(mut sample) => {
                let slot = sample.payload_mut();
                // SAFETY: `current` is a valid `Plan` and the loaned slot holds room for one;
                // the copy goes memory to memory (160 KiB never cross the stack).
                let sample = unsafe {
                    std::ptr::copy_nonoverlapping(&*self.current, slot.as_mut_ptr(), 1);
                    sample.assume_init()
                };
                if let Err(e) = sample.send() {
                    error!(error = ?e, "cannot send the plan");
                }
            }
            Err(e) => error!(error = ?e, "cannot loan a plan sample"),
        }
    }

    // ---------------------------------------------------------------------------------
    // Status
    // ---------------------------------------------------------------------------------

    /// The status a publication would send now.
    pub fn status_message(&self) -> PlannerStatus {
        let wall = self.clock.now();
        let stale = self.world.stale_bits(wall, &self.cfg.staleness);
        // `Planning` also while a triggered plan waits for the compute gate, or a first
        // plan is due (waiting for an ownship state, or about to start at the next pass
        // once that wait is over): a lock-step harness then waits for it as for a plan in
        // flight.
        let state = if self.in_flight.is_some()
            || !self.pending.set.is_empty()
            || self.waiting_for_ownship()
            || self.first_plan_due()
        {
            PlannerState::Planning
        } else if stale != 0
            || (self.world.tasking.is_some() && !self.has_plan)
            || self.world.threats_dropped > 0
        {
            PlannerState::Degraded
        } else {
            PlannerState::Idle
        };
        let mut s = PlannerStatus::zeroed();
        s.header = Header::new(
            SENDER_PLANNER,
            self.status_sequence + 1,
            self.world.now_ns.max(0),
        );
        s.state = state.to_wire();
        s.stale_inputs = stale;
        s.last_input_sequence = self.world.max_sequence;
        s.current_plan_id = if self.has_plan {
            self.current.plan_id
        } else {
            0
        };
        s.messages_received = self.counters.received;
        s.messages_rejected = self.counters.rejected;
        s.plans_made = self.counters.plans;
        s.triggers_coalesced = self.counters.coalesced;
        s.triggers_deferred = self.counters.deferred;
        s.popups_clear = self.counters.popups_clear;
        s.last_plan_compute_ms = self.counters.last_compute_ms;
        s.budget_remaining_ms = self.gate.remaining(wall).as_secs_f64() * 1e3;
        s
    }
}

/// The solve thread's way to wake the message thread: a node of its own and a notifier of
/// `wake/planner` (iceoryx2 ports are not `Send`).
fn solver_waker(vehicle_id: &str) -> Result<Box<dyn FnMut()>, String> {
    let node = ipc::node(&format!("wingman-planner-{vehicle_id}-solve"), false)
        .map_err(|e| e.to_string())?;
    let event =
        ipc::open_event(&node, vehicle_id, Service::PlannerWake).map_err(|e| e.to_string())?;
    let notifier = ipc::notifier(&event, ipc::WAKE_SOLVER).map_err(|e| e.to_string())?;
    Ok(Box::new(move || {
        let _keep = (&node, &event);
        if let Err(e) = notifier.notify() {
            error!(error = ?e, "cannot wake the message thread");
        }
    }))
}

/// The ownship's state carried forward at constant speed and heading from its time to
/// `t`, with the 3-D attitude kept inside the tasking's limits. `None` if the ownship's
/// state is not in the tasking's model (its layout differs).
fn dead_reckon(o: &OwnshipState, t: &Tasking, at: f64) -> Option<[f64; 7]> {
    if o.model().is_none() || o.model() != t.model() {
        return None;
    }
    let dt = (at - o.time_s).max(0.0);
    let v = t.limits.speed_mps;
    let mut x = o.state;
    match t.model() {
        Some(Model::ThreeD) => {
            let l = &t.limits;
            let (sg, cg) = x[idx3::GAMMA].sin_cos();
            let (sc, cc) = x[idx3::CHI].sin_cos();
            x[0] += v * cg * cc * dt;
            x[1] += v * cg * sc * dt;
            x[2] = (x[2] + v * sg * dt).max(l.altitude_min_m);
            let limits = VehicleLimits {
                speed: v,
                turn_rate_max: f64::INFINITY,
                gamma_max: l.gamma_max_rad,
                nz_min: l.nz_min,
                nz_max: l.nz_max,
                mu_max: l.bank_max_rad,
                nz_rate_max: l.nz_rate_max_per_s,
                mu_rate_max: l.bank_rate_max_rps,
                z_min: l.altitude_min_m,
            };
            x[idx3::GAMMA] = x[idx3::GAMMA].clamp(-limits.gamma_max, limits.gamma_max);
            x[idx3::NZ] = x[idx3::NZ].clamp(limits.nz_min, limits.nz_max);
            x[idx3::MU] = x[idx3::MU].clamp(-limits.mu_max, limits.mu_max);
        }
        _ => {
            let (s, c) = x[2].sin_cos();
            x[0] += v * c * dt;
            x[1] += v * s * dt;
        }
    }
    Some(x)
}

/// Kinds of [`ValidationError`] ([`rejection_index`] maps each to one below this).
const REJECTION_KINDS: usize = 7;

/// Index of a validation error's kind (for logging once per kind), below
/// [`REJECTION_KINDS`]. The match is exhaustive: a new kind fails to compile here.
fn rejection_index(e: &ValidationError) -> usize {
    match e {
        ValidationError::ProtocolVersion { .. } => 0,
        ValidationError::NonFinite { .. } => 1,
        ValidationError::CountOverCapacity { .. } => 2,
        ValidationError::CountTooSmall { .. } => 3,
        ValidationError::UnknownEnum { .. } => 4,
        ValidationError::TimeBackwards { .. } => 5,
        ValidationError::OutOfRange { .. } => 6,
    }
}

/// A zero-filled plan on the heap (never on the stack: it is 160 KiB).
fn zeroed_plan() -> Box<Plan> {
    let mut b = Box::<Plan>::new_uninit();
    Plan::zeroed_in(&mut b);
    // SAFETY: `zeroed_in` initialised every byte.
    unsafe { b.assume_init() }
}
