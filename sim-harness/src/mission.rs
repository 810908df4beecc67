//! A mission flown end to end: the planner process (spawned, or one already running), the
//! emulators (datalink, sensor, tracker) and the clock, step by step, until the flown plan
//! reaches its end or the time limit. [`fly`] holds the logic; the binary only wires it.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use wingman_interfaces::{
    Model, Plan, PlannerState, PlannerStatus, Service, ThreatKind, ThreatReport, Wire,
    service_name, threat_name,
};
use wingman_ipc::ServiceConfig;
use wingman_planning::estimation::Estimate;
use wingman_planning::problem::ProblemError;
use wingman_planning::scenario::Scenario;

mod flight;
mod mirror;
mod progress;

pub use flight::fly;

use crate::clock::ClockMode;
use crate::datalink::{Datalink, DatalinkError};
use crate::flight_log::LogError;
use crate::link::{LinkError, PlannerLink};
use crate::process::ProcessError;
use crate::resume::{self, ResumeError, Resumed};
use crate::sensor::SensorError;
use crate::tracker::{Hold, ReceivedPlan, TrackerSample};

/// Where the planner comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum PlannerMode {
    /// Start `wingman-planner serve` (this binary, or the one next to the harness).
    Spawn { binary: Option<PathBuf> },
    /// Use a planner already serving the vehicle id.
    External,
}

/// Everything a flight needs.
#[derive(Debug, Clone)]
pub struct FlyOptions {
    pub scenario: Scenario,
    pub clock: ClockMode,
    pub out_dir: PathBuf,
    pub planner: PlannerMode,
    /// The planner's configuration (its `vehicle_id` is the flight's).
    pub planner_config: ServiceConfig,
    /// Harness step (tracker, ownship, clock), s.
    pub step_s: f64,
    /// Rate of `LeadState`, Hz.
    pub lead_rate_hz: f64,
    /// End of the flight if the plan has not ended by then (`None`: three times the first
    /// plan's duration, at least ten minutes more).
    pub time_limit_s: Option<f64>,
    /// Longest wall-clock wait for the planner in one step.
    pub planner_timeout: Duration,
    /// Print a progress line on stderr.
    pub progress: bool,
    /// Faults injected into the flight (fault-tolerance tests); none by default.
    pub faults: Faults,
    /// Resume the mission the (external) planner is flying instead of starting it
    /// (`fly --resume`, see [`crate::resume`]).
    pub resume: bool,
    /// Longest wait for the planner's status and plan when resuming.
    pub resume_wait: Duration,
}

/// Faults the harness can inject into a flight, for the fault-tolerance tests of
/// `tests/tests/faults.rs` (`fly --kill-planner-at`, `--popup-burst-at`). None by default.
#[derive(Debug, Clone, PartialEq)]
pub struct Faults {
    /// SIGKILL the spawned planner at this mission time (no clean-up: its iceoryx2
    /// resources stay behind), fly on without a planner for [`Faults::restart_after_s`]
    /// (the tracker keeps flying the last plan; the lock-step clock does not wait), then
    /// start a new planner process on the same vehicle id, its log in
    /// `planner.restart.log`. The new planner must clean up the dead node and take the
    /// world from the services' history.
    pub kill_planner_at_s: Option<f64>,
    /// Mission time without a planner after the kill, s.
    pub restart_after_s: f64,
    /// From this mission time on, over one second of mission time, send
    /// [`Faults::popup_burst_count`] static pop-up reports centred on the flown plan 60 s
    /// ahead (4 threat ids re-reported at new places, 300 m radius). They are not part of
    /// the scenario's truth, so the report's metrics do not count them.
    pub popup_burst_at_s: Option<f64>,
    /// Pop-up reports in the burst.
    pub popup_burst_count: u32,
}

impl Default for Faults {
    fn default() -> Self {
        Faults {
            kill_planner_at_s: None,
            restart_after_s: 10.0,
            popup_burst_at_s: None,
            popup_burst_count: 100,
        }
    }
}

/// First threat id of the burst's pop-ups (clear of the scenario's ids).
const BURST_ID_BASE: u32 = 1000;
/// Threat ids the burst cycles through.
const BURST_IDS: u32 = 4;

/// The `k`-th pop-up of a burst of `count`, sent at `t`, centred on `plan` 60 s ahead
/// (spread along it by the pop-up's rank).
fn burst_popup(plan: &wingman_interfaces::Plan, t: f64, k: u32, count: u32) -> ThreatReport {
    let ahead = t + 60.0 + 20.0 * f64::from(k) / f64::from(count.max(1));
    let (x, _) = crate::tracker::reference(plan, ahead);
    let model = plan.model().unwrap_or(Model::TwoD);
    let mut r = ThreatReport::zeroed();
    r.threat_id = BURST_ID_BASE + k % BURST_IDS;
    r.kind = ThreatKind::Static.to_wire();
    r.name = threat_name(&format!("burst-{}", k % BURST_IDS));
    r.appeared_at_s = t;
    r.center_m = position(model, &x);
    r.axes_m = match model {
        Model::TwoD => [300.0, 300.0, 0.0],
        Model::ThreeD => [300.0, 300.0, 300.0],
    };
    r.exponents = [2.0, 2.0, 2.0];
    r
}

impl FlyOptions {
    /// Defaults for `sc`: fast clock, `runs/<name>/`, a spawned planner with
    /// [`harness_planner_config`] on a fresh vehicle id.
    pub fn new(sc: Scenario) -> FlyOptions {
        let vehicle = unique_vehicle_id("fly");
        FlyOptions {
            out_dir: PathBuf::from("runs").join(&sc.name),
            scenario: sc,
            clock: ClockMode::Fast,
            planner: PlannerMode::Spawn { binary: None },
            planner_config: harness_planner_config(&vehicle),
            step_s: 0.1,
            lead_rate_hz: 5.0,
            time_limit_s: None,
            planner_timeout: Duration::from_secs(300),
            progress: true,
            faults: Faults::default(),
            resume: false,
            resume_wait: resume::RESUME_WAIT,
        }
    }
}

/// The planner configuration the harness flies with: the deployment defaults
/// (`planner.toml`: its budgets, compute gate and triggers), with a faster heartbeat. What
/// users run is what a flight measures; a plan its deadline cuts carries its cuts, and
/// `replay` takes them again (docs/ARCHITECTURE.md, "Deadline cuts").
pub fn harness_planner_config(vehicle_id: &str) -> ServiceConfig {
    let mut c = ServiceConfig {
        vehicle_id: vehicle_id.to_string(),
        ..ServiceConfig::default()
    };
    c.status.heartbeat_ms = 200;
    c
}

/// A vehicle id no other run on this host uses: `tag`, the process id and a clock reading.
pub fn unique_vehicle_id(tag: &str) -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    format!("{tag}-{}-{nanos:x}", std::process::id())
}

/// A flight could not be flown.
#[derive(Debug, thiserror::Error)]
pub enum FlyError {
    #[error("scenario: {0}")]
    Problem(#[from] ProblemError),
    #[error("datalink: {0}")]
    Datalink(#[from] DatalinkError),
    #[error("sensor: {0}")]
    Sensor(#[from] SensorError),
    #[error("vehicle: {0}")]
    Vehicle(#[from] wingman_planning::dynamics::DynamicsError),
    #[error("planner configuration: {0}")]
    Config(#[from] wingman_ipc::config::ConfigError),
    #[error("planner process: {0}")]
    Process(#[from] ProcessError),
    #[error("{0}")]
    Link(#[from] LinkError),
    #[error("flight log: {0}")]
    Log(#[from] LogError),
    #[error("{what}: {source}")]
    Io {
        what: String,
        source: std::io::Error,
    },
    #[error("{0}")]
    Planner(String),
    #[error(transparent)]
    Resume(#[from] ResumeError),
}

/// How a flight ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndReason {
    /// The flown plan reached its end.
    PlanEnded,
    /// The time limit came first.
    TimeLimit,
}

/// The keep-out estimate of a moving threat when a plan was made.
#[derive(Debug, Clone, Copy)]
pub struct EstimateSnapshot {
    pub plan_id: u64,
    /// Index of the moving threat (scenario order).
    pub threat: usize,
    /// Mission time the region is drawn for (the plan's trigger time).
    pub at_s: f64,
    pub estimate: Estimate,
}

/// What a flight produced.
#[derive(Debug, Clone)]
pub struct Flight {
    pub scenario: Scenario,
    pub vehicle_id: String,
    pub clock: ClockMode,
    pub planner_config: ServiceConfig,
    /// The tracker after every step, from the start.
    pub samples: Vec<TrackerSample>,
    /// Every plan received.
    pub plans: Vec<ReceivedPlan>,
    pub holds: Vec<Hold>,
    /// True positions of each moving threat at every step (`t`, position).
    pub truth: Vec<Vec<(f64, [f64; 3])>>,
    /// The moving threats' estimates (the planner's filter, mirrored) at each plan.
    pub estimates: Vec<EstimateSnapshot>,
    pub datalink: Datalink,
    pub end_s: f64,
    pub end: EndReason,
    pub last_status: Option<PlannerStatus>,
    /// Planner messages that failed `validate()`.
    pub rejected: u64,
    /// Wall-clock duration of the flight.
    pub wall: Duration,
    /// Where a resumed flight (`fly --resume`) took the mission over (`None`: flown from
    /// the start). The samples, the truth and every plan then begin at the resume.
    pub resumed: Option<Resumed>,
}

/// The time limit of a flight whose first plan ends at `final_s`: three times the plan's
/// duration, at least ten minutes more.
fn default_time_limit(t0: f64, final_s: f64) -> f64 {
    let duration = final_s - t0;
    t0 + (3.0 * duration).max(duration + 600.0)
}

/// Waits (at most `wait` from `since`) for the planner's current plan — the `plan`
/// service's history (`early`: plans taken with the first status), then whatever it
/// publishes — with the planner not planning and the plan the one its status names.
/// Returns the newest plan and the invalid messages dropped. A planner still planning at the limit is resumed on the plan it has (the
/// plan it is computing arrives as any re-plan).
fn wait_for_plan(
    link: &mut PlannerLink,
    early: Vec<Box<Plan>>,
    vehicle: &str,
    wait: Duration,
    since: Instant,
) -> Result<(Box<Plan>, u64), FlyError> {
    let mut newest: Option<Box<Plan>> = None;
    let mut rejected = 0;
    let mut taken = early;
    loop {
        for p in taken.drain(..) {
            if newest.as_ref().is_none_or(|n| p.plan_id > n.plan_id) {
                newest = Some(p);
            }
        }
        let status = link.status();
        let idle = status.is_some_and(|s| s.state() != Some(PlannerState::Planning));
        let current = match (&newest, status) {
            (Some(p), Some(s)) => p.plan_id >= s.current_plan_id,
            _ => false,
        };
        if idle && current {
            break;
        }
        if since.elapsed() > wait {
            if newest.is_some() {
                tracing::warn!(
                    planning = !idle,
                    newer_announced = !current,
                    "resuming on the newest plan received: the planner is still planning or \
                     announces a newer plan"
                );
            }
            break;
        }
        link.wait(Duration::from_millis(100))?;
        let r = link.poll()?;
        rejected += r.rejected;
        taken = r.plans;
    }
    let plan = newest.ok_or_else(|| ResumeError::NoPlan {
        service: service_name(vehicle, Service::Plan).unwrap_or_default(),
        within_s: wait.as_secs_f64(),
    })?;
    Ok((plan, rejected))
}

fn no_status(vehicle: &str, wait: Duration) -> ResumeError {
    ResumeError::NoStatus {
        service: service_name(vehicle, Service::Status).unwrap_or_default(),
        within_s: wait.as_secs_f64(),
    }
}

/// Position of a state (z = 0 in 2-D).
pub fn position(model: Model, x: &[f64; 7]) -> [f64; 3] {
    match model {
        Model::TwoD => [x[0], x[1], 0.0],
        Model::ThreeD => [x[0], x[1], x[2]],
    }
}
