//! Determinism: `3d-replan-popups` (four plans: take-off, moving pop-up, its `t_r`, the
//! lead's new route) flown twice by the real binaries, each flight on its own vehicle id,
//! gives the same sequence of plans byte for byte — every wire byte of every `Plan` the
//! planner published, compared with `compute_ms` (the only wall-clock field) zeroed.
//! Fails if anything in the planner or the lock-step harness depends on timing, thread
//! scheduling or an unseeded RNG.
//!
//! A plan its compute deadline cuts depends on the machine's speed as well (its deadline
//! cuts, which replay takes again: `canonical.rs` replays every flight on the deployment
//! defaults). Two independent flights are comparable only when nothing is cut: these two
//! fly with budgets no plan comes near (2 s per 2-D plan, 6 s per 3-D plan), and every
//! plan is checked to carry no cut. A third flight, on the deployment defaults (re-plans
//! within 300 ms in 3-D, so each re-plan also starts earlier: a plan commits at its start
//! plus its budget), is then held to issue 31's yardstick, event by event: the same events
//! re-plan in the same order; the plan each event leaves in flight (its re-plan, or the
//! refinement that follows a re-plan published short of `Optimal`) is `Optimal` and costs
//! within 0.1 % of the uncut flight's plan for that event; the end is within 1 % of the
//! uncut flight's and the rendezvous within 20 m of it.
//!
//! Why the refinement counts. Whether the pop-up re-plan converges within its 300 ms is
//! the machine's speed: its warm solve took 170-220 ms on the 2-core VM at its usual
//! speed, and 240 ms or more with the VM at half speed (the plan bench's host reference
//! 11.6 ms against 6.1 ms, 2026-12-07), where it comes out `SwarmOnly` and the service
//! refines it at once (1.2 s budget, about 1 s there) into the uncut flight's plan (cost
//! 53.6031 both). A clean-clone CI run failed on the plan count that way. What a user
//! flies after the event is the refined plan, which is what this compares; whether the
//! re-plan alone converges in its budget is measured by the re-plan bench.
//!
//! Why 20 m (issue 31 set 10 m, measured at 5 m then). Whether the pop-up re-plan's
//! mesh-refinement round (about 50 ms) still fits decides between two `Optimal` plans
//! 0.009 % apart in cost, and the flights that follow meet the lead 6.7 m or 15.6 m from
//! the uncut flight's rendezvous (quiet runs on one machine gave either, about half each;
//! a clean-clone CI run gave 15.6 m). The degraded plans issue 31 replaced (`SwarmOnly`,
//! 14 % costlier, flown) met the lead 27-95 m away and 80 s later: the cost check and
//! 20 m still tell those apart.

use std::path::Path;
use std::time::Duration;

use wingman_harness::flight_log::{self, Direction, Entry, Kind};
use wingman_interfaces::Wire;
use wingman_testkit::process::{TempDir, harness, planner_config, report, text, vehicle};

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

/// Flies `3d-replan-popups` into `out` on a fresh vehicle id (`config`: a planner
/// configuration, else the harness's, which is the deployment defaults).
fn fly(out: &Path, tag: &str, config: Option<&Path>) -> serde_json::Value {
    let v = vehicle(tag);
    let mut args = vec![
        "fly",
        "3d-replan-popups",
        "--quiet",
        "--vehicle",
        &v,
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(c) = config {
        args.extend(["--planner-config", c.to_str().unwrap()]);
    }
    let o = harness(&args).wait(Duration::from_secs(900));
    assert!(o.status.success(), "{}", text(&o));
    report(out)
}

#[test]
fn the_same_mission_flown_twice_gives_identical_plans() {
    let dir = TempDir::new("determinism");
    let uncut = planner_config(dir.path(), 2_000, 6_000, "");
    let mut runs = Vec::new();
    let mut reports = Vec::new();
    for k in 0..2 {
        let out = dir.path().join(format!("run{k}"));
        let r = fly(&out, &format!("det{k}"), Some(&uncut));
        for p in r["plans"].as_array().unwrap() {
            assert_eq!(p["cuts"], 0, "a long budget cut a plan: {p}");
        }
        reports.push(r);
        runs.push(plans(&out.join("flight.log")));
    }
    assert!(runs[0].len() >= 4, "{} plans", runs[0].len());
    assert_eq!(runs[0].len(), runs[1].len(), "plan counts differ");
    for (k, (a, b)) in runs[0].iter().zip(&runs[1]).enumerate() {
        let first = a.iter().zip(b).position(|(x, y)| x != y);
        assert!(first.is_none(), "plan {k} differs from byte {first:?} on");
    }

    // The deployment defaults (re-plans within 100 / 300 ms) against the uncut flight.
    let defaults = fly(&dir.path().join("defaults"), "det-defaults", None);
    let uncut = &reports[0];
    let events = |r: &serde_json::Value| -> Vec<Vec<serde_json::Value>> {
        let mut events: Vec<Vec<serde_json::Value>> = Vec::new();
        for p in r["plans"].as_array().unwrap() {
            match events.last_mut() {
                Some(chain) if p["trigger"] == "Refine" => chain.push(p.clone()),
                _ => events.push(vec![p.clone()]),
            }
        }
        events
    };
    let (events, uncut_events) = (events(&defaults), events(uncut));
    assert_eq!(
        uncut_events.len(),
        runs[0].len(),
        "the uncut flight refines nothing"
    );
    let triggers = |e: &[Vec<serde_json::Value>]| -> Vec<String> {
        e.iter().map(|c| c[0]["trigger"].to_string()).collect()
    };
    assert_eq!(
        triggers(&events),
        triggers(&uncut_events),
        "the same events re-plan, in the same order"
    );
    for (chain, uncut_chain) in events.iter().zip(&uncut_events) {
        let (p, q) = (chain.last().unwrap(), &uncut_chain[0]);
        assert!(chain.len() <= 2, "one refinement at most: {chain:?}");
        assert_eq!(
            p["quality"], "Optimal",
            "the plan an event leaves: {chain:?}"
        );
        let (c, c_uncut) = (p["cost"].as_f64().unwrap(), q["cost"].as_f64().unwrap());
        assert!(
            (c - c_uncut).abs() <= 1e-3 * c_uncut,
            "after {}, plan {} costs {c}, the uncut flight's {c_uncut}",
            chain[0]["trigger"],
            p["plan_id"]
        );
    }
    let end = |r: &serde_json::Value| r["end_s"].as_f64().unwrap();
    let (t_default, t_uncut) = (end(&defaults), end(uncut));
    assert!(
        (t_default - t_uncut).abs() <= 0.01 * (t_uncut - defaults["start_s"].as_f64().unwrap()),
        "end {t_default} s against {t_uncut} s"
    );
    let at = |r: &serde_json::Value| -> Vec<f64> {
        r["end_position_m"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect()
    };
    let apart = at(&defaults)
        .iter()
        .zip(at(uncut))
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt();
    assert!(
        apart <= 20.0,
        "the rendezvous is {apart} m from the uncut flight's"
    );
}
