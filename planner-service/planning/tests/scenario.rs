//! The scenario loader: every canonical file loads with the values its text says, every
//! bundled copy equals its file, and broken variants are refused naming file and key.

use std::path::{Path, PathBuf};
use wingman_interfaces::{Model, Objective};
use wingman_planning::scenario::{
    BUNDLED, DISTURBED, EventKind, GUST_LENGTH_M, Scenario, bundled, load_by_path_or_name,
};

fn scenarios_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios")
}

fn canonical_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenarios_dir())
        .expect("scenarios/")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_canonical_file_loads() {
    let files = canonical_files();
    assert_eq!(files.len(), 15, "the canonical set has 15 scenarios");
    for path in files {
        let sc = Scenario::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let stem = path.file_stem().unwrap().to_str().unwrap();
        assert_eq!(sc.name, stem, "name equals the file stem");
        assert_eq!(
            sc.model.position_dim(),
            if stem.starts_with("2d") { 2 } else { 3 }
        );
        match sc.objective {
            Objective::MinTimeRendezvous => assert!(sc.lead.is_some() && sc.final_point.is_none()),
            Objective::FixedTime => {
                assert!(sc.final_point.as_ref().unwrap().time_s.is_some());
            }
            Objective::MinTime => assert!(sc.final_point.as_ref().unwrap().time_s.is_none()),
        }
        assert!(!sc.threats.is_empty());
    }
}

#[test]
fn bundled_copies_equal_the_files() {
    let names: Vec<String> = canonical_files()
        .iter()
        .map(|p| p.file_stem().unwrap().to_str().unwrap().to_string())
        .collect();
    let bundled_names: Vec<String> = BUNDLED.iter().map(|(n, _)| n.to_string()).collect();
    assert_eq!(
        bundled_names, names,
        "BUNDLED lists exactly scenarios/*.toml"
    );
    for (name, text) in BUNDLED {
        let file = std::fs::read_to_string(scenarios_dir().join(format!("{name}.toml"))).unwrap();
        assert_eq!(*text, file);
        let a = bundled(name).unwrap().unwrap();
        let b = load_by_path_or_name(
            scenarios_dir()
                .join(format!("{name}.toml"))
                .to_str()
                .unwrap(),
        )
        .unwrap();
        assert_eq!(a.name, b.name);
        assert_eq!(a.targets, b.targets);
    }
    assert!(load_by_path_or_name("no-such-scenario").is_err());
}

/// Values of `3d-replan-popups.toml`, converted by hand (degrees → radians), with a
/// tolerance of 1e-12 relative.
#[test]
fn values_are_converted_to_si() {
    let sc = bundled("3d-replan-popups").unwrap().unwrap();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
    assert_eq!(sc.model, Model::ThreeD);
    assert_eq!(sc.objective, Objective::MinTimeRendezvous);
    assert!(close(sc.vehicle.speed_mps, 250.0));
    assert!(close(
        sc.vehicle.gamma_max_rad,
        30.0 * std::f64::consts::PI / 180.0
    ));
    assert!(close(
        sc.vehicle.bank_rate_max_rps,
        30.0 * std::f64::consts::PI / 180.0
    ));
    assert!(close(sc.vehicle.altitude_min_m, 500.0));
    assert_eq!(sc.targets, vec![[60000.0, 80000.0, 2000.0]]);
    assert_eq!(sc.threats.len(), 6);
    assert_eq!(sc.threats[4].exponents, [2.0, 2.0, 8.0]);
    assert_eq!(
        sc.threats[0].exponents,
        [2.0, 2.0, 2.0],
        "default exponents"
    );
    assert_eq!(sc.threats[5].appears_at_s, Some(300.0));
    assert_eq!(sc.known_static_threats().count(), 5);
    assert_eq!(sc.known_moving_threats().count(), 0);
    assert!(sc.is_closed_loop());
    let m = &sc.moving_threats[0];
    assert_eq!(m.truth_seed, 7);
    assert!(close(m.sensor.rate_hz, 1.0) && close(m.sensor.sigma_m, 200.0));
    assert_eq!(m.initial_sigma, [500.0, 3.0, 0.3]);
    assert_eq!(sc.events.len(), 1);
    match &sc.events[0].kind {
        EventKind::LeadRoute { route_m, speed_mps } => {
            assert_eq!(route_m.len(), 3);
            assert!(close(*speed_mps, 180.0));
        }
        other => panic!("expected a lead-route event, got {other:?}"),
    }
    let two_d = bundled("2d-min-time-rendezvous-avoidable")
        .unwrap()
        .unwrap();
    assert!(close(
        two_d.threats[3].yaw_rad,
        20.0 * std::f64::consts::PI / 180.0
    ));
    assert_eq!(two_d.threats[3].axes_m, [9000.0, 4000.0, 0.0]);
    assert!(!two_d.is_closed_loop());
}

/// A canonical file with one textual change, the key the error must name, and a word the
/// problem must contain.
struct Broken {
    base: &'static str,
    from: &'static str,
    to: &'static str,
    key: &'static str,
    problem: &'static str,
}

const BROKEN: &[Broken] = &[
    Broken {
        base: "3d-replan-popups",
        from: "speed_mps = 250.0\n",
        to: "",
        key: "vehicle.speed_mps",
        problem: "missing",
    },
    Broken {
        base: "3d-replan-popups",
        from: "position_m = [0.0, 0.0, 15000.0]",
        to: "position_m = [0.0, 0.0]",
        key: "start.position_m",
        problem: "list of 3 numbers",
    },
    Broken {
        base: "2d-min-time-rendezvous-avoidable",
        from: "axes_m = [8000.0, 8000.0]",
        to: "axes_m = [-8000.0, 8000.0]",
        key: "threats[0].axes_m",
        problem: "positive",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "alpha = 0.05",
        to: "alpha = nan",
        key: "weights.alpha",
        problem: "finite",
    },
    Broken {
        base: "3d-replan-popups",
        from: "stiffness = 30.0",
        to: "stiffness = inf",
        key: "weights.stiffness",
        problem: "finite",
    },
    Broken {
        base: "3d-replan-popups",
        from: "position_m = [60000.0, 80000.0, 2000.0]",
        to: "position_m = [60000.0, 80000.0, 100.0]",
        key: "targets[0].position_m",
        problem: "altitude_min_m",
    },
    Broken {
        base: "3d-replan-popups",
        from: "objective = \"min-time-rendezvous\"",
        to: "objective = \"max-fun\"",
        key: "objective",
        problem: "unknown objective",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "model = \"2d\"",
        to: "model = \"4d\"",
        key: "model",
        problem: "\"2d\" or \"3d\"",
    },
    Broken {
        base: "3d-replan-popups",
        from: "speed_mps = 250.0",
        to: "speed_mps = \"fast\"",
        key: "vehicle.speed_mps",
        problem: "number",
    },
    Broken {
        base: "3d-replan-popups",
        from: "speed_mps = 250.0",
        to: "speed_mps = 250.0\nturn_rate_max_dps = 5.0",
        key: "vehicle.turn_rate_max_dps",
        problem: "unknown key",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "time_s = 800.0",
        to: "time_s = -5.0",
        key: "final.time_s",
        problem: "after start.time_s",
    },
    Broken {
        base: "3d-min-time-moving-threat",
        from: "rate_hz = 1.0",
        to: "rate_hz = 0.0",
        key: "moving_threats[0].sensor.rate_hz",
        problem: "positive",
    },
    Broken {
        base: "3d-min-time-moving-threat",
        from: "road_m = [[70000.0, 0.0, 0.0], [100000.0, 150000.0, 0.0]]",
        to: "road_m = [[70000.0, 0.0, 0.0]]",
        key: "moving_threats[0].road_m",
        problem: "2 to 16 points",
    },
    Broken {
        base: "3d-min-time-moving-threat",
        from: "initial_sigma = [500.0, 3.0, 0.3]",
        to: "initial_sigma = [500.0, -3.0, 0.3]",
        key: "moving_threats[0].initial_sigma",
        problem: "negative",
    },
    Broken {
        base: "3d-replan-popups",
        from: "kind = \"lead-route\"",
        to: "kind = \"teleport\"",
        key: "events[0].kind",
        problem: "unknown kind",
    },
    Broken {
        base: "3d-replan-popups",
        from: "speed_mps = 180.0\n\n[[threats]]",
        to: "speed_mps = -180.0\n\n[[threats]]",
        key: "lead.speed_mps",
        problem: "positive",
    },
    Broken {
        base: "3d-replan-popups",
        from: "nz_min = -1.0",
        to: "nz_min = 1.5",
        key: "vehicle.nz_min",
        problem: "level flight",
    },
    Broken {
        base: "2d-min-time-avoidable",
        from: "[final]",
        to: "[finale]",
        key: "finale",
        problem: "unknown key",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "beta = 0.95",
        to: "beta = 1.5",
        key: "weights.beta",
        problem: "[0, 1]",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "[weights]",
        to: "[weights",
        key: "(toml)",
        problem: "not valid TOML",
    },
    Broken {
        base: "3d-replan-popups",
        from: "gamma_max_deg = 30.0",
        to: "gamma_max_deg = 95.0",
        key: "vehicle.gamma_max_deg",
        problem: "below 90",
    },
    Broken {
        base: "3d-min-time-moving-threat",
        from: "seed = 7",
        to: "seed = -7",
        key: "moving_threats[0].truth.seed",
        problem: "non-negative integer",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "stiffness = 30.0\n",
        to: "stiffness = 30.0\n[wind]\ngusts = \"stormy\"\n",
        key: "wind.gusts",
        problem: "unknown intensity",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "stiffness = 30.0\n",
        to: "stiffness = 30.0\n[wind]\ngusts = \"light\"\ngust_sigma_mps = 2.0\n",
        key: "wind.gust_sigma_mps",
        problem: "not both",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "stiffness = 30.0\n",
        to: "stiffness = 30.0\n[wind]\nmean_mps = [1.0, 2.0, 3.0]\n",
        key: "wind.mean_mps",
        problem: "list of 2 numbers",
    },
    Broken {
        base: "2d-fixed-time-avoidable",
        from: "stiffness = 30.0\n",
        to: "stiffness = 30.0\n[aircraft]\nbank_rate_max_dps = 30.0\n",
        key: "aircraft.bank_rate_max_dps",
        problem: "unknown key",
    },
    Broken {
        base: "3d-replan-popups",
        from: "stiffness = 30.0\n",
        to: "stiffness = 30.0\n[aircraft]\nresponse_s = -0.5\n",
        key: "aircraft.response_s",
        problem: "must not be negative",
    },
    Broken {
        base: "3d-replan-popups",
        from: "stiffness = 30.0\n",
        to: "stiffness = 30.0\n[aircraft]\nseed = 1.5\n",
        key: "aircraft.seed",
        problem: "non-negative integer",
    },
];

#[test]
fn broken_variants_are_refused_naming_the_key() {
    assert!(BROKEN.len() >= 10);
    let dir = std::env::temp_dir().join(format!("wingman-broken-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (i, b) in BROKEN.iter().enumerate() {
        let text =
            std::fs::read_to_string(scenarios_dir().join(format!("{}.toml", b.base))).unwrap();
        assert!(
            text.contains(b.from),
            "variant {i}: {:?} not in {}",
            b.from,
            b.base
        );
        let broken = text.replacen(b.from, b.to, 1);
        let path = dir.join(format!("broken-{i}.toml"));
        std::fs::write(&path, broken).unwrap();
        let err =
            Scenario::load(&path).expect_err(&format!("variant {i} ({}) must be refused", b.key));
        assert_eq!(err.key, b.key, "variant {i}: {err}");
        assert!(err.problem.contains(b.problem), "variant {i}: {err}");
        let message = err.to_string();
        assert!(
            message.contains(&path.display().to_string()),
            "names the file: {message}"
        );
        assert!(message.contains(b.key), "names the key: {message}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_missing_file_is_an_error_not_a_panic() {
    let err = Scenario::load("/nonexistent/x.toml").unwrap_err();
    assert_eq!(err.key, "(file)");
    assert!(err.to_string().contains("/nonexistent/x.toml"));
}

#[test]
fn more_static_threats_than_the_planner_holds_are_refused() {
    let base = std::fs::read_to_string(scenarios_dir().join("2d-min-time-avoidable.toml")).unwrap();
    let with = |n: usize| {
        let mut text = base.clone();
        for k in 0..n {
            text.push_str(&format!(
                "\n[[threats]]\nname = \"extra-{k}\"\ncenter_m = [{}.0, -90000.0]\naxes_m = [1000.0, 1000.0]\n",
                10_000 * k
            ));
        }
        Scenario::parse(&text, "many.toml")
    };
    let known = with(0).unwrap().threats.len();
    let room = wingman_planning::threat::MAX_THREATS - known;
    assert_eq!(with(room).unwrap().threats.len(), 16);
    let err = with(room + 1).unwrap_err();
    assert_eq!(err.key, "threats");
    assert!(err.problem.contains("17 static threats"), "{err}");
}

/// `[wind]` and `[aircraft]` are read in SI units and radians, with their defaults; a
/// canonical file has neither (still air, the planner's model).
#[test]
fn wind_and_aircraft_tables_are_read_in_si() {
    let dir = std::env::temp_dir().join(format!("wingman-windy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let deg = std::f64::consts::PI / 180.0;
    let base =
        std::fs::read_to_string(scenarios_dir().join("2d-fixed-time-avoidable.toml")).unwrap();
    let plain = Scenario::load(scenarios_dir().join("2d-fixed-time-avoidable.toml")).unwrap();
    assert!(plain.wind.is_none() && plain.aircraft.is_none());
    let windy = format!(
        "{base}\n[wind]\nmean_mps = [10.0, -12.0]\ngusts = \"moderate\"\nseed = 11\n\
         [aircraft]\nresponse_s = 0.8\nturn_accel_max_dps2 = 2.0\nnav_sigma_m = 10.0\n\
         nav_heading_sigma_deg = 0.2\nseed = 5\n"
    );
    let path = dir.join("windy.toml");
    std::fs::write(&path, windy).unwrap();
    let sc = Scenario::load(&path).unwrap();
    let wind = sc.wind.unwrap();
    assert_eq!(wind.mean_mps, [10.0, -12.0, 0.0]);
    assert_eq!(wind.gust_sigma_mps, 3.0);
    assert_eq!(wind.gust_length_m, GUST_LENGTH_M);
    assert_eq!(wind.seed, 11);
    let a = sc.aircraft.unwrap();
    assert_eq!(a.response_s, 0.8);
    assert!((a.turn_accel_max - 2.0 * deg).abs() < 1e-15);
    assert!((a.nav_heading_sigma - 0.2 * deg).abs() < 1e-15);
    assert_eq!((a.nav_sigma_m, a.nav_tau_s, a.seed), (10.0, 1.0, 5));

    // 3-D: a horizontal mean is enough; the rate limits default to the vehicle's.
    let base = std::fs::read_to_string(scenarios_dir().join("3d-replan-popups.toml")).unwrap();
    let path = dir.join("windy-3d.toml");
    std::fs::write(
        &path,
        format!("{base}\n[wind]\nmean_mps = [5.0, 0.0]\n[aircraft]\nresponse_s = 0.3\n"),
    )
    .unwrap();
    let sc = Scenario::load(&path).unwrap();
    assert_eq!(sc.wind.unwrap().mean_mps, [5.0, 0.0, 0.0]);
    let a = sc.aircraft.unwrap();
    assert_eq!(a.nz_rate_max, sc.vehicle.nz_rate_max_per_s);
    assert_eq!(a.mu_rate_max, sc.vehicle.bank_rate_max_rps);
    assert!(a.turn_accel_max.is_infinite());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `DISTURBED` bundles exactly `scenarios/disturbed/*.toml`, each the same text as its
/// file, each loading, and each with what it is there for.
#[test]
fn the_disturbed_scenarios_are_bundled_and_load() {
    let dir = scenarios_dir().join("disturbed");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().to_string())
        .collect();
    files.sort();
    let names: Vec<String> = DISTURBED.iter().map(|(n, _)| n.to_string()).collect();
    assert_eq!(
        files, names,
        "DISTURBED lists exactly scenarios/disturbed/*.toml"
    );
    for (name, text) in DISTURBED {
        let file = std::fs::read_to_string(dir.join(format!("{name}.toml"))).unwrap();
        assert_eq!(&file, text, "{name}");
        let sc = bundled(name).unwrap().unwrap();
        assert_eq!(sc.name, *name);
        // Each threat keeps its own name (reports and logs name threats by it).
        let threat_names = sc.threats.iter().map(|t| &t.name);
        let moving_names = sc.moving_threats.iter().map(|m| &m.name);
        assert!(
            threat_names.chain(moving_names).all(|n| n != *name),
            "{name}"
        );
    }
    let windy = bundled("2d-fixed-time-windy").unwrap().unwrap();
    assert!(windy.wind.is_some() && windy.objective == Objective::FixedTime);
    let rough = bundled("3d-rendezvous-turbulence").unwrap().unwrap();
    assert!(rough.wind.unwrap().gust_sigma_mps == 3.0 && rough.aircraft.is_some());
    let off = bundled("2d-rendezvous-lead-off-route").unwrap().unwrap();
    assert!(
        off.events
            .iter()
            .any(|e| matches!(e.kind, EventKind::LeadOffRoute { .. }))
    );
    let busy = bundled("2d-four-targets-two-moving-threats")
        .unwrap()
        .unwrap();
    assert!(busy.targets.len() >= 3 && busy.moving_threats.len() >= 2);
}
