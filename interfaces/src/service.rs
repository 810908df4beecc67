//! Service names. Every name starts with `wingman/<vehicle-id>/`, built by
//! [`service_name`] alone, so two wingmen (or two parallel tests) never collide.

/// The services of the contract (see `docs/ARCHITECTURE.md` for who publishes what).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Service {
    /// `Tasking`, harness → planner.
    Tasking,
    /// `LeadRoute`, harness (datalink) → planner.
    LeadRoute,
    /// `LeadState`, harness (datalink) → planner.
    LeadState,
    /// `ThreatReport`, harness (sensor) → planner.
    Threats,
    /// `TrackFix`, harness (sensor) → planner.
    Tracks,
    /// `OwnshipState`, harness (tracker) → planner.
    Ownship,
    /// `Plan`, planner → harness (tracker).
    Plan,
    /// `PlannerStatus`, planner → harness and tests.
    Status,
    /// Event service that wakes the planner after a harness publication.
    PlannerWake,
    /// Event service that wakes the harness after a planner publication.
    HarnessWake,
}

impl Service {
    /// Every service.
    pub const ALL: [Service; 10] = [
        Service::Tasking,
        Service::LeadRoute,
        Service::LeadState,
        Service::Threats,
        Service::Tracks,
        Service::Ownship,
        Service::Plan,
        Service::Status,
        Service::PlannerWake,
        Service::HarnessWake,
    ];

    /// The part of the name after `wingman/<vehicle-id>/`.
    pub const fn suffix(self) -> &'static str {
        match self {
            Service::Tasking => "tasking",
            Service::LeadRoute => "lead/route",
            Service::LeadState => "lead/state",
            Service::Threats => "threats",
            Service::Tracks => "tracks",
            Service::Ownship => "ownship",
            Service::Plan => "plan",
            Service::Status => "status",
            Service::PlannerWake => "wake/planner",
            Service::HarnessWake => "wake/harness",
        }
    }
}

/// Longest vehicle id accepted.
pub const MAX_VEHICLE_ID_LEN: usize = 64;

/// A vehicle id that cannot be part of a service name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum VehicleIdError {
    #[error("the vehicle id is empty")]
    Empty,
    #[error("the vehicle id is longer than {MAX_VEHICLE_ID_LEN} bytes")]
    TooLong,
    #[error("the vehicle id has the character {0:?}; use ASCII letters, digits, '-' and '_'")]
    BadCharacter(char),
}

/// Checks that `id` is 1–64 ASCII letters, digits, `-` or `_`.
pub fn validate_vehicle_id(id: &str) -> Result<(), VehicleIdError> {
    if id.is_empty() {
        return Err(VehicleIdError::Empty);
    }
    if id.len() > MAX_VEHICLE_ID_LEN {
        return Err(VehicleIdError::TooLong);
    }
    match id
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || *c == '-' || *c == '_'))
    {
        Some(c) => Err(VehicleIdError::BadCharacter(c)),
        None => Ok(()),
    }
}

/// `wingman/<vehicle_id>/<service suffix>`, e.g. `wingman/w1/plan`.
pub fn service_name(vehicle_id: &str, service: Service) -> Result<String, VehicleIdError> {
    validate_vehicle_id(vehicle_id)?;
    Ok(format!("wingman/{vehicle_id}/{}", service.suffix()))
}
