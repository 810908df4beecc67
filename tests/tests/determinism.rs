//! Determinism: `3d-replan-popups` (four plans: take-off, moving pop-up, its `t_r`, the
//! lead's new route) flown twice by the real binaries, each flight on its own vehicle id,
//! gives the same sequence of plans byte for byte — every wire byte of every `Plan` the
//! planner published, compared with `compute_ms` (the only wall-clock field) zeroed.
//! Fails if anything in the planner or the lock-step harness depends on timing, thread
//! scheduling or an unseeded RNG.

use std::path::Path;
use std::time::Duration;

use wingman_harness::flight_log::{self, Direction, Entry, Kind};
use wingman_interfaces::Wire;
use wingman_testkit::process::{TempDir, harness, text, vehicle};

/// The plans of a flight log as wire bytes, `compute_ms` zeroed.
fn plans(log: &Path) -> Vec<Vec<u8>> {
    flight_log::read(log)
        .expect("read flight.log")
        .into_iter()
        .filter_map(|e| match e {
            Entry::Message {
                direction: Direction::FromPlanner,
                kind: Kind::Plan,
                bytes,
                ..
            } => {
                let mut p = flight_log::decode_plan(&bytes).expect("a logged plan");
                p.compute_ms = 0.0;
                Some(p.as_bytes().to_vec())
            }
            _ => None,
        })
        .collect()
}

#[test]
fn the_same_mission_flown_twice_gives_identical_plans() {
    let dir = TempDir::new("determinism");
    let mut runs = Vec::new();
    for k in 0..2 {
        let out = dir.path().join(format!("run{k}"));
        let v = vehicle(&format!("det{k}"));
        let o = harness(&[
            "fly",
            "3d-replan-popups",
            "--quiet",
            "--vehicle",
            &v,
            "--out",
            out.to_str().unwrap(),
        ])
        .wait(Duration::from_secs(900));
        assert!(o.status.success(), "{}", text(&o));
        runs.push(plans(&out.join("flight.log")));
    }
    assert!(runs[0].len() >= 4, "{} plans", runs[0].len());
    assert_eq!(runs[0].len(), runs[1].len(), "plan counts differ");
    for (k, (a, b)) in runs[0].iter().zip(&runs[1]).enumerate() {
        let first = a.iter().zip(b).position(|(x, y)| x != y);
        assert!(first.is_none(), "plan {k} differs from byte {first:?} on");
    }
}
