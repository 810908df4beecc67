//! A scenario's content as the messages that carry it: the tasking the lead's datalink
//! sends and the threat reports the sensor sends. The harness sends these; the tests build
//! their inputs with them.

use wingman_interfaces::{
    MAX_TARGETS, Model, Tasking, ThreatKind, ThreatReport, Wire, threat_name,
};

use super::{FinalPoint, Scenario, StaticThreatSpec};

/// A tasking with more targets than a message holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("a tasking of {0} targets: a tasking holds at most {MAX_TARGETS}")]
pub struct TooManyTargets(pub usize);

/// The tasking of `sc` with `targets` and `final_point` (header left for the sender); in
/// 2-D the targets' third coordinate is 0. The wind to plan in is the mean of the
/// scenario's `[wind]` (the gusts are not known ahead).
pub fn tasking(
    sc: &Scenario,
    revision: u32,
    targets: &[[f64; 3]],
    final_point: Option<&FinalPoint>,
) -> Result<Tasking, TooManyTargets> {
    if targets.len() > MAX_TARGETS {
        return Err(TooManyTargets(targets.len()));
    }
    let mut t = Tasking::zeroed();
    t.revision = revision;
    t.model = sc.model.to_wire();
    t.objective = sc.objective.to_wire();
    t.limits = sc.vehicle;
    t.weights = sc.weights;
    t.start_time_s = sc.start.time_s;
    t.start_state = sc.start.state(sc.model);
    if let Some(f) = final_point {
        t.final_state = f.state(sc.model);
        t.final_time_s = f.time_s.unwrap_or(0.0);
    }
    if let Some(w) = &sc.wind {
        t.wind_mps = w.mean_mps;
    }
    t.target_count = targets.len() as u32;
    for (slot, p) in t.targets_m.iter_mut().zip(targets) {
        *slot = *p;
        if sc.model == Model::TwoD {
            slot[2] = 0.0;
        }
    }
    Ok(t)
}

/// The take-off tasking of `sc`: its own targets and final point (a loaded scenario holds
/// at most [`MAX_TARGETS`] targets, so this cannot fail).
pub fn take_off_tasking(sc: &Scenario, revision: u32) -> Tasking {
    tasking(sc, revision, &sc.targets, sc.final_point.as_ref())
        .unwrap_or_else(|e| unreachable!("the scenario loader refuses {e}"))
}

/// A report of threat `id`, of `kind`, named `name`, its other fields zero.
pub fn threat_report(id: u32, kind: ThreatKind, name: &str) -> ThreatReport {
    let mut r = ThreatReport::zeroed();
    r.threat_id = id;
    r.kind = kind.to_wire();
    r.name = threat_name(name);
    r
}

/// The report of static threat `s` under id `id`.
pub fn static_threat_report(id: u32, s: &StaticThreatSpec) -> ThreatReport {
    let mut r = threat_report(id, ThreatKind::Static, &s.name);
    r.center_m = s.center_m;
    r.axes_m = s.axes_m;
    r.exponents = s.exponents;
    r.yaw_rad = s.yaw_rad;
    r
}

/// The reports of the static threats of `sc` known at take-off, ids from 1.
pub fn take_off_threat_reports(sc: &Scenario) -> Vec<ThreatReport> {
    sc.known_static_threats()
        .enumerate()
        .map(|(k, s)| static_threat_report(k as u32 + 1, s))
        .collect()
}
