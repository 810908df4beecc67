use crate::message::{Message, validate_common};
use crate::validate::{self, Checked};
use crate::{Header, PlannerState, Service, wire_struct};

/// `PlannerStatus::stale_inputs` bit: no tasking yet, or the tasking service went quiet.
pub const STALE_TASKING: u32 = 1;
/// Bit: lead state/route not received within the staleness bound.
pub const STALE_LEAD: u32 = 2;
/// Bit: ownship state not received within the staleness bound.
pub const STALE_OWNSHIP: u32 = 4;
/// Bit: a known moving threat's track fixes stopped arriving.
pub const STALE_TRACKS: u32 = 8;

wire_struct! {
    /// The planner's heartbeat (periodic and after every change).
    #[type_name("wingman::PlannerStatus")]
    pub struct PlannerStatus {
        /// Common header.
        pub header: Header ["-"],
        /// `PlannerState` value.
        pub state: u32 ["enum"],
        /// Bits `STALE_*` of inputs that stopped arriving.
        pub stale_inputs: u32 ["bits"],
        /// Highest header `sequence` of an accepted input message, over all input services
        /// (a rejected message's is not echoed; a lock-step client waits for it).
        pub last_input_sequence: u64 ["-"],
        /// `plan_id` of the newest published plan (0: none).
        pub current_plan_id: u64 ["-"],
        /// Messages taken from every input service.
        pub messages_received: u64 ["-"],
        /// Messages rejected and dropped: failed `validate()`, or a header that does not
        /// follow the sender's previous one on its service.
        pub messages_rejected: u64 ["-"],
        /// Messages lost before the planner read them (a subscriber buffer overflowed):
        /// the gaps in each sender's `sequence`, counted one pass after a later one is read.
        pub messages_lost: u64 ["-"],
        /// Plans published.
        pub plans_made: u64 ["-"],
        /// Triggers folded into a plan already pending.
        pub triggers_coalesced: u64 ["-"],
        /// Triggers held back by the minimum spacing or the duty-cycle cap.
        pub triggers_deferred: u64 ["-"],
        /// Pop-ups assessed as clear of the plan (no re-plan).
        pub popups_clear: u64 ["-"],
        /// Compute time of the newest plan.
        pub last_plan_compute_ms: f64 ["ms"],
        /// Compute time left in the duty-cycle window.
        pub budget_remaining_ms: f64 ["ms"],
    }
}

impl PlannerStatus {
    /// The planner state, if the field holds a known value.
    pub fn state(&self) -> Option<PlannerState> {
        PlannerState::from_wire(self.state)
    }
}

impl Message for PlannerStatus {
    const SERVICE: Service = Service::Status;

    fn header(&self) -> &Header {
        &self.header
    }

    fn validate(&self) -> Checked {
        validate_common(self)?;
        validate::enum_value("state", self.state, PlannerState::from_wire)?;
        let known = STALE_TASKING | STALE_LEAD | STALE_OWNSHIP | STALE_TRACKS;
        if self.stale_inputs & !known != 0 {
            return Err(crate::ValidationError::UnknownEnum {
                field: "stale_inputs",
                value: self.stale_inputs,
            });
        }
        validate::non_negative("last_plan_compute_ms", self.last_plan_compute_ms)?;
        validate::non_negative("budget_remaining_ms", self.budget_remaining_ms)
    }
}
