//! `report.json`: the outcome of a flight, documented key by key in `docs/REPORT.md`.
//! Every number is computed from what was flown (the tracker's path) and the truth (every
//! static threat, pop-ups included, and each moving threat at its true position), never
//! from the plans alone.

use serde::Serialize;
use wingman_interfaces::{Model, Objective, PlanPath, Quality, Trigger};
use wingman_planning::metrics::{TargetMiss, simpson, target_misses};
use wingman_planning::threat::{ExposureAcc, Superquadric, ThreatError, ThreatLayout};

use crate::campaign::layout::{segment_dist, xy};
use crate::mission::{EndReason, Flight, position};

/// A target's outcome.
#[derive(Debug, Clone, Serialize)]
pub struct TargetOutcome {
    pub position_m: [f64; 3],
    /// Closest approach (sequential, as the judge), m.
    pub miss_m: f64,
    /// Mission time of the closest approach, s.
    pub at_s: f64,
    /// Within 100 m.
    pub passed: bool,
    /// Tasking revision that set this target.
    pub revision: u32,
}

/// A target a resumed flight did not fly to: the planner had passed it before the resume.
#[derive(Debug, Clone, Serialize)]
pub struct TargetBeforeResume {
    pub position_m: [f64; 3],
    /// Tasking revision that set this target.
    pub revision: u32,
}

/// Smallest `F` of one threat along the flown path.
#[derive(Debug, Clone, Serialize)]
pub struct ThreatOutcome {
    pub name: String,
    pub kind: &'static str,
    pub min_f: f64,
    pub at_s: f64,
}

/// One plan the harness received.
#[derive(Debug, Clone, Serialize)]
pub struct PlanOutcome {
    pub plan_id: u64,
    /// Mission time of the trigger, s.
    pub at_s: f64,
    pub trigger: String,
    pub quality: String,
    /// The planner's path that made it (`Global`, `Warm`).
    pub path: String,
    /// Where its compute deadline cut it (0: nowhere; the plan is the same on any
    /// machine).
    pub cuts: u32,
    pub compute_ms: f64,
    pub cost: f64,
    pub start_s: f64,
    pub valid_until_s: f64,
    pub final_time_s: f64,
    pub next_replan_s: Option<f64>,
    /// From when the tracker could fly it (trigger time + compute time in the lock-step
    /// clock).
    pub available_at_s: f64,
    /// Whether the tracker ever flew it.
    pub flown: bool,
}

/// A stretch of safe hold.
#[derive(Debug, Clone, Serialize)]
pub struct HoldOutcome {
    pub from_s: f64,
    pub to_s: Option<f64>,
    pub after_plan_id: u64,
}

/// The planner's counters at the end (its last status).
#[derive(Debug, Clone, Serialize)]
pub struct PlannerCounters {
    pub plans_made: u64,
    pub messages_received: u64,
    pub messages_rejected: u64,
    /// Inputs lost before the planner read them (gaps in the harness's sequence).
    pub messages_lost: u64,
    pub triggers_coalesced: u64,
    pub triggers_deferred: u64,
    pub popups_clear: u64,
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub scenario: String,
    pub model: String,
    pub objective: String,
    pub clock: String,
    pub vehicle_id: String,
    /// Mission time at which a resumed flight (`fly --resume`) took the mission over
    /// (`None`: flown from the start). The path metrics cover the path flown from then on.
    pub resumed_at_s: Option<f64>,
    /// The targets the planner had passed before the resume (empty unless resumed): not
    /// flown by this harness, so not in `targets` and not judged.
    pub targets_before_resume: Vec<TargetBeforeResume>,
    /// Every target within 100 m, the final point or the lead within 100 m, and the
    /// flown plan ended before the time limit.
    pub completed: bool,
    /// `plan-ended` or `time-limit`.
    pub end: &'static str,
    pub start_s: f64,
    pub end_s: f64,
    pub flight_time_s: f64,
    pub targets: Vec<TargetOutcome>,
    /// Where the aircraft was at `end_s` (x, y, z; z is 0 in 2-D), m.
    pub end_position_m: [f64; 3],
    /// Distance from the final point (or the lead at `end_s`) at the end, m.
    pub final_error_m: f64,
    /// `end_s` minus the fixed final time (fixed-time missions), s.
    pub final_time_error_s: Option<f64>,
    /// When the aircraft reached the final point against the fixed final time
    /// (fixed-time missions), s: the time of its closest approach, or, still short of it
    /// at the end, the end plus the distance left along its track over its ground speed.
    /// Negative: early.
    pub arrival_time_error_s: Option<f64>,
    /// Smallest `F` of any static threat along the flown path (pop-ups included).
    pub min_f_static: Option<f64>,
    /// Smallest `F` of any moving threat's true keep-out region while it exists.
    pub min_f_moving: Option<f64>,
    pub threats: Vec<ThreatOutcome>,
    /// `∫ E dt` along the flown path against the truth, s.
    pub exposure_integral: f64,
    pub max_cross_track_m: f64,
    pub max_vertical_m: f64,
    pub plans: Vec<PlanOutcome>,
    pub replans: usize,
    pub holds: Vec<HoldOutcome>,
    pub planner: Option<PlannerCounters>,
    /// Planner messages that failed `validate()` at the harness.
    pub rejected_messages: u64,
    pub wall_s: f64,
}

/// Closest approach within this counts as reaching a target or the end, m.
pub const REACHED_M: f64 = 100.0;

/// The truth along the flown path of one dimension.
struct Truth<const D: usize> {
    layout: ThreatLayout<D>,
    statics: Vec<(String, Superquadric<D>)>,
}

fn truth<const D: usize>(flight: &Flight) -> Result<Truth<D>, ThreatError> {
    let sc = &flight.scenario;
    let mut statics = Vec::new();
    for t in &sc.threats {
        let q = Superquadric::new(
            std::array::from_fn(|i| t.center_m[i]),
            std::array::from_fn(|i| t.axes_m[i]),
            std::array::from_fn(|i| t.exponents[i]),
            t.yaw_rad,
        )?;
        statics.push((t.name.clone(), q));
    }
    let shapes: Vec<Superquadric<D>> = statics.iter().map(|(_, q)| *q).collect();
    let layout = ThreatLayout::with_threats(sc.weights.stiffness, &shapes)?;
    Ok(Truth { layout, statics })
}

/// The true keep-out region of moving threat `i` at step `k` (absent before it appears).
fn moving_region<const D: usize>(flight: &Flight, i: usize, k: usize) -> Option<Superquadric<D>> {
    let m = flight.scenario.moving_threats.get(i)?;
    let (t, p) = *flight.truth.get(i)?.get(k)?;
    if t < m.appears_at_s {
        return None;
    }
    // The road's direction at the true position: the segment nearest to it.
    let road = &m.road_m;
    let seg = (0..road.len().saturating_sub(1))
        .min_by(|&a, &b| {
            let to = |k: usize| segment_dist(xy(&road[k]), xy(&road[k + 1]), xy(&p));
            to(a).total_cmp(&to(b))
        })
        .unwrap_or(0);
    let (a, b) = (road.get(seg)?, road.get(seg + 1)?);
    let yaw = (b[1] - a[1]).atan2(b[0] - a[0]);
    Superquadric::new(
        std::array::from_fn(|i| p[i]),
        std::array::from_fn(|i| m.axes_m[i]),
        [2.0; D],
        yaw,
    )
    .ok()
}

fn flown_positions<const D: usize>(flight: &Flight) -> Vec<[f64; D]> {
    flight
        .samples
        .iter()
        .map(|x| {
            let p = position(flight.scenario.model, &x.state);
            std::array::from_fn(|i| p[i])
        })
        .collect()
}

/// `E` against the truth at every flown sample.
fn exposure_in<const D: usize>(flight: &Flight, tr: &Truth<D>, pos: &[[f64; D]]) -> Vec<f64> {
    let s = flight.scenario.weights.stiffness;
    let movings = flight.scenario.moving_threats.len();
    (0..pos.len())
        .map(|k| {
            let mut acc = ExposureAcc::<D>::new();
            tr.layout.fold_value_into(&pos[k], &mut acc);
            for i in 0..movings {
                if let Some(q) = moving_region::<D>(flight, i, k) {
                    acc.fold_value(q.f(&pos[k]), s);
                }
            }
            acc.e.value
        })
        .collect()
}

/// The exposure `E` against the truth at every sample of `flight.samples`.
pub fn exposure_series(flight: &Flight) -> Result<Vec<f64>, ThreatError> {
    Ok(match flight.scenario.model {
        Model::TwoD => exposure_in::<2>(flight, &truth::<2>(flight)?, &flown_positions(flight)),
        Model::ThreeD => exposure_in::<3>(flight, &truth::<3>(flight)?, &flown_positions(flight)),
    })
}

struct PathMetrics {
    exposure: f64,
    threats: Vec<ThreatOutcome>,
    targets: Vec<TargetOutcome>,
    before_resume: Vec<TargetBeforeResume>,
}

fn path_metrics<const D: usize>(flight: &Flight) -> Result<PathMetrics, ThreatError> {
    let sc = &flight.scenario;
    let tr = truth::<D>(flight)?;
    let times: Vec<f64> = flight.samples.iter().map(|x| x.t).collect();
    let pos: Vec<[f64; D]> = flown_positions(flight);
    let series = exposure_in::<D>(flight, &tr, &pos);
    let exposure = simpson(&times, &series);
    let mut threats = Vec::new();
    for (name, q) in &tr.statics {
        let best = pos
            .iter()
            .enumerate()
            .map(|(k, w)| (q.f(w), k))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((f, k)) = best {
            threats.push(ThreatOutcome {
                name: name.clone(),
                kind: "static",
                min_f: f,
                at_s: times[k],
            });
        }
    }
    for (i, m) in sc.moving_threats.iter().enumerate() {
        let best = (0..pos.len())
            .filter_map(|k| moving_region::<D>(flight, i, k).map(|q| (q.f(&pos[k]), k)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((f, k)) = best {
            threats.push(ThreatOutcome {
                name: m.name.clone(),
                kind: "moving",
                min_f: f,
                at_s: times[k],
            });
        }
    }
    // Targets: each tasking revision's targets on the path flown while it was in force;
    // an earlier revision's target counts only if it was reached before it was replaced.
    // A resumed flight did not fly to the targets the planner had passed before the
    // resume: they are listed apart, and the search starts at the first one ahead.
    let revisions = flight.datalink.taskings();
    let mut targets = Vec::new();
    let mut before_resume = Vec::new();
    for (r, rev) in revisions.iter().enumerate() {
        let skip = match flight.resumed {
            Some(res) if res.matched.revision == rev.tasking.revision => res.matched.passed,
            _ => 0,
        };
        let all = rev.tasking.targets();
        let skip = skip.min(all.len());
        before_resume.extend(all[..skip].iter().map(|p| TargetBeforeResume {
            position_m: *p,
            revision: rev.tasking.revision,
        }));
        let ahead = &all[skip..];
        let from = times.partition_point(|&t| t < rev.at_s);
        let to = revisions.get(r + 1).map_or(times.len(), |next| {
            times.partition_point(|&t| t < next.at_s)
        });
        let list: Vec<[f64; D]> = ahead
            .iter()
            .map(|p| std::array::from_fn(|i| p[i]))
            .collect();
        let mut out = vec![
            TargetMiss {
                distance: f64::INFINITY,
                index: 0
            };
            list.len()
        ];
        let n = target_misses(&pos[from..to.max(from)], &list, &mut out);
        let last = r + 1 == revisions.len();
        for (j, miss) in out.iter().take(n).enumerate() {
            let passed = miss.distance <= REACHED_M;
            if last || passed {
                let p = ahead[j];
                targets.push(TargetOutcome {
                    position_m: p,
                    miss_m: miss.distance,
                    at_s: times.get(from + miss.index).copied().unwrap_or(f64::NAN),
                    passed,
                    revision: rev.tasking.revision,
                });
            }
        }
    }
    Ok(PathMetrics {
        exposure,
        threats,
        targets,
        before_resume,
    })
}

/// The report of a flight.
pub fn build(flight: &Flight) -> Result<Report, ThreatError> {
    let sc = &flight.scenario;
    let m = match sc.model {
        Model::TwoD => path_metrics::<2>(flight)?,
        Model::ThreeD => path_metrics::<3>(flight)?,
    };
    // The end: the flown plan's final time (the last step may overshoot it by a
    // fraction of a step), or the last sample after a time limit.
    let end_t = match (flight.end, flight.samples.last()) {
        (EndReason::PlanEnded, Some(last)) => flight
            .plans
            .iter()
            .find(|p| p.plan.plan_id == last.plan_id)
            .map_or(last.t, |p| p.plan.final_time_s.min(last.t)),
        (_, Some(last)) => last.t,
        (_, None) => flight.end_s,
    };
    let end_pos = position(sc.model, &state_at(&flight.samples, end_t));
    let goal = match sc.objective {
        Objective::MinTimeRendezvous => flight
            .datalink
            .lead_at(end_t)
            .map(|l| l.position)
            .unwrap_or(end_pos),
        _ => {
            let last = flight.datalink.taskings().last();
            let f = last.map(|r| r.tasking.final_state).unwrap_or_default();
            position(sc.model, &f)
        }
    };
    let final_error_m = end_pos
        .iter()
        .zip(goal)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt();
    let final_time_error_s = match sc.objective {
        Objective::FixedTime => flight
            .datalink
            .taskings()
            .last()
            .map(|r| end_t - r.tasking.final_time_s),
        _ => None,
    };
    let arrival_time_error_s = match (sc.objective, flight.datalink.taskings().last()) {
        (Objective::FixedTime, Some(r)) => {
            arrival_time(&flight.samples, sc.model, goal, end_t).map(|t| t - r.tasking.final_time_s)
        }
        _ => None,
    };
    let min_of = |kind: &str| {
        m.threats
            .iter()
            .filter(|t| t.kind == kind)
            .map(|t| t.min_f)
            .min_by(f64::total_cmp)
    };
    let flown: std::collections::HashSet<u64> = flight.samples.iter().map(|s| s.plan_id).collect();
    let plans: Vec<PlanOutcome> = flight
        .plans
        .iter()
        .map(|p| {
            let q = &p.plan;
            PlanOutcome {
                plan_id: q.plan_id,
                at_s: q.created_at_s,
                trigger: q.trigger().map_or("?", Trigger::name).to_string(),
                quality: q.quality().map_or("?", Quality::name).to_string(),
                path: q.path().map_or("?", PlanPath::name).to_string(),
                cuts: q.cut_count,
                compute_ms: q.compute_ms,
                cost: q.cost,
                start_s: q.start_time_s,
                valid_until_s: q.valid_until_s,
                final_time_s: q.final_time_s,
                next_replan_s: q.next_replan(),
                available_at_s: p.available_at_s,
                flown: flown.contains(&q.plan_id),
            }
        })
        .collect();
    let max_abs = |f: fn(&crate::tracker::TrackerSample) -> f64| {
        flight
            .samples
            .iter()
            .filter(|s| !s.holding && s.plan_id != 0)
            .map(|s| f(s).abs())
            .fold(0.0, f64::max)
    };
    let plan_ended = flight.end == EndReason::PlanEnded;
    let completed = plan_ended
        && m.targets.iter().all(|t| t.passed)
        && final_error_m <= REACHED_M
        && !flight.plans.is_empty();
    Ok(Report {
        scenario: sc.name.clone(),
        model: match sc.model {
            Model::TwoD => "2d".into(),
            Model::ThreeD => "3d".into(),
        },
        objective: sc.objective.name().to_string(),
        clock: flight.clock.to_string(),
        vehicle_id: flight.vehicle_id.clone(),
        resumed_at_s: flight.resumed.map(|r| r.point.t_s),
        targets_before_resume: m.before_resume,
        completed,
        end: if plan_ended {
            "plan-ended"
        } else {
            "time-limit"
        },
        start_s: sc.start.time_s,
        end_s: end_t,
        flight_time_s: end_t - sc.start.time_s,
        targets: m.targets,
        end_position_m: end_pos,
        final_error_m,
        final_time_error_s,
        arrival_time_error_s,
        min_f_static: min_of("static"),
        min_f_moving: min_of("moving"),
        threats: m.threats,
        exposure_integral: m.exposure,
        max_cross_track_m: max_abs(|s| s.deviation.cross_m),
        max_vertical_m: max_abs(|s| s.deviation.vertical_m),
        replans: plans.len().saturating_sub(1),
        plans,
        holds: flight
            .holds
            .iter()
            .map(|h| HoldOutcome {
                from_s: h.from_s,
                to_s: h.to_s,
                after_plan_id: h.after_plan_id,
            })
            .collect(),
        planner: flight.last_status.map(|s| PlannerCounters {
            plans_made: s.plans_made,
            messages_received: s.messages_received,
            messages_rejected: s.messages_rejected,
            messages_lost: s.messages_lost,
            triggers_coalesced: s.triggers_coalesced,
            triggers_deferred: s.triggers_deferred,
            popups_clear: s.popups_clear,
        }),
        rejected_messages: flight.rejected,
        wall_s: flight.wall.as_secs_f64(),
    })
}

/// The flown state at `t`, linear between the tracker's samples.
fn state_at(samples: &[crate::tracker::TrackerSample], t: f64) -> [f64; 7] {
    let k = samples.partition_point(|s| s.t <= t);
    match (
        k.checked_sub(1).and_then(|i| samples.get(i)),
        samples.get(k),
    ) {
        (Some(a), Some(b)) if b.t > a.t => {
            let f = (t - a.t) / (b.t - a.t);
            std::array::from_fn(|i| a.state[i] + f * (b.state[i] - a.state[i]))
        }
        (Some(a), _) => a.state,
        (None, Some(b)) => b.state,
        (None, None) => [0.0; 7],
    }
}

/// When the flight reached `goal`: the time of its closest approach up to `end_t`; if
/// that is the end itself (still short of it), the end plus the distance left along the
/// track over the ground speed there. `None` without samples.
fn arrival_time(
    samples: &[crate::tracker::TrackerSample],
    model: Model,
    goal: [f64; 3],
    end_t: f64,
) -> Option<f64> {
    let flown: Vec<_> = samples.iter().filter(|s| s.t <= end_t).collect();
    let distance = |s: &crate::tracker::TrackerSample| {
        let p = position(model, &s.state);
        p.iter()
            .zip(goal)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt()
    };
    let (k, closest) = flown
        .iter()
        .enumerate()
        .min_by(|a, b| distance(a.1).total_cmp(&distance(b.1)))?;
    if k + 1 < flown.len() || k == 0 {
        return Some(closest.t);
    }
    let before = flown[k - 1];
    let (p0, p1) = (
        position(model, &before.state),
        position(model, &closest.state),
    );
    let dt = closest.t - before.t;
    let velocity: Vec<f64> = p1.iter().zip(p0).map(|(a, b)| (a - b) / dt).collect();
    let speed = velocity.iter().map(|v| v * v).sum::<f64>().sqrt();
    let left: f64 = goal
        .iter()
        .zip(p1)
        .zip(&velocity)
        .map(|((g, p), v)| (g - p) * v / speed)
        .sum();
    Some(closest.t + left.max(0.0) / speed)
}
