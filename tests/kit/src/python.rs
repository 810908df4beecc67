//! A Python interpreter with the packages a test needs: the system `python3` if it can
//! import them, else a virtual environment under `target/` made once and filled from a
//! requirements file (the judge's numpy and scipy, the Python client's iceoryx2).

use std::path::{Path, PathBuf};
use std::process::Command;

fn imports(python: &Path, modules: &str) -> bool {
    Command::new(python)
        .args(["-c", &format!("import {modules}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// `python3` if it imports `modules` (comma-separated), else the virtual environment
/// `target/<venv>` with `requirements` installed (made on first use).
pub fn python_with(modules: &str, requirements: &Path, venv: &str) -> PathBuf {
    let system = PathBuf::from("python3");
    if imports(&system, modules) {
        return system;
    }
    let venv = crate::target_dir().join(venv);
    let python = venv.join("bin/python3");
    if !imports(&python, modules) {
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
