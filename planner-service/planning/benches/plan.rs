//! Planner benchmark (issue 5): for every canonical scenario, the take-off plan with 20
//! swarm seeds — median and p95 of the plan time, the share of swarm, NLP and the rest,
//! the cost spread across seeds, peak heap — and, under budgets too short for the whole
//! NLP stage (2-D 5, 20, 50 ms; 3-D 20, 50, 150 ms), the qualities and how far past its
//! deadline the planner returns. Prints Markdown tables (run with `cargo bench -p
//! wingman-planning --bench plan`; `-- --runs N`, `-- --only NAME` to narrow it,
//! `-- --sequential`, `-- --short-only` for the short budgets alone).
//!
//! It times the global search alone (no waves: a plan from scratch spends the budget the
//! search leaves on further starts, `hybrid::waves`).
//!
//! The peak heap is counted in a pass of its own (the same plans again), not in the
//! timed runs: the counting allocator's shared counters, updated by both threads at
//! every allocation of the solver, cost the timed plans up to 15 %.
//!
//! The scenarios are interleaved: round `k` plans every scenario with seed `k`, so that
//! each scenario's runs spread over the whole bench (`-- --sequential`: each scenario's
//! runs in a row). A fixed workload (`host_reference_ms`) is timed before every round and
//! at the end: the host's speed while the plans ran.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicIsize, Ordering};
use std::time::Duration;

use wingman_interfaces::Quality;
use wingman_planning::clock::{Clock, Deadline, MonotonicClock};
use wingman_planning::collocation::kkt::KktCache;
use wingman_planning::cuts::{CutList, CutLog};
use wingman_planning::hybrid::{Planner, PlannerSettings};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::{BUNDLED, bundled};

/// The system allocator, counting the bytes live and their peak while `COUNTING` is set.
/// Bytes freed while counting that were allocated before are subtracted too: the counted
/// pass creates its planner inside it, so the count is the plan's own.
struct Peak;
static COUNTING: AtomicBool = AtomicBool::new(false);
static LIVE: AtomicIsize = AtomicIsize::new(0);
static PEAK: AtomicIsize = AtomicIsize::new(0);

unsafe impl GlobalAlloc for Peak {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            let size = layout.size() as isize;
            let now = LIVE.fetch_add(size, Ordering::Relaxed) + size;
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if COUNTING.load(Ordering::Relaxed) {
            LIVE.fetch_sub(layout.size() as isize, Ordering::Relaxed);
        }
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// The peak heap of `run` above what was live when it began, in bytes.
fn peak_of(run: impl FnOnce()) -> isize {
    LIVE.store(0, Ordering::Relaxed);
    PEAK.store(0, Ordering::Relaxed);
    COUNTING.store(true, Ordering::SeqCst);
    run();
    COUNTING.store(false, Ordering::SeqCst);
    PEAK.load(Ordering::Relaxed)
}

mod common;
use common::{host_reference_ms, percentile};

#[global_allocator]
static GLOBAL: Peak = Peak;

/// One scenario's timed plans.
#[derive(Default)]
struct Tally {
    times: Vec<f64>,
    swarm: f64,
    nlp: f64,
    ranking: f64,
    total: f64,
    costs: Vec<f64>,
    qualities: std::collections::BTreeMap<String, usize>,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs: u64 = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(20);
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .cloned();
    let sequential = args.iter().any(|a| a == "--sequential");
    let short_only = args.iter().any(|a| a == "--short-only");
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    // The global search alone, which makes a take-off's first plan: the waves after it
    // (`hybrid::waves`) fill whatever budget it leaves, so their time is the budget's; the
    // campaign measures what they find.
    let settings = PlannerSettings {
        wave_starts: 0,
        wave_starts_3d: 0,
        ..PlannerSettings::default()
    };
    let scenarios: Vec<(&str, Problem)> = BUNDLED
        .iter()
        .filter(|(name, _)| only.as_ref().is_none_or(|o| name.contains(o.as_str())))
        .map(|(name, _)| {
            let problem = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
            (*name, problem)
        })
        .collect();
    let settings_of = |seed: u64| PlannerSettings {
        swarm: settings.swarm.clone().with_seed(seed),
        ..settings.clone()
    };
    // The KKT workspaces pooled over the whole bench, as a service's planner pools them
    // over its plans.
    let kkt = Arc::new(KktCache::new());
    if !short_only {
        // One take-off plan with a fresh planner and swarm seed `seed`.
        let plan_once = |problem: &Problem, seed: u64| {
            let s = settings_of(seed);
            Planner::with_kkt_cache(&s, Arc::clone(&kkt))
                .plan(problem, &s, Deadline::after(clock, Duration::from_secs(30)))
                .unwrap()
        };
        let plan = |problem: &Problem, seed: u64, tally: &mut Tally| {
            let out = plan_once(problem, seed);
            let t = out.times.total.as_secs_f64() * 1e3;
            tally.times.push(t);
            tally.swarm += out.times.swarm.as_secs_f64() * 1e3;
            tally.nlp += out.times.nlp.as_secs_f64() * 1e3;
            tally.ranking += out.times.ranking.as_secs_f64() * 1e3;
            tally.total += t;
            tally.costs.push(out.cost);
            *tally
                .qualities
                .entry(format!("{:?}", out.quality))
                .or_insert(0) += 1;
        };
        // Interleaved (default): round `seed` plans every scenario once, so that each
        // scenario's runs spread over the whole bench and a slow spell of the host weighs on
        // all scenarios alike instead of on whichever ran through it. `--sequential`: each
        // scenario's runs in a row (a stream of re-plans of one mission).
        let mut tallies: Vec<Tally> = scenarios.iter().map(|_| Tally::default()).collect();
        let mut host = Vec::new();
        if sequential {
            for ((_, problem), tally) in scenarios.iter().zip(&mut tallies) {
                host.push(host_reference_ms());
                for seed in 1..=runs {
                    plan(problem, seed, tally);
                }
            }
        } else {
            for seed in 1..=runs {
                host.push(host_reference_ms());
                for ((_, problem), tally) in scenarios.iter().zip(&mut tallies) {
                    plan(problem, seed, tally);
                }
            }
        }
        host.push(host_reference_ms());
        // The peak heap of each scenario's plans, untimed, from an empty workspace pool (the
        // pool keeps the workspaces it is given back, up to its budget: counted here).
        let peaks: Vec<f64> = scenarios
            .iter()
            .map(|(_, problem)| {
                kkt.clear_workspace_pool();
                peak_of(|| {
                    for seed in 1..=runs {
                        plan_once(problem, seed);
                    }
                }) as f64
                    / (1024.0 * 1024.0)
            })
            .collect();
        println!(
            "| scenario | median ms | p95 ms | swarm % | NLP % | of it ranking % | rest % | cost min | cost max | spread % | peak heap MiB | quality |"
        );
        println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|");
        for (((name, _), tally), peak) in scenarios.iter().zip(&mut tallies).zip(&peaks) {
            tally.times.sort_by(f64::total_cmp);
            tally.costs.sort_by(f64::total_cmp);
            let (times, costs, total) = (&tally.times, &tally.costs, tally.total);
            let (lo, hi) = (costs[0], costs[costs.len() - 1]);
            println!(
                "| {name} | {:.1} | {:.1} | {:.0} | {:.0} | {:.0} | {:.0} | {lo:.6} | {hi:.6} | {:.3} | {peak:.1} | {} |",
                percentile(times, 0.5),
                percentile(times, 0.95),
                100.0 * tally.swarm / total,
                100.0 * tally.nlp / total,
                100.0 * tally.ranking / total,
                100.0 * (total - tally.swarm - tally.nlp) / total,
                100.0 * (hi - lo) / lo.abs().max(1e-12),
                tally
                    .qualities
                    .iter()
                    .map(|(q, n)| format!("{q} {n}"))
                    .collect::<Vec<_>>()
                    .join(", "),
            );
        }
        let order = if sequential {
            "before each scenario's runs and at the end"
        } else {
            "before each round of all scenarios and at the end"
        };
        let text: Vec<String> = host.iter().map(|h| format!("{h:.1}")).collect();
        host.sort_by(f64::total_cmp);
        println!(
            "\nhost ref ms ({order}): {} (min {:.1}, median {:.1}, max {:.1}); {} solves took their KKT workspace from the pool",
            text.join(" "),
            host[0],
            percentile(&host, 0.5),
            host[host.len() - 1],
            kkt.workspace_reuses(),
        );
    }
    // Short budgets: the quality a budget too short for the whole NLP stage gives (the
    // floor, `Feasible`, or the swarm's path), and how far past its deadline the planner
    // returns.
    let cut_log: &'static CutLog = Box::leak(Box::new(CutLog::new()));
    let mut swarm_only = Vec::new();
    println!("\n| scenario | budget ms | returned after ms (median / max of {runs}) | qualities |");
    println!("|---|---:|---:|---|");
    for (name, problem) in &scenarios {
        let budgets: &[u64] = if problem.dim() == 3 {
            &[20, 50, 150]
        } else {
            &[5, 20, 50]
        };
        for &budget_ms in budgets {
            let mut over = Vec::new();
            let mut qualities = std::collections::BTreeMap::<String, usize>::new();
            // One planner across the runs, as the service keeps one: its estimates of the
            // NLP's timing carry over from plan to plan.
            let mut planner = Planner::with_kkt_cache(&settings, Arc::clone(&kkt));
            for seed in 1..=runs {
                let s = settings_of(seed);
                let began = clock.now();
                cut_log.begin(None);
                let deadline = Deadline::after(clock, Duration::from_millis(budget_ms));
                let out = planner
                    .plan(problem, &s, deadline.with_cuts(cut_log))
                    .unwrap();
                over.push((clock.now() - began).as_secs_f64() * 1e3);
                *qualities.entry(format!("{:?}", out.quality)).or_insert(0) += 1;
                let cuts = cut_log.finish();
                if out.quality == Quality::SwarmOnly && budget_ms == floor_budget(problem.dim()) {
                    swarm_only.push(format!(
                        "{name} seed {seed} at {budget_ms} ms: swarm {:.1} ms, nlp {:.1} ms, \
                         iterations {:?}; cuts {}",
                        out.times.swarm.as_secs_f64() * 1e3,
                        out.times.nlp.as_secs_f64() * 1e3,
                        out.nlp.iterations,
                        CutList(&cuts)
                    ));
                }
            }
            over.sort_by(f64::total_cmp);
            let qualities: Vec<String> =
                qualities.iter().map(|(q, n)| format!("{q} {n}")).collect();
            println!(
                "| {name} | {budget_ms} | {:.1} / {:.1} | {} |",
                percentile(&over, 0.5),
                over[over.len() - 1],
                qualities.join(", ")
            );
        }
    }
    println!("\nSwarmOnly at the floor's budget (50 ms in 2-D, 150 ms in 3-D):");
    for line in &swarm_only {
        println!("- {line}");
    }
}

/// The budget at which a cold plan must not come back `SwarmOnly` (issue 31): 50 ms in
/// 2-D, 150 ms in 3-D.
fn floor_budget(dim: usize) -> u64 {
    if dim == 3 { 150 } else { 50 }
}
