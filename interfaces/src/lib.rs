//! The message contract between the wingman planner process and the harness process.
//!
//! Every message is a `#[repr(C)]`, `Copy`, [`ZeroCopySend`] struct of fixed size that
//! travels over iceoryx2 shared memory without serialisation. Variable-length content sits
//! in fixed-capacity arrays with an explicit count; capacities are the `MAX_*` constants
//! below. Every message starts with a [`Header`] and has a `validate()` that the receiver
//! calls before anything else. `docs/INTERFACES.md` documents every byte; a test keeps it
//! equal to the tables generated from this crate.
//!
//! Conventions (FORMULATION.md §1): local flat Earth, x east, y north, z up; metres,
//! seconds, radians; headings counter-clockwise from +x. State vectors hold the model's
//! states in its order (2-D: `x, y, psi`; 3-D: `x, y, z, gamma, chi, nz, mu`) and zeros
//! after them; control vectors likewise (2-D: `u`; 3-D: `u1, u2`).

pub mod layout;

pub mod doc;
mod header;
mod kinds;
mod lead;
mod message;
mod ownship;
mod plan;
mod service;
mod status;
mod tasking;
mod threat;
mod track;
mod validate;

pub use doc::interfaces_markdown;
pub use header::Header;
pub use kinds::{Model, Objective, PlanPath, PlannerState, Quality, ThreatKind, Trigger};
pub use layout::{Wire, WrongLength};
pub use lead::{LeadRoute, LeadState};
pub use message::Message;
pub use ownship::{OWNSHIP_HOLDING, OwnshipState};
pub use plan::{Plan, PlanCut, PlanSample};
pub use service::{Service, VehicleIdError, service_name, validate_vehicle_id};
pub use status::{PlannerStatus, STALE_LEAD, STALE_OWNSHIP, STALE_TASKING, STALE_TRACKS};
pub use tasking::{Tasking, VehicleLimits, Weights};
pub use threat::{ThreatReport, threat_name};
pub use track::TrackFix;
pub use validate::{Checked, ValidationError};

/// Re-exported so the derive in [`wire_struct!`] resolves in this crate and in users'.
#[cfg(feature = "iceoryx2")]
pub use iceoryx2::prelude::ZeroCopySend;

/// Version of this contract. A message carrying another version is rejected.
pub const PROTOCOL_VERSION: u32 = 5;

/// Intermediate targets in one tasking.
pub const MAX_TARGETS: usize = 8;
/// Phases of a plan: one per leg, so one more than the targets.
pub const MAX_PHASES: usize = MAX_TARGETS + 1;
/// Points of the lead's route polyline.
pub const MAX_ROUTE_POINTS: usize = 16;
/// Points of a moving threat's road polyline.
pub const MAX_ROAD_POINTS: usize = 16;
/// Samples of a plan's trajectory.
pub const MAX_PLAN_SAMPLES: usize = 2048;

/// Deadline cuts carried in one plan (a plan has a few dozen places the deadline can cut).
pub const MAX_PLAN_CUTS: usize = 64;
/// Length of the state vectors (the 3-D model's 7 states; 2-D uses the first 3).
pub const STATE_DIM: usize = 7;
/// Length of the control vectors (the 3-D model's 2 controls; 2-D uses the first).
pub const CONTROL_DIM: usize = 2;
/// Bytes of a threat's name (UTF-8, NUL-padded).
pub const THREAT_NAME_LEN: usize = 24;

/// Sender id of the planner process.
pub const SENDER_PLANNER: u32 = 1;
/// Sender id of the harness process (datalink, sensor, tracker emulators).
pub const SENDER_HARNESS: u32 = 2;
