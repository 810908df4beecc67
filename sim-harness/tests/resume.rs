//! `fly --resume` in its pure parts: the resume point (the planner's mission time rounded up
//! to the step grid, or the plan's later start; the sequence continued), the check that
//! the planner's plan is the scenario's (and which targets it had passed), the timeline
//! replayed to the resume step without flying, the lead's schedule and the tracker taken
//! up there; and a resume with no planner ending in a clear error within its wait.

use std::time::Duration;

use wingman_harness::clock::{Periodic, step_time};
use wingman_harness::datalink::Datalink;
use wingman_harness::mission::{FlyError, FlyOptions, PlannerMode, unique_vehicle_id};
use wingman_harness::resume::{
    MATCH_M, ResumeError, check_plan, replay_timeline, resume_point, step_at_or_after,
};
use wingman_harness::sensor::{SensorOutput, ThreatSensor};
use wingman_harness::tracker::{InnerLoop, ReceivedPlan, reference};
use wingman_interfaces::{
    Header, Model, Plan, PlannerStatus, Quality, SENDER_PLANNER, ThreatKind, Trigger, Wire,
};
use wingman_planning::plan_message::{PlanInfo, write_plan};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::{Scenario, bundled};
use wingman_planning::tracking::TrackingGains;
use wingman_planning::trajectory::Trajectory;

fn scenario(name: &str) -> Scenario {
    bundled(name).expect("bundled").expect("valid")
}

/// A status at mission time `t` having processed inputs up to `sequence`.
fn status(t: f64, sequence: u64) -> PlannerStatus {
    let mut s = PlannerStatus::zeroed();
    s.header = Header::new(SENDER_PLANNER, 7, (t * 1e9).round() as i64);
    s.last_input_sequence = sequence;
    s
}

/// A 2-D plan (id `plan_id`, created and starting at `t0`) flying straight at 200 m/s
/// through `points` (samples every 0.5 s); a phase ends at each point after the first.
fn straight_plan(plan_id: u64, t0: f64, points: &[[f64; 2]]) -> Box<Plan> {
    let v = 200.0;
    let mut tr = Trajectory::default();
    let mut t = t0;
    for w in points.windows(2) {
        let (a, b) = (w[0], w[1]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        let psi = (b[1] - a[1]).atan2(b[0] - a[0]);
        let n = (len / v / 0.5).ceil() as usize;
        for k in 0..n {
            let f = k as f64 / n as f64;
            let x = [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), psi];
            tr.push(
                t + f * len / v,
                [x[0], x[1], x[2], 0.0, 0.0, 0.0, 0.0],
                [0.0; 2],
            );
        }
        t += len / v;
        tr.phase_ends.push(t);
    }
    let last = points[points.len() - 1];
    let psi = tr.states.last().map_or(0.0, |x| x[2]);
    tr.push(t, [last[0], last[1], psi, 0.0, 0.0, 0.0, 0.0], [0.0; 2]);
    let mut plan = Box::new(Plan::zeroed());
    let info = PlanInfo {
        plan_id,
        trigger: Trigger::Initial,
        quality: Quality::Optimal,
        model: Model::TwoD,
        path: wingman_interfaces::PlanPath::Global,
        created_at_s: t0,
        cost: 1.0,
        compute_ms: 1.0,
    };
    write_plan(&mut plan, Header::new(SENDER_PLANNER, 1, 0), &info, &tr).unwrap();
    plan
}

/// `2d-min-time-avoidable`'s mission as a straight plan: start, its target, its final point.
fn avoidable_plan() -> Box<Plan> {
    straight_plan(
        1,
        0.0,
        &[[0.0, 0.0], [30000.0, 40000.0], [80000.0, 10000.0]],
    )
}

#[test]
fn the_resume_point_is_the_planners_time_on_the_step_grid_with_the_sequence_continued() {
    let plan = avoidable_plan();
    // On the grid (to rounding): that step itself (tolerance: 1e-9 s).
    let p = resume_point(&status(52.3, 4711), &plan, 0.0, 0.1).unwrap();
    assert_eq!(p.step, 523);
    assert!((p.t_s - 52.3).abs() < 1e-9, "{p:?}");
    assert!((p.planner_s - 52.3).abs() < 1e-9);
    assert_eq!(p.last_sequence, 4711);
    // Between grid times: the next one.
    let p = resume_point(&status(52.31, 1), &plan, 0.0, 0.1).unwrap();
    assert_eq!(p.step, 524);
    assert!((p.t_s - 52.4).abs() < 1e-9, "{p:?}");
    // A grid that does not start at 0.
    let p = resume_point(&status(12.34, 1), &plan, 2.0, 0.5).unwrap();
    assert_eq!(p.step, 21);
    assert!((p.t_s - 12.5).abs() < 1e-9, "{p:?}");
    // A re-plan that commits after the planner's time: its start.
    let mut later = avoidable_plan();
    later.start_time_s = 60.05;
    let p = resume_point(&status(52.3, 1), &later, 0.0, 0.1).unwrap();
    assert_eq!(p.step, 601);
    assert!((p.t_s - 60.1).abs() < 1e-9, "{p:?}");
    // The grid: a millionth of a step is rounding, not a new step.
    assert_eq!(step_at_or_after(0.0, 0.1, 52.3 + 1e-9), 523);
    assert_eq!(step_at_or_after(0.0, 0.1, 52.3 + 1e-5), 524);
    assert_eq!(step_at_or_after(5.0, 0.1, 3.0), 0);
}

#[test]
fn a_plan_that_has_ended_or_a_time_before_the_start_cannot_be_resumed() {
    let plan = avoidable_plan();
    let end = plan.final_time_s;
    assert!(matches!(
        resume_point(&status(end + 1.0, 1), &plan, 0.0, 0.1),
        Err(ResumeError::Ended { plan_id: 1, .. })
    ));
    // The last step would fall on the end: nothing left to fly.
    assert!(matches!(
        resume_point(&status(end - 0.01, 1), &plan, end - 10.0, 10.0),
        Err(ResumeError::Ended { .. })
    ));
    assert!(matches!(
        resume_point(&status(5.0, 1), &plan, 10.0, 0.1),
        Err(ResumeError::BeforeStart { .. })
    ));
}

#[test]
fn the_planners_plan_is_matched_to_the_scenario_and_says_which_targets_remain() {
    let sc = scenario("2d-min-time-avoidable");
    let dl = Datalink::new(&sc).unwrap();
    let plan = avoidable_plan();
    let at_target = plan.phase_ends()[0];
    let m = check_plan(&sc, &dl, &plan, 10.0, 10.0).unwrap();
    assert_eq!((m.revision, m.passed, m.ahead), (1, 0, 1));
    // Past the target's phase end: passed before the resume.
    let m = check_plan(&sc, &dl, &plan, at_target + 1.0, at_target + 1.0).unwrap();
    assert_eq!((m.passed, m.ahead), (1, 0));
    // A re-plan after the target visits the final point only: the target was passed.
    let replan = straight_plan(2, 300.0, &[[31000.0, 39000.0], [80000.0, 10000.0]]);
    let m = check_plan(&sc, &dl, &replan, 300.0, 300.0).unwrap();
    assert_eq!((m.passed, m.ahead), (1, 0));
    // Within MATCH_M of the target it matches; beyond it, it does not.
    let near = 0.8 * MATCH_M;
    let shifted = straight_plan(
        1,
        0.0,
        &[[0.0, 0.0], [30000.0 + near, 40000.0], [80000.0, 10000.0]],
    );
    assert!(check_plan(&sc, &dl, &shifted, 1.0, 1.0).is_ok());
    let far = 1.2 * MATCH_M;
    let off = straight_plan(
        1,
        0.0,
        &[[0.0, 0.0], [30000.0 + far, 40000.0], [80000.0, 10000.0]],
    );
    let e = check_plan(&sc, &dl, &off, 1.0, 1.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("from target 1"), "{e}");
}

#[test]
fn a_plan_of_another_mission_is_refused_naming_the_difference() {
    let plan = avoidable_plan();
    let other = |name: &str| {
        let sc = scenario(name);
        let dl = Datalink::new(&sc).unwrap();
        check_plan(&sc, &dl, &plan, 1.0, 1.0).unwrap_err()
    };
    let e = other("3d-min-time-avoidable").to_string();
    assert!(
        e.contains("another mission than `3d-min-time-avoidable`") && e.contains("is 2-D"),
        "{e}"
    );
    // The same places, a fixed final time (800 s) the plan does not keep.
    let e = other("2d-fixed-time-avoidable").to_string();
    assert!(e.contains("at the fixed time 800.0 s"), "{e}");
    // The same target, a rendezvous with the lead instead of the final point.
    let e = other("2d-min-time-rendezvous-avoidable").to_string();
    assert!(e.contains("from the lead"), "{e}");
    // More targets than the tasking holds.
    let sc = scenario("2d-min-time-avoidable");
    let dl = Datalink::new(&sc).unwrap();
    let two = straight_plan(
        1,
        0.0,
        &[
            [0.0, 0.0],
            [30000.0, 40000.0],
            [40000.0, 40000.0],
            [80000.0, 10000.0],
        ],
    );
    let e = check_plan(&sc, &dl, &two, 1.0, 1.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("visits 2 target(s)"), "{e}");
}

#[test]
fn the_timeline_replayed_to_a_time_holds_the_world_in_force_then() {
    let sc = scenario("3d-replan-popups");
    let (t0, dt) = (sc.start.time_s, 0.1);
    let moving = &sc.moving_threats[0];
    let statics_at_start = sc
        .threats
        .iter()
        .filter(|t| t.appears_at_s.is_none())
        .count();

    // Before the moving pop-up (60 s): the static threats known at take-off, route 1.
    let mut dl = Datalink::new(&sc).unwrap();
    let mut sensor = ThreatSensor::new(&sc).unwrap();
    let tl = replay_timeline(&mut dl, &mut sensor, t0, dt, 500);
    assert_eq!(tl.reports().count(), statics_at_start);
    assert_eq!(tl.tasking.map(|t| t.revision), Some(1));
    assert_eq!(tl.route.map(|r| r.revision), Some(1));

    // At 305 s: the moving threat and the far pop-up (300 s) too, each once; its fixes at
    // rate_hz since it appeared (one per 1/rate_hz, the last at or before 305 s).
    let mut dl = Datalink::new(&sc).unwrap();
    let mut sensor = ThreatSensor::new(&sc).unwrap();
    let step = 3050;
    let t = step_time(t0, dt, step);
    let tl = replay_timeline(&mut dl, &mut sensor, t0, dt, step);
    let reports: Vec<_> = tl.reports().collect();
    assert_eq!(reports.len(), sc.threats.len() + 1);
    assert_eq!(
        reports
            .iter()
            .filter(|r| r.kind() == Some(ThreatKind::Moving))
            .count(),
        1
    );
    let fixes = tl
        .sensor
        .iter()
        .filter(|o| matches!(o, SensorOutput::Fix(_)))
        .count();
    let expected = ((t - moving.appears_at_s) * moving.sensor.rate_hz + 1e-9).floor() as usize;
    assert_eq!(fixes, expected);
    assert_eq!(tl.route.map(|r| r.revision), Some(1));
    // Everything due by then is taken: the flight does not send it again.
    assert!(dl.taskings_due(t).is_empty() && dl.routes_due(t).is_empty());
    assert!(sensor.poll(t).is_empty());

    // The moving threat's truth does not depend on how it was stepped to the time: a
    // sensor polled once at 305 s stands exactly where the replayed one does (tolerance 0).
    let mut once = ThreatSensor::new(&sc).unwrap();
    let _ = once.poll(t);
    assert_eq!(
        once.movings()[0].truth.state(),
        sensor.movings()[0].truth.state()
    );
    assert_eq!(
        once.movings()[0].truth.time(),
        sensor.movings()[0].truth.time()
    );

    // Past the lead's new route (450 s): revision 2 is in force.
    let mut dl = Datalink::new(&sc).unwrap();
    let mut sensor = ThreatSensor::new(&sc).unwrap();
    let tl = replay_timeline(&mut dl, &mut sensor, t0, dt, 4550);
    assert_eq!(tl.route.map(|r| r.revision), Some(2));
}

#[test]
fn the_lead_schedule_and_the_tracker_are_taken_up_at_the_resume() {
    // The 5 Hz lead schedule from 0 s, taken up at 52.3 s: next tick 52.4 s; at a tick
    // (to 1 µs) that tick.
    let mut p = Periodic::resumed(0.0, 0.2, 52.3);
    assert!((p.next() - 52.4).abs() < 1e-9, "{}", p.next());
    assert!(p.due(52.3).is_none());
    assert!(p.due(52.4).is_some());
    let p = Periodic::resumed(0.0, 0.2, 52.4 + 1e-7);
    assert!((p.next() - 52.4).abs() < 1e-9, "{}", p.next());
    let p = Periodic::resumed(10.0, 0.2, 3.0);
    assert_eq!(p.next(), 10.0);

    // The tracker starts on the plan at the resume time: the plan's state there (1e-9 m),
    // its id flown, no deviation (1e-6 m).
    let sc = scenario("2d-min-time-avoidable");
    let problem = Problem::from_scenario(&sc).unwrap();
    let mut tracker = InnerLoop::new(&problem, TrackingGains::default()).unwrap();
    let plan = avoidable_plan();
    let t = 52.3;
    let (x, _) = reference(&plan, t);
    tracker.start_on(
        t,
        ReceivedPlan {
            plan,
            received_at_s: t,
            available_at_s: t,
        },
    );
    let s = tracker.sample();
    assert_eq!(s.t, t);
    assert_eq!(s.plan_id, 1);
    assert!(!s.holding);
    for i in 0..3 {
        assert!((s.state[i] - x[i]).abs() < 1e-9, "{:?} vs {x:?}", s.state);
    }
    assert!(s.deviation.cross_m.abs() < 1e-6 && s.deviation.along_m.abs() < 1e-6);
    // It flies on along the plan.
    tracker.advance_to(t + 10.0);
    let (x, _) = reference(&tracker.plans()[0].plan, t + 10.0);
    let d = (tracker.state()[0] - x[0]).hypot(tracker.state()[1] - x[1]);
    assert!(d < 5.0, "{d} m off the plan after 10 s");
}

#[test]
fn resuming_with_no_planner_running_ends_in_a_clear_error_within_its_wait() {
    let out = std::env::temp_dir().join(format!("wingman-resume-none-{}", std::process::id()));
    let mut opts = FlyOptions::new(scenario("2d-min-time-avoidable"));
    opts.out_dir = out.clone();
    opts.planner = PlannerMode::External;
    opts.planner_config.vehicle_id = unique_vehicle_id("resume-none");
    opts.resume = true;
    opts.resume_wait = Duration::from_millis(500);
    opts.progress = false;
    let e = wingman_harness::mission::fly(&opts).unwrap_err();
    let _ = std::fs::remove_dir_all(&out);
    assert!(
        matches!(e, FlyError::Resume(ResumeError::NoStatus { .. })),
        "{e}"
    );
    let text = e.to_string();
    assert!(
        text.starts_with("nothing to resume: no planner status on wingman/resume-none-")
            && text.ends_with("/status within 0.5 s"),
        "{text}"
    );

    // And --resume needs an external planner.
    opts.planner = PlannerMode::Spawn { binary: None };
    let e = wingman_harness::mission::fly(&opts).unwrap_err();
    assert!(
        matches!(e, FlyError::Resume(ResumeError::NotExternal)),
        "{e}"
    );
}
