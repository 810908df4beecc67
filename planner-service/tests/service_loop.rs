//! The message loop driven pass by pass from the test (`common::Driven`), so that
//! a test decides which inputs arrive while a plan is in flight. Each test names the
//! protection it checks; each fails without it.

mod common;

use std::time::Duration;

use common::*;
use wingman_planning::plan_message::state_at;

/// B1: a pop-up that arrives while a plan is in flight, clear of the old plan but on the
/// new one, re-plans once the new plan is taken (`on_result` checks the threats newer than
/// the plan's snapshot against the plan now current).
#[test]
fn a_popup_during_a_plan_is_checked_against_the_new_plan() {
    let mut d = Driven::new(test_config(&vehicle("popup-in-flight")));
    let sc = d.first_plan("2d-min-time-avoidable");
    // A new tasking: the target moves 20 km south of the start, far from the old plan.
    let target = [40000.0, -20000.0, 0.0];
    let mut t = tasking_from(&sc, 2);
    t.targets_m[0] = target;
    std::thread::sleep(Duration::from_millis(300)); // past the gate's spacing
    d.h.set_time(5.0);
    d.h.send_tasking(t);
    d.pass();
    assert_eq!(d.status().state(), Some(PlannerState::Planning));
    // A pop-up on the new target, reported while that plan is computed.
    d.h.send_threat(static_threat(
        80,
        [target[0], target[1], 0.0],
        [2000.0, 2000.0, 0.0],
    ));
    d.pass();
    let s = d.status();
    assert_eq!(
        (s.plans_made, s.popups_clear),
        (1, 1),
        "precondition: assessed against the old plan while the new one was in flight"
    );
    d.settle();
    let s = d.status();
    assert_eq!(
        s.plans_made, 3,
        "the tasking's plan, then a re-plan for the pop-up on it"
    );
    let last = d.h.plans.last().unwrap();
    assert_eq!(last.trigger(), Some(Trigger::PopUp));
    assert_eq!(d.h.plans[1].trigger(), Some(Trigger::Tasking));
    // The tasking's plan indeed went through the pop-up (it visits the target).
    let p = &d.h.plans[1];
    let through = p
        .samples()
        .iter()
        .any(|s| (s.state[0] - target[0]).hypot(s.state[1] - target[1]) < 2000.0);
    assert!(through, "the tasking's plan visits the target");
}

/// B2: a deviation waiting behind the compute gate, joined by a pop-up, re-plans from the
/// ownship's (dead-reckoned) state although the plan is named after the pop-up: the
/// splice looks at every pending trigger, not the highest-priority one.
#[test]
fn a_deviation_coalesced_with_a_popup_splices_from_the_ownship() {
    let mut cfg = test_config(&vehicle("deviation-popup"));
    cfg.budget.min_spacing_ms = 4000;
    let mut d = Driven::new(cfg);
    d.first_plan("2d-min-time-avoidable");
    let plan = d.h.plans[0].clone();
    // At t = 10 s the aircraft is 3 km east of the plan, heading north.
    let t = 10.0;
    let on = state_at(&plan, t).unwrap();
    let mut own = ownship_2d(t, 1, [on[0] + 3000.0, on[1], std::f64::consts::FRAC_PI_2]);
    own.cross_track_m = -3000.0;
    d.h.set_time(t);
    d.h.send_ownship(own);
    d.pass();
    assert_eq!(
        d.status().triggers_deferred,
        1,
        "precondition: the deviation waits for the gate"
    );
    let ahead = state_at(&plan, 100.0).unwrap();
    d.h.send_threat(static_threat(
        81,
        [ahead[0], ahead[1], 0.0],
        [1500.0, 1500.0, 0.0],
    ));
    d.pass();
    d.settle();
    assert_eq!(d.status().plans_made, 2, "one plan for both triggers");
    let p = d.h.plans.last().unwrap();
    assert_eq!(p.trigger(), Some(Trigger::PopUp), "named by priority");
    // Commit at now + budget (20 s), from the ownship flown on at 200 m/s heading north.
    let t_c = t + 20.0;
    assert!((p.start_time_s - t_c).abs() < 1e-6, "{}", p.start_time_s);
    let x0 = p.samples()[0].state;
    let expected = [own.state[0], own.state[1] + 200.0 * 20.0];
    assert!(
        (x0[0] - expected[0]).hypot(x0[1] - expected[1]) < 1.0,
        "starts from the ownship's state {expected:?}, not the plan's: {:?}",
        &x0[..2]
    );
}

/// B3: an ownship state reporting `plan_id = u64::MAX` (valid on the wire) cannot make the
/// plan ids overflow and wrap to 0 ("no plan"): an id that large is not continued from.
#[test]
fn a_huge_plan_id_from_the_ownship_does_not_overflow_the_plan_ids() {
    let mut d = Driven::new(test_config(&vehicle("plan-id-max")));
    let sc = wingman_planning::scenario::bundled("2d-min-time-avoidable")
        .unwrap()
        .unwrap();
    d.h.set_time(0.0);
    d.h.send_ownship(ownship_2d(
        0.0,
        u64::MAX,
        [0.0, 0.0, std::f64::consts::FRAC_PI_2],
    ));
    for t in scenario_threats(&sc) {
        d.h.send_threat(t);
    }
    d.h.send_tasking(tasking_from(&sc, 1));
    d.settle();
    assert_eq!(d.status().plans_made, 1);
    let first = d.h.plans[0].plan_id;
    assert_eq!(first, 1, "the huge id is not continued from");
    // A re-plan: its id follows.
    std::thread::sleep(Duration::from_millis(300));
    let ahead = state_at(&d.h.plans[0], 100.0).unwrap();
    d.h.set_time(5.0);
    d.h.send_threat(static_threat(
        82,
        [ahead[0], ahead[1], 0.0],
        [1500.0, 1500.0, 0.0],
    ));
    d.settle();
    assert_eq!(d.status().plans_made, 2);
    assert_eq!(d.h.plans[1].plan_id, 2);
    assert_eq!(d.status().current_plan_id, 2);
}

/// B4: a tasking that repeats the held one under a larger revision keeps the targets
/// already passed: the next re-plan does not fly back to them.
#[test]
fn a_repeated_tasking_with_a_new_revision_keeps_the_passed_targets() {
    let mut d = Driven::new(test_config(&vehicle("tasking-repeat")));
    let sc = d.first_plan("2d-min-time-avoidable");
    let plan = d.h.plans[0].clone();
    let passed = plan.phase_ends()[0] + 1.0;
    d.h.set_time(passed);
    d.h.send_tasking(tasking_from(&sc, 2));
    d.pass();
    assert_eq!(
        d.status().plans_made,
        1,
        "the same content does not re-plan"
    );
    std::thread::sleep(Duration::from_millis(300));
    let ahead = state_at(&plan, passed + 60.0).unwrap();
    d.h.send_threat(static_threat(
        83,
        [ahead[0], ahead[1], 0.0],
        [1500.0, 1500.0, 0.0],
    ));
    d.settle();
    assert_eq!(d.status().plans_made, 2);
    let p = d.h.plans.last().unwrap();
    assert_eq!(p.trigger(), Some(Trigger::PopUp));
    assert_eq!(
        p.phase_count,
        1,
        "the target passed at {:.1} s is not visited again",
        plan.phase_ends()[0]
    );
}

/// B7: a first plan that fails (here the solver refuses a 3-D start state climbing
/// steeper than the vehicle's bound, which the tasking's `validate()` cannot see) is tried again after
/// `FIRST_PLAN_RETRY` (and at once with a new tasking), rather than leaving the service without a plan for good.
#[test]
fn a_failed_first_plan_is_tried_again() {
    let mut d = Driven::new(test_config(&vehicle("first-fails")));
    let sc = wingman_planning::scenario::bundled("3d-min-time-avoidable")
        .unwrap()
        .unwrap();
    let mut t = tasking_from(&sc, 1);
    t.start_state[3] = t.limits.gamma_max_rad + 0.1; // climbing steeper than allowed
    d.h.set_time(0.0);
    d.h.send_tasking(t);
    d.settle();
    let s = d.status();
    assert_eq!(s.plans_made, 0);
    assert_eq!(s.state(), Some(PlannerState::Degraded));
    // After the retry wait, the next pass starts another attempt.
    std::thread::sleep(
        wingman_planner::service::message_loop::FIRST_PLAN_RETRY + Duration::from_millis(100),
    );
    d.pass();
    assert_eq!(
        d.status().state(),
        Some(PlannerState::Planning),
        "the first plan is tried again"
    );
    d.settle();
    // Corrected, the next attempt starts at once (past the gate's spacing) and plans.
    std::thread::sleep(Duration::from_millis(300));
    d.h.send_tasking(tasking_from(&sc, 2));
    d.pass();
    assert_eq!(d.status().state(), Some(PlannerState::Planning));
    d.settle();
    assert_eq!(d.status().plans_made, 1);
    assert_eq!(d.status().current_plan_id, 1);
}

/// B6: a tasking that switches the model (2-D to 3-D) starts the new plan from the
/// ownship's state in the new model, never from the old 2-D plan's `(x, y, psi)` read as
/// a 3-D state (whose altitude would be `psi`).
#[test]
fn a_model_change_starts_from_the_ownship_in_the_new_model() {
    let mut d = Driven::new(test_config(&vehicle("model-change")));
    d.first_plan("2d-min-time-avoidable");
    let sc3 = wingman_planning::scenario::bundled("3d-min-time-avoidable")
        .unwrap()
        .unwrap();
    let t3 = tasking_from(&sc3, 2);
    let t = 10.0;
    let mut own = OwnshipState::zeroed();
    own.time_s = t;
    own.model = Model::ThreeD.to_wire();
    own.plan_id = 1;
    own.state = t3.start_state;
    d.h.set_time(t);
    d.h.send_ownship(own);
    std::thread::sleep(Duration::from_millis(300));
    d.h.send_tasking(t3);
    d.settle();
    assert_eq!(d.status().plans_made, 2, "a plan for the 3-D tasking");
    let p = d.h.plans.last().unwrap();
    assert_eq!(p.model(), Some(Model::ThreeD));
    assert_eq!(p.trigger(), Some(Trigger::Tasking));
    // Dead-reckoned 20 s (the budget) along the ownship's heading and climb.
    let x0 = p.samples()[0].state;
    let (sg, cg) = own.state[3].sin_cos();
    let (sc, cc) = own.state[4].sin_cos();
    let v = t3.limits.speed_mps * 20.0;
    let expected = [
        own.state[0] + v * cg * cc,
        own.state[1] + v * cg * sc,
        own.state[2] + v * sg,
    ];
    for k in 0..3 {
        assert!(
            (x0[k] - expected[k]).abs() < 1.0,
            "start {:?}, expected {expected:?}",
            &x0[..3]
        );
    }
}

/// B9: a restart whose ownship state is stale (mission time far past it) does not
/// dead-reckon it for minutes: the plan waits for a fresh ownship state and starts from
/// it.
#[test]
fn a_restart_does_not_dead_reckon_a_stale_ownship_state() {
    let mut d = Driven::new(test_config(&vehicle("stale-ownship")));
    let sc = wingman_planning::scenario::bundled("2d-min-time-avoidable")
        .unwrap()
        .unwrap();
    let north = std::f64::consts::FRAC_PI_2;
    d.h.set_time(5.0);
    d.h.send_ownship(ownship_2d(5.0, 7, [0.0, 1000.0, north]));
    d.h.set_time(300.0);
    for t in scenario_threats(&sc) {
        d.h.send_threat(t);
    }
    d.h.send_tasking(tasking_from(&sc, 1));
    d.settle();
    assert_eq!(
        d.status().plans_made,
        0,
        "no plan from an ownship state 295 s old"
    );
    let fresh = [20000.0, 30000.0, 0.0];
    d.h.send_ownship(ownship_2d(300.0, 7, fresh));
    d.settle();
    assert_eq!(d.status().plans_made, 1);
    let p = &d.h.plans[0];
    assert_eq!(p.trigger(), Some(Trigger::Restart));
    assert_eq!(p.plan_id, 8, "plan ids continue above the ownship's");
    assert!((p.start_time_s - 320.0).abs() < 1e-6, "{}", p.start_time_s);
    let x0 = p.samples()[0].state;
    assert!(
        (x0[0] - (fresh[0] + 200.0 * 20.0)).abs() < 1.0 && (x0[1] - fresh[1]).abs() < 1.0,
        "from the fresh state flown on 20 s east: {:?}",
        &x0[..2]
    );
}

/// B9: a deviation that waited behind the compute gate while mission time moved on (the
/// ownship state is now 10 s old) does not dead-reckon that stale state: the re-plan
/// splices onto the current plan.
#[test]
fn a_deferred_deviation_does_not_dead_reckon_a_stale_ownship_state() {
    let mut cfg = test_config(&vehicle("stale-deviation"));
    cfg.budget.min_spacing_ms = 3000;
    let mut d = Driven::new(cfg);
    d.first_plan("2d-min-time-avoidable");
    let plan = d.h.plans[0].clone();
    let on = state_at(&plan, 10.0).unwrap();
    let mut own = ownship_2d(10.0, 1, [on[0] + 3000.0, on[1], on[2]]);
    own.cross_track_m = -3000.0;
    d.h.set_time(10.0);
    d.h.send_ownship(own);
    d.pass();
    assert_eq!(d.status().triggers_deferred, 1, "precondition: deferred");
    // Mission time moves on without ownship states (a lead state carries it).
    d.h.set_time(20.0);
    let mut lead = LeadState::zeroed();
    lead.time_s = 20.0;
    lead.speed_mps = 150.0;
    d.h.send_lead_state(lead);
    d.pass();
    d.settle();
    assert_eq!(d.status().plans_made, 2);
    let p = d.h.plans.last().unwrap();
    assert_eq!(p.trigger(), Some(Trigger::Deviation));
    let t_c = 20.0 + 20.0;
    assert!((p.start_time_s - t_c).abs() < 1e-6, "{}", p.start_time_s);
    let expected = state_at(&plan, t_c).unwrap();
    let x0 = p.samples()[0].state;
    assert!(
        (x0[0] - expected[0]).hypot(x0[1] - expected[1]) < 1.0,
        "spliced onto the plan {:?}, not the stale ownship state: {:?}",
        &expected[..2],
        &x0[..2]
    );
}

/// Restart race: a planner restarted mid-mission gets the tasking (and the threats) from
/// history before the tracker's next ownship state. It waits for that state
/// (`triggers.first_plan_wait_ms`) and plans a `Restart` from where the aircraft is, not
/// an `Initial` plan from the tasking's start at t = 0. Without the wait the first pass
/// after the tasking starts an `Initial` plan.
#[test]
fn a_restarted_planner_waits_for_the_ownship_before_its_first_plan() {
    let mut cfg = test_config(&vehicle("restart-wait"));
    cfg.triggers.first_plan_wait_ms = 60_000;
    let mut d = Driven::new(cfg);
    d.send_scenario("2d-min-time-avoidable");
    for _ in 0..5 {
        d.pass();
        std::thread::sleep(Duration::from_millis(5));
    }
    let s = d.status();
    assert_eq!(s.plans_made, 0, "no plan before an ownship state");
    assert_eq!(
        s.state(),
        Some(PlannerState::Planning),
        "a lock-step harness waits"
    );
    let north = std::f64::consts::FRAC_PI_2;
    let here = [20000.0, 30000.0, north];
    d.h.set_time(120.0);
    d.h.send_ownship(ownship_2d(120.0, 3, here));
    d.settle();
    assert_eq!(d.status().plans_made, 1);
    let p = &d.h.plans[0];
    assert_eq!(p.trigger(), Some(Trigger::Restart));
    assert_eq!(p.plan_id, 4, "plan ids continue above the ownship's");
    let x0 = p.samples()[0].state;
    assert!(
        (x0[0] - here[0]).abs() < 1.0 && (x0[1] - here[1]).abs() < 50_000.0,
        "from the ownship's state (dead-reckoned to the commit time): {:?}",
        &x0[..2]
    );
}

/// The other side of the wait: a take-off tasking with no ownship state plans `Initial`
/// from the tasking's start once the wait is over.
#[test]
fn a_first_plan_without_an_ownship_state_starts_after_the_wait() {
    let mut cfg = test_config(&vehicle("first-wait"));
    cfg.triggers.first_plan_wait_ms = 200;
    let mut d = Driven::new(cfg);
    d.first_plan("2d-min-time-avoidable");
    let p = &d.h.plans[0];
    assert_eq!(p.trigger(), Some(Trigger::Initial));
    assert_eq!(p.start_time_s, 0.0);
}

/// B9: a first plan that waits for an ownship state keeps the status `Planning` until it
/// has started, also between the end of that wait and the pass that starts the plan (the
/// status of that window said `Degraded`: a lock-step harness reading it went on as if
/// nothing were due, and `first_plan` here saw no plan). Protection: `first_plan_due` in
/// the status's `Planning` condition.
#[test]
fn a_first_plan_is_planning_from_its_tasking_until_it_has_started() {
    let cfg = test_config(&vehicle("first-due"));
    let wait = Duration::from_millis(cfg.triggers.first_plan_wait_ms);
    let mut d = Driven::new(cfg);
    d.send_scenario("2d-min-time-avoidable");
    d.pass();
    assert_eq!(
        d.status().state(),
        Some(PlannerState::Planning),
        "waiting for an ownship state"
    );
    // The wait is over and no pass has run since: the plan is due, not started.
    std::thread::sleep(wait + Duration::from_millis(50));
    let s = d.status();
    assert_eq!(s.plans_made, 0);
    assert_eq!(
        s.state(),
        Some(PlannerState::Planning),
        "a first plan is due"
    );
    d.settle();
    assert_eq!(
        d.status().plans_made,
        1,
        "the first plan, from the tasking's start"
    );
}
