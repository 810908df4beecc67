//! The wingman simulation harness: everything around the planner process, emulated, and a
//! mission runner that flies a scenario end to end against the real `wingman-planner
//! serve` over iceoryx2. Its binary is `wingman-harness`.
//!
//! - [`datalink`]: the lead's datalink — tasking, lead route, lead state;
//! - [`sensor`]: the threat sensor — static threats, pop-ups, moving threats' seeded
//!   Gauss–Markov truth and noisy track fixes;
//! - [`tracker`]: the inner-loop tracker — flies the newest plan with the vehicle model and
//!   the tracking law, safe hold when no plan is valid, `OwnshipState`;
//! - [`truth`]: the truth model — wind and gusts, the aircraft's lagged response and its
//!   navigation errors (the scenario's `[wind]` and `[aircraft]`);
//! - [`clock`]: fast (lock-step), real-time and scaled mission clocks;
//! - [`link`]: the iceoryx2 ports (through the planner's `service::ipc`);
//! - [`process`]: the planner as a child process;
//! - [`mission`]: [`mission::fly`], the flight itself;
//! - [`flight_log`]: `flight.log`, every message both ways;
//! - [`report`], [`plots`]: `report.json` and the PNG plots;
//! - [`replay`]: a flown log's planner inputs fed to the planner in-process, every plan
//!   compared byte for byte;
//! - [`campaign`]: many random missions flown, judged against the yardstick, reported;
//! - [`resume`]: `fly --resume`, a new harness taking over the mission a planner flies
//!   after its harness died.

pub mod campaign;
pub mod clock;
pub mod datalink;
pub mod flight_log;
pub mod fly_all;
pub mod link;
pub mod mission;
pub mod plots;
pub mod process;
pub mod replay;
pub mod report;
pub mod resume;
pub mod sensor;
pub mod tracker;
pub mod truth;

use wingman_planning::scenario::{BUNDLED, DISTURBED, Scenario, ScenarioError, bundled};

/// One line per bundled scenario: name, then its summary.
pub fn list_bundled() -> Result<Vec<(String, String)>, ScenarioError> {
    BUNDLED
        .iter()
        .chain(DISTURBED)
        .filter_map(|(name, _)| bundled(name))
        .map(|sc| {
            let sc: Scenario = sc?;
            Ok((sc.name, sc.summary))
        })
        .collect()
}

/// Flies a mission and writes its outputs (`report.json`, `flight.log`, the plots) into
/// `opts.out_dir`; returns the report and a one-paragraph summary.
pub fn run_fly(opts: &mission::FlyOptions) -> anyhow::Result<(report::Report, String)> {
    use anyhow::Context;
    let flight = mission::fly(opts)?;
    let report = report::build(&flight).context("report")?;
    let path = opts.out_dir.join("report.json");
    let json = serde_json::to_string_pretty(&report).context("report as JSON")?;
    std::fs::write(&path, json + "\n").with_context(|| format!("write {}", path.display()))?;
    let pngs = plots::draw_all(&flight, &report, &opts.out_dir)
        .map_err(|e| anyhow::anyhow!("plots: {e}"))?;
    let text = summary(&report, &opts.out_dir, &pngs);
    Ok((report, text))
}

/// The lines `fly` prints at the end.
pub fn summary(r: &report::Report, out: &std::path::Path, pngs: &[String]) -> String {
    let targets: Vec<String> = r
        .targets
        .iter()
        .map(|t| format!("{:.0} m", t.miss_m))
        .collect();
    let mut s = format!(
        "{}{}: {} at t = {:.1} s ({}), targets missed by [{}], final error {:.1} m, min F static {}, \
         exposure {:.2} s, {} plan(s), {} re-plan(s), {} hold(s), {:.1} s wall\n",
        r.scenario,
        r.resumed_at_s.map_or(String::new(), |t| format!(
            " (resumed at {t:.1} s, {} target(s) passed before)",
            r.targets_before_resume.len()
        )),
        if r.completed {
            "COMPLETED"
        } else {
            "NOT COMPLETED"
        },
        r.end_s,
        r.end,
        targets.join(", "),
        r.final_error_m,
        r.min_f_static.map_or("-".into(), |f| format!("{f:.3}")),
        r.exposure_integral,
        r.plans.len(),
        r.replans,
        r.holds.len(),
        r.wall_s,
    );
    for p in &r.plans {
        s.push_str(&format!(
            "  plan {:>2} at {:7.1} s  {:<16} {:<9} {:<6} compute {:6.0} ms  cuts {:>2}  cost {:10.4}  \
             starts {:7.1} s\n",
            p.plan_id,
            p.at_s,
            p.trigger,
            p.quality,
            p.path,
            p.compute_ms,
            p.cuts,
            p.cost,
            p.start_s
        ));
    }
    s.push_str(&format!(
        "wrote {}/report.json, flight.log, planner.log, planner.toml{}",
        out.display(),
        pngs.iter().map(|p| format!(", {p}")).collect::<String>()
    ));
    s
}
