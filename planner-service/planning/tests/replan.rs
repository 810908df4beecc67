//! Re-plan timing (FORMULATION.md §6): `t_r` of eqs. (7.1)–(7.6) on a hand-worked
//! crossing, the property that `t_r` never comes after the plan enters the propagated
//! keep-out region, and the pop-up test.

// Index loops over matrix and vector entries read like the formulas they check.
#![allow(clippy::needless_range_loop)]

use proptest::prelude::*;
use proptest::test_runner::{Config as ProptestConfig, RngSeed};
use wingman_planning::estimation::{Estimate, GaussMarkov, MovingThreat, Road};
use wingman_planning::replan::{
    PlanPoint, ReplanCause, critical_distance, moving_popup_hit, replan_time, static_popup_hit,
};
use wingman_planning::threat::Threat2;

/// Straight-line plan `w(t) = p0 + v t`, samples at `t = 0, 1, ..., n-1` s.
fn straight_plan<const D: usize>(p0: [f64; D], v: [f64; D], n: usize) -> Vec<PlanPoint<D>> {
    (0..n)
        .map(|i| {
            let t = i as f64;
            PlanPoint {
                t,
                position: std::array::from_fn(|k| p0[k] + v[k] * t),
                velocity: v,
            }
        })
        .collect()
}

/// The threat drives north (+y) on the road x = 0 at 10 m/s from (0, -2000) at t = 0; no
/// process noise and a certain speed, so `sigma_d = 500` m at all times; `ax0 = 1000`.
fn northbound_threat<const D: usize>() -> MovingThreat<D> {
    let mut a = [0.0; D];
    let mut b = [0.0; D];
    a[1] = -10000.0;
    b[1] = 10000.0;
    let road = Road::new(&[a, b]).unwrap();
    let est = Estimate::with_sigmas(0.0, [8000.0, 10.0, 0.0], [500.0, 0.0, 0.0]).unwrap();
    MovingThreat::new(road, [1000.0; D], GaussMarkov::new(60.0, 0.0).unwrap(), est).unwrap()
}

/// Hand-worked case. Wingman: `w(t) = (-6000 + 60 t, -8000 + 80 t)` (100 m/s, heading
/// 53.13°); threat centre `c(t) = (0, -2000 + 10 t)`, velocity (0, 10).
///
/// - `|cos alpha| = |(60, 80)·(0, 10)| / (100 · 10) = 0.8` (eq. 7.6), constant;
/// - `|c(t) - c(0)| = 10 t`; `w - c = (60 t - 6000, 70 t - 6000)`, `H² = (60t-6000)² + (70t-6000)²`;
/// - `rho = ax0 + sigma (1 + xi) = 1000 + 500 (1 + 10 t · 0.8 / H)` (eqs. 7.4, 7.5), so
///   `H <= rho  <=>  H² - 1500 H - 4000 t <= 0`.
/// - t = 74: `w - c = (-1560, -820)`, `H² = 3 106 000`, `H = 1762.385`:
///   `3 106 000 - 2 643 577 - 296 000 = 166 423 > 0`, no trigger;
/// - t = 75: `w - c = (-1500, -750)`, `H² = 2 812 500`, `H = 1677.051`:
///   `2 812 500 - 2 515 576 - 300 000 = -3 076 <= 0`: **t_r = 75 s**, with
///   `rho = 1500 + 500 · 600 / 1677.051 = 1678.886` m.
///
/// At 75 s the wingman is still outside the region (`F = (750/1500)^2.5 + (1500/1000)² =
/// 2.43`), so the cause is the critical distance.
#[test]
fn hand_worked_crossing() {
    let plan = straight_plan([-6000.0, -8000.0], [60.0, 80.0], 201);
    let threat = northbound_threat::<2>();
    let tr = replan_time(&plan, &threat).expect("the plan approaches the threat");
    assert_eq!(tr.index, 75);
    assert_eq!(tr.t, 75.0);
    assert_eq!(tr.cause, ReplanCause::CriticalDistance);
    // tolerance: 1e-6 m on the hand-computed distances
    assert!(
        (tr.h - 2_812_500.0_f64.sqrt()).abs() <= 1e-6,
        "H = {}",
        tr.h
    );
    assert!(
        (tr.rho - (1500.0 + 300_000.0 / 2_812_500.0_f64.sqrt())).abs() <= 1e-6,
        "rho = {}",
        tr.rho
    );
    let c0 = *threat.region_at(0.0).shape.center();
    let before = critical_distance(&threat, &c0, &plan[74]);
    assert!(!before.triggers);
    assert!((before.h - 3_106_000.0_f64.sqrt()).abs() <= 1e-6);
    assert!((before.abs_cos_alpha - 0.8).abs() <= 1e-15);
    assert!((before.travelled - 740.0).abs() <= 1e-9);
    assert!((threat.f(&plan[75].position, 75.0) - (0.5f64.powf(2.5) + 2.25)).abs() <= 1e-12);

    // the same crossing in 3-D (road and wingman at z = 0) gives the same instant
    let plan3 = straight_plan([-6000.0, -8000.0, 0.0], [60.0, 80.0, 0.0], 201);
    let tr3 = replan_time(&plan3, &northbound_threat::<3>()).unwrap();
    assert_eq!((tr3.index, tr3.cause), (75, ReplanCause::CriticalDistance));

    // flying away from the threat: no re-plan
    let away = straight_plan([-6000.0, -8000.0], [-60.0, -80.0], 201);
    assert_eq!(replan_time(&away, &threat), None);
    assert_eq!(replan_time(&[], &threat), None);
}

/// A crossing geometry that always enters the region: the wingman passes within half an
/// axis of the threat's predicted centre at an integer time `tc`.
#[derive(Debug, Clone)]
struct Crossing {
    road_dir: f64,
    road_origin: [f64; 2],
    d0: f64,
    speed_t: f64,
    sigma: [f64; 3],
    sigma_a: f64,
    tau: f64,
    ax0: f64,
    ay: f64,
    heading: f64,
    speed_w: f64,
    tc: usize,
    offset: [f64; 2],
}

fn crossing() -> impl Strategy<Value = Crossing> {
    (
        (
            0.0..std::f64::consts::TAU,
            -2e4..2e4,
            -2e4..2e4,
            0.0..3e4,
            0.0..30.0,
        ),
        (0.0..2000.0, 0.0..5.0, 0.0..0.5, 0.0..1.0, 5.0..200.0),
        (
            500.0..10000.0,
            500.0..15000.0,
            0.0..std::f64::consts::TAU,
            100.0..300.0,
            30usize..300,
        ),
        (-0.5..0.5, -0.5..0.5),
    )
        .prop_map(
            |(
                (road_dir, ox, oy, d0, speed_t),
                (s0, s1, s2, sigma_a, tau),
                (ax0, ay, heading, speed_w, tc),
                (o0, o1),
            )| {
                Crossing {
                    road_dir,
                    road_origin: [ox, oy],
                    d0,
                    speed_t,
                    sigma: [s0, s1, s2],
                    sigma_a,
                    tau,
                    ax0,
                    ay,
                    heading,
                    speed_w,
                    tc,
                    offset: [o0, o1],
                }
            },
        )
}

fn build(c: &Crossing) -> (MovingThreat<2>, Vec<PlanPoint<2>>) {
    let (s, co) = c.road_dir.sin_cos();
    let [ox, oy] = c.road_origin;
    let road = Road::new(&[[ox, oy], [ox + 2e5 * co, oy + 2e5 * s]]).unwrap();
    let est = Estimate::with_sigmas(0.0, [c.d0, c.speed_t, 0.0], c.sigma).unwrap();
    let threat = MovingThreat::new(
        road,
        [c.ax0, c.ay],
        GaussMarkov::new(c.tau, c.sigma_a).unwrap(),
        est,
    )
    .unwrap();
    let tc = c.tc as f64;
    let reg = threat.region_at(tc);
    let centre = *reg.shape.center();
    let m = 0.5 * c.ax0.min(c.ay);
    let at_tc = [centre[0] + c.offset[0] * m, centre[1] + c.offset[1] * m];
    let v = [c.speed_w * c.heading.cos(), c.speed_w * c.heading.sin()];
    let plan = straight_plan([at_tc[0] - v[0] * tc, at_tc[1] - v[1] * tc], v, 400);
    (threat, plan)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 512,
        rng_seed: RngSeed::Fixed(0x072e_91a4),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// `t_r` exists and lies at or before the first sample inside the propagated keep-out
    /// region (F < 1), and no earlier sample meets either trigger (t_r is the first).
    #[test]
    fn replan_time_never_after_entering_the_region(c in crossing()) {
        let (threat, plan) = build(&c);
        let first_inside = plan.iter().position(|p| threat.f(&p.position, p.t) < 1.0);
        prop_assert!(first_inside.is_some(), "the generated plan must enter the region");
        let entry = first_inside.unwrap_or(usize::MAX);
        let tr = replan_time(&plan, &threat);
        prop_assert!(tr.is_some());
        let tr = tr.unwrap_or_else(|| unreachable!());
        prop_assert!(tr.index <= entry, "t_r at sample {} after entering at {}", tr.index, entry);
        let c0 = *threat.region_at(plan[0].t).shape.center();
        for p in &plan[..tr.index] {
            let cd = critical_distance(&threat, &c0, p);
            prop_assert!(!cd.triggers && threat.f(&p.position, p.t) > 1.0);
            // the division-free test agrees with H <= rho written out (eq. 7.3)
            prop_assert!(cd.h > cd.rho);
        }
    }
}

#[test]
fn popup_test_finds_the_first_sample_inside() {
    // path along the x-axis at 100 m/s; a circle of radius 1000 m centred at (10000, 500):
    // F = ((x - 10000)² + 500²)/1000² < 1 first at x = 9200 (t = 92 s, F = 0.89);
    // F < 0.5 first at x = 9600 (t = 96 s, F = 0.41)
    let plan = straight_plan([0.0, 0.0], [100.0, 0.0], 201);
    let circle = Threat2::ellipsoid([10000.0, 500.0], [1000.0, 1000.0]).unwrap();
    let hit = static_popup_hit(&plan, &circle, 1.0).unwrap();
    assert_eq!((hit.index, hit.t), (92, 92.0));
    assert!((hit.f - 0.89).abs() <= 1e-12);
    let hit = static_popup_hit(&plan, &circle, 0.5).unwrap();
    assert_eq!(hit.index, 96);
    assert!((hit.f - 0.41).abs() <= 1e-12);
    // remaining samples only: from t = 93 s the first remaining sample is inside
    assert_eq!(
        static_popup_hit(&plan[93..], &circle, 1.0).unwrap().index,
        0
    );
    assert_eq!(static_popup_hit(&plan[110..], &circle, 1.0), None);
    // a pop-up far from the plan causes no re-plan
    let far = Threat2::ellipsoid([20000.0, 140000.0], [10000.0, 10000.0]).unwrap();
    assert_eq!(static_popup_hit(&plan, &far, 1.0), None);
}

/// The moving threat counts at its propagated region. Road x = 15000 northwards; the threat
/// starts at y = -3000 at 10 m/s with sigma_d = 600 m held (no process noise), so
/// `ax = 1600`, `px = 2.6`. Wingman on y = 0 at 100 m/s from x = 0. At time t:
/// `F = |(3000 - 10t)/1600|^2.6 + ((100t - 15000)/800)²`:
/// t = 147: 0.8902 + 0.1406 = 1.031; t = 148: 0.8752 + 0.0625 = 0.9377 → first hit 148 s.
/// Without the inflation (ax = 1000, px = 2) the path never enters: at t = 150, F = 2.25.
#[test]
fn popup_test_uses_the_propagated_moving_region() {
    let road = Road::new(&[[15000.0, -50000.0], [15000.0, 50000.0]]).unwrap();
    let model = GaussMarkov::new(60.0, 0.0).unwrap();
    let est = Estimate::with_sigmas(0.0, [47000.0, 10.0, 0.0], [600.0, 0.0, 0.0]).unwrap();
    let threat = MovingThreat::new(road, [1000.0, 800.0], model, est).unwrap();
    let plan = straight_plan([0.0, 0.0], [100.0, 0.0], 301);
    let hit = moving_popup_hit(&plan, &threat, 1.0).unwrap();
    assert_eq!(hit.index, 148);
    // tolerance 1e-4 on the hand-computed F
    assert!((hit.f - 0.9377).abs() <= 1e-4, "F = {}", hit.f);
    let certain = Estimate::with_sigmas(0.0, [47000.0, 10.0, 0.0], [0.0, 0.0, 0.0]).unwrap();
    let mut small = threat;
    small.set_estimate(certain);
    assert_eq!(moving_popup_hit(&plan, &small, 1.0), None);
    // before it appears the threat does not count
    let late = threat.with_appears_at(200.0);
    assert_eq!(moving_popup_hit(&plan, &late, 1.0), None);
}
