//! Campaigns: many random well-posed missions flown end to end, each take-off planned
//! again with the yardstick of global optimality, and their statistics
//! (`wingman-harness campaign`, docs/CAMPAIGN.md).
//!
//! - [`kind`]: what a mission is (model, objective, features) and the filters;
//! - [`layout`], [`generate`]: drawing mission `i` of campaign `seed` as a scenario file;
//! - [`run`]: a campaign or one shard of it (`--shard i/n`), `jobs` flights at a time,
//!   `results.json` written as missions land;
//! - [`outcome`]: one mission's numbers and the criteria it misses;
//! - [`independent`]: the independent solver (CasADi + IPOPT) on every k-th take-off;
//! - [`merge`]: one campaign's results from its shards';
//! - [`summary`], [`charts`]: `report.md`, `summary.json` and the CDF charts;
//! - [`progress`]: the progress line with the time left.
//!
//! A campaign spreads over machines through any batch scheduler: each task runs one
//! shard, and `campaign merge` joins them (deploy/slurm, deploy/k8s).

pub mod charts;
pub mod generate;
pub mod independent;
pub mod kind;
pub mod layout;
pub mod merge;
pub mod outcome;
pub mod progress;
pub mod run;
pub mod summary;
