//! Faults, each its own test, with the real `wingman-planner serve` process (and the real
//! `wingman-harness` where a mission is flown). Every test has its own vehicle id, a
//! watchdog on every child and clean-up in `Drop` (children killed, dead iceoryx2 nodes
//! removed). Each test's doc names the protection it exercises: without it, the test
//! fails.

use std::time::Duration;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wingman_harness::flight_log::{self, Direction, Kind};
use wingman_harness::tracker::reference;
use wingman_interfaces::*;
use wingman_ipc::{self as ipc, Ipc};
use wingman_planning::scenario::bundled;
use wingman_planning::scenario::messages::{
    take_off_tasking as tasking_from, take_off_threat_reports as scenario_threats,
};
use wingman_testkit::fake_harness::{FakeHarness, static_threat};
use wingman_testkit::process::{
    Proc, TempDir, harness, harness_logging, planner, planner_config, report, text, vehicle,
};
use wingman_testkit::rogue::{Rogue, send_invalid};
use wingman_tests::outcome::{assert_every_tr_followed, assert_mission_succeeded, plans};

const FLIGHT: Duration = Duration::from_secs(900);
const WAIT: Duration = Duration::from_secs(120);

/// Sends `msgs` (each checked invalid) in batches no larger than the planner's subscriber
/// buffer, waiting after each until the planner has taken it, so that none is dropped by
/// the buffer's overflow unread.
fn send_batches<M: Message + 'static>(
    h: &mut FakeHarness,
    p: &mut wingman_testkit::process::Proc,
    port: &iceoryx2::port::publisher::Publisher<Ipc, M, ()>,
    msgs: &[M],
) {
    let n = ipc::qos(M::SERVICE).subscriber_buffer.min(4);
    for chunk in msgs.chunks(n) {
        let received = h.last_status().messages_received;
        for m in chunk {
            send_invalid(port, *m);
        }
        h.wake();
        let want = received + chunk.len() as u64;
        assert!(
            h.wait_until(WAIT, |h| h
                .status
                .is_some_and(|s| s.messages_received >= want)),
            "the planner stopped reading {}: {:?}",
            M::NAME,
            h.status
        );
        assert!(p.is_running(), "the planner crashed");
    }
}

/// A valid header of the harness at mission time `t`, sequence `seq`.
fn header(seq: u64, t: f64) -> Header {
    Header::new(SENDER_HARNESS, seq, (t * 1e9) as i64)
}

/// The malformed messages of one message type: a NaN, a count over capacity (where the
/// type has a count), another protocol version, and `random` messages of random bytes.
fn malformed<M: Message>(
    rng: &mut ChaCha8Rng,
    valid: M,
    nan: impl Fn(&mut M),
    over: Option<&dyn Fn(&mut M)>,
    random: usize,
) -> Vec<M> {
    let mut out = Vec::new();
    let mut m = valid;
    nan(&mut m);
    out.push(m);
    if let Some(over) = over {
        let mut m = valid;
        over(&mut m);
        out.push(m);
    }
    let mut bytes = valid.as_bytes().to_vec();
    bytes[..4].copy_from_slice(&(PROTOCOL_VERSION + 7).to_le_bytes());
    out.push(M::read_from_bytes(&bytes).unwrap());
    for _ in 0..random {
        let mut b = vec![0u8; size_of::<M>()];
        rng.fill_bytes(&mut b);
        out.push(M::read_from_bytes(&b).unwrap());
    }
    out
}

/// A planner process and a fake harness that has sent `2d-min-time-avoidable` (threats,
/// tasking) and received the first plan.
fn planner_with_first_plan(
    dir: &TempDir,
    tag: &str,
    extra: &str,
) -> (wingman_testkit::process::Proc, FakeHarness, String) {
    let v = vehicle(tag);
    let cfg = planner_config(dir.path(), 2000, 6000, extra);
    let p = planner(&cfg, &v, &dir.path().join("planner.log"));
    let mut h = FakeHarness::new(&v);
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    h.first_plan(&scenario_threats(&sc), tasking_from(&sc, 1), WAIT);
    (p, h, v)
}

/// A rogue publisher on every input service sends malformed messages — a NaN, a count
/// over capacity, another protocol version, random bytes — to a planner that is flying a
/// plan: every one is rejected and counted, nothing crashes, the plan does not change,
/// and valid input is still served afterwards.
///
/// Protection: `validate()` on every received message before anything else (the service's
/// `admit`). Without it the NaN or over-capacity tasking reaches the world model and
/// re-plans (or the solver sees NaN), and `messages_rejected` no longer matches.
#[test]
fn a_rogue_publisher_of_malformed_messages_is_rejected_and_counted() {
    let dir = TempDir::new("rogue");
    let (mut p, mut h, v) = planner_with_first_plan(&dir, "rogue", "");
    let before = h.last_status();
    let plan_id = before.current_plan_id;
    let rogue = Rogue::new(&v);
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    let t = 1.0;

    let mut task = tasking_from(&sc, 2);
    task.header = header(1000, t);
    task.targets_m[0][0] = 5000.0; // a real change, were it accepted
    let mut route = LeadRoute::zeroed();
    route.header = header(1001, t);
    route.revision = 1;
    route.point_count = 2;
    route.points_m[1] = [1000.0, 0.0, 0.0];
    route.speed_mps = 200.0;
    let mut lead = LeadState::zeroed();
    lead.header = header(1002, t);
    let mut threat = static_threat(70, [20000.0, 20000.0, 0.0], [3000.0, 3000.0, 0.0]);
    threat.header = header(1003, t);
    let mut fix = TrackFix::zeroed();
    fix.header = header(1004, t);
    fix.sigma_m = 10.0;
    let mut own = OwnshipState::zeroed();
    own.header = header(1005, t);

    let tasks = malformed(
        &mut rng,
        task,
        |m: &mut Tasking| m.final_state[0] = f64::NAN,
        Some(&|m: &mut Tasking| m.target_count = MAX_TARGETS as u32 + 1),
        8,
    );
    let routes = malformed(
        &mut rng,
        route,
        |m: &mut LeadRoute| m.speed_mps = f64::INFINITY,
        Some(&|m: &mut LeadRoute| m.point_count = MAX_ROUTE_POINTS as u32 + 1),
        8,
    );
    let leads = malformed(
        &mut rng,
        lead,
        |m: &mut LeadState| m.position_m[1] = f64::NAN,
        None,
        8,
    );
    let threats = malformed(
        &mut rng,
        threat,
        |m: &mut ThreatReport| m.axes_m[0] = f64::NAN,
        Some(&|m: &mut ThreatReport| m.road_point_count = MAX_ROAD_POINTS as u32 + 1),
        8,
    );
    let fixes = malformed(
        &mut rng,
        fix,
        |m: &mut TrackFix| m.position_m[0] = f64::NAN,
        None,
        8,
    );
    let owns = malformed(
        &mut rng,
        own,
        |m: &mut OwnshipState| m.state[0] = f64::NAN,
        None,
        8,
    );
    let total =
        (tasks.len() + routes.len() + leads.len() + threats.len() + fixes.len() + owns.len())
            as u64;
    send_batches(&mut h, &mut p, &rogue.ports.tasking, &tasks);
    send_batches(&mut h, &mut p, &rogue.ports.route, &routes);
    send_batches(&mut h, &mut p, &rogue.ports.lead_state, &leads);
    send_batches(&mut h, &mut p, &rogue.ports.threats, &threats);
    send_batches(&mut h, &mut p, &rogue.ports.tracks, &fixes);
    send_batches(&mut h, &mut p, &rogue.ports.ownship, &owns);
    assert!(
        h.wait_until(WAIT, |h| h.status.is_some_and(|s| s.messages_rejected
            - before.messages_rejected
            == total)),
        "rejections: {:?} (expected {total} more than {})",
        h.status.map(|s| s.messages_rejected),
        before.messages_rejected
    );
    // Valid input is still served: a pop-up clear of the plan is assessed.
    h.set_time(2.0);
    h.send_threat(static_threat(
        71,
        [-40000.0, -40000.0, 0.0],
        [2000.0, 2000.0, 0.0],
    ));
    h.wake();
    assert!(h.wait_processed(WAIT));
    std::thread::sleep(Duration::from_millis(500));
    h.poll();
    let s = h.last_status();
    assert_eq!(s.messages_rejected - before.messages_rejected, total);
    assert_eq!(s.messages_received - before.messages_received, total + 1);
    assert_eq!(s.popups_clear, before.popups_clear + 1);
    assert_eq!(s.plans_made, before.plans_made, "a plan for invalid input");
    assert_eq!(s.current_plan_id, plan_id);
    assert_eq!(h.plans.len(), 1);
    assert!(p.is_running(), "the planner crashed");
    drop(rogue);
    assert!(p.terminate(Duration::from_secs(30)).success());
}

/// A planner given a 3-D deadline far too short to converge (30 ms) still publishes a
/// plan, flagged `SwarmOnly` or `Feasible` (not `Optimal`), within its deadline (the
/// planner's own compute time, with a generous allowance for a loaded machine), for the
/// take-off and for a re-plan, and the re-plan commits at its trigger time plus the
/// budget.
///
/// Protection: the anytime deadline (the solver's wall-clock check and the best iterate
/// returned with its quality). Without it the solver runs to convergence: an `Optimal`
/// plan after 1–3 s.
#[test]
fn a_deadline_too_short_to_converge_still_gives_a_flagged_plan_in_time() {
    let dir = TempDir::new("deadline");
    let v = vehicle("deadline");
    let budget_ms = 30.0;
    // A flagged plan is refined (with the same 30 ms here): not this test's subject.
    let cfg = planner_config(dir.path(), 30, 30, "\n[triggers]\nrefine = false\n");
    let mut p = planner(&cfg, &v, &dir.path().join("planner.log"));
    let mut h = FakeHarness::new(&v);
    assert!(h.wait_until(Duration::from_secs(60), |h| h.status.is_some()));
    let sc = bundled("3d-min-time-avoidable").unwrap().unwrap();
    h.set_time(0.0);
    for t in scenario_threats(&sc) {
        h.send_threat(t);
    }
    h.send_tasking(tasking_from(&sc, 1));
    h.wake();
    assert!(
        h.wait_until(WAIT, |h| !h.plans.is_empty()),
        "no plan: {:?}",
        h.status
    );
    let flagged = |p: &Plan| matches!(p.quality(), Some(Quality::SwarmOnly | Quality::Feasible));
    // Allowance for a machine shared with other jobs: far below a converged 3-D plan.
    let in_time = |p: &Plan| p.compute_ms <= budget_ms + 500.0;
    let first = &h.plans[0];
    assert!(flagged(first), "quality {:?}", first.quality());
    assert!(in_time(first), "compute {} ms", first.compute_ms);
    assert!(first.validate().is_ok());

    // A pop-up on the plan ahead: a re-plan under the same deadline.
    let first = first.clone();
    let re = &popup_ahead(&mut h, first);
    assert_eq!(re.trigger(), Some(Trigger::PopUp));
    assert!(flagged(re), "quality {:?}", re.quality());
    assert!(in_time(re), "compute {} ms", re.compute_ms);
    assert!(
        (re.start_time_s - (re.created_at_s + budget_ms / 1e3)).abs() < 1e-6,
        "commit at trigger + budget: {} vs {}",
        re.start_time_s,
        re.created_at_s
    );
    assert!(p.is_running());
    assert!(p.terminate(Duration::from_secs(30)).success());
}

/// At mission time 10 s, a 1.5 km pop-up on `first` 200 s ahead; the re-plan it makes.
fn popup_ahead(h: &mut FakeHarness, first: Box<Plan>) -> Box<Plan> {
    let on = wingman_planning::plan_message::state_at(&first, 200.0).unwrap();
    h.set_time(10.0);
    h.send_threat(static_threat(
        90,
        [on[0], on[1], on[2]],
        [1500.0, 1500.0, 1500.0],
    ));
    h.wake();
    assert!(
        h.wait_until(WAIT, |h| h.plans.len() >= 2),
        "no re-plan: {:?}",
        h.status
    );
    h.plans[1].clone()
}

/// A re-plan whose deadline (10 ms, far below a 3-D NLP solve) leaves the swarm's path is
/// refined at once: a `Refine` plan follows, from the last NLP plan (the take-off's), with the
/// refinement budget (4 s here: its commit is its creation + 4 s), and it is `Optimal`.
/// With `refine = false` the flagged re-plan stays the plan in flight.
///
/// Protection: `refine_due` raised after a plan short of `Optimal` and the budget of a
/// refinement being its own (with the re-plan budget the refinement is cut at 10 ms as
/// well and comes out flagged; without the trigger no third plan comes).
#[test]
fn a_replan_its_deadline_cut_short_is_refined_with_the_refinement_budget() {
    for refine in [true, false] {
        let dir = TempDir::new("refine");
        let v = vehicle("refine");
        let cfg = dir.path().join("planner.toml");
        std::fs::write(
            &cfg,
            format!(
                "[budget]\nplan_2d_ms = 2000\nplan_3d_ms = 6000\nreplan_2d_ms = 10\n\
                 replan_3d_ms = 10\nrefine_3d_ms = 4000\nduty_cycle = 1.0\nduty_window_ms = 60000\n\n\
                 [status]\nheartbeat_ms = 100\n\n[triggers]\nrefine = {refine}\n"
            ),
        )
        .expect("write planner.toml");
        let mut p = planner(&cfg, &v, &dir.path().join("planner.log"));
        let mut h = FakeHarness::new(&v);
        let sc = bundled("3d-min-time-avoidable").unwrap().unwrap();
        h.first_plan(&scenario_threats(&sc), tasking_from(&sc, 1), WAIT);
        let first = h.plans[0].clone();
        assert_eq!(first.quality(), Some(Quality::Optimal));
        let re = popup_ahead(&mut h, first);
        assert_eq!(re.trigger(), Some(Trigger::PopUp));
        assert_ne!(re.quality(), Some(Quality::Optimal), "a 10 ms 3-D re-plan");
        if refine {
            assert!(
                h.wait_until(WAIT, |h| h.plans.len() >= 3),
                "no refinement: {:?}",
                h.status
            );
            let refined = &h.plans[2];
            assert_eq!(refined.trigger(), Some(Trigger::Refine));
            assert_eq!(refined.quality(), Some(Quality::Optimal));
            assert!(
                (refined.start_time_s - (refined.created_at_s + 4.0)).abs() < 1e-6,
                "commit at creation + the refinement budget: {} vs {}",
                refined.start_time_s,
                refined.created_at_s
            );
            assert!(refined.validate().is_ok());
        } else {
            // Nothing follows the flagged re-plan: the planner goes idle on it.
            assert!(!h.wait_until(Duration::from_secs(3), |h| h.plans.len() >= 3));
        }
        assert!(p.is_running());
        assert!(p.terminate(Duration::from_secs(30)).success());
    }
}

/// `kill -9` of the planner mid-flight (harness `--kill-planner-at 100 --restart-after
/// 20`): the tracker keeps flying the last plan (no safe hold), a new planner process
/// starts on the same vehicle id, removes the dead node's iceoryx2 resources, takes the
/// tasking and threats from the services' history, and publishes a `Restart` plan from
/// the tracker's state that the mission completes on.
///
/// Protections: the tracker flying the last valid plan when no planner answers; the
/// services' history (without it the new planner has no tasking and never plans: the
/// harness times out); the dead-node clean-up at start-up (asserted from the new
/// planner's log). A `Restart` plan (from the tracker's state) is required: an
/// `Initial` one means the new planner planned from the tasking's start at mission time 0
/// — the service does so when the tasking's history reaches it before any ownship state,
/// which the harness avoids by handing over the history with the next ownship state.
#[test]
fn a_planner_killed_mid_flight_is_replaced_and_the_mission_completes() {
    let dir = TempDir::new("kill-planner");
    let out = dir.path().join("run");
    let v = vehicle("killplanner");
    let o = harness_logging(
        &[
            "fly",
            "3d-min-time-moving-threat",
            "--quiet",
            "--vehicle",
            &v,
            "--kill-planner-at",
            "100",
            "--restart-after",
            "20",
            "--out",
            out.to_str().unwrap(),
        ],
        "info",
    )
    .wait(FLIGHT);
    assert!(o.status.success(), "{}", text(&o));
    let r = report(&out);
    assert_mission_succeeded(&r);
    assert_every_tr_followed(&r);
    let plans = plans(&r);
    let restart: Vec<_> = plans.iter().filter(|p| p.trigger == "Restart").collect();
    assert_eq!(restart.len(), 1, "one Restart plan: {plans:?}");
    assert!(
        (restart[0].at_s - 120.0).abs() < 1.0,
        "the new planner planned at once: {plans:?}"
    );
    assert!(
        !plans.iter().any(|p| p.at_s > 100.0 && p.at_s < 119.9),
        "a plan while no planner ran: {plans:?}"
    );
    let log = std::fs::read_to_string(out.join("planner.restart.log")).unwrap();
    assert!(
        log.contains("removed the resources of dead iceoryx2 nodes"),
        "the new planner did not clean up the dead node:\n{log}"
    );
}

/// Starts a planner and a harness flying `2d-min-time-avoidable` against it in the real
/// -time clock, and kills the harness (`kill -9`) once the flight is under way. Returns
/// the planner, the status watcher and the folder.
fn kill_the_harness(dir: &TempDir, v: &str) -> (wingman_testkit::process::Proc, FakeStatus) {
    let cfg = planner_config(dir.path(), 2000, 6000, "\n[staleness]\nownship_ms = 500\n");
    let p = planner(&cfg, v, &dir.path().join("planner.log"));
    let first = dir.path().join("first");
    let mut hx = harness(&[
        "fly",
        "2d-min-time-avoidable",
        "--quiet",
        "--planner",
        "external",
        "--clock",
        "realtime",
        "--vehicle",
        v,
        "--out",
        first.to_str().unwrap(),
    ]);
    let mut watch = FakeStatus::new(v);
    assert!(
        watch.wait(WAIT, |s| s.plans_made >= 1 && s.stale_inputs == 0),
        "the first flight did not get going: {:?}",
        watch.last
    );
    std::thread::sleep(Duration::from_secs(2));
    assert!(hx.is_running(), "the first harness ended early");
    hx.kill9();
    (p, watch)
}

/// `kill -9` of the harness mid-flight: the planner keeps running, reports the ownship
/// input stale in `PlannerStatus` (and keeps its heartbeat and plan), and still stops
/// cleanly on SIGTERM.
///
/// Protection: the staleness bits of the status (without them `stale_inputs` stays 0),
/// and the planner's independence of its peers (a dead publisher is not an error: without
/// that the planner exits or its heartbeat stops, and the wait for the stale bit fails).
#[test]
fn a_harness_killed_mid_flight_leaves_the_planner_running_and_reporting_stale_inputs() {
    let dir = TempDir::new("kill-harness");
    let v = vehicle("killharness");
    let (mut p, mut watch) = kill_the_harness(&dir, &v);
    let before = watch.last.unwrap();
    assert!(
        watch.wait(WAIT, |s| s.stale_inputs & STALE_OWNSHIP != 0),
        "no stale ownship reported: {:?}",
        watch.last
    );
    let s = watch.last.unwrap();
    assert_eq!(
        s.current_plan_id, before.current_plan_id,
        "the plan is kept"
    );
    assert!(p.is_running(), "the planner died with its harness");
    assert!(p.terminate(Duration::from_secs(30)).success());
}

/// After its harness was killed (`kill -9`, at about 2 s of mission time), the planner
/// serves a new harness process that resumes the mission (`fly --resume`): the new harness
/// starts at the planner's mission time on its current plan, the planner takes its inputs
/// (no rejection; the stale ownship bit clears), the mission completes, and a pop-up the
/// new harness reports at 40 s (`--popup-burst-at 40 --popup-burst-count 1`, on the plan
/// ahead) is re-planned by the planner that kept running (plan ids continuing above the
/// resumed one). The planner then stops cleanly.
///
/// Protections: the resume point — mission time and input sequence continued from the
/// planner's status (a new harness whose clock restarts at 0 has every input refused as
/// time going backwards: `messages_rejected` grows and no pop-up plan comes; one whose
/// sequence restarts passes the lock-step barrier before the planner has read its inputs,
/// and the planner's highest sequence no longer counts the new inputs on from the old);
/// the world replayed to the resume time (tasking and route repeats: no `Tasking` or
/// `Initial` re-plan) and the tracker started on the current plan (its first ownship
/// state, read from `flight.log`, is the plan's state at the resume time). Without
/// `--resume` (the harness flying the mission again from its start) this test fails.
#[test]
fn a_harness_killed_mid_flight_is_replaced_by_a_new_one_the_planner_serves() {
    let dir = TempDir::new("new-harness");
    let v = vehicle("newharness");
    let (mut p, mut watch) = kill_the_harness(&dir, &v);
    assert!(
        watch.wait(WAIT, |s| s.stale_inputs & STALE_OWNSHIP != 0),
        "no stale ownship reported: {:?}",
        watch.last
    );
    let s = watch.last.unwrap();
    let planner_s = s.header.mission_time_ns as f64 * 1e-9;
    let second = dir.path().join("second");
    let hx = resume(
        "2d-min-time-avoidable",
        &v,
        &second,
        &["--popup-burst-at", "40", "--popup-burst-count", "1"],
    );
    // Served while it flies: the new harness's inputs are fresh again.
    assert!(
        watch.wait(WAIT, |st| st.stale_inputs == 0
            && st.messages_received > s.messages_received),
        "the planner never saw the new harness's inputs fresh: {:?}",
        watch.last
    );
    let o = hx.wait(FLIGHT);
    assert!(o.status.success(), "{}", text(&o));
    let r = report(&second);
    let resumed = r["resumed_at_s"].as_f64().expect("resumed_at_s");
    assert!(
        resumed >= planner_s - 1e-6 && resumed <= planner_s + 0.1 + 1e-6,
        "resumed at {resumed} s, the planner was at {planner_s} s"
    );
    assert!(
        resumed < 40.0,
        "the kill came too late for the pop-up: {resumed} s"
    );
    assert_mission_succeeded(&r);
    assert_every_tr_followed(&r);
    let rows = plans(&r);
    let ids: Vec<u64> = r["plans"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["plan_id"].as_u64().unwrap())
        .collect();
    assert_eq!(
        ids[0], s.current_plan_id,
        "resumed on another plan: {rows:?}"
    );
    assert_eq!(r["plans"][0]["flown"], true);
    // The aircraft took up the flight on the plan: the new harness's first ownship state
    // is the resumed plan's state at the resume time (1 m; the plan's own interpolation).
    let log = flight_log::read(&second.join("flight.log")).unwrap();
    let plan = flight_log::plans(&log)
        .next()
        .expect("the resumed plan in flight.log");
    let own: OwnshipState = flight_log::messages(&log, Direction::ToPlanner, Kind::OwnshipState)
        .find_map(flight_log::decode)
        .expect("an ownship state in flight.log");
    assert_eq!(plan.plan_id, s.current_plan_id);
    assert_eq!(own.plan_id, plan.plan_id);
    assert!((own.time_s - resumed).abs() < 1e-9);
    let (x, _) = reference(&plan, resumed);
    let off = (own.state[0] - x[0]).hypot(own.state[1] - x[1]);
    assert!(off < 1.0, "the aircraft resumed {off} m off the plan");
    let after = &rows[1..];
    assert!(
        !after.is_empty()
            && after
                .iter()
                .all(|p| p.trigger == "PopUp" && (40.0..41.0).contains(&p.at_s)),
        "the planner's plans after the resume are the pop-up's only: {rows:?}"
    );
    assert_eq!(ids[1], s.current_plan_id + 1, "plan ids: {ids:?}");
    let counters = &r["planner"];
    assert_eq!(
        counters["messages_rejected"].as_u64().unwrap(),
        s.messages_rejected,
        "the new harness's inputs were refused"
    );
    assert_eq!(
        counters["plans_made"].as_u64().unwrap(),
        s.plans_made + after.len() as u64
    );
    assert_eq!(r["rejected_messages"].as_u64().unwrap(), 0);
    // The input sequence went on from the planner's: every input of the new harness was
    // processed, numbered on from the last one the planner had.
    let received = counters["messages_received"].as_u64().unwrap();
    assert!(watch.wait(WAIT, |st| st.messages_received >= received));
    let end = watch.last.unwrap();
    assert_eq!(
        end.last_input_sequence,
        s.last_input_sequence + (end.messages_received - s.messages_received),
        "the sequence did not continue: {s:?} then {end:?}"
    );
    assert!(
        r["targets_before_resume"].as_array().unwrap().is_empty(),
        "the target lies ahead of a resume at {resumed} s"
    );
    assert!(p.is_running(), "the planner died");
    assert!(p.terminate(Duration::from_secs(30)).success());
}

/// `wingman-harness fly SCENARIO --resume` against the external planner of vehicle `v`,
/// quiet, writing into `out`, with `extra` arguments.
fn resume(scenario: &str, v: &str, out: &std::path::Path, extra: &[&str]) -> Proc {
    let out = out.to_str().unwrap();
    let mut args = vec![
        "fly",
        scenario,
        "--resume",
        "--quiet",
        "--planner",
        "external",
        "--vehicle",
        v,
        "--out",
        out,
    ];
    args.extend_from_slice(extra);
    harness(&args)
}

/// `fly --resume` of another scenario than the planner flies is refused with an error
/// naming the difference (here a 3-D scenario against a 2-D plan), exit code 1; the
/// planner is left as it was (no input sent, so nothing rejected, and still running).
///
/// Protection: the check of the planner's plan against the scenario before anything is
/// sent (without it the harness publishes a 3-D tasking into a 2-D mission).
#[test]
fn resuming_a_planner_that_flies_another_mission_is_refused() {
    let dir = TempDir::new("resume-other");
    let (mut p, mut h, v) = planner_with_first_plan(&dir, "resumeother", "");
    let before = h.last_status();
    let o = resume("3d-min-time-avoidable", &v, &dir.path().join("run"), &[]).wait(WAIT);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("the planner flies another mission than `3d-min-time-avoidable`")
            && err.contains("is 2-D, the scenario is 3-D"),
        "{err}"
    );
    std::thread::sleep(Duration::from_millis(300));
    h.poll();
    let after = h.last_status();
    assert_eq!(after.messages_received, before.messages_received);
    assert_eq!(after.plans_made, before.plans_made);
    assert!(p.is_running(), "the planner died");
    assert!(p.terminate(Duration::from_secs(30)).success());
}

/// A subscriber of a vehicle's `status` service.
struct FakeStatus {
    sub: iceoryx2::port::subscriber::Subscriber<Ipc, PlannerStatus, ()>,
    last: Option<PlannerStatus>,
    _node: iceoryx2::node::Node<Ipc>,
}

impl FakeStatus {
    fn new(v: &str) -> FakeStatus {
        let node = ipc::node(&format!("status-watch-{v}"), false).unwrap();
        let sub = ipc::subscriber(&ipc::open_publish_subscribe(&node, v).unwrap()).unwrap();
        FakeStatus {
            sub,
            last: None,
            _node: node,
        }
    }

    fn wait(&mut self, limit: Duration, done: impl Fn(&PlannerStatus) -> bool) -> bool {
        use iceoryx2::port::update_connections::UpdateConnections;
        let start = std::time::Instant::now();
        while start.elapsed() < limit {
            let _ = self.sub.update_connections();
            while let Ok(Some(s)) = self.sub.receive() {
                let s = *s.payload();
                assert!(s.validate().is_ok(), "an invalid status: {s:?}");
                self.last = Some(s);
            }
            if self.last.as_ref().is_some_and(&done) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        false
    }
}

/// A burst of 100 pop-ups within one second of mission time, each on the flown plan
/// ahead (harness `--popup-burst-at 60`): the planner coalesces them into a few re-plans
/// (its status counters account for every pop-up) and the mission still completes.
///
/// Protection: coalescing of triggers that arrive together or while a plan is in flight
/// (and the minimum spacing between plans). Without it every pop-up re-plans: as many
/// re-plans as pop-ups, and `triggers_coalesced` stays 0.
#[test]
fn a_burst_of_popups_is_coalesced_and_the_mission_completes() {
    let dir = TempDir::new("burst");
    let out = dir.path().join("run");
    let v = vehicle("burst");
    let o = harness(&[
        "fly",
        "2d-min-time-avoidable",
        "--quiet",
        "--vehicle",
        &v,
        "--popup-burst-at",
        "60",
        "--out",
        out.to_str().unwrap(),
    ])
    .wait(FLIGHT);
    assert!(o.status.success(), "{}", text(&o));
    let r = report(&out);
    assert_mission_succeeded(&r);
    let plans = plans(&r);
    let burst: Vec<_> = plans.iter().filter(|p| p.trigger == "PopUp").collect();
    let s = &r["planner"];
    let coalesced = s["triggers_coalesced"].as_u64().unwrap();
    let deferred = s["triggers_deferred"].as_u64().unwrap();
    let clear = s["popups_clear"].as_u64().unwrap();
    eprintln!(
        "burst: {} re-plans, coalesced {coalesced}, deferred {deferred}, clear {clear}",
        burst.len()
    );
    assert!(!burst.is_empty(), "no re-plan for the burst: {plans:?}");
    assert!(
        burst.len() <= 10,
        "{} re-plans for one burst: {plans:?}",
        burst.len()
    );
    assert!(
        burst.iter().all(|p| (60.0..62.0).contains(&p.at_s)),
        "{plans:?}"
    );
    assert!(coalesced >= 1, "no trigger coalesced");
    assert!(
        burst.len() as u64 + coalesced + deferred + clear >= 100,
        "pop-ups unaccounted for: {} plans, {coalesced} coalesced, {deferred} deferred, {clear} clear",
        burst.len()
    );
    assert_eq!(s["messages_rejected"].as_u64().unwrap(), 0);
}
