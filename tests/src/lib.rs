//! What the multi-process tests check in a flight's `report.json` (the fixtures they share
//! with the other crates' tests are in `wingman-testkit`).

pub mod fuzz;
pub mod outcome;
