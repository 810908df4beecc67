//! Fuzzing the planner service's message handlers: `run(...)` in-process over real
//! iceoryx2 services, flying a plan, gets messages of arbitrary bytes and valid messages
//! with one arbitrary 8-byte word, on every input service (proptest). Every one that fails
//! `validate()` must be rejected and counted; none may panic the service, change the
//! plan, or let a non-finite number through (every plan and status stays valid). The
//! message types' own `validate()` is fuzzed in `interfaces/tests/validate.rs`.

use std::cell::RefCell;
use std::time::Duration;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use wingman_interfaces::*;
use wingman_planner::service::ServiceThread;
use wingman_planning::scenario::bundled;
use wingman_planning::scenario::messages::{
    take_off_tasking as tasking_from, take_off_threat_reports as scenario_threats,
};
use wingman_testkit::fake_harness::*;
use wingman_testkit::process::vehicle;
use wingman_testkit::rogue::{Rogue, send_invalid};

const WAIT: Duration = Duration::from_secs(120);

/// The message on input `service` (0–5) built from `bytes` (random bytes if `word` is
/// `None`, else a valid message of that type with the 8-byte word `word` set to `bytes`'
/// first 8 bytes); `None` if it happens to be valid.
fn send(r: &Rogue, service: usize, bytes: &[u8], word: Option<usize>) -> bool {
    fn build<M: Message>(valid: M, bytes: &[u8], word: Option<usize>) -> Option<M> {
        let mut b = match word {
            None => bytes[..size_of::<M>()].to_vec(),
            Some(w) => {
                let mut b = valid.as_bytes().to_vec();
                let at = (w * 8) % (b.len() - 7);
                b[at..at + 8].copy_from_slice(&bytes[..8]);
                b
            }
        };
        b.truncate(size_of::<M>());
        let m = M::read_from_bytes(&b).ok()?;
        m.validate().is_err().then_some(m)
    }
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    let h = Header::new(SENDER_HARNESS, 1, 1_000_000_000);
    macro_rules! go {
        ($port:ident, $valid:expr) => {
            match build($valid, bytes, word) {
                Some(m) => {
                    send_invalid(&r.ports.$port, m);
                    true
                }
                None => false,
            }
        };
    }
    match service {
        0 => go!(
            tasking,
            Tasking {
                header: h,
                ..tasking_from(&sc, 9)
            }
        ),
        1 => go!(route, {
            let mut m = LeadRoute::zeroed();
            m.header = h;
            m.revision = 1;
            m.point_count = 2;
            m.points_m[1] = [1000.0, 0.0, 0.0];
            m.speed_mps = 200.0;
            m
        }),
        2 => go!(
            lead_state,
            LeadState {
                header: h,
                ..LeadState::zeroed()
            }
        ),
        3 => go!(threats, {
            let mut m = static_threat(80, [20000.0, 20000.0, 0.0], [3000.0, 3000.0, 0.0]);
            m.header = h;
            m
        }),
        4 => go!(tracks, {
            let mut m = TrackFix::zeroed();
            m.header = h;
            m.sigma_m = 10.0;
            m
        }),
        _ => go!(
            ownship,
            OwnshipState {
                header: h,
                ..OwnshipState::zeroed()
            }
        ),
    }
}

#[test]
fn arbitrary_messages_to_a_running_service_are_rejected_without_effect() {
    let v = vehicle("fuzz");
    wingman_ipc::logging::init();
    let service = ServiceThread::start(test_config(&v)).expect("start the service");
    let mut h = FakeHarness::new(&v);
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    h.first_plan(&scenario_threats(&sc), tasking_from(&sc, 1), WAIT);
    let before = h.last_status();
    let rogue = Rogue::new(&v);
    let sent = RefCell::new(0u64);
    let h = RefCell::new(h);
    let mut runner = TestRunner::new(Config {
        cases: 96,
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (
        0usize..6,
        proptest::collection::vec(any::<u8>(), 700),
        proptest::option::of(0usize..40),
    );
    runner
        .run(&strategy, |(service, bytes, word)| {
            if !send(&rogue, service, &bytes, word) {
                return Ok(());
            }
            let mut h = h.borrow_mut();
            let mut n = sent.borrow_mut();
            *n += 1;
            let want = before.messages_received + *n;
            h.wake();
            prop_assert!(
                h.wait_until(WAIT, |h| h
                    .status
                    .is_some_and(|s| s.messages_received >= want)),
                "the service stopped reading: {:?}",
                h.status
            );
            let s = h.last_status();
            prop_assert_eq!(s.messages_rejected - before.messages_rejected, *n);
            prop_assert_eq!(s.plans_made, before.plans_made);
            prop_assert_eq!(h.plans.len(), 1);
            Ok(())
        })
        .unwrap();
    let h = h.into_inner();
    let n = sent.into_inner();
    assert!(n >= 48, "only {n} invalid messages generated");
    let s = h.last_status();
    assert_eq!(s.current_plan_id, before.current_plan_id);
    drop(rogue);
    let summary = service.stop(|| h.wake()).expect("the service stops");
    assert_eq!(
        summary.status.messages_rejected - before.messages_rejected,
        n
    );
}
