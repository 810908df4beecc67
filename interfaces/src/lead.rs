use crate::message::{Message, validate_common};
use crate::validate::{self, Checked};
use crate::{Header, MAX_ROUTE_POINTS, Service, wire_struct};

wire_struct! {
    /// The lead's state from the datalink (periodic).
    #[type_name("wingman::LeadState")]
    pub struct LeadState {
        /// Common header.
        pub header: Header ["-"],
        /// Mission time of the state.
        pub time_s: f64 ["s"],
        /// Position `[x, y, z]` (z = 0 in 2-D).
        pub position_m: [f64; 3] ["m"],
        /// Heading chi (psi in 2-D), counter-clockwise from +x.
        pub heading_rad: f64 ["rad"],
        /// Flight-path angle gamma (0 in 2-D).
        pub gamma_rad: f64 ["rad"],
        /// Ground speed of the lead.
        pub speed_mps: f64 ["m/s"],
        /// `revision` of the `LeadRoute` the lead is flying.
        pub route_revision: u32 ["-"],
        /// Zero; keeps the next field 8-byte aligned.
        pub reserved: u32 ["-"],
    }
}

impl Message for LeadState {
    const SERVICE: Service = Service::LeadState;

    fn header(&self) -> &Header {
        &self.header
    }

    fn validate(&self) -> Checked {
        validate_common(self)?;
        validate::positive("speed_mps", self.speed_mps)
    }
}

wire_struct! {
    /// The lead's route: it flies the polyline at constant speed, at the first point at
    /// `start_time_s`, and keeps its last heading past the last point. Re-sent whenever it
    /// changes, with a larger `revision`.
    #[type_name("wingman::LeadRoute")]
    pub struct LeadRoute {
        /// Common header.
        pub header: Header ["-"],
        /// Grows with every change of route; starts at 1.
        pub revision: u32 ["-"],
        /// Number of valid entries in `points_m` (2 or more).
        pub point_count: u32 ["-"],
        /// Mission time at which the lead is at `points_m[0]`.
        pub start_time_s: f64 ["s"],
        /// Constant speed along the route.
        pub speed_mps: f64 ["m/s"],
        /// Route polyline `[x, y, z]` (z = 0 in 2-D); `point_count` valid.
        pub points_m: [[f64; 3]; MAX_ROUTE_POINTS] ["m"],
    }
}

impl LeadRoute {
    /// The valid points (empty if `point_count` is over capacity).
    pub fn points(&self) -> &[[f64; 3]] {
        self.points_m
            .get(..self.point_count as usize)
            .unwrap_or(&[])
    }
}

impl Message for LeadRoute {
    const SERVICE: Service = Service::LeadRoute;

    fn header(&self) -> &Header {
        &self.header
    }

    fn validate(&self) -> Checked {
        validate_common(self)?;
        let n = validate::count("point_count", self.point_count, 2, MAX_ROUTE_POINTS)?;
        validate::positive("speed_mps", self.speed_mps)?;
        validate::polyline("points_m", &self.points_m[..n])
    }
}
