//! The status: `PlannerStatus` as a publication would send it now, and its publication
//! (after a pass that changed anything, and at each heartbeat).

use tracing::error;
use wingman_interfaces::{Header, PlannerState, PlannerStatus, SENDER_PLANNER, Wire};

use super::MessageLoop;

impl MessageLoop {
    /// The last status published.
    pub fn status(&self) -> &PlannerStatus {
        &self.last_status
    }

    /// Publishes the status and notifies `wake/harness`. (iceoryx2 0.10 allocates a small
    /// shared-state `Arc` for every loaned sample, freed when it is sent: the one
    /// allocation of a pass that is not ours.)
    pub fn publish_status(&mut self) {
        let s = self.status_message();
        match self.ports.status.loan_uninit() {
            Ok(sample) => {
                if let Err(e) = sample.write_payload(s).send() {
                    error!(error = ?e, "cannot send the status");
                }
            }
            Err(e) => error!(error = ?e, "cannot loan a status sample"),
        }
        self.status_sequence += 1;
        self.last_status = s;
        let _ = self.ports.harness.notify();
    }

    /// The status a publication would send now.
    pub fn status_message(&self) -> PlannerStatus {
        let wall = self.clock.now();
        let stale = self.world.stale_bits(wall, &self.cfg.staleness);
        // `Planning` also while a triggered plan waits for the compute gate, or a first
        // plan is due (waiting for an ownship state, or about to start at the next pass
        // once that wait is over): a lock-step harness then waits for it as for a plan in
        // flight.
        let state = if self.lifecycle.is_planning()
            || !self.lifecycle.pending().is_empty()
            || self.waiting_for_ownship()
            || self.first_plan_due()
        {
            PlannerState::Planning
        } else if stale != 0
            || (self.world.tasking.is_some() && !self.has_plan)
            || self.world.threats_dropped > 0
        {
            PlannerState::Degraded
        } else {
            PlannerState::Idle
        };
        let mut s = PlannerStatus::zeroed();
        s.header = Header::new(
            SENDER_PLANNER,
            self.status_sequence + 1,
            self.world.now_ns.max(0),
        );
        s.state = state.to_wire();
        s.stale_inputs = stale;
        s.last_input_sequence = self.world.max_sequence;
        s.current_plan_id = if self.has_plan {
            self.current.plan_id
        } else {
            0
        };
        s.messages_received = self.counters.received;
        s.messages_rejected = self.counters.rejected;
        s.messages_lost = self.world.gaps.lost;
        s.plans_made = self.counters.plans;
        s.triggers_coalesced = self.counters.coalesced;
        s.triggers_deferred = self.counters.deferred;
        s.popups_clear = self.counters.popups_clear;
        s.last_plan_compute_ms = self.counters.last_compute_ms;
        s.budget_remaining_ms = self.gate.remaining(wall).as_secs_f64() * 1e3;
        s
    }
}
