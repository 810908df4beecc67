//! `replay`: a flown `flight.log` fed back to the planner. `wingman-planner serve` (found
//! as `fly` finds it) starts with the logged configuration on a fresh vehicle id; the
//! logged inputs are published as they were (headers included) and, at every logged
//! lock-step barrier, the replay waits as the flight did until the planner has processed them and is idle. Every
//! plan that comes out is compared with the logged one **byte for byte**, except
//! `compute_ms` (a wall-clock measurement): same inputs and seed, same plan.
//!
//! A resumed flight's log (`fly --resume`) is refused: the planner's world before the
//! resume came from another harness and is not in it.
//!
//! A log flown with the lock-step clock replays exactly. A real-time log has no barriers:
//! the replay then syncs after each mission time's inputs, which need not be how the
//! planner saw them in flight, and says so.

use std::mem::offset_of;
use std::path::{Path, PathBuf};
use std::time::Duration;

use wingman_interfaces::{Plan, Wire};
use wingman_ipc::ServiceConfig;
use wingman_planning::cuts::ReplayCuts;
use wingman_planning::plan_message::{TRUNCATED_CUTS, cuts_of};

use crate::flight_log::{self, Direction, Entry, LogWriter};
use crate::link::PlannerLink;
use crate::mission::unique_vehicle_id;
use crate::process::{PlannerProcess, ProcessError, planner_binary};

/// A replay that could not run.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error("{0}")]
    Log(#[from] flight_log::LogError),
    #[error("the logged planner configuration: {0}")]
    Config(#[from] wingman_ipc::config::ConfigError),
    #[error("{0}")]
    Link(#[from] crate::link::LinkError),
    #[error("the planner service: {0}")]
    Service(String),
    #[error("{0}")]
    Process(#[from] ProcessError),
    #[error(
        "plan {plan_id} carries a deadline cut of unknown site {code:#010x}: the log was flown \
         with another version of the planner"
    )]
    UnknownCut { plan_id: u64, code: u32 },
    #[error(
        "plan {plan_id} was cut by its deadline in more places than its message holds: its \
         course cannot be replayed"
    )]
    TruncatedCuts { plan_id: u64 },
    #[error(
        "a resumed flight's log (taken over at mission time {mission_s:.1} s from a planner on plan {plan_id}): \
         the planner's world before the resume is not in it, so its plans cannot be replayed"
    )]
    Resumed { mission_s: f64, plan_id: u64 },
}

/// One plan that came out different.
#[derive(Debug, Clone, PartialEq)]
pub struct Mismatch {
    pub plan_id: u64,
    /// The fields whose bytes differ (`compute_ms` ignored).
    pub fields: Vec<&'static str>,
    /// Quality flag and compute time of the logged and the replayed plan: a plan stopped
    /// by its deadline (not `Optimal`, or a compute time near the budget) depends on the
    /// machine's speed at the time, not only on its inputs.
    pub logged: (u32, f64),
    pub replayed: (u32, f64),
}

/// What a replay found.
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayOutcome {
    pub scenario: String,
    /// The log has lock-step barriers (a fast-clock flight).
    pub lock_step: bool,
    pub inputs: usize,
    pub plans_logged: usize,
    pub plans_replayed: usize,
    /// Plans identical byte for byte (except `compute_ms`).
    pub identical: usize,
    pub mismatches: Vec<Mismatch>,
}

impl ReplayOutcome {
    /// Every logged plan came out identical, and no other plan came out.
    pub fn all_identical(&self) -> bool {
        self.plans_logged == self.plans_replayed
            && self.identical == self.plans_logged
            && self.mismatches.is_empty()
    }
}

impl std::fmt::Display for ReplayOutcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "{}: {} inputs replayed{}, {} plan(s) logged, {} replayed, {} identical byte for byte \
             (compute_ms aside)",
            self.scenario,
            self.inputs,
            if self.lock_step {
                " in lock-step"
            } else {
                " (real-time log: no lock-step barriers, synced per mission time)"
            },
            self.plans_logged,
            self.plans_replayed,
            self.identical
        )?;
        for m in &self.mismatches {
            writeln!(
                f,
                "  plan {} differs in: {} (quality {} / {}, compute {:.0} / {:.0} ms, logged / replayed)",
                m.plan_id,
                m.fields.join(", "),
                m.logged.0,
                m.replayed.0,
                m.logged.1,
                m.replayed.1
            )?;
        }
        write!(
            f,
            "{}",
            if self.all_identical() {
                "every plan identical"
            } else {
                "PLANS DIFFER"
            }
        )
    }
}

/// `wingman-planner serve` started for a replay, with its configuration and log in a
/// folder of its own that goes with it.
struct ReplayPlanner {
    process: PlannerProcess,
    dir: PathBuf,
}

impl ReplayPlanner {
    /// Starts the planner with `config`, taking the logged plans' deadline cuts.
    fn start(config: &ServiceConfig, cuts: &ReplayCuts) -> Result<ReplayPlanner, ReplayError> {
        let dir = std::env::temp_dir().join(format!("wingman-{}", config.vehicle_id));
        let io = |e: std::io::Error| ReplayError::Service(format!("{}: {e}", dir.display()));
        std::fs::create_dir_all(&dir).map_err(io)?;
        let config_path = dir.join("planner.toml");
        std::fs::write(&config_path, config.to_toml()).map_err(io)?;
        let cuts_path = dir.join("replay-cuts.txt");
        std::fs::write(&cuts_path, cuts.to_text()).map_err(io)?;
        let process = PlannerProcess::spawn(
            &planner_binary()?,
            &config_path,
            &config.vehicle_id,
            Some(&cuts_path),
            &dir.join("planner.log"),
        )?;
        Ok(ReplayPlanner { process, dir })
    }

    fn is_running(&mut self) -> bool {
        self.process.is_running()
    }

    /// Stops the planner (SIGTERM: it finishes its plan and exits 0).
    fn stop(&mut self) -> Result<(), ReplayError> {
        match self.process.stop(Duration::from_secs(10)) {
            Some(status) if status.success() => Ok(()),
            other => Err(ReplayError::Service(format!(
                "the planner did not stop cleanly ({other:?}); its log: {}",
                std::fs::read_to_string(self.dir.join("planner.log")).unwrap_or_default()
            ))),
        }
    }
}

impl Drop for ReplayPlanner {
    fn drop(&mut self) {
        self.process.kill();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The deadline cuts of the logged plans, which the replay's planner takes instead of its
/// own deadlines: a plan cut by its deadline in flight takes the same course again.
fn replay_cuts(logged: &[Box<Plan>]) -> Result<ReplayCuts, ReplayError> {
    let mut cuts = ReplayCuts::default();
    for plan in logged {
        let plan_id = plan.plan_id;
        let of_plan = cuts_of(plan).map_err(|code| match code {
            TRUNCATED_CUTS => ReplayError::TruncatedCuts { plan_id },
            code => ReplayError::UnknownCut { plan_id, code },
        })?;
        cuts.insert(plan.plan_id, of_plan);
    }
    Ok(cuts)
}

/// The bytes of a plan with `compute_ms` zeroed.
fn comparable(plan: &Plan) -> Vec<u8> {
    let mut b = plan.as_bytes().to_vec();
    let at = offset_of!(Plan, compute_ms);
    b[at..at + 8].fill(0);
    b
}

/// The fields of `Plan` whose bytes differ between `a` and `b`.
fn differing_fields(a: &[u8], b: &[u8]) -> Vec<&'static str> {
    Plan::fields()
        .iter()
        .filter(|f| {
            let r = f.offset..f.offset + f.size;
            a.get(r.clone()) != b.get(r)
        })
        .map(|f| f.name)
        .collect()
}

/// Replays `log` (see the module documentation). `timeout`: the longest wait for the
/// planner at one barrier.
pub fn replay(log: &Path, timeout: Duration) -> Result<ReplayOutcome, ReplayError> {
    let entries = flight_log::read(log)?;
    let (scenario, config_text) = match entries.first() {
        Some(Entry::Start {
            scenario,
            planner_config,
            ..
        }) => (scenario.clone(), planner_config.clone()),
        _ => {
            return Err(ReplayError::Log(flight_log::LogError::Version {
                path: log.display().to_string(),
                found: "no start record".into(),
            }));
        }
    };
    if let Some((mission_s, plan_id)) = entries.iter().find_map(|e| match e {
        Entry::Resume {
            mission_s, plan_id, ..
        } => Some((*mission_s, *plan_id)),
        _ => None,
    }) {
        return Err(ReplayError::Resumed { mission_s, plan_id });
    }
    let mut config = ServiceConfig::from_toml(&config_text, "flight.log (planner_config)")?;
    config.vehicle_id = unique_vehicle_id("replay");
    let lock_step = entries.iter().any(|e| matches!(e, Entry::Sync { .. }));
    let logged: Vec<Box<Plan>> = flight_log::plans(&entries).collect();
    let cuts = replay_cuts(&logged)?;

    let mut link = PlannerLink::open(&config.vehicle_id, LogWriter::discard())?;
    let mut planner = ReplayPlanner::start(&config, &cuts)?;
    let mut replayed: Vec<Box<Plan>> = Vec::new();
    let up = std::time::Instant::now();
    while link.status().is_none() {
        link.poll()?;
        if !planner.is_running() || up.elapsed() > Duration::from_secs(30) {
            return Err(ReplayError::Service("the service did not start".into()));
        }
        link.wait(Duration::from_millis(50))?;
    }
    let mut inputs = 0;
    let mut group_time: Option<f64> = None;
    let barrier = |link: &mut PlannerLink,
                   replayed: &mut Vec<Box<Plan>>,
                   planner: &mut ReplayPlanner|
     -> Result<(), ReplayError> {
        link.wake()?;
        let (r, ok) = link.sync(timeout, || planner.is_running())?;
        replayed.extend(r.plans);
        if ok {
            Ok(())
        } else {
            Err(ReplayError::Service(format!(
                "the planner did not process the inputs within {timeout:?}"
            )))
        }
    };
    for e in &entries {
        match e {
            Entry::Message {
                direction: Direction::ToPlanner,
                kind,
                bytes,
                mission_s,
                ..
            } => {
                if !lock_step {
                    if group_time.is_some_and(|t| t != *mission_s) {
                        barrier(&mut link, &mut replayed, &mut planner)?;
                    }
                    group_time = Some(*mission_s);
                }
                if link.send_logged(*kind, bytes)? {
                    inputs += 1;
                }
            }
            Entry::Sync { .. } => barrier(&mut link, &mut replayed, &mut planner)?,
            _ => {}
        }
    }
    barrier(&mut link, &mut replayed, &mut planner)?;
    planner.stop()?;

    let mut identical = 0;
    let mut mismatches = Vec::new();
    for (a, b) in logged.iter().zip(&replayed) {
        let (ba, bb) = (comparable(a), comparable(b));
        if ba == bb {
            identical += 1;
        } else {
            mismatches.push(Mismatch {
                plan_id: a.plan_id,
                fields: differing_fields(&ba, &bb),
                logged: (a.quality, a.compute_ms),
                replayed: (b.quality, b.compute_ms),
            });
        }
    }
    Ok(ReplayOutcome {
        scenario,
        lock_step,
        inputs,
        plans_logged: logged.len(),
        plans_replayed: replayed.len(),
        identical,
        mismatches,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mismatch names the differing fields and both plans' quality and compute time, so
    /// a plan cut by its deadline (machine speed) can be told from a nondeterministic one.
    #[test]
    fn a_mismatch_reports_the_fields_quality_and_compute_time() {
        let o = ReplayOutcome {
            scenario: "s".into(),
            lock_step: true,
            inputs: 10,
            plans_logged: 1,
            plans_replayed: 1,
            identical: 0,
            mismatches: vec![Mismatch {
                plan_id: 3,
                fields: vec!["samples", "cost"],
                logged: (1, 420.0),
                replayed: (2, 2001.0),
            }],
        };
        assert!(!o.all_identical());
        let text = o.to_string();
        assert!(
            text.contains("plan 3 differs in: samples, cost (quality 1 / 2, compute 420 / 2001 ms"),
            "{text}"
        );
        assert!(
            text.ends_with("PLANS DIFFER") || text.contains("PLANS DIFFER"),
            "{text}"
        );
    }
}
