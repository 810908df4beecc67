//! The `u32`-coded enums of the protocol.

use crate::wire_enum;

wire_enum! {
    /// Vehicle model; the wire value is the model's dimension.
    pub enum Model {
        /// Planar model: states `x, y, psi`, control `u` (turn rate).
        TwoD = 2,
        /// 3-D point-mass model: states `x, y, z, gamma, chi, nz, mu`, controls `u1, u2`.
        ThreeD = 3,
    }
}

impl Model {
    /// Number of states.
    pub const fn state_dim(self) -> usize {
        match self {
            Model::TwoD => 3,
            Model::ThreeD => 7,
        }
    }

    /// Number of controls.
    pub const fn control_dim(self) -> usize {
        match self {
            Model::TwoD => 1,
            Model::ThreeD => 2,
        }
    }

    /// Number of position coordinates.
    pub const fn position_dim(self) -> usize {
        match self {
            Model::TwoD => 2,
            Model::ThreeD => 3,
        }
    }
}

wire_enum! {
    /// What the plan optimises and how it ends (FORMULATION.md §4).
    pub enum Objective {
        /// Reach the final state at the fixed final time; cost: running cost.
        FixedTime = 0,
        /// Reach the final state; cost: `alpha tf + (1 - alpha) J_run`.
        MinTime = 1,
        /// Meet the lead (its state at `tf`); cost as `MinTime`.
        MinTimeRendezvous = 2,
    }
}

wire_enum! {
    /// Kind of a threat report.
    pub enum ThreatKind {
        /// A static superquadric region.
        Static = 0,
        /// A threat moving along a known road, estimated by a Kalman filter.
        Moving = 1,
    }
}

wire_enum! {
    /// Why a plan was made.
    pub enum Trigger {
        /// The first plan of a tasking.
        Initial = 0,
        /// A pop-up threat reaches the remaining plan.
        PopUp = 1,
        /// The tasking changed (targets, final point, objective).
        Tasking = 2,
        /// The lead's route changed (rendezvous moves).
        LeadRoute = 3,
        /// The scheduled re-plan time t_r of a moving threat came.
        ScheduledReplan = 4,
        /// The tracker deviates from the plan beyond the configured bound.
        Deviation = 5,
        /// The current plan expires with no successor.
        Expiry = 6,
        /// The planner restarted and plans from the current ownship state.
        Restart = 7,
        /// The plan in flight fell short of `Optimal` (its deadline cut it: mostly a short
        /// re-plan): it is planned again, from the last plan the NLP made, with the longer
        /// refinement budget.
        Refine = 8,
        /// The lead left the route it announced, without a new route: its observed state
        /// moves the predicted meeting point beyond the configured distance. The
        /// rendezvous is re-planned with the lead flying on as observed.
        LeadOffRoute = 9,
    }
}

wire_enum! {
    /// How good a plan is.
    pub enum Quality {
        /// The collocation NLP converged: locally optimal and feasible.
        Optimal = 0,
        /// The NLP stopped early with the constraints within tolerance.
        Feasible = 1,
        /// The swarm's best path, lifted to the full model (no NLP result).
        SwarmOnly = 2,
        /// A fallback (e.g. the previous plan extended or a hold).
        Degraded = 3,
    }
}

wire_enum! {
    /// Which path of the planner made a plan.
    pub enum PlanPath {
        /// The global search: seeds, swarm, ranked starts, finalists, refinement.
        Global = 0,
        /// A re-plan's warm path: the plan in flight, cut at the new start and solved again.
        Warm = 1,
    }
}

wire_enum! {
    /// What the planner is doing.
    pub enum PlannerState {
        /// Waiting for a trigger.
        Idle = 0,
        /// A plan is being computed, or a triggered plan waits for the compute gate (a
        /// lock-step harness waits for both alike).
        Planning = 1,
        /// Running, but without a valid plan or with stale inputs.
        Degraded = 2,
    }
}
