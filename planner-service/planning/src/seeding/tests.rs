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
