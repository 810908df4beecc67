//! Inputs: draining the subscribers, validating each sample, updating the world model and
//! raising the event triggers (tasking and route changes, pop-ups, the ownship state a
//! waiting plan needs).

use std::time::Duration;

use tracing::{error, info, warn};
use wingman_interfaces::{
    LeadRoute, LeadState, Message, Model, Objective, OwnshipState, Tasking, ThreatReport, TrackFix,
    Trigger, ValidationError,
};
use wingman_planning::lead::LeadPath;

use super::lifecycle::FirstPlan;
use super::{MAX_CONTINUED_PLAN_ID, MessageLoop};
use crate::service::triggers::{self, PopupAssessment, RouteDecision, TaskingDecision};
use crate::service::world::{self, FixOutcome, Input, ThreatChange, ThreatSlot};

/// Input problems the loop logs once, then only counts.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Logged {
    rejections: [[bool; REJECTION_KINDS]; Input::COUNT],
    receive_errors: [bool; Input::COUNT],
    plan_id: bool,
    fix_refused: bool,
}

impl MessageLoop {
    /// Drains every input subscriber; returns the number of samples taken.
    pub(super) fn drain(&mut self) -> u64 {
        let before = self.counters.received;
        macro_rules! drain {
            ($port:ident, $input:expr, $handle:ident) => {
                loop {
                    match self.ports.$port.receive() {
                        Ok(Some(sample)) => {
                            let msg = *sample.payload();
                            drop(sample);
                            if self.admit($input, &msg) {
                                self.$handle(&msg);
                            }
                        }
                        Ok(None) => break,
                        Err(e) => {
                            let k = $input as usize;
                            if !self.logged.receive_errors[k] {
                                self.logged.receive_errors[k] = true;
                                error!(input = $input.name(), error = ?e, "receive failed");
                            }
                            break;
                        }
                    }
                }
            };
        }
        drain!(tasking, Input::Tasking, on_tasking);
        drain!(route, Input::LeadRoute, on_route);
        drain!(threats, Input::Threats, on_threat);
        drain!(tracks, Input::Tracks, on_fix);
        drain!(lead_state, Input::LeadState, on_lead_state);
        drain!(ownship, Input::Ownship, on_ownship);
        self.world.gaps.end_pass();
        self.counters.received - before
    }

    /// Counts a sample and validates it, its header against the sender's previous one on
    /// this input included; an invalid one is counted, logged once per input and kind, and
    /// changes nothing else (its sequence is not echoed).
    fn admit<M: Message>(&mut self, input: Input, msg: &M) -> bool {
        self.counters.received += 1;
        let wall = self.clock.now();
        let checked = msg
            .validate()
            .and_then(|()| self.world.accept_header(input, msg.header(), wall));
        if msg.header().validate().is_ok() {
            let live = wingman_ipc::qos(M::SERVICE).history_size == 0;
            self.world.gaps.read(msg.header(), checked.is_ok(), live);
        }
        match checked {
            Ok(()) => true,
            Err(e) => {
                self.counters.rejected += 1;
                let kind = rejection_index(&e);
                let logged = &mut self.logged.rejections[input as usize][kind];
                if !*logged {
                    *logged = true;
                    warn!(
                        input = input.name(),
                        error = %e,
                        "dropped an invalid message (further ones of this kind are only counted)"
                    );
                }
                false
            }
        }
    }

    fn on_tasking(&mut self, t: &Tasking) {
        let decision = self.world.apply_tasking(t);
        if matches!(decision, TaskingDecision::First | TaskingDecision::Changed) {
            self.content_revision = t.revision;
        }
        match decision {
            TaskingDecision::First => {
                self.first = match self.world.ownship {
                    None => {
                        let wait = Duration::from_millis(self.cfg.triggers.first_plan_wait_ms);
                        FirstPlan::WaitingForOwnship {
                            until: self.clock.now() + wait,
                        }
                    }
                    Some(_) => FirstPlan::Due,
                };
            }
            TaskingDecision::Changed if !self.has_plan && !self.lifecycle.is_planning() => {
                info!(revision = t.revision, "tasking changed before a first plan");
                self.first.make_due();
            }
            // With a plan held or in flight (the arm above takes the other cases).
            TaskingDecision::Changed => {
                info!(revision = t.revision, "tasking changed");
                self.raise(Trigger::Tasking);
            }
            // Only the start may differ (it is not compared): a waiting first plan uses it
            // at once.
            TaskingDecision::Unchanged if !self.has_plan => self.first.end_retry_wait(),
            TaskingDecision::Unchanged | TaskingDecision::Stale => {}
        }
    }

    fn on_route(&mut self, r: &LeadRoute) {
        let decision = self.world.apply_route(r);
        let rendezvous = self
            .world
            .tasking
            .as_ref()
            .is_some_and(|t| t.objective() == Some(Objective::MinTimeRendezvous));
        if decision == RouteDecision::Changed
            && rendezvous
            && (self.has_plan || self.lifecycle.is_planning())
        {
            info!(revision = r.revision, "lead route changed");
            self.raise(Trigger::LeadRoute);
        } else if matches!(decision, RouteDecision::First | RouteDecision::Changed)
            && !self.has_plan
            && !self.lifecycle.is_planning()
            && self.world.tasking.is_some()
        {
            // No plan yet (none made, or the first one failed): try with this route.
            self.first.make_due();
        }
    }

    fn on_lead_state(&mut self, s: &LeadState) {
        self.world.apply_lead_state(s);
        self.check_lead_off_route(s);
    }

    /// A rendezvous whose lead, as `s` observes it, left the route the planner holds
    /// (that revision) without a new one: the held route becomes the lead flying on as
    /// observed, and the rendezvous is re-planned (`LeadOffRoute`).
    fn check_lead_off_route(&mut self, s: &LeadState) {
        let rendezvous = self
            .world
            .tasking
            .as_ref()
            .is_some_and(|t| t.objective() == Some(Objective::MinTimeRendezvous));
        let Some(route) = self.world.route else {
            return;
        };
        let meet_at_s = self.current.final_time_s;
        // A lead still waiting for its route's start is on it (LeadPath: at rest there).
        let on_its_way = s.time_s >= route.start_time_s && s.time_s < meet_at_s;
        if !rendezvous || !self.has_plan || s.route_revision != route.revision || !on_its_way {
            return;
        }
        let Ok(path) = LeadPath::new(route.points(), route.speed_mps, route.start_time_s) else {
            return;
        };
        let off_m = triggers::lead_off_route_m(&path, s, meet_at_s);
        if off_m <= self.cfg.triggers.lead_off_route_m {
            return;
        }
        info!(
            t = s.time_s,
            off_m,
            meet_at_s,
            "the lead left its route: re-plan the rendezvous with the lead as observed"
        );
        let model = self.world.tasking.as_ref().and_then(Tasking::model);
        let observed = triggers::observed_route(s, route.revision, model.unwrap_or(Model::ThreeD));
        self.world.route = Some(observed);
        self.raise(Trigger::LeadOffRoute);
    }

    fn on_ownship(&mut self, s: &OwnshipState) {
        self.world.apply_ownship(s);
        let model = self.world.tasking.as_ref().and_then(Tasking::model);
        if s.model() == model
            && let Some(set) = self.awaiting_start.take()
        {
            info!("an ownship state to start from: the waiting plan starts");
            self.batch.add(set);
        }
        // Plan ids keep growing across a restart of the planner: before its first plan,
        // the planner continues above the id the tracker flies. Once it has a plan, the
        // ids are its own. An id too large to continue from is refused (logged once).
        if !self.has_plan && s.plan_id >= self.next_plan_id {
            if s.plan_id < MAX_CONTINUED_PLAN_ID {
                self.next_plan_id = s.plan_id + 1;
            } else if !self.logged.plan_id {
                self.logged.plan_id = true;
                error!(
                    plan_id = s.plan_id,
                    limit = MAX_CONTINUED_PLAN_ID,
                    "the ownship reports a plan id too large to continue from; ignored"
                );
            }
        }
    }

    fn on_threat(&mut self, r: &ThreatReport) {
        let wall = self.clock.now();
        let slot = match self.world.apply_threat(r, wall) {
            ThreatChange::New(s) | ThreatChange::Changed(s) => s,
            ThreatChange::Unchanged => return,
            ThreatChange::Full => {
                // Logged once; the status says `Degraded` from now on.
                if self.world.threats_dropped == 1 {
                    error!(
                        threat = r.threat_id,
                        static_capacity = world::MAX_STATIC_THREATS,
                        moving_capacity = world::MAX_MOVING_THREATS,
                        "no room for another threat: report ignored, the planner is Degraded \
                         (further ones are only counted)"
                    );
                }
                return;
            }
            ThreatChange::Refused(e) => {
                warn!(threat = r.threat_id, error = %e, "moving threat refused");
                return;
            }
        };
        if !self.has_plan {
            // No plan to assess: a plan in flight does not know it, so it is pending.
            if self.lifecycle.is_planning() {
                self.raise(Trigger::PopUp);
            }
            return;
        }
        match self.assess_popup(slot) {
            Some(PopupAssessment::Touches(hit)) => {
                info!(
                    threat = r.threat_id,
                    at_s = hit.t,
                    f = hit.f,
                    "pop-up reaches the plan: re-plan"
                );
                self.raise(Trigger::PopUp);
            }
            Some(PopupAssessment::Clear) => {
                self.counters.popups_clear += 1;
                info!(threat = r.threat_id, "pop-up clear of the plan: no re-plan");
                if let ThreatSlot::Moving(i) = slot {
                    self.schedule(i);
                }
            }
            None => warn!(threat = r.threat_id, "pop-up does not fit the plan's model"),
        }
    }

    fn on_fix(&mut self, f: &TrackFix) {
        let wall = self.clock.now();
        match self.world.apply_fix(f, wall) {
            FixOutcome::Applied(i) => {
                if self.has_plan {
                    self.schedule(i);
                }
            }
            FixOutcome::Refused(e) => {
                self.counters.fixes_refused += 1;
                if !self.logged.fix_refused {
                    self.logged.fix_refused = true;
                    warn!(
                        threat = f.threat_id,
                        error = %e,
                        "a track fix was refused by the filter (further ones are only counted)"
                    );
                }
            }
            FixOutcome::UnknownThreat => {}
        }
    }
}

/// Kinds of [`ValidationError`] ([`rejection_index`] maps each to one below this).
const REJECTION_KINDS: usize = 8;

/// Index of a validation error's kind (for logging once per kind), below
/// [`REJECTION_KINDS`]. The match is exhaustive: a new kind fails to compile here.
fn rejection_index(e: &ValidationError) -> usize {
    match e {
        ValidationError::ProtocolVersion { .. } => 0,
        ValidationError::NonFinite { .. } => 1,
        ValidationError::CountOverCapacity { .. } => 2,
        ValidationError::CountTooSmall { .. } => 3,
        ValidationError::UnknownEnum { .. } => 4,
        ValidationError::TimeBackwards { .. } => 5,
        ValidationError::OutOfRange { .. } => 6,
        ValidationError::SequenceNotIncreasing { .. } => 7,
    }
}
