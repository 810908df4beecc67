//! `fly-all`: every canonical scenario flown in turn (fast clock unless told otherwise),
//! each flight's log replayed, and the table of outcomes that `docs/RESULTS.md` holds.

use std::path::{Path, PathBuf};
use std::time::Duration;

use wingman_planning::scenario::Scenario;

use crate::mission::{self, FlyOptions};
use crate::replay::{self, ReplayOutcome};
use crate::report::{REACHED_M, Report};

/// One scenario's row.
#[derive(Debug, Clone)]
pub struct Row {
    pub scenario: String,
    /// The report, or why the flight failed.
    pub report: Result<Report, String>,
    pub replay: Option<Result<ReplayOutcome, String>>,
}

impl Row {
    /// Whether the scenario's threats can be avoided (its name does not say
    /// "unavoidable"): then the flown path must keep min F >= 1.
    pub fn avoidable(&self) -> bool {
        !self.scenario.contains("unavoidable")
    }

    /// The criteria: completed (targets and end within 100 m), min F >= 1 when
    /// avoidable, and (when replayed) every plan identical.
    pub fn passes(&self) -> bool {
        let Ok(r) = &self.report else {
            return false;
        };
        let safe = !self.avoidable() || r.min_f_static.is_none_or(|f| f >= 1.0);
        let replay_ok = match &self.replay {
            None => true,
            Some(Ok(o)) => o.all_identical(),
            Some(Err(_)) => false,
        };
        r.completed && safe && replay_ok
    }
}

/// Flies each scenario with `base` options (its output in `out_root/<name>/`, a fresh
/// vehicle id each), replays its log if asked, and returns the rows.
pub fn fly_all(
    scenarios: &[Scenario],
    base: &FlyOptions,
    out_root: &Path,
    with_replay: bool,
) -> Vec<Row> {
    let mut rows = Vec::new();
    for sc in scenarios {
        let mut opts = base.clone();
        opts.scenario = sc.clone();
        opts.out_dir = out_root.join(&sc.name);
        opts.planner_config.vehicle_id = mission::unique_vehicle_id("fly-all");
        let report = crate::run_fly(&opts).map(|(report, _)| report);
        let report = report.map_err(|e| format!("{e:#}"));
        match &report {
            Ok(r) => eprintln!(
                "{}: {} ({} plans)",
                sc.name,
                if r.completed {
                    "completed"
                } else {
                    "NOT completed"
                },
                r.plans.len()
            ),
            Err(e) => eprintln!("{}: failed: {e}", sc.name),
        }
        let replay = (with_replay && report.is_ok()).then(|| {
            replay::replay(&opts.out_dir.join("flight.log"), Duration::from_secs(300))
                .map_err(|e| e.to_string())
        });
        match &replay {
            Some(Ok(o)) if !o.all_identical() => eprintln!("{o}"),
            Some(Err(e)) => eprintln!("{}: replay failed: {e}", sc.name),
            _ => {}
        }
        rows.push(Row {
            scenario: sc.name.clone(),
            report,
            replay,
        });
    }
    rows
}

/// The Markdown table of `rows`.
pub fn table(rows: &[Row]) -> String {
    let mut s = String::from(
        "| scenario | completed | target miss [m] | final / rendezvous error [m] | min F static (needs ≥ 1) | min F moving | ∫E dt [s] | end [s] | plans (trigger at s) | holds | replay |\n\
         |---|---|---|---:|---:|---:|---:|---:|---|---:|---|\n",
    );
    for row in rows {
        let Ok(r) = &row.report else {
            s.push_str(&format!(
                "| {} | **failed**: {} | | | | | | | | | |\n",
                row.scenario,
                row.report.as_ref().err().map_or("", String::as_str)
            ));
            continue;
        };
        let misses: Vec<String> = r
            .targets
            .iter()
            .map(|t| format!("{:.0}", t.miss_m))
            .collect();
        let plans: Vec<String> = r
            .plans
            .iter()
            .map(|p| format!("{} {:.0}", p.trigger, p.at_s))
            .collect();
        let min_f = r.min_f_static.map_or("-".to_string(), |f| {
            let need = if row.avoidable() {
                ""
            } else {
                " (unavoidable)"
            };
            format!("{f:.3}{need}")
        });
        let replay = match &row.replay {
            None => "-".to_string(),
            Some(Ok(o)) if o.all_identical() => {
                format!("{}/{} identical", o.identical, o.plans_logged)
            }
            Some(Ok(o)) => format!("**{}/{} identical**", o.identical, o.plans_logged),
            Some(Err(e)) => format!("**failed**: {e}"),
        };
        s.push_str(&format!(
            "| {} | {} | {} | {:.1} | {} | {} | {:.3} | {:.1} | {} | {} | {} |\n",
            row.scenario,
            if row.passes() { "yes" } else { "**no**" },
            misses.join(", "),
            r.final_error_m,
            min_f,
            r.min_f_moving
                .map_or("-".to_string(), |f| format!("{f:.3}")),
            r.exposure_integral,
            r.end_s,
            plans.join(", "),
            r.holds.len(),
            replay,
        ));
    }
    s.push_str(&format!(
        "\n{} of {} scenarios meet the criteria (targets and end within {REACHED_M:.0} m, min F ≥ 1 \
         on avoidable scenarios, every plan identical on replay).\n",
        rows.iter().filter(|r| r.passes()).count(),
        rows.len()
    ));
    s
}

/// The canonical scenarios: `dir/*.toml` in name order if `dir` exists, else the bundled
/// ones.
pub fn canonical(dir: &Path) -> Result<Vec<Scenario>, wingman_planning::scenario::ScenarioError> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "toml"))
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    if files.is_empty() {
        return wingman_planning::scenario::BUNDLED
            .iter()
            .filter_map(|(n, _)| wingman_planning::scenario::bundled(n))
            .collect();
    }
    files.iter().map(Scenario::load).collect()
}
