//! The service's settings (`planner.toml`). Every setting has a default, so an empty file
//! (or no file) is a valid configuration; unknown keys are refused so a typo cannot
//! silently drop a setting. `planner.toml` at the repository root documents every key and
//! holds exactly these defaults (a test keeps them equal).

use std::path::Path;
use std::time::Duration;

use serde::{Deserialize, Serialize};
use wingman_interfaces::{Model, validate_vehicle_id};

/// A configuration that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{file}: cannot be read: {source}")]
    Read {
        file: String,
        source: std::io::Error,
    },
    #[error("{file}: {message}")]
    Parse { file: String, message: String },
    #[error("key `{key}`: {problem}")]
    Invalid { key: &'static str, problem: String },
}

/// Everything `wingman-planner serve` can be told.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ServiceConfig {
    /// Vehicle id: every service name starts with `wingman/<vehicle_id>/`.
    pub vehicle_id: String,
    pub budget: BudgetConfig,
    pub triggers: TriggerConfig,
    pub staleness: StalenessConfig,
    pub status: StatusConfig,
    pub solver: SolverConfig,
    pub scheduling: SchedulingConfig,
}

/// Compute budget of one plan, and the limits that keep bursts of triggers from starving
/// the flight computer.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BudgetConfig {
    /// Deadline of a 2-D take-off plan (trigger `Initial`), ms. The aircraft waits at the
    /// tasking's start for it, so it costs no mission time: long enough that the global
    /// search and its wave run to their end on a slow flight computer, and the take-off
    /// plan is the same on any computer that holds it.
    pub takeoff_2d_ms: u64,
    /// Deadline of a 3-D take-off plan, ms.
    pub takeoff_3d_ms: u64,
    /// Deadline of a 2-D plan made from scratch in flight, ms: a new tasking, a restart
    /// (nothing in flight to start from). A plan commits this long after it starts
    /// (mission time when it is started, which is later than its trigger if the compute
    /// gate deferred it).
    pub plan_2d_ms: u64,
    /// Deadline of a 3-D plan made from scratch in flight, ms.
    pub plan_3d_ms: u64,
    /// Deadline of a 2-D re-plan of the plan in flight (a pop-up, a moving threat's
    /// scheduled re-plan, a deviation, a lead-route change, an expiry), ms: the
    /// aircraft's reaction time. The re-plan starts from the plan in flight and then
    /// searches globally with the time left.
    pub replan_2d_ms: u64,
    /// Deadline of a 3-D re-plan of the plan in flight, ms.
    pub replan_3d_ms: u64,
    /// Deadline of a 2-D refinement (`Refine`: a plan published short of `Optimal`
    /// planned again at once), ms; taken between `replan_2d_ms` and `plan_2d_ms`.
    pub refine_2d_ms: u64,
    /// Deadline of a 3-D refinement, ms; taken between `replan_3d_ms` and `plan_3d_ms`.
    pub refine_3d_ms: u64,
    /// Least wall-clock time between the starts of two plans, ms.
    pub min_spacing_ms: u64,
    /// Share of one core the planner may spend planning over the sliding window (0–1].
    pub duty_cycle: f64,
    /// Length of the duty-cycle window, ms.
    pub duty_window_ms: u64,
}

impl BudgetConfig {
    /// The largest of the budgets, ms.
    pub fn largest_ms(&self) -> u64 {
        self.takeoff_2d_ms
            .max(self.takeoff_3d_ms)
            .max(self.plan_2d_ms)
            .max(self.plan_3d_ms)
            .max(self.replan_2d_ms)
            .max(self.replan_3d_ms)
    }
}

/// When to re-plan (FORMULATION.md §6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TriggerConfig {
    /// A pop-up re-plans when `F < f_star` at a remaining sample of the plan.
    pub f_star: f64,
    /// A cross-track deviation (from `OwnshipState`) beyond this re-plans, m.
    pub deviation_cross_m: f64,
    /// A vertical deviation beyond this re-plans (3-D), m.
    pub deviation_vertical_m: f64,
    /// Being ahead of or behind the plan beyond this re-plans, m (a constant airspeed
    /// cannot make it up; a gust or a wind the plan did not know builds it up).
    pub deviation_along_m: f64,
    /// The along-track bound in the last `deviation_end_window_s` of a plan that does not
    /// fix its final time (min-time, rendezvous), m: the deviation left at the end is the
    /// end's miss, and a new plan there only re-times the arrival. A fixed final time
    /// keeps `deviation_along_m` to its end: late in the mission no path makes up for it.
    pub deviation_along_end_m: f64,
    /// How long before a plan's final time `deviation_along_end_m` applies, s.
    pub deviation_end_window_s: f64,
    /// A scheduled re-plan time `t_r` is looked for only this long after a plan's start,
    /// s: a plan just made from the newest estimate is not re-made at once.
    pub replan_min_lead_s: f64,
    /// Before its first plan the service waits this long (wall clock) after the tasking
    /// for an ownship state, ms: a planner restarted mid-mission gets the tasking from
    /// history before the tracker's next state, and must plan from where the aircraft
    /// is (`Restart`), not from the tasking's start (`Initial`). With an ownship state at
    /// hand it plans at once.
    pub first_plan_wait_ms: u64,
    /// A plan made short of `Optimal` (its deadline cut the NLP: mostly a short re-plan) is
    /// planned again once, from the last plan the NLP made, with the `refine_*_ms` budget
    /// (`Refine`).
    pub refine: bool,
    /// A rendezvous re-plans (`LeadOffRoute`) when the lead's observed state, flown on
    /// straight, would put it this far from where the held route puts it at the planned
    /// meeting time, m: a lead that turned or changed speed without a new route.
    pub lead_off_route_m: f64,
}

/// Inputs that stop arriving are reported in `PlannerStatus::stale_inputs` (wall clock).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StalenessConfig {
    /// Lead state (rendezvous missions only), ms.
    pub lead_ms: u64,
    /// Ownship state, ms.
    pub ownship_ms: u64,
    /// Track fixes of a known moving threat, ms.
    pub tracks_ms: u64,
}

/// The heartbeat.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StatusConfig {
    /// `PlannerStatus` is published at least this often, ms.
    pub heartbeat_ms: u64,
}

/// The message thread's place in the kernel's scheduler (see `service::sched`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SchedulingConfig {
    /// Fair-scheduler slice of the message thread, µs (100-100000; 0 keeps the kernel's
    /// default). A short slice lets a message wake the thread at once on a core a busy
    /// process holds; its CPU share is unchanged. Kernels before 6.12 ignore it.
    pub message_slice_us: u64,
}

/// The hybrid planner on the solve thread.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverConfig {
    /// Seed of the particle swarm (same inputs and seed: same plan).
    pub seed: u64,
    /// Threads a plan runs on: the particle swarm's workers, and the NLP starts solved
    /// side by side (`PlannerSettings::threads`). 1 keeps planning on one core. The
    /// duty-cycle cap counts a plan's budget once per thread. (`swarm_threads`, its old
    /// name, is read too.)
    #[serde(alias = "swarm_threads")]
    pub threads: usize,
    /// Plans as if in still air, whatever wind the tasking gives (`Tasking.wind_mps`): the
    /// comparison a wind-aware plan is measured against. false: plans in that wind.
    pub still_air: bool,
}

impl Default for ServiceConfig {
    fn default() -> Self {
        ServiceConfig {
            vehicle_id: "w1".into(),
            budget: BudgetConfig::default(),
            triggers: TriggerConfig::default(),
            staleness: StalenessConfig::default(),
            status: StatusConfig::default(),
            solver: SolverConfig::default(),
            scheduling: SchedulingConfig::default(),
        }
    }
}

impl Default for BudgetConfig {
    fn default() -> Self {
        BudgetConfig {
            takeoff_2d_ms: 2000,
            takeoff_3d_ms: 2500,
            plan_2d_ms: 500,
            plan_3d_ms: 2500,
            replan_2d_ms: 100,
            replan_3d_ms: 300,
            refine_2d_ms: 500,
            refine_3d_ms: 1200,
            min_spacing_ms: 250,
            duty_cycle: 0.5,
            duty_window_ms: 10_000,
        }
    }
}

impl Default for TriggerConfig {
    fn default() -> Self {
        TriggerConfig {
            f_star: 1.0,
            deviation_cross_m: 500.0,
            deviation_vertical_m: 200.0,
            deviation_along_m: 100.0,
            deviation_along_end_m: 50.0,
            deviation_end_window_s: 180.0,
            replan_min_lead_s: 1.0,
            first_plan_wait_ms: 300,
            refine: true,
            lead_off_route_m: 1000.0,
        }
    }
}

impl Default for StalenessConfig {
    fn default() -> Self {
        StalenessConfig {
            lead_ms: 2000,
            ownship_ms: 1000,
            tracks_ms: 5000,
        }
    }
}

impl Default for StatusConfig {
    fn default() -> Self {
        StatusConfig { heartbeat_ms: 1000 }
    }
}

impl Default for SchedulingConfig {
    fn default() -> Self {
        SchedulingConfig {
            message_slice_us: 100,
        }
    }
}

impl Default for SolverConfig {
    fn default() -> Self {
        SolverConfig {
            seed: 1,
            threads: 2,
            still_air: false,
        }
    }
}

/// Most plan intervals the duty-cycle window keeps (see `budget::ComputeGate`).
pub const DUTY_HISTORY: usize = 256;

impl ServiceConfig {
    /// Parses TOML text; `file` names it in errors. The result is validated.
    pub fn from_toml(text: &str, file: &str) -> Result<ServiceConfig, ConfigError> {
        let cfg: ServiceConfig = toml::from_str(text).map_err(|e| ConfigError::Parse {
            file: file.to_string(),
            message: e.to_string().trim_end().replace('\n', " "),
        })?;
        cfg.validate()?;
        Ok(cfg)
    }

    /// Reads and validates a configuration file.
    pub fn load(path: impl AsRef<Path>) -> Result<ServiceConfig, ConfigError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
            file: file.clone(),
            source,
        })?;
        Self::from_toml(&text, &file)
    }

    /// The configuration as TOML (what `serve --print-config` shows).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// Checks ranges and consistency.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bad = |key: &'static str, problem: String| Err(ConfigError::Invalid { key, problem });
        if let Err(e) = validate_vehicle_id(&self.vehicle_id) {
            return bad("vehicle_id", e.to_string());
        }
        let b = &self.budget;
        for (key, ms) in [
            ("budget.takeoff_2d_ms", b.takeoff_2d_ms),
            ("budget.takeoff_3d_ms", b.takeoff_3d_ms),
            ("budget.plan_2d_ms", b.plan_2d_ms),
            ("budget.plan_3d_ms", b.plan_3d_ms),
            ("budget.replan_2d_ms", b.replan_2d_ms),
            ("budget.replan_3d_ms", b.replan_3d_ms),
            ("budget.refine_2d_ms", b.refine_2d_ms),
            ("budget.refine_3d_ms", b.refine_3d_ms),
        ] {
            if ms == 0 {
                return bad(key, "must be positive".into());
            }
        }
        if self.solver.threads == 0 {
            return bad("solver.threads", "must be at least 1".into());
        }
        if !(b.duty_cycle > 0.0 && b.duty_cycle <= 1.0) {
            return bad(
                "budget.duty_cycle",
                format!("must be in (0, 1], got {}", b.duty_cycle),
            );
        }
        if b.duty_window_ms == 0 {
            return bad("budget.duty_window_ms", "must be positive".into());
        }
        let cap_ms = b.duty_cycle * b.duty_window_ms as f64;
        let threads = self.solver.threads;
        let largest = b.largest_ms() as f64 * threads as f64;
        if cap_ms < largest {
            return bad(
                "budget.duty_cycle",
                format!(
                    "duty_cycle x duty_window_ms = {cap_ms} ms is less than the core time one \
                     plan may use (its budget x solver.threads {threads} = {largest} ms): no \
                     plan could ever start"
                ),
            );
        }
        let spacing = b.min_spacing_ms.max(1);
        if b.duty_window_ms / spacing > DUTY_HISTORY as u64 {
            return bad(
                "budget.min_spacing_ms",
                format!(
                    "duty_window_ms / min_spacing_ms must be at most {DUTY_HISTORY} (plans the \
                     window can hold)"
                ),
            );
        }
        let t = &self.triggers;
        if !(t.f_star.is_finite() && t.f_star > 0.0) {
            return bad(
                "triggers.f_star",
                format!("must be positive, got {}", t.f_star),
            );
        }
        for (key, v) in [
            ("triggers.deviation_cross_m", t.deviation_cross_m),
            ("triggers.deviation_vertical_m", t.deviation_vertical_m),
            ("triggers.deviation_along_m", t.deviation_along_m),
            ("triggers.deviation_along_end_m", t.deviation_along_end_m),
            ("triggers.lead_off_route_m", t.lead_off_route_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(key, format!("must be positive, got {v}"));
            }
        }
        if !(t.deviation_end_window_s.is_finite() && t.deviation_end_window_s >= 0.0) {
            return bad(
                "triggers.deviation_end_window_s",
                "must not be negative".into(),
            );
        }
        if !(t.replan_min_lead_s.is_finite() && t.replan_min_lead_s >= 0.0) {
            return bad("triggers.replan_min_lead_s", "must not be negative".into());
        }
        if t.first_plan_wait_ms > 60_000 {
            return bad(
                "triggers.first_plan_wait_ms",
                "must be at most 60000 (a first plan would wait a minute)".into(),
            );
        }
        if self.status.heartbeat_ms == 0 {
            return bad("status.heartbeat_ms", "must be positive".into());
        }
        let slice = self.scheduling.message_slice_us;
        if slice != 0 && !(100..=100_000).contains(&slice) {
            return bad(
                "scheduling.message_slice_us",
                format!("must be 0 (the kernel's default) or 100-100000 µs, got {slice}"),
            );
        }
        let s = &self.staleness;
        if s.lead_ms == 0 || s.ownship_ms == 0 || s.tracks_ms == 0 {
            return bad("staleness", "bounds must be positive".into());
        }
        Ok(())
    }

    /// Compute budget of the take-off plan of `model`.
    pub fn takeoff_budget(&self, model: Model) -> Duration {
        Duration::from_millis(match model {
            Model::TwoD => self.budget.takeoff_2d_ms,
            Model::ThreeD => self.budget.takeoff_3d_ms,
        })
    }

    /// Compute budget of one plan of `model` made from scratch in flight.
    pub fn plan_budget(&self, model: Model) -> Duration {
        Duration::from_millis(match model {
            Model::TwoD => self.budget.plan_2d_ms,
            Model::ThreeD => self.budget.plan_3d_ms,
        })
    }

    /// Compute budget of one re-plan of `model` from the plan in flight.
    pub fn replan_budget(&self, model: Model) -> Duration {
        Duration::from_millis(match model {
            Model::TwoD => self.budget.replan_2d_ms,
            Model::ThreeD => self.budget.replan_3d_ms,
        })
    }

    /// Deadline of a refinement of a plan of `model` (`Refine`): between the re-plan's and
    /// the plan-from-scratch budget (a refinement is never shorter than the re-plan it
    /// refines).
    pub fn refine_budget(&self, model: Model) -> Duration {
        let b = &self.budget;
        Duration::from_millis(match model {
            Model::TwoD => b.refine_2d_ms.min(b.plan_2d_ms).max(b.replan_2d_ms),
            Model::ThreeD => b.refine_3d_ms.min(b.plan_3d_ms).max(b.replan_3d_ms),
        })
    }

    /// Heartbeat period.
    pub fn heartbeat(&self) -> Duration {
        Duration::from_millis(self.status.heartbeat_ms)
    }
}
