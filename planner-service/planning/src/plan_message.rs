//! The `Plan` message from a planned trajectory: the dense trajectory is resampled to at
//! most [`MAX_PLAN_SAMPLES`] samples — the first and the last, every phase end time, and
//! otherwise uniform in time — written in place (the message is 160 KiB: never on the
//! stack), and the samples are turned into the [`PlanPoint`]s the triggers test.
//!
//! Allocation-free: the sample times are written straight into the message.

use wingman_interfaces::{
    Header, MAX_PHASES, MAX_PLAN_CUTS, MAX_PLAN_SAMPLES, Message, Model, Plan, PlanCut, PlanPath,
    PlanSample, Quality, Trigger, ValidationError,
};

use crate::cuts::{Cut, Site};

use crate::dynamics::{Planar, Spatial};
use crate::replan::PlanPoint;
use crate::trajectory::Trajectory;

/// Two sample times closer than this are one.
pub const TIME_EPS: f64 = 1e-6;

/// What the message says besides the samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanInfo {
    pub plan_id: u64,
    pub trigger: Trigger,
    pub quality: Quality,
    pub model: Model,
    /// The planner's path that made it.
    pub path: PlanPath,
    /// Mission time of the trigger.
    pub created_at_s: f64,
    pub cost: f64,
    pub compute_ms: f64,
}

/// A trajectory that cannot become a plan message.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ExportError {
    #[error("the trajectory has fewer than two samples")]
    TooShort,
    #[error("the trajectory has {0} phases, over the message's capacity")]
    TooManyPhases(usize),
    #[error("the plan message is invalid: {0}")]
    Invalid(#[from] ValidationError),
}

/// Times of at most `max` samples over `[t0, tf]`: `times` (the dense samples) when they
/// fit beside the interior phase ends, else a uniform grid; merged with the interior
/// `phase_ends`, which are always kept (a grid time within [`TIME_EPS`] of one gives way).
/// Strictly increasing, first `t0`, last `tf`. Calls `emit` for each; returns the count.
pub fn sample_times(
    times: &[f64],
    phase_ends: &[f64],
    max: usize,
    mut emit: impl FnMut(usize, f64),
) -> usize {
    let (Some(&t0), Some(&tf)) = (times.first(), times.last()) else {
        return 0;
    };
    let interior = |e: &&f64| **e > t0 + TIME_EPS && **e < tf - TIME_EPS;
    let n_phase = phase_ends.iter().filter(interior).count();
    let slots = max.saturating_sub(n_phase).max(2);
    let dense = times.len() <= slots;
    let n_grid = if dense { times.len() } else { slots };
    let grid = |k: usize| -> f64 {
        if dense {
            times[k]
        } else if k + 1 == n_grid {
            tf
        } else {
            t0 + (tf - t0) * k as f64 / (n_grid - 1) as f64
        }
    };
    let mut ends = phase_ends.iter().filter(interior).copied().peekable();
    let mut count = 0;
    let mut last = f64::NEG_INFINITY;
    let mut push = |t: f64, count: &mut usize| {
        if t > last + TIME_EPS && *count < max {
            emit(*count, t);
            *count += 1;
            last = t;
        }
    };
    for k in 0..n_grid {
        let t = grid(k);
        while let Some(&e) = ends.peek() {
            if e <= t + TIME_EPS {
                push(e, &mut count);
                ends.next();
            } else {
                break;
            }
        }
        push(t, &mut count);
    }
    count
}

/// Writes the plan message for `tr` into `out` (zeroed first): header, `info`, phase
/// ends, samples. `valid_until` is the trajectory's end and there is no scheduled re-plan;
/// [`set_next_replan`] sets both once `t_r` is known. The message is validated.
pub fn write_plan(
    out: &mut Plan,
    header: Header,
    info: &PlanInfo,
    tr: &Trajectory,
) -> Result<(), ExportError> {
    let n = tr.len();
    if n < 2 {
        return Err(ExportError::TooShort);
    }
    if tr.phase_ends.len() > MAX_PHASES || tr.phase_ends.is_empty() {
        return Err(ExportError::TooManyPhases(tr.phase_ends.len()));
    }
    // Zero the fixed part and the counts; samples past the count are never read but must
    // be finite for `validate()`: zero them too.
    out.header = header;
    out.plan_id = info.plan_id;
    out.trigger = info.trigger.to_wire();
    out.quality = info.quality.to_wire();
    out.model = info.model.to_wire();
    out.phase_count = tr.phase_ends.len() as u32;
    out.has_next_replan = 0;
    out.next_replan_s = 0.0;
    out.path = info.path.to_wire();
    out.cut_count = 0;
    out.cuts = [PlanCut { site: 0, step: 0 }; MAX_PLAN_CUTS];
    out.created_at_s = info.created_at_s;
    out.cost = info.cost;
    out.compute_ms = info.compute_ms;
    out.phase_end_s = [0.0; MAX_PHASES];
    out.phase_end_s[..tr.phase_ends.len()].copy_from_slice(&tr.phase_ends);
    let samples = &mut out.samples;
    let count = sample_times(&tr.times, &tr.phase_ends, MAX_PLAN_SAMPLES, |k, t| {
        samples[k].t_s = t;
    });
    for s in samples[..count].iter_mut() {
        let (state, control) = tr.at(s.t_s).ok_or(ExportError::TooShort)?;
        s.state = state;
        s.control = control;
    }
    for s in samples[count..].iter_mut() {
        *s = PlanSample {
            t_s: 0.0,
            state: [0.0; 7],
            control: [0.0; 2],
        };
    }
    out.sample_count = count as u32;
    out.start_time_s = samples[0].t_s;
    out.final_time_s = samples[count - 1].t_s;
    out.valid_until_s = out.final_time_s;
    // The last phase ends with the trajectory; round-off must not put it after the last
    // sample.
    if let Some(last) = out.phase_end_s[..tr.phase_ends.len()].last_mut() {
        *last = last.min(out.final_time_s);
    }
    out.validate()?;
    Ok(())
}

/// Sets the scheduled re-plan time: `valid_until` becomes `t_r` when it falls before the
/// plan's end.
pub fn set_next_replan(plan: &mut Plan, t_r: Option<f64>) {
    match t_r {
        Some(t) if t >= plan.start_time_s => {
            plan.has_next_replan = 1;
            plan.next_replan_s = t;
            plan.valid_until_s = plan.final_time_s.min(t);
        }
        _ => {
            plan.has_next_replan = 0;
            plan.next_replan_s = 0.0;
            plan.valid_until_s = plan.final_time_s;
        }
    }
}

/// Writes the plan's deadline cuts (sorted, as `CutLog::finish` gives them); the number
/// that did not fit. Then the last entry is [`TRUNCATED_CUTS`] with that number as its
/// step, and a replay of the plan refuses it.
pub fn set_cuts(plan: &mut Plan, cuts: &[Cut]) -> usize {
    let fits = cuts.len() <= MAX_PLAN_CUTS;
    let kept = if fits { cuts.len() } else { MAX_PLAN_CUTS - 1 };
    for (slot, cut) in plan.cuts.iter_mut().zip(&cuts[..kept]) {
        *slot = PlanCut {
            site: cut.site.code(),
            step: cut.step,
        };
    }
    let dropped = cuts.len() - kept;
    if !fits {
        plan.cuts[kept] = PlanCut {
            site: TRUNCATED_CUTS,
            step: dropped as u32,
        };
    }
    plan.cut_count = (kept + usize::from(!fits)) as u32;
    dropped
}

/// The site code of the last cut of a plan whose cuts did not all fit in its message.
pub const TRUNCATED_CUTS: u32 = u32::MAX;

/// The deadline cuts a plan carries, for a replay (an unknown site code is an error: the
/// plan was made by another version of the planner).
pub fn cuts_of(plan: &Plan) -> Result<Vec<Cut>, u32> {
    plan.cuts()
        .iter()
        .map(|c| {
            Site::from_code(c.site)
                .map(|site| Cut { site, step: c.step })
                .ok_or(c.site)
        })
        .collect()
}

/// State (model order, zero-padded) of a plan at time `t`, linear between samples and
/// clamped to the ends, as the tracker flies it. `None` for a plan without samples.
pub fn state_at(plan: &Plan, t: f64) -> Option<[f64; 7]> {
    let s = plan.samples();
    let (first, last) = (s.first()?, s.last()?);
    if t <= first.t_s {
        return Some(first.state);
    }
    if t >= last.t_s {
        return Some(last.state);
    }
    let k = s.partition_point(|p| p.t_s <= t) - 1;
    let (a, b) = (&s[k], &s[k + 1]);
    let f = (t - a.t_s) / (b.t_s - a.t_s);
    Some(std::array::from_fn(|i| {
        a.state[i] + f * (b.state[i] - a.state[i])
    }))
}

/// The plan's samples as trigger points, in the plan's model (the other buffer is
/// emptied). The buffers hold [`MAX_PLAN_SAMPLES`] points, reserved at start-up.
#[derive(Debug, Clone, Default)]
pub struct PlanPoints {
    pub planar: Vec<PlanPoint<2>>,
    pub spatial: Vec<PlanPoint<3>>,
}

impl PlanPoints {
    /// Buffers for a full plan.
    pub fn with_capacity() -> Self {
        PlanPoints {
            planar: Vec::with_capacity(MAX_PLAN_SAMPLES),
            spatial: Vec::with_capacity(MAX_PLAN_SAMPLES),
        }
    }

    pub fn clear(&mut self) {
        self.planar.clear();
        self.spatial.clear();
    }

    /// Fills the points from the plan's samples; velocities over the ground from the model
    /// at `speed` in the steady `wind`.
    pub fn fill(&mut self, plan: &Plan, speed: f64, wind: [f64; 3]) {
        self.clear();
        match plan.model() {
            Some(Model::TwoD) => {
                let Ok(model) = Planar::new(speed).map(|m| m.with_wind(wind)) else {
                    return;
                };
                self.planar.extend(plan.samples().iter().map(|s| {
                    PlanPoint::from_state2(&model, s.t_s, &[s.state[0], s.state[1], s.state[2]])
                }));
            }
            Some(Model::ThreeD) => {
                let Ok(model) = Spatial::new(speed).map(|m| m.with_wind(wind)) else {
                    return;
                };
                self.spatial.extend(
                    plan.samples()
                        .iter()
                        .map(|s| PlanPoint::from_state3(&model, s.t_s, &s.state)),
                );
            }
            None => {}
        }
    }
}
