//! One campaign mission's outcome: the flight's numbers from its `report.json`, the
//! yardstick's take-off plan, and which of the criteria it missed.

use serde::{Deserialize, Serialize};

use super::independent::IndependentNumbers;
use super::kind::MissionKind;
use crate::report::{REACHED_M, Report};

/// Largest miss of a fixed final time that meets the criteria, s.
pub const FINAL_TIME_S: f64 = 2.0;
/// Largest gap of the default take-off plan's cost over the yardstick's that counts as
/// "within" it (see [`MissionOutcome::gap`]).
pub const GAP_TOL: f64 = 0.005;
/// Costs below this are compared in absolute terms: the gap's denominator is at least
/// this, so a gap within [`GAP_TOL`] means within 0.5 % or within 1e-4 (the tolerance of
/// the canonical plans' quality test). A fixed-time plan on an avoidable layout with time
/// to spare costs 1e-4 to 1e-3 (a little turning, no exposure): there 0.5 % is below
/// what the solver's own tolerance resolves.
pub const COST_FLOOR: f64 = 0.02;

/// A plan of the flight.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlanNumbers {
    pub trigger: String,
    pub at_s: f64,
    pub quality: String,
    pub path: String,
    pub compute_ms: f64,
    pub cost: f64,
    pub cuts: u32,
}

/// What the flight measured (a subset of its `report.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FlightNumbers {
    pub completed: bool,
    /// `plan-ended` or `time-limit`.
    pub end: String,
    pub end_s: f64,
    pub target_miss_m: Vec<f64>,
    pub final_error_m: f64,
    pub final_time_error_s: Option<f64>,
    pub min_f_static: Option<f64>,
    pub min_f_moving: Option<f64>,
    pub exposure_s: f64,
    pub plans: Vec<PlanNumbers>,
    pub holds: usize,
    pub messages_lost: u64,
    /// Smallest F of each static threat (pop-ups included) along the flown path.
    #[serde(default)]
    pub min_f_by_threat: Vec<(String, f64)>,
}

/// The yardstick's take-off plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct YardstickNumbers {
    pub cost: f64,
    pub quality: String,
    /// Each run's cost, in run order.
    pub run_costs: Vec<f64>,
    /// Deadline cuts over its runs (0: the same on any machine).
    pub cuts: usize,
    pub compute_s: f64,
}

/// One mission of a campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MissionOutcome {
    pub index: usize,
    pub name: String,
    pub kind: MissionKind,
    /// Why the mission could not be flown (then `flight` is `None`).
    pub error: Option<String>,
    pub flight: Option<FlightNumbers>,
    pub yardstick: Option<YardstickNumbers>,
    /// Why the yardstick could not plan the take-off (the flight's numbers stand).
    #[serde(default)]
    pub yardstick_error: Option<String>,
    /// The independent solver's take-off, on the missions it plans
    /// ([`super::independent::selected`]).
    #[serde(default)]
    pub independent: Option<IndependentNumbers>,
    /// Why the independent solver gave no take-off there.
    #[serde(default)]
    pub independent_error: Option<String>,
    /// The criteria it missed, in words (empty: it meets them all).
    pub misses: Vec<String>,
    /// Its folder under the campaign's, kept when it failed or its take-off plan is
    /// outside [`GAP_TOL`] of the yardstick (else removed).
    pub kept: Option<String>,
    pub wall_s: f64,
}

impl FlightNumbers {
    /// The numbers of `r`.
    pub fn of(r: &Report) -> FlightNumbers {
        FlightNumbers {
            completed: r.completed,
            end: r.end.to_string(),
            end_s: r.end_s,
            target_miss_m: r.targets.iter().map(|t| finite(t.miss_m)).collect(),
            final_error_m: finite(r.final_error_m),
            final_time_error_s: r.final_time_error_s.map(finite),
            min_f_static: r.min_f_static.map(finite),
            min_f_moving: r.min_f_moving.map(finite),
            exposure_s: finite(r.exposure_integral),
            min_f_by_threat: r
                .threats
                .iter()
                .filter(|t| t.kind == "static")
                .map(|t| (t.name.clone(), finite(t.min_f)))
                .collect(),
            plans: r
                .plans
                .iter()
                .map(|p| PlanNumbers {
                    trigger: p.trigger.clone(),
                    at_s: p.at_s,
                    quality: p.quality.clone(),
                    path: p.path.clone(),
                    compute_ms: finite(p.compute_ms),
                    cost: finite(p.cost),
                    cuts: p.cuts,
                })
                .collect(),
            holds: r.holds.len(),
            messages_lost: r.planner.as_ref().map_or(0, |c| c.messages_lost),
        }
    }

    /// The criteria this flight of a mission of `kind` misses: every target and the end
    /// within 100 m, a fixed final time within 2 s, min F ≥ 1 of the static threats on an
    /// avoidable layout.
    pub fn misses(&self, kind: &MissionKind) -> Vec<String> {
        let mut misses = Vec::new();
        if !self.completed {
            misses.push(format!("not completed ({})", self.end));
        }
        for (k, m) in self.target_miss_m.iter().enumerate() {
            if *m > REACHED_M {
                misses.push(format!("target {} missed by {m:.0} m", k + 1));
            }
        }
        if self.final_error_m > REACHED_M {
            misses.push(format!("end missed by {:.0} m", self.final_error_m));
        }
        if let Some(dt) = self.final_time_error_s
            && dt.abs() > FINAL_TIME_S
        {
            misses.push(format!("final time off by {dt:.1} s"));
        }
        if !kind.unavoidable
            && let Some(f) = self.min_f_static
            && f < 1.0
        {
            misses.push(format!("entered a static threat (min F {f:.3})"));
        }
        // Where a target sits in a defended threat, only that threat may be entered.
        if kind.unavoidable
            && let Some((name, f)) = self
                .min_f_by_threat
                .iter()
                .filter(|(name, _)| Some(name) != kind.defended.as_ref())
                .min_by(|a, b| a.1.total_cmp(&b.1))
            && *f < 1.0
        {
            misses.push(format!("entered static threat {name} (min F {f:.3})"));
        }
        misses
    }

    /// The take-off plan (the first plan, triggered `Initial`).
    pub fn take_off(&self) -> Option<&PlanNumbers> {
        self.plans.first().filter(|p| p.trigger == "Initial")
    }
}

/// `x`, or `f64::MAX` with its sign when it is not finite (JSON has no infinity, and a
/// `null` would not read back): "never reached" reads as 1.8e308 m.
pub fn finite(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else if x < 0.0 {
        -f64::MAX
    } else {
        f64::MAX
    }
}

impl MissionOutcome {
    /// A mission that could not be flown: `error` says why.
    pub fn not_flown(
        index: usize,
        name: &str,
        kind: &MissionKind,
        error: String,
    ) -> MissionOutcome {
        MissionOutcome {
            index,
            name: name.to_string(),
            kind: kind.clone(),
            error: Some(error),
            flight: None,
            yardstick: None,
            yardstick_error: None,
            independent: None,
            independent_error: None,
            misses: vec!["not flown".into()],
            kept: None,
            wall_s: 0.0,
        }
    }

    /// Whether the mission was flown and meets every criterion.
    pub fn meets_criteria(&self) -> bool {
        self.error.is_none() && self.misses.is_empty()
    }

    /// The default take-off plan's cost `c` over the yardstick's `y`, relative:
    /// `(c − y) / max(|y|, COST_FLOOR)` (negative: the default did better).
    pub fn gap(&self) -> Option<f64> {
        let take_off = self.flight.as_ref()?.take_off()?;
        let y = self.yardstick.as_ref()?.cost;
        (take_off.cost.is_finite() && y.is_finite())
            .then(|| (take_off.cost - y) / y.abs().max(COST_FLOOR))
    }

    /// Whether it is kept for a look: it failed, or its take-off plan is outside
    /// [`GAP_TOL`] of the yardstick.
    pub fn outlying(&self) -> bool {
        !self.meets_criteria() || self.gap().is_some_and(|g| g > GAP_TOL)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kind(unavoidable: bool) -> MissionKind {
        MissionKind {
            model: "2d".into(),
            objective: "fixed-time".into(),
            targets: 2,
            threats: 3,
            popups: 0,
            moving: 0,
            unavoidable,
            lead_change: false,
            wind: false,
            defended: unavoidable.then(|| "t0".to_string()),
        }
    }

    fn flight() -> FlightNumbers {
        FlightNumbers {
            completed: true,
            end: "plan-ended".into(),
            end_s: 800.0,
            target_miss_m: vec![5.0, 99.0],
            final_error_m: 1.0,
            final_time_error_s: Some(0.5),
            min_f_static: Some(1.2),
            min_f_moving: None,
            exposure_s: 0.0,
            plans: vec![PlanNumbers {
                trigger: "Initial".into(),
                at_s: 0.0,
                quality: "Optimal".into(),
                path: "Global".into(),
                compute_ms: 100.0,
                cost: 1.01,
                cuts: 0,
            }],
            holds: 0,
            messages_lost: 0,
            min_f_by_threat: vec![("t0".into(), 0.2), ("t1".into(), 1.2)],
        }
    }

    #[test]
    fn each_criterion_is_named_when_missed() {
        assert!(flight().misses(&kind(false)).is_empty());
        let mut f = flight();
        f.target_miss_m[1] = 101.0;
        f.final_error_m = 150.0;
        f.final_time_error_s = Some(-2.5);
        f.min_f_static = Some(0.9);
        let m = f.misses(&kind(false));
        assert_eq!(m.len(), 4, "{m:?}");
        assert!(m[0].contains("target 2") && m[3].contains("0.900"));
        // Entering the defended threat is allowed where a target sits inside it; another
        // one is not.
        assert_eq!(f.misses(&kind(true)).len(), 3);
        f.min_f_by_threat[1].1 = 0.9;
        let m = f.misses(&kind(true));
        assert!(m.last().unwrap().contains("threat t1"), "{m:?}");
        assert_eq!(finite(f64::INFINITY), f64::MAX);
        assert_eq!(finite(f64::NEG_INFINITY), -f64::MAX);
    }

    #[test]
    fn the_gap_is_relative_to_the_yardstick() {
        let mut o = MissionOutcome {
            index: 0,
            name: "m".into(),
            kind: kind(false),
            error: None,
            flight: Some(flight()),
            yardstick: Some(YardstickNumbers {
                cost: 1.0,
                quality: "Optimal".into(),
                run_costs: vec![1.0],
                cuts: 0,
                compute_s: 1.0,
            }),
            yardstick_error: None,
            independent: None,
            independent_error: None,
            misses: Vec::new(),
            kept: None,
            wall_s: 1.0,
        };
        assert!((o.gap().unwrap() - 0.01).abs() < 1e-12);
        assert!(o.outlying());
        o.yardstick.as_mut().unwrap().cost = 1.008;
        assert!(!o.outlying());
        // Small costs compare in absolute terms: 1e-4 over 0.02 is the 0.5 % tolerance.
        o.flight.as_mut().unwrap().plans[0].cost = 0.0005;
        o.yardstick.as_mut().unwrap().cost = 0.0004;
        assert!((o.gap().unwrap() - 0.005).abs() < 1e-12);
        o.flight.as_mut().unwrap().plans[0].trigger = "PopUp".into();
        assert_eq!(o.gap(), None);
    }
}
