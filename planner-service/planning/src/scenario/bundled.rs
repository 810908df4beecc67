//! The scenarios bundled into the binaries, and loading a scenario by path or name.

use std::path::Path;

use super::error::ScenarioError;
use super::types::Scenario;

macro_rules! bundled {
    ($name:literal) => {
        (
            $name,
            include_str!(concat!("../../../../scenarios/", $name, ".toml")),
        )
    };
    ($dir:literal / $name:literal) => {
        (
            $name,
            include_str!(concat!("../../../../scenarios/", $dir, "/", $name, ".toml")),
        )
    };
}

/// The canonical scenarios shipped with the project (`scenarios/*.toml`), by name.
pub const BUNDLED: &[(&str, &str)] = &[
    bundled!("2d-fixed-time-avoidable"),
    bundled!("2d-fixed-time-unavoidable"),
    bundled!("2d-min-time-avoidable"),
    bundled!("2d-min-time-rendezvous-avoidable"),
    bundled!("2d-min-time-rendezvous-unavoidable"),
    bundled!("2d-min-time-unavoidable"),
    bundled!("3d-fixed-time-avoidable"),
    bundled!("3d-fixed-time-unavoidable"),
    bundled!("3d-min-time-avoidable"),
    bundled!("3d-min-time-moving-threat"),
    bundled!("3d-min-time-rendezvous-avoidable"),
    bundled!("3d-min-time-rendezvous-unavoidable"),
    bundled!("3d-min-time-unavoidable"),
    bundled!("3d-rendezvous-moving-threat"),
    bundled!("3d-replan-popups"),
];

/// The disturbed-flight scenarios (`scenarios/disturbed/*.toml`): wind and turbulence,
/// an aircraft that is not the planner's model, a lead that leaves its route, many targets
/// and moving threats. Bundled like the canonical ones, flown by the test suite; the
/// customer's reference optima cover only the canonical set.
pub const DISTURBED: &[(&str, &str)] = &[
    bundled!("disturbed" / "2d-fixed-time-windy"),
    bundled!("disturbed" / "2d-four-targets-two-moving-threats"),
    bundled!("disturbed" / "2d-rendezvous-lead-off-route"),
    bundled!("disturbed" / "3d-rendezvous-turbulence"),
];

/// A bundled scenario by name, canonical or disturbed.
pub fn bundled(name: &str) -> Option<Result<Scenario, ScenarioError>> {
    let canonical = BUNDLED
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, text)| (format!("scenarios/{n}.toml"), *text));
    let disturbed = || {
        DISTURBED
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(n, text)| (format!("scenarios/disturbed/{n}.toml"), *text))
    };
    canonical
        .or_else(disturbed)
        .map(|(file, text)| Scenario::parse(text, &format!("{file} (bundled)")))
}

/// Loads `arg` as a file path if it names a file, else as a bundled scenario's name.
pub fn load_by_path_or_name(arg: &str) -> Result<Scenario, ScenarioError> {
    let path = Path::new(arg);
    if path.exists() || arg.ends_with(".toml") {
        return Scenario::load(path);
    }
    bundled(arg).unwrap_or_else(|| {
        Err(ScenarioError {
            file: arg.to_string(),
            key: "(file)".into(),
            problem: format!(
                "no such file, and no bundled scenario of that name (bundled: {})",
                BUNDLED
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })
    })
}
