//! Legendre–Gauss–Radau points, quadrature weights and the Radau differentiation matrix
//! on `[-1, 1]` (the GPOPS-II scheme of the dissertation, FORMULATION.md §4).
//!
//! With `N` collocation points `tau_1 = -1 < tau_2 < … < tau_N < 1` (the roots of
//! `P_{N-1} + P_N`) and the non-collocated end `tau_{N+1} = +1`, a state is the Lagrange
//! polynomial through the `N + 1` support points; its derivative at the `N` collocation
//! points is `D · X` with the `N × (N + 1)` matrix `D`, and `∫ f ≈ Σ w_i f(tau_i)` is exact
//! for polynomials of degree up to `2N - 2`.

/// LGR points, weights and differentiation matrix for one mesh interval.
#[derive(Debug, Clone, PartialEq)]
pub struct Lgr {
    /// `N` collocation points, then `+1`: `N + 1` support points on `[-1, 1]`.
    pub support: Vec<f64>,
    /// `N` quadrature weights (sum 2).
    pub weights: Vec<f64>,
    /// Row-major `N × (N + 1)` differentiation matrix.
    pub diff: Vec<f64>,
    /// Barycentric weights of the `N + 1` support points (for interpolation).
    pub barycentric: Vec<f64>,
}

impl Lgr {
    /// The scheme with `n` collocation points (`n >= 1`).
    pub fn new(n: usize) -> Lgr {
        assert!(n >= 1, "an LGR interval needs at least one point");
        let (points, weights) = points_and_weights(n);
        let mut support = points;
        support.push(1.0);
        let barycentric = barycentric_weights(&support);
        let m = n + 1;
        let mut diff = vec![0.0; n * m];
        for i in 0..n {
            let mut diagonal = 0.0;
            for j in 0..m {
                if i != j {
                    let d = (barycentric[j] / barycentric[i]) / (support[i] - support[j]);
                    diff[i * m + j] = d;
                    diagonal -= d;
                }
            }
            diff[i * m + i] = diagonal;
        }
        Lgr {
            support,
            weights,
            diff,
            barycentric,
        }
    }

    /// Number of collocation points `N`.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Never empty (`N >= 1`); for clippy's `len_without_is_empty`.
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// `D[i][j]`.
    pub fn d(&self, i: usize, j: usize) -> f64 {
        self.diff[i * (self.len() + 1) + j]
    }

    /// Lagrange basis values `l_j(tau)` of the `N + 1` support points, written to `out`
    /// (barycentric formula; exact at the support points).
    pub fn basis(&self, tau: f64, out: &mut [f64]) {
        debug_assert_eq!(out.len(), self.support.len());
        if let Some(k) = self.support.iter().position(|&s| s == tau) {
            out.iter_mut().for_each(|o| *o = 0.0);
            out[k] = 1.0;
            return;
        }
        let mut sum = 0.0;
        for ((o, &s), &b) in out.iter_mut().zip(&self.support).zip(&self.barycentric) {
            *o = b / (tau - s);
            sum += *o;
        }
        out.iter_mut().for_each(|o| *o /= sum);
    }
}

/// Legendre polynomials `P_{n-1}(x)` and `P_n(x)` by the three-term recurrence.
fn legendre_pair(n: usize, x: f64) -> (f64, f64) {
    let (mut p_prev, mut p) = (1.0, x);
    if n == 0 {
        return (0.0, 1.0);
    }
    for k in 2..=n {
        let kf = k as f64;
        let next = ((2.0 * kf - 1.0) * x * p - (kf - 1.0) * p_prev) / kf;
        p_prev = p;
        p = next;
    }
    (p_prev, p)
}

/// The `n` LGR points (roots of `P_{n-1} + P_n`, `-1` first) and their weights, by Newton
/// iteration from the Chebyshev–Gauss–Radau points (von Winckel's `lgrnodes`).
fn points_and_weights(n: usize) -> (Vec<f64>, Vec<f64>) {
    let nf = n as f64;
    let mut x: Vec<f64> = (0..n)
        .map(|i| -(2.0 * std::f64::consts::PI * i as f64 / (2.0 * nf - 1.0)).cos())
        .collect();
    for xi in x.iter_mut().skip(1) {
        for _ in 0..100 {
            let (p_nm1, p_n) = legendre_pair(n, *xi);
            let step = (1.0 - *xi) / nf * (p_nm1 + p_n) / (p_nm1 - p_n);
            *xi -= step;
            if step.abs() <= 1e-15 {
                break;
            }
        }
    }
    let mut w = vec![0.0; n];
    w[0] = 2.0 / (nf * nf);
    for i in 1..n {
        let (p_nm1, _) = legendre_pair(n, x[i]);
        w[i] = (1.0 - x[i]) / (nf * p_nm1).powi(2);
    }
    (x, w)
}

fn barycentric_weights(points: &[f64]) -> Vec<f64> {
    points
        .iter()
        .enumerate()
        .map(|(j, &pj)| {
            let prod: f64 = points
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != j)
                .map(|(_, &pk)| pj - pk)
                .product();
            1.0 / prod
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// N = 3 in closed form: points -1, (1 ∓ √6)/5; weights 2/9, (16 ± √6)/18. Tolerance
    /// 1e-14 absolute.
    #[test]
    fn three_points_match_the_closed_form() {
        let l = Lgr::new(3);
        let s6 = 6f64.sqrt();
        let want_x = [-1.0, (1.0 - s6) / 5.0, (1.0 + s6) / 5.0, 1.0];
        let want_w = [2.0 / 9.0, (16.0 + s6) / 18.0, (16.0 - s6) / 18.0];
        for (a, b) in l.support.iter().zip(want_x) {
            assert!((a - b).abs() < 1e-14, "{a} vs {b}");
        }
        for (a, b) in l.weights.iter().zip(want_w) {
            assert!((a - b).abs() < 1e-14, "{a} vs {b}");
        }
    }

    /// Quadrature is exact (1e-12 relative) for every monomial of degree <= 2N - 2, and
    /// D differentiates every monomial of degree <= N exactly (1e-10 absolute), for
    /// N = 2..=20: checked against the analytic integral and derivative.
    #[test]
    fn quadrature_and_differentiation_are_exact_on_polynomials() {
        for n in 2..=20 {
            let l = Lgr::new(n);
            for deg in 0..=(2 * n - 2) {
                let q: f64 = (0..n)
                    .map(|i| l.weights[i] * l.support[i].powi(deg as i32))
                    .sum();
                let exact = if deg % 2 == 0 {
                    2.0 / (deg as f64 + 1.0)
                } else {
                    0.0
                };
                assert!(
                    (q - exact).abs() < 1e-12 * exact.abs().max(1.0),
                    "n={n} deg={deg}"
                );
            }
            for deg in 0..=n {
                for i in 0..n {
                    let d: f64 = (0..=n)
                        .map(|j| l.d(i, j) * l.support[j].powi(deg as i32))
                        .sum();
                    let exact = if deg == 0 {
                        0.0
                    } else {
                        deg as f64 * l.support[i].powi(deg as i32 - 1)
                    };
                    assert!(
                        (d - exact).abs() < 1e-10 * (1.0 + exact.abs()),
                        "n={n} deg={deg} i={i}: {d} vs {exact}"
                    );
                }
            }
        }
    }

    /// The basis interpolates a degree-N polynomial exactly between the points (1e-12).
    #[test]
    fn basis_interpolates() {
        let l = Lgr::new(8);
        let f = |x: f64| 3.0 * x.powi(8) - x.powi(3) + 0.5;
        let values: Vec<f64> = l.support.iter().map(|&s| f(s)).collect();
        let mut basis = vec![0.0; 9];
        for k in 0..=40 {
            let tau = -1.0 + 2.0 * k as f64 / 40.0;
            l.basis(tau, &mut basis);
            let v: f64 = basis.iter().zip(&values).map(|(b, v)| b * v).sum();
            assert!((v - f(tau)).abs() < 1e-12, "tau={tau}");
        }
    }
}
