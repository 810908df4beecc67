//! The service's decisions as pure functions (`service::triggers`,
//! `wingman_planning::plan_message`, `wingman_ipc::config`): each trigger fires on the case that should fire it and not on the
//! near miss beside it.
//!
//! Geometry of the pop-up and `t_r` cases: the plan flies east along `y = 0` at 200 m/s,
//! `x = 200 t`, sampled every second for 100 s; it passes `x = 10 km` at `t = 50 s`.

use std::time::Duration;

use wingman_interfaces::*;
use wingman_ipc::ServiceConfig;
use wingman_ipc::config::{ConfigError, TriggerConfig};
use wingman_planner::service::triggers::*;
use wingman_planning::estimation::{Estimate, GaussMarkov, MovingThreat, Road};
use wingman_planning::plan_message::{
    PlanInfo, sample_times, set_next_replan, state_at, write_plan,
};
use wingman_planning::replan::PlanPoint;
use wingman_planning::threat::Superquadric;
use wingman_planning::trajectory::Trajectory;

fn plan() -> Vec<PlanPoint<2>> {
    (0..=100)
        .map(|k| {
            let t = k as f64;
            PlanPoint {
                t,
                position: [200.0 * t, 0.0],
                velocity: [200.0, 0.0],
            }
        })
        .collect()
}

fn circle(center: [f64; 2], r: f64) -> Superquadric<2> {
    Superquadric::ellipsoid(center, [r, r]).unwrap()
}

#[test]
fn a_static_popup_touching_the_plan_fires_and_one_1km_clear_does_not() {
    let p = plan();
    // Radius 2 km, centre 1.9 km from the track: it reaches the plan.
    let hit = static_popup(&p, &circle([10000.0, 1900.0], 2000.0), 1.0);
    match hit {
        PopupAssessment::Touches(h) => {
            assert!(h.f < 1.0 && (40.0..=60.0).contains(&h.t), "{h:?}")
        }
        PopupAssessment::Clear => panic!("a threat over the track must re-plan"),
    }
    // Centre 3 km from the track: its boundary passes 1 km clear of the plan.
    let near_miss = circle([10000.0, 3000.0], 2000.0);
    assert_eq!(static_popup(&p, &near_miss, 1.0), PopupAssessment::Clear);
    // F* from the configuration widens the test: F = (3/2)^2 = 2.25 on the track.
    assert!(static_popup(&p, &near_miss, 2.3).touches());
    assert_eq!(static_popup(&p, &near_miss, 2.2), PopupAssessment::Clear);
}

#[test]
fn a_popup_on_the_part_already_flown_does_not_fire() {
    let p = plan();
    // Over the track at x = 2 km, which the plan passes at t = 10 s.
    let behind = circle([2000.0, 0.0], 1000.0);
    assert!(static_popup(remaining(&p, 0.0), &behind, 1.0).touches());
    assert_eq!(
        static_popup(remaining(&p, 30.0), &behind, 1.0),
        PopupAssessment::Clear
    );
    assert_eq!(remaining(&p, 30.0)[0].t, 30.0);
    assert_eq!(remaining(&p, 29.5)[0].t, 30.0);
    assert!(remaining(&p, 101.0).is_empty());
}

/// A threat driving north at 20 m/s on the road `x = 10 km`, certain position (sigma_d =
/// 1 m, no process noise), keep-out semi-axes 1 km; at `t = 50 s` its centre is
/// `y_at_50` (0: on the plan when the plan passes).
fn northbound(y_at_50: f64) -> MovingThreat<2> {
    let road = Road::new(&[[10000.0, -20000.0], [10000.0, 20000.0]]).unwrap();
    let d0 = 20000.0 + y_at_50 - 20.0 * 50.0;
    let est = Estimate::with_sigmas(0.0, [d0, 20.0, 0.0], [1.0, 0.0, 0.0]).unwrap();
    MovingThreat::new(
        road,
        [1000.0, 1000.0],
        GaussMarkov::new(60.0, 0.0).unwrap(),
        est,
    )
    .unwrap()
}

#[test]
fn a_moving_popup_fires_at_its_propagated_region_and_not_when_it_arrives_late() {
    let p = plan();
    // Crossing the track when the plan passes: the propagated region reaches it.
    match moving_popup(&p, &northbound(0.0), 1.0) {
        PopupAssessment::Touches(h) => assert!((45.0..=55.0).contains(&h.t), "{h:?}"),
        PopupAssessment::Clear => panic!("a threat crossing the plan must re-plan"),
    }
    // The same threat 1.5 km further back: its region (1 km) misses the plan by ~0.5 km
    // at every sample's time, although its road crosses the track.
    assert_eq!(
        moving_popup(&p, &northbound(-1500.0), 1.0),
        PopupAssessment::Clear
    );
    // Tested at the region's time: the late threat reaches y = 0 at t = 125 s, after the
    // plan has left (a static test at that place would fire).
    let late = northbound(-1500.0);
    let c = *late.region_at(125.0).shape.center();
    assert!(c[1].abs() < 1e-6);
}

#[test]
fn t_r_is_scheduled_for_a_threat_coming_close_and_not_for_one_staying_clear() {
    let p = plan();
    let r = scheduled_replan(&p, &northbound(0.0), 0.0).expect("t_r");
    assert!(r.t <= 50.0, "t_r no later than the crossing: {r:?}");
    assert!(r.h <= r.rho);
    // Looked for only after `not_before`.
    let later = scheduled_replan(&p, &northbound(0.0), r.t + 0.5).expect("t_r");
    assert!(later.t > r.t);
    // 1.5 km back: H stays near 1.5 km, above rho ~ 1 km + sigma_d: no t_r.
    assert!(scheduled_replan(&p, &northbound(-1500.0), 0.0).is_none());
    // Acted on one budget early, so the new plan commits at t_r.
    let (t_r, lead) = (r.t, 0.15);
    assert!(scheduled_due(t_r - lead, t_r, lead));
    assert!(!scheduled_due(t_r - lead - 0.01, t_r, lead));
}

fn tasking(revision: u32) -> Tasking {
    let mut t = Tasking::zeroed();
    t.revision = revision;
    t.model = Model::TwoD.to_wire();
    t.objective = Objective::MinTime.to_wire();
    t.limits.speed_mps = 200.0;
    t.limits.turn_rate_max_rps = 0.1;
    t.weights = Weights {
        alpha: 0.05,
        beta: 0.95,
        stiffness: 30.0,
    };
    t.start_time_s = 10.0;
    t.final_state = [80000.0, 10000.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    t.target_count = 1;
    t.targets_m[0] = [30000.0, 40000.0, 0.0];
    t
}

#[test]
fn a_tasking_change_fires_only_with_a_larger_revision_and_new_content() {
    let held = tasking(2);
    assert_eq!(tasking_decision(None, &held), TaskingDecision::First);
    let mut moved = tasking(3);
    moved.targets_m[0][0] += 1.0;
    assert_eq!(
        tasking_decision(Some(&held), &moved),
        TaskingDecision::Changed
    );
    let mut new_final = tasking(3);
    new_final.final_state[1] = 0.0;
    assert_eq!(
        tasking_decision(Some(&held), &new_final),
        TaskingDecision::Changed
    );
    // Near misses: new content without a larger revision, a larger revision without new
    // content (the header and start may differ: they are not the task).
    let mut same_revision = moved;
    same_revision.revision = 2;
    assert_eq!(
        tasking_decision(Some(&held), &same_revision),
        TaskingDecision::Stale
    );
    let mut repeat = tasking(3);
    repeat.header.sequence = 99;
    assert_eq!(
        tasking_decision(Some(&held), &repeat),
        TaskingDecision::Unchanged
    );
    assert_eq!(
        tasking_decision(Some(&held), &tasking(1)),
        TaskingDecision::Stale
    );
}

fn route(revision: u32, x_end: f64) -> LeadRoute {
    let mut r = LeadRoute::zeroed();
    r.revision = revision;
    r.point_count = 2;
    r.speed_mps = 150.0;
    r.points_m[1] = [x_end, 0.0, 0.0];
    r
}

#[test]
fn a_lead_route_change_fires_only_with_a_larger_revision_and_another_route() {
    let held = route(1, 50000.0);
    assert_eq!(route_decision(None, &held), RouteDecision::First);
    assert_eq!(
        route_decision(Some(&held), &route(2, 50001.0)),
        RouteDecision::Changed
    );
    assert_eq!(
        route_decision(Some(&held), &route(2, 50000.0)),
        RouteDecision::Unchanged
    );
    assert_eq!(
        route_decision(Some(&held), &route(1, 60000.0)),
        RouteDecision::Stale
    );
}

/// The lead on `route(1, 200 km)` (east at 150 m/s from the origin at t = 0) observed at
/// t = 100 s at `position`, heading `heading_deg`, at `speed`.
fn observed(position: [f64; 3], heading_deg: f64, speed: f64) -> LeadState {
    let mut s = LeadState::zeroed();
    s.time_s = 100.0;
    s.position_m = position;
    s.heading_rad = heading_deg.to_radians();
    s.speed_mps = speed;
    s.route_revision = 1;
    s
}

/// Meeting at t = 500 s (400 s ahead): a lead on its route is 0 m off; one 2 degrees off
/// its heading drifts 150 * 400 * 2 sin(1 deg) = 2 094 m by then (bound 1 000 m: fires),
/// 0.5 degree drifts 524 m (does not); 3 m/s faster drifts 1 200 m (fires), 2 m/s 800 m
/// (does not); 1.1 km aside now fires at once. Checked against that geometry to 1e-6 m.
#[test]
fn a_lead_off_its_route_fires_beyond_the_bound_at_the_meeting_time() {
    let r = route(1, 200000.0);
    let path = wingman_planning::lead::LeadPath::new(r.points(), r.speed_mps, 0.0).unwrap();
    let off = |s: &LeadState| lead_off_route_m(&path, s, 500.0);
    let bound = ServiceConfig::default().triggers.lead_off_route_m;
    assert_eq!(bound, 1000.0);
    let on = [15000.0, 0.0, 0.0];
    assert!(off(&observed(on, 0.0, 150.0)).abs() < 1e-6);
    for (heading, speed, expected) in [
        (2.0, 150.0, 150.0 * 400.0 * 2.0 * 1.0f64.to_radians().sin()),
        (0.5, 150.0, 150.0 * 400.0 * 2.0 * 0.25f64.to_radians().sin()),
        (0.0, 153.0, 1200.0),
        (0.0, 152.0, 800.0),
    ] {
        let d = off(&observed(on, heading, speed));
        assert!(
            (d - expected).abs() < 1e-6,
            "{heading} deg, {speed} m/s: {d} against {expected}"
        );
        assert_eq!(d > bound, expected > bound);
    }
    assert!(off(&observed([15000.0, 1100.0, 0.0], 0.0, 150.0)) > bound);
    // Met already: only where it is counts.
    assert!(lead_off_route_m(&path, &observed(on, 30.0, 150.0), 90.0).abs() < 1e-6);
    // The re-plan meets the lead as observed: that route puts it where it is, going on
    // as it goes, so the same state is on it.
    let s = observed([15000.0, 300.0, 0.0], 20.0, 160.0);
    let o = observed_route(&s, 1, Model::TwoD);
    assert_eq!((o.revision, o.start_time_s, o.speed_mps), (1, 100.0, 160.0));
    let flown =
        wingman_planning::lead::LeadPath::new(o.points(), o.speed_mps, o.start_time_s).unwrap();
    let d = lead_off_route_m(&flown, &s, 500.0);
    assert!(d < 1e-6, "{d}");
}

fn ownship(plan_id: u64, cross: f64, vertical: f64) -> OwnshipState {
    let mut o = OwnshipState::zeroed();
    o.plan_id = plan_id;
    o.cross_track_m = cross;
    o.vertical_m = vertical;
    o
}

#[test]
fn a_deviation_fires_beyond_the_bound_on_the_plan_flown() {
    let b = DeviationBounds {
        cross_m: 500.0,
        vertical_m: 200.0,
        along_m: 300.0,
    };
    assert!(deviation_exceeded(&ownship(7, -500.5, 0.0), 7, &b));
    assert!(deviation_exceeded(&ownship(7, 0.0, 200.5), 7, &b));
    assert!(!deviation_exceeded(&ownship(7, 499.5, -199.5), 7, &b));
    let mut behind = ownship(7, 0.0, 0.0);
    behind.along_track_m = -300.5;
    assert!(deviation_exceeded(&behind, 7, &b));
    behind.along_track_m = 299.5;
    assert!(!deviation_exceeded(&behind, 7, &b));
    // Reported against an older plan (the tracker has not switched yet): not ours.
    assert!(!deviation_exceeded(&ownship(6, 900.0, 0.0), 7, &b));
    // Flying a safe hold: that is the expiry trigger's case.
    let mut hold = ownship(7, 900.0, 0.0);
    hold.flags = OWNSHIP_HOLDING;
    assert!(!deviation_exceeded(&hold, 7, &b));
}

#[test]
fn the_along_track_bound_tightens_near_the_end_of_a_free_final_time() {
    let cfg = TriggerConfig::default();
    let (along, end) = (cfg.deviation_along_m, cfg.deviation_along_end_m);
    assert!(end < along, "the defaults tighten it: {end} < {along}");
    let window = cfg.deviation_end_window_s;
    let at = |fixed, now| DeviationBounds::at(&cfg, fixed, now, 1000.0).along_m;
    // A min-time or rendezvous plan: the end bound from `window` before its end on.
    assert_eq!(at(false, 1000.0 - window - 0.1), along);
    assert_eq!(at(false, 1000.0 - window), end);
    assert_eq!(at(false, 1005.0), end);
    // A fixed final time keeps the plan's bound to the end.
    assert_eq!(at(true, 999.0), along);
    // The other bounds do not change.
    let b = DeviationBounds::at(&cfg, false, 999.0, 1000.0);
    assert_eq!(
        (b.cross_m, b.vertical_m),
        (cfg.deviation_cross_m, cfg.deviation_vertical_m)
    );
    // An end bound set above the plan's bound does not loosen it.
    let loose = TriggerConfig {
        deviation_along_end_m: 2.0 * along,
        ..cfg.clone()
    };
    assert_eq!(
        DeviationBounds::at(&loose, false, 999.0, 1000.0).along_m,
        along
    );
}

#[test]
fn expiry_fires_before_a_cut_short_plan_ends_and_not_at_the_missions_end() {
    let cut = PlanWindow {
        start_s: 0.0,
        valid_until_s: 100.0,
        final_time_s: 200.0,
    };
    assert!(expiry_due(99.85, &cut, 0.15, false));
    assert!(!expiry_due(99.8, &cut, 0.15, false));
    let whole = PlanWindow {
        valid_until_s: 200.0,
        ..cut
    };
    assert!(!expiry_due(199.9, &whole, 0.15, false));
    assert!(
        !expiry_due(300.0, &whole, 0.15, false),
        "the mission is over"
    );
    // The tracker flying a safe hold before the plan's end: re-plan now.
    assert!(expiry_due(50.0, &whole, 0.15, true));
    assert!(!expiry_due(300.0, &whole, 0.15, true));
}

#[test]
fn a_hold_counts_against_the_plan_it_replaced_and_a_plan_the_tracker_did_not_take() {
    let mut o = ownship(3, 0.0, 0.0);
    o.time_s = 604.8;
    o.flags |= OWNSHIP_HOLDING;
    // The tracker holds after flying plan 3, or past plan 4's start without taking it.
    assert!(holds_instead_of(&o, 3, 0.0));
    assert!(holds_instead_of(&o, 4, 604.8));
    // Near misses: plan 4 starts after the hold was reported (it answers the hold); the
    // tracker flies its plan (no hold).
    assert!(!holds_instead_of(&o, 4, 605.1));
    o.flags &= !OWNSHIP_HOLDING;
    assert!(!holds_instead_of(&o, 3, 0.0));
}

#[test]
fn the_first_plan_is_a_restart_when_the_mission_is_under_way() {
    let t = tasking(1);
    assert_eq!(first_plan_trigger(&t, None), Trigger::Initial);
    let mut o = ownship(0, 0.0, 0.0);
    o.time_s = 10.0;
    assert_eq!(first_plan_trigger(&t, Some(&o)), Trigger::Initial);
    o.time_s = 10.5;
    assert_eq!(first_plan_trigger(&t, Some(&o)), Trigger::Restart);
    let flying = ownship(4, 0.0, 0.0);
    assert_eq!(first_plan_trigger(&t, Some(&flying)), Trigger::Restart);
}

#[test]
fn pending_triggers_name_the_plan_by_priority() {
    let mut s = TriggerSet::default();
    assert!(s.is_empty() && s.primary().is_none());
    s.insert(Trigger::PopUp);
    assert!(s.only_popups());
    s.insert(Trigger::ScheduledReplan);
    assert!(!s.only_popups());
    assert_eq!(s.primary(), Some(Trigger::PopUp));
    s.insert(Trigger::LeadOffRoute);
    assert_eq!(s.primary(), Some(Trigger::LeadOffRoute));
    s.insert(Trigger::Tasking);
    assert_eq!(s.primary(), Some(Trigger::Tasking));
    assert!(s.contains(Trigger::ScheduledReplan) && !s.contains(Trigger::Expiry));
}

#[test]
fn a_plan_short_of_optimal_or_into_a_new_threat_is_refined_once_with_its_own_budget() {
    // Fires: every quality short of `Optimal`, whatever re-plan made it.
    for q in [Quality::Feasible, Quality::SwarmOnly, Quality::Degraded] {
        for t in [
            Trigger::Initial,
            Trigger::PopUp,
            Trigger::LeadRoute,
            Trigger::Expiry,
        ] {
            assert!(refine_due(true, q, t, false), "{q:?} after {t:?}");
        }
    }
    // Fires too: an optimal plan that enters a threat the plan before it kept clear of.
    for t in [Trigger::LeadRoute, Trigger::ScheduledReplan, Trigger::PopUp] {
        assert!(refine_due(true, Quality::Optimal, t, true), "{t:?}");
    }
    // Near misses: an optimal plan clear of new threats, a refinement's own plan (short
    // or into a new threat), the setting off.
    assert!(!refine_due(true, Quality::Optimal, Trigger::PopUp, false));
    assert!(!refine_due(
        true,
        Quality::SwarmOnly,
        Trigger::Refine,
        false
    ));
    assert!(!refine_due(true, Quality::Optimal, Trigger::Refine, true));
    assert!(!refine_due(
        false,
        Quality::SwarmOnly,
        Trigger::PopUp,
        false
    ));
    assert!(!refine_due(false, Quality::Optimal, Trigger::PopUp, true));
    // Its budget is the refinement's only while nothing else is pending.
    let mut s = TriggerSet::default();
    assert!(!refine_only(s));
    s.insert(Trigger::Refine);
    assert!(refine_only(s) && !from_scratch(s));
    assert_eq!(s.primary(), Some(Trigger::Refine));
    s.insert(Trigger::PopUp);
    assert!(!refine_only(s));
    assert_eq!(s.primary(), Some(Trigger::PopUp));
}

/// A trajectory of `n` samples over `[0, 1000]` s with phase ends at 333.3, 700 and 1000.
fn dense(n: usize) -> Trajectory {
    let mut tr = Trajectory::default();
    for k in 0..n {
        let t = 1000.0 * k as f64 / (n - 1) as f64;
        tr.push(
            t,
            [200.0 * t, 5.0 * t, 0.1 * t, 0.0, 0.0, 0.0, 0.0],
            [0.1, 0.0],
        );
    }
    tr.phase_ends = vec![333.3, 700.0, 1000.0];
    tr
}

#[test]
fn sample_times_keep_the_ends_and_the_phase_ends_within_capacity() {
    let tr = dense(10_000);
    let mut out = Vec::new();
    let n = sample_times(&tr.times, &tr.phase_ends, 2048, |k, t| {
        assert_eq!(k, out.len());
        out.push(t)
    });
    assert_eq!(n, 2048);
    assert_eq!(out.len(), n);
    assert_eq!((out[0], out[n - 1]), (0.0, 1000.0));
    assert!(out.windows(2).all(|w| w[1] > w[0]));
    for e in &tr.phase_ends {
        assert!(out.contains(e), "phase end {e} kept");
    }
    // Uniform otherwise: 2046 grid times (2048 less the two interior phase ends), so
    // steps of 1000 / 2045 s except beside the inserted phase ends.
    let step = 1000.0 / 2045.0;
    let uniform = out
        .windows(2)
        .filter(|w| (w[1] - w[0] - step).abs() < 1e-9)
        .count();
    assert!(uniform >= 2040, "{uniform}");
    // A short trajectory is kept whole, phase ends added.
    let short = dense(100);
    let mut few = Vec::new();
    sample_times(&short.times, &short.phase_ends, 2048, |_, t| few.push(t));
    assert_eq!(
        few.len(),
        102,
        "100 samples and the phase ends at 333.3 and 700 s"
    );
}

#[test]
fn a_plan_message_is_written_in_place_and_validates() {
    let tr = dense(5000);
    let mut plan = Box::<Plan>::new_uninit();
    Plan::zeroed_in(&mut plan);
    // SAFETY: zeroed_in initialised it.
    let mut plan = unsafe { plan.assume_init() };
    let info = PlanInfo {
        plan_id: 3,
        trigger: Trigger::PopUp,
        quality: Quality::Feasible,
        model: Model::TwoD,
        path: wingman_interfaces::PlanPath::Global,
        created_at_s: -0.2,
        cost: 12.5,
        compute_ms: 140.0,
    };
    write_plan(&mut plan, Header::new(SENDER_PLANNER, 1, 0), &info, &tr).unwrap();
    assert_eq!(plan.sample_count as usize, MAX_PLAN_SAMPLES);
    assert_eq!(plan.phase_ends(), &[333.3, 700.0, 1000.0]);
    assert_eq!((plan.start_time_s, plan.final_time_s), (0.0, 1000.0));
    assert_eq!(plan.valid_until_s, 1000.0);
    assert!(plan.next_replan().is_none());
    let s = state_at(&plan, 700.0).unwrap();
    assert!((s[0] - 140000.0).abs() < 1e-6 && (s[1] - 3500.0).abs() < 1e-6);
    // A scheduled re-plan cuts the validity short.
    set_next_replan(&mut plan, Some(420.0));
    assert_eq!(
        (plan.valid_until_s, plan.next_replan()),
        (420.0, Some(420.0))
    );
    plan.validate().unwrap();
    set_next_replan(&mut plan, Some(5000.0));
    assert_eq!(plan.valid_until_s, 1000.0);
    set_next_replan(&mut plan, None);
    assert!(plan.next_replan().is_none());
    plan.validate().unwrap();
}

#[test]
fn planner_toml_documents_exactly_the_defaults() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../planner.toml");
    let cfg = ServiceConfig::load(path).unwrap();
    assert_eq!(cfg, ServiceConfig::default());
    // Every key of the defaults appears in the file (none is left undocumented).
    let text = std::fs::read_to_string(path).unwrap();
    let defaults: toml::Table = toml::from_str(&ServiceConfig::default().to_toml()).unwrap();
    let file: toml::Table = toml::from_str(&text).unwrap();
    assert_eq!(defaults, file);
}

#[test]
fn a_bad_configuration_is_refused_naming_the_key() {
    let e = ServiceConfig::from_toml("[budget]\nplan_2d_msec = 100\n", "x.toml").unwrap_err();
    assert!(
        matches!(&e, ConfigError::Parse { .. }) && e.to_string().contains("plan_2d_msec"),
        "{e}"
    );
    let e = ServiceConfig::from_toml("[budget]\nduty_cycle = 0.01\n", "x.toml").unwrap_err();
    assert!(e.to_string().contains("budget.duty_cycle"), "{e}");
    let e = ServiceConfig::from_toml("vehicle_id = \"a/b\"\n", "x.toml").unwrap_err();
    assert!(e.to_string().contains("vehicle_id"), "{e}");
    let e =
        ServiceConfig::from_toml("[scheduling]\nmessage_slice_us = 50\n", "x.toml").unwrap_err();
    assert!(e.to_string().contains("scheduling.message_slice_us"), "{e}");
    for us in [0, 100, 100_000] {
        let ok = ServiceConfig::from_toml(&format!("[scheduling]\nmessage_slice_us = {us}\n"), "x")
            .unwrap();
        assert_eq!(ok.scheduling.message_slice_us, us);
    }
    let ok = ServiceConfig::from_toml("[budget]\nplan_2d_ms = 90\n", "x.toml").unwrap();
    assert_eq!(ok.budget.plan_2d_ms, 90);
    assert_eq!(
        ok.budget.plan_3d_ms,
        ServiceConfig::default().budget.plan_3d_ms,
        "the rest keeps its defaults"
    );
}

/// B5: the duty-cycle cap must hold a plan's budget once per thread it runs on; one
/// `solver.threads` sets the swarm's and the NLP's threads (`swarm_threads` still reads).
/// Nit: a bad `plan_3d_ms` is reported under its own key.
#[test]
fn the_duty_cycle_cap_holds_a_budget_per_thread() {
    // 600 ms x 2 threads = 1200 ms > 0.1 x 10 s.
    let budget = "[budget]\ntakeoff_2d_ms = 300\ntakeoff_3d_ms = 600\nplan_2d_ms = 300\n\
                  plan_3d_ms = 600\nduty_cycle = 0.1\n";
    let e = ServiceConfig::from_toml(budget, "x.toml").unwrap_err();
    assert!(
        e.to_string().contains("budget.duty_cycle") && e.to_string().contains("1200"),
        "{e}"
    );
    // On one thread 600 ms fits 1 s.
    let one = ServiceConfig::from_toml(&format!("{budget}[solver]\nthreads = 1\n"), "x").unwrap();
    assert_eq!(one.solver.threads, 1);
    let old = ServiceConfig::from_toml("[solver]\nswarm_threads = 1\n", "x").unwrap();
    assert_eq!(old.solver.threads, 1);
    let e = ServiceConfig::from_toml("[solver]\nthreads = 0\n", "x").unwrap_err();
    assert!(e.to_string().contains("solver.threads"), "{e}");
    let e = ServiceConfig::from_toml("[budget]\nplan_3d_ms = 0\n", "x").unwrap_err();
    assert!(e.to_string().contains("budget.plan_3d_ms"), "{e}");
    // The take-off budget counts too: 2.5 s x 2 threads > 0.4 x 10 s.
    let e = ServiceConfig::from_toml("[budget]\nduty_cycle = 0.4\n", "x").unwrap_err();
    assert!(e.to_string().contains("5000"), "{e}");
    let e = ServiceConfig::from_toml("[budget]\ntakeoff_2d_ms = 0\n", "x").unwrap_err();
    assert!(e.to_string().contains("budget.takeoff_2d_ms"), "{e}");
}

/// The take-off plan takes the take-off budget whatever else is pending; a plan from
/// scratch in flight (a new tasking, a restart, no plan to re-plan) the plan budget; a
/// refinement alone or of a deviation the refinement's; any other re-plan the re-plan's.
#[test]
fn each_plan_takes_the_budget_of_its_kind() {
    let set = |ts: &[Trigger]| TriggerSet::of(ts);
    let cases = [
        (set(&[Trigger::Initial]), false, BudgetKind::TakeOff),
        (
            set(&[Trigger::Initial, Trigger::PopUp]),
            false,
            BudgetKind::TakeOff,
        ),
        (set(&[Trigger::Restart]), false, BudgetKind::FromScratch),
        (set(&[Trigger::Tasking]), true, BudgetKind::FromScratch),
        (set(&[Trigger::PopUp]), false, BudgetKind::FromScratch),
        (set(&[Trigger::Refine]), true, BudgetKind::Refine),
        (
            set(&[Trigger::Deviation, Trigger::Refine]),
            true,
            BudgetKind::Refine,
        ),
        (
            set(&[Trigger::PopUp, Trigger::Refine]),
            true,
            BudgetKind::Replan,
        ),
        (set(&[Trigger::LeadRoute]), true, BudgetKind::Replan),
    ];
    for (s, has_plan, kind) in cases {
        assert_eq!(
            budget_kind(s, has_plan),
            kind,
            "{s:?}, plan in flight {has_plan}"
        );
    }
    // The deployment defaults: a take-off plan holds more than a plan from scratch in
    // flight in 2-D, as much in 3-D.
    let d = ServiceConfig::default();
    assert_eq!(d.takeoff_budget(Model::TwoD), Duration::from_millis(2000));
    assert_eq!(
        d.takeoff_budget(Model::ThreeD),
        d.plan_budget(Model::ThreeD)
    );
}

/// B2: the splice starts from the ownship when any pending trigger is a deviation or a
/// restart, whatever trigger names the plan.
#[test]
fn a_pending_deviation_splices_from_the_ownship_whatever_names_the_plan() {
    let mut set = TriggerSet::EMPTY;
    set.insert(Trigger::PopUp);
    assert!(!splice_from_ownship(set, false));
    assert!(splice_from_ownship(set, true), "a safe hold");
    set.insert(Trigger::Deviation);
    assert_eq!(set.primary(), Some(Trigger::PopUp));
    assert!(splice_from_ownship(set, false));
    assert!(!set.only_of(&[Trigger::PopUp, Trigger::ScheduledReplan]));
    let mut restart = TriggerSet::EMPTY;
    restart.insert(Trigger::Restart);
    restart.insert(Trigger::Tasking);
    assert!(splice_from_ownship(restart, false));
}

#[test]
fn a_deviation_re_plan_into_a_threat_or_short_of_the_nlp_keeps_the_plan_in_flight() {
    use DeviationPlan::*;
    let set = TriggerSet::of;
    let deviation = set(&[Trigger::Deviation]);
    let refinement = set(&[Trigger::Deviation, Trigger::Refine]);
    assert!(refines_deviation(refinement));
    assert!(!refines_deviation(deviation));
    assert!(!refines_deviation(set(&[Trigger::Refine])));
    for (s, made, enters, then) in [
        // Into a threat the plan in flight avoids: dropped, converged or not.
        (deviation, Quality::Optimal, true, KeepAndRetry),
        (refinement, Quality::Feasible, true, KeepAndRetry),
        // The swarm's path: refined from the ownship; once refined, kept.
        (deviation, Quality::SwarmOnly, false, KeepAndRefine),
        (refinement, Quality::SwarmOnly, false, KeepAndRetry),
        // Anything else is flown (a Feasible one refined as usual).
        (deviation, Quality::Optimal, false, Publish),
        (deviation, Quality::Feasible, false, Publish),
        (refinement, Quality::Optimal, false, Publish),
        // With another trigger the plan in flight no longer answers everything.
        (
            set(&[Trigger::Deviation, Trigger::PopUp]),
            Quality::SwarmOnly,
            true,
            Publish,
        ),
        (
            set(&[Trigger::LeadRoute]),
            Quality::SwarmOnly,
            true,
            Publish,
        ),
        (set(&[Trigger::Refine]), Quality::SwarmOnly, true, Publish),
        (TriggerSet::EMPTY, Quality::SwarmOnly, true, Publish),
    ] {
        assert_eq!(
            deviation_plan(s, made, enters),
            then,
            "{s:?} {made:?} {enters}"
        );
    }
}
