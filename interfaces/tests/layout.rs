//! The byte layout of every wire type is pinned here: sizes, alignments, every field's
//! offset (written out by hand), and the golden bytes of one filled instance. Moving,
//! resizing or retyping a field fails these tests; so does a `docs/INTERFACES.md` that no
//! longer matches the code.
//!
//! After an intended change of the contract (bump `PROTOCOL_VERSION`!), regenerate the
//! golden files and the document with `WINGMAN_BLESS=1 cargo test -p wingman-interfaces`.

mod common;

use std::fmt::Write as _;
use std::mem::{align_of, size_of};
use std::path::PathBuf;
use wingman_interfaces::layout::Wire;
use wingman_interfaces::*;

fn offsets<T: Wire>() -> Vec<(&'static str, usize)> {
    T::fields().iter().map(|f| (f.name, f.offset)).collect()
}

#[track_caller]
fn pin<T: Wire>(size: usize, align: usize, expected: &[(&str, usize)]) {
    assert_eq!(size_of::<T>(), size, "size of {}", T::NAME);
    assert_eq!(align_of::<T>(), align, "alignment of {}", T::NAME);
    let got = offsets::<T>();
    let want: Vec<(&str, usize)> = expected.to_vec();
    assert_eq!(got, want, "field offsets of {}", T::NAME);
}

#[test]
fn header_layout() {
    pin::<Header>(
        24,
        8,
        &[
            ("protocol_version", 0),
            ("sender_id", 4),
            ("sequence", 8),
            ("mission_time_ns", 16),
        ],
    );
}

#[test]
fn tasking_layout() {
    pin::<VehicleLimits>(
        72,
        8,
        &[
            ("speed_mps", 0),
            ("turn_rate_max_rps", 8),
            ("gamma_max_rad", 16),
            ("nz_min", 24),
            ("nz_max", 32),
            ("bank_max_rad", 40),
            ("nz_rate_max_per_s", 48),
            ("bank_rate_max_rps", 56),
            ("altitude_min_m", 64),
        ],
    );
    pin::<Weights>(24, 8, &[("alpha", 0), ("beta", 8), ("stiffness", 16)]);
    pin::<Tasking>(
        480,
        8,
        &[
            ("header", 0),
            ("revision", 24),
            ("model", 28),
            ("objective", 32),
            ("target_count", 36),
            ("limits", 40),
            ("weights", 112),
            ("start_time_s", 136),
            ("start_state", 144),
            ("final_state", 200),
            ("final_time_s", 256),
            ("targets_m", 264),
            ("wind_mps", 456),
        ],
    );
}

#[test]
fn lead_layouts() {
    pin::<LeadState>(
        88,
        8,
        &[
            ("header", 0),
            ("time_s", 24),
            ("position_m", 32),
            ("heading_rad", 56),
            ("gamma_rad", 64),
            ("speed_mps", 72),
            ("route_revision", 80),
            ("reserved", 84),
        ],
    );
    pin::<LeadRoute>(
        432,
        8,
        &[
            ("header", 0),
            ("revision", 24),
            ("point_count", 28),
            ("start_time_s", 32),
            ("speed_mps", 40),
            ("points_m", 48),
        ],
    );
}

#[test]
fn threat_layout() {
    pin::<ThreatReport>(
        656,
        8,
        &[
            ("header", 0),
            ("threat_id", 24),
            ("kind", 28),
            ("appeared_at_s", 32),
            ("name", 40),
            ("center_m", 64),
            ("axes_m", 88),
            ("exponents", 112),
            ("yaw_rad", 136),
            ("road_point_count", 144),
            ("reserved", 148),
            ("road_m", 152),
            ("estimate_time_s", 536),
            ("estimate_mean", 544),
            ("estimate_covariance", 568),
            ("accel_sigma_mps2", 640),
            ("accel_tau_s", 648),
        ],
    );
}

#[test]
fn track_and_ownship_layouts() {
    pin::<TrackFix>(
        72,
        8,
        &[
            ("header", 0),
            ("threat_id", 24),
            ("reserved", 28),
            ("time_s", 32),
            ("position_m", 40),
            ("sigma_m", 64),
        ],
    );
    pin::<OwnshipState>(
        144,
        8,
        &[
            ("header", 0),
            ("time_s", 24),
            ("model", 32),
            ("flags", 36),
            ("plan_id", 40),
            ("state", 48),
            ("control", 104),
            ("cross_track_m", 120),
            ("along_track_m", 128),
            ("vertical_m", 136),
        ],
    );
}

#[test]
fn plan_layout() {
    pin::<PlanSample>(80, 8, &[("t_s", 0), ("state", 8), ("control", 64)]);
    pin::<PlanCut>(8, 4, &[("site", 0), ("step", 4)]);
    pin::<Plan>(
        704 + 80 * MAX_PLAN_SAMPLES,
        8,
        &[
            ("header", 0),
            ("plan_id", 24),
            ("trigger", 32),
            ("quality", 36),
            ("model", 40),
            ("phase_count", 44),
            ("sample_count", 48),
            ("has_next_replan", 52),
            ("path", 56),
            ("cut_count", 60),
            ("created_at_s", 64),
            ("start_time_s", 72),
            ("valid_until_s", 80),
            ("cost", 88),
            ("final_time_s", 96),
            ("compute_ms", 104),
            ("next_replan_s", 112),
            ("phase_end_s", 120),
            ("cuts", 192),
            ("samples", 704),
        ],
    );
    const { assert!(MAX_PLAN_SAMPLES >= 512) };
}

#[test]
fn status_layout() {
    pin::<PlannerStatus>(
        120,
        8,
        &[
            ("header", 0),
            ("state", 24),
            ("stale_inputs", 28),
            ("last_input_sequence", 32),
            ("current_plan_id", 40),
            ("messages_received", 48),
            ("messages_rejected", 56),
            ("messages_lost", 64),
            ("plans_made", 72),
            ("triggers_coalesced", 80),
            ("triggers_deferred", 88),
            ("popups_clear", 96),
            ("last_plan_compute_ms", 104),
            ("budget_remaining_ms", 112),
        ],
    );
}

fn bless() -> bool {
    std::env::var_os("WINGMAN_BLESS").is_some()
}

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Hex dump of the 16-byte rows that are not all zero: `offset: bytes`.
fn dump(bytes: &[u8]) -> String {
    let mut out = format!("# {} bytes; rows of zeros omitted\n", bytes.len());
    for (k, row) in bytes.chunks(16).enumerate() {
        if row.iter().any(|&b| b != 0) {
            let _ = write!(out, "{:08x}:", k * 16);
            for b in row {
                let _ = write!(out, " {b:02x}");
            }
            out.push('\n');
        }
    }
    out
}

#[track_caller]
fn golden<T: Wire + PartialEq + std::fmt::Debug>(file: &str, value: &T) {
    let path = crate_dir().join("tests/golden").join(file);
    let got = dump(value.as_bytes());
    if bless() {
        std::fs::write(&path, &got).expect("write golden file");
        return;
    }
    let want = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (WINGMAN_BLESS=1 writes it)", path.display()));
    assert_eq!(
        got,
        want,
        "golden bytes of {} differ from {}",
        T::NAME,
        path.display()
    );
    // And the bytes read back to the same value.
    assert_eq!(
        &T::read_from_bytes(value.as_bytes()).expect("length"),
        value
    );
}

#[test]
fn golden_bytes() {
    golden("tasking.hex", &common::tasking());
    golden("lead_state.hex", &common::lead_state());
    golden("lead_route.hex", &common::lead_route());
    golden("threat_static.hex", &common::threat_static());
    golden("threat_moving.hex", &common::threat_moving());
    golden("track_fix.hex", &common::track_fix());
    golden("ownship.hex", &common::ownship());
    golden("plan.hex", &common::plan());
    golden("status.hex", &common::status());
}

const BEGIN: &str =
    "<!-- BEGIN GENERATED: cargo test -p wingman-interfaces (WINGMAN_BLESS=1 rewrites) -->";
const END: &str = "<!-- END GENERATED -->";

#[test]
fn interfaces_document_matches_the_code() {
    let path = crate_dir().join("../docs/INTERFACES.md");
    let text = std::fs::read_to_string(&path).expect("docs/INTERFACES.md");
    let (head, rest) = text
        .split_once(BEGIN)
        .expect("BEGIN marker in docs/INTERFACES.md");
    let (body, tail) = rest
        .split_once(END)
        .expect("END marker in docs/INTERFACES.md");
    let generated = format!("\n{}", interfaces_markdown());
    if bless() {
        std::fs::write(&path, format!("{head}{BEGIN}{generated}{END}{tail}")).expect("write doc");
        return;
    }
    assert!(
        body == generated,
        "docs/INTERFACES.md is out of date with the code; run WINGMAN_BLESS=1 cargo test -p \
         wingman-interfaces and review the diff"
    );
}

#[test]
fn every_example_is_valid() {
    common::tasking().validate().unwrap();
    common::lead_state().validate().unwrap();
    common::lead_route().validate().unwrap();
    common::threat_static().validate().unwrap();
    common::threat_moving().validate().unwrap();
    common::track_fix().validate().unwrap();
    common::ownship().validate().unwrap();
    common::plan().validate().unwrap();
    common::status().validate().unwrap();
}

#[test]
fn service_names_are_per_vehicle() {
    assert_eq!(
        service_name("w1", Service::Plan).unwrap(),
        "wingman/w1/plan"
    );
    assert_eq!(
        service_name("w1", Service::LeadRoute).unwrap(),
        "wingman/w1/lead/route"
    );
    let a: Vec<String> = Service::ALL
        .iter()
        .map(|s| service_name("a", *s).unwrap())
        .collect();
    let b: Vec<String> = Service::ALL
        .iter()
        .map(|s| service_name("b", *s).unwrap())
        .collect();
    let mut all: Vec<&String> = a.iter().chain(b.iter()).collect();
    all.sort();
    all.dedup();
    assert_eq!(all.len(), 2 * Service::ALL.len(), "names collide");
    assert_eq!(service_name("", Service::Plan), Err(VehicleIdError::Empty));
    assert_eq!(
        service_name("a/b", Service::Plan),
        Err(VehicleIdError::BadCharacter('/'))
    );
    assert_eq!(
        service_name(&"x".repeat(65), Service::Plan),
        Err(VehicleIdError::TooLong)
    );
}
