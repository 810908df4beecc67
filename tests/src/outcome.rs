//! Checks of a flight's `report.json` (keys in `docs/REPORT.md`) shared by the
//! multi-process tests: the mission's outcome, and that every re-plan is one the mission
//! called for (each scheduled `t_r` followed, nothing else).

use serde_json::Value;

/// A plan of the report: trigger, trigger time, commit time, scheduled `t_r`.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanRow {
    pub trigger: String,
    pub at_s: f64,
    pub start_s: f64,
    pub next_replan_s: Option<f64>,
}

/// The report's plans, in order.
pub fn plans(r: &Value) -> Vec<PlanRow> {
    r["plans"]
        .as_array()
        .expect("plans")
        .iter()
        .map(|p| PlanRow {
            trigger: p["trigger"].as_str().expect("trigger").to_string(),
            at_s: p["at_s"].as_f64().expect("at_s"),
            start_s: p["start_s"].as_f64().expect("start_s"),
            next_replan_s: p["next_replan_s"].as_f64(),
        })
        .collect()
}

/// The mission's outcome on the flown path: completed, every target within 100 m, the
/// final point or the lead within 100 m, no safe hold, and (on an avoidable layout, every
/// scenario without `unavoidable` in its name) never inside a static threat, min F ≥ 1;
/// and no input lost before the planner read it.
pub fn assert_mission_succeeded(r: &Value) {
    let name = r["scenario"].as_str().expect("scenario");
    assert_eq!(r["completed"], true, "{name} not completed: {r:#}");
    let targets = r["targets"].as_array().expect("targets");
    for t in targets {
        let miss = t["miss_m"].as_f64().expect("miss_m");
        assert!(miss <= 100.0, "{name}: target missed by {miss} m: {t}");
    }
    let fe = r["final_error_m"].as_f64().expect("final_error_m");
    assert!(fe <= 100.0, "{name}: final/rendezvous error {fe} m");
    if !name.contains("unavoidable") {
        let f = r["min_f_static"].as_f64().expect("min_f_static");
        assert!(f >= 1.0, "{name}: inside a static threat, min F = {f}");
    }
    assert!(
        r["holds"].as_array().expect("holds").is_empty(),
        "{name}: safe holds {}",
        r["holds"]
    );
    let plans = plans(r);
    assert_eq!(
        plans.first().map(|p| p.trigger.as_str()),
        Some("Initial"),
        "{name}"
    );
    // The harness publishes at the documented rates: the planner read every input.
    if let Some(lost) = r["planner"]["messages_lost"].as_u64() {
        assert_eq!(lost, 0, "{name}: inputs lost before the planner read them");
    }
}

/// Every scheduled re-plan time `t_r` is followed: the plan after one that scheduled
/// `t_r` is either a `ScheduledReplan` committing at `t_r`, or a plan triggered before
/// `t_r` by something else (which replaced the schedule). A `t_r` of the last plan must
/// lie after the end of the flight. Returns how many `t_r` re-plans there were.
pub fn assert_every_tr_followed(r: &Value) -> usize {
    let name = r["scenario"].as_str().unwrap_or("?");
    let end = r["end_s"].as_f64().expect("end_s");
    let plans = plans(r);
    let mut followed = 0;
    for (i, p) in plans.iter().enumerate() {
        let Some(tr) = p.next_replan_s else { continue };
        match plans.get(i + 1) {
            Some(n) if n.trigger == "ScheduledReplan" => {
                assert!(
                    (n.start_s - tr).abs() < 0.5,
                    "{name}: t_r {tr} s of plan {i} re-planned for {} s: {plans:?}",
                    n.start_s
                );
                followed += 1;
            }
            Some(n) => assert!(
                n.at_s <= tr + 1e-6,
                "{name}: t_r {tr} s of plan {i} missed: next plan {n:?}"
            ),
            None => assert!(
                tr >= end,
                "{name}: t_r {tr} s of the last plan missed (flight ended at {end} s): {plans:?}"
            ),
        }
    }
    for (i, p) in plans.iter().enumerate().skip(1) {
        if p.trigger == "ScheduledReplan" {
            assert!(
                plans[i - 1].next_replan_s.is_some(),
                "{name}: a ScheduledReplan no plan scheduled: {plans:?}"
            );
        }
    }
    followed
}

/// Every `Refine` plan follows a plan short of `Optimal` that was not a refinement itself;
/// returns how many there are.
pub fn assert_every_refine_follows_a_short_plan(r: &Value) -> usize {
    let plans = r["plans"].as_array().expect("plans");
    let mut refines = 0;
    for (k, p) in plans.iter().enumerate() {
        if p["trigger"] != "Refine" {
            continue;
        }
        refines += 1;
        let before = k.checked_sub(1).map(|j| &plans[j]);
        assert!(
            before.is_some_and(|b| b["quality"] != "Optimal" && b["trigger"] != "Refine"),
            "a Refine plan after {before:?}"
        );
    }
    refines
}

/// `3d-replan-popups` (issue 7): the take-off plan, a re-plan for the moving pop-up at
/// 60 s, the `t_r` re-plans its estimate schedules, a re-plan for the lead's new route at
/// 450 s, and nothing else — in particular none for the far pop-up at 300 s — then the
/// rendezvous on the new route.
pub fn assert_replan_popups(r: &Value) {
    assert_eq!(r["scenario"], "3d-replan-popups");
    let plans = plans(r);
    let near = |t: f64, at: f64| (t - at).abs() < 0.5;
    let count = |k: &str, at: f64| {
        plans
            .iter()
            .filter(|p| p.trigger == k && near(p.at_s, at))
            .count()
    };
    assert_eq!(
        count("PopUp", 60.0),
        1,
        "one PopUp re-plan at 60 s: {plans:?}"
    );
    assert_eq!(
        count("LeadRoute", 450.0),
        1,
        "one LeadRoute re-plan at 450 s: {plans:?}"
    );
    assert!(
        !plans.iter().any(|p| (299.5..310.0).contains(&p.at_s)),
        "a re-plan for the far pop-up at 300 s: {plans:?}"
    );
    let trs = assert_every_tr_followed(r);
    assert!(
        trs >= 1,
        "no t_r re-plan after the moving pop-up: {plans:?}"
    );
    // Nothing else: every plan is the take-off plan, the two events, a t_r, or the
    // refinement of a plan short of optimal (which follows it at once).
    let refines = assert_every_refine_follows_a_short_plan(r);
    assert_eq!(
        plans.len(),
        3 + trs + refines,
        "unexplained re-plans: {plans:?}"
    );
    assert!(
        r["planner"]["popups_clear"].as_u64().expect("popups_clear") >= 1,
        "the far pop-up was not assessed clear"
    );
    assert!(
        r["end_s"].as_f64().expect("end_s") > 450.0,
        "rendezvous on the new route"
    );
}
