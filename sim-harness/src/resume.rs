//! `fly --resume`: a new harness takes over the mission a planner is still flying after its
//! harness died (`kill -9`). The planner keeps its world (tasking, route, threats, Kalman
//! filters, plan, its mission clock and the highest input sequence it processed); the new
//! harness picks the mission up where the planner has it instead of starting it again:
//!
//! 1. [`resume_point`]: the planner's newest mission time (its status header), or the
//!    current plan's start if that is later, rounded up to the harness's step grid; the
//!    input sequence continues above the status's `last_input_sequence` (the lock-step
//!    clock waits for the status to echo its sequence, and the planner orders one sender's
//!    headers by mission time: both keep growing across the two harness processes, which
//!    share the sender id `SENDER_HARNESS`).
//! 2. [`check_plan`]: the planner's plan must be one of this scenario's — its model, the
//!    targets it still visits (the tasking's last ones) and its end (the final point, or
//!    the lead) within [`MATCH_M`] of the scenario's tasking in force at the planner's
//!    mission time, and a fixed-time tasking's final time within [`MATCH_FINAL_TIME_S`].
//!    The status and the plan carry no scenario name, tasking revision, objective or
//!    threats, so this is what can be told apart (a min-time scenario resumed on a planner
//!    flying the fixed-time one of the same places, or another scenario's threats, are
//!    not seen); it also says which targets the planner had passed.
//! 3. [`replay_timeline`]: the scenario's timeline up to the resume step *without flying*:
//!    the tasking and the lead route in force, every threat known by then (static, pop-ups,
//!    moving ones), the moving threats' truth (its random process does not depend on the
//!    aircraft) and the sensor's fixes, which are not sent again (the planner's filters
//!    have those that reached it) but feed the harness's mirror of the filters.
//!
//! The flight then starts on the current plan at the resume time (the tracker's state is
//! the plan's there, the plan's id the flown one) and goes on as any flight.

use std::time::Duration;

use wingman_interfaces::{LeadRoute, Objective, Plan, PlannerStatus, Tasking};
use wingman_planning::scenario::Scenario;

use crate::clock::step_time;
use crate::datalink::Datalink;
use crate::mission::position;
use crate::sensor::{SensorOutput, ThreatSensor};
use crate::tracker::reference;

/// Longest wait for the planner's status and plan before there is nothing to resume.
pub const RESUME_WAIT: Duration = Duration::from_secs(10);

/// Largest distance between the planner's plan and the scenario's targets or end for the
/// plan to count as this scenario's, m: far above a plan's own error there (metres; tens
/// of metres for a 3-D plan flown with the tracking law), far below the distances between
/// the places of different missions.
pub const MATCH_M: f64 = 500.0;

/// Largest difference between the plan's final time and a fixed-time tasking's, s (the
/// planner's plans meet it exactly).
pub const MATCH_FINAL_TIME_S: f64 = 1.0;

/// Grid times within this share of a step count as on the grid.
const GRID_TOL: f64 = 1e-6;

/// A flight that cannot be resumed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResumeError {
    #[error(
        "--resume takes over a planner already flying the mission: it needs --planner external"
    )]
    NotExternal,
    #[error("nothing to resume: no planner status on {service} within {within_s} s")]
    NoStatus { service: String, within_s: f64 },
    #[error(
        "nothing to resume: no plan on {service} within {within_s} s (the planner has not planned)"
    )]
    NoPlan { service: String, within_s: f64 },
    #[error(
        "nothing to resume: the planner's plan {plan_id} ends at {final_s:.1} s, and the planner is at mission time {at_s:.1} s"
    )]
    Ended {
        plan_id: u64,
        final_s: f64,
        at_s: f64,
    },
    #[error(
        "the planner's mission time {at_s:.1} s is before the scenario's start at {start_s:.1} s"
    )]
    BeforeStart { at_s: f64, start_s: f64 },
    #[error("the planner flies another mission than `{scenario}`: {detail}")]
    Mismatch { scenario: String, detail: String },
}

/// Where a resumed flight begins.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResumePoint {
    /// The planner's newest mission time (its status header), s.
    pub planner_s: f64,
    /// Mission time of the first step of the resumed flight (on the step grid), s.
    pub t_s: f64,
    /// Its step index: `t_s = t0 + step * dt`.
    pub step: u64,
    /// The highest input sequence the planner processed: the new harness's first input
    /// has the next one.
    pub last_sequence: u64,
}

/// The first step `k` with `t0 + k dt` at or after `t` (a time within a millionth of a
/// step of a grid time counts as on it); 0 before `t0`.
pub fn step_at_or_after(t0: f64, dt: f64, t: f64) -> u64 {
    let steps = (t - t0) / dt;
    if steps <= 0.0 {
        0
    } else {
        (steps - GRID_TOL).ceil().max(0.0) as u64
    }
}

/// The resume point of a flight with start `t0` and step `dt` against the planner's
/// `status` and current `plan` (module documentation, step 1).
pub fn resume_point(
    status: &PlannerStatus,
    plan: &Plan,
    t0: f64,
    dt: f64,
) -> Result<ResumePoint, ResumeError> {
    let planner_s = status.header.mission_time_ns as f64 * 1e-9;
    if planner_s < t0 - GRID_TOL * dt {
        return Err(ResumeError::BeforeStart {
            at_s: planner_s,
            start_s: t0,
        });
    }
    // A re-plan that commits after the planner's mission time: the plan it replaces is no
    // longer in the `plan` service's history (it holds one), so the flight resumes at the
    // new plan's start.
    let from = planner_s.max(plan.start_time_s);
    let step = step_at_or_after(t0, dt, from);
    let t_s = step_time(t0, dt, step);
    if t_s >= plan.final_time_s {
        return Err(ResumeError::Ended {
            plan_id: plan.plan_id,
            final_s: plan.final_time_s,
            at_s: planner_s,
        });
    }
    Ok(ResumePoint {
        planner_s,
        t_s,
        step,
        last_sequence: status.last_input_sequence,
    })
}

/// A resumed flight: where it took over and what the planner's plan said then.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resumed {
    pub point: ResumePoint,
    /// The planner's plan the flight resumed on (the flown plan at the resume).
    pub plan_id: u64,
    pub matched: PlanMatch,
}

/// What the planner's plan says of the scenario's tasking.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PlanMatch {
    /// The tasking revision the planner holds (the newest due by its mission time).
    pub revision: u32,
    /// Targets of that revision passed before the resume: the plan no longer visits them,
    /// or reaches them at or before the resume time.
    pub passed: usize,
    /// Targets of that revision still ahead.
    pub ahead: usize,
}

fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Checks that `plan` is one of `sc`'s at the planner's mission time `planner_s` (module
/// documentation, step 2) and says which targets remain at the resume time `t_s`.
pub fn check_plan(
    sc: &Scenario,
    datalink: &Datalink,
    plan: &Plan,
    planner_s: f64,
    t_s: f64,
) -> Result<PlanMatch, ResumeError> {
    let mismatch = |detail: String| ResumeError::Mismatch {
        scenario: sc.name.clone(),
        detail,
    };
    let dims = |m: wingman_interfaces::Model| match m {
        wingman_interfaces::Model::TwoD => "2-D",
        wingman_interfaces::Model::ThreeD => "3-D",
    };
    let model = plan
        .model()
        .ok_or_else(|| mismatch("a plan of no known model".into()))?;
    if model != sc.model {
        return Err(mismatch(format!(
            "its plan {} is {}, the scenario is {}",
            plan.plan_id,
            dims(model),
            dims(sc.model)
        )));
    }
    let revisions = datalink.taskings();
    let Some(held) = revisions
        .iter()
        .rev()
        .find(|r| r.at_s <= planner_s + 1e-9)
        .or(revisions.first())
    else {
        return Err(mismatch("the scenario has no tasking".into()));
    };
    let tasking: &Tasking = &held.tasking;
    let targets = tasking.targets();
    let ends = plan.phase_ends();
    let visits = ends.len().saturating_sub(1);
    if visits > targets.len() {
        return Err(mismatch(format!(
            "its plan {} visits {visits} target(s), the scenario's tasking revision {} has {}",
            plan.plan_id,
            tasking.revision,
            targets.len()
        )));
    }
    let skipped = targets.len() - visits;
    for (g, end) in ends[..visits].iter().enumerate() {
        let at = position(model, &reference(plan, *end).0);
        let target = &targets[skipped + g];
        let d = distance(&at, target);
        if d > MATCH_M {
            return Err(mismatch(format!(
                "its plan {} passes ({:.0}, {:.0}, {:.0}) m at {end:.1} s, {d:.0} m from target \
                 {} of the scenario's tasking revision {} at ({:.0}, {:.0}, {:.0}) m",
                plan.plan_id,
                at[0],
                at[1],
                at[2],
                skipped + g + 1,
                tasking.revision,
                target[0],
                target[1],
                target[2]
            )));
        }
    }
    let last = plan
        .samples()
        .last()
        .ok_or_else(|| mismatch("a plan without samples".into()))?;
    let end = position(model, &last.state);
    let (goal, what) = match sc.objective {
        Objective::MinTimeRendezvous => {
            let lead = datalink
                .flown_route_at(planner_s)
                .map(|r| r.path.at(plan.final_time_s).position)
                .ok_or_else(|| mismatch("the rendezvous scenario has no lead route".into()))?;
            (lead, "the lead")
        }
        _ => (position(model, &tasking.final_state), "the final point"),
    };
    let d = distance(&end, &goal);
    if d > MATCH_M {
        return Err(mismatch(format!(
            "its plan {} ends at ({:.0}, {:.0}, {:.0}) m at {:.1} s, {d:.0} m from {what} of the \
             scenario's tasking revision {} at ({:.0}, {:.0}, {:.0}) m",
            plan.plan_id,
            end[0],
            end[1],
            end[2],
            plan.final_time_s,
            tasking.revision,
            goal[0],
            goal[1],
            goal[2]
        )));
    }
    if sc.objective == Objective::FixedTime
        && (plan.final_time_s - tasking.final_time_s).abs() > MATCH_FINAL_TIME_S
    {
        return Err(mismatch(format!(
            "its plan {} ends at {:.1} s, the scenario's tasking revision {} at the fixed time \
             {:.1} s",
            plan.plan_id, plan.final_time_s, tasking.revision, tasking.final_time_s
        )));
    }
    let passed_on_plan = ends[..visits].iter().filter(|&&e| e <= t_s).count();
    Ok(PlanMatch {
        revision: tasking.revision,
        passed: skipped + passed_on_plan,
        ahead: visits - passed_on_plan,
    })
}

/// The scenario's world at the resume step (module documentation, step 3).
#[derive(Debug, Clone)]
pub struct Timeline {
    /// The tasking in force (the newest revision due by the resume time).
    pub tasking: Option<Tasking>,
    /// The lead's route in force.
    pub route: Option<LeadRoute>,
    /// What the sensor reported at every step up to the resume step, in order: every
    /// threat known by then (each once) and the fixes the old harness sent or would have.
    pub sensor: Vec<SensorOutput>,
}

impl Timeline {
    /// The threat reports (each known threat once, in the order they appeared).
    pub fn reports(&self) -> impl Iterator<Item = &wingman_interfaces::ThreatReport> {
        self.sensor.iter().filter_map(|o| match o {
            SensorOutput::Report(r) => Some(r),
            SensorOutput::Fix(_) => None,
        })
    }
}

/// Replays the datalink and the sensor over steps `0..=step` of the grid `t0 + k dt`
/// without flying: afterwards both stand as after a flight's step `step`, and the timeline
/// says what was in force and known then.
pub fn replay_timeline(
    datalink: &mut Datalink,
    sensor: &mut ThreatSensor,
    t0: f64,
    dt: f64,
    step: u64,
) -> Timeline {
    let mut outputs = Vec::new();
    for k in 0..=step {
        outputs.extend(sensor.poll(step_time(t0, dt, k)));
    }
    let t = step_time(t0, dt, step);
    let tasking = datalink.taskings_due(t).last().map(|r| r.tasking);
    let route = datalink.routes_due(t).last().map(|r| r.message);
    Timeline {
        tasking,
        route,
        sensor: outputs,
    }
}
