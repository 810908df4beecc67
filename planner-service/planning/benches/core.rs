//! Benchmarks of the planning core (issue 4): layout exposure per point with the
//! `3d-replan-popups` static threats, one Kalman predict + update, and `t_r` on a
//! 512-sample plan. Numbers and the command are in `docs/BENCHMARKS.md`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use wingman_planning::estimation::{Estimate, GaussMarkov, KalmanFilter, MovingThreat};
use wingman_planning::problem::{Problem, Threats};
use wingman_planning::replan::{PlanPoint, moving_popup_hit, replan_time};
use wingman_planning::scenario::bundled;
use wingman_planning::threat::ThreatLayout;

/// The static threats of `scenarios/3d-replan-popups.toml` known at take-off and its
/// moving threat "mobile-sam" (estimate at t = 0), as the planner's problem holds them.
fn popups() -> (ThreatLayout<3>, MovingThreat<3>) {
    let sc = bundled("3d-replan-popups").unwrap().unwrap();
    match Problem::from_scenario(&sc).unwrap().threats {
        Threats::Spatial { layout, moving } => (layout, moving.into_iter().next().unwrap()),
        Threats::Planar { .. } => unreachable!("a 3-D scenario"),
    }
}

fn popups_layout() -> ThreatLayout<3> {
    popups().0
}

fn mobile_sam() -> MovingThreat<3> {
    popups().1
}

/// 32 x 32 points over the scenario's area (x 0..160 km, y 0..140 km) at 3000 m.
fn grid_points() -> Vec<[f64; 3]> {
    (0..32 * 32)
        .map(|k| [(k % 32) as f64 * 5000.0, (k / 32) as f64 * 4500.0, 3000.0])
        .collect()
}

/// 1024 points each within 1.4 semi-axes of a threat centre (every threat near them is
/// evaluated in full: the cut-off spares nothing of the nearest one).
fn near_points(layout: &ThreatLayout<3>) -> Vec<[f64; 3]> {
    (0..1024)
        .map(|k| {
            let t = &layout.threats()[k % layout.len()];
            let a = (k as f64 * 0.618_034).fract() * std::f64::consts::TAU;
            let r = 0.6 + 0.8 * (k as f64 * 0.414_214).fract();
            let (c, ax) = (t.center(), t.axes());
            [
                c[0] + r * ax[0] * a.cos(),
                c[1] + r * ax[1] * a.sin(),
                0.3 * ax[2],
            ]
        })
        .collect()
}

fn exposure(c: &mut Criterion) {
    let layout = popups_layout();
    let sets = [("grid", grid_points()), ("near", near_points(&layout))];
    let mut g = c.benchmark_group("exposure_1024_points");
    g.throughput(Throughput::Elements(1024));
    for (name, pts) in &sets {
        g.bench_function(format!("{name}/E"), |b| {
            b.iter(|| {
                pts.iter()
                    .map(|w| layout.exposure(black_box(w)))
                    .sum::<f64>()
            })
        });
        g.bench_function(format!("{name}/E+grad"), |b| {
            b.iter(|| {
                pts.iter()
                    .map(|w| layout.exposure_grad(black_box(w)).1[0])
                    .sum::<f64>()
            })
        });
        g.bench_function(format!("{name}/E+grad+hess"), |b| {
            b.iter(|| {
                pts.iter()
                    .map(|w| layout.exposure_hess(black_box(w)).hess[(0, 1)])
                    .sum::<f64>()
            })
        });
    }
    g.finish();
}

fn kalman(c: &mut Criterion) {
    let gm = GaussMarkov::new(60.0, 0.3).unwrap();
    let est = Estimate::with_sigmas(0.0, [58000.0, 15.0, 0.0], [500.0, 3.0, 0.3]).unwrap();
    let mut g = c.benchmark_group("kalman");
    g.bench_function("predict+update (dt = 1 s, cached Phi/Qd)", |b| {
        let mut kf = KalmanFilter::new(gm, 200.0, est).unwrap();
        let mut z = 58000.0;
        b.iter(|| {
            kf.predict(black_box(1.0)).unwrap();
            z += 15.0;
            kf.update(black_box(z)).unwrap();
            if kf.estimate().t > 1e5 {
                kf.reset(est);
                z = 58000.0;
            }
        })
    });
    g.bench_function("predict+update (new dt: Van Loan expm)", |b| {
        let mut kf = KalmanFilter::new(gm, 200.0, est).unwrap();
        let mut k = 0u64;
        b.iter(|| {
            k += 1;
            let dt = 0.9 + (k % 1000) as f64 * 1e-4;
            kf.predict(black_box(dt)).unwrap();
            kf.update(black_box(58000.0 + 15.0 * kf.estimate().t))
                .unwrap();
            if kf.estimate().t > 1e5 {
                kf.reset(est);
            }
        })
    });
    g.bench_function("discretize(dt = 1 s)", |b| {
        b.iter(|| gm.discretize(black_box(1.0)).unwrap())
    });
    g.finish();
}

fn replan(c: &mut Criterion) {
    let threat = mobile_sam();
    // 512 samples at 1 s heading away from the threat: no sample triggers, so every
    // sample is evaluated (the worst case)
    let plan: Vec<PlanPoint<3>> = (0..512)
        .map(|i| {
            let t = i as f64;
            PlanPoint {
                t,
                position: [-100.0 * t, 250.0 * t, 15000.0],
                velocity: [-100.0, 250.0, 0.0],
            }
        })
        .collect();
    assert!(replan_time(&plan, &threat).is_none());
    let mut g = c.benchmark_group("replan_512_samples");
    g.throughput(Throughput::Elements(512));
    g.bench_function("t_r (full scan)", |b| {
        b.iter(|| replan_time(black_box(&plan), black_box(&threat)))
    });
    g.bench_function("moving pop-up test (full scan)", |b| {
        b.iter(|| moving_popup_hit(black_box(&plan), black_box(&threat), 1.0))
    });
    g.finish();
}

criterion_group!(benches, exposure, kalman, replan);
criterion_main!(benches);
