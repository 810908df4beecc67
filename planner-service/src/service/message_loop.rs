//! The message loop: the message thread's state (ports, world, triggers, the compute gate,
//! the solve thread) and its pass. [`run`](super::run::run) sleeps in an iceoryx2 WaitSet
//! (the `wake/planner` listener, the heartbeat interval, and a timeout while a plan is
//! deferred or a first plan waits for an ownship state) and on each wake-up makes one
//! pass ([`MessageLoop::process`]):
//!
//! 1. takes the solve thread's finished plan, if any, and publishes it as a `Plan`
//!    (`results`);
//! 2. drains every input subscriber: each sample is `validate()`d first (an invalid one is
//!    dropped, counted, and logged once per input and kind), then updates the world model
//!    and raises the event triggers (pop-ups, tasking and route changes) (`inputs`);
//! 3. evaluates the time triggers (scheduled `t_r`, deviation, expiry) and, when a trigger
//!    is pending and no plan is in flight, starts a plan if the compute gate admits it
//!    (`planning`), from the start state `splice` finds;
//! 4. publishes `PlannerStatus` (echoing the highest input sequence, after all of the
//!    above is visible) and notifies `wake/harness` (`status`).
//!
//! Where the loop stands with its plan is explicit (`lifecycle`): a `PlanLifecycle`
//! (`Idle`, `Triggered`, `Deferred` by the compute gate, `Planning` with a follow-up) and,
//! before the first plan is triggered, a `FirstPlan` (`NotDue`, `WaitingForOwnship`,
//! `Due`, `RetryAfterFailure`).
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
//! compute gate or a first plan for an ownship state. The injected clock bounds compute (deadlines, gate, staleness) only.

mod inputs;
mod lifecycle;
mod planning;
mod results;
mod splice;
mod status;

use std::time::Duration;

use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use tracing::{error, info, warn};
use wingman_interfaces::{
    LeadRoute, LeadState, Model, OwnshipState, Plan, PlannerStatus, Service, Tasking, ThreatReport,
    TrackFix, Wire,
};

use super::budget::{ComputeGate, GateSettings};
use super::run::{RunOptions, ServiceError};
use super::solver::Solver;
use super::triggers::{self, BudgetKind, TriggerSet};
use super::world::World;
use inputs::Logged;
use lifecycle::{FirstPlan, PlanLifecycle};
use planning::{Batch, FiredFor};
use wingman_ipc::config::ServiceConfig;
use wingman_ipc::{self as ipc, Ipc, IpcError};
use wingman_planning::clock::Clock;
use wingman_planning::hybrid::PlannerSettings;
use wingman_planning::plan_message::PlanPoints;
use wingman_planning::problem::Problem;

/// Largest plan id (exclusive) a restarted planner continues from: far above any real
/// mission's count, far below `u64::MAX`, so plan ids never wrap to 0 ("no plan").
pub const MAX_CONTINUED_PLAN_ID: u64 = 1 << 48;

/// Wall-clock wait before a failed first plan is tried again with the same inputs (the
/// planner is deterministic: an immediate retry would fail the same way; the mission
/// time, and with it a restart's start, moves on meanwhile).
pub const FIRST_PLAN_RETRY: Duration = Duration::from_secs(2);

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
    /// A plan is held (`current` is one): from the first plan on, for good. Apart from
    /// `lifecycle`: a re-plan is triggered, deferred and computed while the held plan is
    /// flown.
    has_plan: bool,
    /// Tasking revision and passed targets the current plan was made with.
    plan_revision: u32,
    plan_targets_from: usize,
    /// The first revision with the held tasking's content (later ones only repeat it).
    content_revision: u32,
    points: PlanPoints,
    /// The problem buffers, lent to the solver while a plan is in flight.
    problem: Option<Box<Problem>>,
    /// What the loop is doing about its next plan: idle, triggered, deferred by the
    /// compute gate, or planning (with a follow-up).
    lifecycle: PlanLifecycle,
    /// The first plan before it is triggered: kept apart from `lifecycle` (the two overlap
    /// after a failed first plan; see `FirstPlan`).
    first: FirstPlan,
    /// Triggers whose plan had no state to start from (no fresh ownship state where the
    /// plan cannot say): raised again by the next ownship state of the tasking's model.
    /// Kept apart from `lifecycle`: other triggers are planned while these wait, and a plan
    /// made meanwhile clears them.
    awaiting_start: Option<TriggerSet>,
    /// Triggers raised in this pass, folded into `lifecycle` by `evaluate`.
    batch: Batch,
    gate: ComputeGate,
    counters: Counters,
    next_plan_id: u64,
    plan_sequence: u64,
    status_sequence: u64,
    /// The plans whose time triggers have fired (once per plan each).
    fired: FiredFor,
    /// Input problems logged once already.
    logged: Logged,
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
            options.replay_cuts.clone(),
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
            lifecycle: PlanLifecycle::Idle,
            first: FirstPlan::NotDue,
            awaiting_start: None,
            batch: Batch::default(),
            gate,
            counters: Counters::default(),
            next_plan_id: 1,
            plan_sequence: 0,
            status_sequence: 0,
            fired: FiredFor::default(),
            logged: Logged::default(),
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
        let deferred = self.lifecycle.deferred_until();
        let first = self
            .first
            .ownship_wait_until()
            .filter(|_| self.waiting_for_ownship());
        match deferred.into_iter().chain(first).min() {
            Some(at) => at
                .saturating_sub(self.clock.now())
                .max(Duration::from_micros(100)),
            None => Duration::MAX,
        }
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

    /// Ends the run: waits for the plan in flight (it ends by its deadline) and publishes
    /// it, publishes a last status, stops the solve thread. Returns the last status.
    pub fn finish(mut self) -> PlannerStatus {
        if let PlanLifecycle::Planning { ticket, .. } = self.lifecycle {
            let wait = ticket.budget + Duration::from_secs(2);
            if let Some(result) = self.solver.wait_result(wait) {
                self.on_result(result);
            }
        }
        self.lifecycle.drop_pending();
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

    /// Whether a plan for the triggers `set` re-plans the plan in flight: there is one,
    /// and the triggers leave something of it to start from (not a first plan, a new
    /// tasking or a restart).
    fn replans_in_flight(&self, set: TriggerSet) -> bool {
        triggers::replans_in_flight(set, self.has_plan)
    }

    /// Budget of a plan of the current tasking's model for the triggers `set`: the
    /// take-off plan's, a plan from scratch's, a refinement's or a re-plan's.
    fn budget(&self, set: TriggerSet) -> Duration {
        let model = self
            .world
            .tasking
            .as_ref()
            .and_then(Tasking::model)
            .unwrap_or(Model::ThreeD);
        match triggers::budget_kind(set, self.has_plan) {
            BudgetKind::TakeOff => self.cfg.takeoff_budget(model),
            BudgetKind::FromScratch => self.cfg.plan_budget(model),
            BudgetKind::Refine => self.cfg.refine_budget(model),
            BudgetKind::Replan => self.cfg.replan_budget(model),
        }
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

/// A zero-filled plan on the heap (never on the stack: it is 160 KiB).
fn zeroed_plan() -> Box<Plan> {
    let mut b = Box::<Plan>::new_uninit();
    Plan::zeroed_in(&mut b);
    // SAFETY: `zeroed_in` initialised every byte.
    unsafe { b.assume_init() }
}
