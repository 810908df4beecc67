use crate::message::{Message, validate_common};
use crate::validate::{self, Checked};
use crate::{Header, Service, wire_struct};

wire_struct! {
    /// One measured position of a moving threat from the onboard sensor.
    #[type_name("wingman::TrackFix")]
    pub struct TrackFix {
        /// Common header.
        pub header: Header ["-"],
        /// `threat_id` of the moving threat's `ThreatReport`.
        pub threat_id: u32 ["-"],
        /// Zero; keeps the next field 8-byte aligned.
        pub reserved: u32 ["-"],
        /// Mission time of the measurement.
        pub time_s: f64 ["s"],
        /// Measured position `[x, y, z]` (z = 0 in 2-D).
        pub position_m: [f64; 3] ["m"],
        /// Standard deviation of the measurement along each axis.
        pub sigma_m: f64 ["m"],
    }
}

impl Message for TrackFix {
    const SERVICE: Service = Service::Tracks;

    fn header(&self) -> &Header {
        &self.header
    }

    fn validate(&self) -> Checked {
        validate_common(self)?;
        validate::positive("sigma_m", self.sigma_m)
    }
}
