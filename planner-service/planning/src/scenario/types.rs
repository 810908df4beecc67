//! A scenario in SI units and radians: the start, the end, the lead, the threats and
//! the events of one flight.

use std::fmt;
use std::path::Path;

use toml::Table;
use wingman_interfaces::{Model, Objective, VehicleLimits, Weights};

use super::disturbance::{AircraftSpec, WindSpec};
use super::error::ScenarioError;
use super::reader::Reader;

/// Where the wingman starts (level, unbanked flight in 3-D: `Nz = 1`, `mu = 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct Start {
    pub time_s: f64,
    pub position_m: [f64; 3],
    pub heading_rad: f64,
    pub gamma_rad: f64,
}

impl Start {
    /// The start state in model order, zero-padded to 7 (3-D: level, unbanked flight).
    pub fn state(&self, model: Model) -> [f64; 7] {
        let p = &self.position_m;
        match model {
            Model::TwoD => [p[0], p[1], self.heading_rad, 0.0, 0.0, 0.0, 0.0],
            Model::ThreeD => [p[0], p[1], p[2], self.gamma_rad, self.heading_rad, 1.0, 0.0],
        }
    }
}

/// The final point of `fixed-time` and `min-time` missions.
#[derive(Debug, Clone, PartialEq)]
pub struct FinalPoint {
    pub position_m: [f64; 3],
    pub heading_rad: f64,
    pub gamma_rad: f64,
    /// Final load factor (3-D), 1 unless the file says otherwise.
    pub nz: f64,
    /// Final bank angle (3-D), 0 unless the file says otherwise.
    pub mu_rad: f64,
    /// Fixed final time (`fixed-time` only).
    pub time_s: Option<f64>,
}

impl FinalPoint {
    /// The final state in model order, zero-padded to 7.
    pub fn state(&self, model: Model) -> [f64; 7] {
        let p = &self.position_m;
        match model {
            Model::TwoD => [p[0], p[1], self.heading_rad, 0.0, 0.0, 0.0, 0.0],
            Model::ThreeD => [
                p[0],
                p[1],
                p[2],
                self.gamma_rad,
                self.heading_rad,
                self.nz,
                self.mu_rad,
            ],
        }
    }
}

/// The lead's route for a rendezvous: flown at constant speed from `start.time_s`.
#[derive(Debug, Clone, PartialEq)]
pub struct LeadSpec {
    pub route_m: Vec<[f64; 3]>,
    pub speed_mps: f64,
}

/// A static superquadric threat.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticThreatSpec {
    pub name: String,
    pub center_m: [f64; 3],
    /// Semi-axes; the third is 0 in 2-D.
    pub axes_m: [f64; 3],
    /// Exponents per axis (default 2); the third is 0 in 2-D.
    pub exponents: [f64; 3],
    pub yaw_rad: f64,
    /// A pop-up reported at this time; `None`: known before take-off.
    pub appears_at_s: Option<f64>,
}

/// The onboard sensor's fixes of a moving threat.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorSpec {
    pub rate_hz: f64,
    pub sigma_m: f64,
}

/// A threat moving along a known road (FORMULATION.md §5).
#[derive(Debug, Clone, PartialEq)]
pub struct MovingThreatSpec {
    pub name: String,
    pub road_m: Vec<[f64; 3]>,
    /// Keep-out semi-axes when the position is certain: along the road, across, up.
    pub axes_m: [f64; 3],
    pub initial_distance_m: f64,
    pub initial_speed_mps: f64,
    pub accel_sigma_mps2: f64,
    pub accel_tau_s: f64,
    /// Standard deviations of `[d, v, a]` at `start.time_s`.
    pub initial_sigma: [f64; 3],
    pub appears_at_s: f64,
    pub sensor: SensorSpec,
    /// Seed of the harness's random truth motion.
    pub truth_seed: u64,
}

/// A change of tasking in flight.
#[derive(Debug, Clone, PartialEq)]
pub enum EventKind {
    /// The lead flies a new route from the event's time on.
    LeadRoute {
        route_m: Vec<[f64; 3]>,
        speed_mps: f64,
    },
    /// The lead flies a new route from the event's time on without announcing it: no
    /// route message, only its state shows it.
    LeadOffRoute {
        route_m: Vec<[f64; 3]>,
        speed_mps: f64,
    },
    /// A new list of remaining targets.
    Targets { targets_m: Vec<[f64; 3]> },
    /// A new final point.
    Final(FinalPoint),
}

/// An event of the flight.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    pub at_s: f64,
    pub kind: EventKind,
}

/// A checked scenario in SI units and radians.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    pub name: String,
    pub summary: String,
    /// The file it was read from, as named to the loader.
    pub source: String,
    pub model: Model,
    pub objective: Objective,
    /// Vehicle limits; the fields of the other model are zero.
    pub vehicle: VehicleLimits,
    pub weights: Weights,
    pub start: Start,
    pub targets: Vec<[f64; 3]>,
    /// For `fixed-time` and `min-time`.
    pub final_point: Option<FinalPoint>,
    /// For `min-time-rendezvous`.
    pub lead: Option<LeadSpec>,
    pub threats: Vec<StaticThreatSpec>,
    pub moving_threats: Vec<MovingThreatSpec>,
    pub events: Vec<Event>,
    /// The wind the harness flies (`None`: still air).
    pub wind: Option<WindSpec>,
    /// How the real aircraft differs from the planner's model (`None`: not at all).
    pub aircraft: Option<AircraftSpec>,
}

impl Scenario {
    /// Reads and checks a scenario file.
    pub fn load(path: impl AsRef<Path>) -> Result<Scenario, ScenarioError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError {
            file: file.clone(),
            key: "(file)".into(),
            problem: format!("cannot be read: {e}"),
        })?;
        Scenario::parse(&text, &file)
    }

    /// Checks scenario text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Scenario, ScenarioError> {
        let root: Table = text.parse().map_err(|e: toml::de::Error| ScenarioError {
            file: file.to_string(),
            key: "(toml)".into(),
            problem: format!("not valid TOML: {}", e.message()),
        })?;
        Reader { file }.scenario(&root)
    }

    /// Number of position coordinates (2 or 3).
    pub fn dim(&self) -> usize {
        self.model.position_dim()
    }

    /// Static threats known before take-off (no `appears_at_s` after `start.time_s`).
    pub fn known_static_threats(&self) -> impl Iterator<Item = &StaticThreatSpec> {
        let t0 = self.start.time_s;
        self.threats
            .iter()
            .filter(move |t| t.appears_at_s.is_none_or(|a| a <= t0))
    }

    /// Moving threats known before take-off.
    pub fn known_moving_threats(&self) -> impl Iterator<Item = &MovingThreatSpec> {
        let t0 = self.start.time_s;
        self.moving_threats
            .iter()
            .filter(move |m| m.appears_at_s <= t0)
    }

    /// Whether the scenario only makes sense flown end to end (events or pop-ups after
    /// take-off), as the reference's `is_closed_loop`.
    pub fn is_closed_loop(&self) -> bool {
        let t0 = self.start.time_s;
        !self.events.is_empty()
            || self
                .threats
                .iter()
                .any(|t| t.appears_at_s.is_some_and(|a| a > t0))
            || self.moving_threats.iter().any(|m| m.appears_at_s > t0)
    }
}

impl fmt::Display for Scenario {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let model = match self.model {
            Model::TwoD => "2d",
            Model::ThreeD => "3d",
        };
        let objective = match self.objective {
            Objective::FixedTime => "fixed-time",
            Objective::MinTime => "min-time",
            Objective::MinTimeRendezvous => "min-time-rendezvous",
        };
        write!(
            f,
            "{} ({model}, {objective}): {} target(s), {} static threat(s), {} moving threat(s), {} event(s)",
            self.name,
            self.targets.len(),
            self.threats.len(),
            self.moving_threats.len(),
            self.events.len()
        )
    }
}
