//! The offline `plan` command: plan a scenario's take-off plan and write it for the judge
//! and for people (`plan.csv`, `plan.json`), with a one-line summary.

use std::path::{Path, PathBuf};
use std::time::Duration;

use serde_json::json;
use wingman_interfaces::{Model, Quality};

use wingman_planning::clock::{Clock, Deadline};
use wingman_planning::cuts::{Cut, CutLog};
use wingman_planning::hybrid::{
    Exhaustive, PlanOutcome, Planner, PlannerSettings, plan_exhaustive,
};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::Scenario;

/// What to plan and where to write it.
#[derive(Debug, Clone)]
pub struct PlanRequest {
    pub scenario: Scenario,
    pub seed: u64,
    /// Compute budget; `None`: the model's default (with `exhaustive`: of each run).
    pub deadline: Option<Duration>,
    pub out_dir: PathBuf,
    /// Plan with the yardstick of global optimality instead of the deployment settings
    /// (`hybrid::plan_exhaustive`: this many runs, seeded from `seed` on).
    pub exhaustive_runs: Option<usize>,
}

/// Default compute budget of an offline plan.
pub fn default_deadline(model: Model) -> Duration {
    match model {
        Model::TwoD => Duration::from_millis(2000),
        Model::ThreeD => Duration::from_millis(5000),
    }
}

/// Plans the request and writes `plan.csv`, `plan.json` and `plan.png` into its folder.
pub fn plan_scenario(
    request: &PlanRequest,
    clock: &'static dyn Clock,
) -> anyhow::Result<PlanOutcome> {
    let problem = Problem::from_scenario(&request.scenario)?;
    let (outcome, cuts, seeds) = match request.exhaustive_runs {
        Some(runs) => plan_yardstick(request, &problem, runs, clock)?,
        None => plan_default(request, &problem, clock)?,
    };
    std::fs::create_dir_all(&request.out_dir)?;
    write_outputs(
        &request.out_dir,
        &request.scenario,
        &problem,
        &outcome,
        &cuts,
    )?;
    draw_plan(
        &request.out_dir.join("plan.png"),
        &request.scenario,
        &problem,
        seeds,
        &outcome,
    )
    .map_err(|e| anyhow::anyhow!("drawing plan.png: {e}"))?;
    Ok(outcome)
}

/// The seeds' paths, for the plot.
type SeedPaths = Vec<Vec<[f64; 2]>>;

/// A plan on the deployment settings: the outcome, its deadline cuts and the seeds.
fn plan_default(
    request: &PlanRequest,
    problem: &Problem,
    clock: &'static dyn Clock,
) -> anyhow::Result<(PlanOutcome, Vec<Cut>, SeedPaths)> {
    let mut settings = PlannerSettings::default();
    settings.swarm = settings.swarm.with_seed(request.seed);
    let budget = request
        .deadline
        .unwrap_or_else(|| default_deadline(problem.model));
    let mut planner = Planner::new(&settings);
    // Deadlines need `'static` parts; one small log per offline plan.
    let log: &'static CutLog = Box::leak(Box::new(CutLog::new()));
    log.begin(None);
    let deadline = Deadline::after(clock, budget).with_cuts(log);
    let outcome = planner.plan(problem, &settings, deadline)?;
    let seeds = planner
        .swarm_workspace()
        .seed_paths()
        .map(|(_, points)| points.iter().map(|p| [p[0], p[1]]).collect())
        .collect();
    Ok((outcome, log.finish(), seeds))
}

/// A plan of the yardstick (`runs` runs, each with the request's budget or 60 s); it
/// draws no seeds (each run has its own), and its cuts are counted, not listed.
fn plan_yardstick(
    request: &PlanRequest,
    problem: &Problem,
    runs: usize,
    clock: &'static dyn Clock,
) -> anyhow::Result<(PlanOutcome, Vec<Cut>, SeedPaths)> {
    let mut how = Exhaustive {
        runs,
        seed: request.seed,
        ..Exhaustive::default()
    };
    if let Some(budget) = request.deadline {
        how.budget = budget;
    }
    let o = plan_exhaustive(problem, &how, clock)?;
    if o.cuts > 0 {
        tracing::warn!(
            cuts = o.cuts,
            "the yardstick's budget cut its search: a longer --deadline-ms makes it independent of the machine"
        );
    }
    Ok((o.best, Vec::new(), Vec::new()))
}

/// `plan.png`: the threats, the seeds, the swarm's best and the final plan.
fn draw_plan(
    path: &Path,
    sc: &Scenario,
    problem: &Problem,
    seeds: SeedPaths,
    o: &PlanOutcome,
) -> Result<(), Box<dyn std::error::Error>> {
    use plotters::style::RGBColor;
    use wingman_plot::{MapMarker, MapPath, MapPlot, Stroke, draw_map};
    let xy = |s: &[f64; 7]| [s[0], s[1]];
    let mut paths = Vec::new();
    for (k, points) in seeds.into_iter().enumerate() {
        paths.push(MapPath {
            label: (k == 0).then(|| "spline seeds".to_string()),
            color: RGBColor(110, 110, 110),
            stroke: Stroke::Thin,
            points,
        });
    }
    if let Some(lead) = &problem.lead {
        let tf = o.trajectory.final_time().unwrap_or(problem.t0);
        let points = (0..=100)
            .map(|k| {
                let p = lead
                    .at(problem.t0 + (tf - problem.t0) * k as f64 / 100.0)
                    .position;
                [p[0], p[1]]
            })
            .collect();
        paths.push(MapPath {
            label: Some("lead until the rendezvous".into()),
            color: RGBColor(40, 150, 60),
            stroke: Stroke::Bold,
            points,
        });
    }
    paths.push(MapPath {
        label: Some(format!("swarm best (cost {:.4})", o.swarm_cost)),
        color: RGBColor(240, 140, 0),
        stroke: Stroke::Dashed,
        points: o.swarm_best.states.iter().map(xy).collect(),
    });
    paths.push(MapPath {
        label: Some(format!(
            "plan, {} (cost {:.4})",
            quality_name(o.quality),
            o.cost
        )),
        color: RGBColor(20, 70, 200),
        stroke: Stroke::Bold,
        points: o.trajectory.states.iter().map(xy).collect(),
    });
    let mut markers = vec![MapMarker {
        label: " start".into(),
        color: RGBColor(0, 0, 0),
        at: [problem.x0[0], problem.x0[1]],
    }];
    for (i, t) in problem.targets.iter().enumerate() {
        markers.push(MapMarker {
            label: format!(" target {}", i + 1),
            color: RGBColor(150, 0, 150),
            at: [t[0], t[1]],
        });
    }
    if let Some(f) = &problem.final_state {
        markers.push(MapMarker {
            label: " final point".into(),
            color: RGBColor(0, 0, 0),
            at: [f[0], f[1]],
        });
    }
    let plot = MapPlot {
        title: format!("{}: take-off plan", sc.name),
        problem,
        outlines: Vec::new(),
        paths,
        markers,
    };
    draw_map(path, &plot, (1100, 900))
}

fn quality_name(q: Quality) -> &'static str {
    q.name()
}

/// Writes `plan.json` and `plan.csv` (the judge's format) of `outcome` into `dir`; `cuts`:
/// where its deadline cut it.
pub fn write_outputs(
    dir: &Path,
    sc: &Scenario,
    problem: &Problem,
    o: &PlanOutcome,
    cuts: &[Cut],
) -> anyhow::Result<()> {
    let tr = &o.trajectory;
    std::fs::write(dir.join("plan.csv"), tr.to_csv(problem.model))?;
    let (nx, nu) = (problem.nx(), problem.nu());
    let doc = json!({
        "scenario": sc.name,
        "quality": quality_name(o.quality),
        "path": o.path.name(),
        "cuts": cuts.iter().map(ToString::to_string).collect::<Vec<_>>(),
        "cost": o.cost,
        "final_time_s": tr.final_time(),
        "phase_ends_s": tr.phase_ends,
        "swarm_cost": o.swarm_cost,
        "swarm_iterations": o.swarm_iterations,
        "nlp_iterations": o.nlp.iterations,
        "nlp_objective": o.nlp.objective,
        "mesh_intervals": o.nlp.intervals,
        "compute_ms": {
            "swarm": o.times.swarm.as_secs_f64() * 1e3,
            "nlp": o.times.nlp.as_secs_f64() * 1e3,
            "export": o.times.export.as_secs_f64() * 1e3,
            "total": o.times.total.as_secs_f64() * 1e3,
        },
        "times": tr.times,
        "states": tr.states.iter().map(|s| s[..nx].to_vec()).collect::<Vec<_>>(),
        "controls": tr.controls.iter().map(|u| u[..nu].to_vec()).collect::<Vec<_>>(),
    });
    std::fs::write(dir.join("plan.json"), serde_json::to_string_pretty(&doc)?)?;
    Ok(())
}

/// The one-line summary printed by the command.
pub fn summary(sc: &Scenario, o: &PlanOutcome) -> String {
    let exposure = wingman_planning::metrics::simpson_by(&o.trajectory.times, |_| 0.0);
    let _ = exposure;
    format!(
        "{}: quality {} cost {:.6} final time {:.2} s | swarm {:.1} ms ({} it, cost {:.4}) nlp {:.1} ms (it {:?}) export {:.1} ms total {:.1} ms",
        sc.name,
        quality_name(o.quality),
        o.cost,
        o.trajectory.final_time().unwrap_or(f64::NAN),
        o.times.swarm.as_secs_f64() * 1e3,
        o.swarm_iterations,
        o.swarm_cost,
        o.times.nlp.as_secs_f64() * 1e3,
        o.nlp.iterations,
        o.times.export.as_secs_f64() * 1e3,
        o.times.total.as_secs_f64() * 1e3,
    )
}
