//! Deciding and starting a plan: the first plan's trigger, the event triggers' batch, the
//! time triggers over the current plan (scheduled `t_r`, expiry, deviation), the pop-up
//! test, folding the triggers into the [lifecycle](super::lifecycle::PlanLifecycle), the
//! compute gate, the commit time and the request to the solve thread.

use tracing::{error, info, warn};
use wingman_interfaces::{Model, Objective, Trigger};

use super::MessageLoop;
use super::lifecycle::{FirstPlan, PlanLifecycle};
use super::splice::NoSplice;
use crate::service::solver::{SolveRequest, Ticket};
use crate::service::triggers::{self, DeviationBounds, PlanWindow, PopupAssessment, TriggerSet};
use crate::service::world::{self, ThreatSlot};

/// The longest ownship step the time triggers' lead takes in, s (a stalled ownship feed
/// must not make every plan expire at once).
const MAX_TIME_STEP_S: f64 = 1.0;

/// Triggers raised in one pass, before `evaluate` folds them into the lifecycle.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Batch {
    set: TriggerSet,
    /// How many raises (a trigger raised twice counts twice as coalesced).
    count: u64,
}

impl Batch {
    /// Adds the triggers of one raise.
    pub(super) fn add(&mut self, set: TriggerSet) {
        self.set = self.set.union(set);
        self.count += 1;
    }

    fn is_empty(&self) -> bool {
        self.set.is_empty()
    }
}

/// The plan id each time trigger last fired for: each fires once per plan.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct FiredFor {
    deviation: u64,
    /// Mission time from which a deviation from the plan `deviation` may re-plan again:
    /// its re-plan was dropped ([`triggers::deviation_plan`]). Never otherwise.
    deviation_retry_s: Option<f64>,
    expiry: u64,
    scheduled: u64,
}

impl FiredFor {
    /// The deviation from the plan in flight may re-plan again from mission time `at`.
    pub(super) fn retry_deviation_at(&mut self, at: f64) {
        self.deviation_retry_s = Some(at);
    }
}

impl MessageLoop {
    /// A first plan is due: the tasking (and a rendezvous's route) is here and no failed
    /// first plan waits for its retry. It starts at the next pass once no longer
    /// [waiting for an ownship state](Self::waiting_for_ownship).
    pub(super) fn first_plan_due(&self) -> bool {
        let Some(t) = &self.world.tasking else {
            return false;
        };
        let needs_route = t.objective() == Some(Objective::MinTimeRendezvous);
        self.first.awaited()
            && self.first.retry_passed(self.clock.now())
            && (!needs_route || self.world.route.is_some())
    }

    /// A first plan waits for an ownship state ([`FirstPlan::WaitingForOwnship`], none
    /// here yet and the wait not over).
    pub(super) fn waiting_for_ownship(&self) -> bool {
        self.world.ownship.is_none()
            && self
                .first
                .ownship_wait_until()
                .is_some_and(|at| self.clock.now() < at)
    }

    /// Raises a trigger: into this pass's batch.
    pub(super) fn raise(&mut self, t: Trigger) {
        let mut set = TriggerSet::EMPTY;
        set.insert(t);
        self.batch.add(set);
    }

    /// Pop-up test of one threat against the plan from now on.
    pub(super) fn assess_popup(&self, slot: ThreatSlot) -> Option<PopupAssessment> {
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

    /// The known static threats the current plan enters (F below `f_star` at one of its
    /// samples from now on), by slot.
    pub(super) fn static_threats_entered(&self) -> [bool; world::MAX_STATIC_THREATS] {
        let mut entered = [false; world::MAX_STATIC_THREATS];
        for (i, e) in entered.iter_mut().enumerate() {
            *e = self.world.static_threat(i).is_some()
                && self
                    .assess_popup(ThreatSlot::Static(i))
                    .is_some_and(|a| a.touches());
        }
        entered
    }

    /// Recomputes `t_r` of moving threat `i` over the current plan.
    pub(super) fn schedule(&mut self, i: usize) {
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

    /// Time triggers, folding the batch into the pending set, and starting a plan.
    /// Returns whether anything changed.
    pub(super) fn evaluate(&mut self) -> bool {
        let now = self.world.now_s();
        // The time triggers re-plan the plan in flight: so far ahead they fire, and one
        // ownship report earlier (the planner sees time pass in those steps: fired at the
        // first report within one budget of `t_r`, a plan committed up to a step after
        // it, and the tracker held in between).
        let lead = self.budget(TriggerSet::EMPTY).as_secs_f64()
            + self.world.ownship_step_s().min(MAX_TIME_STEP_S);
        if self.first_plan_due()
            && !self.waiting_for_ownship()
            && let Some(t) = &self.world.tasking
        {
            let trigger = triggers::first_plan_trigger(t, self.world.ownship.as_ref());
            self.first = FirstPlan::NotDue;
            self.raise(trigger);
        }
        // A refinement waiting for the gate does not hold the time triggers back: they join
        // it (and their plan takes their budget and their splice).
        let pending = self.lifecycle.pending();
        let quiet =
            !self.lifecycle.is_planning() && (pending.is_empty() || triggers::refine_only(pending));
        if self.has_plan && quiet && self.batch.is_empty() {
            self.time_triggers(now, lead);
        }
        let mut changed = false;
        if self.batch.count > 0 {
            let busy = self.lifecycle.is_planning() || !self.lifecycle.pending().is_empty();
            self.counters.coalesced += if busy {
                self.batch.count
            } else {
                self.batch.count - 1
            };
            let at = if now.is_finite() { now } else { 0.0 };
            self.lifecycle.fold(self.batch.set, at);
            self.batch = Batch::default();
            changed = true;
        }
        if !self.lifecycle.is_planning() && !self.lifecycle.pending().is_empty() {
            changed |= self.try_start();
        }
        changed
    }

    /// The time triggers of the current plan at mission time `now`, `lead` seconds (a
    /// plan's budget) ahead: its scheduled re-plan, its expiry, a deviation from it.
    fn time_triggers(&mut self, now: f64, lead: f64) {
        let id = self.current.plan_id;
        // The plan promised its re-plan time (its `valid_until`): newer estimates may
        // bring it forward, never push it back.
        let promised = (self.fired.scheduled != id)
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
            self.fired.scheduled = id;
            self.raise(Trigger::ScheduledReplan);
        }
        let holding = self
            .world
            .ownship
            .as_ref()
            .is_some_and(|o| triggers::holds_instead_of(o, id, self.current.start_time_s));
        let window = PlanWindow {
            start_s: self.current.start_time_s,
            valid_until_s: self.current.valid_until_s,
            final_time_s: self.current.final_time_s,
        };
        // A plan cut short by its scheduled re-plan expires only if that re-plan has
        // fired and brought no successor (the schedule is then cleared).
        if self.fired.expiry != id
            && (scheduled.is_none() || holding)
            && self.batch.is_empty()
            && triggers::expiry_due(now, &window, lead, holding)
        {
            self.fired.expiry = id;
            info!(holding, "plan expires");
            self.raise(Trigger::Expiry);
        }
        let fixed_time = self
            .world
            .tasking
            .as_ref()
            .is_none_or(|t| t.objective() == Some(Objective::FixedTime));
        let bounds = DeviationBounds::at(
            &self.cfg.triggers,
            fixed_time,
            now,
            self.current.final_time_s,
        );
        let retry = self.fired.deviation_retry_s.is_some_and(|at| now >= at);
        if (self.fired.deviation != id || retry)
            && let Some(o) = &self.world.ownship
            && triggers::deviation_exceeded(o, id, &bounds)
        {
            self.fired.deviation = id;
            self.fired.deviation_retry_s = None;
            info!(
                cross_m = o.cross_track_m,
                vertical_m = o.vertical_m,
                along_m = o.along_track_m,
                "deviation from the plan"
            );
            self.raise(Trigger::Deviation);
        }
    }

    /// Starts the pending plan if the gate admits it, else defers it.
    fn try_start(&mut self) -> bool {
        let pending = match self.lifecycle {
            PlanLifecycle::Triggered(p) | PlanLifecycle::Deferred { pending: p, .. } => p,
            PlanLifecycle::Idle | PlanLifecycle::Planning { .. } => return false,
        };
        let budget = self.budget(pending.set);
        let wall = self.clock.now();
        if !self.gate.admits(wall, budget) {
            if self.lifecycle.defer(self.gate.earliest_start(wall, budget)) {
                self.counters.deferred += 1;
            }
            return false;
        }
        let set = pending.set;
        let Some(trigger) = set.primary() else {
            return false;
        };
        let created_at_s = pending.created_at_s;
        self.lifecycle = PlanLifecycle::Idle;
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
        let filled = self.world.fill_problem(&splice, &mut problem);
        if self.cfg.solver.still_air {
            problem.wind = [0.0; 3];
        }
        match filled {
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
            triggers: set,
            created_at_s,
            budget,
            epoch: self.world.epoch,
            targets_from: splice.targets_from,
            tasking_revision: tasking.revision,
            // The solve thread starts from the plan in flight if it made it and the
            // problem continues its tasking.
            warm_from: self.replans_in_flight(set).then_some(self.current.plan_id),
        };
        match self.solver.submit(SolveRequest { problem, ticket }) {
            Ok(()) => {
                self.gate.begin(wall);
                self.lifecycle = PlanLifecycle::Planning {
                    ticket,
                    follow_up: Default::default(),
                };
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
}
