use crate::message::{Message, validate_common};
use crate::validate::{self, Checked, ValidationError};
use crate::{
    CONTROL_DIM, Header, MAX_PHASES, MAX_PLAN_CUTS, MAX_PLAN_SAMPLES, Model, PlanPath, Quality,
    STATE_DIM, Service, Trigger, wire_struct,
};

wire_struct! {
    /// One sample of a planned trajectory.
    #[type_name("wingman::PlanSample")]
    pub struct PlanSample {
        /// Mission time.
        pub t_s: f64 ["s"],
        /// State (model order, zero-padded).
        pub state: [f64; STATE_DIM] ["m, rad, g"],
        /// Control (model order, zero-padded).
        pub control: [f64; CONTROL_DIM] ["rad/s, 1/s"],
    }
}

wire_struct! {
    /// A place where the plan's compute deadline changed the course of its computation: a
    /// solve stopped after so many iterations, the swarm after so many rounds, a start not
    /// solved, a path not run. Opaque to clients (`site` names the planner's work, `step`
    /// how far it got); a replay feeds a plan's cuts back to the planner so that it takes
    /// the same course (docs/ARCHITECTURE.md, "Deadline cuts").
    #[type_name("wingman::PlanCut")]
    pub struct PlanCut {
        /// The work that was cut.
        pub site: u32 ["code"],
        /// How far it got when it was cut.
        pub step: u32 ["-"],
    }
}

wire_struct! {
    /// A plan for the tracker (planner → harness). The tracker flies the newest plan whose
    /// `start_time_s` has come, interpolating the samples linearly in time, until
    /// `valid_until_s`.
    #[type_name("wingman::Plan")]
    pub struct Plan {
        /// Common header.
        pub header: Header ["-"],
        /// Grows with every plan; starts at 1.
        pub plan_id: u64 ["-"],
        /// `Trigger` value.
        pub trigger: u32 ["enum"],
        /// `Quality` value.
        pub quality: u32 ["enum"],
        /// `Model` value (2 or 3).
        pub model: u32 ["enum"],
        /// Number of valid entries in `phase_end_s` (targets + 1).
        pub phase_count: u32 ["-"],
        /// Number of valid entries in `samples` (2 or more).
        pub sample_count: u32 ["-"],
        /// 1 if `next_replan_s` holds a scheduled re-plan time, else 0.
        pub has_next_replan: u32 ["bool"],
        /// `PlanPath` value: the path whose plan this is.
        pub path: u32 ["enum"],
        /// Number of valid entries in `cuts` (0: the deadline cut nothing; the plan is what
        /// its inputs and seed make on any machine).
        pub cut_count: u32 ["-"],
        /// Mission time of the trigger that caused the plan.
        pub created_at_s: f64 ["s"],
        /// Commit time: the tracker switches to this plan here (first sample's time).
        pub start_time_s: f64 ["s"],
        /// The plan may be flown until here (its end, or the next scheduled re-plan).
        pub valid_until_s: f64 ["s"],
        /// Objective value of the plan (FORMULATION.md §4).
        pub cost: f64 ["-"],
        /// Planned final time tf (last sample's time).
        pub final_time_s: f64 ["s"],
        /// Wall-clock compute time of the plan.
        pub compute_ms: f64 ["ms"],
        /// Scheduled re-plan time t_r (FORMULATION.md §6), valid if `has_next_replan`.
        pub next_replan_s: f64 ["s"],
        /// Mission time at which each phase ends (phase g ends on target g; the last on the
        /// final point or the rendezvous).
        pub phase_end_s: [f64; MAX_PHASES] ["s"],
        /// Where the deadline cut the computation, sorted; `cut_count` valid.
        pub cuts: [PlanCut; MAX_PLAN_CUTS] ["-"],
        /// Trajectory samples in increasing time; `sample_count` valid.
        pub samples: [PlanSample; MAX_PLAN_SAMPLES] ["-"],
    }
}

impl Plan {
    /// The trigger, if the field holds a known value.
    pub fn trigger(&self) -> Option<Trigger> {
        Trigger::from_wire(self.trigger)
    }

    /// The quality, if the field holds a known value.
    pub fn quality(&self) -> Option<Quality> {
        Quality::from_wire(self.quality)
    }

    /// The vehicle model, if the field holds a known value.
    pub fn model(&self) -> Option<Model> {
        Model::from_wire(self.model)
    }

    /// The path, if the field holds a known value.
    pub fn path(&self) -> Option<PlanPath> {
        PlanPath::from_wire(self.path)
    }

    /// The valid deadline cuts (empty if the count is over capacity).
    pub fn cuts(&self) -> &[PlanCut] {
        self.cuts.get(..self.cut_count as usize).unwrap_or(&[])
    }

    /// The valid samples (empty if the count is over capacity).
    pub fn samples(&self) -> &[PlanSample] {
        self.samples
            .get(..self.sample_count as usize)
            .unwrap_or(&[])
    }

    /// The valid phase end times (empty if the count is over capacity).
    pub fn phase_ends(&self) -> &[f64] {
        self.phase_end_s
            .get(..self.phase_count as usize)
            .unwrap_or(&[])
    }

    /// The scheduled re-plan time, if any.
    pub fn next_replan(&self) -> Option<f64> {
        (self.has_next_replan != 0).then_some(self.next_replan_s)
    }
}

impl Message for Plan {
    const SERVICE: Service = Service::Plan;

    fn header(&self) -> &Header {
        &self.header
    }

    fn validate(&self) -> Checked {
        validate_common(self)?;
        validate::enum_value("trigger", self.trigger, Trigger::from_wire)?;
        validate::enum_value("quality", self.quality, Quality::from_wire)?;
        validate::enum_value("model", self.model, Model::from_wire)?;
        validate::enum_value("path", self.path, PlanPath::from_wire)?;
        validate::count("cut_count", self.cut_count, 0, MAX_PLAN_CUTS)?;
        let phases = validate::count("phase_count", self.phase_count, 1, MAX_PHASES)?;
        let n = validate::count("sample_count", self.sample_count, 2, MAX_PLAN_SAMPLES)?;
        if self.has_next_replan > 1 {
            return Err(ValidationError::UnknownEnum {
                field: "has_next_replan",
                value: self.has_next_replan,
            });
        }
        if self.plan_id == 0 {
            return Err(ValidationError::OutOfRange {
                field: "plan_id",
                problem: "must start at 1",
            });
        }
        validate::non_negative("compute_ms", self.compute_ms)?;
        for w in self.samples[..n].windows(2) {
            if w[1].t_s <= w[0].t_s {
                return Err(ValidationError::TimeBackwards { field: "samples" });
            }
        }
        let (first, last) = (self.samples[0].t_s, self.samples[n - 1].t_s);
        validate::not_before("samples", first, self.start_time_s)?;
        validate::not_before("valid_until_s", self.valid_until_s, self.start_time_s)?;
        validate::not_before("final_time_s", self.final_time_s, first)?;
        let mut previous = first;
        for &end in &self.phase_end_s[..phases] {
            validate::not_before("phase_end_s", end, previous)?;
            previous = end;
        }
        validate::not_before("samples", last, previous)?;
        if let Some(tr) = self.next_replan() {
            validate::not_before("next_replan_s", tr, self.start_time_s)?;
        }
        Ok(())
    }
}
