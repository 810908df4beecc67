//! Planner benchmark (issue 5): for every canonical scenario, the take-off plan with 20
//! swarm seeds — median and p95 of the plan time, the share of swarm, NLP and the rest,
//! the cost spread across seeds, peak heap — and how far past a too-short deadline the
//! planner returns. Prints a Markdown table (run with `cargo bench -p wingman-planner
//! --bench plan`; `-- --runs N`, `-- --only NAME` to narrow it).
//!
//! The peak heap is counted in a pass of its own (the same plans again), not in the
//! timed runs: the counting allocator's shared counters, updated by both threads at
//! every allocation of the solver, cost the timed plans up to 15 %.
//!
//! The last column times a fixed workload (`host_reference_ms`) just before and just after
//! each scenario's timed plans: the host's speed while they ran.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicIsize, Ordering};
use std::time::Duration;

use wingman_planner::clock::{Clock, Deadline, MonotonicClock};
use wingman_planner::hybrid::{Planner, PlannerSettings};
use wingman_planner::problem::Problem;
use wingman_planner::scenario::{BUNDLED, bundled};

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

#[path = "support/kkt_block.rs"]
mod kkt_block;
use kkt_block::kkt_block;

#[global_allocator]
static GLOBAL: Peak = Peak;

/// The host's speed now: a fixed workload (400 dense Bunch–Kaufman factorisations of one
/// 72 × 72 KKT-shaped block, the planner's hottest kernel) run on two threads at once, as
/// the planner runs; the slower thread's median of three timings, in ms. Timed before and
/// after each scenario, so that its plan times can be read against the speed the host had
/// while they ran (a shared VM's speed swings by up to 1.8× within minutes;
/// docs/BENCHMARKS.md).
fn host_reference_ms() -> f64 {
    std::thread::scope(|s| {
        let other = s.spawn(reference_workload_ms);
        let here = reference_workload_ms();
        here.max(other.join().expect("the reference workload does not panic"))
    })
}

/// One thread's part of [`host_reference_ms`]: the block of the kkt bench's `n = 72`
/// case (42 primal and 30 dual rows).
fn reference_workload_ms() -> f64 {
    use wingman_planner::collocation::bunch_kaufman as bk;
    const N: usize = 72;
    let k = kkt_block(42, 30, N as u64);
    let mut a = k.clone();
    let mut piv = vec![0i32; N];
    let mut work = vec![0.0; bk::work_len(N)];
    let mut times: Vec<f64> = (0..3)
        .map(|_| {
            let began = std::time::Instant::now();
            for _ in 0..400 {
                a.copy_from_slice(&k);
                std::hint::black_box(bk::factor(&mut a, N, &mut piv, &mut work))
                    .expect("the reference block is nonsingular");
            }
            began.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[1]
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let k = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[k.min(sorted.len() - 1)]
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
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    let settings = PlannerSettings::default();
    println!(
        "| scenario | median ms | p95 ms | swarm % | NLP % | of it ranking % | rest % | cost min | cost max | spread % | peak heap MiB | quality | host ref ms |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|");
    for (name, _) in BUNDLED {
        if only.as_ref().is_some_and(|o| !name.contains(o.as_str())) {
            continue;
        }
        let problem = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
        let mut times = Vec::new();
        let (mut swarm, mut nlp, mut ranking, mut total) = (0.0, 0.0, 0.0, 0.0);
        let mut costs = Vec::new();
        let mut qualities = std::collections::BTreeMap::new();
        let reference_before = host_reference_ms();
        for seed in 1..=runs {
            let s = PlannerSettings {
                swarm: settings.swarm.clone().with_seed(seed),
                ..settings.clone()
            };
            let mut planner = Planner::new(&s);
            let out = planner
                .plan(
                    &problem,
                    &s,
                    Deadline::after(clock, Duration::from_secs(30)),
                )
                .unwrap();
            let t = out.times.total.as_secs_f64() * 1e3;
            times.push(t);
            swarm += out.times.swarm.as_secs_f64() * 1e3;
            nlp += out.times.nlp.as_secs_f64() * 1e3;
            ranking += out.times.ranking.as_secs_f64() * 1e3;
            total += t;
            costs.push(out.cost);
            *qualities.entry(format!("{:?}", out.quality)).or_insert(0) += 1;
        }
        let reference_after = host_reference_ms();
        // The peak heap over the same plans, untimed.
        let peak = peak_of(|| {
            for seed in 1..=runs {
                let s = PlannerSettings {
                    swarm: settings.swarm.clone().with_seed(seed),
                    ..settings.clone()
                };
                let mut planner = Planner::new(&s);
                let plan = planner.plan(
                    &problem,
                    &s,
                    Deadline::after(clock, Duration::from_secs(30)),
                );
                assert!(plan.is_ok());
            }
        }) as f64
            / (1024.0 * 1024.0);
        times.sort_by(f64::total_cmp);
        costs.sort_by(f64::total_cmp);
        let (lo, hi) = (costs[0], costs[costs.len() - 1]);
        println!(
            "| {name} | {:.1} | {:.1} | {:.0} | {:.0} | {:.0} | {:.0} | {lo:.6} | {hi:.6} | {:.3} | {peak:.1} | {} | {reference_before:.1} / {reference_after:.1} |",
            percentile(&times, 0.5),
            percentile(&times, 0.95),
            100.0 * swarm / total,
            100.0 * nlp / total,
            100.0 * ranking / total,
            100.0 * (total - swarm - nlp) / total,
            100.0 * (hi - lo) / lo.abs().max(1e-12),
            qualities
                .iter()
                .map(|(q, n)| format!("{q} {n}"))
                .collect::<Vec<_>>()
                .join(", "),
        );
    }
    // Deadline overshoot: a budget far too short for the NLP.
    println!("\n| scenario | budget ms | returned after ms (median / max of {runs}) | quality |");
    println!("|---|---:|---:|---|");
    for name in ["2d-min-time-avoidable", "3d-min-time-rendezvous-avoidable"] {
        if only.as_ref().is_some_and(|o| !name.contains(o.as_str())) {
            continue;
        }
        let problem = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
        for budget_ms in [5u64, 20, 50] {
            let mut over = Vec::new();
            let mut quality = String::new();
            // One planner across the runs, as the service keeps one: its estimate of the
            // NLP's set-up time carries over from plan to plan.
            let mut planner = Planner::new(&settings);
            for seed in 1..=runs {
                let s = PlannerSettings {
                    swarm: settings.swarm.clone().with_seed(seed),
                    ..settings.clone()
                };
                let began = clock.now();
                let out = planner
                    .plan(
                        &problem,
                        &s,
                        Deadline::after(clock, Duration::from_millis(budget_ms)),
                    )
                    .unwrap();
                over.push((clock.now() - began).as_secs_f64() * 1e3);
                quality = format!("{:?}", out.quality);
            }
            over.sort_by(f64::total_cmp);
            println!(
                "| {name} | {budget_ms} | {:.1} / {:.1} | {quality} (last) |",
                percentile(&over, 0.5),
                over[over.len() - 1]
            );
        }
    }
}
