//! The geometry a campaign's missions are drawn on: threat footprints and their bounding
//! discs, the points a threat must keep clear of, and the length of a path that avoids
//! every threat (what a fixed final time must leave room for).
//!
//! Every threat is centred on the ground (3-D superquadrics are domes whose horizontal
//! cross-section shrinks with height), so a path that stays outside every footprint's
//! bounding disc is outside every threat at any altitude. Threats of an avoidable layout
//! keep a gap between their discs wide enough for a turn, so such a path always exists.

use std::f64::consts::PI;

/// A threat's footprint on the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    pub center: [f64; 2],
    /// Semi-axes in the threat's own frame, m.
    pub axes: [f64; 2],
    /// The horizontal exponent (2: ellipse; larger: closer to a rectangle).
    pub exponent: f64,
    pub yaw_deg: f64,
}

impl Footprint {
    /// Radius of a disc about the centre that holds the footprint.
    pub fn radius(&self) -> f64 {
        let [a, b] = self.axes;
        if self.exponent <= 2.0 {
            a.max(b)
        } else {
            a.hypot(b)
        }
    }

    /// Whether the footprint's disc, widened by `margin`, keeps clear of `p`.
    pub fn clear_of(&self, p: [f64; 2], margin: f64) -> bool {
        dist(self.center, p) >= self.radius() + margin
    }

    /// Whether the two footprints' discs are at least `gap` apart.
    pub fn apart(&self, other: &Footprint, gap: f64) -> bool {
        dist(self.center, other.center) >= self.radius() + other.radius() + gap
    }
}

/// The horizontal part of a point.
pub fn xy(p: &[f64; 3]) -> [f64; 2] {
    [p[0], p[1]]
}

/// Distance of two points, m.
pub fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Horizontal distance of `p` from the segment `a`–`b`, m (the flight report's too).
pub fn segment_dist(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let r = [p[0] - a[0], p[1] - a[1]];
    let l2 = d[0] * d[0] + d[1] * d[1];
    let s = if l2 > 0.0 {
        ((r[0] * d[0] + r[1] * d[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (r[0] - s * d[0]).hypot(r[1] - s * d[1])
}

/// The point a fraction `f` along `a`–`b`, moved `side` metres to its left.
pub fn along(a: [f64; 2], b: [f64; 2], f: f64, side: f64) -> [f64; 2] {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len = dx.hypot(dy).max(1.0);
    [
        a[0] + f * dx - side * dy / len,
        a[1] + f * dy + side * dx / len,
    ]
}

/// An upper bound on the length of a path through `legs` (3-D points: the straight legs'
/// lengths) that keeps out of every disc of `discs` and turns at each of the `legs`
/// points with radius `turn_radius`: a disc a leg crosses costs at most the half circle
/// around it instead of its chord (`(π − 2) r`, with some room to spare), each turn at
/// most a full circle's half.
pub fn avoiding_length(legs: &[[f64; 3]], discs: &[([f64; 2], f64)], turn_radius: f64) -> f64 {
    let mut length = 0.0;
    for w in legs.windows(2) {
        let (a, b) = (w[0], w[1]);
        length += ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
        for &(c, r) in discs {
            if segment_dist([a[0], a[1]], [b[0], b[1]], c) < r {
                length += (PI - 1.5) * r;
            }
        }
    }
    length + legs.len() as f64 * PI * turn_radius
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_disc_holds_its_footprint() {
        // Points on the footprint's edge (F = 1) lie within the disc, for every shape.
        for exponent in [2.0, 4.0, 8.0] {
            let fp = Footprint {
                center: [1000.0, -2000.0],
                axes: [5000.0, 3000.0],
                exponent,
                yaw_deg: 30.0,
            };
            for k in 0..64 {
                let t = 2.0 * PI * k as f64 / 64.0;
                // The superellipse's edge in its own frame.
                let (c, s) = (t.cos(), t.sin());
                let x = fp.axes[0] * c.signum() * c.abs().powf(2.0 / exponent);
                let y = fp.axes[1] * s.signum() * s.abs().powf(2.0 / exponent);
                let r = x.hypot(y);
                assert!(
                    r <= fp.radius() + 1e-9,
                    "p {exponent}: {r} > {}",
                    fp.radius()
                );
            }
        }
    }

    #[test]
    fn the_avoiding_length_adds_detours_only_for_crossed_discs() {
        let legs = [[0.0, 0.0, 0.0], [100_000.0, 0.0, 0.0]];
        let none = avoiding_length(&legs, &[], 0.0);
        assert!((none - 100_000.0).abs() < 1e-6);
        let off = avoiding_length(&legs, &[([50_000.0, 20_000.0], 5000.0)], 0.0);
        assert!((off - 100_000.0).abs() < 1e-6);
        let on = avoiding_length(&legs, &[([50_000.0, 1000.0], 5000.0)], 0.0);
        // Around the half circle (π r) instead of the chord (< 2 r): at most (π − 2) r.
        assert!(on - 100_000.0 >= (PI - 2.0) * 5000.0);
        assert!((segment_dist([0.0, 0.0], [10.0, 0.0], [5.0, 3.0]) - 3.0).abs() < 1e-12);
        let p = along([0.0, 0.0], [10.0, 0.0], 0.5, 2.0);
        assert!((p[0] - 5.0).abs() < 1e-12 && (p[1] - 2.0).abs() < 1e-12);
    }
}
