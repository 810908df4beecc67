//! Issue 5's robustness bar: 20 random well-posed scenarios (fixed seed; mixed models and
//! objectives, 1–2 targets, 3–7 threats, avoidable by construction) are each planned and
//! judged by the independent evaluator: final condition within 50 m and 0.5°, every
//! target within 50 m, bounds held, never inside a static threat (min F ≥ 1), and no
//! planner failure or non-finite number.

use wingman_planner::offline::{PlanRequest, plan_scenario};
use wingman_planning::clock::MonotonicClock;
use wingman_planning::scenario::Scenario;
use wingman_testkit::judge::evaluate;
use wingman_testkit::random_scenario::random_scenario;

const FAMILY_SEED: u64 = 20261123;

#[test]
fn twenty_random_scenarios_are_planned_feasibly() {
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    let root = std::env::temp_dir().join(format!("wingman-robust-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let mut failures = Vec::new();
    for i in 0..20 {
        let (name, text) = random_scenario(FAMILY_SEED, i);
        let toml = root.join(format!("{name}.toml"));
        std::fs::write(&toml, &text).unwrap();
        let scenario = Scenario::load(&toml)
            .unwrap_or_else(|e| panic!("generated scenario refused: {e}\n{text}"));
        let request = PlanRequest {
            scenario,
            seed: 1,
            deadline: Some(std::time::Duration::from_secs(60)),
            out_dir: root.join(&name),
            exhaustive_runs: None,
        };
        let outcome = match plan_scenario(&request, clock) {
            Ok(o) => o,
            Err(e) => {
                failures.push(format!("{name}: planner error {e:#}"));
                continue;
            }
        };
        assert!(
            outcome.trajectory.is_valid(),
            "{name}: non-finite or unordered trajectory"
        );
        assert!(outcome.cost.is_finite(), "{name}: non-finite cost");
        let r = evaluate(&toml, &request.out_dir.join("plan.csv"));
        let num = |k: &str| r[k].as_f64().unwrap_or(f64::INFINITY);
        let mut problems = Vec::new();
        if num("final_pos_err_m") > 50.0 {
            problems.push(format!(
                "final position error {:.1} m",
                num("final_pos_err_m")
            ));
        }
        for key in ["final_heading_err_deg", "final_gamma_err_deg"] {
            if r.get(key).is_some() && num(key) > 0.5 {
                problems.push(format!("{key} {:.3}", num(key)));
            }
        }
        for m in r["target_min_dist_m"].as_array().into_iter().flatten() {
            if m.as_f64().unwrap_or(f64::INFINITY) > 50.0 {
                problems.push(format!("target missed by {m} m"));
            }
        }
        for (k, v) in r["bound_violation"].as_object().into_iter().flatten() {
            if v.as_f64().unwrap_or(f64::INFINITY) > 1e-6 {
                problems.push(format!("bound {k} violated by {v}"));
            }
        }
        if num("min_F_static") < 1.0 {
            problems.push(format!(
                "enters a static threat (min F {:.3})",
                num("min_F_static")
            ));
        }
        println!(
            "{name:40} {:?} cost {:.4} final {:.1} m minF {:.3} {:.0} ms",
            outcome.quality,
            num("cost"),
            num("final_pos_err_m"),
            num("min_F_static"),
            outcome.times.total.as_secs_f64() * 1e3
        );
        if !problems.is_empty() {
            failures.push(format!("{name}: {}", problems.join("; ")));
        }
    }
    let _ = std::fs::remove_dir_all(&root);
    assert!(
        failures.is_empty(),
        "judged failures:\n{}",
        failures.join("\n")
    );
}
