//! PNG plots of a flight (placeholder until the plots land).
use std::path::Path;

/// Draws every plot; returns the file names written.
pub fn draw_all(
    _flight: &crate::mission::Flight,
    _report: &crate::report::Report,
    _out: &Path,
) -> Result<Vec<String>, Box<dyn std::error::Error + Send + Sync>> {
    Ok(Vec::new())
}
