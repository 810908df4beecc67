use crate::message::{Message, validate_common};
use crate::validate::{self, Checked, ValidationError};
use crate::{Header, MAX_TARGETS, Model, Objective, STATE_DIM, Service, wire_struct};

wire_struct! {
    /// Limits of the vehicle (FORMULATION.md §2). 2-D uses `speed_mps` and
    /// `turn_rate_max_rps`; 3-D uses the others.
    #[type_name("wingman::VehicleLimits")]
    pub struct VehicleLimits {
        /// Constant airspeed V.
        pub speed_mps: f64 ["m/s"],
        /// 2-D: bound on |u| = |psi'|.
        pub turn_rate_max_rps: f64 ["rad/s"],
        /// 3-D: bound on |gamma|.
        pub gamma_max_rad: f64 ["rad"],
        /// 3-D: lower bound on the load factor Nz.
        pub nz_min: f64 ["g"],
        /// 3-D: upper bound on Nz.
        pub nz_max: f64 ["g"],
        /// 3-D: bound on |mu|.
        pub bank_max_rad: f64 ["rad"],
        /// 3-D: bound on |u1| = |Nz'|.
        pub nz_rate_max_per_s: f64 ["1/s"],
        /// 3-D: bound on |u2| = |mu'|.
        pub bank_rate_max_rps: f64 ["rad/s"],
        /// 3-D: lowest altitude z.
        pub altitude_min_m: f64 ["m"],
    }
}

wire_struct! {
    /// Weights of the cost (FORMULATION.md §3–4).
    #[type_name("wingman::Weights")]
    pub struct Weights {
        /// Time against running cost, in [0, 1].
        pub alpha: f64 ["-"],
        /// Exposure against control effort, in [0, 1].
        pub beta: f64 ["-"],
        /// Stiffness s of the exposure sigmoid, > 0.
        pub stiffness: f64 ["-"],
    }
}

wire_struct! {
    /// The mission task from the lead (harness → planner). A new `revision` replaces the
    /// whole tasking. For `MinTimeRendezvous` the lead's path comes in `LeadRoute`.
    #[type_name("wingman::Tasking")]
    pub struct Tasking {
        /// Common header.
        pub header: Header ["-"],
        /// Grows with every change of tasking; starts at 1.
        pub revision: u32 ["-"],
        /// `Model` value (2 or 3).
        pub model: u32 ["enum"],
        /// `Objective` value.
        pub objective: u32 ["enum"],
        /// Number of valid entries in `targets_m`.
        pub target_count: u32 ["-"],
        /// Vehicle limits.
        pub limits: VehicleLimits ["-"],
        /// Cost weights.
        pub weights: Weights ["-"],
        /// Mission time of `start_state`.
        pub start_time_s: f64 ["s"],
        /// State at `start_time_s` (model order, zero-padded): the first plan starts here.
        pub start_state: [f64; STATE_DIM] ["m, rad, g"],
        /// Final state for `FixedTime` and `MinTime` (model order, zero-padded); zeros for
        /// a rendezvous.
        pub final_state: [f64; STATE_DIM] ["m, rad, g"],
        /// Fixed final time for `FixedTime`; 0 otherwise.
        pub final_time_s: f64 ["s"],
        /// Intermediate targets in order, `[x, y, z]` (z = 0 in 2-D); `target_count` valid.
        pub targets_m: [[f64; 3]; MAX_TARGETS] ["m"],
        /// The steady wind to plan in, `[x, y, z]` (the air mass's velocity; z = 0 in
        /// 2-D; zeros: still air). Slower than `limits.speed_mps`.
        pub wind_mps: [f64; 3] ["m/s"],
    }
}

impl Tasking {
    /// The vehicle model, if the field holds a known value.
    pub fn model(&self) -> Option<Model> {
        Model::from_wire(self.model)
    }

    /// The objective, if the field holds a known value.
    pub fn objective(&self) -> Option<Objective> {
        Objective::from_wire(self.objective)
    }

    /// The valid targets (empty if `target_count` is over capacity).
    pub fn targets(&self) -> &[[f64; 3]] {
        self.targets_m
            .get(..self.target_count as usize)
            .unwrap_or(&[])
    }
}

impl Message for Tasking {
    const SERVICE: Service = Service::Tasking;

    fn header(&self) -> &Header {
        &self.header
    }

    fn validate(&self) -> Checked {
        validate_common(self)?;
        let model = validate::enum_value("model", self.model, Model::from_wire)?;
        let objective = validate::enum_value("objective", self.objective, Objective::from_wire)?;
        validate::count("target_count", self.target_count, 0, MAX_TARGETS)?;
        if self.revision == 0 {
            return Err(ValidationError::OutOfRange {
                field: "revision",
                problem: "must start at 1",
            });
        }
        let l = &self.limits;
        validate::positive("limits.speed_mps", l.speed_mps)?;
        match model {
            Model::TwoD => validate::positive("limits.turn_rate_max_rps", l.turn_rate_max_rps)?,
            Model::ThreeD => {
                validate::within(
                    "limits.gamma_max_rad",
                    l.gamma_max_rad,
                    f64::MIN_POSITIVE,
                    core::f64::consts::FRAC_PI_2 - 1e-9,
                    "must be in (0, pi/2)",
                )?;
                if !(l.nz_min < 1.0 && 1.0 < l.nz_max) {
                    return Err(ValidationError::OutOfRange {
                        field: "limits.nz_min",
                        problem: "level flight (Nz = 1) must lie strictly inside [nz_min, nz_max]",
                    });
                }
                validate::positive("limits.bank_max_rad", l.bank_max_rad)?;
                validate::positive("limits.nz_rate_max_per_s", l.nz_rate_max_per_s)?;
                validate::positive("limits.bank_rate_max_rps", l.bank_rate_max_rps)?;
            }
        }
        let wind = self.wind_mps.iter().map(|w| w * w).sum::<f64>().sqrt();
        if wind >= l.speed_mps {
            return Err(ValidationError::OutOfRange {
                field: "wind_mps",
                problem: "the wind must be slower than limits.speed_mps",
            });
        }
        let w = &self.weights;
        validate::within("weights.alpha", w.alpha, 0.0, 1.0, "must be in [0, 1]")?;
        validate::within("weights.beta", w.beta, 0.0, 1.0, "must be in [0, 1]")?;
        validate::positive("weights.stiffness", w.stiffness)?;
        if objective == Objective::FixedTime && self.final_time_s <= self.start_time_s {
            return Err(ValidationError::TimeBackwards {
                field: "final_time_s",
            });
        }
        if model == Model::ThreeD {
            let z_min = l.altitude_min_m;
            if self.start_state[2] < z_min {
                return Err(ValidationError::OutOfRange {
                    field: "start_state",
                    problem: "altitude under limits.altitude_min_m",
                });
            }
            if self.targets().iter().any(|t| t[2] < z_min) {
                return Err(ValidationError::OutOfRange {
                    field: "targets_m",
                    problem: "altitude under limits.altitude_min_m",
                });
            }
            if objective != Objective::MinTimeRendezvous && self.final_state[2] < z_min {
                return Err(ValidationError::OutOfRange {
                    field: "final_state",
                    problem: "altitude under limits.altitude_min_m",
                });
            }
        }
        Ok(())
    }
}
