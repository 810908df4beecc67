use wingman_interfaces::MAX_PHASES;

use super::families::decode;
use super::*;

#[test]
fn labels_read_like_the_reference() {
    let mut l = SeedLabel {
        kind: SeedKind::Arc,
        legs: 2,
        bulges: [0.0; MAX_PHASES],
        altitude: Altitude::Direct,
        spatial: false,
    };
    l.bulges[0] = 0.5;
    l.bulges[1] = -0.5;
    assert_eq!(l.to_string(), "LR@0.5");
    l.bulges[0] = 0.0;
    l.bulges[1] = 0.25;
    l.spatial = true;
    l.altitude = Altitude::High;
    assert_eq!(l.to_string(), "SL@0.25/high");
    l.bulges[0] = -0.5;
    assert_eq!(l.to_string(), "R0.5L0.25/high");
    l.kind = SeedKind::Random(3);
    assert_eq!(l.to_string(), "rand3/high");
}

#[test]
fn decode_enumerates_every_combination() {
    let opts = [0.0, 1.0, -1.0];
    let all: Vec<_> = (0..9).map(|i| decode(i, &opts, 2)).collect();
    for a in &opts {
        for b in &opts {
            assert!(all.iter().any(|p| p[0] == *a && p[1] == *b));
        }
    }
}

/// The early and late profiles of the first leg of `3d-fixed-time-avoidable` (15 km down
/// to a 2 km target): early reaches the target's altitude first at the ramp angle and
/// holds it, late holds the start's altitude and meets the target's at the ramp angle;
/// checked on every point of the leg against the ramp computed here.
#[test]
fn early_and_late_profiles_descend_first_or_last() {
    let sc = crate::scenario::bundled("3d-fixed-time-avoidable")
        .unwrap()
        .unwrap();
    let problem = crate::problem::Problem::from_scenario(&sc).unwrap();
    let settings = SeedSettings::default().with_early_late_profiles(true);
    let mut out = Vec::new();
    seeds(&problem, &settings, &mut out).unwrap();
    let (za, zb) = (sc.start.position_m[2], sc.targets[0][2]);
    let tan = (settings.ramp_gamma_ratio * sc.vehicle.gamma_max_rad).tan();
    let ramp = (za - zb).abs() / tan;
    let mut checked = [0, 0];
    for seed in &out {
        let early = match seed.label.altitude {
            Altitude::Early => true,
            Altitude::Late => false,
            _ => continue,
        };
        let last = seed.gates[0];
        let len = seed.arc[last];
        assert!(ramp < len, "the leg holds the ramp");
        for k in 0..=last {
            let (s, z) = (seed.arc[k], seed.points[k][2]);
            // On the polyline the profile is stretched by at most a few metres in 40 km.
            let (hold_from, hold_to, held) = if early {
                (ramp * 1.01, len, zb)
            } else {
                (0.0, (len - ramp) * 0.99, za)
            };
            if s >= hold_from && s <= hold_to {
                assert!((z - held).abs() < 1.0, "{}: z {z} at s {s}", seed.label);
            }
            let expected_ramp = if early {
                za - s * tan
            } else {
                za - (s - (len - ramp)) * tan
            };
            let on_ramp = if early {
                s < ramp * 0.99
            } else {
                s > (len - ramp) * 1.01
            };
            if on_ramp {
                assert!(
                    (z - expected_ramp).abs() < 0.01 * (za - zb),
                    "{}: z {z} at s {s}",
                    seed.label
                );
            }
        }
        checked[usize::from(early)] += 1;
    }
    assert!(checked[0] > 0 && checked[1] > 0, "{checked:?}");
}

/// The fixed-time slack on one leg: for each leg and side one seed that is the scan's
/// cheapest combination but on that leg, with the length `V (t_f - t_0)` (within 0.1 %,
/// the bisection's and the polyline's tolerance; the length is measured here on the
/// seed's points).
#[test]
fn one_leg_fits_take_all_the_spare_length_on_one_leg() {
    let sc = crate::scenario::bundled("2d-fixed-time-avoidable")
        .unwrap()
        .unwrap();
    let problem = crate::problem::Problem::from_scenario(&sc).unwrap();
    let mut out = Vec::new();
    seeds(&problem, &SeedSettings::default(), &mut out).unwrap();
    let t_f = sc.final_point.as_ref().unwrap().time_s.unwrap();
    let want = sc.vehicle.speed_mps * (t_f - sc.start.time_s);
    let scan = out
        .iter()
        .find(|s| s.label.kind == SeedKind::Scan)
        .expect("a scan seed")
        .label
        .bulges;
    let legs = sc.targets.len() + 1;
    let mut found = vec![[false; 2]; legs];
    for seed in out
        .iter()
        .filter(|s| s.label.kind == SeedKind::FixedTimeFit)
    {
        let b = &seed.label.bulges;
        let others_as_scan = |g: usize| (0..legs).all(|h| h == g || b[h] == scan[h]);
        let Some(g) = (0..legs).find(|&g| b[g] != scan[g] && others_as_scan(g)) else {
            continue;
        };
        let length: f64 = seed
            .points
            .windows(2)
            .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
            .sum();
        assert!(
            (length - want).abs() < 1e-3 * want,
            "{}: length {length} against {want}",
            seed.label
        );
        found[g][usize::from(b[g] < 0.0)] = true;
    }
    assert!(
        found.iter().all(|f| f[0] && f[1]),
        "legs and sides found: {found:?}"
    );
}
