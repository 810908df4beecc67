//! The start state of a plan (splicing): the tasking's start for a first plan, else the
//! state at the commit time `now + budget` — the current plan's there, or the ownship's
//! dead-reckoned to it when the plan cannot say.

use std::time::Duration;

use tracing::{error, info, warn};
use wingman_interfaces::{Model, OwnshipState, Plan, Tasking, Trigger};

use super::MessageLoop;
use crate::service::triggers::{self, TriggerSet};
use crate::service::world::Splice;
use wingman_planning::dynamics::{Limits, idx3};
use wingman_planning::plan_message as export;

/// Why a plan cannot start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum NoSplice {
    /// The plan ends before the commit time: nothing to re-plan.
    MissionOver,
    /// No state to start from (no fresh ownship state of the tasking's model where the
    /// plan cannot say).
    NoStart,
}

impl MessageLoop {
    /// Where a plan for the pending triggers `set` starts: the tasking's start for the
    /// first plan; else the commit time `now + budget` and the state the current plan
    /// predicts there (the state the tracker will be in), or the ownship's state
    /// dead-reckoned to it when the plan cannot say (a deviation or a restart among the
    /// pending triggers, whichever names the plan; a safe hold; past the plan's end; a
    /// tasking of another model). Only a fresh ownship state (mission time within
    /// `staleness.ownship_ms` of now) of the tasking's model is dead-reckoned; without one
    /// the plan's own state is used if it can be, else there is no plan for now. Targets
    /// the current plan passes before the commit time are left out.
    pub(super) fn splice(&self, set: TriggerSet, budget: Duration) -> Result<Splice, NoSplice> {
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
        // A hold the current plan answers (reported before it started) is not this plan's.
        let holding = own.is_some_and(|o| {
            o.holding()
                && plan.is_none_or(|p| triggers::holds_instead_of(o, p.plan_id, p.start_time_s))
        });
        let from_ownship = triggers::splice_from_ownship(set, holding);
        let mission_over =
            plan.is_some_and(|p| p.valid_until_s >= p.final_time_s && t_c >= p.final_time_s);
        // (A deviation there is the aircraft arriving behind the plan: a plan from it would
        // last the budget's few seconds, too short for the NLP, and a swarm's path there
        // turns the aircraft away from the end it is about to reach.)
        let ends_anyway = [
            Trigger::PopUp,
            Trigger::ScheduledReplan,
            Trigger::Refine,
            Trigger::Deviation,
        ];
        if mission_over && set.only_of(&ends_anyway) {
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
            let limits = Limits {
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
