//! Benchmark of the seeds + particle swarm (issue 5) on every canonical scenario: wall
//! time per run (median and p95 over `SWARM_RUNS` runs with different seeds, default 20),
//! the swarm's best cost and objective against the reference optimum
//! (`tools/judge/costs.toml`), the spread of the objective across
//! seeds, and the best path's target and end pass distances. Numbers and the command are
//! in `docs/BENCHMARKS.md` (its swarm section).
//!
//! Environment: `SWARM_RUNS` (runs per scenario), `SWARM_ONLY` (substring filter on the
//! scenario name), `SWARM_THREADS`, `SWARM_PARTICLES`, `SWARM_ITERATIONS`, `SWARM_DT`,
//! `SWARM_SUBSTEPS` (override the defaults), `SWARM_EXPORT=DIR` (write the first run's
//! best path per scenario as `DIR/<scenario>.csv` in the judge's format).

use std::time::{Duration, Instant};

use wingman_interfaces::Model;
use wingman_planning::clock::{Deadline, MonotonicClock};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::{self, BUNDLED};
use wingman_planning::swarm::{self, SwarmSettings, SwarmWorkspace};
use wingman_planning::trajectory::Trajectory;

/// One scenario of the summary line.
struct Row {
    spatial: bool,
    median_ms: f64,
    /// The first run's objective over the reference cost.
    first: f64,
    /// The mean over the runs of the same.
    mean: f64,
}

fn env<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

/// `cost = ...` of each `[scenario]` table of the reference's costs.toml.
fn reference_costs() -> Vec<(String, f64)> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tools/judge/costs.toml");
    let Ok(text) = std::fs::read_to_string(path) else {
        return Vec::new();
    };
    let Ok(table) = text.parse::<toml::Table>() else {
        return Vec::new();
    };
    table
        .iter()
        .filter_map(|(k, v)| Some((k.clone(), v.get("cost")?.as_float()?)))
        .collect()
}

fn percentile(sorted: &[Duration], p: f64) -> Duration {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

fn write_csv(path: &str, model: Model, t: &Trajectory) -> std::io::Result<()> {
    use std::fmt::Write as _;
    let mut s = String::new();
    match model {
        Model::TwoD => {
            s.push_str("t,x,y,psi,u\n");
            for i in 0..t.len() {
                let (x, u) = (&t.states[i], &t.controls[i]);
                let _ = writeln!(s, "{},{},{},{},{}", t.times[i], x[0], x[1], x[2], u[0]);
            }
        }
        Model::ThreeD => {
            s.push_str("t,x,y,z,gamma,chi,nz,mu,u1,u2\n");
            for i in 0..t.len() {
                let (x, u) = (&t.states[i], &t.controls[i]);
                let _ = writeln!(
                    s,
                    "{},{},{},{},{},{},{},{},{},{}",
                    t.times[i], x[0], x[1], x[2], x[3], x[4], x[5], x[6], u[0], u[1]
                );
            }
        }
    }
    std::fs::write(path, s)
}

fn main() {
    // `cargo bench` passes `--bench`; ignore arguments.
    let runs: usize = env("SWARM_RUNS").unwrap_or(20).max(1);
    let only: Option<String> = env("SWARM_ONLY");
    let export: Option<String> = env("SWARM_EXPORT");
    let mut base = SwarmSettings::default();
    if let Some(v) = env("SWARM_THREADS") {
        base = base.with_threads(v);
    }
    if let Some(v) = env("SWARM_PARTICLES") {
        base = base.with_particles(v);
    }
    if let Some(v) = env("SWARM_ITERATIONS") {
        base = base.with_max_iterations(v);
    }
    if let Some(v) = env("SWARM_DT") {
        base = base.with_dt(v);
    }
    if let Some(v) = env("SWARM_SUBSTEPS") {
        base = base.with_substeps(v);
    }
    if let Some(v) = env("SWARM_MISS") {
        base = base.with_miss_weight(v);
    }
    if let Some(v) = env("SWARM_HEADING") {
        base = base.with_heading_weight(v);
    }
    if let Ok(v) = std::env::var("SWARM_BULGES") {
        let r: Vec<f64> = v.split(',').filter_map(|x| x.parse().ok()).collect();
        base.seeds = base.seeds.clone().with_bulge_ratios(&r);
    }
    if let Some(v) = env("SWARM_MAX_SEEDS") {
        base.seeds = base.seeds.clone().with_max_seeds(v);
    }
    if let Some(v) = env("SWARM_MERGE") {
        base = base.with_merge_fraction(v);
    }
    if let Some(v) = env("SWARM_GROUPS") {
        base = base.with_groups(v);
    }
    if std::env::var("SWARM_DIRECT").is_ok() {
        base = base.with_parameterisation(swarm::Parameterisation::Direct);
    }
    if let Some(v) = env("SWARM_STALL") {
        base = base.with_stall_iterations(v);
    }
    let refs = reference_costs();
    let clock = MonotonicClock::new();
    println!(
        "settings: particles {} iterations {} dt {} s substeps {} threads {} D* {} m; {runs} runs (seeds 0..{runs})",
        base.particles, base.max_iterations, base.dt, base.substeps, base.threads, base.d_star
    );
    println!(
        "{:<36} {:>8} {:>8} {:>6} {:>5} {:>10} {:>10} {:>10} {:>7} {:>7} {:>9} {:>14}  best seed",
        "scenario",
        "med ms",
        "p95 ms",
        "iters",
        "seeds",
        "swarm J",
        "ref J",
        "J/ref",
        "spread",
        "seed/J",
        "tf s",
        "passes m"
    );
    let mut summary: Vec<Row> = Vec::new();
    for (name, _) in BUNDLED {
        if only.as_deref().is_some_and(|o| !name.contains(o)) {
            continue;
        }
        let sc = match scenario::bundled(name) {
            Some(Ok(sc)) => sc,
            _ => continue,
        };
        let Ok(problem) = Problem::from_scenario(&sc) else {
            continue;
        };
        let mut ws = SwarmWorkspace::new(&base);
        let mut times = Vec::new();
        let mut objectives = Vec::new();
        let mut first = None;
        for r in 0..runs {
            let settings = base.clone().with_seed(r as u64);
            let t = Instant::now();
            let out = swarm::run(&problem, &settings, &mut ws, Deadline::never(&clock));
            times.push(t.elapsed());
            match out {
                Ok(o) => {
                    objectives.push(o.report.objective);
                    if let (Some(dir), true) = (&export, std::env::var("SWARM_EXPORT_ALL").is_ok())
                    {
                        let _ = std::fs::create_dir_all(dir);
                        let _ = write_csv(&format!("{dir}/{name}.r{r}.csv"), sc.model, &o.best);
                        for (k, c) in o.candidates.iter().enumerate() {
                            let _ = write_csv(
                                &format!("{dir}/{name}.r{r}.c{k}.csv"),
                                sc.model,
                                &c.trajectory,
                            );
                        }
                    }
                    if first.is_none() {
                        first = Some(o);
                    }
                }
                Err(e) => println!("{name}: error {e}"),
            }
        }
        times.sort();
        let Some(o) = first else { continue };
        if let Some(dir) = &export {
            let _ = std::fs::create_dir_all(dir);
            let _ = write_csv(&format!("{dir}/{name}.csv"), sc.model, &o.best);
            if std::env::var("SWARM_EXPORT_CANDIDATES").is_ok() {
                for (k, c) in o.candidates.iter().enumerate() {
                    let _ = write_csv(
                        &format!("{dir}/{name}.cand{k}={:.4}.csv", c.cost),
                        sc.model,
                        &c.trajectory,
                    );
                }
                let _ = std::fs::write(format!("{dir}/{name}.best_cost"), format!("{}", o.cost));
            }
            if std::env::var("SWARM_EXPORT_SEEDS").is_ok() {
                // The last run's seeds as flown, with their swarm cost in the file name.
                let sdir = format!("{dir}/{name}.seeds");
                let _ = std::fs::create_dir_all(&sdir);
                for i in 0..ws.seeds().len() {
                    let label = ws.seeds()[i].label().to_string().replace('/', "_");
                    if let Some((cost, _, t)) = ws.seed_trajectory(i) {
                        let _ = write_csv(&format!("{sdir}/{label}={cost:.4}.csv"), sc.model, &t);
                    }
                }
            }
        }
        let reference = refs.iter().find(|(k, _)| k == name).map(|(_, c)| *c);
        let lo = objectives.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = objectives.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if let Some(c) = reference
            && c > 1e-2
        {
            summary.push(Row {
                spatial: sc.model == Model::ThreeD,
                median_ms: percentile(&times, 0.5).as_secs_f64() * 1e3,
                first: o.report.objective / c,
                mean: objectives.iter().map(|j| j / c).sum::<f64>() / objectives.len() as f64,
            });
        }
        let passes: Vec<String> = o.report.pass_distances[..o.report.phases]
            .iter()
            .map(|d| format!("{d:.0}"))
            .collect();
        println!(
            "{:<36} {:>8.2} {:>8.2} {:>6} {:>5} {:>10.4} {:>10.4} {:>10.3} {:>7.3} {:>7.3} {:>9.1} {:>14}  {}",
            name,
            percentile(&times, 0.5).as_secs_f64() * 1e3,
            percentile(&times, 0.95).as_secs_f64() * 1e3,
            o.iterations,
            o.seeds,
            o.report.objective,
            reference.unwrap_or(f64::NAN),
            reference.map_or(f64::NAN, |c| o.report.objective / c),
            if lo.abs() > 0.0 {
                (hi - lo) / lo.abs()
            } else {
                0.0
            },
            o.seeds_best_cost / o.cost,
            o.report.final_time,
            passes.join("/"),
            o.seeds_best,
        );
    }
    for (label, three) in [("2-D", false), ("3-D", true)] {
        let rows: Vec<&Row> = summary.iter().filter(|r| r.spatial == three).collect();
        if rows.is_empty() {
            continue;
        }
        let n = rows.len() as f64;
        let geo = |f: fn(&Row) -> f64| (rows.iter().map(|r| f(r).ln()).sum::<f64>() / n).exp();
        println!(
            "{label}: max median {:.1} ms, geomean J/ref first run {:.4}, over all runs {:.4} (scenarios with ref J > 0.01)",
            rows.iter().map(|r| r.median_ms).fold(0.0, f64::max),
            geo(|r| r.first),
            geo(|r| r.mean),
        );
    }
}
