//! The wingman planner service: the planner as the customer deploys it — its own process,
//! talking to the rest of the aircraft only through the messages of `wingman-interfaces`
//! over iceoryx2 (`wingman-ipc`), planning with `wingman-planning` only when triggered,
//! under a compute budget. Also the offline `plan` command of the `wingman-planner` binary.

pub mod offline;
pub mod service;
