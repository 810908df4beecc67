//! `wingman-harness campaign` as a user runs it: a CI-sized campaign of random missions
//! flown end to end on the deployment defaults, judged against the yardstick; the same
//! campaign as four shards merged; a failed mission kept and flown alone again.

use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

use wingman_harness::campaign::outcome::{FlightNumbers, MissionOutcome};
use wingman_harness::campaign::run::{CampaignResults, read_results};
use wingman_harness::campaign::summary::Verdict;
use wingman_testkit::process::{TempDir, harness, report, text};

/// Missions of the CI-sized campaign, and its seed.
const COUNT: usize = 30;
const SEED: &str = "3";

/// The campaigns of this file run one at a time: flights charge their compute time to
/// mission time, so two campaigns side by side on two cores cut each other's plans.
static ALONE: Mutex<()> = Mutex::new(());

/// Runs `wingman-harness campaign <args>`; returns its exit code and its results.
fn campaign(args: &[&str], out: &Path) -> (Option<i32>, CampaignResults) {
    let mut all = vec!["campaign", "--quiet", "--out", out.to_str().unwrap()];
    all.extend_from_slice(args);
    let o = harness(&all).wait(Duration::from_secs(1200));
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "campaign {args:?}: {}",
        text(&o)
    );
    (o.status.code(), read_results(out).unwrap())
}

/// Whether a mission's flight had no deadline cut in any plan: then every plan, hence the
/// flight, is the same on any machine and in any run.
fn cut_free(o: &MissionOutcome) -> bool {
    o.flight
        .as_ref()
        .is_some_and(|f| f.plans.iter().all(|p| p.cuts == 0))
}

/// Whether two flights of a mission are the same flight, compute times aside: the same
/// plans (trigger, quality, path, cost, cuts) and the same outcome. A plan is flown from
/// when it is ready (its trigger plus its compute time, charged to mission time), so the
/// flown path moves by what a few milliseconds of flight make: within 1 m, 1e-3 of F,
/// 1e-6 s of exposure (or 1e-3 of it), 0.1 s of the end.
fn same_flight(a: &FlightNumbers, b: &FlightNumbers) -> bool {
    let near = |x: f64, y: f64, tol: f64| (x - y).abs() <= tol;
    let plans = |f: &FlightNumbers| -> Vec<_> {
        f.plans
            .iter()
            .map(|p| {
                (
                    p.trigger.clone(),
                    p.quality.clone(),
                    p.path.clone(),
                    p.cost,
                    p.cuts,
                )
            })
            .collect()
    };
    let opt = |x: Option<f64>, y: Option<f64>, tol: f64| match (x, y) {
        (Some(x), Some(y)) => near(x, y, tol),
        (x, y) => x.is_none() && y.is_none(),
    };
    plans(a) == plans(b)
        && a.completed == b.completed
        && a.holds == b.holds
        && near(a.end_s, b.end_s, 0.1)
        && a.target_miss_m.len() == b.target_miss_m.len()
        && a.target_miss_m
            .iter()
            .zip(&b.target_miss_m)
            .all(|(x, y)| near(*x, *y, 1.0))
        && near(a.final_error_m, b.final_error_m, 1.0)
        && opt(a.final_time_error_s, b.final_time_error_s, 0.1)
        && opt(a.min_f_static, b.min_f_static, 1e-3)
        && opt(a.min_f_moving, b.min_f_moving, 1e-3)
        && near(a.exposure_s, b.exposure_s, 1e-6f64.max(1e-3 * a.exposure_s))
}

#[test]
fn a_ci_sized_campaign_meets_its_bars_and_four_merged_shards_give_its_outcomes() {
    let _alone = ALONE.lock().unwrap_or_else(|p| p.into_inner());
    let dir = TempDir::new("campaign");
    let whole = dir.path().join("whole");
    let count = COUNT.to_string();
    let base = ["--count", count.as_str(), "--seed", SEED];
    let (code, r) = campaign(&base, &whole);

    // Every mission drawn was flown and judged.
    assert_eq!(r.outcomes.len(), COUNT);
    assert!(r.outcomes.iter().enumerate().all(|(i, o)| o.index == i));
    for o in &r.outcomes {
        assert_eq!(o.error, None, "{}", o.name);
        let y = o.yardstick.as_ref().expect("a yardstick plan");
        assert_eq!(y.cuts, 0, "{}: the yardstick's budget cut it", o.name);
        assert!(o.gap().is_some(), "{}", o.name);
    }
    // What it measures. The yardstick bar (≥ 98 % within 0.5 % of the yardstick)
    // is not met yet (docs/CAMPAIGN.md lists the misses); these are the floors of the
    // planner as it stands, below what this campaign measured on the 2-core machine at
    // half its usual speed (29 and 27 of 30): the take-off budget holds the take-off's
    // work there (docs/decisions/0046), so the gaps do not depend on the machine's speed;
    // a re-plan's cuts still do (c3-0013 meets the criteria in some runs, not others).
    let meeting = r.outcomes.iter().filter(|o| o.meets_criteria()).count();
    let within = r
        .outcomes
        .iter()
        .filter(|o| o.gap().is_some_and(|g| g <= 0.005))
        .count();
    let report_md = std::fs::read_to_string(whole.join("report.md")).unwrap();
    assert!(
        meeting >= 28,
        "{meeting} of {COUNT} meet the criteria\n{report_md}"
    );
    assert!(
        within >= 25,
        "{within} of {COUNT} within 0.5 %\n{report_md}"
    );
    let passes = meeting as f64 >= 0.99 * COUNT as f64 && within as f64 >= 0.98 * COUNT as f64;
    assert_eq!(code, Some(if passes { 0 } else { 1 }), "{report_md}");
    // The report and its charts.
    assert!(report_md.contains(&format!("| {meeting} / {COUNT} (")));
    for png in ["gap_cdf.png", "compute_cdf.png", "errors_cdf.png"] {
        let bytes = std::fs::read(whole.join(png)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG"), "{png}");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(whole.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["meeting_criteria"], meeting);
    assert_eq!(summary["passes"], passes);

    // The same campaign as four shards, merged.
    let mut shards = Vec::new();
    for i in 0..4 {
        let out = dir.path().join(format!("shard-{i}"));
        let shard = format!("{i}/4");
        let mut args = base.to_vec();
        args.extend(["--shard", shard.as_str()]);
        let (code, part) = campaign(&args, &out);
        assert_eq!(code, Some(0), "a shard exits 0 once it ran");
        assert_eq!(part.outcomes.len(), (i..COUNT).step_by(4).count());
        shards.push(out);
    }
    let merged_dir = dir.path().join("merged");
    let mut args = vec!["campaign", "merge", "--out", merged_dir.to_str().unwrap()];
    args.extend(shards.iter().map(|s| s.to_str().unwrap()));
    let o = harness(&args).wait(Duration::from_secs(120));
    let merged = read_results(&merged_dir).unwrap();
    let merged_passes = Verdict::of(&merged).passes();
    assert_eq!(
        o.status.code(),
        Some(if merged_passes { 0 } else { 1 }),
        "{}",
        text(&o)
    );
    assert_eq!(merged.spec, r.spec);
    assert_eq!(merged.outcomes.len(), COUNT);
    // Compute times aside: a flight that no deadline cut in either run is the same flight.
    let mut compared = 0;
    for (a, b) in r.outcomes.iter().zip(&merged.outcomes) {
        assert_eq!((a.index, &a.name, &a.kind), (b.index, &b.name, &b.kind));
        assert_eq!(
            a.yardstick.as_ref().map(|y| y.cost),
            b.yardstick.as_ref().map(|y| y.cost),
            "{}: the yardstick is the same on any machine",
            a.name
        );
        if cut_free(a) && cut_free(b) {
            compared += 1;
            assert_eq!(a.misses, b.misses, "{}", a.name);
            let (fa, fb) = (a.flight.as_ref().unwrap(), b.flight.as_ref().unwrap());
            assert!(same_flight(fa, fb), "{}:\n{fa:?}\n{fb:?}", a.name);
        }
    }
    // Since the waves (decision 0040) the clock gates a take-off's wave: on this 2-core
    // machine 7-12 of the 30 flights carry no cut at all, depending on its speed; with the
    // VM at half speed and 2-D lead changes planned from scratch (decision 0045: a 100 ms
    // plan from scratch is always cut) a clean-clone CI run had 4. At least a tenth are
    // compared. A deterministic wave gate (docs/CAMPAIGN.md, left to do) would compare more.
    assert!(
        compared >= COUNT / 10,
        "only {compared} flights without a deadline cut"
    );
    // Merging a shard twice is refused.
    let again = harness(&[
        "campaign",
        "merge",
        "--out",
        dir.path().join("twice").to_str().unwrap(),
        shards[0].to_str().unwrap(),
        shards[0].to_str().unwrap(),
    ])
    .wait(Duration::from_secs(60));
    assert_eq!(again.status.code(), Some(2), "{}", text(&again));
    assert!(text(&again).contains("already merged"));
}

#[test]
fn a_failed_mission_is_kept_and_flown_alone_fails_the_same_way() {
    // A planner that re-plans for a pop-up only when it lies on the plan's very centre
    // line (f_star 1e-6): pop-ups across the plan are flown into. (Pop-ups are drawn on
    // the route, not on the plan: of seed 4's first 8 missions, 2 plans cross one.)
    let _alone = ALONE.lock().unwrap_or_else(|p| p.into_inner());
    let dir = TempDir::new("campaign-failed");
    let config = dir.path().join("blind.toml");
    std::fs::write(&config, "[triggers]\nf_star = 1e-6\n").unwrap();
    let out = dir.path().join("c");
    let (code, r) = campaign(
        &[
            "--count",
            "8",
            "--seed",
            "4",
            "--with",
            "popups",
            "--without",
            "unavoidable",
            "--no-yardstick",
            "--planner-config",
            config.to_str().unwrap(),
        ],
        &out,
    );
    let failed: Vec<&MissionOutcome> = r.outcomes.iter().filter(|o| !o.meets_criteria()).collect();
    assert!(!failed.is_empty(), "no pop-up was flown into: {r:?}");
    assert_eq!(code, Some(1), "a campaign under its bar exits 1");
    for o in &r.outcomes {
        // Only the failed missions keep their folders.
        assert_eq!(o.kept.is_some(), !o.meets_criteria(), "{}", o.name);
    }
    // A flight no deadline cut if there is one: flown alone, it must be the same flight.
    let f = failed.iter().find(|o| cut_free(o)).unwrap_or(&failed[0]);
    assert!(
        f.misses
            .iter()
            .any(|m| m.contains("entered a static threat")),
        "{f:?}"
    );
    let kept = out.join(f.kept.as_ref().unwrap());
    let again = dir.path().join("again");
    let o = harness(&[
        "fly",
        kept.join(format!("{}.toml", f.name)).to_str().unwrap(),
        "--planner-config",
        kept.join("planner.toml").to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
        "--quiet",
    ])
    .wait(Duration::from_secs(300));
    assert!(o.status.success(), "{}", text(&o));
    // The same failure; with no deadline cut in either flight, the same flight.
    let rep = report(&again);
    let min_f = rep["min_f_static"].as_f64().unwrap();
    assert!(min_f < 1.0, "flown alone, it keeps out (min F {min_f})");
    let flown = f.flight.as_ref().unwrap();
    let cuts_alone: u64 = rep["plans"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["cuts"].as_u64().unwrap())
        .sum();
    if cut_free(f) && cuts_alone == 0 {
        assert!((min_f - flown.min_f_static.unwrap()).abs() <= 1e-3);
        assert_eq!(rep["plans"].as_array().unwrap().len(), flown.plans.len());
    }
}

/// The independent solver (`tools/yardstick/ipopt_multistart.py`: CasADi + IPOPT on a
/// transcription of its own, judged by the customer's judge) on the take-offs of a small
/// campaign: on each, some of its starts (its straight path, the default plan and the
/// yardstick's) converge, and finds no basin better than the yardstick's by more than the gap
/// tolerance (0.5 %, or 1e-4 on costs below 0.02). Mission 1 of seed 3 is one whose
/// default take-off plan is 1.6 % above the yardstick's: the independent solver confirms
/// the yardstick's basin (measured 68.7634 against 68.7684). A missing script is refused
/// up front.
#[test]
fn the_independent_solver_finds_nothing_better_than_the_yardstick() {
    let _alone = ALONE.lock().unwrap_or_else(|p| p.into_inner());
    let dir = TempDir::new("campaign-independent");
    let script = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tools/yardstick/ipopt_multistart.py")
        .canonicalize()
        .unwrap();
    let out = dir.path().join("c");
    let (_, r) = campaign(
        &[
            "--count",
            "2",
            "--seed",
            SEED,
            "--independent-every",
            "1",
            "--independent-solver",
            script.to_str().unwrap(),
            // Its straight start besides the default's and the yardstick's (its bulged
            // ones double its time: about 40 s per start on these missions).
            "--independent-arg=--bulges=0",
        ],
        &out,
    );
    let report_md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report_md.contains("## The independent solver"),
        "{report_md}"
    );
    for o in &r.outcomes {
        let i = o
            .independent
            .as_ref()
            .unwrap_or_else(|| panic!("{}: {:?}", o.name, o.independent_error));
        assert!(i.converged >= 1 && i.cost.is_finite(), "{}: {i:?}", o.name);
        let g = o.yardstick_vs_independent().unwrap();
        assert!(
            g <= 0.005,
            "{}: the independent solver beat the yardstick by {:.3} % ({} from {})\n{report_md}",
            o.name,
            100.0 * g,
            i.cost,
            i.start
        );
        // Its starts were written beside the kept scenario.
        if let Some(kept) = &o.kept {
            assert!(out.join(kept).join("default_plan.json").is_file());
        }
    }
    // A campaign asked to run a solver that is not there stops before it flies.
    let o = harness(&[
        "campaign",
        "--count",
        "1",
        "--independent-every",
        "1",
        "--independent-solver",
        "/nonexistent/solver.py",
        "--out",
        dir.path().join("none").to_str().unwrap(),
    ])
    .wait(Duration::from_secs(60));
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("--independent-solver"), "{}", text(&o));
}
