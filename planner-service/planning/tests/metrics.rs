//! Trajectory metrics: quadrature exactness, the exposure integral against an independent
//! fine-grid computation, minimum F, final and target errors and bound violations, each
//! against a hand computation.

// Index loops over matrix and vector entries read like the formulas they check.
#![allow(clippy::needless_range_loop)]

use wingman_planning::dynamics::{Limits, SpatialLimits};
use wingman_planning::estimation::{Estimate, GaussMarkov, MovingThreat, Road};
use wingman_planning::metrics::{
    BoundViolations, TargetMiss, bound_violations_2d, bound_violations_3d, exposure_integral,
    final_errors_2d, final_errors_3d, min_f_moving, min_f_static, simpson, target_misses,
    time_inside,
};
use wingman_planning::threat::{Threat2, ThreatLayout};

#[test]
fn simpson_is_exact_where_it_should_be() {
    // uniform, odd count: exact for cubics; int_0^2 (x³ - 2x + 1) dx = 4 - 4 + 2 = 2
    let t: Vec<f64> = (0..9).map(|i| i as f64 * 0.25).collect();
    let v: Vec<f64> = t.iter().map(|x| x * x * x - 2.0 * x + 1.0).collect();
    // tolerance: 1e-14 (exact up to rounding)
    assert!((simpson(&t, &v) - 2.0).abs() <= 1e-14);
    // non-uniform: exact for quadratics; int_0^3 (3x² + 1) dx = 27 + 3 = 30
    let t = [0.0, 0.1, 0.5, 0.6, 1.7, 2.0, 3.0];
    let v: Vec<f64> = t.iter().map(|x| 3.0 * x * x + 1.0).collect();
    assert!(
        (simpson(&t, &v) - 30.0).abs() <= 1e-12,
        "{}",
        simpson(&t, &v)
    );
    // even count: Simpson on the first n-1 samples, a trapezoid on the last step
    // (evaluate.py): samples of x² at 0, 1, 2, 3: 1/3 (0 + 4 + 4) + (4 + 9)/2 = 8/3 + 6.5
    let got = simpson(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, 4.0, 9.0]);
    assert!((got - (8.0 / 3.0 + 6.5)).abs() <= 1e-14);
    assert_eq!(simpson(&[1.0], &[5.0]), 0.0);
    assert_eq!(simpson(&[1.0, 3.0], &[5.0, 7.0]), 12.0);
}

/// A straight pass through two overlapping 2-D threats and a moving one, against the
/// exposure computed directly (1 - prod of the logistic eps, every threat) and integrated
/// with the trapezoid rule on a 100x finer grid.
#[test]
fn exposure_integral_matches_a_fine_independent_integration() {
    let s = 8.0;
    let statics = [
        Threat2::ellipsoid([5000.0, 200.0], [1500.0, 1000.0]).unwrap(),
        Threat2::new([7000.0, -300.0], [1200.0, 2000.0], [3.0, 2.0], 0.4).unwrap(),
    ];
    let layout = ThreatLayout::with_threats(s, &statics).unwrap();
    let road = Road::new(&[[9000.0, -5000.0], [9000.0, 5000.0]]).unwrap();
    let est = Estimate::with_sigmas(0.0, [3000.0, 20.0, 0.0], [200.0, 1.0, 0.1]).unwrap();
    let moving = [MovingThreat::new(
        road,
        [800.0, 600.0],
        GaussMarkov::new(30.0, 0.3).unwrap(),
        est,
    )
    .unwrap()
    .with_appears_at(10.0)];
    let pos = |t: f64| [100.0 * t, 50.0 * (t / 20.0).sin()];
    let e = |t: f64| {
        let w = pos(t);
        let mut prod = 1.0;
        for th in &statics {
            prod *= 1.0 / (1.0 + (-s * (th.f(&w) - 1.0)).exp());
        }
        if t >= 10.0 {
            prod *= 1.0 / (1.0 + (-s * (moving[0].f(&w, t) - 1.0)).exp());
        }
        1.0 - prod
    };
    let n = 241; // 0.5 s samples over 120 s
    let times: Vec<f64> = (0..n).map(|i| i as f64 * 0.5).collect();
    let positions: Vec<[f64; 2]> = times.iter().map(|t| pos(*t)).collect();
    let got = exposure_integral(&times, &positions, &layout, &moving);
    let fine = 24001;
    let h = 120.0 / (fine - 1) as f64;
    let mut want = 0.0;
    for i in 0..fine - 1 {
        let t = i as f64 * h;
        want += 0.5 * h * (e(t) + e(t + h));
    }
    // tolerance: 1e-3 relative (Simpson on 0.5 s samples of a sigmoid that turns over
    // ~1 s, against a 5 ms trapezoid; measured difference ~1e-5)
    assert!(
        (got - want).abs() <= 1e-3 * want,
        "Simpson {got} vs fine trapezoid {want}"
    );
    assert!(want > 10.0, "the pass must actually be exposed ({want})");
    // time inside: F < 1 of any threat, per sample
    let inside = time_inside(&times, &positions, &statics, &moving);
    let mut fine_inside = 0.0;
    for i in 0..fine - 1 {
        let t = i as f64 * h;
        let w = pos(t);
        if statics.iter().any(|th| th.f(&w) < 1.0) || (t >= 10.0 && moving[0].f(&w, t) < 1.0) {
            fine_inside += h;
        }
    }
    // tolerance: one sample step per boundary crossing (4 crossings of 0.5 s)
    assert!(
        (inside - fine_inside).abs() <= 2.0,
        "{inside} vs {fine_inside}"
    );
}

#[test]
fn min_f_static_and_moving() {
    let th = Threat2::ellipsoid([1000.0, 0.0], [500.0, 500.0]).unwrap();
    let times = [0.0, 1.0, 2.0, 3.0];
    let pos = [[0.0, 0.0], [900.0, 0.0], [1000.0, 100.0], [2000.0, 0.0]];
    let m = min_f_static(&times, &pos, &th).unwrap();
    // by hand: F = (d/500)²: 4, 0.04, 0.04 (tie: first kept), 4
    assert_eq!(m.index, 1);
    assert!((m.f - 0.04).abs() <= 1e-15);
    assert_eq!(min_f_static(&[], &[], &th), None);
    // a moving threat appearing at t = 2 s only counts from there
    let road = Road::new(&[[0.0, 0.0], [10000.0, 0.0]]).unwrap();
    let est = Estimate::with_sigmas(0.0, [1000.0, 0.0, 0.0], [0.0; 3]).unwrap();
    let mv = MovingThreat::new(
        road,
        [500.0, 500.0],
        GaussMarkov::new(10.0, 0.0).unwrap(),
        est,
    )
    .unwrap()
    .with_appears_at(2.0);
    let m = min_f_moving(&times, &pos, &mv).unwrap();
    assert_eq!((m.index, m.t), (2, 2.0));
    assert!((m.f - 0.04).abs() <= 1e-15);
    assert_eq!(min_f_moving(&times[..2], &pos[..2], &mv), None);
}

#[test]
fn final_and_target_errors() {
    // heading 359° vs 1°: 2° after wrapping
    let deg = std::f64::consts::PI / 180.0;
    let e = final_errors_2d(&[3.0, 4.0, 359.0 * deg], &[0.0, 0.0, 1.0 * deg]);
    assert!((e.position - 5.0).abs() <= 1e-15 && (e.heading - 2.0 * deg).abs() <= 1e-12);
    let e = final_errors_3d(
        &[1.0, 2.0, 2.0, 0.1, -3.1, 1.2, 0.05],
        &[0.0, 0.0, 0.0, 0.0, 3.1, 1.0, 0.0],
    );
    assert!((e.position - 3.0).abs() <= 1e-15);
    assert!((e.heading - (std::f64::consts::TAU - 6.2)).abs() <= 1e-12);
    assert!((e.gamma - 0.1).abs() <= 1e-15 && (e.nz - 0.2).abs() <= 1e-12 && e.mu == 0.05);
    // sequential targets: B is passed first, but A comes first in order, so B is searched
    // only from A's closest approach on
    let path: Vec<[f64; 2]> = (0..=10).map(|i| [i as f64 * 100.0, 0.0]).collect();
    let targets = [[800.0, 30.0], [200.0, 0.0]];
    let mut out = [TargetMiss {
        distance: 0.0,
        index: 0,
    }; 2];
    assert_eq!(target_misses(&path, &targets, &mut out), 2);
    assert_eq!(
        out[0],
        TargetMiss {
            distance: 30.0,
            index: 8
        }
    );
    assert_eq!(
        out[1],
        TargetMiss {
            distance: 600.0,
            index: 8
        }
    );
}

#[test]
fn bound_violations_by_hand() {
    let deg = std::f64::consts::PI / 180.0;
    let limits = Limits::spatial(SpatialLimits {
        speed: 250.0,
        gamma_max: 30.0 * deg,
        nz_min: -1.0,
        nz_max: 4.0,
        mu_max: 70.0 * deg,
        nz_rate_max: 1.0,
        mu_rate_max: 30.0 * deg,
        z_min: 500.0,
    })
    .unwrap();
    let states = [
        [0.0, 0.0, 450.0, 0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 1000.0, -32.0 * deg, 0.0, -1.5, 75.0 * deg],
        [0.0, 0.0, 1000.0, 10.0 * deg, 0.0, 4.25, -71.0 * deg],
    ];
    let controls = [[0.5, 0.0], [-1.75, 31.0 * deg], [0.0, -35.0 * deg]];
    let v = bound_violations_3d(&states, &controls, &limits);
    assert!((v.z_min - 50.0).abs() <= 1e-12);
    assert!((v.gamma - 2.0 * deg).abs() <= 1e-12);
    assert!((v.nz - 0.5).abs() <= 1e-12);
    assert!((v.mu - 5.0 * deg).abs() <= 1e-12);
    assert!((v.u1 - 0.75).abs() <= 1e-12);
    assert!((v.u2 - 5.0 * deg).abs() <= 1e-12);
    assert!((v.max() - 50.0).abs() <= 1e-12);
    assert_eq!(
        bound_violations_3d(&states[..0], &controls[..0], &limits),
        BoundViolations::default()
    );
    let l2 = Limits::planar(100.0, 0.1).unwrap();
    let v = bound_violations_2d(&[[0.05], [-0.13]], &l2);
    assert!((v.u - 0.03).abs() <= 1e-15 && v.z_min == 0.0);
}
