//! The emulators as pure units: the tracker follows a plan, switches at a plan's start
//! and availability, holds past `valid_until` without a successor; the sensor's noise has
//! the stated statistics and its truth is repeatable; the lead's routes and state come at
//! their times; the clock parses and ticks as documented.

use wingman_harness::clock::{ClockMode, Pacer, Periodic, step_time};
use wingman_harness::datalink::Datalink;
use wingman_harness::sensor::{SensorOutput, ThreatSensor};
use wingman_harness::tracker::{InnerLoop, ReceivedPlan, abeam, reference};
use wingman_harness::truth::Truth;
use wingman_interfaces::{
    Header, Model, OWNSHIP_HOLDING, Plan, Quality, SENDER_PLANNER, Trigger, Wire,
};
use wingman_planning::dynamics::{Planar, rk4_step_with};
use wingman_planning::plan_message::{PlanInfo, set_next_replan, write_plan};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::{AircraftSpec, Scenario, bundled};
use wingman_planning::tracking::{Tracker, TrackingGains};
use wingman_planning::trajectory::Trajectory;

fn scenario(name: &str) -> Scenario {
    bundled(name).expect("bundled").expect("valid")
}

/// A 2-D plan from `(t0, x0)`: straight for 100 s, then a smooth left turn (turn rate up to
/// half its limit and back over 100 s), then straight, flown open loop with the model
/// (samples every 0.5 s).
fn planar_plan(problem: &Problem, plan_id: u64, t0: f64, x0: [f64; 3], len_s: f64) -> Box<Plan> {
    let model = Planar::new(problem.limits.speed).unwrap();
    let rate = 0.5 * problem.limits.turn_rate_max;
    let u_at = |t: f64| {
        let s = t - t0;
        if (100.0..200.0).contains(&s) {
            rate * (std::f64::consts::PI * (s - 100.0) / 100.0).sin().powi(2)
        } else {
            0.0
        }
    };
    let mut tr = Trajectory::default();
    let mut x = x0;
    let n = (len_s / 0.5) as usize;
    for k in 0..=n {
        let t = t0 + 0.5 * k as f64;
        tr.push(t, [x[0], x[1], x[2], 0.0, 0.0, 0.0, 0.0], [u_at(t), 0.0]);
        x = rk4_step_with(&model, t, &x, 0.5, &mut |t, _| [u_at(t)]);
    }
    tr.phase_ends = vec![t0 + len_s];
    let mut plan = Box::new(Plan::zeroed());
    let info = PlanInfo {
        plan_id,
        trigger: if plan_id == 1 {
            Trigger::Initial
        } else {
            Trigger::PopUp
        },
        quality: Quality::Optimal,
        model: Model::TwoD,
        path: wingman_interfaces::PlanPath::Global,
        created_at_s: t0,
        cost: 1.0,
        compute_ms: 100.0,
    };
    write_plan(
        &mut plan,
        Header::new(SENDER_PLANNER, plan_id, 0),
        &info,
        &tr,
    )
    .unwrap();
    plan
}

fn received(plan: Box<Plan>, available_at_s: f64) -> ReceivedPlan {
    ReceivedPlan {
        plan,
        received_at_s: available_at_s,
        available_at_s,
    }
}

#[test]
fn the_tracker_follows_a_plan_and_recovers_from_an_offset() {
    let sc = scenario("2d-min-time-avoidable");
    let problem = Problem::from_scenario(&sc).unwrap();
    let x0 = [problem.x0[0], problem.x0[1], problem.x0[2]];
    // From the plan's own start state: stays on it through the turn.
    let mut exact = InnerLoop::new(&problem, TrackingGains::default()).unwrap();
    exact.receive(received(planar_plan(&problem, 1, 0.0, x0, 400.0), 0.0));
    let mut worst: f64 = 0.0;
    for k in 1..=3900 {
        exact.advance_to(0.1 * k as f64);
        let s = exact.sample();
        assert_eq!(s.plan_id, 1);
        assert!(!s.holding);
        worst = worst.max(s.deviation.cross_m.abs().max(s.deviation.along_m.abs()));
    }
    assert!(worst < 1.0, "deviation on the plan's own start: {worst} m");

    // From 300 m to the right of it: the feedback brings it back.
    let mut problem_off = problem.clone();
    problem_off.x0[0] += 300.0; // heading north: +x is to the right
    let mut off = InnerLoop::new(&problem_off, TrackingGains::default()).unwrap();
    off.receive(received(planar_plan(&problem, 1, 0.0, x0, 400.0), 0.0));
    off.advance_to(0.1);
    let first = off.sample().deviation.cross_m;
    assert!((first + 300.0).abs() < 25.0, "starts 300 m right: {first}");
    off.advance_to(390.0);
    let last = off.sample().deviation;
    assert!(
        last.cross_m.abs() < 10.0,
        "still {} m off after 390 s",
        last.cross_m
    );
    let own = off.ownship();
    assert_eq!(own.plan_id, 1);
    assert_eq!(own.flags & OWNSHIP_HOLDING, 0);
    assert_eq!(own.cross_track_m, last.cross_m);
}

/// The disturbed tracker's reference is the plan's point abeam the aircraft, not the point
/// of the same time: an aircraft on the path `ahead` seconds ahead of (or behind) its plan,
/// on the straight and in the turn, gets the plan's state at `t + ahead` (to 0.5 m; the
/// plan is linear between 0.5 s samples), and one 60 m to the side of that point too.
#[test]
fn the_disturbed_tracker_follows_the_point_abeam() {
    let problem = Problem::from_scenario(&scenario("2d-min-time-avoidable")).unwrap();
    let plan = planar_plan(&problem, 1, 0.0, [0.0, 0.0, 0.3], 300.0);
    let tracker = Tracker::new(&problem, TrackingGains::default());
    let v = problem.limits.speed;
    for (t, ahead) in [(50.0, 1.6), (50.0, -2.4), (140.0, 1.6), (160.0, -2.4)] {
        let (want, _) = reference(&plan, t + ahead);
        let psi = want[2];
        for side in [0.0, 60.0] {
            let mut x = want;
            x[0] -= side * psi.sin();
            x[1] += side * psi.cos();
            let (got, _) = abeam(&plan, &tracker, t, &x, v);
            let apart = (got[0] - want[0]).hypot(got[1] - want[1]);
            assert!(apart < 0.5, "t {t} ahead {ahead} side {side}: {apart} m");
        }
        let (same_time, _) = reference(&plan, t);
        let moved = (same_time[0] - want[0]).hypot(same_time[1] - want[1]);
        assert!(
            moved > 0.9 * ahead.abs() * v,
            "the points differ: {moved} m"
        );
    }
}

/// The largest cross-track deviation of an aircraft that lags its commands by
/// `response_s` (nothing else disturbs it) flying [`planar_plan`]'s turn, m.
fn worst_cross_track_in_the_turn(response_s: f64) -> f64 {
    let mut sc = scenario("2d-min-time-avoidable");
    let problem = Problem::from_scenario(&sc).unwrap();
    sc.aircraft = Some(AircraftSpec {
        response_s,
        turn_accel_max: f64::INFINITY,
        nz_rate_max: problem.limits.nz_rate_max,
        mu_rate_max: problem.limits.mu_rate_max,
        nav_sigma_m: 0.0,
        nav_heading_sigma: 0.0,
        nav_tau_s: 1.0,
        seed: 0,
    });
    let x0 = [problem.x0[0], problem.x0[1], problem.x0[2]];
    let mut tl = InnerLoop::new(&problem, TrackingGains::default())
        .unwrap()
        .with_truth(Truth::of(&sc, &problem));
    tl.receive(received(planar_plan(&problem, 1, 0.0, x0, 400.0), 0.0));
    (1..=3000)
        .map(|k| {
            tl.advance_to(0.1 * k as f64);
            tl.sample().deviation.cross_m.abs()
        })
        .fold(0.0, f64::max)
}

/// The disturbed tracker's feed-forward is the plan's control one response time of the
/// aircraft ahead: behind a first-order lag of time constant `tau` the applied turn rate
/// then follows the plan's to the order of `tau^2` times its rate of change (here at most
/// 0.64 s^2 x 0.0014 rad/s^2 ~ 1e-3 rad/s) where the plan's own control would leave it
/// `tau` x the turn rate behind (0.8 s x 0.044 rad/s ~ 0.035 rad of heading at the height
/// of the turn). The aircraft flies the turn within 5 m, as one without the lag does.
#[test]
fn the_disturbed_tracker_leads_its_command_by_the_aircrafts_response() {
    let without_lag = worst_cross_track_in_the_turn(0.0);
    let lagging = worst_cross_track_in_the_turn(0.8);
    assert!(without_lag < 1.0, "no lag: {without_lag} m");
    assert!(lagging < 5.0, "a 0.8 s lag: {lagging} m");
}

#[test]
fn the_tracker_switches_at_start_and_availability_and_holds_without_a_successor() {
    let sc = scenario("2d-min-time-avoidable");
    let problem = Problem::from_scenario(&sc).unwrap();
    let x0 = [problem.x0[0], problem.x0[1], problem.x0[2]];
    let mut first = planar_plan(&problem, 1, 0.0, x0, 400.0);
    // Cut short by a scheduled re-plan at 50 s.
    set_next_replan(&mut first, Some(50.0));
    assert_eq!(first.valid_until_s, 50.0);
    let mut tl = InnerLoop::new(&problem, TrackingGains::default()).unwrap();
    tl.receive(received(first, 0.0));
    tl.advance_to(40.0);
    assert_eq!(tl.sample().plan_id, 1);
    // A successor that starts at 45 s but is only available from 48 s.
    let at = wingman_planning::plan_message::state_at(&tl.plans()[0].plan, 45.0).unwrap();
    let second = planar_plan(&problem, 2, 45.0, [at[0], at[1], at[2]], 300.0);
    tl.receive(received(second.clone(), 48.0));
    tl.advance_to(47.0);
    assert_eq!(tl.sample().plan_id, 1, "not available yet");
    tl.advance_to(48.5);
    assert_eq!(tl.sample().plan_id, 2, "switches once available");
    assert!(tl.holds().is_empty());

    // No successor past valid_until: a hold, reported in the ownship state.
    let mut lonely = planar_plan(&problem, 1, 0.0, x0, 400.0);
    set_next_replan(&mut lonely, Some(50.0));
    let mut tl = InnerLoop::new(&problem, TrackingGains::default()).unwrap();
    tl.receive(received(lonely, 0.0));
    tl.advance_to(49.9);
    assert!(!tl.holding());
    tl.advance_to(51.0);
    assert!(tl.holding());
    let own = tl.ownship();
    assert_eq!(own.flags & OWNSHIP_HOLDING, OWNSHIP_HOLDING);
    assert_eq!(own.plan_id, 1);
    // A level turn at half the turn-rate limit.
    assert!((own.control[0] - 0.5 * problem.limits.turn_rate_max).abs() < 1e-12);
    let psi_before = tl.state()[2];
    tl.advance_to(61.0);
    let turned = tl.state()[2] - psi_before;
    assert!(
        (turned - 10.0 * 0.5 * problem.limits.turn_rate_max).abs() < 1e-6,
        "turned {turned} rad in 10 s"
    );
    // A new plan ends the hold.
    let at = *tl.state();
    tl.receive(received(
        planar_plan(&problem, 2, 62.0, [at[0], at[1], at[2]], 300.0),
        61.0,
    ));
    tl.advance_to(63.0);
    assert!(!tl.holding());
    assert_eq!(tl.holds().len(), 1);
    assert_eq!(tl.holds()[0].from_s.round(), 50.0);
    assert_eq!(tl.holds()[0].to_s.map(f64::round), Some(62.0));
    assert_eq!(tl.sample().plan_id, 2);
}

#[test]
fn a_three_d_hold_is_a_level_turn() {
    let sc = scenario("3d-min-time-avoidable");
    let problem = Problem::from_scenario(&sc).unwrap();
    let mut tl = InnerLoop::new(&problem, TrackingGains::default()).unwrap();
    // No plan at all: hold from the start.
    tl.advance_to(120.0);
    assert!(tl.holding());
    let x = tl.state();
    let z0 = problem.x0[2];
    assert!((x[2] - z0).abs() < 50.0, "altitude {} from {z0}", x[2]);
    assert!(x[3].abs() < 0.01, "flight-path angle {}", x[3]);
    assert!((x[6] - 30f64.to_radians()).abs() < 0.02, "bank {}", x[6]);
}

#[test]
fn sensor_fixes_have_the_stated_noise_and_repeat_with_the_seed() {
    let sc = scenario("3d-min-time-moving-threat");
    let m = &sc.moving_threats[0];
    let sigma = m.sensor.sigma_m;
    let mut sensor = ThreatSensor::new(&sc).unwrap();
    let mut again = ThreatSensor::new(&sc).unwrap();
    let statics = sc.threats.len();
    let mut errors = Vec::new();
    let mut reports = 0;
    let step = 0.1;
    for k in 0..=20_000u64 {
        let t = step_time(sc.start.time_s, step, k);
        let out = sensor.poll(t);
        assert_eq!(out, again.poll(t), "same seed, same outputs");
        let truth = sensor.movings()[0].true_position();
        for o in out {
            match o {
                SensorOutput::Report(r) => {
                    reports += 1;
                    assert!(r.threat_id as usize <= statics + 1);
                }
                SensorOutput::Fix(f) => {
                    assert_eq!(f.threat_id as usize, statics + 1);
                    assert_eq!(f.sigma_m, sigma);
                    assert!((f.time_s - t).abs() < step);
                    errors.extend(f.position_m.iter().zip(truth).map(|(m, t)| m - t));
                }
            }
        }
    }
    assert_eq!(reports, statics + 1, "each threat reported once");
    let n = errors.len() as f64;
    assert!(n > 3.0 * 1500.0, "{n} fix coordinates");
    let mean = errors.iter().sum::<f64>() / n;
    let sd = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n).sqrt();
    // Standard error of the mean sigma/sqrt(n); of the deviation about sigma/sqrt(2n).
    assert!(mean.abs() < 4.0 * sigma / n.sqrt(), "mean error {mean}");
    assert!(
        (sd / sigma - 1.0).abs() < 4.0 / (2.0 * n).sqrt(),
        "sd {sd} for sigma {sigma}"
    );
}

#[test]
fn a_moving_threat_is_reported_when_it_appears_with_the_propagated_estimate() {
    let sc = scenario("3d-replan-popups");
    let m = &sc.moving_threats[0];
    let mut sensor = ThreatSensor::new(&sc).unwrap();
    let mut seen = None;
    let mut fixes = Vec::new();
    for k in 0..=700u64 {
        let t = step_time(0.0, 0.1, k);
        for o in sensor.poll(t) {
            match o {
                SensorOutput::Report(r) if r.kind == 1 => seen = Some((t, r)),
                SensorOutput::Fix(f) => fixes.push(f.time_s),
                _ => {}
            }
        }
    }
    let (t, r) = seen.expect("the moving threat is reported");
    assert!((t - m.appears_at_s).abs() < 1e-9);
    assert_eq!(r.estimate_time_s, m.appears_at_s);
    // Mean: constant speed from the initial distance (zero initial acceleration).
    let d = m.initial_distance_m + m.initial_speed_mps * m.appears_at_s;
    assert!(
        (r.estimate_mean[0] - d).abs() < 1e-6,
        "{:?}",
        r.estimate_mean
    );
    // The variance of d grew from initial_sigma[0]^2.
    assert!(r.covariance(0, 0) > m.initial_sigma[0].powi(2));
    // Fixes at rate_hz from the appearance on (1 Hz: 61 s, 62 s, …, 70 s).
    assert_eq!(fixes.len(), 10);
    assert!((fixes[0] - (m.appears_at_s + 1.0 / m.sensor.rate_hz)).abs() < 1e-9);
}

#[test]
fn pop_ups_come_at_their_time_and_only_once() {
    let sc = scenario("3d-replan-popups");
    let mut sensor = ThreatSensor::new(&sc).unwrap();
    let count = |out: &[SensorOutput]| {
        out.iter()
            .filter(|o| matches!(o, SensorOutput::Report(r) if r.kind == 0))
            .count()
    };
    let known = sc.known_static_threats().count();
    assert_eq!(count(&sensor.poll(0.0)), known);
    assert_eq!(count(&sensor.poll(299.9)), 0);
    let at_300 = sensor.poll(300.0);
    assert_eq!(count(&at_300), 1);
    assert!(at_300.iter().any(
        |o| matches!(o, SensorOutput::Report(r) if r.name() == "popup-far" && r.appeared_at_s == 300.0)
    ));
    assert_eq!(count(&sensor.poll(300.1)), 0);
}

#[test]
fn the_lead_route_changes_at_its_event_and_the_state_follows_it() {
    let sc = scenario("3d-replan-popups");
    let mut dl = Datalink::new(&sc).unwrap();
    let first = dl.routes_due(0.0).to_vec();
    assert_eq!(first.len(), 1);
    assert_eq!(first[0].message.revision, 1);
    assert!(dl.routes_due(449.9).is_empty());
    let second = dl.routes_due(450.0).to_vec();
    assert_eq!(second.len(), 1);
    assert_eq!(second[0].message.revision, 2);
    assert_eq!(second[0].message.start_time_s, 450.0);
    assert!(dl.routes_due(1000.0).is_empty(), "each route once");
    // 180 m/s east along the first route, then from the new route's first point.
    let s = dl.lead_state(100.0).unwrap();
    assert!((s.position_m[0] - 18_000.0).abs() < 1e-6 && s.position_m[1] == 0.0);
    assert_eq!(s.route_revision, 1);
    let s = dl.lead_state(450.0).unwrap();
    assert_eq!(s.route_revision, 2);
    assert!((s.position_m[0] - 81_000.0).abs() < 1e-6);
    let s = dl.lead_state(460.0).unwrap();
    let heading = (40_000f64).atan2(150_000.0 - 81_000.0);
    assert!((s.heading_rad - heading).abs() < 1e-12);
    assert!((s.speed_mps - 180.0).abs() < 1e-12);
    // The tasking goes out once, at the start, with the scenario's targets.
    let t = dl.taskings_due(0.0).to_vec();
    assert_eq!(t.len(), 1);
    assert_eq!(t[0].tasking.revision, 1);
    assert_eq!(t[0].tasking.targets(), &sc.targets[..]);
    assert!(dl.taskings_due(2000.0).is_empty());
    // No lead without a rendezvous.
    let dl = Datalink::new(&scenario("2d-min-time-avoidable")).unwrap();
    assert!(!dl.has_lead() && dl.lead_state(10.0).is_none());
}

#[test]
fn the_clock_parses_and_ticks() {
    assert_eq!("fast".parse::<ClockMode>(), Ok(ClockMode::Fast));
    assert_eq!("realtime".parse::<ClockMode>(), Ok(ClockMode::Realtime));
    assert_eq!("x10".parse::<ClockMode>(), Ok(ClockMode::Scaled(10.0)));
    assert_eq!("x0.5".parse::<ClockMode>(), Ok(ClockMode::Scaled(0.5)));
    for bad in ["x0", "x-2", "xinf", "slow", "10", "x"] {
        assert!(bad.parse::<ClockMode>().is_err(), "{bad} accepted");
    }
    assert!(ClockMode::Fast.is_lock_step() && !ClockMode::Scaled(4.0).is_lock_step());

    // 5 Hz on a 0.1 s step: every other step, no drift over a long flight.
    let mut p = Periodic::new(0.0, 0.2);
    let ticks: Vec<u64> = (0..=10_000u64)
        .filter(|&k| p.due(step_time(0.0, 0.1, k)).is_some())
        .collect();
    assert_eq!(ticks.len(), 5001);
    assert!(ticks.iter().all(|k| k % 2 == 0));

    // The paced clocks: x4 makes 40 mission seconds one of wall time.
    let std = std::time::Duration::from_secs_f64;
    let pacer = Pacer::new(ClockMode::Scaled(4.0), 100.0);
    assert_eq!(pacer.wait_for(140.0, std(0.0)), std(10.0));
    assert_eq!(pacer.wait_for(140.0, std(12.0)), std(0.0));
    let fast = Pacer::new(ClockMode::Fast, 0.0);
    assert_eq!(fast.wait_for(1e6, std(0.0)), std(0.0));
}
