//! A clamped cubic spline in the horizontal plane through up to [`MAX_NODES`] points,
//! parameterised by Lee's centripetal scheme (the accumulated square root of the chord
//! length, MATLAB's `cscvn` of appendix A), with the end derivatives given as directions
//! (the initial heading and the final heading): MATLAB's `spline` with end slopes.
//!
//! Fixed-capacity storage (`Copy`, no heap): building and evaluating never allocates.

use wingman_interfaces::MAX_PHASES;

/// Most nodes a seed spline holds: the start, then a bulge point and an end point per leg.
pub(crate) const MAX_NODES: usize = 2 * MAX_PHASES + 1;

/// Abscissae and weights of 5-point Gauss–Legendre quadrature on `[0, 1]`.
const GL5: [(f64, f64); 5] = [
    (0.046_910_077_030_668_004, 0.118_463_442_528_094_54),
    (0.230_765_344_947_158_45, 0.239_314_335_249_683_23),
    (0.5, 0.284_444_444_444_444_45),
    (0.769_234_655_052_841_6, 0.239_314_335_249_683_23),
    (0.953_089_922_969_332, 0.118_463_442_528_094_54),
];

/// A C² piecewise-cubic curve `p(tau)` through the nodes (cubic Hermite form).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Spline2 {
    n: usize,
    /// Parameter of each node (`tau_0 = 0`).
    tau: [f64; MAX_NODES],
    /// The nodes.
    p: [[f64; 2]; MAX_NODES],
    /// `dp/dtau` at each node.
    m: [[f64; 2]; MAX_NODES],
}

impl Spline2 {
    /// The clamped spline through `points` (2 to [`MAX_NODES`], consecutive points at
    /// least 1e-6 apart), leaving the first point along `start_heading` and arriving at the
    /// last along `end_heading` (radians, counter-clockwise from +x). `None` when the
    /// points do not qualify.
    // The indices follow the tridiagonal system's notation (rows, coordinates).
    #[allow(clippy::needless_range_loop)]
    pub(crate) fn new(points: &[[f64; 2]], start_heading: f64, end_heading: f64) -> Option<Self> {
        let n = points.len();
        if !(2..=MAX_NODES).contains(&n) {
            return None;
        }
        let mut s = Spline2 {
            n,
            tau: [0.0; MAX_NODES],
            p: [[0.0; 2]; MAX_NODES],
            m: [[0.0; 2]; MAX_NODES],
        };
        s.p[..n].copy_from_slice(points);
        // Centripetal parameterisation; h[i] = tau[i+1] - tau[i].
        let mut h = [0.0; MAX_NODES];
        let mut chord = [0.0; MAX_NODES];
        for i in 0..n - 1 {
            let c = dist2(&points[i], &points[i + 1]);
            if !(c.is_finite() && c >= 1e-6) {
                return None;
            }
            chord[i] = c;
            h[i] = c.sqrt();
            s.tau[i + 1] = s.tau[i] + h[i];
        }
        // End derivatives: the heading direction at the segment's mean parametric speed.
        let (s0, c0) = start_heading.sin_cos();
        let (s1, c1) = end_heading.sin_cos();
        let v0 = chord[0] / h[0];
        let v1 = chord[n - 2] / h[n - 2];
        s.m[0] = [v0 * c0, v0 * s0];
        s.m[n - 1] = [v1 * c1, v1 * s1];
        if n > 2 {
            // Interior slopes of the C² spline (tridiagonal, Thomas algorithm):
            // h_i m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_{i-1} m_{i+1}
            //     = 3 (h_i d_{i-1} + h_{i-1} d_i),   d_i = (p_{i+1} - p_i) / h_i.
            let k = n - 2; // unknowns m_1 ..= m_{n-2}
            let mut diag = [0.0; MAX_NODES];
            let mut upper = [0.0; MAX_NODES];
            let mut rhs = [[0.0; 2]; MAX_NODES];
            for r in 0..k {
                let i = r + 1;
                let (ha, hb) = (h[i - 1], h[i]);
                diag[r] = 2.0 * (ha + hb);
                upper[r] = ha;
                for c in 0..2 {
                    let da = (points[i][c] - points[i - 1][c]) / ha;
                    let db = (points[i + 1][c] - points[i][c]) / hb;
                    rhs[r][c] = 3.0 * (hb * da + ha * db);
                }
                if r == 0 {
                    for c in 0..2 {
                        rhs[r][c] -= hb * s.m[0][c];
                    }
                }
                if r == k - 1 {
                    for c in 0..2 {
                        rhs[r][c] -= ha * s.m[n - 1][c];
                    }
                }
            }
            // Forward sweep: row r has lower coefficient h_{r+1} (= hb of row r).
            for r in 1..k {
                let lower = h[r + 1];
                let w = lower / diag[r - 1];
                diag[r] -= w * upper[r - 1];
                for c in 0..2 {
                    rhs[r][c] -= w * rhs[r - 1][c];
                }
            }
            for r in (0..k).rev() {
                for c in 0..2 {
                    let next = if r + 1 < k { s.m[r + 2][c] } else { 0.0 };
                    let up = if r + 1 < k { upper[r] } else { 0.0 };
                    s.m[r + 1][c] = (rhs[r][c] - up * next) / diag[r];
                }
            }
        }
        s.m[..n]
            .iter()
            .flatten()
            .all(|v| v.is_finite())
            .then_some(s)
    }

    /// Number of nodes.
    pub(crate) fn nodes(&self) -> usize {
        self.n
    }

    /// Position and `dp/dtau` on segment `i` (node `i` to `i + 1`) at fraction `f` in [0, 1].
    pub(crate) fn eval(&self, i: usize, f: f64) -> ([f64; 2], [f64; 2]) {
        let h = self.tau[i + 1] - self.tau[i];
        let (f2, f3) = (f * f, f * f * f);
        let h00 = 2.0 * f3 - 3.0 * f2 + 1.0;
        let h10 = f3 - 2.0 * f2 + f;
        let h01 = -2.0 * f3 + 3.0 * f2;
        let h11 = f3 - f2;
        let d00 = 6.0 * f2 - 6.0 * f;
        let d10 = 3.0 * f2 - 4.0 * f + 1.0;
        let d01 = -6.0 * f2 + 6.0 * f;
        let d11 = 3.0 * f2 - 2.0 * f;
        let (a, b) = (&self.p[i], &self.p[i + 1]);
        let (ma, mb) = (&self.m[i], &self.m[i + 1]);
        let pos =
            std::array::from_fn(|c| h00 * a[c] + h10 * h * ma[c] + h01 * b[c] + h11 * h * mb[c]);
        let der =
            std::array::from_fn(|c| (d00 * a[c] + d01 * b[c]) / h + d10 * ma[c] + d11 * mb[c]);
        (pos, der)
    }

    /// Arc length of segment `i` (5-point Gauss–Legendre on `|p'|` over each half of the
    /// segment: relative error below 1e-7 on the seeds' segments).
    pub(crate) fn segment_length(&self, i: usize) -> f64 {
        let h = self.tau[i + 1] - self.tau[i];
        let mut sum = 0.0;
        for half in [0.0, 0.5] {
            for &(x, w) in &GL5 {
                let (_, d) = self.eval(i, half + 0.5 * x);
                sum += 0.5 * w * (d[0] * d[0] + d[1] * d[1]).sqrt();
            }
        }
        sum * h
    }
}

/// Distance between two horizontal points.
#[inline]
pub(crate) fn dist2(a: &[f64; 2], b: &[f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spline interpolates its nodes, leaves and arrives along the given headings and
    /// is C¹ at interior nodes (1e-9 relative).
    #[test]
    fn interpolates_with_clamped_ends() {
        let pts = [
            [0.0, 0.0],
            [1000.0, 800.0],
            [3000.0, 1000.0],
            [4000.0, -500.0],
        ];
        let s = Spline2::new(&pts, 1.2, -0.7).unwrap();
        for i in 0..3 {
            let (a, _) = s.eval(i, 0.0);
            let (b, _) = s.eval(i, 1.0);
            for c in 0..2 {
                assert!((a[c] - pts[i][c]).abs() < 1e-9 * 4000.0);
                assert!((b[c] - pts[i + 1][c]).abs() < 1e-9 * 4000.0);
            }
        }
        let (_, d0) = s.eval(0, 0.0);
        assert!((d0[1].atan2(d0[0]) - 1.2).abs() < 1e-12);
        let (_, d1) = s.eval(2, 1.0);
        assert!((d1[1].atan2(d1[0]) + 0.7).abs() < 1e-12);
        for i in 1..3 {
            let (_, l) = s.eval(i - 1, 1.0);
            let (_, r) = s.eval(i, 0.0);
            for c in 0..2 {
                assert!((l[c] - r[c]).abs() < 1e-9 * l[c].abs().max(1.0));
            }
        }
        // Second derivative continuity by finite differences of the first.
        let e = 1e-6;
        let (_, la) = s.eval(0, 1.0 - e);
        let (_, lb) = s.eval(0, 1.0);
        let (_, ra) = s.eval(1, 0.0);
        let (_, rb) = s.eval(1, e);
        let hl = s.tau[1] - s.tau[0];
        let hr = s.tau[2] - s.tau[1];
        for c in 0..2 {
            let sl = (lb[c] - la[c]) / (e * hl);
            let sr = (rb[c] - ra[c]) / (e * hr);
            assert!((sl - sr).abs() < 1e-3 * sl.abs().max(1.0), "{sl} {sr}");
        }
    }

    /// A straight two-node spline along its own direction has the chord's length (1e-9).
    #[test]
    fn straight_length() {
        let s = Spline2::new(
            &[[0.0, 0.0], [3000.0, 4000.0]],
            0.927_295_218_001_612_2,
            0.927_295_218_001_612_2,
        )
        .unwrap();
        assert!((s.segment_length(0) - 5000.0).abs() < 1e-6);
    }
}
