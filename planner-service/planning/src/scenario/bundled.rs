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

/// A bundled scenario by name.
pub fn bundled(name: &str) -> Option<Result<Scenario, ScenarioError>> {
    BUNDLED
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, text)| Scenario::parse(text, &format!("scenarios/{n}.toml (bundled)")))
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
