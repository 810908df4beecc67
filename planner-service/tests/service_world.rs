//! The world model of the message thread (`service::world::World`) on its own: capacity
//! limits, a threat changing kind, a track fix the filter refuses. Each test names the
//! protection it checks; each fails without it.

mod common;

use std::time::Duration;

use wingman_interfaces::*;
use wingman_planner::service::world::{
    FixOutcome, MAX_MOVING_THREATS, MAX_STATIC_THREATS, ThreatChange, ThreatSlot, World,
};

fn static_report(id: u32, x: f64) -> ThreatReport {
    let mut r = ThreatReport::zeroed();
    r.threat_id = id;
    r.kind = ThreatKind::Static.to_wire();
    r.center_m = [x, 0.0, 0.0];
    r.axes_m = [1000.0, 1000.0, 0.0];
    r.exponents = [2.0, 2.0, 0.0];
    r
}

/// A moving threat of `common`, its estimate at 10 s and a little different
/// per id.
fn moving_report(id: u32) -> ThreatReport {
    let mut r = common::moving_threat(id);
    r.estimate_time_s = 10.0;
    r.estimate_mean[0] += id as f64;
    r
}

const WALL: Duration = Duration::from_secs(1);

/// B8: a threat over capacity is counted (`threats_dropped`, which makes the status
/// `Degraded`), not silently ignored.
#[test]
fn a_threat_over_capacity_is_counted() {
    let mut w = World::default();
    for id in 0..MAX_STATIC_THREATS as u32 {
        assert!(matches!(
            w.apply_threat(&static_report(id, 1000.0 * id as f64), WALL),
            ThreatChange::New(_)
        ));
    }
    assert_eq!(w.threats_dropped, 0);
    assert_eq!(
        w.apply_threat(&static_report(99, 0.0), WALL),
        ThreatChange::Full
    );
    assert_eq!(
        w.apply_threat(&static_report(99, 0.0), WALL),
        ThreatChange::Full
    );
    assert_eq!(w.threats_dropped, 2);
    // A known threat re-reported still fits.
    assert!(matches!(
        w.apply_threat(&static_report(3, 500.0), WALL),
        ThreatChange::Changed(ThreatSlot::Static(_))
    ));
    assert_eq!(w.threats_dropped, 2);
}

/// B8: a static threat re-reported as moving while the moving table is full keeps its
/// static entry (the old entry is removed only once the new one is stored).
#[test]
fn a_kind_change_that_does_not_fit_keeps_the_old_entry() {
    let mut w = World::default();
    assert!(matches!(
        w.apply_threat(&static_report(1, 0.0), WALL),
        ThreatChange::New(ThreatSlot::Static(_))
    ));
    for id in 10..10 + MAX_MOVING_THREATS as u32 {
        assert!(matches!(
            w.apply_threat(&moving_report(id), WALL),
            ThreatChange::New(ThreatSlot::Moving(_))
        ));
    }
    let epoch = w.epoch;
    assert_eq!(w.apply_threat(&moving_report(1), WALL), ThreatChange::Full);
    assert_eq!(
        w.statics().count(),
        1,
        "the static entry of threat 1 is kept"
    );
    assert_eq!(w.epoch, epoch, "nothing changed");
    // With room, the kind change moves it.
    let mut w2 = World::default();
    w2.apply_threat(&static_report(1, 0.0), WALL);
    assert!(matches!(
        w2.apply_threat(&moving_report(1), WALL),
        ThreatChange::New(ThreatSlot::Moving(_))
    ));
    assert_eq!(w2.statics().count(), 0);
}

/// Smaller: a fix refused after the prediction step leaves the filter as it was (not
/// predicted to the fix's time without its update).
#[test]
fn a_refused_fix_leaves_the_filter_unchanged() {
    let mut w = World::default();
    w.apply_threat(&moving_report(5), WALL);
    let (_, before) = w.movings().next().map(|(i, m)| (i, *m.estimate())).unwrap();
    let mut fix = TrackFix::zeroed();
    fix.threat_id = 5;
    fix.time_s = 20.0;
    fix.sigma_m = 50.0;
    fix.position_m = [f64::NAN, 120000.0, 0.0];
    let outcome = w.apply_fix(&fix, WALL);
    assert!(matches!(outcome, FixOutcome::Refused(_)), "{outcome:?}");
    let after = *w.movings().next().unwrap().1.estimate();
    assert_eq!(before, after, "the refused fix changed the estimate");
}
