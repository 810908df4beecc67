use crate::message::{Message, validate_common};
use crate::validate::{self, Checked, ValidationError};
use crate::{Header, MAX_ROAD_POINTS, Service, THREAT_NAME_LEN, ThreatKind, wire_struct};

wire_struct! {
    /// A threat from the onboard sensor: a static superquadric (FORMULATION.md §3) or a
    /// threat moving along a known road (§5) with the estimate of its distance along the
    /// road. Sent when the threat becomes known; the latest report per `threat_id` wins.
    #[type_name("wingman::ThreatReport")]
    pub struct ThreatReport {
        /// Common header.
        pub header: Header ["-"],
        /// Unique per threat for the whole mission, never 0.
        pub threat_id: u32 ["-"],
        /// `ThreatKind` value.
        pub kind: u32 ["enum"],
        /// Mission time at which the threat became known (0 or less: before take-off).
        pub appeared_at_s: f64 ["s"],
        /// Name for people: UTF-8, NUL-padded.
        pub name: [u8; THREAT_NAME_LEN] ["-"],
        /// Static: centre `[x, y, z]` (z = 0 in 2-D). Moving: unused (zeros).
        pub center_m: [f64; 3] ["m"],
        /// Static: semi-axes. Moving: keep-out semi-axes when the position is certain
        /// (along the road, across, up). 2-D: the third is unused (zero).
        pub axes_m: [f64; 3] ["m"],
        /// Static: exponents per axis (2 for an ellipsoid). Moving: unused (zeros).
        pub exponents: [f64; 3] ["-"],
        /// Static: yaw of the threat's x-axis, counter-clockwise from +x.
        pub yaw_rad: f64 ["rad"],
        /// Moving: number of valid entries in `road_m` (2 or more). Static: 0.
        pub road_point_count: u32 ["-"],
        /// Zero; keeps the next field 8-byte aligned.
        pub reserved: u32 ["-"],
        /// Moving: road polyline `[x, y, z]`; `road_point_count` valid.
        pub road_m: [[f64; 3]; MAX_ROAD_POINTS] ["m"],
        /// Moving: mission time of the estimate below.
        pub estimate_time_s: f64 ["s"],
        /// Moving: estimated `[d, v, a]` along the road.
        pub estimate_mean: [f64; 3] ["m, m/s, m/s^2"],
        /// Moving: covariance of the estimate, row-major 3 x 3, symmetric.
        pub estimate_covariance: [f64; 9] ["m^2, ..."],
        /// Moving: standard deviation of the Gauss–Markov acceleration.
        pub accel_sigma_mps2: f64 ["m/s^2"],
        /// Moving: correlation time tau of the acceleration.
        pub accel_tau_s: f64 ["s"],
    }
}

/// Writes `name` into a wire name field, truncated at a character boundary to fit.
pub fn threat_name(name: &str) -> [u8; THREAT_NAME_LEN] {
    let mut out = [0u8; THREAT_NAME_LEN];
    let mut end = name.len().min(THREAT_NAME_LEN);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    out[..end].copy_from_slice(&name.as_bytes()[..end]);
    out
}

impl ThreatReport {
    /// The threat kind, if the field holds a known value.
    pub fn kind(&self) -> Option<ThreatKind> {
        ThreatKind::from_wire(self.kind)
    }

    /// The name up to its first NUL (lossy for invalid UTF-8).
    pub fn name(&self) -> String {
        let end = self
            .name
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(self.name.len());
        String::from_utf8_lossy(&self.name[..end]).into_owned()
    }

    /// The valid road points (empty if the count is over capacity).
    pub fn road(&self) -> &[[f64; 3]] {
        self.road_m
            .get(..self.road_point_count as usize)
            .unwrap_or(&[])
    }

    /// Covariance entry `(i, j)`.
    pub fn covariance(&self, i: usize, j: usize) -> f64 {
        self.estimate_covariance[3 * i + j]
    }
}

impl Message for ThreatReport {
    const SERVICE: Service = Service::Threats;

    fn header(&self) -> &Header {
        &self.header
    }

    fn validate(&self) -> Checked {
        validate_common(self)?;
        let kind = validate::enum_value("kind", self.kind, ThreatKind::from_wire)?;
        if self.threat_id == 0 {
            return Err(ValidationError::OutOfRange {
                field: "threat_id",
                problem: "0 is reserved",
            });
        }
        // The first two axes always matter; the third only in 3-D, where it is positive.
        validate::positive("axes_m", self.axes_m[0])?;
        validate::positive("axes_m", self.axes_m[1])?;
        validate::non_negative("axes_m", self.axes_m[2])?;
        match kind {
            ThreatKind::Static => {
                for (k, e) in self.exponents.iter().enumerate() {
                    if k < 2 || self.axes_m[2] > 0.0 {
                        validate::positive("exponents", *e)?;
                    }
                }
                validate::count("road_point_count", self.road_point_count, 0, 0)?;
            }
            ThreatKind::Moving => {
                let n = validate::count(
                    "road_point_count",
                    self.road_point_count,
                    2,
                    MAX_ROAD_POINTS,
                )?;
                validate::polyline("road_m", &self.road_m[..n])?;
                validate::positive("accel_tau_s", self.accel_tau_s)?;
                validate::non_negative("accel_sigma_mps2", self.accel_sigma_mps2)?;
                for i in 0..3 {
                    validate::non_negative("estimate_covariance", self.covariance(i, i))?;
                    for j in 0..i {
                        let (a, b) = (self.covariance(i, j), self.covariance(j, i));
                        if (a - b).abs() > 1e-9 * (1.0 + a.abs().max(b.abs())) {
                            return Err(ValidationError::OutOfRange {
                                field: "estimate_covariance",
                                problem: "must be symmetric",
                            });
                        }
                    }
                }
            }
        }
        Ok(())
    }
}
