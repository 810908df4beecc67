//! A 3-D mission with a threat moving on a road (`3d-min-time-moving-threat`) through the
//! in-process service: the first plan is made from the threat's reported estimate; every
//! track fix goes to its Kalman filter; when the plan carries a scheduled re-plan time
//! `t_r`, a mission clock reaching `t_r - budget` makes a `ScheduledReplan` plan that
//! commits at `t_r`.

mod common;

use std::time::Duration;

use common::*;
use wingman_planning::scenario::bundled;

#[test]
fn a_moving_threat_is_tracked_and_its_t_r_schedules_a_replan() {
    let v = vehicle("moving");
    let mut cfg = test_config(&v);
    // A re-plan commits `budget` after its trigger; with a budget longer than the gap
    // to the next t_r every plan would be due at once. (A debug build may return a
    // swarm-only plan within it: the quality is not checked here.)
    cfg.budget.plan_3d_ms = 5000;
    cfg.budget.replan_3d_ms = 5000;
    let budget_s = cfg.budget.plan_3d_ms as f64 * 1e-3;
    wingman_ipc::logging::init();
    let service = ServiceThread::start(cfg).expect("start the service");
    let mut h = FakeHarness::new(&v);
    assert!(h.wait_until(Duration::from_secs(20), |h| h.status.is_some()));
    let sc = bundled("3d-min-time-moving-threat").unwrap().unwrap();
    let m = &sc.moving_threats[0];
    let mut report = ThreatReport::zeroed();
    report.threat_id = 40;
    report.kind = ThreatKind::Moving.to_wire();
    report.axes_m = m.axes_m;
    report.road_point_count = m.road_m.len() as u32;
    for (k, p) in m.road_m.iter().enumerate() {
        report.road_m[k] = *p;
    }
    report.estimate_time_s = 0.0;
    report.estimate_mean = [m.initial_distance_m, m.initial_speed_mps, 0.0];
    let s = m.initial_sigma;
    report.estimate_covariance = [
        s[0] * s[0],
        0.0,
        0.0,
        0.0,
        s[1] * s[1],
        0.0,
        0.0,
        0.0,
        s[2] * s[2],
    ];
    report.accel_sigma_mps2 = m.accel_sigma_mps2;
    report.accel_tau_s = m.accel_tau_s;
    for t in scenario_threats(&sc) {
        h.send_threat(t);
    }
    h.send_threat(report);
    h.send_tasking(tasking_from(&sc, 1));
    h.wake();
    assert!(
        h.wait_until(Duration::from_secs(180), |h| !h.plans.is_empty()
            && h.status
                .is_some_and(|s| s.state() != Some(PlannerState::Planning))),
        "no first plan: {:?}",
        h.status
    );
    let first = h.plans[0].clone();
    assert_eq!(first.model(), Some(Model::ThreeD));
    assert_eq!(first.trigger(), Some(Trigger::Initial));
    eprintln!(
        "first plan: quality {:?}, final {:.1} s, valid until {:.1} s, t_r {:?}",
        first.quality(),
        first.final_time_s,
        first.valid_until_s,
        first.next_replan()
    );

    // Track fixes at 1 Hz along the road, on the estimate's mean motion.
    let dir = {
        let (a, b) = (m.road_m[0], m.road_m[1]);
        let l = (b[0] - a[0]).hypot(b[1] - a[1]);
        [(b[0] - a[0]) / l, (b[1] - a[1]) / l]
    };
    for k in 1..=10 {
        let t = k as f64;
        h.set_time(t);
        let d = m.initial_distance_m + m.initial_speed_mps * t;
        let mut fix = TrackFix::zeroed();
        fix.threat_id = 40;
        fix.time_s = t;
        fix.position_m = [
            m.road_m[0][0] + d * dir[0],
            m.road_m[0][1] + d * dir[1],
            0.0,
        ];
        fix.sigma_m = m.sensor.sigma_m;
        h.send_fix(fix);
        h.wake();
    }
    assert!(h.wait_processed(Duration::from_secs(60)));
    let s = h.last_status();
    assert_eq!(s.messages_rejected, 0);
    assert_eq!(
        s.stale_inputs & STALE_TRACKS,
        0,
        "the fixes keep the track fresh"
    );
    assert_eq!(s.plans_made, 1, "fixes alone do not re-plan");

    // T5: the threat drives up its road across the straight line to the final point,
    // and its uncertainty grows with time: the plan comes within rho of it, so it
    // carries a t_r (444.6 s in a release build) and is valid only until then.
    let t_r = first
        .next_replan()
        .expect("the first plan passes the moving threat's region: it carries a t_r");
    assert_eq!(first.valid_until_s, t_r.min(first.final_time_s));
    // The mission clock nears t_r - budget in ownship reports 0.1 s apart: the planner
    // sees time pass in those steps, so the scheduled re-plan fires one step early, at
    // the first report at or after t_r - budget - 0.1 s, and commits before t_r (fired at
    // the first report after t_r - budget, it would commit up to a step after t_r, and the
    // tracker would hold in between).
    let step = 0.1;
    let own_at = |t: f64| {
        let mut own = OwnshipState::zeroed();
        own.time_s = t;
        own.model = Model::ThreeD.to_wire();
        own.plan_id = first.plan_id;
        own.state = wingman_planning::plan_message::state_at(&first, t).unwrap();
        own
    };
    for k in [3.0, 2.0] {
        // The first report has no step yet (the lead is the budget); the second is one
        // step short of the lead with it: a near miss.
        let t = t_r - budget_s - k * step;
        h.set_time(t);
        h.send_ownship(own_at(t));
        h.wake();
        assert!(h.wait_processed(Duration::from_secs(60)));
        let s = h.last_status();
        assert!(
            s.plans_made == 1 && s.state() != Some(PlannerState::Planning),
            "no re-plan yet at t_r - budget - {k} steps: {s:?}"
        );
    }
    let fired_at = t_r - budget_s - step;
    h.set_time(fired_at);
    h.send_ownship(own_at(fired_at));
    h.wake();
    assert!(
        h.wait_until(Duration::from_secs(180), |h| h
            .status
            .is_some_and(
                |s| s.plans_made >= 2 && s.state() != Some(PlannerState::Planning)
            )),
        "no scheduled re-plan: {:?}",
        h.status
    );
    let second = &h.plans[1];
    assert_eq!(second.trigger(), Some(Trigger::ScheduledReplan));
    // Triggered at mission time t_r - budget - step (the ownship's header), committed one
    // budget later: one step before t_r.
    assert!(
        (second.start_time_s - (t_r - step)).abs() < 1e-6,
        "the re-plan commits at (t_r - budget - step) + budget = {}, got {}",
        t_r - step,
        second.start_time_s
    );
    eprintln!(
        "scheduled re-plan: quality {:?}, start {:.1} s (t_r {t_r:.1} s), t_r now {:?}",
        second.quality(),
        second.start_time_s,
        second.next_replan()
    );
    service.stop(|| h.wake()).expect("the service stops");
}
