//! The planner service driven in-process over real iceoryx2 services by a small fake
//! harness (`common`), each test on its own vehicle id:
//!
//! - a tasking gives a plan of quality `Optimal` or `Feasible`, starting at the tasking's
//!   start; an invalid message is rejected and counted and changes nothing; a pop-up clear
//!   of the plan is counted and causes no plan;
//! - a burst of 50 pop-ups that each touch the plan, within one second of mission time,
//!   gives at most 3 plans, and the coalesced counter accounts for the rest.

mod common;

use std::time::Duration;

use common::*;
use wingman_planner::service::ExitReason;
use wingman_planning::plan_message::state_at;

const PLAN_WAIT: Duration = Duration::from_secs(120);

/// Starts a service, sends the threats and tasking of `2d-min-time-avoidable` at mission
/// time 0 and waits for the first plan.
fn first_plan(tag: &str) -> (ServiceThread, FakeHarness) {
    let v = vehicle(tag);
    wingman_ipc::logging::init();
    let service = ServiceThread::start(test_config(&v)).expect("start the service");
    let mut h = FakeHarness::new(&v);
    first_plan_of(&mut h, "2d-min-time-avoidable", PLAN_WAIT);
    (service, h)
}

#[test]
fn a_tasking_gives_a_plan_and_bad_or_clear_inputs_change_nothing() {
    let (service, mut h) = first_plan("plan");
    let plan = &h.plans[0];
    assert!(
        matches!(plan.quality(), Some(Quality::Optimal | Quality::Feasible)),
        "quality {:?}",
        plan.quality()
    );
    assert_eq!(plan.trigger(), Some(Trigger::Initial));
    assert_eq!(plan.plan_id, 1);
    assert_eq!(
        plan.start_time_s, 0.0,
        "the first plan starts at the tasking's start"
    );
    assert_eq!(plan.phase_count, 2, "one target, then the final point");
    assert!(plan.sample_count >= 2 && plan.sample_count as usize <= MAX_PLAN_SAMPLES);
    let first = plan.samples()[0];
    let start = [0.0, 0.0, std::f64::consts::FRAC_PI_2];
    assert!(
        first.state[..3]
            .iter()
            .zip(start)
            .all(|(a, b)| (a - b).abs() < 1e-6),
        "starts at the tasking's start state: {:?}",
        &first.state[..3]
    );
    let last = plan.samples()[plan.sample_count as usize - 1];
    assert!(
        (last.state[0] - 80000.0).hypot(last.state[1] - 10000.0) < 100.0,
        "ends at the final point: {:?}",
        &last.state[..2]
    );
    assert_eq!(plan.phase_ends()[1], plan.final_time_s);
    assert!(plan.next_replan().is_none(), "no moving threat, no t_r");
    let s = h.last_status();
    assert_eq!(s.current_plan_id, 1);
    assert_eq!(s.last_input_sequence, h.sequence);
    assert_eq!(s.messages_rejected, 0);
    assert!(s.last_plan_compute_ms > 0.0);

    // Rejected: an invalid threat report (NaN centre) numbered 10^15, a message of
    // another protocol version, and two valid reports whose sequence does not grow on the
    // threats input (a repeat of the last accepted one's, a step back). Nothing but the
    // count moves: the status keeps echoing the sequence before them (it used to echo the
    // invalid report's 10^15, which every later lock-step barrier then passed at once).
    let echoed = s.last_input_sequence;
    // `first_plan` sent the scenario's threats, then the tasking.
    let last_threat = h.sequence - 1;
    h.set_time(5.0);
    let mut bad = static_threat(50, [10000.0, 10000.0, 0.0], [1000.0, 1000.0, 0.0]);
    bad.header = h.header();
    bad.center_m[0] = f64::NAN;
    bad.header.sequence = 1_000_000_000_000_000;
    h.send_threat_raw(bad);
    let mut foreign = static_threat(51, [10000.0, 10000.0, 0.0], [1000.0, 1000.0, 0.0]);
    foreign.header = h.header();
    foreign.header.protocol_version = PROTOCOL_VERSION + 1;
    h.send_threat_raw(foreign);
    for sequence in [last_threat, last_threat - 1] {
        let mut stale = static_threat(52, [-40000.0, 40000.0, 0.0], [2000.0, 2000.0, 0.0]);
        stale.header = h.header();
        stale.header.sequence = sequence;
        h.send_threat_raw(stale);
    }
    h.wake();
    assert!(
        h.wait_until(Duration::from_secs(20), |h| h
            .status
            .is_some_and(|s| s.messages_rejected == 4)),
        "rejections not counted: {:?}",
        h.status
    );
    let s = h.last_status();
    assert_eq!(
        s.last_input_sequence, echoed,
        "a rejected sequence is echoed"
    );
    assert_eq!((s.plans_made, s.popups_clear), (1, 0));
    // A pop-up far from the plan, numbered on: assessed, counted, no plan.
    h.send_threat(static_threat(
        60,
        [-40000.0, -40000.0, 0.0],
        [2000.0, 2000.0, 0.0],
    ));
    h.wake();
    assert!(h.wait_processed(Duration::from_secs(20)));
    std::thread::sleep(Duration::from_millis(500));
    h.poll();
    let s = h.last_status();
    assert_eq!(s.messages_rejected, 4);
    assert_eq!(s.popups_clear, 1);
    assert_eq!(s.plans_made, 1, "no plan for invalid or clear inputs");
    assert_eq!(s.current_plan_id, 1);
    assert_eq!(h.plans.len(), 1);
    // The accepted message's sequence is echoed.
    assert_eq!(s.last_input_sequence, h.sequence);

    let summary = service.stop(|| h.wake()).expect("the service stops");
    assert_eq!(summary.exit, ExitReason::Requested);
    assert_eq!(summary.status.plans_made, 1);
}

#[test]
fn a_burst_of_popups_is_coalesced_into_few_plans() {
    let (service, mut h) = first_plan("burst");
    let plan = h.plans[0].clone();
    // 50 pop-ups within one second of mission time, each centred on the plan ahead (12
    // threat ids re-reported at new places: the layout holds 16 threats, 4 are known).
    let mut last_seq = 0;
    for k in 0..50 {
        h.set_time(10.0 + 0.02 * k as f64);
        let on = state_at(&plan, 60.0 + 8.0 * k as f64).unwrap();
        let id = 100 + (k % 12) as u32;
        last_seq = h.send_threat(static_threat(
            id,
            [on[0], on[1], 0.0],
            [1500.0, 1500.0, 0.0],
        ));
        h.wake();
        // Spread over half a second of wall time, so that pop-ups also arrive while a
        // plan is in flight (a release build plans in a few hundred milliseconds).
        std::thread::sleep(Duration::from_millis(10));
    }
    // Quiet: every input processed, nothing planning, no new plan for a while.
    assert!(
        h.wait_until(PLAN_WAIT, |h| h.status.is_some_and(|s| {
            s.last_input_sequence >= last_seq && s.state() != Some(PlannerState::Planning)
        })),
        "the burst was not processed: {:?}",
        h.status
    );
    loop {
        let made = h.last_status().plans_made;
        std::thread::sleep(Duration::from_millis(1500));
        assert!(h.wait_processed(PLAN_WAIT));
        if h.last_status().plans_made == made {
            break;
        }
    }
    let s = h.last_status();
    let burst_plans = s.plans_made - 1;
    eprintln!(
        "burst: {burst_plans} plans, coalesced {}, deferred {}, clear {}",
        s.triggers_coalesced, s.triggers_deferred, s.popups_clear
    );
    assert!(
        (1..=3).contains(&burst_plans),
        "{burst_plans} plans for one burst"
    );
    // Every pop-up is clear of the plan it was assessed against (counted in
    // `popups_clear`), or raised a trigger; every trigger either opened a pending set
    // (each of which became one plan) or was folded into one (`triggers_coalesced`). A
    // taken plan may raise one more trigger itself, for a threat reported while it was
    // computed that reaches it (B1): at most one per plan.
    let accounted = s.triggers_coalesced + burst_plans + s.popups_clear;
    assert!(
        (50..=50 + burst_plans).contains(&accounted),
        "coalesced {} + plans {burst_plans} + clear {} = {accounted}, not 50 (+ at most one \
         per plan)",
        s.triggers_coalesced,
        s.popups_clear
    );
    // `triggers_deferred` counts pending sets the gate held back, once each: each became
    // a plan.
    assert!(s.triggers_deferred <= burst_plans, "{s:?}");
    assert_eq!(s.messages_rejected, 0);
    let newest = h.plans.last().unwrap();
    assert_eq!(newest.plan_id, s.current_plan_id);
    assert_eq!(newest.trigger(), Some(Trigger::PopUp));
    // A re-plan commits at the mission time it was started (10-11 s: the burst's, the
    // latest message's header) + the budget (20 s), from the state the plan it replaces
    // predicts there.
    let budget_s = 20.0;
    assert!(
        (10.0 + budget_s..=11.0 + budget_s).contains(&newest.start_time_s),
        "a re-plan starts at its commit time (now + budget): {}",
        newest.start_time_s
    );
    let before = &h.plans[h.plans.len() - 2];
    let expected = state_at(before, newest.start_time_s).unwrap();
    let x0 = newest.samples()[0].state;
    assert!(
        (x0[0] - expected[0]).hypot(x0[1] - expected[1]) < 1.0
            && (x0[2] - expected[2]).abs() < 1e-6,
        "spliced onto the previous plan: {:?} vs {:?}",
        &x0[..3],
        &expected[..3]
    );
    service.stop(|| h.wake()).expect("the service stops");
}

#[test]
fn a_burst_over_a_buffer_is_counted_as_lost_and_none_is_at_the_documented_rate() {
    let (service, mut h) = first_plan("loss");
    let plan = h.plans[0].clone();
    let on_plan = |t: f64| {
        let s = state_at(&plan, t).unwrap();
        ownship_2d(t, plan.plan_id, [s[0], s[1], s[2]])
    };
    let mut t = 1.0;
    // The documented rate: at most a subscriber buffer's worth of messages per service
    // between two notifications (ownship states 4, threat reports 64: here 4 of each).
    for round in 0..3 {
        for k in 0..4 {
            h.set_time(t);
            h.send_ownship(on_plan(t));
            h.send_threat(static_threat(
                200 + k,
                [-60_000.0 - 1000.0 * round as f64, -60_000.0, 0.0],
                [2000.0, 2000.0, 0.0],
            ));
            t += 0.1;
        }
        h.wake();
        assert!(h.wait_processed(PLAN_WAIT), "round {round}: {:?}", h.status);
    }
    // One more pass settles the last round's sequences.
    h.set_time(t);
    h.send_ownship(on_plan(t));
    h.wake();
    assert!(h.wait_processed(PLAN_WAIT));
    assert_eq!(h.last_status().messages_lost, 0, "at the documented rate");
    // Ten ownship states before one notification: the buffer keeps the newest four, the
    // other six are lost, and counted once a later message has been read.
    for _ in 0..10 {
        t += 0.1;
        h.set_time(t);
        h.send_ownship(on_plan(t));
    }
    h.wake();
    assert!(h.wait_processed(PLAN_WAIT));
    t += 0.1;
    h.set_time(t);
    h.send_ownship(on_plan(t));
    h.wake();
    assert!(h.wait_processed(PLAN_WAIT));
    let s = h.last_status();
    assert_eq!(s.messages_lost, 6, "{s:?}");
    assert_eq!(s.messages_rejected, 0);
    service.stop(|| h.wake()).expect("the service stops");
}
