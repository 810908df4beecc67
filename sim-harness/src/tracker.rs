//! The inner-loop tracker: flies the newest plan whose start time has come (and which the
//! harness has received — in the lock-step clock, from `created_at + compute` on) with the
//! vehicle model (RK4) and the tracking law of `wingman_planning::tracking` (the plan's
//! controls as feed-forward plus feedback on position and heading error), reports
//! `OwnshipState` with its deviation from the plan, and flies a safe hold — a level turn —
//! when the plan it flies is past its `valid_until` with no successor received (or it has
//! no plan), logging each hold.
//!
//! With a truth model ([`crate::truth`]: the scenario's `[wind]` and `[aircraft]`) the
//! tracker commands from the navigation solution against the plan's point abeam the
//! aircraft ([`abeam`]: it follows the path), the aircraft answers with its own lag
//! and limits (held over each step), the wind carries it over the ground, and
//! `OwnshipState` reports the navigation solution; the samples keep the true state.

use wingman_interfaces::{Model, OWNSHIP_HOLDING, OwnshipState, Plan, Wire};
use wingman_planning::dynamics::{
    DynamicsError, G0, Limits, Planar, Spatial, rk4_step_with, wrap_angle,
};
use wingman_planning::problem::Problem;
use wingman_planning::tracking::{Deviation, Tracker, TrackingGains};

use crate::truth::Truth;

/// Longest integration step, s.
pub const MAX_SUBSTEP_S: f64 = 0.05;
/// Bank of the 3-D safe hold (or half the bank limit if that is less), rad.
pub const HOLD_BANK_RAD: f64 = 30.0 * std::f64::consts::PI / 180.0;
const EPS_S: f64 = 1e-6;

/// A plan the harness received, and from when the tracker may fly it.
#[derive(Debug, Clone)]
pub struct ReceivedPlan {
    pub plan: Box<Plan>,
    /// Mission time at which the harness took it from the `plan` service.
    pub received_at_s: f64,
    /// Mission time from which the tracker may fly it (the lock-step clock charges the
    /// plan's compute time here).
    pub available_at_s: f64,
}

/// A stretch of safe hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hold {
    pub from_s: f64,
    /// End of the hold (`None` while holding).
    pub to_s: Option<f64>,
    /// The plan flown before it (0: none yet).
    pub after_plan_id: u64,
}

/// What the tracker is doing at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerSample {
    pub t: f64,
    pub state: [f64; 7],
    pub control: [f64; 2],
    pub plan_id: u64,
    pub holding: bool,
    pub deviation: Deviation,
    /// The wind at the aircraft, m/s (0 in still air).
    pub wind: [f64; 3],
}

/// The vehicle model.
#[derive(Debug, Clone, Copy)]
enum Vehicle {
    Planar(Planar),
    Spatial(Spatial),
}

/// The inner-loop tracker of one vehicle.
#[derive(Debug, Clone)]
pub struct InnerLoop {
    model: Model,
    limits: Limits,
    tracker: Tracker,
    vehicle: Vehicle,
    t: f64,
    state: [f64; 7],
    control: [f64; 2],
    deviation: Deviation,
    plans: Vec<ReceivedPlan>,
    flying: Option<usize>,
    holds: Vec<Hold>,
    /// The wind, the aircraft's response and its navigation (`None`: the planner's model
    /// in still air).
    truth: Option<Truth>,
}

impl InnerLoop {
    /// The tracker at the problem's start state and time, with no plan.
    pub fn new(problem: &Problem, gains: TrackingGains) -> Result<InnerLoop, DynamicsError> {
        let v = problem.limits.speed;
        let vehicle = match problem.model {
            Model::TwoD => Vehicle::Planar(Planar::new(v)?),
            Model::ThreeD => Vehicle::Spatial(Spatial::new(v)?),
        };
        Ok(InnerLoop {
            model: problem.model,
            limits: problem.limits,
            tracker: Tracker::new(problem, gains),
            vehicle,
            t: problem.t0,
            state: problem.x0,
            control: [0.0; 2],
            deviation: Deviation::default(),
            plans: Vec::new(),
            flying: None,
            holds: Vec::new(),
            truth: None,
        })
    }

    /// The tracker flying the aircraft and air of `truth` (`None`: the planner's model in
    /// still air).
    pub fn with_truth(mut self, truth: Option<Truth>) -> InnerLoop {
        self.truth = truth;
        self.update_deviation();
        self
    }

    /// Takes a plan from the planner.
    pub fn receive(&mut self, plan: ReceivedPlan) {
        self.plans.push(plan);
        self.select();
    }

    /// Starts the tracker on `plan` at mission time `t` (a resumed flight): the state and
    /// control are the plan's at `t`, the plan is the flown one (once its start and
    /// availability have come).
    pub fn start_on(&mut self, t: f64, plan: ReceivedPlan) {
        let (x, u) = reference(&plan.plan, t);
        self.t = t;
        self.state = x;
        self.control = u;
        // The disturbances start again from their seeds; the aircraft flies the plan's
        // control already.
        if let Some(truth) = &mut self.truth {
            truth.applying(u);
        }
        self.receive(plan);
        self.update_deviation();
    }

    /// Every plan received, in order.
    pub fn plans(&self) -> &[ReceivedPlan] {
        &self.plans
    }

    /// The plan being flown.
    pub fn flying(&self) -> Option<&ReceivedPlan> {
        self.flying.map(|i| &self.plans[i])
    }

    /// Whether the tracker flies a safe hold.
    pub fn holding(&self) -> bool {
        self.holds.last().is_some_and(|h| h.to_s.is_none())
    }

    /// Every hold so far.
    pub fn holds(&self) -> &[Hold] {
        &self.holds
    }

    /// Mission time.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Current state (model order, zero-padded).
    pub fn state(&self) -> &[f64; 7] {
        &self.state
    }

    /// Whether a received plan newer than the one flown waits for its start.
    pub fn successor_waiting(&self) -> bool {
        let current = self.flying().map_or(0, |p| p.plan.plan_id);
        self.plans.iter().any(|p| p.plan.plan_id > current)
    }

    /// Whether the flown plan has reached its end (the mission is over).
    pub fn plan_finished(&self) -> bool {
        self.flying().is_some_and(|p| {
            let plan = &p.plan;
            plan.valid_until_s >= plan.final_time_s - EPS_S
                && self.t >= plan.final_time_s - EPS_S
                && !self.successor_waiting()
        })
    }

    /// Picks the newest plan whose start time and availability have come, and decides
    /// whether to hold.
    fn select(&mut self) {
        let t = self.t + EPS_S;
        let best = self
            .plans
            .iter()
            .enumerate()
            .filter(|(_, p)| p.available_at_s <= t && p.plan.start_time_s <= t)
            .max_by_key(|(_, p)| p.plan.plan_id)
            .map(|(i, _)| i);
        if best.is_some() {
            self.flying = best;
        }
        let newer_received = self.successor_waiting_received();
        let hold = match self.flying() {
            None => true,
            // A plan that reaches the mission's end is not left past its end: the
            // mission is over there (`plan_finished`).
            Some(p) => {
                let reaches_end = p.plan.valid_until_s >= p.plan.final_time_s - EPS_S;
                // Past valid-until the plan may still be flown until a successor that
                // was received starts; a hold, once begun, lasts until one starts.
                !reaches_end
                    && self.t > p.plan.valid_until_s + EPS_S
                    && (!newer_received || self.holding())
            }
        };
        match (hold, self.holding()) {
            (true, false) => {
                let after_plan_id = self.flying().map_or(0, |p| p.plan.plan_id);
                tracing::warn!(
                    t = self.t,
                    after_plan_id,
                    "no valid plan: flying a safe hold (level turn)"
                );
                self.holds.push(Hold {
                    from_s: self.t,
                    to_s: None,
                    after_plan_id,
                });
            }
            (false, true) => {
                if let Some(h) = self.holds.last_mut() {
                    h.to_s = Some(self.t);
                }
                tracing::info!(t = self.t, "hold ends: flying the plan again");
            }
            _ => {}
        }
    }

    /// A plan newer than the flown one that the harness already has (its start may lie
    /// ahead): the flown plan is then not left without a successor.
    fn successor_waiting_received(&self) -> bool {
        let current = self.flying().map_or(0, |p| p.plan.plan_id);
        self.plans
            .iter()
            .any(|p| p.plan.plan_id > current && p.available_at_s <= self.t + EPS_S)
    }

    /// Flies from the current time to `t` (steps of at most [`MAX_SUBSTEP_S`]), switching
    /// plans and holds at step boundaries.
    pub fn advance_to(&mut self, t: f64) {
        while self.t < t - EPS_S {
            self.select();
            let h = (t - self.t).min(MAX_SUBSTEP_S);
            self.step(h);
        }
        self.t = self.t.max(t);
        self.select();
        self.update_deviation();
    }

    fn step(&mut self, h: f64) {
        if self.truth.is_some() {
            self.step_disturbed(h);
            return;
        }
        let t0 = self.t;
        let holding = self.holding();
        let plan = self.flying.map(|i| &*self.plans[i].plan);
        let tracker = self.tracker;
        let limits = self.limits;
        let model = self.model;
        let mut control = |t: f64, x: &[f64; 7]| -> [f64; 2] {
            match (plan, holding) {
                (Some(p), false) => {
                    let (xr, ur) = reference(p, t);
                    tracker.control(x, &xr, &ur)
                }
                _ => hold_control(model, &limits, x),
            }
        };
        match self.vehicle {
            Vehicle::Planar(m) => {
                let x: [f64; 3] = [self.state[0], self.state[1], self.state[2]];
                let mut c = |t: f64, x: &[f64; 3]| {
                    let full = [x[0], x[1], x[2], 0.0, 0.0, 0.0, 0.0];
                    [control(t, &full)[0]]
                };
                let first = c(t0, &x);
                let next = rk4_step_with(&m, t0, &x, h, &mut c);
                self.state[..3].copy_from_slice(&next);
                self.control = [first[0], 0.0];
            }
            Vehicle::Spatial(m) => {
                let first = control(t0, &self.state);
                let next = rk4_step_with(&m, t0, &self.state, h, &mut control);
                self.state = next;
                self.control = first;
            }
        }
        self.t = t0 + h;
    }

    /// One step of the truth model: the command from the navigation solution, the
    /// aircraft's response to it held over the step, the wind's drift.
    fn step_disturbed(&mut self, h: f64) {
        let t0 = self.t;
        let sensed = self.sensed();
        let command = self.command(t0, &sensed);
        let Some(truth) = self.truth.as_mut() else {
            return;
        };
        let applied = truth.respond(command, h);
        let wind = truth.wind();
        truth.advance(h);
        let mut hold = |_: f64, _: &[f64; 3]| [applied[0]];
        match self.vehicle {
            Vehicle::Planar(m) => {
                let x: [f64; 3] = [self.state[0], self.state[1], self.state[2]];
                let next = rk4_step_with(&m, t0, &x, h, &mut hold);
                self.state[..3].copy_from_slice(&next);
            }
            Vehicle::Spatial(m) => {
                self.state = rk4_step_with(&m, t0, &self.state, h, &mut |_, _| applied);
            }
        }
        truth.drift(&mut self.state, wind, h);
        self.control = applied;
        self.t = t0 + h;
    }

    /// The tracker's command at `t` for the state `x` it sees: the tracking law on the
    /// flown plan's point abeam `x`, its feed-forward the plan's control one response time
    /// of the aircraft later (a first-order lag then applies it when the plan does), or
    /// the safe hold.
    fn command(&self, t: f64, x: &[f64; 7]) -> [f64; 2] {
        match (self.flying(), self.holding()) {
            (Some(p), false) => {
                let at = abeam_time(&p.plan, &self.tracker, t, x, self.limits.speed);
                let lead_s = self.truth.as_ref().map_or(0.0, Truth::response_s);
                let (xr, _) = reference(&p.plan, at);
                let (_, ur) = reference(&p.plan, at + lead_s);
                self.tracker.control(x, &xr, &ur)
            }
            _ => hold_control(self.model, &self.limits, x),
        }
    }

    /// The state as the tracker sees it: the navigation solution (the true state without
    /// a truth model).
    fn sensed(&self) -> [f64; 7] {
        self.truth
            .as_ref()
            .map_or(self.state, |truth| truth.sense(&self.state))
    }

    fn update_deviation(&mut self) {
        let sensed = self.sensed();
        self.deviation = match (self.flying(), self.holding()) {
            (Some(p), false) => {
                let (xr, _) = reference(&p.plan, self.t);
                self.tracker.deviation(&sensed, &xr)
            }
            _ => Deviation::default(),
        };
    }

    /// What the tracker does now.
    pub fn sample(&self) -> TrackerSample {
        TrackerSample {
            t: self.t,
            state: self.state,
            control: self.control,
            plan_id: self.flying().map_or(0, |p| p.plan.plan_id),
            holding: self.holding(),
            deviation: self.deviation,
            wind: self.truth.as_ref().map_or([0.0; 3], Truth::wind),
        }
    }

    /// The `OwnshipState` message now (header left for the sender).
    pub fn ownship(&self) -> OwnshipState {
        let s = self.sample();
        let mut m = OwnshipState::zeroed();
        m.time_s = s.t;
        m.model = self.model.to_wire();
        m.flags = if s.holding { OWNSHIP_HOLDING } else { 0 };
        m.plan_id = s.plan_id;
        m.state = self.sensed();
        m.control = s.control;
        m.cross_track_m = s.deviation.cross_m;
        m.along_track_m = s.deviation.along_m;
        m.vertical_m = s.deviation.vertical_m;
        m
    }
}

/// The plan's state and control at `t`, linear between samples, clamped to its ends.
pub fn reference(plan: &Plan, t: f64) -> ([f64; 7], [f64; 2]) {
    let s = plan.samples();
    let (Some(first), Some(last)) = (s.first(), s.last()) else {
        return ([0.0; 7], [0.0; 2]);
    };
    if t <= first.t_s {
        return (first.state, first.control);
    }
    if t >= last.t_s {
        return (last.state, last.control);
    }
    let k = s.partition_point(|p| p.t_s <= t).saturating_sub(1);
    let (a, b) = (&s[k], &s[(k + 1).min(s.len() - 1)]);
    let span = b.t_s - a.t_s;
    let f = if span > 0.0 { (t - a.t_s) / span } else { 0.0 };
    (
        std::array::from_fn(|i| a.state[i] + f * (b.state[i] - a.state[i])),
        std::array::from_fn(|i| a.control[i] + f * (b.control[i] - a.control[i])),
    )
}

/// The plan's state and control abeam `x` (at plan time near `t`): the point at time `t`
/// moved along the plan by `x`'s along-track deviation from it, twice over. The tracker of
/// a disturbed flight follows the path: an aircraft the gusts have put ahead of or behind
/// its plan flies the plan's path on, rather than a short cut across a turn towards where
/// the plan is now (at constant airspeed it cannot make up time, and a cut turn misses the
/// target on it); the along-track deviation is the planner's to re-plan.
pub fn abeam(
    plan: &Plan,
    tracker: &Tracker,
    t: f64,
    x: &[f64; 7],
    speed: f64,
) -> ([f64; 7], [f64; 2]) {
    reference(plan, abeam_time(plan, tracker, t, x, speed))
}

/// The plan time of the point abeam `x` ([`abeam`]).
pub fn abeam_time(plan: &Plan, tracker: &Tracker, t: f64, x: &[f64; 7], speed: f64) -> f64 {
    let mut at = t;
    for _ in 0..2 {
        at += tracker.deviation(x, &reference(plan, at).0).along_m / speed;
    }
    at
}

/// The safe hold: a level turn to the left. 2-D: half the turn-rate limit. 3-D: bank
/// [`HOLD_BANK_RAD`] (at most half the bank limit), flight-path angle driven to zero (up
/// when near the altitude floor), the load factor that holds the turn level.
pub fn hold_control(model: Model, l: &Limits, x: &[f64; 7]) -> [f64; 2] {
    match model {
        Model::TwoD => [0.5 * l.turn_rate_max, 0.0],
        Model::ThreeD => {
            let (gamma, nz, mu) = (x[3], x[5], x[6]);
            let k_att = 0.25;
            let k_act = 1.5;
            let gamma_cmd = if x[2] < l.z_min + 200.0 { 0.05 } else { 0.0 };
            let mu_cmd = HOLD_BANK_RAD.min(0.5 * l.mu_max);
            let gamma_rate = k_att * (gamma_cmd - gamma);
            let nz_cmd = ((l.speed * gamma_rate / G0 + gamma.cos()) / mu_cmd.cos())
                .clamp(l.nz_min, l.nz_max);
            [
                (k_act * (nz_cmd - nz)).clamp(-l.nz_rate_max, l.nz_rate_max),
                (k_act * wrap_angle(mu_cmd - mu)).clamp(-l.mu_rate_max, l.mu_rate_max),
            ]
        }
    }
}
