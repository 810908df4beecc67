//! The wingman simulation harness: the emulators around the planner (lead datalink,
//! threat sensor, inner-loop tracker) and the mission runner. Its binary is
//! `wingman-harness`.

use wingman_planner::scenario::{BUNDLED, Scenario, ScenarioError, bundled};

/// One line per bundled scenario: name, then its summary.
pub fn list_bundled() -> Result<Vec<(String, String)>, ScenarioError> {
    BUNDLED
        .iter()
        .map(|(name, _)| {
            let sc: Scenario = bundled(name).expect("listed in BUNDLED")?;
            Ok((name.to_string(), sc.summary))
        })
        .collect()
}
