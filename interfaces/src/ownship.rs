use crate::message::{Message, validate_common};
use crate::validate::{self, Checked};
use crate::{CONTROL_DIM, Header, Model, STATE_DIM, Service, wire_struct};

/// `OwnshipState::flags` bit: the tracker flies a safe hold (no valid plan).
pub const OWNSHIP_HOLDING: u32 = 1;

wire_struct! {
    /// The wingman's state from the inner-loop tracker (periodic).
    #[type_name("wingman::OwnshipState")]
    pub struct OwnshipState {
        /// Common header.
        pub header: Header ["-"],
        /// Mission time of the state.
        pub time_s: f64 ["s"],
        /// `Model` value (2 or 3).
        pub model: u32 ["enum"],
        /// Bit 0 (`OWNSHIP_HOLDING`): flying a safe hold. Other bits are zero.
        pub flags: u32 ["bits"],
        /// `plan_id` of the plan being flown (0: none).
        pub plan_id: u64 ["-"],
        /// Full state (model order, zero-padded).
        pub state: [f64; STATE_DIM] ["m, rad, g"],
        /// Control applied (model order, zero-padded).
        pub control: [f64; CONTROL_DIM] ["rad/s, 1/s"],
        /// Signed distance from the plan across its track (positive left).
        pub cross_track_m: f64 ["m"],
        /// Signed distance from the plan's point at `time_s` along its track (positive ahead).
        pub along_track_m: f64 ["m"],
        /// Height above the plan's point at `time_s` (0 in 2-D).
        pub vertical_m: f64 ["m"],
    }
}

impl OwnshipState {
    /// The vehicle model, if the field holds a known value.
    pub fn model(&self) -> Option<Model> {
        Model::from_wire(self.model)
    }

    /// Whether the tracker flies a safe hold.
    pub fn holding(&self) -> bool {
        self.flags & OWNSHIP_HOLDING != 0
    }
}

impl Message for OwnshipState {
    const SERVICE: Service = Service::Ownship;

    fn header(&self) -> &Header {
        &self.header
    }

    fn validate(&self) -> Checked {
        validate_common(self)?;
        validate::enum_value("model", self.model, Model::from_wire)?;
        if self.flags & !OWNSHIP_HOLDING != 0 {
            return Err(crate::ValidationError::UnknownEnum {
                field: "flags",
                value: self.flags,
            });
        }
        Ok(())
    }
}
