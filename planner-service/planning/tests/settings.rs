//! The planner's settings are checked when a plan starts, with a typed error naming the
//! setting, not refused by the solver mid-plan.

use std::time::Duration;

use wingman_planning::clock::{Deadline, ManualClock};
use wingman_planning::collocation::{FeralOrdering, MuStrategy, NlpSettings, NlpSettingsError};
use wingman_planning::hybrid::{PlanError, Planner, PlannerSettings, PlannerSettingsError};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::bundled;

#[test]
fn the_default_settings_are_valid() {
    assert_eq!(NlpSettings::default().validate(), Ok(()));
    assert_eq!(PlannerSettings::default().validate(), Ok(()));
}

#[test]
fn the_builder_sets_what_it_names() {
    let s = NlpSettings::default()
        .with_tol(1e-5)
        .with_mu_strategy(MuStrategy::Adaptive)
        .with_feral_ordering(FeralOrdering::Metis)
        .with_extra("max_soc", "2");
    assert_eq!(s.tol, 1e-5);
    assert_eq!(s.mu_strategy.as_str(), "adaptive");
    assert_eq!(s.feral_ordering.as_str(), "metis");
    assert_eq!(s.extra, vec![("max_soc".to_string(), "2".to_string())]);
    assert_eq!(s.validate(), Ok(()));
}

#[test]
fn out_of_range_settings_are_refused_by_name() {
    for (settings, name) in [
        (NlpSettings::default().with_tol(0.0), "tol"),
        (NlpSettings::default().with_tol(f64::NAN), "tol"),
        (NlpSettings::default().with_max_iter(0), "max_iter"),
        (NlpSettings::default().with_mu_init(Some(-1.0)), "mu_init"),
        (
            NlpSettings::default().with_acceptable_iter(-1),
            "acceptable_iter",
        ),
    ] {
        match settings.validate() {
            Err(NlpSettingsError::OutOfRange { setting, .. }) => assert_eq!(setting, name),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn an_extra_option_the_solver_does_not_know_is_refused_at_validation() {
    let bad = NlpSettings::default().with_extra("no_such_option", "1");
    assert!(matches!(bad.validate(), Err(NlpSettingsError::Refused(_))));
    let bad_word = NlpSettings::default().with_extra("mu_strategy", "sideways");
    assert!(matches!(
        bad_word.validate(),
        Err(NlpSettingsError::Refused(_))
    ));
}

/// The solver's own time budgets are refused: when a solve stops is the planner's deadline's
/// choice, recorded as a deadline cut so that a replay takes it again.
#[test]
fn an_extra_option_that_spends_the_solvers_own_time_is_refused() {
    for name in [
        "max_wall_time",
        "max_cpu_time",
        "adaptive_mu_budget_pin_fraction",
        "crossover",
    ] {
        let bad = NlpSettings::default().with_extra(name, "1");
        assert!(
            matches!(
                bad.validate(),
                Err(NlpSettingsError::OutOfRange {
                    setting: "extra",
                    ..
                })
            ),
            "{name}"
        );
    }
    let fine = NlpSettings::default().with_extra("max_soc", "2");
    assert_eq!(fine.validate(), Ok(()));
}

#[test]
fn a_plan_with_bad_settings_fails_before_it_starts() {
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    let problem = Problem::from_scenario(&sc).unwrap();
    let mut settings = PlannerSettings::default();
    settings.ranking_nlp = settings.ranking_nlp.with_extra("no_such_option", "1");
    let clock: &'static ManualClock = Box::leak(Box::new(ManualClock::new()));
    let mut planner = Planner::new(&settings);
    let deadline = || Deadline::after(clock, Duration::from_secs(10));
    let err = planner
        .plan(&problem, &settings, deadline())
        .expect_err("bad settings");
    // A refusal is not remembered as checked: the same settings are refused again.
    assert!(planner.plan(&problem, &settings, deadline()).is_err());
    assert!(
        matches!(
            err,
            PlanError::Settings(PlannerSettingsError::Nlp {
                stage: "ranking_nlp",
                ..
            })
        ),
        "{err}"
    );
    let settings = PlannerSettings {
        swarm_share: 1.5,
        ..PlannerSettings::default()
    };
    assert!(matches!(
        settings.validate(),
        Err(PlannerSettingsError::OutOfRange {
            setting: "swarm_share",
            ..
        })
    ));
}

/// The waves' settings out of range are refused, each by its name; the defaults and the
/// yardstick's (no waves) pass.
#[test]
fn bad_wave_settings_are_refused_by_name() {
    let cases: [(&str, PlannerSettings); 6] = [
        (
            "wave_starts",
            PlannerSettings {
                wave_starts: 201,
                ..PlannerSettings::default()
            },
        ),
        (
            "wave_starts_3d",
            PlannerSettings {
                wave_starts_3d: 201,
                ..PlannerSettings::default()
            },
        ),
        (
            "wave_share",
            PlannerSettings {
                wave_share: 0.0,
                ..PlannerSettings::default()
            },
        ),
        (
            "wave_share_3d",
            PlannerSettings {
                wave_share_3d: 1.5,
                ..PlannerSettings::default()
            },
        ),
        (
            "wave_gap_tol",
            PlannerSettings {
                wave_gap_tol: f64::NAN,
                ..PlannerSettings::default()
            },
        ),
        (
            "wave_gap_tol",
            PlannerSettings {
                wave_gap_tol: -0.1,
                ..PlannerSettings::default()
            },
        ),
    ];
    for (name, settings) in cases {
        match settings.validate() {
            Err(PlannerSettingsError::OutOfRange { setting, .. }) => assert_eq!(setting, name),
            other => panic!("{name}: {other:?}"),
        }
    }
    assert_eq!(PlannerSettings::default().validate(), Ok(()));
    assert_eq!(PlannerSettings::exhaustive(1).validate(), Ok(()));
    let mut bad_seeds = PlannerSettings::default();
    bad_seeds.wave_seeds.max_seeds = 0;
    assert!(
        bad_seeds.validate().is_err(),
        "the waves' seeds are checked"
    );
}
