//! The hot paths do not allocate: a counting global allocator around the Kalman predict /
//! update and the exposure evaluations (with gradient and Hessian), plus the other calls
//! the optimizer and the service make in loops.
//!
//! The count is per thread (a `const`-initialised thread-local, which itself never
//! allocates), so tests running in parallel do not disturb each other.

use std::hint::black_box;

use wingman_planning::dynamics::{OdeModel, Spatial, rk4_step};
use wingman_planning::estimation::{
    Estimate, GaussMarkov, KalmanFilter, Road, exposure_at, exposure_eval_at,
};
use wingman_planning::metrics::exposure_integral;
use wingman_planning::replan::{PlanPoint, moving_popup_hit, replan_time};

mod common;
use common::{mobile_sam, popups_layout};

wingman_testkit::counting_allocator!();
use counting_alloc::allocations_in;
use wingman_testkit::counting_alloc;

#[test]
fn the_counter_sees_allocations() {
    // the guard itself works: a heap allocation is counted
    let n = allocations_in(|| {
        black_box(vec![1u8; 64]);
    });
    assert!(
        n >= 1,
        "the counting allocator saw {n} allocations for a Vec"
    );
}

#[test]
fn kalman_predict_and_update_do_not_allocate() {
    let gm = GaussMarkov::new(60.0, 0.3).unwrap();
    let est = Estimate::with_sigmas(0.0, [58000.0, 15.0, 0.0], [500.0, 3.0, 0.3]).unwrap();
    let road = Road::new(&[[70000.0, 0.0, 0.0], [100000.0, 150000.0, 0.0]]).unwrap();
    let mut kf = KalmanFilter::new(gm, 200.0, est).unwrap();
    let n = allocations_in(|| {
        for k in 0..200 {
            // varying steps: every other predict recomputes Phi, Qd (matrix exponential)
            let dt = if k % 2 == 0 {
                1.0
            } else {
                0.5 + 0.001 * k as f64
            };
            kf.predict(dt).unwrap();
            kf.update(58000.0 + 15.0 * k as f64).unwrap();
            kf.update_position(&road, &[80000.0, 60000.0, 10.0])
                .unwrap();
        }
        kf.predict_to(kf.estimate().t + 3600.0).unwrap();
        black_box(gm.discretize(1234.5).unwrap());
        black_box(gm.distance_at(kf.estimate(), 5000.0));
    });
    assert_eq!(n, 0, "Kalman predict/update allocated {n} times");
}

#[test]
fn exposure_and_derivatives_do_not_allocate() {
    let layout = popups_layout();
    let mv = [mobile_sam()];
    let n = allocations_in(|| {
        for i in 0..500 {
            let w = [300.0 * i as f64, 200.0 * i as f64, 5000.0];
            black_box(layout.exposure(&w));
            black_box(layout.exposure_grad(&w));
            black_box(layout.exposure_hess(&w));
            black_box(exposure_at(&layout, &mv, &w, i as f64));
            black_box(exposure_eval_at(&layout, &mv, &w, i as f64));
            black_box(mv[0].eval(&w, i as f64));
        }
    });
    assert_eq!(n, 0, "exposure evaluation allocated {n} times");
}

#[test]
fn dynamics_replan_and_metrics_do_not_allocate() {
    let model = Spatial::new(250.0).unwrap();
    let threat = mobile_sam();
    let layout = popups_layout();
    let plan: Vec<PlanPoint<3>> = (0..512)
        .map(|i| {
            let t = i as f64;
            PlanPoint {
                t,
                position: [60000.0 + 150.0 * t, 20000.0 + 100.0 * t, 3000.0],
                velocity: [150.0, 100.0, 0.0],
            }
        })
        .collect();
    let times: Vec<f64> = plan.iter().map(|p| p.t).collect();
    let positions: Vec<[f64; 3]> = plan.iter().map(|p| p.position).collect();
    let n = allocations_in(|| {
        let x = [0.0, 0.0, 3000.0, 0.05, 0.3, 1.1, 0.2];
        black_box(rk4_step(&model, &x, &[0.1, 0.05], 0.1));
        black_box(model.jac_x(&x, &[0.1, 0.05]));
        black_box(model.hessians(&x, &[0.1, 0.05]));
        black_box(replan_time(&plan, &threat));
        black_box(moving_popup_hit(&plan, &threat, 1.0));
        black_box(exposure_integral(&times, &positions, &layout, &[threat]));
    });
    assert_eq!(n, 0, "dynamics / replan / metrics allocated {n} times");
}
