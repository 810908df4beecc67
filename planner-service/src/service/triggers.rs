//! When to re-plan (FORMULATION.md §6, issue 6 item 2): each trigger as a pure function of
//! the world and the current plan, with no clock, no allocation and no I/O, so each can be
//! tested on the case that fires it and on the near miss beside it.
//!
//! The triggers are, and nothing else (no periodic re-planning):
//! - the first tasking ([`Trigger::Initial`], or [`Trigger::Restart`] when the mission is
//!   already under way: a restarted planner);
//! - a pop-up whose region reaches the remaining plan, `F < F*` ([`static_popup`],
//!   [`moving_popup`]; a moving threat at its region propagated to each sample's time);
//! - a tasking change: a larger revision with other targets, final point, objective,
//!   model, limits or weights ([`tasking_decision`]);
//! - a lead route change: a larger revision with another route ([`route_decision`]);
//! - a lead that leaves its route without a new one: its observed state moves the
//!   predicted meeting point beyond a bound ([`lead_off_route_m`]);
//! - the scheduled `t_r` of a moving threat that touches the plan (eqs. 7.1–7.6,
//!   [`scheduled_replan`]), acted on one plan budget early so the new plan commits at
//!   `t_r` ([`scheduled_due`]);
//! - the tracker's deviation from the plan beyond a bound ([`deviation_exceeded`]);
//! - the plan expiring with no successor, or the tracker flying a safe hold
//!   ([`expiry_due`]);
//! - a plan made short of `Optimal` (its deadline cut the NLP), refined once with a
//!   longer budget ([`refine_due`]).

use wingman_interfaces::{
    LeadRoute, LeadState, Model, OwnshipState, Quality, Tasking, Trigger, Wire,
};

use wingman_ipc::config::TriggerConfig;
use wingman_planning::lead::LeadPath;

use wingman_planning::estimation::MovingThreat;
use wingman_planning::replan::{self, PlanPoint, PopupHit, ReplanTime};
use wingman_planning::threat::Superquadric;

/// What a received tasking means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TaskingDecision {
    /// The first tasking: plan the mission.
    First,
    /// A larger revision with different content: re-plan.
    Changed,
    /// A larger revision with the same content: keep it, no plan.
    Unchanged,
    /// Not a larger revision (a repeat or an old one): ignore.
    Stale,
}

/// Compares a received tasking with the one held.
pub fn tasking_decision(held: Option<&Tasking>, received: &Tasking) -> TaskingDecision {
    let Some(held) = held else {
        return TaskingDecision::First;
    };
    if received.revision <= held.revision {
        return TaskingDecision::Stale;
    }
    let same = held.model == received.model
        && held.objective == received.objective
        && held.limits == received.limits
        && held.weights == received.weights
        && held.targets() == received.targets()
        && held.final_state == received.final_state
        && held.final_time_s == received.final_time_s
        && held.wind_mps == received.wind_mps;
    if same {
        TaskingDecision::Unchanged
    } else {
        TaskingDecision::Changed
    }
}

/// What a received lead route means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RouteDecision {
    First,
    Changed,
    Unchanged,
    Stale,
}

/// Compares a received lead route with the one held.
pub fn route_decision(held: Option<&LeadRoute>, received: &LeadRoute) -> RouteDecision {
    let Some(held) = held else {
        return RouteDecision::First;
    };
    if received.revision <= held.revision {
        return RouteDecision::Stale;
    }
    let same = held.points() == received.points()
        && held.speed_mps == received.speed_mps
        && held.start_time_s == received.start_time_s;
    if same {
        RouteDecision::Unchanged
    } else {
        RouteDecision::Changed
    }
}

/// How far the lead, flown on straight from its observed state `s`, would be at the
/// meeting time `meet_at_s` from where `route` puts it then, m: the difference of the two
/// now, plus the difference of their velocities over the time left (0 once met).
pub fn lead_off_route_m(route: &LeadPath, s: &LeadState, meet_at_s: f64) -> f64 {
    let on_route = route.at(s.time_s);
    let observed = lead_velocity(s);
    let ahead = (meet_at_s - s.time_s).max(0.0);
    (0..3)
        .map(|i| {
            let now = s.position_m[i] - on_route.position[i];
            let drift = (observed[i] - on_route.velocity[i]) * ahead;
            (now + drift).powi(2)
        })
        .sum::<f64>()
        .sqrt()
}

/// The route the lead flies as observed in `s`: straight on from its position at its
/// heading, flight-path angle and speed, from `s.time_s` (`revision` kept: the route it
/// stands for), long enough for any mission; level at `z = 0` in 2-D.
pub fn observed_route(s: &LeadState, revision: u32, model: Model) -> LeadRoute {
    const AHEAD_M: f64 = 2.0e6;
    let mut s = *s;
    if model == Model::TwoD {
        s.gamma_rad = 0.0;
        s.position_m[2] = 0.0;
    }
    let v = lead_velocity(&s);
    let speed = s.speed_mps.max(f64::MIN_POSITIVE);
    let mut r = LeadRoute::zeroed();
    r.revision = revision;
    r.point_count = 2;
    r.start_time_s = s.time_s;
    r.speed_mps = s.speed_mps;
    r.points_m[0] = s.position_m;
    r.points_m[1] = std::array::from_fn(|i| s.position_m[i] + v[i] / speed * AHEAD_M);
    r
}

/// The lead's velocity in `s`, from its heading, flight-path angle and speed.
fn lead_velocity(s: &LeadState) -> [f64; 3] {
    let (sg, cg) = s.gamma_rad.sin_cos();
    let (sc, cc) = s.heading_rad.sin_cos();
    [
        s.speed_mps * cg * cc,
        s.speed_mps * cg * sc,
        s.speed_mps * sg,
    ]
}

/// A pop-up assessed against the remaining plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PopupAssessment {
    /// `F < F*` at this sample: re-plan.
    Touches(PopupHit),
    /// Clear of the plan: logged, counted, no plan.
    Clear,
}

impl PopupAssessment {
    pub fn touches(&self) -> bool {
        matches!(self, PopupAssessment::Touches(_))
    }
}

/// The samples of `plan` at or after `now`.
pub fn remaining<const D: usize>(plan: &[PlanPoint<D>], now: f64) -> &[PlanPoint<D>] {
    let k = plan.partition_point(|p| p.t < now);
    &plan[k..]
}

/// Pop-up test of a static threat against the remaining plan.
pub fn static_popup<const D: usize>(
    remaining: &[PlanPoint<D>],
    threat: &Superquadric<D>,
    f_star: f64,
) -> PopupAssessment {
    match replan::static_popup_hit(remaining, threat, f_star) {
        Some(hit) => PopupAssessment::Touches(hit),
        None => PopupAssessment::Clear,
    }
}

/// Pop-up test of a moving threat against the remaining plan, its region propagated to
/// each sample's time.
pub fn moving_popup<const D: usize>(
    remaining: &[PlanPoint<D>],
    threat: &MovingThreat<D>,
    f_star: f64,
) -> PopupAssessment {
    match replan::moving_popup_hit(remaining, threat, f_star) {
        Some(hit) => PopupAssessment::Touches(hit),
        None => PopupAssessment::Clear,
    }
}

/// `t_r` (eqs. 7.1–7.6) of a moving threat over a plan, looked for from `not_before` on
/// (the plan's start plus `replan_min_lead_s`). `None`: the threat never comes within the
/// critical distance of the plan.
pub fn scheduled_replan<const D: usize>(
    plan: &[PlanPoint<D>],
    threat: &MovingThreat<D>,
    not_before: f64,
) -> Option<ReplanTime> {
    replan::replan_time(remaining(plan, not_before), threat)
}

/// Whether the scheduled re-plan is due at mission time `now`: one plan budget (`lead_s`)
/// before `t_r`, so that the new plan commits at `t_r`. (Mission time travels in whole
/// nanoseconds: a microsecond of tolerance absorbs the rounding.)
pub fn scheduled_due(now: f64, t_r: f64, lead_s: f64) -> bool {
    now >= t_r - lead_s - TIME_TOLERANCE_S
}

/// Tolerance of mission-time comparisons, s.
pub const TIME_TOLERANCE_S: f64 = 1e-6;

/// Bounds of the tracker's deviation from the plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeviationBounds {
    pub cross_m: f64,
    pub vertical_m: f64,
    /// Ahead of or behind the plan: at a constant airspeed only a new plan makes up for
    /// it, and a rendezvous or a fixed final time needs it made up.
    pub along_m: f64,
}

impl DeviationBounds {
    /// The bounds of the trigger configuration at mission time `now` for a plan ending at
    /// `final_time_s`: near the end of a plan whose final time is free (`fixed_time`
    /// false), the tighter along-track bound, since what is left there is the end's miss.
    pub fn at(cfg: &TriggerConfig, fixed_time: bool, now: f64, final_time_s: f64) -> Self {
        let near_end = !fixed_time && final_time_s - now <= cfg.deviation_end_window_s;
        DeviationBounds {
            cross_m: cfg.deviation_cross_m,
            vertical_m: cfg.deviation_vertical_m,
            along_m: if near_end {
                cfg.deviation_along_end_m.min(cfg.deviation_along_m)
            } else {
                cfg.deviation_along_m
            },
        }
    }
}

/// Whether the ownship, flying the plan `current_plan_id`, deviates from it beyond the
/// bounds. A report about another plan (the tracker has not switched yet) or from a safe
/// hold does not count: the hold is [`expiry_due`]'s case.
pub fn deviation_exceeded(
    ownship: &OwnshipState,
    current_plan_id: u64,
    bounds: &DeviationBounds,
) -> bool {
    current_plan_id != 0
        && ownship.plan_id == current_plan_id
        && !ownship.holding()
        && (ownship.cross_track_m.abs() > bounds.cross_m
            || ownship.vertical_m.abs() > bounds.vertical_m
            || ownship.along_track_m.abs() > bounds.along_m)
}

/// The current plan's time window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanWindow {
    pub start_s: f64,
    pub valid_until_s: f64,
    pub final_time_s: f64,
}

impl PlanWindow {
    /// Whether the plan may be flown to its end (not cut short by a scheduled re-plan).
    pub fn reaches_end(&self) -> bool {
        self.valid_until_s >= self.final_time_s
    }
}

/// Whether the tracker flies a safe hold instead of plan `plan_id` (which starts at
/// `plan_start_s`): it holds after flying that plan, or it still holds at or after that
/// plan's start (it did not take it). A hold reported before a newer plan starts is the
/// older plan's, which the newer one answers: counting it again for every newer plan
/// re-plans on end while mission time stands still (a lock-step harness waits for the
/// planner to be idle before it moves the clock and the tracker on).
pub fn holds_instead_of(ownship: &OwnshipState, plan_id: u64, plan_start_s: f64) -> bool {
    ownship.holding()
        && (ownship.plan_id == plan_id
            || (ownship.plan_id < plan_id && ownship.time_s >= plan_start_s - TIME_TOLERANCE_S))
}

/// Whether the plan expires with no successor: at mission time `now` it is within one
/// plan budget (`lead_s`) of `valid_until` while cut short of its end, or the tracker
/// reports flying a safe hold. A plan that runs to its end (the mission's end) does not
/// expire: the mission is over.
pub fn expiry_due(now: f64, plan: &PlanWindow, lead_s: f64, holding: bool) -> bool {
    if holding {
        return now < plan.final_time_s || !plan.reaches_end();
    }
    !plan.reaches_end() && now >= plan.valid_until_s - lead_s - TIME_TOLERANCE_S
}

/// Whether a plan just made is refined: it fell short of `Optimal` (a re-plan's short
/// budget cut its NLP, leaving the swarm's path or an unconverged solution to fly, which
/// may miss the end by hundreds of metres), or it enters a known static threat that the
/// plan before it kept clear of (`enters_new_threat`: a re-plan that converged in a basin
/// across the threat), and it is not itself a refinement (one attempt, so a mission the
/// NLP cannot solve does not plan on end). The refinement re-plans the plan in flight
/// with its own budget, longer than a re-plan's ([`refine_only`]): the aircraft flies
/// the short plan meanwhile.
pub fn refine_due(enabled: bool, made: Quality, trigger: Trigger, enters_new_threat: bool) -> bool {
    enabled && trigger != Trigger::Refine && (made != Quality::Optimal || enters_new_threat)
}

/// What becomes of a plan made for a deviation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeviationPlan {
    /// Published, as any other plan.
    Publish,
    /// Dropped, the plan in flight kept; the deviation may re-plan again
    /// [`DEVIATION_RETRY_S`] later.
    KeepAndRetry,
    /// Dropped, the plan in flight kept, and the deviation re-planned at once with the
    /// refinement's budget ([`refines_deviation`]).
    KeepAndRefine,
}

/// What becomes of a plan made for the triggers `set` that came out `made`, entering a
/// known static threat the plan in flight kept clear of or not (`enters_new_threat`). A
/// re-plan for a deviation alone (or its refinement) that enters such a threat is dropped:
/// the plan in flight still takes the aircraft through every target to the end clear of
/// the threats (the tracker flies back to it), where a short re-plan from a deviated state
/// may stop in a basin across a threat (a windy fixed-time mission's, 2 700 s from its end:
/// cost 0.003 before, 52 after, and its refinement stayed across). A deviation re-plan
/// that did not converge (`SwarmOnly`) is dropped and refined at once from the ownship:
/// the swarm's path of a deviated aircraft a few seconds before a target misses the
/// target, and on a long mission the refinement's budget converges where the re-plan's
/// did not. If the refinement does not converge either, the plan in flight stays.
pub fn deviation_plan(set: TriggerSet, made: Quality, enters_new_threat: bool) -> DeviationPlan {
    let deviation_only = set.is_exactly(&[Trigger::Deviation]);
    let refinement = refines_deviation(set);
    if !(deviation_only || refinement) {
        DeviationPlan::Publish
    } else if enters_new_threat || (refinement && made == Quality::SwarmOnly) {
        DeviationPlan::KeepAndRetry
    } else if made == Quality::SwarmOnly {
        DeviationPlan::KeepAndRefine
    } else {
        DeviationPlan::Publish
    }
}

/// Whether the triggers `set` refine a deviation re-plan (a deviation and a refinement,
/// nothing else): planned from the ownship with the refinement's budget.
pub fn refines_deviation(set: TriggerSet) -> bool {
    set.is_exactly(&[Trigger::Deviation, Trigger::Refine])
}

/// Mission time after a dropped deviation re-plan ([`deviation_plan`]) before the
/// deviation from the same plan may re-plan again, s.
pub const DEVIATION_RETRY_S: f64 = 10.0;

/// Whether the triggers `set` ask only for a refinement (it has its own budget, between a
/// re-plan's and a plan from scratch's).
pub fn refine_only(set: TriggerSet) -> bool {
    set.is_exactly(&[Trigger::Refine])
}

/// Whether the first plan of a tasking is a restart: the tracker already flies a plan
/// (of a predecessor process), or the ownship's clock is past the tasking's start.
pub fn first_plan_trigger(tasking: &Tasking, ownship: Option<&OwnshipState>) -> Trigger {
    match ownship {
        Some(o) if o.plan_id != 0 || o.time_s > tasking.start_time_s => Trigger::Restart,
        _ => Trigger::Initial,
    }
}

/// A set of pending triggers (a bit per [`Trigger`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TriggerSet(u32);

/// Triggers in the order the plan message names them when several are pending.
const PRIORITY: [Trigger; 10] = [
    Trigger::Initial,
    Trigger::Restart,
    Trigger::Tasking,
    Trigger::LeadRoute,
    Trigger::LeadOffRoute,
    Trigger::PopUp,
    Trigger::Deviation,
    Trigger::ScheduledReplan,
    Trigger::Expiry,
    Trigger::Refine,
];

impl TriggerSet {
    pub const EMPTY: TriggerSet = TriggerSet(0);

    /// The set of `triggers`.
    pub fn of(triggers: &[Trigger]) -> TriggerSet {
        let mut set = TriggerSet::EMPTY;
        for &t in triggers {
            set.insert(t);
        }
        set
    }

    /// Whether the set holds `triggers` and nothing else.
    pub fn is_exactly(&self, triggers: &[Trigger]) -> bool {
        *self == TriggerSet::of(triggers)
    }

    pub fn insert(&mut self, t: Trigger) {
        self.0 |= 1 << t.to_wire();
    }

    pub fn contains(&self, t: Trigger) -> bool {
        self.0 & (1 << t.to_wire()) != 0
    }

    pub fn is_empty(&self) -> bool {
        self.0 == 0
    }

    pub fn union(self, other: TriggerSet) -> TriggerSet {
        TriggerSet(self.0 | other.0)
    }

    /// Whether every pending trigger is a pop-up (which a newer plan may already avoid).
    pub fn only_popups(&self) -> bool {
        self.0 == 1 << Trigger::PopUp.to_wire()
    }

    /// Whether every pending trigger is one of `allowed`.
    pub fn only_of(&self, allowed: &[Trigger]) -> bool {
        let mask = allowed.iter().fold(0, |m, t| m | 1 << t.to_wire());
        self.0 & !mask == 0
    }

    /// The trigger a plan made for this set is named after.
    pub fn primary(&self) -> Option<Trigger> {
        PRIORITY.into_iter().find(|t| self.contains(*t))
    }
}

/// Whether a plan for the triggers `set` is made from scratch: a first plan, a new
/// tasking or a restart leave no plan in flight to start from (the other triggers re-plan
/// it, with the re-plan budget).
pub fn from_scratch(set: TriggerSet) -> bool {
    [Trigger::Initial, Trigger::Tasking, Trigger::Restart]
        .iter()
        .any(|&t| set.contains(t))
}

/// Whether a plan for the triggers `set` re-plans the plan in flight: there is one
/// (`has_plan`), and the triggers leave something of it to start from (not a first plan,
/// a new tasking or a restart).
pub fn replans_in_flight(set: TriggerSet, has_plan: bool) -> bool {
    has_plan && !from_scratch(set)
}

/// Which of the configured budgets a plan takes (`[budget]` in `planner.toml`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BudgetKind {
    /// The take-off plan: the aircraft waits at the tasking's start for it.
    TakeOff,
    /// A plan from scratch in flight: a new tasking, a restart, or no plan to re-plan.
    FromScratch,
    /// A refinement of a plan short of `Optimal` (a deviation's included).
    Refine,
    /// A re-plan of the plan in flight: the aircraft's reaction time.
    Replan,
}

/// The budget of a plan for the triggers `set`, `has_plan` saying whether a plan is in
/// flight.
pub fn budget_kind(set: TriggerSet, has_plan: bool) -> BudgetKind {
    if set.contains(Trigger::Initial) {
        BudgetKind::TakeOff
    } else if !replans_in_flight(set, has_plan) {
        BudgetKind::FromScratch
    } else if refine_only(set) || refines_deviation(set) {
        BudgetKind::Refine
    } else {
        BudgetKind::Replan
    }
}

/// Whether a re-plan for the pending triggers `set` starts from the ownship's state rather
/// than from the state the current plan predicts: the aircraft left the plan (a deviation
/// or a restart is pending, whatever trigger names the plan) or flies a safe hold.
pub fn splice_from_ownship(set: TriggerSet, holding: bool) -> bool {
    set.contains(Trigger::Deviation) || set.contains(Trigger::Restart) || holding
}
