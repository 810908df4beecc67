//! The independent judge (`tools/judge/evaluate.py`, the customer's reference) run on an
//! exported trajectory. Python needs numpy and scipy: if the system `python3` lacks them,
//! a virtual environment under `target/judge-venv` is made once and they are installed
//! from `tools/judge/requirements.txt`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The judge's folder in the project.
pub fn judge_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tools/judge")
}

/// A Python interpreter with numpy and scipy (set up on first use).
pub fn python() -> &'static PathBuf {
    static PYTHON: OnceLock<PathBuf> = OnceLock::new();
    PYTHON.get_or_init(|| {
        crate::python::python_with(
            "numpy, scipy",
            &judge_dir().join("requirements.txt"),
            "judge-venv",
        )
    })
}

/// The judge's report on `trajectory` (CSV or JSON) for `scenario`.
pub fn evaluate(scenario: &Path, trajectory: &Path) -> serde_json::Value {
    let out = Command::new(python())
        .arg(judge_dir().join("evaluate.py"))
        .arg(scenario)
        .arg(trajectory)
        .output()
        .expect("run the judge");
    assert!(
        out.status.success(),
        "judge failed on {}: {}",
        trajectory.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("the judge prints JSON")
}

/// The reference optimum of a canonical scenario (`tools/judge/costs.toml`), if listed.
pub fn reference_cost(name: &str) -> Option<f64> {
    let text = std::fs::read_to_string(judge_dir().join("costs.toml")).ok()?;
    let mut in_section = false;
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('[') {
            in_section = line == format!("[{name}]");
        } else if in_section && let Some(v) = line.strip_prefix("cost =") {
            return v.trim().parse().ok();
        }
    }
    None
}
