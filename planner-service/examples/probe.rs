//! Tuning probe of the hybrid planner: plans bundled scenarios with the default settings,
//! overridden by environment variables, and prints per scenario the median plan time, its
//! split, the NLP iterations and the planner's own cost against the reference optimum.
//!
//! `cargo run --release -p wingman-planner --example probe -- [NAME-FILTER] [RUNS]`
//!
//! Overrides: `PROBE_SW_ITERS`, `PROBE_SW_STALL`, `PROBE_SW_PARTICLES`, `PROBE_SW_THREADS` (the swarm's), `PROBE_STARTS`, `PROBE_FINALISTS`, `PROBE_ROUNDS`, `PROBE_RANK_PTS`,
//! `PROBE_RANK_S`, `PROBE_MESH_PTS`, `PROBE_MESH_S`, `PROBE_THREADS`, `PROBE_DEFECT_TOL`
//! (the refinement's tolerance, m), `PROBE_MAX_SPLIT` (its most parts per interval),
//! `PROBE_CROSSING` (the finalists' crossing split's threshold; 0: none), `PROBE_DUP_TOL` and `PROBE_GAP_TOL` (the finalists'
//! duplicate and gap tolerances),
//! `PROBE_NLP="name=value;name=value"` (extra solver options; `PROBE_RANK_NLP` and
//! `PROBE_FINAL_NLP` for the ranking or the working-mesh solves only, `PROBE_FIN_NLP` for the
//! finalists' only, `PROBE_REF_NLP` for the refined solves only); `PROBE_FIN_TOL`, `PROBE_FIN_ACC`, `PROBE_FIN_SOC=0|1` (the finalists'
//! tolerance, acceptable tolerance, second-order check); `PROBE_RANK_FEAS` (the largest
//! scaled violation of a ranking solve that still ranks); `PROBE_FIRST_SEED` (1);
//! `PROBE_KKT=feral|structured` (the KKT linear solver of every NLP solve);
//! `PROBE_SOC=0|1` and `PROBE_TOL` (the second-order check and the tolerance of the
//! refined solves);
//! `PROBE_ITS=1` prints every plan's NLP iterations per solve (deterministic, unlike times),
//! and with `PROBE_MESH=1` its final mesh's intervals per phase;
//! `PROBE_OUT=DIR` writes
//! each plan's `plan.json` / `plan.csv` into `DIR/NAME-SEED/` for the judge;
//! `PROBE_PAIR="NAME=VALUE"` times every seed twice against itself, with the settings of the
//! environment (A) and with the override `NAME=VALUE` on top (B; the variable is also set
//! while B plans, for what reads it at plan time), in the order A B B A, and prints
//! `PAIR name seed A-ms B-ms` (the means of each pair) and per scenario the median of the
//! B/A ratios: a comparison that a slow spell of the host weighs on alike.

use std::sync::Arc;
use std::time::Duration;

use wingman_planning::clock::{Deadline, MonotonicClock};
use wingman_planning::collocation::KktSolver;
use wingman_planning::collocation::kkt::KktCache;
use wingman_planning::hybrid::{Planner, PlannerSettings};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::{BUNDLED, bundled};

fn env<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

/// The solver options `name=value;name=value` of environment variable `name`.
fn extra_options(name: &str) -> Vec<(String, String)> {
    std::env::var(name)
        .unwrap_or_default()
        .split(';')
        .filter_map(|kv| kv.split_once('='))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// The median (upper, for an even count) of `v`, which it leaves sorted.
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Sets (or with `None` removes) environment variable `name`. Called only between plans,
/// when the planner's threads have ended and the probe runs on one thread.
fn set_env(name: &str, value: Option<&str>) {
    // SAFETY: no other thread runs while the probe changes its environment.
    unsafe {
        match value {
            Some(v) => std::env::set_var(name, v),
            None => std::env::remove_var(name),
        }
    }
}

/// The planner's settings: the defaults with the `PROBE_*` overrides of the environment.
fn settings_from_env() -> PlannerSettings {
    let mut s = PlannerSettings::default();
    if let Some(v) = env("PROBE_SW_ITERS") {
        s.swarm.max_iterations = v;
    }
    if let Some(v) = env("PROBE_SW_STALL") {
        s.swarm.stall_iterations = v;
    }
    if let Some(v) = env("PROBE_SW_THREADS") {
        s.swarm.threads = v;
    }
    if let Some(v) = env("PROBE_SW_PARTICLES") {
        s.swarm.particles = v;
    }
    if let Some(v) = env("PROBE_STARTS") {
        s.starts = v;
    }
    if let Some(v) = env("PROBE_FINALISTS") {
        s.finalists = v;
    }
    if let Some(v) = env::<f64>("PROBE_CROSSING") {
        s.crossing_split = (v > 0.0).then_some(v);
    }
    if let Some(v) = env("PROBE_DUP_TOL") {
        s.finalist_duplicate_tol = v;
    }
    if let Some(v) = env("PROBE_GAP_TOL") {
        s.finalist_gap_tol = v;
    }
    if let Some(v) = env("PROBE_ROUNDS") {
        s.refine_rounds = v;
    }
    if let Some(v) = env("PROBE_RANK_PTS") {
        s.ranking_mesh.points = v;
        s.ranking_mesh_3d.points = v;
    }
    if let Some(v) = env("PROBE_RANK_S") {
        s.ranking_mesh.interval_s = v;
        s.ranking_mesh_3d.interval_s = v;
    }
    if let Some(v) = env("PROBE_MESH_PTS") {
        s.mesh.points = v;
    }
    if let Some(v) = env("PROBE_MESH_S") {
        s.mesh.interval_s = v;
    }
    if let Some(v) = env("PROBE_DEFECT_TOL") {
        s.refine.defect_tol_m = v;
    }
    if let Some(v) = env::<usize>("PROBE_MAX_SPLIT") {
        s.refine.max_split = v;
    }
    if let Some(v) = env("PROBE_THREADS") {
        s.threads = v;
    }
    if let Some(v) = env::<u8>("PROBE_WARM") {
        s.warm_mesh_changes = v != 0;
    }
    if let Some(v) = env("PROBE_WARM_MU") {
        s.nlp.warm_start_mu_init = v;
        s.finalist_nlp.warm_start_mu_init = v;
    }
    if let Some(v) = env("PROBE_WARM_PUSH") {
        s.nlp.warm_start_push = v;
        s.finalist_nlp.warm_start_push = v;
    }
    if let Ok(v) = std::env::var("PROBE_KKT") {
        let kkt = match v.as_str() {
            "feral" => KktSolver::Feral,
            "structured" => KktSolver::Structured,
            other => panic!("PROBE_KKT={other}: feral or structured"),
        };
        s.nlp.kkt = kkt;
        s.finalist_nlp.kkt = kkt;
        s.ranking_nlp.kkt = kkt;
    }
    s.nlp.extra.extend(extra_options("PROBE_NLP"));
    s.finalist_nlp.extra.extend(extra_options("PROBE_NLP"));
    s.ranking_nlp.extra.extend(extra_options("PROBE_NLP"));
    s.nlp.extra.extend(extra_options("PROBE_FINAL_NLP"));
    s.finalist_nlp
        .extra
        .extend(extra_options("PROBE_FINAL_NLP"));
    s.nlp.extra.extend(extra_options("PROBE_REF_NLP"));
    s.finalist_nlp.extra.extend(extra_options("PROBE_FIN_NLP"));
    if let Some(v) = env::<u8>("PROBE_SOC") {
        s.nlp.second_order_check = v != 0;
    }
    if let Some(v) = env("PROBE_TOL") {
        s.nlp.tol = v;
    }
    if let Some(v) = env("PROBE_FIN_TOL") {
        s.finalist_nlp.tol = v;
    }
    if let Some(v) = env("PROBE_FIN_ACC") {
        s.finalist_nlp.acceptable_tol = v;
    }
    if let Some(v) = env::<u8>("PROBE_FIN_SOC") {
        s.finalist_nlp.second_order_check = v != 0;
    }
    if let Some(v) = env("PROBE_RANK_FEAS") {
        s.ranking_feasibility_tol = v;
    }
    s.ranking_nlp.extra.extend(extra_options("PROBE_RANK_NLP"));
    s
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let filter = args.get(1).cloned().unwrap_or_default();
    let runs: u64 = args.get(2).and_then(|v| v.parse().ok()).unwrap_or(3);
    // The KKT workspaces and factorisation counts of every planner below.
    let kkt = Arc::new(KktCache::new());
    let refs: toml::Table = toml::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tools/judge/costs.toml"
        ))
        .unwrap_or_default(),
    )
    .unwrap_or_default();
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    let s = settings_from_env();
    // Paired timing: `PROBE_PAIR="NAME=VALUE"` plans every seed with the settings above and
    // with NAME=VALUE set on top, alternately (A B B A), and prints both times.
    let pair = std::env::var("PROBE_PAIR").ok().and_then(|kv| {
        let (name, value) = kv.split_once('=')?;
        let (name, value) = (name.to_string(), value.to_string());
        let before = std::env::var(&name).ok();
        set_env(&name, Some(&value));
        let b = settings_from_env();
        set_env(&name, before.as_deref());
        Some((b, name, value, before))
    });
    let mut worst = 0.0f64;
    for (name, _) in BUNDLED {
        if !name.contains(filter.as_str()) {
            continue;
        }
        let problem = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
        let reference = refs
            .get(*name)
            .and_then(|t| t.get("cost"))
            .and_then(|c| c.as_float())
            .unwrap_or(f64::NAN);
        let mut times = Vec::new();
        let mut swarm_times = Vec::new();
        let mut line = String::new();
        let mut ratios = Vec::new();
        let mut pairs: Vec<(f64, f64)> = Vec::new();
        // One planner per scenario, as the service keeps one: its workspace and its
        // estimate of the NLP's set-up time carry over from plan to plan.
        let mut planner = Planner::with_kkt_cache(&s, Arc::clone(&kkt));
        let first = env::<u64>("PROBE_FIRST_SEED").unwrap_or(1);
        for seed in first..first + runs {
            let st = PlannerSettings {
                swarm: s.swarm.clone().with_seed(seed),
                ..s.clone()
            };
            let budget_ms = env::<u64>("PROBE_DEADLINE_MS").unwrap_or(30_000);
            if let Some((b, var, value, before)) = &pair {
                let sb = PlannerSettings {
                    swarm: b.swarm.clone().with_seed(seed),
                    ..b.clone()
                };
                let mut ms = [0.0; 2];
                for k in [0, 1, 1, 0] {
                    // B also plans with the variable set, for what reads it at plan time.
                    let (settings, env_value) = if k == 0 {
                        (&st, before.as_deref())
                    } else {
                        (&sb, Some(value.as_str()))
                    };
                    set_env(var, env_value);
                    let deadline = Deadline::after(clock, Duration::from_millis(budget_ms));
                    let out = planner.plan(&problem, settings, deadline).unwrap();
                    ms[k] += out.times.total.as_secs_f64() * 1e3 / 2.0;
                }
                set_env(var, before.as_deref());
                println!("PAIR {name} {seed} {:.1} {:.1}", ms[0], ms[1]);
                pairs.push((ms[0], ms[1]));
                continue;
            }
            eprintln!("PLAN {name} {seed}");
            let began = std::time::Instant::now();
            let out = planner
                .plan(
                    &problem,
                    &st,
                    Deadline::after(clock, Duration::from_millis(budget_ms)),
                )
                .unwrap();
            if budget_ms < 30_000 {
                println!(
                    "  budget {budget_ms} ms: returned after {:.2} ms ({:?}; swarm {:.2} nlp {:.2} export {:.2})",
                    began.elapsed().as_secs_f64() * 1e3,
                    out.quality,
                    out.times.swarm.as_secs_f64() * 1e3,
                    out.times.nlp.as_secs_f64() * 1e3,
                    out.times.export.as_secs_f64() * 1e3,
                );
            }
            if let Ok(dir) = std::env::var("PROBE_OUT") {
                // The judge's inputs: `tools/judge/evaluate.py SCENARIO DIR/NAME-SEED/plan.csv`.
                let dir = std::path::Path::new(&dir).join(format!("{name}-{seed}"));
                std::fs::create_dir_all(&dir).unwrap();
                let sc = bundled(name).unwrap().unwrap();
                // The probe does not record deadline cuts: plan.json lists none.
                wingman_planner::offline::write_outputs(&dir, &sc, &problem, &out, &[]).unwrap();
            }
            let ratio = out.cost / reference;
            ratios.push(ratio);
            times.push(out.times.total.as_secs_f64() * 1e3);
            swarm_times.push(out.times.swarm.as_secs_f64() * 1e3);
            if std::env::var("PROBE_RANKING").is_ok() {
                let best = out
                    .nlp
                    .ranking
                    .iter()
                    .cloned()
                    .fold(f64::INFINITY, f64::min);
                println!(
                    "  seed {seed}: ratio {ratio:.4} ranking/best {:?}",
                    out.nlp
                        .ranking
                        .iter()
                        .map(|c| format!("{:.4}", c / best))
                        .collect::<Vec<_>>()
                );
            }
            if std::env::var("PROBE_ITS").is_ok() {
                // One line per plan: `ITS name seed ratio [iterations per solve]`.
                println!("ITS {name} {seed} {ratio:.5} {:?}", out.nlp.iterations);
                if std::env::var("PROBE_MESH").is_ok() {
                    println!("MESH {name} {seed} {:?}", out.nlp.intervals);
                }
                if std::env::var("PROBE_RANKED").is_ok() {
                    let best = out
                        .nlp
                        .ranking
                        .iter()
                        .copied()
                        .fold(f64::INFINITY, f64::min);
                    let rel: Vec<String> = out
                        .nlp
                        .ranking
                        .iter()
                        .map(|c| format!("{:.3}", c / best))
                        .collect();
                    println!(
                        "RANKED {name} {seed} [{}] fin {:?}",
                        rel.join(", "),
                        out.nlp.finalists
                    );
                }
            }
            if seed == 1 {
                line = format!(
                    "swarm {:.0} nlp {:.0} (rank {:.0}) it {:?} q {:?}",
                    out.times.swarm.as_secs_f64() * 1e3,
                    out.times.nlp.as_secs_f64() * 1e3,
                    out.times.ranking.as_secs_f64() * 1e3,
                    out.nlp.iterations,
                    out.quality
                );
            }
        }
        if !pairs.is_empty() {
            println!(
                "{name:<36} A med {:7.1} ms  B med {:7.1} ms  median B/A {:.3} ({} seeds)",
                median(&mut pairs.iter().map(|p| p.0).collect::<Vec<_>>()),
                median(&mut pairs.iter().map(|p| p.1).collect::<Vec<_>>()),
                median(&mut pairs.iter().map(|p| p.1 / p.0).collect::<Vec<_>>()),
                pairs.len()
            );
        }
        if times.is_empty() {
            continue;
        }
        let max_ratio = ratios.iter().cloned().fold(0.0, f64::max);
        worst = worst.max(max_ratio);
        println!(
            "{name:<36} med {:7.1} ms max {:7.1} swarm med {:5.1} | cost/ref max {:.5} [{}] | {line}",
            median(&mut times),
            times[times.len() - 1],
            median(&mut swarm_times),
            max_ratio,
            ratios
                .iter()
                .map(|r| format!("{r:.4}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    println!("worst cost/ref {worst:.5}");
    let counts = kkt.counts();
    println!(
        "KKT factorisations: {} by block elimination ({} without pivot groups, {} stopped on a \
         surplus of negative eigenvalues), {} handed to FERAL; {} solves took their \
         workspace from the pool",
        counts.block_factorizations,
        counts.plain_factorizations,
        counts.surplus_stops,
        counts.feral_fallbacks,
        kkt.workspace_reuses()
    );
}
