//! A Python interpreter with the packages a test needs: the system `python3` if it can
//! import them, else a virtual environment under `target/` made once and filled from a
//! requirements file (the judge's numpy and scipy, the Python client's iceoryx2).

use std::path::{Path, PathBuf};
use std::process::Command;

/// Whether `python` runs `check` (Python code) without an error.
fn passes(python: &Path, check: &str) -> bool {
    Command::new(python)
        .args(["-c", check])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `python3` if it imports `modules` (comma-separated), else the virtual environment
/// `target/<venv>` with `requirements` installed (made on first use).
pub fn python_with(modules: &str, requirements: &Path, venv: &str) -> PathBuf {
    python_passing(&format!("import {modules}"), requirements, venv)
}

/// `python3` if it has version `version` of package `package` (importable as `package`),
/// else the virtual environment `target/<venv>` with `requirements` installed: for a
/// package whose version must match exactly (the iceoryx2 binding and the Rust iceoryx2
/// share memory layouts).
pub fn python_with_version(
    package: &str,
    version: &str,
    requirements: &Path,
    venv: &str,
) -> PathBuf {
    let check = format!(
        "import {package}, importlib.metadata as m; \
         assert m.version('{package}') == '{version}', m.version('{package}')"
    );
    python_passing(&check, requirements, venv)
}

fn python_passing(check: &str, requirements: &Path, venv: &str) -> PathBuf {
    let system = PathBuf::from("python3");
    if passes(&system, check) {
        return system;
    }
    let venv = crate::target_dir().join(venv);
    let python = venv.join("bin/python3");
    if !passes(&python, check) {
        let ok = Command::new("python3")
            .args(["-m", "venv"])
            .arg(&venv)
            .status()
            .is_ok_and(|s| s.success());
        assert!(
            ok,
            "python3 -m venv {} failed: Python 3 with venv is needed",
            venv.display()
        );
        let ok = Command::new(&python)
            .args(["-m", "pip", "install", "--quiet", "-r"])
            .arg(requirements)
            .status()
            .is_ok_and(|s| s.success());
        assert!(ok, "installing {} failed", requirements.display());
    }
    python
}
