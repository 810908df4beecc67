//! Fixtures shared by the tests of every crate, in one place instead of copies:
//!
//! - this module: the workspace's real binaries (built once if needed, in the running
//!   test's profile) and the project's folders;
//! - [`process`]: temporary folders, child processes with a watchdog that `Drop` kills and
//!   cleans up after, vehicle ids unique to a test;
//! - [`counting_alloc`]: the counting global allocator of the no-allocation tests;
//! - [`fake_harness`]: the harness side of the services over real iceoryx2, and messages
//!   built for tests;
//! - [`rogue`]: a process that publishes whatever bytes it is given;
//! - [`judge`]: the customer's independent judge run on an exported trajectory;
//! - [`random_scenario`]: random well-posed scenario files.
//!
//! It depends on the messages and the IPC contract only, so every crate's tests can use it
//! without a dependency cycle.

pub mod counting_alloc;
pub mod fake_harness;
pub mod judge;
pub mod process;
pub mod python;
pub mod random_scenario;
pub mod rogue;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

/// The workspace's `target/<profile>` folder of the running test executable
/// (`target/<profile>/deps/<test>-<hash>`).
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("current_exe");
    exe.parent()
        .and_then(Path::parent)
        .expect("test executable under target/<profile>/deps")
        .to_path_buf()
}

fn profile_name(dir: &Path) -> String {
    match dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") => "dev".to_string(),
        Some(other) => other.to_string(),
        None => "dev".to_string(),
    }
}

/// The workspace's `target/` folder.
pub fn target_dir() -> PathBuf {
    profile_dir()
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("target"))
}

/// Builds the workspace binaries once per test process, in the test's profile.
fn build_binaries() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = profile_dir();
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_string());
        let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../Cargo.toml");
        let status = Command::new(cargo)
            .args(["build", "--quiet", "--profile", &profile_name(&dir)])
            .args(["--bin", "wingman-planner", "--bin", "wingman-harness"])
            .arg("--manifest-path")
            .arg(manifest)
            .status()
            .expect("run cargo build");
        assert!(status.success(), "building the binaries failed");
        dir
    })
}

/// Path of a workspace binary (`wingman-planner`, `wingman-harness`), built if needed.
pub fn binary(name: &str) -> PathBuf {
    let path = build_binaries().join(name);
    assert!(path.exists(), "{} was not built", path.display());
    path
}

/// The project's `scenarios/` folder.
pub fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios")
}
