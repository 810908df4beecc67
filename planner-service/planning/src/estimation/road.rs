//! The road a moving threat drives on: a polyline with its distance along it, the point
//! and direction at a distance, and the projection of a position onto it (eq. 6.2).

use super::{EstimationError, MAX_ROAD_POINTS};

/// A point on the road with the road's direction there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoadPoint<const D: usize> {
    /// Position.
    pub point: [f64; D],
    /// Yaw of the segment (horizontal direction, counter-clockwise from +x), rad.
    pub yaw: f64,
    /// Unit tangent of the segment (with its vertical part in 3-D).
    pub direction: [f64; D],
}

/// A road polyline of 2 to [`MAX_ROAD_POINTS`] points (fixed capacity, `Copy`).
///
/// Distance runs along the polyline (eq. 6.2, in all `D` coordinates) from its first
/// point; before the start and past the end the first and last segments are extended, as
/// `scenario.py` does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Road<const D: usize> {
    points: [[f64; D]; MAX_ROAD_POINTS],
    /// Distance at each point; `cum[0] = 0`.
    cum: [f64; MAX_ROAD_POINTS],
    len: usize,
}

impl<const D: usize> Road<D> {
    /// A road through `points`: 2 to [`MAX_ROAD_POINTS`] finite points, consecutive ones
    /// differing horizontally.
    pub fn new(points: &[[f64; D]]) -> Result<Self, EstimationError> {
        const { assert!(D == 2 || D == 3, "roads are 2-D or 3-D") };
        if points.len() < 2 {
            return Err(EstimationError::RoadTooShort { got: points.len() });
        }
        if points.len() > MAX_ROAD_POINTS {
            return Err(EstimationError::RoadTooLong {
                got: points.len(),
                max: MAX_ROAD_POINTS,
            });
        }
        if points.iter().flatten().any(|v| !v.is_finite()) {
            return Err(EstimationError::NotFinite {
                field: "road point",
            });
        }
        let mut road = Self {
            points: [[0.0; D]; MAX_ROAD_POINTS],
            cum: [0.0; MAX_ROAD_POINTS],
            len: points.len(),
        };
        road.points[..points.len()].copy_from_slice(points);
        for k in 1..points.len() {
            let (a, b) = (&points[k - 1], &points[k]);
            if (b[0] - a[0]).hypot(b[1] - a[1]) <= 0.0 {
                return Err(EstimationError::DegenerateSegment { index: k - 1 });
            }
            road.cum[k] = road.cum[k - 1] + dist(a, b);
        }
        Ok(road)
    }

    /// The road's points.
    pub fn points(&self) -> &[[f64; D]] {
        &self.points[..self.len]
    }

    /// Length of the polyline.
    pub fn length(&self) -> f64 {
        self.cum[self.len - 1]
    }

    /// Segment holding distance `d`: the last `k` with `cum[k] <= d`, clamped to the
    /// segments (`searchsorted(..., side="right") - 1` clipped, as in `scenario.py`).
    #[inline]
    pub fn segment_at(&self, d: f64) -> usize {
        let nseg = self.len - 1;
        let mut k = 0;
        while k + 1 < nseg && self.cum[k + 1] <= d {
            k += 1;
        }
        k
    }

    /// The point at distance `d` along the road (extrapolated past the ends) with the yaw
    /// and unit tangent of its segment.
    #[inline]
    pub fn point_at(&self, d: f64) -> RoadPoint<D> {
        let k = self.segment_at(d);
        let (a, b) = (&self.points[k], &self.points[k + 1]);
        let l = self.cum[k + 1] - self.cum[k];
        let frac = (d - self.cum[k]) / l;
        RoadPoint {
            point: std::array::from_fn(|i| a[i] + frac * (b[i] - a[i])),
            yaw: (b[1] - a[1]).atan2(b[0] - a[0]),
            direction: std::array::from_fn(|i| (b[i] - a[i]) / l),
        }
    }

    /// Distance along the road of the road point nearest to `w` (the first and last
    /// segments extended past the ends): the table look-up of a sensor fix (dissertation
    /// §6.3.2; docs/FORMULATION.md §5).
    pub fn project(&self, w: &[f64; D]) -> f64 {
        let nseg = self.len - 1;
        let mut best = (f64::INFINITY, 0.0);
        for k in 0..nseg {
            let (a, b) = (&self.points[k], &self.points[k + 1]);
            let seg: [f64; D] = std::array::from_fn(|i| b[i] - a[i]);
            let rel: [f64; D] = std::array::from_fn(|i| w[i] - a[i]);
            let l2: f64 = seg.iter().map(|v| v * v).sum();
            let mut t = seg.iter().zip(&rel).map(|(s, r)| s * r).sum::<f64>() / l2;
            if k > 0 {
                t = t.max(0.0);
            }
            if k + 1 < nseg {
                t = t.min(1.0);
            }
            let d2: f64 = (0..D).map(|i| (rel[i] - t * seg[i]).powi(2)).sum();
            if d2 < best.0 {
                best = (d2, self.cum[k] + t * (self.cum[k + 1] - self.cum[k]));
            }
        }
        best.1
    }
}

fn dist<const D: usize>(a: &[f64; D], b: &[f64; D]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (y - x) * (y - x))
        .sum::<f64>()
        .sqrt()
}
