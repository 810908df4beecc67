//! The spline seeds (appendices A and B): where they start, which way they leave, where
//! they pass, how long they are, and how they are flown — each against an independent
//! computation with a stated tolerance.

use wingman_interfaces::{Model, Objective};
use wingman_planning::clock::{Deadline, ManualClock};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::{self, BUNDLED};
use wingman_planning::seeding::{self, Altitude, Seed, SeedError, SeedKind, SeedSettings};
use wingman_planning::swarm::{self, SwarmSettings, SwarmWorkspace};

fn problem(name: &str) -> Problem {
    let sc = scenario::bundled(name)
        .unwrap_or_else(|| panic!("no scenario {name}"))
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    Problem::from_scenario(&sc).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn build(p: &Problem, settings: &SeedSettings) -> Vec<Seed> {
    let mut out = Vec::new();
    seeding::seeds(p, settings, &mut out).unwrap_or_else(|e| panic!("seeds: {e}"));
    out
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn start_of(p: &Problem) -> ([f64; 3], f64) {
    let x = &p.x0;
    match p.model {
        Model::TwoD => ([x[0], x[1], 0.0], x[2]),
        Model::ThreeD => ([x[0], x[1], x[2]], x[4]),
    }
}

/// Every seed starts at the start (1e-6 m) and leaves it along the initial heading: the
/// chord from the first point to the point 20 m along a finely sampled seed (20 000
/// points) points along the heading within 2e-3 rad (a chord of length `l` on a curve of
/// curvature `k` deviates by `k l / 2`; the seeds' curvature is below 1/(2 km) there).
#[test]
fn seeds_leave_the_start_along_the_initial_heading() {
    let settings = SeedSettings::default().with_points_per_seed(20_000);
    for (name, _) in BUNDLED {
        let p = problem(name);
        let (start, heading) = start_of(&p);
        for s in &build(&p, &settings) {
            let first = s.points()[0];
            assert!(dist(&first, &start) < 1e-6, "{name} {}", s.label());
            let ahead = s.point_at_arc(20.0);
            let chord = (ahead[1] - first[1]).atan2(ahead[0] - first[0]);
            let err = (chord - heading).sin().abs();
            assert!(
                err < 2e-3,
                "{name} {}: chord {chord} heading {heading}",
                s.label()
            );
            assert_eq!(s.start_heading(), heading);
        }
    }
}

/// The spline passes through every target and ends at the final point (1e-6 m), the gates
/// index those points, and a 3-D seed stays within `|gamma| <= gamma_max` (slope of its
/// points, 1e-9) and above `z_min`.
#[test]
fn seeds_pass_through_every_target_and_end_at_the_final_point() {
    for (name, _) in BUNDLED {
        let p = problem(name);
        for s in &build(&p, &SeedSettings::default()) {
            let gates = s.gates();
            assert_eq!(gates.len(), p.targets.len() + 1, "{name}");
            for (g, t) in gates.iter().zip(&p.targets) {
                assert!(
                    dist(&s.points()[*g], t) < 1e-6,
                    "{name} {} target",
                    s.label()
                );
            }
            let end = s.points()[*gates.last().unwrap_or(&0)];
            assert_eq!(*gates.last().unwrap_or(&0), s.points().len() - 1);
            if let Some(f) = &p.final_state {
                let want = match p.model {
                    Model::TwoD => [f[0], f[1], 0.0],
                    Model::ThreeD => [f[0], f[1], f[2]],
                };
                assert!(dist(&end, &want) < 1e-6, "{name} {} end", s.label());
            }
            if p.model == Model::ThreeD {
                let tan_max = p.limits.gamma_max.tan();
                for w in s.points().windows(2).zip(s.arc_lengths().windows(2)) {
                    let (pts, arc) = w;
                    let ds = arc[1] - arc[0];
                    if ds > 1.0 {
                        assert!(
                            (pts[1][2] - pts[0][2]).abs() <= tan_max * ds * (1.0 + 1e-9),
                            "{name} {} slope",
                            s.label()
                        );
                    }
                    assert!(pts[0][2] >= p.limits.z_min - 1e-9);
                }
            }
        }
    }
}

/// Every straight/left/right combination per leg is present for each ratio, and in 3-D
/// each with both altitude profiles (the reference's winning starts are of this kind).
#[test]
fn every_left_straight_right_combination_is_present() {
    for (name, profiles) in [("2d-min-time-avoidable", 1), ("3d-min-time-avoidable", 2)] {
        let p = problem(name);
        let seeds = build(&p, &SeedSettings::default());
        for alt in [Altitude::Direct, Altitude::High].iter().take(profiles) {
            for r in [0.25, 0.5] {
                for a in [-r, 0.0, r] {
                    for b in [-r, 0.0, r] {
                        assert!(
                            seeds.iter().any(|s| {
                                let l = s.label();
                                l.kind == SeedKind::Arc
                                    && l.altitude == *alt
                                    && l.bulges[0] == a
                                    && l.bulges[1] == b
                            }),
                            "{name}: no arc ({a}, {b}) {alt:?}"
                        );
                    }
                }
            }
        }
        let names: Vec<String> = seeds.iter().map(|s| s.label().to_string()).collect();
        assert!(names.iter().any(|n| n == "LR@0.5"), "{names:?}");
        assert!(names.iter().any(|n| n == "SS"), "{names:?}");
    }
}

/// A seed's length is its 3-D arc length: the sum of its polyline's chords agrees within
/// 0.5 % (the polyline is an inscribed approximation of the spline).
#[test]
fn seed_length_is_the_arc_length() {
    for name in ["2d-min-time-avoidable", "3d-min-time-avoidable"] {
        let p = problem(name);
        for s in &build(&p, &SeedSettings::default().with_points_per_seed(4000)) {
            let poly: f64 = s.points().windows(2).map(|w| dist(&w[0], &w[1])).sum();
            assert!(
                (poly - s.length()).abs() <= 5e-3 * s.length(),
                "{name} {}: {poly} vs {}",
                s.label(),
                s.length()
            );
        }
    }
}

/// Fixed-time fits are as long as `V (t_f - t_0)` (1e-4 relative, bisection to 1e-6 on
/// the ratio).
#[test]
fn fixed_time_fits_match_the_flight_length() {
    for name in ["2d-fixed-time-avoidable", "3d-fixed-time-unavoidable"] {
        let p = problem(name);
        assert_eq!(p.objective, Objective::FixedTime);
        let want = p.limits.speed * (p.final_time.unwrap_or(0.0) - p.t0);
        let seeds = build(&p, &SeedSettings::default());
        let fits: Vec<&Seed> = seeds
            .iter()
            .filter(|s| s.label().kind == SeedKind::FixedTimeFit)
            .collect();
        assert!(fits.len() >= 8, "{name}: {} fits", fits.len());
        for s in fits {
            assert!(
                (s.length() - want).abs() <= 1e-4 * want,
                "{name} {}: {} vs {want}",
                s.label(),
                s.length()
            );
        }
    }
}

/// Rendezvous seeds end at the lead's position at their predicted meeting time (1e-6 m)
/// along its heading, and that time is when the seed flown at `V` arrives: `t0 + L / V`
/// within 1e-4 of the flight time, `L` from the seed's own polyline (4000 points: its
/// chords are within 3e-5 of the arc, corners of the altitude ramps included; a wrong
/// meeting time is off by seconds).
#[test]
fn rendezvous_seeds_meet_the_lead() {
    for name in [
        "2d-min-time-rendezvous-avoidable",
        "3d-min-time-rendezvous-avoidable",
    ] {
        let p = problem(name);
        let Some(lead) = p.lead else {
            panic!("{name}: no lead");
        };
        let v = p.limits.speed;
        let seeds = build(&p, &SeedSettings::default().with_points_per_seed(4000));
        assert!(seeds.len() >= 25, "{name}");
        for s in &seeds {
            let t = s.rendezvous_time().unwrap_or(f64::NAN);
            assert!(s.rendezvous_residual() < 1e-3, "{name} {}", s.label());
            let lp = lead.at(t);
            let mut want = lp.position;
            if p.model == Model::TwoD {
                want[2] = 0.0;
            }
            let end = *s.points().last().unwrap_or(&[f64::NAN; 3]);
            assert!(dist(&end, &want) < 1e-6, "{name} {}", s.label());
            assert_eq!(s.end_heading(), lp.heading);
            let poly: f64 = s.points().windows(2).map(|w| dist(&w[0], &w[1])).sum();
            let arrive = p.t0 + poly / v;
            assert!(
                (arrive - t).abs() < 1e-4 * (t - p.t0),
                "{name} {}: arrives {arrive}, meeting {t}",
                s.label()
            );
        }
    }
}

/// Flown by the swarm's model (its particles before any iteration), at least 80 % of the
/// seeds reach the end inside the horizon (are feasible; only seeds longer than 1.2 times
/// the shortest may not: the horizon is sized for seeds up to 1.5 times the shortest),
/// and every such seed passes every target within 2 km, at least 90 % of them within
/// 200 m (the guidance homes on the target; measured with the default 6.7 s samples: all
/// but a few 2-D seeds within 200 m, the worst at 1.2 km where the spline makes a hairpin
/// at the target, tighter than the turn-rate bound allows). The target distances are recomputed here from the returned
/// trajectories' states (closest point of the sample segments around the reported
/// pass).
#[test]
fn flown_seeds_pass_every_target() {
    let clock = ManualClock::new();
    for (name, _) in BUNDLED {
        let p = problem(name);
        let settings = SwarmSettings::default().with_max_iterations(0);
        let mut ws = SwarmWorkspace::new(&settings);
        let out = swarm::run(&p, &settings, &mut ws, Deadline::never(&clock))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(out.seeds, ws.seeds().len());
        let h = out.dt / settings.substeps as f64;
        let v = p.limits.speed;
        let rate = match p.model {
            Model::TwoD => p.limits.turn_rate_max,
            Model::ThreeD => {
                let l = &p.limits;
                9.80665 * l.mu_max.tan().min((l.nz_max * l.nz_max - 1.0).sqrt()) / v
            }
        };
        let sagitta = v * h * h * rate / 8.0;
        let shortest = ws
            .seeds()
            .iter()
            .map(|s| s.length())
            .fold(f64::INFINITY, f64::min);
        let mut feasible = 0;
        let (mut passes, mut close) = (0, 0);
        for i in 0..ws.seeds().len() {
            let length = ws.seeds()[i].length();
            let label = ws.seeds()[i].label().to_string();
            let Some((_, rep, traj)) = ws.seed_trajectory(i) else {
                panic!("{name}: seed {i}");
            };
            assert!(traj.is_valid(), "{name} {label}");
            if !rep.feasible {
                assert!(length > 1.2 * shortest, "{name} {label} is infeasible");
                continue;
            }
            feasible += 1;
            let pos: Vec<[f64; 3]> = traj
                .states
                .iter()
                .map(|x| match p.model {
                    Model::TwoD => [x[0], x[1], 0.0],
                    Model::ThreeD => [x[0], x[1], x[2]],
                })
                .collect();
            for (k, t) in p.targets.iter().enumerate() {
                // Closest approach over the segments around the reported pass time.
                let tp = rep.pass_times[k];
                let i0 = traj.times.partition_point(|&s| s < tp).saturating_sub(2);
                let i1 = (i0 + 4).min(pos.len() - 1);
                let d = (i0..i1)
                    .map(|j| segment_distance(&pos[j], &pos[j + 1], t))
                    .fold(f64::INFINITY, f64::min);
                assert!(d < 2000.0, "{name} {label}: target {k} missed by {d} m");
                passes += 1;
                close += usize::from(d < 200.0);
                // The report measures to the chord between samples, the trajectory holds
                // the pass sample on the flown arc: they differ by at most the sagitta
                // `V h² r / 8` of a sample's arc at the turn-rate bound `r` (+10 %).
                assert!(
                    (d - rep.pass_distances[k]).abs() < 1.1 * sagitta,
                    "{name} {label}: {d} vs {}",
                    rep.pass_distances[k]
                );
            }
        }
        assert!(
            feasible * 5 >= ws.seeds().len() * 4,
            "{name}: {feasible} of {} feasible",
            ws.seeds().len()
        );
        assert!(
            close * 10 >= passes * 9,
            "{name}: {close} of {passes} passes within 200 m"
        );
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

/// The same settings give the same seeds (bit for bit), and a reused output vector gives
/// the same as a fresh one.
#[test]
fn seeds_are_deterministic() {
    let p = problem("3d-rendezvous-moving-threat");
    let settings = SeedSettings::default();
    let a = build(&p, &settings);
    let mut b = build(&p, &settings.clone().with_rng_seed(99));
    seeding::seeds(&p, &settings, &mut b).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.label(), y.label());
        assert_eq!(x.points(), y.points());
        assert_eq!(x.length(), y.length());
    }
}

/// Bad settings and problems the seeds cannot serve are errors, not panics.
#[test]
fn bad_settings_are_refused() {
    let p = problem("2d-min-time-avoidable");
    let mut out = Vec::new();
    for bad in [
        SeedSettings::default().with_bulge_ratios(&[f64::NAN]),
        SeedSettings::default().with_bulge_ratios(&[-0.5]),
        SeedSettings::default().with_max_seeds(0),
        SeedSettings::default().with_points_per_seed(3),
        SeedSettings::default().with_scan_steps(1),
        SeedSettings::default().with_random_seeds(500),
    ] {
        assert!(matches!(
            seeding::seeds(&p, &bad, &mut out),
            Err(SeedError::Settings(_))
        ));
    }
    let mut q = p.clone();
    q.lead = None;
    q.objective = Objective::MinTimeRendezvous;
    assert!(matches!(
        seeding::seeds(&q, &SeedSettings::default(), &mut out),
        Err(SeedError::Problem(_))
    ));
}
