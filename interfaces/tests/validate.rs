//! `validate()` rejects every kind of broken message with a typed error naming the field,
//! for each message type, and never panics on arbitrary bytes.

mod common;

use proptest::prelude::*;
use wingman_interfaces::*;

fn wrong_version<M: Message>(mut m: M, set: impl Fn(&mut M, u32)) {
    set(&mut m, PROTOCOL_VERSION + 1);
    assert_eq!(
        m.validate(),
        Err(ValidationError::ProtocolVersion {
            expected: PROTOCOL_VERSION,
            found: PROTOCOL_VERSION + 1
        }),
        "{}",
        M::NAME
    );
}

#[track_caller]
fn rejects<M: Message>(m: &M, expected: ValidationError) {
    assert_eq!(m.validate(), Err(expected), "{}", M::NAME);
}

#[test]
fn tasking_is_checked() {
    wrong_version(common::tasking(), |m, v| m.header.protocol_version = v);
    let mut m = common::tasking();
    m.weights.beta = f64::NAN;
    rejects(&m, ValidationError::NonFinite { field: "beta" });
    let mut m = common::tasking();
    m.targets_m[7][1] = f64::INFINITY; // an unused slot counts too
    rejects(&m, ValidationError::NonFinite { field: "targets_m" });
    let mut m = common::tasking();
    m.target_count = MAX_TARGETS as u32 + 1;
    rejects(
        &m,
        ValidationError::CountOverCapacity {
            field: "target_count",
            count: 9,
            capacity: 8,
        },
    );
    let mut m = common::tasking();
    m.objective = 7;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "objective",
            value: 7,
        },
    );
    let mut m = common::tasking();
    m.model = 4;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "model",
            value: 4,
        },
    );
    let mut m = common::tasking();
    m.objective = Objective::FixedTime.to_wire();
    m.final_time_s = 0.25; // before start_time_s = 0.5
    rejects(
        &m,
        ValidationError::TimeBackwards {
            field: "final_time_s",
        },
    );
    let mut m = common::tasking();
    m.targets_m[1][2] = 100.0;
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "targets_m",
            ..
        })
    ));
    let mut m = common::tasking();
    m.limits.nz_max = 0.9;
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "limits.nz_min",
            ..
        })
    ));
    let mut m = common::tasking();
    m.weights.alpha = 1.5;
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "weights.alpha",
            ..
        })
    ));
    // A wind as fast as the aircraft leaves no plan; one just slower is accepted.
    let mut m = common::tasking();
    let v = m.limits.speed_mps;
    m.wind_mps = [0.6 * v, 0.8 * v, 0.0];
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "wind_mps",
            ..
        })
    ));
    m.wind_mps = [0.6 * v, 0.79 * v, 0.0];
    assert!(m.validate().is_ok());
    m.wind_mps[2] = f64::NAN;
    rejects(&m, ValidationError::NonFinite { field: "wind_mps" });
}

#[test]
fn lead_messages_are_checked() {
    wrong_version(common::lead_state(), |m, v| m.header.protocol_version = v);
    let mut m = common::lead_state();
    m.position_m[2] = f64::NAN;
    rejects(
        &m,
        ValidationError::NonFinite {
            field: "position_m",
        },
    );
    let mut m = common::lead_state();
    m.speed_mps = -1.0;
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "speed_mps",
            ..
        })
    ));

    wrong_version(common::lead_route(), |m, v| m.header.protocol_version = v);
    let mut m = common::lead_route();
    m.start_time_s = f64::NEG_INFINITY;
    rejects(
        &m,
        ValidationError::NonFinite {
            field: "start_time_s",
        },
    );
    let mut m = common::lead_route();
    m.point_count = 17;
    rejects(
        &m,
        ValidationError::CountOverCapacity {
            field: "point_count",
            count: 17,
            capacity: 16,
        },
    );
    let mut m = common::lead_route();
    m.point_count = 1;
    rejects(
        &m,
        ValidationError::CountTooSmall {
            field: "point_count",
            count: 1,
            minimum: 2,
        },
    );
    let mut m = common::lead_route();
    m.points_m[1] = m.points_m[0];
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "points_m",
            ..
        })
    ));
}

#[test]
fn threat_report_is_checked() {
    wrong_version(common::threat_static(), |m, v| {
        m.header.protocol_version = v
    });
    let mut m = common::threat_static();
    m.yaw_rad = f64::NAN;
    rejects(&m, ValidationError::NonFinite { field: "yaw_rad" });
    let mut m = common::threat_static();
    m.kind = 2;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "kind",
            value: 2,
        },
    );
    let mut m = common::threat_static();
    m.axes_m[0] = -5.0;
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "axes_m",
            ..
        })
    ));
    let mut m = common::threat_moving();
    m.estimate_covariance[4] = f64::NAN;
    rejects(
        &m,
        ValidationError::NonFinite {
            field: "estimate_covariance",
        },
    );
    let mut m = common::threat_moving();
    m.road_point_count = 40;
    rejects(
        &m,
        ValidationError::CountOverCapacity {
            field: "road_point_count",
            count: 40,
            capacity: 16,
        },
    );
    let mut m = common::threat_moving();
    m.estimate_covariance[1] = 99.0; // (0, 1) != (1, 0)
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "estimate_covariance",
            ..
        })
    ));
    let mut m = common::threat_moving();
    m.accel_tau_s = 0.0;
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "accel_tau_s",
            ..
        })
    ));
}

#[test]
fn track_fix_is_checked() {
    wrong_version(common::track_fix(), |m, v| m.header.protocol_version = v);
    let mut m = common::track_fix();
    m.time_s = f64::NAN;
    rejects(&m, ValidationError::NonFinite { field: "time_s" });
    let mut m = common::track_fix();
    m.sigma_m = 0.0;
    assert!(matches!(
        m.validate(),
        Err(ValidationError::OutOfRange {
            field: "sigma_m",
            ..
        })
    ));
}

#[test]
fn ownship_is_checked() {
    wrong_version(common::ownship(), |m, v| m.header.protocol_version = v);
    let mut m = common::ownship();
    m.state[4] = f64::INFINITY;
    rejects(&m, ValidationError::NonFinite { field: "state" });
    let mut m = common::ownship();
    m.model = 0;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "model",
            value: 0,
        },
    );
    let mut m = common::ownship();
    m.flags = 6;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "flags",
            value: 6,
        },
    );
}

#[test]
fn plan_is_checked() {
    wrong_version(common::plan(), |m, v| m.header.protocol_version = v);
    let mut m = common::plan();
    m.samples[1].control[1] = f64::NAN;
    rejects(&m, ValidationError::NonFinite { field: "control" });
    let mut m = common::plan();
    m.sample_count = MAX_PLAN_SAMPLES as u32 + 1;
    rejects(
        &m,
        ValidationError::CountOverCapacity {
            field: "sample_count",
            count: MAX_PLAN_SAMPLES as u32 + 1,
            capacity: MAX_PLAN_SAMPLES as u32,
        },
    );
    let mut m = common::plan();
    m.phase_count = 10;
    rejects(
        &m,
        ValidationError::CountOverCapacity {
            field: "phase_count",
            count: 10,
            capacity: 9,
        },
    );
    let mut m = common::plan();
    m.quality = 9;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "quality",
            value: 9,
        },
    );
    let mut m = common::plan();
    m.trigger = 99;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "trigger",
            value: 99,
        },
    );
    let mut m = common::plan();
    m.path = 2;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "path",
            value: 2,
        },
    );
    let mut m = common::plan();
    m.cut_count = MAX_PLAN_CUTS as u32 + 1;
    rejects(
        &m,
        ValidationError::CountOverCapacity {
            field: "cut_count",
            count: MAX_PLAN_CUTS as u32 + 1,
            capacity: MAX_PLAN_CUTS as u32,
        },
    );
    let mut m = common::plan();
    m.samples[2].t_s = 200.0; // before samples[1]
    rejects(&m, ValidationError::TimeBackwards { field: "samples" });
    let mut m = common::plan();
    m.valid_until_s = 10.0;
    rejects(
        &m,
        ValidationError::TimeBackwards {
            field: "valid_until_s",
        },
    );
}

#[test]
fn status_is_checked() {
    wrong_version(common::status(), |m, v| m.header.protocol_version = v);
    let mut m = common::status();
    m.budget_remaining_ms = f64::NAN;
    rejects(
        &m,
        ValidationError::NonFinite {
            field: "budget_remaining_ms",
        },
    );
    let mut m = common::status();
    m.state = 3;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "state",
            value: 3,
        },
    );
    let mut m = common::status();
    m.stale_inputs = 16;
    rejects(
        &m,
        ValidationError::UnknownEnum {
            field: "stale_inputs",
            value: 16,
        },
    );
}

#[test]
fn header_time_must_not_go_backwards() {
    let a = common::header(1);
    let mut b = common::header(2);
    assert_eq!(b.check_follows(&a), Ok(()));
    b.mission_time_ns = a.mission_time_ns - 1;
    assert_eq!(
        b.check_follows(&a),
        Err(ValidationError::TimeBackwards {
            field: "header.mission_time_ns"
        })
    );
}

#[test]
fn header_sequence_must_grow() {
    let a = common::header(1);
    let mut b = a;
    // A gap is fine (the sender's one counter also numbers its other services).
    b.sequence = a.sequence + 5;
    assert_eq!(b.check_follows(&a), Ok(()));
    for found in [a.sequence, a.sequence - 1] {
        b.sequence = found;
        assert_eq!(
            b.check_follows(&a),
            Err(ValidationError::SequenceNotIncreasing {
                previous: a.sequence,
                found
            }),
            "a repeat or a step back"
        );
    }
}

/// Validates `bytes` read as `M`; a message that passes holds only finite numbers.
fn survives<M: Message>(bytes: &[u8]) {
    let m = M::read_from_bytes(bytes).expect("length");
    if m.validate().is_ok() {
        assert_eq!(m.first_non_finite(), None);
    }
}

fn mutate<M: Message>(m: M, word: usize, value: u64) -> Vec<u8> {
    let mut bytes = m.as_bytes().to_vec();
    let k = (word * 8) % (bytes.len() - 7) / 8 * 8;
    bytes[k..k + 8].copy_from_slice(&value.to_ne_bytes());
    bytes
}

proptest! {
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 700)) {
        survives::<Tasking>(&bytes[..std::mem::size_of::<Tasking>()]);
        survives::<LeadState>(&bytes[..std::mem::size_of::<LeadState>()]);
        survives::<LeadRoute>(&bytes[..std::mem::size_of::<LeadRoute>()]);
        survives::<ThreatReport>(&bytes[..std::mem::size_of::<ThreatReport>()]);
        survives::<TrackFix>(&bytes[..std::mem::size_of::<TrackFix>()]);
        survives::<OwnshipState>(&bytes[..std::mem::size_of::<OwnshipState>()]);
        survives::<PlannerStatus>(&bytes[..std::mem::size_of::<PlannerStatus>()]);
        let mut plan = vec![0u8; std::mem::size_of::<Plan>()];
        plan[..bytes.len()].copy_from_slice(&bytes);
        survives::<Plan>(&plan);
    }

    #[test]
    fn one_arbitrary_field_never_panics(word in 0usize..30_000, value in any::<u64>()) {
        survives::<Tasking>(&mutate(common::tasking(), word, value));
        survives::<LeadState>(&mutate(common::lead_state(), word, value));
        survives::<LeadRoute>(&mutate(common::lead_route(), word, value));
        survives::<ThreatReport>(&mutate(common::threat_static(), word, value));
        survives::<ThreatReport>(&mutate(common::threat_moving(), word, value));
        survives::<TrackFix>(&mutate(common::track_fix(), word, value));
        survives::<OwnshipState>(&mutate(common::ownship(), word, value));
        survives::<Plan>(&mutate(common::plan(), word, value));
        survives::<PlannerStatus>(&mutate(common::status(), word, value));
    }
}
