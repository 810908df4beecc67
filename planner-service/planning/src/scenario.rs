//! Scenario files (`scenarios/FORMAT.md`): one TOML file holds a mission's tasking, the
//! vehicle, the threat world and the events of one flight.
//!
//! [`Scenario::load`] returns a typed scenario in SI units and radians, or refuses the file
//! with one [`ScenarioError`] that names the file, the key and the problem. Positions are
//! stored as `[x, y, z]` with `z = 0` in 2-D. Unknown keys are refused too, so a typo
//! cannot silently drop a setting.

mod bundled;
mod disturbance;
mod error;
pub mod messages;
mod parse;
mod reader;
mod types;

pub use bundled::{BUNDLED, DISTURBED, bundled, load_by_path_or_name};
pub use disturbance::{AircraftSpec, GUST_LENGTH_M, GUSTS, WindSpec};
pub use error::ScenarioError;
pub use types::{
    Event, EventKind, FinalPoint, LeadSpec, MovingThreatSpec, Scenario, SensorSpec, Start,
    StaticThreatSpec,
};
