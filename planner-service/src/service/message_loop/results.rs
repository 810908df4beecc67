//! Taking a finished plan: publishing it and making it current (its moving threats'
//! scheduled re-plans, the ids and sequences), or after a failed first plan scheduling
//! the retry; then checking the threats reported while it was computed against it.

use tracing::{error, info, warn};
use wingman_interfaces::{Header, SENDER_PLANNER, Trigger};

use super::lifecycle::{FirstPlan, PlanLifecycle};
use super::{FIRST_PLAN_RETRY, MessageLoop};
use crate::service::solver::{SolveResult, Ticket};
use crate::service::triggers::{self, DeviationPlan};
use crate::service::world::{self, ThreatSlot};
use wingman_planning::cuts::Cut;
use wingman_planning::hybrid::PlanOutcome;
use wingman_planning::plan_message::{self as export, PlanInfo};

impl MessageLoop {
    /// Takes the solve thread's result: the plan computed is done (its follow-up, if any,
    /// is triggered).
    pub(super) fn on_result(&mut self, result: SolveResult) {
        let SolveResult {
            problem,
            ticket,
            outcome,
            started,
            finished,
            core_time,
            cuts,
        } = result;
        self.lifecycle.plan_done();
        self.problem = Some(problem);
        self.gate.record(started, finished, core_time);
        let compute_ms = finished.saturating_sub(started).as_secs_f64() * 1e3;
        self.counters.last_compute_ms = compute_ms;
        match outcome {
            Ok(o) => self.accept(&o, &ticket, compute_ms, &cuts),
            Err(e) => {
                warn!(trigger = ticket.trigger.name(), error = %e, "no plan made");
                // Without a plan the status says `Degraded`; the first plan is tried again
                // (the compute gate spaces the attempts), and a new tasking or route is
                // taken into the next attempt.
                if !self.has_plan {
                    self.first = FirstPlan::RetryAfterFailure {
                        at: self.clock.now() + FIRST_PLAN_RETRY,
                    };
                }
            }
        }
        // Threats that changed while the plan was computed are not in it: check each
        // against the plan now current (a pop-up clear of the old plan may lie on the new
        // one). Pending pop-ups that the new plan already avoids need no follow-up.
        if self.has_plan && self.world.epoch > ticket.epoch {
            let touch = self.popups_touch(ticket.epoch);
            let pending = self.lifecycle.pending();
            if pending.only_popups() && !touch {
                info!("pop-ups during the plan are clear of it: no follow-up");
                self.lifecycle = PlanLifecycle::Idle;
            } else if touch && pending.is_empty() {
                info!("a threat reported during the plan reaches it: re-plan");
                self.raise(Trigger::PopUp);
            }
        }
    }

    /// Whether any threat changed after `epoch` reaches the current plan.
    fn popups_touch(&self, epoch: u64) -> bool {
        let mut touches = false;
        for i in 0..world::MAX_STATIC_THREATS {
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

    /// Publishes a plan made by the solver and makes it current, unless the plan in flight
    /// is better kept ([`triggers::deviation_plan`]).
    fn accept(&mut self, o: &PlanOutcome, ticket: &Ticket, compute_ms: f64, cuts: &[Cut]) {
        // The model, speed and wind of the problem planned (the tasking may have changed
        // since).
        let Some((model, speed, wind)) = self
            .problem
            .as_ref()
            .map(|p| (p.model, p.limits.speed, p.wind))
        else {
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
            path: o.path,
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
        let dropped = export::set_cuts(&mut self.scratch, cuts);
        if dropped > 0 {
            warn!(
                dropped,
                "the plan's deadline cuts do not all fit in the message: a replay cannot \
                 take its course"
            );
        }
        let enters_new = self.new_plan_enters_new_threat(speed, wind);
        if self.keeps_plan_in_flight(o, ticket, enters_new) {
            self.points.fill(&self.current, speed, wind);
            return;
        }
        // Scheduled re-plans of the moving threats over the new plan.
        std::mem::swap(&mut self.current, &mut self.scratch);
        self.has_plan = true;
        let slots: [Option<usize>; world::MAX_MOVING_THREATS] = {
            let mut s = [None; world::MAX_MOVING_THREATS];
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
        // A plan that enters a known static threat the plan before it kept clear of: the
        // refinement's global search has the time to look around it.
        if triggers::refine_due(
            self.cfg.triggers.refine,
            o.quality,
            ticket.trigger,
            enters_new,
        ) {
            info!(
                quality = o.quality.name(),
                enters_new_threat = enters_new,
                "plan short of optimal or into a threat the plan before avoided: refine it"
            );
            self.raise(Trigger::Refine);
        }
    }

    /// Whether the plan written into `scratch` enters a known static threat the plan in
    /// flight kept clear of: a re-plan whose short budget left it in a basin across the
    /// threat (the plan in flight dragged across it by a new rendezvous or a deviation, or
    /// pressed into it by a moving threat). Leaves the plan points on the new plan.
    fn new_plan_enters_new_threat(&mut self, speed: f64, wind: [f64; 3]) -> bool {
        let before = self.has_plan.then(|| self.static_threats_entered());
        self.points.fill(&self.scratch, speed, wind);
        before.is_some_and(|before| {
            let now = self.static_threats_entered();
            now.iter()
                .zip(&before)
                .any(|(now, before)| *now && !*before)
        })
    }

    /// Whether the plan `o` made for `ticket` is dropped and the plan in flight kept
    /// ([`triggers::deviation_plan`]); if so the deviation is refined at once or may
    /// re-plan again later.
    fn keeps_plan_in_flight(&mut self, o: &PlanOutcome, ticket: &Ticket, enters_new: bool) -> bool {
        let now = self.world.now_s();
        if !(self.has_plan && self.current.valid_until_s > now) {
            return false;
        }
        let then = triggers::deviation_plan(ticket.triggers, o.quality, enters_new);
        if then == DeviationPlan::Publish {
            return false;
        }
        info!(
            plan_id = self.current.plan_id,
            quality = o.quality.name(),
            cost = o.cost,
            enters_new_threat = enters_new,
            then = ?then,
            "the deviation re-plan did not converge or enters a threat the plan in flight \
             avoids: the plan in flight is kept"
        );
        match then {
            DeviationPlan::KeepAndRefine => {
                self.raise(Trigger::Deviation);
                self.raise(Trigger::Refine);
            }
            _ => self
                .fired
                .retry_deviation_at(now + triggers::DEVIATION_RETRY_S),
        }
        true
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
}
