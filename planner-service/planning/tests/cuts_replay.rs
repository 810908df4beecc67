//! Deadline cuts (`wingman_planning::cuts`): a plan that a short deadline cut, planned
//! again with no deadline but its recorded cuts, is the same plan byte for byte — cold
//! plans and warm re-plans, in 2-D and 3-D — and the replay takes exactly the recorded
//! cuts. The cuts themselves depend on the machine's speed (this test does not pin them);
//! what it checks is that they are all the plan depends on besides its inputs.

use std::time::Duration;

use wingman_interfaces::Quality;
use wingman_planning::clock::Deadline;
use wingman_planning::cuts::{Cut, CutLog, Part, Site, Work};
use wingman_planning::hybrid::{FlyingPlan, PlanOutcome, Planner, PlannerSettings};
use wingman_planning::problem::{Problem, Threats};
use wingman_planning::threat::Superquadric;

mod common;
use common::{clock, planned};

/// Plans `p` under `budget` recording its cuts, then with no deadline replaying them:
/// (the plan cut, the replay, the cuts recorded, the cuts the replay took).
fn cut_and_replayed(
    p: &Problem,
    flying: Option<&FlyingPlan>,
    budget: Duration,
) -> (PlanOutcome, PlanOutcome, Vec<Cut>, Vec<Cut>) {
    let log: &'static CutLog = Box::leak(Box::new(CutLog::new()));
    log.begin(None);
    let cut = plan_static(p, flying, Deadline::after(clock(), budget).with_cuts(log));
    let recorded = log.finish();
    log.begin(Some(&recorded));
    let replayed = plan_static(p, flying, Deadline::never(clock()).with_cuts(log));
    let taken = log.finish();
    (cut, replayed, recorded, taken)
}

/// Plans `p` (re-plans it from `flying` if given) with a fresh planner under `deadline`.
fn plan_static(
    p: &Problem,
    flying: Option<&FlyingPlan>,
    deadline: Deadline<'static>,
) -> PlanOutcome {
    let settings = PlannerSettings::default();
    let mut planner = Planner::new(&settings);
    match flying {
        Some(f) => planner.replan(p, &settings, deadline, f),
        None => planner.plan(p, &settings, deadline),
    }
    .expect("a plan")
}

fn assert_same_plan(name: &str, a: &PlanOutcome, b: &PlanOutcome, recorded: &[Cut], taken: &[Cut]) {
    assert!(
        !recorded.is_empty(),
        "{name}: the short deadline cut nothing (the test would prove nothing)"
    );
    assert_eq!(taken, recorded, "{name}: the replay took other cuts");
    assert_eq!(a.quality, b.quality, "{name}");
    assert_eq!(a.path, b.path, "{name}");
    assert_eq!(a.cost.to_bits(), b.cost.to_bits(), "{name}");
    assert_eq!(a.trajectory, b.trajectory, "{name}: {recorded:?}");
}

#[test]
fn a_cold_plan_cut_short_replays_byte_for_byte() {
    for (name, budget_ms) in [
        ("2d-min-time-avoidable", 30),
        ("3d-fixed-time-avoidable", 120),
    ] {
        let (p, _) = planned(name);
        let (a, b, recorded, taken) = cut_and_replayed(&p, None, Duration::from_millis(budget_ms));
        assert_same_plan(name, &a, &b, &recorded, &taken);
    }
}

/// A take-off plan whose budget ends in its waves (`hybrid::waves`: the global search
/// done, a wave not started or cut) replays byte for byte. Which budget ends there depends
/// on the machine's speed: the shortest of a rising scale whose cuts include a wave's.
#[test]
fn a_take_off_plan_cut_in_its_waves_replays_byte_for_byte() {
    let name = "2d-min-time-avoidable";
    let (p, _) = planned(name);
    let in_a_wave = |c: &Cut| matches!(c.site.part, Part::Wave(_));
    let mut seen = Vec::new();
    for budget_ms in [80, 120, 160, 240, 320, 480] {
        let (a, b, recorded, taken) = cut_and_replayed(&p, None, Duration::from_millis(budget_ms));
        if recorded.iter().any(in_a_wave) {
            assert_same_plan(name, &a, &b, &recorded, &taken);
            return;
        }
        seen.push((budget_ms, recorded));
    }
    panic!("{name}: no budget ended in a wave: {seen:?}");
}

#[test]
fn a_warm_re_plan_cut_short_replays_byte_for_byte() {
    for (name, budget_ms) in [
        ("2d-min-time-avoidable", 15),
        ("3d-fixed-time-avoidable", 60),
    ] {
        let (take_off, path) = planned(name);
        let flying = FlyingPlan::new(&take_off, path);
        let p = popup_ahead(&take_off, &flying);
        let budget = Duration::from_millis(budget_ms);
        let (a, b, recorded, taken) = cut_and_replayed(&p, Some(&flying), budget);
        assert!(
            a.warm.is_some(),
            "{name}: the re-plan continues the plan in flight"
        );
        assert_same_plan(name, &a, &b, &recorded, &taken);
    }
}

/// A refinement round the deadline stops short of converging leaves the `Optimal` plan of
/// the mesh before it, not the round's unconverged iterate (a 2-D re-plan flew such an
/// iterate through a threat). The winner's round is cut at each of its iterations in turn
/// by a replayed cut (the course a deadline there takes): the plan stays `Optimal`, its
/// cost within 1 % of the uncut plan's (the mesh before the round against the refined
/// one). Kept the cut iterate, a `Feasible` plan would lose to a wave's `Optimal` one 8 %
/// dearer (this scenario, cut at the round's last iteration).
#[test]
fn a_refinement_round_cut_short_keeps_the_optimal_plan_before_it() {
    let name = "2d-min-time-unavoidable";
    let (p, _) = planned(name);
    let uncut = plan_static(&p, None, Deadline::never(clock()));
    assert_eq!(uncut.quality, Quality::Optimal, "{name}");
    let log: &'static CutLog = Box::leak(Box::new(CutLog::new()));
    let mut rounds_cut = 0;
    for candidate in 0..PlannerSettings::default().finalists as u8 {
        let site = Site {
            part: Part::Global,
            work: Work::Round {
                candidate,
                round: 0,
            },
        };
        // Each iteration of the round, until the round ends before the cut.
        for step in 1.. {
            let cut = [Cut { site, step }];
            log.begin(Some(&cut));
            let plan = plan_static(&p, None, Deadline::never(clock()).with_cuts(log));
            if log.finish().is_empty() {
                break; // the round ended before, or never ran (not the winner)
            }
            rounds_cut += 1;
            assert_eq!(plan.quality, Quality::Optimal, "{cut:?}");
            let gap = (plan.cost - uncut.cost).abs() / uncut.cost.abs();
            assert!(gap < 0.01, "{cut:?}: {} against {}", plan.cost, uncut.cost);
        }
    }
    assert!(
        rounds_cut >= 3,
        "the winner's round was cut {rounds_cut} times"
    );
}

/// The re-plan problem at 20 % of `flying` with a pop-up on its path ahead (the warm path
/// ranks its bends, and seeds in 2-D).
fn popup_ahead(take_off: &Problem, flying: &FlyingPlan) -> Problem {
    let tf = flying.path.final_time().unwrap();
    let mut p = take_off.clone();
    p.t0 = take_off.t0 + 0.2 * (tf - take_off.t0);
    p.x0 = flying.path.at(p.t0).unwrap().0;
    let (ahead, _) = flying.path.at(p.t0 + 0.3 * (tf - p.t0)).unwrap();
    match &mut p.threats {
        Threats::Planar { layout, .. } => layout
            .push(Superquadric::ellipsoid([ahead[0], ahead[1]], [4000.0, 4000.0]).unwrap())
            .unwrap(),
        Threats::Spatial { layout, .. } => layout
            .push(
                Superquadric::ellipsoid([ahead[0], ahead[1], ahead[2]], [4000.0, 4000.0, 3000.0])
                    .unwrap(),
            )
            .unwrap(),
    }
    p
}

/// A plan's cuts survive the `Plan` message; more than it holds are marked, and refused.
#[test]
fn cuts_travel_in_the_plan_message_and_an_overflow_is_marked() {
    use wingman_interfaces::{MAX_PLAN_CUTS, Plan, Wire};
    use wingman_planning::plan_message::{TRUNCATED_CUTS, cuts_of, set_cuts};

    let cut = |i: u16, step: u32| Cut {
        site: Site {
            part: Part::Global,
            work: Work::Rank(i),
        },
        step,
    };
    let mut plan = Plan::zeroed();
    let few: Vec<Cut> = (0..3).map(|i| cut(i, 7 + u32::from(i))).collect();
    assert_eq!(set_cuts(&mut plan, &few), 0);
    assert_eq!(cuts_of(&plan), Ok(few));

    let many: Vec<Cut> = (0..MAX_PLAN_CUTS as u16 + 5).map(|i| cut(i, 1)).collect();
    assert_eq!(
        set_cuts(&mut plan, &many),
        6,
        "the last slot marks the overflow"
    );
    assert_eq!(plan.cut_count as usize, MAX_PLAN_CUTS);
    assert_eq!(plan.cuts[MAX_PLAN_CUTS - 1].site, TRUNCATED_CUTS);
    assert_eq!(plan.cuts[MAX_PLAN_CUTS - 1].step, 6);
    assert_eq!(cuts_of(&plan), Err(TRUNCATED_CUTS));
}
