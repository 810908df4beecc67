//! The lead's path over time: it flies a polyline at constant speed, at the first point at
//! `t0`, and keeps its last heading past the last point (scenarios/FORMAT.md; the judge's
//! `Lead.state`). Before `t0` it waits at the first point.

use wingman_interfaces::MAX_ROUTE_POINTS;

/// A lead route that cannot be flown.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LeadError {
    #[error("a lead route needs 2 to {MAX_ROUTE_POINTS} points, got {0}")]
    PointCount(usize),
    #[error("lead route point {0} does not differ horizontally from the one before it")]
    Repeated(usize),
    #[error("the lead's speed must be finite and positive, got {0}")]
    Speed(f64),
    #[error("a lead route value is not finite")]
    NotFinite,
}

/// The lead's state at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeadPoint {
    /// Position `[x, y, z]` (z = 0 in 2-D).
    pub position: [f64; 3],
    /// Velocity `[x', y', z']`: the derivative of `position` with respect to time.
    pub velocity: [f64; 3],
    /// Heading, counter-clockwise from +x.
    pub heading: f64,
    /// Flight-path angle (0 in 2-D).
    pub gamma: f64,
}

/// A lead route, in fixed-capacity storage (`Copy`, no heap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LeadPath {
    points: [[f64; 3]; MAX_ROUTE_POINTS],
    /// Cumulative 3-D length at each point.
    cumulative: [f64; MAX_ROUTE_POINTS],
    len: usize,
    speed: f64,
    t0: f64,
}

impl LeadPath {
    /// The lead flying `route` (2 to `MAX_ROUTE_POINTS` points, `z = 0` in 2-D) at `speed`,
    /// at `route[0]` at time `t0`.
    pub fn new(route: &[[f64; 3]], speed: f64, t0: f64) -> Result<LeadPath, LeadError> {
        if !(2..=MAX_ROUTE_POINTS).contains(&route.len()) {
            return Err(LeadError::PointCount(route.len()));
        }
        if !(speed.is_finite() && speed > 0.0) {
            return Err(LeadError::Speed(speed));
        }
        if !t0.is_finite() || route.iter().flatten().any(|v| !v.is_finite()) {
            return Err(LeadError::NotFinite);
        }
        let mut points = [[0.0; 3]; MAX_ROUTE_POINTS];
        let mut cumulative = [0.0; MAX_ROUTE_POINTS];
        points[..route.len()].copy_from_slice(route);
        for k in 1..route.len() {
            let (a, b) = (route[k - 1], route[k]);
            if (b[0] - a[0]).hypot(b[1] - a[1]) <= 0.0 {
                return Err(LeadError::Repeated(k));
            }
            cumulative[k] = cumulative[k - 1] + distance(&a, &b);
        }
        Ok(LeadPath {
            points,
            cumulative,
            len: route.len(),
            speed,
            t0,
        })
    }

    /// The route's points.
    pub fn route(&self) -> &[[f64; 3]] {
        &self.points[..self.len]
    }

    /// The lead's speed.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Time at which the lead is at the first point.
    pub fn t0(&self) -> f64 {
        self.t0
    }

    /// The lead's state at time `t` (allocation-free).
    pub fn at(&self, t: f64) -> LeadPoint {
        let moving = t >= self.t0;
        let dist = self.speed * (t - self.t0).max(0.0);
        // Segment k spans cumulative[k]..cumulative[k + 1]; the last one extends forever.
        let last = self.len - 2;
        let mut k = 0;
        while k < last && dist >= self.cumulative[k + 1] {
            k += 1;
        }
        let (a, b) = (self.points[k], self.points[k + 1]);
        let seg_len = self.cumulative[k + 1] - self.cumulative[k];
        let frac = (dist - self.cumulative[k]) / seg_len;
        let dir = [
            (b[0] - a[0]) / seg_len,
            (b[1] - a[1]) / seg_len,
            (b[2] - a[2]) / seg_len,
        ];
        let v = if moving { self.speed } else { 0.0 };
        LeadPoint {
            position: [
                a[0] + frac * (b[0] - a[0]),
                a[1] + frac * (b[1] - a[1]),
                a[2] + frac * (b[2] - a[2]),
            ],
            velocity: [v * dir[0], v * dir[1], v * dir[2]],
            heading: (b[1] - a[1]).atan2(b[0] - a[0]),
            gamma: (b[2] - a[2]).atan2((b[0] - a[0]).hypot(b[1] - a[1])),
        }
    }
}

/// The straight-line distance between two points, m.
pub(crate) fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hand-computed states on a two-segment route (1e-9 absolute).
    #[test]
    fn states_along_a_bent_route() {
        let lead = LeadPath::new(
            &[
                [0.0, 0.0, 0.0],
                [3000.0, 4000.0, 0.0],
                [3000.0, 9000.0, 0.0],
            ],
            100.0,
            10.0,
        )
        .unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        let p = lead.at(5.0); // before t0: waits at the first point
        assert_eq!(p.position, [0.0, 0.0, 0.0]);
        assert_eq!(p.velocity, [0.0, 0.0, 0.0]);
        let p = lead.at(35.0); // 2500 m along the first leg (3-4-5 triangle)
        assert!(close(p.position[0], 1500.0) && close(p.position[1], 2000.0));
        assert!(close(p.velocity[0], 60.0) && close(p.velocity[1], 80.0));
        assert!(close(p.heading, (4.0f64).atan2(3.0)));
        let p = lead.at(70.0); // 6000 m: 1000 m up the second leg
        assert!(close(p.position[0], 3000.0) && close(p.position[1], 5000.0));
        assert!(close(p.heading, std::f64::consts::FRAC_PI_2));
        let p = lead.at(200.0); // 19000 m: 14000 m up the second leg, 9000 m past its end
        assert!(close(p.position[0], 3000.0) && close(p.position[1], 18000.0));
    }

    /// The velocity is the time derivative of the position (central differences, 1e-6).
    #[test]
    fn velocity_is_the_derivative_of_position() {
        let lead = LeadPath::new(
            &[
                [0.0, 0.0, 100.0],
                [3000.0, 4000.0, 700.0],
                [9000.0, 4000.0, 700.0],
            ],
            150.0,
            0.0,
        )
        .unwrap();
        for t in [1.0, 17.3, 29.0, 45.0, 120.0] {
            let (a, b) = (lead.at(t - 1e-4), lead.at(t + 1e-4));
            let p = lead.at(t);
            for c in 0..3 {
                let fd = (b.position[c] - a.position[c]) / 2e-4;
                assert!((fd - p.velocity[c]).abs() < 1e-6 * 150.0, "t={t} c={c}");
            }
        }
    }

    #[test]
    fn bad_routes_are_refused() {
        assert_eq!(
            LeadPath::new(&[[0.0; 3]], 1.0, 0.0),
            Err(LeadError::PointCount(1))
        );
        assert_eq!(
            LeadPath::new(&[[0.0; 3], [0.0, 0.0, 5.0]], 1.0, 0.0),
            Err(LeadError::Repeated(1))
        );
        assert_eq!(
            LeadPath::new(&[[0.0; 3], [1.0, 0.0, 0.0]], -1.0, 0.0),
            Err(LeadError::Speed(-1.0))
        );
    }
}
