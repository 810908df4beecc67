//! The Python client (`clients/python/`), tested against the real planner binary: its
//! script flies a short 2-D mission lock-step and checks the take-off plan (finite, from
//! the start state, to the final point, within the deployment budget), a pop-up on the
//! plan re-planning and a clear one only counted, every kind of bad input rejected with
//! the planner alive and its plan unchanged, and both start orders (the client creating
//! the services first, the planner first). Python needs the iceoryx2 package: the system
//! `python3` if it has it, else a virtual environment under `target/`.

use std::path::PathBuf;
use std::process::Command;

use wingman_testkit::binary;
use wingman_testkit::process::{TempDir, vehicle};
use wingman_testkit::python::python_with_version;

#[test]
fn the_python_client_flies_a_short_mission_against_the_planner() {
    let clients = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../clients/python");
    // The binding's version must be the Rust crate's (clients/python/requirements.txt).
    let python = python_with_version(
        "iceoryx2",
        "0.10.0",
        &clients.join("requirements.txt"),
        "python-client-venv",
    );
    let dir = TempDir::new("python-client");
    let out = Command::new(python)
        .arg(clients.join("tests/fly_short_mission.py"))
        .arg("--planner")
        .arg(binary("wingman-planner"))
        .args(["--vehicle", &vehicle("py")])
        .arg("--log-dir")
        .arg(dir.path())
        .env("RUST_LOG", "info")
        .output()
        .expect("run the Python client's script");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("every check holds"),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.matches("\nok   ").count() >= 30, "{text}");
}
