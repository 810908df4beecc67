//! The particle swarm: determinism (threads, workspace reuse), monotone global best,
//! every canonical scenario flown through its targets, deadlines, the cost against an
//! independent evaluation, the model followed by the returned path, bad input. Tests use
//! small settings (8–16 particles, 10–40 iterations) to stay fast in debug builds; the
//! default settings' speed and quality are in the bench (`benches/swarm.rs`).

use std::time::Duration;

use wingman_interfaces::{Model, Objective};
use wingman_planning::clock::{Deadline, ManualClock};
use wingman_planning::dynamics::wrap_angle;
use wingman_planning::problem::Problem;
use wingman_planning::scenario::{self, BUNDLED};
use wingman_planning::seeding::SeedSettings;
use wingman_planning::swarm::{
    self, Parameterisation, SwarmError, SwarmOutcome, SwarmSettings, SwarmStatus, SwarmWorkspace,
};

use wingman_planning::clock::TickingClock;

fn problem(name: &str) -> Problem {
    let sc = scenario::bundled(name)
        .unwrap_or_else(|| panic!("no scenario {name}"))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    Problem::from_scenario(&sc).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Small settings for quick tests: 12 particles in 3 groups, 25 iterations, fewer seeds.
fn small() -> SwarmSettings {
    SwarmSettings::default()
        .with_particles(12)
        .with_groups(3)
        .with_max_iterations(25)
        .with_seeds(
            SeedSettings::default()
                .with_random_seeds(2)
                .with_scan_steps(33),
        )
}

fn run(p: &Problem, s: &SwarmSettings, ws: &mut SwarmWorkspace) -> SwarmOutcome {
    let clock = ManualClock::new();
    swarm::run(p, s, ws, Deadline::never(&clock)).unwrap_or_else(|e| panic!("swarm: {e}"))
}

fn position(p: &Problem, x: &[f64; 7]) -> [f64; 3] {
    match p.model {
        Model::TwoD => [x[0], x[1], 0.0],
        Model::ThreeD => [x[0], x[1], x[2]],
    }
}

fn segment_distance(a: &[f64; 3], b: &[f64; 3], p: &[f64; 3]) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|k| b[k] - a[k]);
    let w: [f64; 3] = std::array::from_fn(|k| p[k] - a[k]);
    let dd: f64 = d.iter().map(|v| v * v).sum();
    let f = if dd > 0.0 {
        (d.iter().zip(&w).map(|(x, y)| x * y).sum::<f64>() / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|k| (w[k] - f * d[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The same input and seed give a bit-identical trajectory, cost and history: with two
/// threads or one, and in a workspace that planned another problem before (a moving threat
/// and a rendezvous: every cache is exercised).
#[test]
fn same_seed_gives_bit_identical_results() {
    let p = problem("3d-rendezvous-moving-threat");
    let other = problem("2d-min-time-avoidable");
    let two = small().with_seed(7).with_threads(2);
    let one = two.clone().with_threads(1);
    let mut ws = SwarmWorkspace::new(&two);
    let a = run(&p, &two, &mut ws);
    let ha = ws.history().to_vec();
    run(&other, &two, &mut ws);
    let b = run(&p, &two, &mut ws);
    assert_eq!(ws.history(), &ha[..]);
    let mut ws1 = SwarmWorkspace::new(&one);
    let c = run(&p, &one, &mut ws1);
    assert_eq!(ws1.history(), &ha[..]);
    for o in [&b, &c] {
        assert_eq!(o.best, a.best);
        assert_eq!(o.cost.to_bits(), a.cost.to_bits());
        assert_eq!(o.iterations, a.iterations);
        assert_eq!(o.candidates.len(), a.candidates.len());
    }
    let d = run(&p, &two.clone().with_seed(8), &mut ws);
    assert!(d.best != a.best, "another seed should fly another path");
}

/// The global best's cost never increases from one iteration to the next, starts at the
/// best seed's and ends at most at the returned path's (which is ranked by its objective
/// among the groups' bests).
#[test]
fn global_best_never_increases() {
    for name in ["2d-min-time-avoidable", "3d-fixed-time-unavoidable"] {
        let p = problem(name);
        let s = small().with_max_iterations(40).with_stall_iterations(1000);
        let mut ws = SwarmWorkspace::new(&s);
        let o = run(&p, &s, &mut ws);
        let h = ws.history();
        assert_eq!(
            h.len(),
            o.iterations + 2,
            "{name}: seed + init + iterations"
        );
        assert!(h.windows(2).all(|w| w[1] <= w[0]), "{name}: {h:?}");
        assert!(h[h.len() - 1] <= o.cost);
        assert!(h[h.len() - 1] <= o.seeds_best_cost);
        assert_eq!(h[0], o.seeds_best_cost);
    }
}

/// On every canonical scenario the swarm returns a valid, finite trajectory starting at
/// the initial state that passes every target within `D*` and ends within `D*` of the
/// final point or the lead. The distances are recomputed from the trajectory's states
/// (closest point of the sample segments, targets in order) and must not exceed the
/// swarm's report by more than the sagitta of a sample's arc (the report measures to the
/// chords, the trajectory holds the pass samples on the arcs: `V h² r / 8`, +10 %).
#[test]
fn every_canonical_scenario_is_flown_through_its_targets() {
    let s = small()
        .with_particles(8)
        .with_groups(2)
        .with_max_iterations(10);
    let mut ws = SwarmWorkspace::new(&s);
    for (name, _) in BUNDLED {
        let p = problem(name);
        let o = run(&p, &s, &mut ws);
        let t = &o.best;
        assert!(t.is_valid(), "{name}");
        assert!(o.cost.is_finite() && o.report.feasible, "{name}");
        assert_eq!(
            t.states[0][..p.nx()],
            p.x0[..p.nx()],
            "{name}: initial state"
        );
        assert_eq!(t.times[0], p.t0);
        assert_eq!(t.phase_ends.len(), p.phases(), "{name}");
        assert!(t.phase_ends.windows(2).all(|w| w[1] >= w[0]));
        assert_eq!(t.phase_ends.last().copied(), t.final_time());
        let h = o.dt / s.substeps as f64;
        let v = p.limits.speed;
        let rate = match p.model {
            Model::TwoD => p.limits.turn_rate_max,
            Model::ThreeD => {
                let l = &p.limits;
                9.80665 * l.mu_max.tan().min((l.nz_max * l.nz_max - 1.0).sqrt()) / v
            }
        };
        let sagitta = 1.1 * v * h * h * rate / 8.0;
        let pos: Vec<[f64; 3]> = t.states.iter().map(|x| position(&p, x)).collect();
        let mut from = 0;
        for (k, target) in p.targets.iter().enumerate() {
            let (mut best, mut at) = (f64::INFINITY, from);
            for j in from..pos.len() - 1 {
                let d = segment_distance(&pos[j], &pos[j + 1], target);
                if d < best {
                    best = d;
                    at = j;
                }
            }
            from = at;
            assert!(best < s.d_star, "{name}: target {k} missed by {best} m");
            assert!(
                best <= o.report.pass_distances[k] + sagitta,
                "{name}: target {k}: {best} vs reported {}",
                o.report.pass_distances[k]
            );
        }
        let last = pos[pos.len() - 1];
        let tf = t.final_time().unwrap_or(f64::NAN);
        let end = match (p.objective, &p.final_state, &p.lead) {
            (Objective::MinTimeRendezvous, _, Some(lead)) => {
                let q = lead.at(tf).position;
                position(&p, &[q[0], q[1], q[2], 0.0, 0.0, 0.0, 0.0])
            }
            (_, Some(f), _) => position(&p, f),
            _ => panic!("{name}: no end"),
        };
        let d =
            ((last[0] - end[0]).powi(2) + (last[1] - end[1]).powi(2) + (last[2] - end[2]).powi(2))
                .sqrt();
        assert!(d < s.d_star, "{name}: ends {d} m from the end");
        assert!(
            (d - o.report.pass_distances[p.phases() - 1]).abs() <= sagitta,
            "{name}: end {d} vs reported {}",
            o.report.pass_distances[p.phases() - 1]
        );
    }
}

/// With a deadline already passed the swarm returns the best seed (as flown: the same
/// trajectory as `seed_trajectory` of that seed, bit for bit), flagged `MaxTime`, after no
/// iteration.
#[test]
fn an_expired_deadline_returns_the_best_seed() {
    let p = problem("2d-min-time-rendezvous-avoidable");
    let s = small();
    let mut ws = SwarmWorkspace::new(&s);
    let clock = ManualClock::new();
    let deadline = Deadline::after(&clock, Duration::ZERO);
    let o = swarm::run(&p, &s, &mut ws, deadline).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(o.status, SwarmStatus::MaxTime);
    assert_eq!(o.iterations, 0);
    assert_eq!(o.cost, o.seeds_best_cost);
    let index = ws
        .seeds()
        .iter()
        .position(|seed| *seed.label() == o.seeds_best)
        .unwrap_or_else(|| panic!("best seed {} not found", o.seeds_best));
    let Some((cost, _, traj)) = ws.seed_trajectory(index) else {
        panic!("no seed trajectory");
    };
    assert_eq!(cost, o.cost);
    assert_eq!(traj, o.best);
    assert!(o.best.is_valid());
}

/// The number of seeds of `p` under `s`, and a run on a [`TickingClock`] whose budget
/// covers the seeds (each built and each scored but the first reads the clock once) and
/// about `extra` more readings.
fn ticking_run(p: &Problem, s: &SwarmSettings, extra: u64) -> (u64, SwarmOutcome) {
    let mut ws = SwarmWorkspace::new(s);
    let seeds = run(p, s, &mut ws).seeds as u64;
    let clock = TickingClock::default();
    let o = swarm::run(
        p,
        s,
        &mut ws,
        Deadline::after(&clock, Duration::from_millis(2 * seeds + extra)),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    (seeds, o)
}

/// The deadline is checked every iteration: on a clock that advances 1 ms per reading, a
/// budget that covers the seeds (each built and each scored reads the clock once) and 30
/// more readings stops the run after some iterations with `MaxTime` and a valid best
/// path.
#[test]
fn a_deadline_during_the_run_stops_it() {
    let p = problem("2d-min-time-avoidable");
    let s = small()
        .with_max_iterations(1000)
        .with_stall_iterations(1000);
    let (seeds, o) = ticking_run(&p, &s, 30);
    assert_eq!(o.status, SwarmStatus::MaxTime);
    assert_eq!(o.seeds as u64, seeds);
    assert!(
        o.iterations > 0 && o.iterations < 40,
        "{} iterations",
        o.iterations
    );
    assert!(o.best.is_valid());
    assert!(o.cost <= o.seeds_best_cost);
}

/// The swarm starts a round of its particles only while one still fits: on a clock that
/// advances 1 ms per reading, a budget that leaves a few readings after the seeds (less
/// than the first round is expected to take: as long as scoring as many seeds) returns the
/// best seed with no iteration, instead of starting a round it would end past the
/// deadline.
#[test]
fn no_round_starts_that_would_end_past_the_deadline() {
    let p = problem("2d-min-time-avoidable");
    let s = small().with_threads(1);
    let (seeds, o) = ticking_run(&p, &s, 4);
    assert_eq!(o.status, SwarmStatus::MaxTime);
    assert_eq!(o.seeds as u64, seeds, "every seed scored");
    assert_eq!(o.iterations, 0, "no round started");
    assert_eq!(o.evaluations, o.seeds, "not even the particles' first");
    assert!(o.best.is_valid());
    assert_eq!(o.cost, o.seeds_best_cost);
}

/// A deadline too short for the seeds: the first ones are built and scored (at least
/// one), the rest left out, and the best of those scored comes back, valid.
#[test]
fn a_deadline_during_the_seeds_keeps_the_first_ones() {
    let p = problem("2d-min-time-avoidable");
    let s = small();
    let mut ws = SwarmWorkspace::new(&s);
    let all = run(&p, &s, &mut ws);
    let clock = TickingClock::default();
    let o = swarm::run(
        &p,
        &s,
        &mut ws,
        Deadline::after(&clock, Duration::from_millis(all.seeds as u64 / 2)),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(o.status, SwarmStatus::MaxTime);
    assert_eq!(o.iterations, 0);
    assert!(
        o.seeds >= 1 && o.seeds < all.seeds,
        "{} of {}",
        o.seeds,
        all.seeds
    );
    assert!(o.best.is_valid());
    assert!(o.cost.is_finite());
    // The seeds built are the first of the full set, in order: the same best or a worse.
    assert!(o.seeds_best_cost >= all.seeds_best_cost);
}

/// The swarm's objective of its best 2-D path equals an independent evaluation on the
/// returned trajectory: `alpha tf + (1 - alpha) ∫ (1 - beta) u² + beta E(p, t) dt`, the
/// effort integrated exactly for the held turn rates and the exposure of
/// `Problem::exposure` by the trapezoid rule on the samples (relative 2e-3: the swarm
/// integrates on its uniform samples, the trajectory adds the pass samples). In 3-D the
/// exposure integral is compared the same way.
#[test]
fn the_swarm_cost_matches_an_independent_evaluation() {
    for name in [
        "2d-min-time-avoidable",
        "2d-fixed-time-unavoidable",
        "2d-min-time-rendezvous-unavoidable",
        "3d-min-time-moving-threat",
    ] {
        let p = problem(name);
        let s = small();
        let mut ws = SwarmWorkspace::new(&s);
        let o = run(&p, &s, &mut ws);
        let t = &o.best;
        let (mut expo, mut effort) = (0.0, 0.0);
        for i in 0..t.len() - 1 {
            let dt = t.times[i + 1] - t.times[i];
            let ea = p.exposure(&position(&p, &t.states[i]), t.times[i]);
            let eb = p.exposure(&position(&p, &t.states[i + 1]), t.times[i + 1]);
            expo += 0.5 * dt * (ea + eb);
            effort += t.controls[i][0].powi(2) * dt;
        }
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-9);
        assert!(
            rel(expo, o.report.exposure_integral) < 2e-3
                || (expo - o.report.exposure_integral).abs() < 1e-3,
            "{name}: exposure {expo} vs {}",
            o.report.exposure_integral
        );
        if p.model == Model::TwoD {
            let w = &p.weights;
            let tf = t.final_time().unwrap_or(f64::NAN);
            let j_run = (1.0 - w.beta) * effort + w.beta * expo;
            let objective = match p.objective {
                Objective::FixedTime => j_run,
                _ => w.alpha * tf + (1.0 - w.alpha) * j_run,
            };
            assert!(
                rel(effort, o.report.effort_integral) < 1e-9,
                "{name}: effort {effort} vs {}",
                o.report.effort_integral
            );
            assert!(
                rel(objective, o.report.objective) < 2e-3,
                "{name}: objective {objective} vs {}",
                o.report.objective
            );
        }
    }
}

/// The returned path follows the model. 2-D: each sample is the exact arc from the one
/// before with the held turn rate (1e-6 m, 1e-9 rad). 3-D: constant speed (each chord is
/// `V dt` within 1e-3) along the mean flight-path angle and heading of its ends (2e-3 rad:
/// the midpoint rule of the reduced model), `Nz` and `mu` lifted (finite, `|mu| <= pi/2`).
#[test]
fn the_returned_path_follows_the_model() {
    for name in ["2d-min-time-rendezvous-avoidable", "3d-min-time-avoidable"] {
        let p = problem(name);
        let s = small();
        let mut ws = SwarmWorkspace::new(&s);
        let t = run(&p, &s, &mut ws).best;
        let v = p.limits.speed;
        for i in 0..t.len() - 1 {
            let (a, b) = (&t.states[i], &t.states[i + 1]);
            let dt = t.times[i + 1] - t.times[i];
            match p.model {
                Model::TwoD => {
                    let u = t.controls[i][0];
                    let psi = a[2] + u * dt;
                    let (x, y) = if u.abs() > 1e-12 {
                        (
                            a[0] + v / u * (psi.sin() - a[2].sin()),
                            a[1] - v / u * (psi.cos() - a[2].cos()),
                        )
                    } else {
                        (a[0] + v * dt * a[2].cos(), a[1] + v * dt * a[2].sin())
                    };
                    assert!(
                        (x - b[0]).abs() < 1e-6 && (y - b[1]).abs() < 1e-6,
                        "{name} {i}"
                    );
                    assert!((psi - b[2]).abs() < 1e-9, "{name} {i}");
                    assert!(u.abs() <= p.limits.turn_rate_max + 1e-12);
                }
                Model::ThreeD => {
                    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    assert!((len - v * dt).abs() < 1e-3 * v * dt, "{name} {i}: {len}");
                    let gm = 0.5 * (a[3] + b[3]);
                    let cm = a[4] + 0.5 * wrap_angle(b[4] - a[4]);
                    assert!((d[2] / len - gm.sin()).abs() < 2e-3, "{name} {i} gamma");
                    assert!(
                        wrap_angle(d[1].atan2(d[0]) - cm).abs() < 2e-3,
                        "{name} {i} chi"
                    );
                    assert!(a[5].is_finite() && a[6].abs() <= std::f64::consts::FRAC_PI_2);
                    assert!(a[3].abs() <= p.limits.gamma_max + 1e-12);
                    assert!(a[2] >= p.limits.z_min - 1.0);
                }
            }
        }
    }
}

/// The seeds' paths are exposed for plotting, one per seed, each from the start.
#[test]
fn seed_paths_are_exposed() {
    let p = problem("3d-min-time-avoidable");
    let s = small();
    let mut ws = SwarmWorkspace::new(&s);
    let o = run(&p, &s, &mut ws);
    assert_eq!(ws.seed_paths().count(), o.seeds);
    for (_, pts) in ws.seed_paths() {
        assert_eq!(pts[0], [p.x0[0], p.x0[1], p.x0[2]]);
    }
}

/// The other groups' bests come back as candidates: valid, feasible, and different paths
/// from the returned one and from each other.
#[test]
fn candidates_are_other_paths() {
    let p = problem("2d-min-time-avoidable");
    let s = small().with_candidates(2);
    let mut ws = SwarmWorkspace::new(&s);
    let o = run(&p, &s, &mut ws);
    assert!(!o.candidates.is_empty() && o.candidates.len() <= 2);
    for c in &o.candidates {
        assert!(c.trajectory.is_valid() && c.report.feasible);
        assert!(c.trajectory != o.best);
    }
    assert!(
        o.candidates
            .windows(2)
            .all(|w| w[1].trajectory != w[0].trajectory)
    );
}

/// The dissertation's direct parameterisation (the controls themselves) also runs,
/// deterministically.
#[test]
fn the_direct_parameterisation_runs() {
    let p = problem("2d-fixed-time-avoidable");
    let s = small().with_parameterisation(Parameterisation::Direct);
    let mut ws = SwarmWorkspace::new(&s);
    let a = run(&p, &s, &mut ws);
    let b = run(&p, &s, &mut ws);
    assert!(a.best.is_valid());
    assert_eq!(a.best, b.best);
}

/// Bad settings and ill-posed problems are errors, not panics.
#[test]
fn bad_input_is_an_error() {
    let p = problem("2d-min-time-avoidable");
    let clock = ManualClock::new();
    let mut ws = SwarmWorkspace::new(&small());
    for bad in [
        small().with_particles(1),
        small().with_dt(f64::NAN),
        small().with_substeps(0),
        small().with_groups(0),
        small().with_d_star(-1.0),
        small().with_threads(0),
        small().with_constriction(1.5),
    ] {
        assert!(matches!(
            swarm::run(&p, &bad, &mut ws, Deadline::never(&clock)),
            Err(SwarmError::Settings(_))
        ));
    }
    let mut q = p.clone();
    q.x0[0] = f64::NAN;
    assert!(matches!(
        swarm::run(&q, &small(), &mut ws, Deadline::never(&clock)),
        Err(SwarmError::Problem(_))
    ));
    let mut q = p.clone();
    q.final_state = None;
    assert!(matches!(
        swarm::run(&q, &small(), &mut ws, Deadline::never(&clock)),
        Err(SwarmError::Problem(_))
    ));
    // A problem that still works after the errors.
    let o = swarm::run(&p, &small(), &mut ws, Deadline::never(&clock));
    assert!(o.is_ok_and(|o| o.best.is_valid()));
}
