//! [`fly`]: one mission flown step by step. The set-up (configuration, log, planner
//! process, its first status, a resume's take-over) and each step (injected faults, the
//! step's inputs, the planner's answer, the tracker's advance) are functions of their own
//! on [`InFlight`], the flight in progress.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use wingman_interfaces::{Plan, Quality, Trigger};
use wingman_ipc as ipc;
use wingman_planning::problem::Problem;
use wingman_planning::scenario::Scenario;
use wingman_planning::tracking::TrackingGains;

use super::mirror::Mirror;
use super::progress::Progress;
use super::{
    EndReason, EstimateSnapshot, Flight, FlyError, FlyOptions, PlannerMode, burst_popup,
    default_time_limit, no_status, wait_for_plan,
};
use crate::clock::{Pacer, Periodic, step_time};
use crate::datalink::Datalink;
use crate::flight_log::{Entry, LogWriter};
use crate::link::{LinkError, PlannerLink, Received};
use crate::process::{PlannerProcess, planner_binary};
use crate::resume::{self, ResumeError, Resumed, Timeline};
use crate::sensor::{SensorOutput, ThreatSensor};
use crate::tracker::{InnerLoop, ReceivedPlan, TrackerSample};
use crate::truth::Truth;

/// Flies `opts.scenario` end to end.
pub fn fly(opts: &FlyOptions) -> Result<Flight, FlyError> {
    if opts.resume && opts.planner != PlannerMode::External {
        return Err(ResumeError::NotExternal.into());
    }
    let mut flight = InFlight::start(opts)?;
    let end = loop {
        flight.inject_planner_faults()?;
        flight.publish_inputs()?;
        flight.take_answer()?;
        if let Some(end) = flight.end_reached() {
            break end;
        }
        flight.advance();
    };
    flight.finish(end)
}

/// A flight in progress.
struct InFlight<'o> {
    opts: &'o FlyOptions,
    sc: &'o Scenario,
    datalink: Datalink,
    sensor: ThreatSensor,
    tracker: InnerLoop,
    link: PlannerLink,
    /// The spawned planner (`None`: an external one, or killed and not yet restarted).
    planner: Option<PlannerProcess>,
    config_path: PathBuf,
    vehicle: String,
    wall_start: Instant,
    mirror: Mirror,
    /// Threat id of the first moving threat (the static ones come first).
    moving_base: u32,
    rejected: u64,
    resumed: Option<Resumed>,
    /// The world a resumed flight's first step publishes again.
    replayed: Option<Timeline>,
    t0: f64,
    t_start: f64,
    k_start: u64,
    k: u64,
    t: f64,
    lead_tick: Periodic,
    truth: Vec<Vec<(f64, [f64; 3])>>,
    estimates: Vec<EstimateSnapshot>,
    time_limit: f64,
    samples: Vec<TrackerSample>,
    progress: Progress,
    pacer: Pacer,
    killed: bool,
    /// Mission time at which a killed planner is started again.
    restart_at: Option<f64>,
    burst_sent: u32,
}

impl<'o> InFlight<'o> {
    /// Everything up to the first step: the emulators, the configuration and the log
    /// written, the planner started and heard from, a resume's take-over.
    fn start(opts: &'o FlyOptions) -> Result<InFlight<'o>, FlyError> {
        let sc = &opts.scenario;
        let problem = Problem::from_scenario(sc)?;
        let mut datalink = Datalink::new(sc)?;
        let mut sensor = ThreatSensor::new(sc)?;
        let mut tracker =
            InnerLoop::new(&problem, TrackingGains::default())?.with_truth(Truth::of(sc, &problem));
        let cfg = &opts.planner_config;
        cfg.validate()?;
        let vehicle = cfg.vehicle_id.clone();
        let (config_path, log) = write_start(opts)?;

        let cleanup = ipc::remove_dead_nodes(Duration::from_secs(1)).map_err(LinkError::from)?;
        if cleanup.removed > 0 {
            tracing::info!(removed = cleanup.removed, "removed dead iceoryx2 nodes");
        }
        let mut planner = match &opts.planner {
            PlannerMode::Spawn { binary } => {
                let p = spawn_planner(binary, &config_path, &vehicle, opts, "planner.log")?;
                tracing::debug!(pid = p.id(), vehicle = %vehicle, "planner started");
                Some(p)
            }
            PlannerMode::External => None,
        };
        let mut link = PlannerLink::open(&vehicle, log)?;
        let wall_start = Instant::now();
        let up = Instant::now();
        let early = first_status(opts, &mut link, &mut planner, &vehicle, up)?;

        let t0 = sc.start.time_s;
        let mut mirror = Mirror::new(sc.moving_threats.len());
        let moving_base = sensor.static_count() as u32 + 1;
        let mut rejected = early.rejected;
        let take_over = if opts.resume {
            let (plan, r) = wait_for_plan(&mut link, early.plans, &vehicle, opts.resume_wait, up)?;
            rejected += r;
            Some(take_over(
                opts,
                &mut link,
                &mut datalink,
                &mut sensor,
                &mut mirror,
                moving_base,
                plan,
            )?)
        } else {
            None
        };
        let resumed = take_over.as_ref().map(|(r, _, _)| *r);
        let t_start = resumed.map_or(t0, |r| r.point.t_s);
        let k_start = resumed.map_or(0, |r| r.point.step);
        let mut estimates = Vec::new();
        let mut time_limit = opts.time_limit_s.unwrap_or(t0 + 7200.0);
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
        let samples = vec![tracker.sample()];
        Ok(InFlight {
            opts,
            sc,
            datalink,
            sensor,
            tracker,
            link,
            planner,
            config_path,
            vehicle,
            wall_start,
            mirror,
            moving_base,
            rejected,
            resumed,
            replayed,
            t0,
            t_start,
            k_start,
            k: k_start,
            t: t_start,
            lead_tick: Periodic::resumed(t0, 1.0 / opts.lead_rate_hz, t_start),
            truth: vec![Vec::new(); sc.moving_threats.len()],
            estimates,
            time_limit,
            samples,
            progress: Progress::new(opts.progress),
            pacer: Pacer::new(opts.clock, t_start),
            killed: false,
            restart_at: None,
            burst_sent: 0,
        })
    }

    /// Step 0: the planner killed at its fault time, and started again after the pause.
    fn inject_planner_faults(&mut self) -> Result<(), FlyError> {
        let (faults, t) = (&self.opts.faults, self.t);
        if let Some(at) = faults.kill_planner_at_s
            && !self.killed
            && t >= at
            && let Some(p) = self.planner.as_mut()
        {
            tracing::info!(
                pid = p.id(),
                mission_s = t,
                "fault: planner killed (SIGKILL)"
            );
            p.kill();
            self.killed = true;
            self.restart_at = Some(t + faults.restart_after_s);
        }
        if let Some(at) = self.restart_at
            && t >= at
            && let PlannerMode::Spawn { binary } = &self.opts.planner
        {
            let p = spawn_planner(
                binary,
                &self.config_path,
                &self.vehicle,
                self.opts,
                "planner.restart.log",
            )?;
            tracing::info!(pid = p.id(), mission_s = t, "fault: planner started again");
            self.planner = Some(p);
            self.restart_at = None;
            self.wait_for_restarted_planner()?;
        }
        Ok(())
    }

    /// As at start-up: a restarted planner's inputs count once it is up (subscribed),
    /// which its first heartbeat tells.
    fn wait_for_restarted_planner(&mut self) -> Result<(), FlyError> {
        self.link.forget_status();
        let up = Instant::now();
        while self.link.status().is_none() {
            self.link.poll()?;
            if self.planner.as_mut().is_some_and(|p| !p.is_running()) {
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
            self.link.wait(Duration::from_millis(100))?;
        }
        Ok(())
    }

    /// Step 1: this step's inputs, then the planner woken.
    fn publish_inputs(&mut self) -> Result<(), FlyError> {
        let t = self.t;
        self.link.set_time(t);
        self.link.refresh();
        if let Some(world) = self.replayed.take() {
            // A resumed flight's first step: the world in force at the resume, again. The
            // planner holds it already (repeats: no re-plan); the new publishers' history
            // holds it for later subscribers.
            for r in world.reports() {
                self.link.send_threat(*r)?;
            }
            if let Some(r) = world.route {
                self.link.send_route(r)?;
            }
            if let Some(tk) = world.tasking {
                self.link.send_tasking(tk)?;
            }
        }
        self.send_burst()?;
        for out in self.sensor.poll(t) {
            match out {
                SensorOutput::Report(r) => {
                    if r.threat_id >= self.moving_base {
                        self.mirror
                            .report((r.threat_id - self.moving_base) as usize, &r);
                    }
                    self.link.send_threat(r)?;
                }
                SensorOutput::Fix(f) => {
                    self.mirror
                        .fix((f.threat_id.saturating_sub(self.moving_base)) as usize, &f);
                    self.link.send_fix(f)?;
                }
            }
        }
        for (i, m) in self.sensor.movings().iter().enumerate() {
            self.truth[i].push((t, m.true_position()));
        }
        for r in self.datalink.routes_due(t).to_vec() {
            self.link.send_route(r.message)?;
        }
        for r in self.datalink.taskings_due(t).to_vec() {
            self.link.send_tasking(r.tasking)?;
        }
        if self.lead_tick.due(t).is_some()
            && let Some(s) = self.datalink.lead_state(t)
        {
            self.link.send_lead_state(s)?;
        }
        self.link.send_ownship(self.tracker.ownship())?;
        self.link.wake()?;
        Ok(())
    }

    /// The injected pop-up burst's share of this step.
    fn send_burst(&mut self) -> Result<(), FlyError> {
        let (faults, t) = (&self.opts.faults, self.t);
        if let Some(at) = faults.popup_burst_at_s
            && t >= at
            && self.burst_sent < faults.popup_burst_count
            && let Some(flying) = self.tracker.flying()
        {
            // One second of mission time: the same share of the burst at every step.
            let steps = (1.0 / self.opts.step_s).round().max(1.0) as u32;
            let per_step = faults.popup_burst_count.div_ceil(steps);
            for _ in 0..per_step.min(faults.popup_burst_count - self.burst_sent) {
                let r = burst_popup(&flying.plan, t, self.burst_sent, faults.popup_burst_count);
                self.link.send_threat(r)?;
                self.burst_sent += 1;
            }
        }
        Ok(())
    }

    /// Step 2: the planner's answer. The lock-step clock waits for it; every clock waits
    /// for the first plan at take-off (it is planned before the flight), and the paced
    /// clocks start after it.
    fn take_answer(&mut self) -> Result<(), FlyError> {
        let (opts, t) = (self.opts, self.t);
        let planner_down = self.restart_at.is_some();
        let first_step = self.k == self.k_start;
        let received: Received = if (opts.clock.is_lock_step() || first_step) && !planner_down {
            let planner = &mut self.planner;
            let (r, ok) = self.link.sync(opts.planner_timeout, || {
                planner.as_mut().is_none_or(|p| p.is_running())
            })?;
            if !ok {
                let why = if self.planner.as_mut().is_some_and(|p| !p.is_running()) {
                    "the planner process exited".to_string()
                } else {
                    format!("no answer within {:?}", opts.planner_timeout)
                };
                return Err(FlyError::Planner(format!(
                    "{why} at mission time {t:.1} s (see {})",
                    opts.out_dir.join("planner.log").display()
                )));
            }
            if first_step {
                self.pacer = Pacer::new(opts.clock, self.t_start);
            }
            r
        } else {
            self.link.poll()?
        };
        self.rejected += received.rejected;
        for plan in received.plans {
            self.receive_plan(plan);
        }
        self.progress.show(self.sc, t, &self.tracker, false);
        Ok(())
    }

    /// A plan handed to the tracker, available when a real-time flight would have it.
    fn receive_plan(&mut self, plan: Box<Plan>) {
        let (opts, t) = (self.opts, self.t);
        let available_at_s = match (opts.clock.is_lock_step(), plan.trigger()) {
            (_, Some(Trigger::Initial)) => plan.start_time_s.min(t).max(self.t0),
            (true, _) => (plan.created_at_s + plan.compute_ms / 1e3).max(t),
            (false, _) => t,
        };
        self.mirror.snapshot(&plan, &mut self.estimates);
        if self.tracker.plans().is_empty() && opts.time_limit_s.is_none() {
            self.time_limit = default_time_limit(self.t0, plan.final_time_s);
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
        self.tracker.receive(ReceivedPlan {
            plan,
            received_at_s: t,
            available_at_s,
        });
    }

    /// Step 3: the flown plan ended, or the time limit came.
    fn end_reached(&self) -> Option<EndReason> {
        if self.tracker.plan_finished() {
            Some(EndReason::PlanEnded)
        } else if self.t >= self.time_limit {
            Some(EndReason::TimeLimit)
        } else {
            None
        }
    }

    /// The next step: the clock paced, the tracker flown to it.
    fn advance(&mut self) {
        self.k += 1;
        self.t = step_time(self.t0, self.opts.step_s, self.k);
        self.pacer.sleep_until(self.t);
        self.tracker.advance_to(self.t);
        self.samples.push(self.tracker.sample());
    }

    /// The log closed, the planner stopped, and what the flight produced.
    fn finish(mut self, end: EndReason) -> Result<Flight, FlyError> {
        let t = self.t;
        self.progress.show(self.sc, t, &self.tracker, true);
        self.link.log.write(&Entry::End {
            mission_s: t,
            completed: end == EndReason::PlanEnded,
        });
        self.link.log.flush()?;
        let last_status = self.link.status().copied();
        drop(self.link);
        if let Some(p) = self.planner.as_mut()
            && let Some(status) = p.stop(Duration::from_secs(10))
            && !status.success()
        {
            tracing::warn!(?status, "the planner exited with an error");
        }
        Ok(Flight {
            scenario: self.sc.clone(),
            vehicle_id: self.vehicle,
            clock: self.opts.clock,
            planner_config: self.opts.planner_config.clone(),
            samples: self.samples,
            plans: self.tracker.plans().to_vec(),
            holds: self.tracker.holds().to_vec(),
            truth: self.truth,
            estimates: self.estimates,
            datalink: self.datalink,
            end_s: t,
            end,
            last_status,
            rejected: self.rejected,
            wall: self.wall_start.elapsed(),
            resumed: self.resumed,
        })
    }
}

/// The output folder made, `planner.toml` written into it, and the flight log opened
/// with its start record.
fn write_start(opts: &FlyOptions) -> Result<(PathBuf, LogWriter), FlyError> {
    let cfg = &opts.planner_config;
    let io = |what: String| move |source| FlyError::Io { what, source };
    std::fs::create_dir_all(&opts.out_dir)
        .map_err(io(format!("create {}", opts.out_dir.display())))?;
    let config_path = opts.out_dir.join("planner.toml");
    std::fs::write(&config_path, cfg.to_toml())
        .map_err(io(format!("write {}", config_path.display())))?;
    let mut log = LogWriter::create(&opts.out_dir.join("flight.log"))?;
    log.write(&Entry::Start {
        version: crate::flight_log::LOG_VERSION,
        scenario: opts.scenario.name.clone(),
        vehicle_id: cfg.vehicle_id.clone(),
        clock: opts.clock.to_string(),
        planner_config: cfg.to_toml(),
    });
    Ok((config_path, log))
}

/// `wingman-planner serve` started (the given binary, or the one next to the harness),
/// its log in `log_name` in the output folder.
fn spawn_planner(
    binary: &Option<PathBuf>,
    config_path: &std::path::Path,
    vehicle: &str,
    opts: &FlyOptions,
    log_name: &str,
) -> Result<PlannerProcess, FlyError> {
    let bin = match binary {
        Some(b) => b.clone(),
        None => planner_binary()?,
    };
    Ok(PlannerProcess::spawn(
        &bin,
        config_path,
        vehicle,
        None,
        &opts.out_dir.join(log_name),
    )?)
}

/// Waits until the planner is up (and subscribed), which its first heartbeat tells.
/// Returns the plans that came with it (the `plan` service's history: a resumed flight's
/// plan).
fn first_status(
    opts: &FlyOptions,
    link: &mut PlannerLink,
    planner: &mut Option<PlannerProcess>,
    vehicle: &str,
    up: Instant,
) -> Result<Received, FlyError> {
    let status_wait = if opts.resume {
        opts.resume_wait
    } else {
        Duration::from_secs(30)
    };
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
                return Err(no_status(vehicle, status_wait).into());
            }
            return Err(FlyError::Planner(format!(
                "no status from a planner on vehicle `{vehicle}` within 30 s"
            )));
        }
        link.wait(Duration::from_millis(100))?;
    }
    Ok(early)
}

/// A resumed flight: the planner's plan and the world at the resume point, the emulators
/// brought there without flying, the link continuing the planner's sequence.
fn take_over(
    opts: &FlyOptions,
    link: &mut PlannerLink,
    datalink: &mut Datalink,
    sensor: &mut ThreatSensor,
    mirror: &mut Mirror,
    moving_base: u32,
    plan: Box<Plan>,
) -> Result<(Resumed, Box<Plan>, Timeline), FlyError> {
    let sc = &opts.scenario;
    let (t0, dt) = (sc.start.time_s, opts.step_s);
    let status = link
        .status()
        .copied()
        .ok_or_else(|| no_status(&opts.planner_config.vehicle_id, opts.resume_wait))?;
    let point = resume::resume_point(&status, &plan, t0, dt)?;
    let matched = resume::check_plan(sc, datalink, &plan, point.planner_s, point.t_s)?;
    let timeline = resume::replay_timeline(datalink, sensor, t0, dt, point.step);
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
    Ok((resumed, plan, timeline))
}
