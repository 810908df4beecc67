//! The one error of reading a scenario.

/// A scenario file that breaks the format.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{file}: key `{key}`: {problem}")]
pub struct ScenarioError {
    /// The file as it was named to the loader.
    pub file: String,
    /// Dotted path of the offending key (`threats[2].axes_m`), or `(file)` / `(toml)` when
    /// the file cannot be read or parsed.
    pub key: String,
    /// What is wrong, in words.
    pub problem: String,
}
