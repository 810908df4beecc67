//! The message loop allocates nothing per message after start-up: a counting global
//! allocator around [`MessageLoop::update`] and the status it composes — draining real
//! iceoryx2 subscribers, validating every sample, updating the world (the Kalman filter
//! of a moving threat included), assessing pop-ups against the plan, rescheduling `t_r`,
//! rejecting invalid messages, a repeated tasking, a changed lead route — over hundreds
//! of passes, with a tracing subscriber installed at `warn`; then around starting a
//! re-plan for a pop-up and one for a deviation (checked not deferred by the gate), and
//! taking their results.
//!
//! Publishing the status (and notifying the harness) allocates exactly one small block
//! per sample inside iceoryx2 0.10 (`Publisher::loan_uninit` creates a shared-state `Arc`
//! per loaned sample and frees it on send); the test pins that to at most one per
//! publication, so any allocation of ours there fails it too.
//!
//! The count is per thread (the solve thread allocates for its plans, by design, on its
//! own thread). Not covered: iceoryx2's `WaitSet::wait_and_process_once`, which collects
//! the ready file descriptors of each wake-up into a small `Vec`.

mod common;

use std::time::{Duration, Instant};

use common::*;
use wingman_planner::service::{MessageLoop, RunOptions, Shutdown};
use wingman_planning::clock::MonotonicClock;
use wingman_planning::plan_message::state_at;
use wingman_planning::scenario::bundled;

wingman_testkit::counting_allocator!();
use counting_alloc::allocations_in;
use wingman_testkit::counting_alloc;

/// One step of inputs: ownship, lead state, a track fix, a pop-up clear of the plan
/// (moved a little every time, so it is assessed again), an invalid message.
fn send_step(h: &mut FakeHarness, i: usize) {
    let t = 20.0 + 0.05 * i as f64;
    h.set_time(t);
    let mut own = ownship_2d(t, 1, [0.0, 200.0 * t, std::f64::consts::FRAC_PI_2]);
    own.cross_track_m = 12.0;
    own.along_track_m = -3.0;
    h.send_ownship(own);
    let mut lead = LeadState::zeroed();
    lead.time_s = t;
    lead.speed_mps = 150.0;
    h.send_lead_state(lead);
    let mut fix = TrackFix::zeroed();
    fix.threat_id = 90;
    fix.time_s = t;
    fix.position_m = [-60000.0 + 1000.0 + 10.0 * t + 30.0, 120000.0, 0.0];
    fix.sigma_m = 50.0;
    h.send_fix(fix);
    h.send_threat(static_threat(
        70,
        [-50000.0 - i as f64, -50000.0, 0.0],
        [2000.0, 2000.0, 0.0],
    ));
    let mut bad = static_threat(71, [0.0, 0.0, 0.0], [1000.0, 1000.0, 0.0]);
    bad.header = h.header();
    bad.axes_m[1] = -1.0;
    h.send_threat_raw(bad);
    // A tasking repeating the held one under a new revision (no re-plan), and a lead
    // route changed every step (it re-plans only a rendezvous).
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    h.send_tasking(tasking_from(&sc, 2 + i as u32));
    let mut route = LeadRoute::zeroed();
    route.revision = 1 + i as u32;
    route.point_count = 2;
    route.speed_mps = 150.0;
    route.points_m[1] = [100000.0 + i as f64, 0.0, 0.0];
    h.send_route(route);
}

#[test]
fn a_pass_of_the_message_loop_does_not_allocate() {
    let v = vehicle("noalloc");
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    let options = RunOptions {
        config: test_config(&v),
        clock,
        handle_signals: false,
        shutdown: Shutdown::new(),
        replay_cuts: None,
    };
    // A subscriber as in the service (its formatter allocates for every line it writes):
    // at `warn`, a steady pass writes none.
    let _ = tracing_subscriber::fmt()
        .with_max_level(tracing_subscriber::filter::LevelFilter::WARN)
        .with_writer(std::io::sink)
        .try_init();
    let mut ml = MessageLoop::new(&options).expect("message loop");
    let mut h = FakeHarness::new(&v);

    // Start-up: a world and a first plan (the solve thread allocates for it).
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    for t in scenario_threats(&sc) {
        h.send_threat(t);
    }
    h.send_threat(moving_threat(90));
    h.send_tasking(tasking_from(&sc, 1));
    let start = Instant::now();
    while ml.status().plans_made == 0 {
        assert!(start.elapsed() < Duration::from_secs(120), "no first plan");
        ml.process(false);
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(ml.status().current_plan_id, 1);

    // Warm-up: every path once (connections, first log line of each rejection kind).
    for i in 0..20 {
        send_step(&mut h, i);
        ml.process(i % 5 == 0);
        h.poll();
    }
    let before = *ml.status();

    let (mut ours, mut publishing) = (0, 0);
    let passes = 300;
    for i in 20..20 + passes {
        send_step(&mut h, i);
        ours += allocations_in(|| {
            assert!(ml.update(), "the inputs changed the world");
            std::hint::black_box(ml.status_message());
        });
        publishing += allocations_in(|| ml.publish_status());
        h.poll();
    }
    let after = *ml.status();
    assert_eq!(
        ours, 0,
        "allocations in {passes} passes of the message loop"
    );
    assert!(
        publishing <= passes,
        "{publishing} allocations publishing {passes} statuses (iceoryx2 makes one per loan)"
    );
    // The passes did the work: 7 messages each, one rejected, one clear pop-up.
    assert_eq!(
        after.messages_received - before.messages_received,
        7 * passes as u64
    );
    assert_eq!(
        after.messages_rejected - before.messages_rejected,
        passes as u64
    );
    assert_eq!(after.popups_clear - before.popups_clear, passes as u64);
    assert_eq!(after.plans_made, 1, "nothing here triggers a plan");
    assert_eq!(after.last_input_sequence, h.sequence);

    // A pop-up on the plan: starting the re-plan (problem snapshot into the reused
    // buffers, request to the solve thread) allocates nothing either; taking the result
    // and publishing the plan allocates only iceoryx2's loan.
    // Past the gate's spacing, so that the plan starts in this pass (not deferred).
    std::thread::sleep(Duration::from_millis(300));
    let on = state_at(&h.plans[0], 200.0).unwrap();
    h.send_threat(static_threat(
        72,
        [on[0], on[1], 0.0],
        [1500.0, 1500.0, 0.0],
    ));
    let starting = allocations_in(|| assert!(ml.update()));
    let s = ml.status_message();
    assert_eq!(s.state(), Some(PlannerState::Planning));
    assert_eq!(
        s.triggers_deferred, before.triggers_deferred,
        "the plan started in the pass measured, not deferred"
    );
    assert_eq!(starting, 0, "allocations starting a plan");
    take_plan(&mut ml, 2);

    // A deviation: a re-plan from the ownship's dead-reckoned state, started allocation
    // free too.
    std::thread::sleep(Duration::from_millis(300));
    let t = 20.0 + 0.05 * (20 + passes) as f64;
    h.set_time(t);
    let mut own = ownship_2d(t, 2, [3000.0, 200.0 * t, std::f64::consts::FRAC_PI_2]);
    own.cross_track_m = -3000.0;
    h.send_ownship(own);
    let before = ml.status_message();
    let starting = allocations_in(|| assert!(ml.update()));
    let s = ml.status_message();
    assert_eq!(s.state(), Some(PlannerState::Planning));
    assert_eq!(s.triggers_deferred, before.triggers_deferred);
    assert_eq!(starting, 0, "allocations starting a deviation re-plan");
    take_plan(&mut ml, 3);
    let p = {
        h.poll();
        h.plans.last().unwrap().clone()
    };
    assert_eq!(p.trigger(), Some(Trigger::Deviation));
}

/// Passes until plan `n` is taken; taking and publishing it allocates only iceoryx2's
/// loan.
fn take_plan(ml: &mut MessageLoop, n: u64) {
    let start = Instant::now();
    let mut taking = 0;
    while ml.status_message().plans_made < n {
        assert!(start.elapsed() < Duration::from_secs(120), "no plan {n}");
        std::thread::sleep(Duration::from_millis(5));
        taking += allocations_in(|| {
            ml.update();
        });
    }
    assert!(
        taking <= 1,
        "{taking} allocations taking and publishing plan {n}"
    );
}
