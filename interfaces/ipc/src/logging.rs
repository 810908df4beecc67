//! Logging set-up shared by the binaries: `tracing` to stderr, level from `RUST_LOG`
//! (default [`DEFAULT_FILTER`]: `info`, but only warnings from the NLP solver, which
//! reports per-iteration decisions at `info`), human-readable, or JSON lines when
//! `WINGMAN_LOG_FORMAT=json`.

use tracing_subscriber::EnvFilter;

/// The filter without `RUST_LOG`: our own events from `info`, the solver crates
/// (pounce-rs, FERAL) from `warn`.
pub const DEFAULT_FILTER: &str = "info,pounce=warn,feral=warn";

/// Installs the global subscriber once; later calls do nothing.
pub fn init() {
    let filter =
        EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new(DEFAULT_FILTER));
    let json = std::env::var("WINGMAN_LOG_FORMAT").is_ok_and(|v| v.eq_ignore_ascii_case("json"));
    let builder = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr);
    // A second call finds a subscriber installed; that is fine.
    let _ = if json {
        builder.json().try_init()
    } else {
        builder.try_init()
    };
}
