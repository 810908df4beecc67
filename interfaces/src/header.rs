use crate::validate::{self, Checked, ValidationError};
use crate::wire_struct;

wire_struct! {
    /// Starts every message. A sender's `sequence` grows by one per message it publishes,
    /// one counter across all its services, so that the planner's status can echo the last
    /// input it accepted. On each input service the planner accepts a message only if its
    /// `sequence` is greater than the one of the sender's previous accepted message there
    /// and its `mission_time_ns` (the sender's mission clock when it published) not
    /// smaller: a repeat or a step back is rejected.
    #[type_name("wingman::Header")]
    pub struct Header {
        /// `PROTOCOL_VERSION` of the sender.
        pub protocol_version: u32 ["-"],
        /// Who sent it: 1 planner, 2 harness, other values for test tools.
        pub sender_id: u32 ["-"],
        /// The sender's message counter, one across all its services, starting at 1.
        pub sequence: u64 ["-"],
        /// Mission time at publication.
        pub mission_time_ns: i64 ["ns"],
    }
}

impl Header {
    /// A header of this protocol version.
    pub const fn new(sender_id: u32, sequence: u64, mission_time_ns: i64) -> Self {
        Header {
            protocol_version: crate::PROTOCOL_VERSION,
            sender_id,
            sequence,
            mission_time_ns,
        }
    }

    /// Mission time in seconds.
    pub fn mission_time_s(&self) -> f64 {
        self.mission_time_ns as f64 * 1e-9
    }

    /// Protocol version check (first thing every `validate()` does).
    pub fn validate(&self) -> Checked {
        validate::protocol(self.protocol_version)
    }

    /// Checks that this header may follow `previous` from the same sender on the same
    /// service: the sequence must grow and the mission clock must not go backwards.
    pub fn check_follows(&self, previous: &Header) -> Checked {
        if self.sequence <= previous.sequence {
            return Err(ValidationError::SequenceNotIncreasing {
                previous: previous.sequence,
                found: self.sequence,
            });
        }
        if self.mission_time_ns < previous.mission_time_ns {
            return Err(ValidationError::TimeBackwards {
                field: "header.mission_time_ns",
            });
        }
        Ok(())
    }
}
