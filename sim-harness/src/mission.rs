//! A mission flown end to end: the planner process (spawned, or one already running), the
//! emulators (datalink, sensor, tracker) and the clock, step by step, until the flown plan
//! reaches its end or the time limit. [`fly`] holds the logic; the binary only wires it.

use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use wingman_interfaces::{
    Model, Plan, PlannerState, PlannerStatus, Quality, Service, ThreatKind, ThreatReport, Trigger,
    Wire, service_name, threat_name,
};
use wingman_ipc as ipc;
use wingman_ipc::ServiceConfig;
use wingman_planning::estimation::{Estimate, GaussMarkov, KalmanFilter, Road};
use wingman_planning::problem::{Problem, ProblemError};
use wingman_planning::scenario::Scenario;
use wingman_planning::tracking::TrackingGains;

use crate::clock::{ClockMode, Pacer, Periodic, step_time};
use crate::datalink::{Datalink, DatalinkError};
use crate::flight_log::{Entry, LogError, LogWriter};
use crate::link::{LinkError, PlannerLink, Received};
use crate::process::{PlannerProcess, ProcessError, planner_binary};
use crate::resume::{self, ResumeError, Resumed, Timeline};
use crate::sensor::{SensorError, SensorOutput, ThreatSensor};
use crate::tracker::{Hold, InnerLoop, ReceivedPlan, TrackerSample};

/// Where the planner comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum PlannerMode {
    /// Start `wingman-planner serve` (this binary, or the one next to the harness).
    Spawn { binary: Option<PathBuf> },
    /// Use a planner already serving the vehicle id.
    External,
}

/// Everything a flight needs.
#[derive(Debug, Clone)]
pub struct FlyOptions {
    pub scenario: Scenario,
    pub clock: ClockMode,
    pub out_dir: PathBuf,
    pub planner: PlannerMode,
    /// The planner's configuration (its `vehicle_id` is the flight's).
    pub planner_config: ServiceConfig,
    /// Harness step (tracker, ownship, clock), s.
    pub step_s: f64,
    /// Rate of `LeadState`, Hz.
    pub lead_rate_hz: f64,
    /// End of the flight if the plan has not ended by then (`None`: three times the first
    /// plan's duration, at least ten minutes more).
    pub time_limit_s: Option<f64>,
    /// Longest wall-clock wait for the planner in one step.
    pub planner_timeout: Duration,
    /// Print a progress line on stderr.
    pub progress: bool,
    /// Faults injected into the flight (fault-tolerance tests); none by default.
    pub faults: Faults,
    /// Resume the mission the (external) planner is flying instead of starting it
    /// (`fly --resume`, see [`crate::resume`]).
    pub resume: bool,
    /// Longest wait for the planner's status and plan when resuming.
    pub resume_wait: Duration,
}

/// Faults the harness can inject into a flight, for the fault-tolerance tests of
/// `tests/tests/faults.rs` (`fly --kill-planner-at`, `--popup-burst-at`). None by default.
#[derive(Debug, Clone, PartialEq)]
pub struct Faults {
    /// SIGKILL the spawned planner at this mission time (no clean-up: its iceoryx2
    /// resources stay behind), fly on without a planner for [`Faults::restart_after_s`]
    /// (the tracker keeps flying the last plan; the lock-step clock does not wait), then
    /// start a new planner process on the same vehicle id, its log in
    /// `planner.restart.log`. The new planner must clean up the dead node and take the
    /// world from the services' history.
    pub kill_planner_at_s: Option<f64>,
    /// Mission time without a planner after the kill, s.
    pub restart_after_s: f64,
    /// From this mission time on, over one second of mission time, send
    /// [`Faults::popup_burst_count`] static pop-up reports centred on the flown plan 60 s
    /// ahead (4 threat ids re-reported at new places, 300 m radius). They are not part of
    /// the scenario's truth, so the report's metrics do not count them.
    pub popup_burst_at_s: Option<f64>,
    /// Pop-up reports in the burst.
    pub popup_burst_count: u32,
}

impl Default for Faults {
    fn default() -> Self {
        Faults {
            kill_planner_at_s: None,
            restart_after_s: 10.0,
            popup_burst_at_s: None,
            popup_burst_count: 100,
        }
    }
}

/// First threat id of the burst's pop-ups (clear of the scenario's ids).
const BURST_ID_BASE: u32 = 1000;
/// Threat ids the burst cycles through.
const BURST_IDS: u32 = 4;

/// The `k`-th pop-up of a burst of `count`, sent at `t`, centred on `plan` 60 s ahead
/// (spread along it by the pop-up's rank).
fn burst_popup(plan: &wingman_interfaces::Plan, t: f64, k: u32, count: u32) -> ThreatReport {
    let ahead = t + 60.0 + 20.0 * f64::from(k) / f64::from(count.max(1));
    let (x, _) = crate::tracker::reference(plan, ahead);
    let model = plan.model().unwrap_or(Model::TwoD);
    let mut r = ThreatReport::zeroed();
    r.threat_id = BURST_ID_BASE + k % BURST_IDS;
    r.kind = ThreatKind::Static.to_wire();
    r.name = threat_name(&format!("burst-{}", k % BURST_IDS));
    r.appeared_at_s = t;
    r.center_m = position(model, &x);
    r.axes_m = match model {
        Model::TwoD => [300.0, 300.0, 0.0],
        Model::ThreeD => [300.0, 300.0, 300.0],
    };
    r.exponents = [2.0, 2.0, 2.0];
    r
}

impl FlyOptions {
    /// Defaults for `sc`: fast clock, `runs/<name>/`, a spawned planner with
    /// [`harness_planner_config`] on a fresh vehicle id.
    pub fn new(sc: Scenario) -> FlyOptions {
        let vehicle = unique_vehicle_id("fly");
        FlyOptions {
            out_dir: PathBuf::from("runs").join(&sc.name),
            scenario: sc,
            clock: ClockMode::Fast,
            planner: PlannerMode::Spawn { binary: None },
            planner_config: harness_planner_config(&vehicle),
            step_s: 0.1,
            lead_rate_hz: 5.0,
            time_limit_s: None,
            planner_timeout: Duration::from_secs(300),
            progress: true,
            faults: Faults::default(),
            resume: false,
            resume_wait: resume::RESUME_WAIT,
        }
    }
}

/// The planner configuration the harness flies with: the defaults, with budgets that let
/// today's planner converge (2 s per 2-D plan, 6 s per 3-D plan; a converged plan returns
/// early, and the lock-step clock charges the time it took) and no duty-cycle cap beyond
/// one core over a minute.
pub fn harness_planner_config(vehicle_id: &str) -> ServiceConfig {
    let mut c = ServiceConfig {
        vehicle_id: vehicle_id.to_string(),
        ..ServiceConfig::default()
    };
    c.budget.plan_2d_ms = 2_000;
    c.budget.plan_3d_ms = 6_000;
    c.budget.duty_cycle = 1.0;
    c.budget.duty_window_ms = 60_000;
    c.status.heartbeat_ms = 200;
    c
}

/// A vehicle id no other run on this host uses: `tag`, the process id and a clock reading.
pub fn unique_vehicle_id(tag: &str) -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    format!("{tag}-{}-{nanos:x}", std::process::id())
}

/// A flight could not be flown.
#[derive(Debug, thiserror::Error)]
pub enum FlyError {
    #[error("scenario: {0}")]
    Problem(#[from] ProblemError),
    #[error("datalink: {0}")]
    Datalink(#[from] DatalinkError),
    #[error("sensor: {0}")]
    Sensor(#[from] SensorError),
    #[error("vehicle: {0}")]
    Vehicle(#[from] wingman_planning::dynamics::DynamicsError),
    #[error("planner configuration: {0}")]
    Config(#[from] wingman_ipc::config::ConfigError),
    #[error("planner process: {0}")]
    Process(#[from] ProcessError),
    #[error("{0}")]
    Link(#[from] LinkError),
    #[error("flight log: {0}")]
    Log(#[from] LogError),
    #[error("{what}: {source}")]
    Io {
        what: String,
        source: std::io::Error,
    },
    #[error("{0}")]
    Planner(String),
    #[error(transparent)]
    Resume(#[from] ResumeError),
}

/// How a flight ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndReason {
    /// The flown plan reached its end.
    PlanEnded,
    /// The time limit came first.
    TimeLimit,
}

/// The keep-out estimate of a moving threat when a plan was made.
#[derive(Debug, Clone, Copy)]
pub struct EstimateSnapshot {
    pub plan_id: u64,
    /// Index of the moving threat (scenario order).
    pub threat: usize,
    /// Mission time the region is drawn for (the plan's trigger time).
    pub at_s: f64,
    pub estimate: Estimate,
}

/// What a flight produced.
#[derive(Debug, Clone)]
pub struct Flight {
    pub scenario: Scenario,
    pub vehicle_id: String,
    pub clock: ClockMode,
    pub planner_config: ServiceConfig,
    /// The tracker after every step, from the start.
    pub samples: Vec<TrackerSample>,
    /// Every plan received.
    pub plans: Vec<ReceivedPlan>,
    pub holds: Vec<Hold>,
    /// True positions of each moving threat at every step (`t`, position).
    pub truth: Vec<Vec<(f64, [f64; 3])>>,
    /// The moving threats' estimates (the planner's filter, mirrored) at each plan.
    pub estimates: Vec<EstimateSnapshot>,
    pub datalink: Datalink,
    pub end_s: f64,
    pub end: EndReason,
    pub last_status: Option<PlannerStatus>,
    /// Planner messages that failed `validate()`.
    pub rejected: u64,
    /// Wall-clock duration of the flight.
    pub wall: Duration,
    /// Where a resumed flight (`fly --resume`) took the mission over (`None`: flown from
    /// the start). The samples, the truth and every plan then begin at the resume.
    pub resumed: Option<Resumed>,
}

/// The moving threats' filters as the planner runs them (same reports, same fixes, same
/// code), so the plots can show what the planner estimated.
struct Mirror {
    filters: Vec<Option<(KalmanFilter, Road<3>, f64)>>,
}

impl Mirror {
    fn report(&mut self, k: usize, r: &wingman_interfaces::ThreatReport) {
        let make = || -> Option<(KalmanFilter, Road<3>, f64)> {
            let model = GaussMarkov::new(r.accel_tau_s, r.accel_sigma_mps2).ok()?;
            let road = Road::<3>::new(r.road()).ok()?;
            let est = Estimate::new(
                r.estimate_time_s,
                nalgebra::Vector3::from(r.estimate_mean),
                nalgebra::Matrix3::from_row_slice(&r.estimate_covariance),
            )
            .ok()?;
            Some((KalmanFilter::new(model, 1.0, est).ok()?, road, 1.0))
        };
        if let Some(slot) = self.filters.get_mut(k) {
            *slot = make();
        }
    }

    fn fix(&mut self, k: usize, f: &wingman_interfaces::TrackFix) {
        let Some(Some((filter, road, sigma))) = self.filters.get_mut(k) else {
            return;
        };
        if f.sigma_m != *sigma
            && let Ok(nf) = KalmanFilter::new(*filter.model(), f.sigma_m, *filter.estimate())
        {
            *filter = nf;
            *sigma = f.sigma_m;
        }
        if filter.predict_to(f.time_s).is_ok() {
            let _ = filter.update_position(road, &f.position_m);
        }
    }

    /// Records every moving threat's estimate as `plan` was made from it.
    fn snapshot(&self, plan: &Plan, out: &mut Vec<EstimateSnapshot>) {
        for threat in 0..self.filters.len() {
            if let Some(estimate) = self.estimate(threat) {
                out.push(EstimateSnapshot {
                    plan_id: plan.plan_id,
                    threat,
                    at_s: plan.created_at_s,
                    estimate,
                });
            }
        }
    }

    fn estimate(&self, k: usize) -> Option<Estimate> {
        self.filters
            .get(k)
            .and_then(|f| f.as_ref())
            .map(|(f, _, _)| *f.estimate())
    }
}

/// Flies `opts.scenario` end to end.
pub fn fly(opts: &FlyOptions) -> Result<Flight, FlyError> {
    if opts.resume && opts.planner != PlannerMode::External {
        return Err(ResumeError::NotExternal.into());
    }
    let sc = &opts.scenario;
    let problem = Problem::from_scenario(sc)?;
    let mut datalink = Datalink::new(sc)?;
    let mut sensor = ThreatSensor::new(sc)?;
    let mut tracker = InnerLoop::new(&problem, TrackingGains::default())?;
    let cfg = &opts.planner_config;
    cfg.validate()?;
    let vehicle = cfg.vehicle_id.clone();
    let io = |what: String| move |source| FlyError::Io { what, source };
    std::fs::create_dir_all(&opts.out_dir)
        .map_err(io(format!("create {}", opts.out_dir.display())))?;
    let config_path = opts.out_dir.join("planner.toml");
    std::fs::write(&config_path, cfg.to_toml())
        .map_err(io(format!("write {}", config_path.display())))?;
    let mut log = LogWriter::create(&opts.out_dir.join("flight.log"))?;
    log.write(&Entry::Start {
        version: crate::flight_log::LOG_VERSION,
        scenario: sc.name.clone(),
        vehicle_id: vehicle.clone(),
        clock: opts.clock.to_string(),
        planner_config: cfg.to_toml(),
    });

    let cleanup = ipc::remove_dead_nodes(Duration::from_secs(1)).map_err(LinkError::from)?;
    if cleanup.removed > 0 {
        tracing::info!(removed = cleanup.removed, "removed dead iceoryx2 nodes");
    }
    let mut planner = match &opts.planner {
        PlannerMode::Spawn { binary } => {
            let bin = match binary {
                Some(b) => b.clone(),
                None => planner_binary()?,
            };
            let p = PlannerProcess::spawn(
                &bin,
                &config_path,
                &vehicle,
                &opts.out_dir.join("planner.log"),
            )?;
            tracing::debug!(pid = p.id(), vehicle = %vehicle, "planner started");
            Some(p)
        }
        PlannerMode::External => None,
    };
    let mut link = PlannerLink::open(&vehicle, log)?;
    let wall_start = Instant::now();

    // The planner is up (and subscribed) once its heartbeat arrives.
    let up = Instant::now();
    let status_wait = if opts.resume {
        opts.resume_wait
    } else {
        Duration::from_secs(30)
    };
    // Plans that come with it (the `plan` service's history: a resumed flight's plan).
    let mut early = Received::default();
    while link.status().is_none() {
        let r = link.poll()?;
        early.plans.extend(r.plans);
        early.rejected += r.rejected;
        if planner.as_mut().is_some_and(|p| !p.is_running()) {
            return Err(FlyError::Planner(format!(
                "the planner exited at start-up (see {})",
                opts.out_dir.join("planner.log").display()
            )));
        }
        if up.elapsed() > status_wait {
            if opts.resume {
                return Err(no_status(&vehicle, status_wait).into());
            }
            return Err(FlyError::Planner(format!(
                "no status from a planner on vehicle `{vehicle}` within 30 s"
            )));
        }
        link.wait(Duration::from_millis(100))?;
    }

    let t0 = sc.start.time_s;
    let dt = opts.step_s;
    let mut mirror = Mirror {
        filters: vec![None; sc.moving_threats.len()],
    };
    let moving_base = sensor.static_count() as u32 + 1;
    let mut rejected = early.rejected;
    // A resumed flight: the planner's plan and the world at the resume point.
    let mut take_over: Option<(Resumed, Box<Plan>, Timeline)> = None;
    if opts.resume {
        let (plan, r) = wait_for_plan(&mut link, early.plans, &vehicle, opts.resume_wait, up)?;
        rejected += r;
        let status = link
            .status()
            .copied()
            .ok_or_else(|| no_status(&vehicle, opts.resume_wait))?;
        let point = resume::resume_point(&status, &plan, t0, dt)?;
        let matched = resume::check_plan(sc, &datalink, &plan, point.planner_s, point.t_s)?;
        let timeline = resume::replay_timeline(&mut datalink, &mut sensor, t0, dt, point.step);
        for out in &timeline.sensor {
            match out {
                SensorOutput::Report(r) if r.threat_id >= moving_base => {
                    mirror.report((r.threat_id - moving_base) as usize, r);
                }
                SensorOutput::Report(_) => {}
                SensorOutput::Fix(f) => {
                    mirror.fix((f.threat_id.saturating_sub(moving_base)) as usize, f);
                }
            }
        }
        link.continue_sequence(point.last_sequence);
        link.set_time(point.t_s);
        link.log.write(&Entry::Resume {
            mission_s: point.t_s,
            planner_s: point.planner_s,
            plan_id: plan.plan_id,
            last_sequence: point.last_sequence,
        });
        tracing::info!(
            mission_s = point.t_s,
            planner_s = point.planner_s,
            plan_id = plan.plan_id,
            last_sequence = point.last_sequence,
            targets_passed = matched.passed,
            "resuming the planner's mission"
        );
        let resumed = Resumed {
            point,
            plan_id: plan.plan_id,
            matched,
        };
        take_over = Some((resumed, plan, timeline));
    }
    let resumed = take_over.as_ref().map(|(r, _, _)| *r);
    let t_start = resumed.map_or(t0, |r| r.point.t_s);
    let k_start = resumed.map_or(0, |r| r.point.step);
    let mut lead_tick = Periodic::resumed(t0, 1.0 / opts.lead_rate_hz, t_start);
    let mut truth: Vec<Vec<(f64, [f64; 3])>> = vec![Vec::new(); sc.moving_threats.len()];
    let mut estimates = Vec::new();
    let mut time_limit = opts.time_limit_s.unwrap_or(t0 + 7200.0);
    // The world the resumed flight's first step publishes again.
    let mut replayed: Option<Timeline> = None;
    if let Some((r, plan, timeline)) = take_over {
        mirror.snapshot(&plan, &mut estimates);
        if opts.time_limit_s.is_none() {
            time_limit = default_time_limit(t0, plan.final_time_s);
        }
        tracker.start_on(
            r.point.t_s,
            ReceivedPlan {
                plan,
                received_at_s: r.point.t_s,
                available_at_s: r.point.t_s,
            },
        );
        replayed = Some(timeline);
    }
    let mut samples = vec![tracker.sample()];
    let mut progress = Progress::new(opts.progress);
    let mut pacer = Pacer::new(opts.clock, t_start);
    let mut k: u64 = k_start;
    let mut t = t_start;
    let faults = &opts.faults;
    let mut killed = false;
    // Mission time at which a killed planner is started again.
    let mut restart_at: Option<f64> = None;
    let mut burst_sent: u32 = 0;

    let end = loop {
        // 0. Injected faults: the planner killed, then started again.
        if let Some(at) = faults.kill_planner_at_s
            && !killed
            && t >= at
            && let Some(p) = planner.as_mut()
        {
            tracing::info!(
                pid = p.id(),
                mission_s = t,
                "fault: planner killed (SIGKILL)"
            );
            p.kill();
            killed = true;
            restart_at = Some(t + faults.restart_after_s);
        }
        if let Some(at) = restart_at
            && t >= at
            && let PlannerMode::Spawn { binary } = &opts.planner
        {
            let bin = match binary {
                Some(b) => b.clone(),
                None => planner_binary()?,
            };
            let p = PlannerProcess::spawn(
                &bin,
                &config_path,
                &vehicle,
                &opts.out_dir.join("planner.restart.log"),
            )?;
            tracing::info!(pid = p.id(), mission_s = t, "fault: planner started again");
            planner = Some(p);
            restart_at = None;
            // As at start-up: its inputs count once it is up (subscribed), which its
            // first heartbeat tells.
            link.forget_status();
            let up = Instant::now();
            while link.status().is_none() {
                link.poll()?;
                if planner.as_mut().is_some_and(|p| !p.is_running()) {
                    return Err(FlyError::Planner(
                        "the restarted planner exited at start-up".into(),
                    ));
                }
                if up.elapsed() > Duration::from_secs(30) {
                    return Err(FlyError::Planner(
                        "no status from the restarted planner within 30 s".into(),
                    ));
                }
                // No `refresh()` here: the history (tasking, threats) reaches the new
                // planner with this step's ownship state, so it plans from where the
                // aircraft is (`Restart`), not from the tasking's start.
                link.wait(Duration::from_millis(100))?;
            }
        }
        let planner_down = restart_at.is_some();

        // 1. This step's inputs.
        link.set_time(t);
        link.refresh();
        if let Some(world) = replayed.take() {
            // A resumed flight's first step: the world in force at the resume, again. The
            // planner holds it already (repeats: no re-plan); the new publishers' history
            // holds it for later subscribers.
            for r in world.reports() {
                link.send_threat(*r)?;
            }
            if let Some(r) = world.route {
                link.send_route(r)?;
            }
            if let Some(tk) = world.tasking {
                link.send_tasking(tk)?;
            }
        }
        if let Some(at) = faults.popup_burst_at_s
            && t >= at
            && burst_sent < faults.popup_burst_count
            && let Some(flying) = tracker.flying()
        {
            // One second of mission time: the same share of the burst at every step.
            let steps = (1.0 / dt).round().max(1.0) as u32;
            let per_step = faults.popup_burst_count.div_ceil(steps);
            for _ in 0..per_step.min(faults.popup_burst_count - burst_sent) {
                let r = burst_popup(&flying.plan, t, burst_sent, faults.popup_burst_count);
                link.send_threat(r)?;
                burst_sent += 1;
            }
        }
        for out in sensor.poll(t) {
            match out {
                SensorOutput::Report(r) => {
                    if r.threat_id >= moving_base {
                        mirror.report((r.threat_id - moving_base) as usize, &r);
                    }
                    link.send_threat(r)?;
                }
                SensorOutput::Fix(f) => {
                    mirror.fix((f.threat_id.saturating_sub(moving_base)) as usize, &f);
                    link.send_fix(f)?;
                }
            }
        }
        for (i, m) in sensor.movings().iter().enumerate() {
            truth[i].push((t, m.true_position()));
        }
        for r in datalink.routes_due(t).to_vec() {
            link.send_route(r.message)?;
        }
        for r in datalink.taskings_due(t).to_vec() {
            link.send_tasking(r.tasking)?;
        }
        if lead_tick.due(t).is_some()
            && let Some(s) = datalink.lead_state(t)
        {
            link.send_lead_state(s)?;
        }
        link.send_ownship(tracker.ownship())?;
        link.wake()?;

        // 2. The planner's answer: lock-step waits for it.
        // Every clock waits for the first plan at take-off (it is planned before the
        // flight); the paced clocks start after it.
        let received: Received = if (opts.clock.is_lock_step() || k == k_start) && !planner_down {
            let (r, ok) = link.sync(opts.planner_timeout, || {
                planner.as_mut().is_none_or(|p| p.is_running())
            })?;
            if !ok {
                let why = if planner.as_mut().is_some_and(|p| !p.is_running()) {
                    "the planner process exited".to_string()
                } else {
                    format!("no answer within {:?}", opts.planner_timeout)
                };
                return Err(FlyError::Planner(format!(
                    "{why} at mission time {t:.1} s (see {})",
                    opts.out_dir.join("planner.log").display()
                )));
            }
            if k == k_start {
                pacer = Pacer::new(opts.clock, t_start);
            }
            r
        } else {
            link.poll()?
        };
        rejected += received.rejected;
        for plan in received.plans {
            let available_at_s = match (opts.clock.is_lock_step(), plan.trigger()) {
                (_, Some(Trigger::Initial)) => plan.start_time_s.min(t).max(t0),
                (true, _) => (plan.created_at_s + plan.compute_ms / 1e3).max(t),
                (false, _) => t,
            };
            mirror.snapshot(&plan, &mut estimates);
            if tracker.plans().is_empty() && opts.time_limit_s.is_none() {
                time_limit = default_time_limit(t0, plan.final_time_s);
            }
            tracing::debug!(
                plan_id = plan.plan_id,
                trigger = plan.trigger().map_or("?", Trigger::name),
                quality = plan.quality().map_or("?", Quality::name),
                start_s = plan.start_time_s,
                available_at_s,
                compute_ms = plan.compute_ms,
                "plan received"
            );
            tracker.receive(ReceivedPlan {
                plan,
                received_at_s: t,
                available_at_s,
            });
        }
        progress.show(sc, t, &tracker, false);

        // 3. The end, or the next step.
        if tracker.plan_finished() {
            break EndReason::PlanEnded;
        }
        if t >= time_limit {
            break EndReason::TimeLimit;
        }
        k += 1;
        t = step_time(t0, dt, k);
        pacer.sleep_until(t);
        tracker.advance_to(t);
        samples.push(tracker.sample());
    };
    progress.show(sc, t, &tracker, true);

    link.log.write(&Entry::End {
        mission_s: t,
        completed: end == EndReason::PlanEnded,
    });
    link.log.flush()?;
    let last_status = link.status().copied();
    drop(link);
    if let Some(p) = planner.as_mut()
        && let Some(status) = p.stop(Duration::from_secs(10))
        && !status.success()
    {
        tracing::warn!(?status, "the planner exited with an error");
    }
    Ok(Flight {
        scenario: sc.clone(),
        vehicle_id: vehicle,
        clock: opts.clock,
        planner_config: cfg.clone(),
        samples,
        plans: tracker.plans().to_vec(),
        holds: tracker.holds().to_vec(),
        truth,
        estimates,
        datalink,
        end_s: t,
        end,
        last_status,
        rejected,
        wall: wall_start.elapsed(),
        resumed,
    })
}

/// The time limit of a flight whose first plan ends at `final_s`: three times the plan's
/// duration, at least ten minutes more.
fn default_time_limit(t0: f64, final_s: f64) -> f64 {
    let duration = final_s - t0;
    t0 + (3.0 * duration).max(duration + 600.0)
}

/// Waits (at most `wait` from `since`) for the planner's current plan — the `plan`
/// service's history (`early`: plans taken with the first status), then whatever it
/// publishes — with the planner not planning and the plan the one its status names.
/// Returns the newest plan and the invalid messages dropped. A planner still planning at the limit is resumed on the plan it has (the
/// plan it is computing arrives as any re-plan).
fn wait_for_plan(
    link: &mut PlannerLink,
    early: Vec<Box<Plan>>,
    vehicle: &str,
    wait: Duration,
    since: Instant,
) -> Result<(Box<Plan>, u64), FlyError> {
    let mut newest: Option<Box<Plan>> = None;
    let mut rejected = 0;
    let mut taken = early;
    loop {
        for p in taken.drain(..) {
            if newest.as_ref().is_none_or(|n| p.plan_id > n.plan_id) {
                newest = Some(p);
            }
        }
        let status = link.status();
        let idle = status.is_some_and(|s| s.state() != Some(PlannerState::Planning));
        let current = match (&newest, status) {
            (Some(p), Some(s)) => p.plan_id >= s.current_plan_id,
            _ => false,
        };
        if idle && current {
            break;
        }
        if since.elapsed() > wait {
            if newest.is_some() {
                tracing::warn!(
                    planning = !idle,
                    newer_announced = !current,
                    "resuming on the newest plan received: the planner is still planning or \
                     announces a newer plan"
                );
            }
            break;
        }
        link.wait(Duration::from_millis(100))?;
        let r = link.poll()?;
        rejected += r.rejected;
        taken = r.plans;
    }
    let plan = newest.ok_or_else(|| ResumeError::NoPlan {
        service: service_name(vehicle, Service::Plan).unwrap_or_default(),
        within_s: wait.as_secs_f64(),
    })?;
    Ok((plan, rejected))
}

fn no_status(vehicle: &str, wait: Duration) -> ResumeError {
    ResumeError::NoStatus {
        service: service_name(vehicle, Service::Status).unwrap_or_default(),
        within_s: wait.as_secs_f64(),
    }
}

/// The progress line: mission time, phase, plan flown, re-plans so far.
struct Progress {
    on: bool,
    tty: bool,
    last: Option<Instant>,
    last_t: f64,
}

impl Progress {
    fn new(on: bool) -> Progress {
        Progress {
            on,
            tty: std::io::stderr().is_terminal(),
            last: None,
            last_t: f64::NEG_INFINITY,
        }
    }

    fn show(&mut self, sc: &Scenario, t: f64, tracker: &InnerLoop, last: bool) {
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

/// Position of a state (z = 0 in 2-D).
pub fn position(model: Model, x: &[f64; 7]) -> [f64; 3] {
    match model {
        Model::TwoD => [x[0], x[1], 0.0],
        Model::ThreeD => [x[0], x[1], x[2]],
    }
}
