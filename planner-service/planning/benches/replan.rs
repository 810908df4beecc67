//! Re-plan benchmark (issue 31): how fast and how well the planner re-plans from the plan
//! in flight. For every bundled scenario, the take-off plan is made (long budget), then
//! at several mission times re-plan events are made of it:
//! - `popup-ahead`: a threat appears on the path ahead;
//! - `popup-clear`: a threat appears beside the path ahead, clear of it;
//! - `moving-tr`: a moving threat's scheduled re-plan (its estimate propagated to the
//!   commit time and found 300 m further along its road); scenarios with moving threats;
//! - `lead-change`: the lead turns onto a new route 3 km to its left; rendezvous missions;
//! - `deviation`: the aircraft is 600 m to the side of the plan;
//! - `tasking`: the final point moves by 5 km (a new tasking: no warm start).
//!
//! Each event is re-planned from the plan in flight ([`Planner::replan`]) with budgets of
//! 10, 20, 50, 100, 150 and 200 ms, and planned cold with a long budget from the same start
//! and world (the yardstick). Prints, per model and event kind: the time to the first
//! `Optimal` plan (of the 200 ms re-plan), and per budget the cost over the yardstick
//! (median, p95, max), the share within 1.005, the qualities and which path won.
//!
//! `cargo bench -p wingman-planning --bench replan` (`-- --only NAME` to narrow it). The
//! events costlier than 1.005 x the yardstick at the budgets (50 ms in 2-D, 150 ms
//! in 3-D) are listed after the tables, with what each path did.

use std::collections::BTreeMap;
use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;
use std::time::Duration;

use wingman_interfaces::{Model, Objective, Quality};
use wingman_planning::clock::{Deadline, MonotonicClock};
use wingman_planning::collocation::kkt::KktCache;
use wingman_planning::hybrid::{FlyingPlan, PlanOutcome, PlanPath, Planner, PlannerSettings};
use wingman_planning::lead::LeadPath;
use wingman_planning::problem::{Problem, Threats};
use wingman_planning::scenario::{BUNDLED, bundled};
use wingman_planning::threat::Superquadric;

mod common;
use common::{host_reference_ms, percentile};

/// The re-plan budgets, ms.
const BUDGETS: [u64; 6] = [10, 20, 50, 100, 150, 200];
/// The yardstick's budget.
const LONG: Duration = Duration::from_secs(30);
/// Where in the take-off plan the events happen (share of its duration).
const WHEN: [f64; 3] = [0.2, 0.4, 0.6];

/// One re-plan event: its kind and the problem at its commit time.
struct Event {
    kind: &'static str,
    problem: Problem,
}

/// The heading's unit vector and its left normal at a state (x, y plane).
fn frame(problem: &Problem, x: &[f64; 7]) -> ([f64; 2], [f64; 2]) {
    let h = x[problem.heading_index()];
    let (s, c) = h.sin_cos();
    ([c, s], [-s, c])
}

/// A circular threat of radius `r` (2-D) or a dome of radius `r` as high (3-D) at `c`.
fn add_threat(problem: &mut Problem, c: [f64; 2], r: f64) -> bool {
    match &mut problem.threats {
        Threats::Planar { layout, .. } => Superquadric::ellipsoid(c, [r, r])
            .ok()
            .is_some_and(|t| layout.push(t).is_ok()),
        Threats::Spatial { layout, .. } => {
            Superquadric::ellipsoid([c[0], c[1], 0.0], [r, r, 1.5 * r])
                .ok()
                .is_some_and(|t| layout.push(t).is_ok())
        }
    }
}

/// The pop-up events at `t_c`: a threat on the path ahead where it is clear of the start,
/// the targets and the end, and the same threat moved 1.6 radii to the side.
fn popups(base: &Problem, flying: &FlyingPlan, t_c: f64, tf: f64) -> Vec<Event> {
    let r = if base.dim() == 3 { 12_000.0 } else { 6_000.0 };
    let clear_of = |p: [f64; 2]| {
        let far = |q: [f64; 3]| (p[0] - q[0]).hypot(p[1] - q[1]) > 1.5 * r;
        let end = base.final_state.map(|x| [x[0], x[1], 0.0]);
        far([base.x0[0], base.x0[1], 0.0])
            && base.targets.iter().all(|&q| far(q))
            && end.is_none_or(far)
    };
    let Some((x, _)) = [0.35, 0.5, 0.25]
        .iter()
        .filter_map(|f| flying.path.at(t_c + f * (tf - t_c)))
        .find(|(x, _)| clear_of([x[0], x[1]]))
    else {
        return Vec::new();
    };
    let (_, left) = frame(base, &x);
    let mut events = Vec::new();
    for (kind, side) in [("popup-ahead", 0.0), ("popup-clear", 1.6 * r)] {
        let mut problem = base.clone();
        let c = [x[0] + side * left[0], x[1] + side * left[1]];
        if add_threat(&mut problem, c, r) {
            events.push(Event { kind, problem });
        }
    }
    events
}

/// The events at mission time `t_c` of the plan `flying` of `take_off`.
fn events_at(take_off: &Problem, flying: &FlyingPlan, t_c: f64) -> Vec<Event> {
    let path = &flying.path;
    let tf = path.final_time().expect("a plan");
    let (x, _) = path.at(t_c).expect("inside the plan");
    let mut base = take_off.clone();
    base.t0 = t_c;
    base.x0 = x;
    let passed = path.phase_ends[..path.phase_ends.len() - 1]
        .iter()
        .filter(|&&e| e <= t_c)
        .count();
    base.targets.drain(..passed);
    let mut events = popups(&base, flying, t_c, tf);
    if base.has_moving_threats() {
        let mut problem = base.clone();
        match &mut problem.threats {
            Threats::Planar { moving, .. } => moving.iter_mut().for_each(|m| nudge(m, t_c)),
            Threats::Spatial { moving, .. } => moving.iter_mut().for_each(|m| nudge(m, t_c)),
        }
        events.push(Event {
            kind: "moving-tr",
            problem,
        });
    }
    if let Some(lead) = &base.lead {
        let at = lead.at(t_c).position;
        let (_, left) = frame(&base, &x);
        let mut route = vec![at];
        route.extend(
            lead.route()
                .iter()
                .skip(1)
                .map(|p| [p[0] + 3000.0 * left[0], p[1] + 3000.0 * left[1], p[2]]),
        );
        if let Ok(new) = LeadPath::new(&route, lead.speed(), t_c) {
            let mut problem = base.clone();
            problem.lead = Some(new);
            events.push(Event {
                kind: "lead-change",
                problem,
            });
        }
    }
    let mut deviated = base.clone();
    let (_, left) = frame(&base, &x);
    deviated.x0[0] += 600.0 * left[0];
    deviated.x0[1] += 600.0 * left[1];
    events.push(Event {
        kind: "deviation",
        problem: deviated,
    });
    let mut tasking = base.clone();
    let end = tasking.final_state.as_mut().map(|s| &mut s[..2]);
    let moved = match end {
        Some(e) => {
            let h = e[1].atan2(e[0]) + FRAC_PI_2;
            e[0] += 5000.0 * h.cos();
            e[1] += 5000.0 * h.sin();
            true
        }
        None => false,
    };
    if moved || take_off.objective == Objective::MinTimeRendezvous {
        if !moved {
            // A rendezvous has no final point: the target moves instead.
            if let Some(t) = tasking.targets.first_mut() {
                t[1] += 5000.0;
            }
        }
        events.push(Event {
            kind: "tasking",
            problem: tasking,
        });
    }
    events
}

/// A moving threat's estimate propagated to `t` and found 300 m further along its road.
fn nudge<const D: usize>(m: &mut wingman_planning::estimation::MovingThreat<D>, t: f64) {
    if let Ok(mut est) = m.model().propagate(m.estimate(), t) {
        est.mean[0] += 300.0;
        m.set_estimate(est);
    }
}

/// The results of one kind of event in one model.
#[derive(Default)]
struct Tally {
    events: usize,
    /// The warm path's time to `Optimal` (ms; infinite: none within 200 ms).
    first_optimal: Vec<f64>,
    /// Per budget: cost / yardstick, qualities, warm wins.
    ratio: BTreeMap<u64, Vec<f64>>,
    quality: BTreeMap<u64, BTreeMap<&'static str, usize>>,
    warm: BTreeMap<u64, usize>,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1))
        .cloned();
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    // The take-off plans and the cold plans are the global search's alone (no waves, as
    // when this bench's numbers were taken): the re-plans are what it measures.
    let settings = PlannerSettings {
        wave_starts: 0,
        wave_starts_3d: 0,
        ..PlannerSettings::default()
    };
    let kkt = Arc::new(KktCache::new());
    // One planner re-plans all events of a model, as a service's does; the yardstick has
    // its own.
    let mut planners = [
        Planner::with_kkt_cache(&settings, Arc::clone(&kkt)),
        Planner::with_kkt_cache(&settings, Arc::clone(&kkt)),
    ];
    let mut yardstick = Planner::with_kkt_cache(&settings, Arc::clone(&kkt));
    let mut tallies: BTreeMap<(usize, &'static str), Tally> = BTreeMap::new();
    let mut host = vec![host_reference_ms()];
    let mut outliers = Vec::new();
    for (name, _) in BUNDLED {
        if only.as_ref().is_some_and(|o| !name.contains(o.as_str())) {
            continue;
        }
        let take_off = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
        let first = yardstick
            .plan(&take_off, &settings, Deadline::after(clock, LONG))
            .unwrap();
        let flying = FlyingPlan::new(&take_off, first.trajectory).with_solution(first.solution);
        let (t_start, tf) = (take_off.t0, flying.path.final_time().unwrap());
        for share in WHEN {
            let t_c = t_start + share * (tf - t_start);
            for event in events_at(&take_off, &flying, t_c) {
                let cold = yardstick
                    .plan(&event.problem, &settings, Deadline::after(clock, LONG))
                    .unwrap();
                let model = event.problem.model;
                let tally = tallies
                    .entry((event.problem.dim(), event.kind))
                    .or_default();
                tally.events += 1;
                let planner = &mut planners[usize::from(model == Model::ThreeD)];
                for budget in BUDGETS {
                    let deadline = Deadline::after(clock, Duration::from_millis(budget));
                    // A new tasking cannot start warm: it is planned as a take-off plan.
                    let out = if event.kind == "tasking" {
                        planner.plan(&event.problem, &settings, deadline)
                    } else {
                        planner.replan(&event.problem, &settings, deadline, &flying)
                    };
                    let out = out.unwrap();
                    record(tally, budget, &out, cold.cost);
                    if budget == judged_budget(event.problem.dim()) && out.cost > 1.005 * cold.cost
                    {
                        outliers.push(outlier(name, share, &event, budget, &out, cold.cost));
                    }
                    if budget == 200 {
                        let first = out.first_optimal.map_or(f64::INFINITY, ms);
                        tally.first_optimal.push(first);
                    }
                }
            }
        }
        host.push(host_reference_ms());
    }
    print_tables(&mut tallies);
    print_summary(&tallies);
    println!("\nEvents over 1.005 x the yardstick at 50 ms (2-D) / 150 ms (3-D):");
    for o in &outliers {
        println!("- {o}");
    }
    host.sort_by(f64::total_cmp);
    println!(
        "\nhost ref ms (before, after each scenario): min {:.1}, median {:.1}, max {:.1}",
        host[0],
        percentile(&host, 0.5),
        host[host.len() - 1]
    );
}

/// The budget the issue judges re-plans at: 50 ms in 2-D, 150 ms in 3-D.
fn judged_budget(dim: usize) -> u64 {
    if dim == 3 { 150 } else { 50 }
}

/// One line on an event whose re-plan came out costlier than 1.005 x its yardstick.
fn outlier(
    name: &str,
    share: f64,
    event: &Event,
    budget: u64,
    out: &PlanOutcome,
    yardstick: f64,
) -> String {
    let warm = out.warm.as_ref().map_or("none".to_string(), |w| {
        format!(
            "{:?} cost {:.4} in {:.1} ms, iterations {:?}",
            w.quality,
            w.cost,
            ms(w.elapsed),
            w.nlp.iterations
        )
    });
    format!(
        "{name} at {share} {} {budget} ms: {:.4} x ({:?}, path {:?}); warm: {warm}; global: swarm \
         {:.1} ms, nlp {:.1} ms, iterations {:?}",
        event.kind,
        out.cost / yardstick,
        out.quality,
        out.path,
        ms(out.times.swarm),
        ms(out.times.nlp),
        out.nlp.iterations
    )
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn record(tally: &mut Tally, budget: u64, out: &PlanOutcome, yardstick: f64) {
    tally
        .ratio
        .entry(budget)
        .or_default()
        .push(out.cost / yardstick);
    let q = match out.quality {
        Quality::Optimal => "Optimal",
        Quality::Feasible => "Feasible",
        _ => "SwarmOnly",
    };
    *tally
        .quality
        .entry(budget)
        .or_default()
        .entry(q)
        .or_default() += 1;
    *tally.warm.entry(budget).or_default() += usize::from(out.path == PlanPath::Warm);
}

/// Issue 31's yardsticks per model, over the re-plan events (tasking changes apart: they
/// cannot start warm): the median time to `Optimal`, and at the judged budget the share
/// within 1.005 of the yardstick and the worst ratio.
fn print_summary(tallies: &BTreeMap<(usize, &'static str), Tally>) {
    println!(
        "\n| model | re-plan events | time to Optimal ms, median | judged budget ms | within 1.005 | worst |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    for dim in [2, 3] {
        let budget = judged_budget(dim);
        let replans = || {
            tallies
                .iter()
                .filter(move |((d, kind), _)| *d == dim && *kind != "tasking")
                .map(|(_, t)| t)
        };
        let mut first: Vec<f64> = replans().flat_map(|t| t.first_optimal.clone()).collect();
        let ratios: Vec<f64> = replans().flat_map(|t| t.ratio[&budget].clone()).collect();
        if first.is_empty() {
            continue;
        }
        first.sort_by(f64::total_cmp);
        let within = ratios.iter().filter(|&&v| v <= 1.005).count();
        let worst = ratios.iter().copied().fold(f64::NAN, f64::max);
        println!(
            "| {dim}-D | {} | {:.1} | {budget} | {within}/{} | {worst:.4} |",
            first.len(),
            percentile(&first, 0.5),
            ratios.len(),
        );
    }
}

fn print_tables(tallies: &mut BTreeMap<(usize, &'static str), Tally>) {
    println!("| model | event | events | time to Optimal ms (median / p95 / max) |");
    println!("|---|---|---:|---|");
    for ((model, kind), t) in tallies.iter_mut() {
        t.first_optimal.sort_by(f64::total_cmp);
        let f = &t.first_optimal;
        println!(
            "| {model}-D | {kind} | {} | {:.1} / {:.1} / {:.1} |",
            t.events,
            percentile(f, 0.5),
            percentile(f, 0.95),
            f[f.len() - 1]
        );
    }
    println!(
        "\n| model | event | budget ms | cost / yardstick (median / p95 / max) | within 1.005 | qualities | warm won |"
    );
    println!("|---|---|---:|---|---:|---|---:|");
    for ((model, kind), t) in tallies.iter_mut() {
        for budget in BUDGETS {
            let r = t.ratio.get_mut(&budget).expect("every budget");
            r.sort_by(f64::total_cmp);
            let within = r.iter().filter(|&&v| v <= 1.005).count();
            let qualities = t.quality[&budget]
                .iter()
                .map(|(q, n)| format!("{q} {n}"))
                .collect::<Vec<_>>()
                .join(", ");
            println!(
                "| {model}-D | {kind} | {budget} | {:.4} / {:.4} / {:.4} | {within}/{} | {qualities} | {} |",
                percentile(r, 0.5),
                percentile(r, 0.95),
                r[r.len() - 1],
                r.len(),
                t.warm[&budget],
            );
        }
    }
}
