//! The bisector scan (each leg's cost along its bisector and its local minima), the cost
//! of a seed's path, and the polish of a scanned combination in context.

use wingman_interfaces::MAX_PHASES;

use super::context::{Context, EndPoint, Geometry};
use super::seed::Altitude;
use super::settings::SeedSettings;

impl Context<'_> {
    /// Where the seeds end for the scan: the final point, or the lead at the straight-line
    /// meeting estimate.
    pub(super) fn scan_end(&self) -> Option<EndPoint> {
        match (self.end, self.lead) {
            (Some(e), _) => Some(e),
            (None, Some(lead)) => Some(self.lead_end(lead, self.meet_estimate)),
            (None, None) => None,
        }
    }

    /// Cost of leg `g` of `geo` flown at `V` from `t_start`: `alpha` times its duration
    /// plus `(1 - alpha) beta ∫E dt` along it (midpoint rule, 12 points per spline segment,
    /// exposure at each point's time); fixed-time objectives weigh the duration by
    /// `1e-3 beta` only (to break ties between threat-free bulges). Returns the cost and
    /// the duration.
    pub(super) fn leg_cost(&self, geo: &Geometry, g: usize, t_start: f64) -> (f64, f64) {
        const M: usize = 12;
        let first = if g == 0 { 0 } else { geo.gate_nodes[g - 1] };
        let last = geo.gate_nodes[g];
        let prof = &geo.profiles[g];
        let len_h: f64 = geo.seg_len[first..last].iter().sum();
        let stretch = if len_h > 0.0 {
            prof.length() / len_h
        } else {
            1.0
        };
        let w = &self.problem.weights;
        let alpha = if self.fixed_time.is_some() {
            1e-3 * w.beta
        } else {
            w.alpha
        };
        let mut s_h = 0.0;
        let mut expo = 0.0;
        for i in first..last {
            let ds = geo.seg_len[i] / M as f64;
            for j in 0..M {
                let (p, _) = geo.spline.eval(i, (j as f64 + 0.5) / M as f64);
                let sm = s_h + 0.5 * ds;
                let z = if self.spatial { prof.z_at(sm) } else { 0.0 };
                let t = t_start + sm * stretch / self.speed;
                let w = [p[0], p[1], z];
                let e = match &self.table {
                    Some(table) => table.exposure(self.problem, &w, t),
                    None => self.problem.exposure(&w, t),
                };
                expo += e * ds * stretch / self.speed;
                s_h += ds;
            }
        }
        let duration = prof.length() / self.speed;
        (alpha * duration + (1.0 - alpha) * w.beta * expo, duration)
    }

    /// Cost of the whole seed (every leg's [`Context::leg_cost`], each leg starting when
    /// the previous one ends).
    pub(super) fn path_cost(
        &self,
        bulges: &[f64; MAX_PHASES],
        alt: Altitude,
        end: &EndPoint,
    ) -> f64 {
        let Some(geo) = self.geometry(bulges, alt, end) else {
            return f64::INFINITY;
        };
        let mut t = self.t0;
        let mut cost = 0.0;
        for g in 0..self.legs {
            let (c, d) = self.leg_cost(&geo, g, t);
            cost += c;
            t += d;
        }
        cost
    }

    /// Polishes a scanned combination in context (the scan saw each leg with the others
    /// straight): for each leg in turn, the best ratio on a grid of 5 within `±1` scan
    /// step, then a golden-section search in the bracket around it; two rounds.
    pub(super) fn polish(
        &self,
        step: f64,
        bulges: &mut [f64; MAX_PHASES],
        alt: Altitude,
        end: &EndPoint,
    ) {
        let cost = |b: &[f64; MAX_PHASES]| self.path_cost(b, alt, end);
        let mut best = cost(bulges);
        for _ in 0..2 {
            for g in 0..self.legs {
                let b0 = bulges[g];
                let h = 0.5 * step;
                let mut arg = 0i32;
                for k in -2i32..=2 {
                    if k == 0 {
                        continue;
                    }
                    let mut t = *bulges;
                    t[g] = b0 + k as f64 * h;
                    let c = cost(&t);
                    if c < best {
                        best = c;
                        arg = k;
                    }
                }
                // Golden section on [b* - h, b* + h].
                let (mut lo, mut hi) = (b0 + (arg as f64 - 1.0) * h, b0 + (arg as f64 + 1.0) * h);
                let r = 0.618_033_988_749_894_8;
                let at = |x: f64| {
                    let mut t = *bulges;
                    t[g] = x;
                    cost(&t)
                };
                let (mut x1, mut x2) = (hi - r * (hi - lo), lo + r * (hi - lo));
                let (mut f1, mut f2) = (at(x1), at(x2));
                for _ in 0..5 {
                    if f1 < f2 {
                        hi = x2;
                        (x2, f2) = (x1, f1);
                        x1 = hi - r * (hi - lo);
                        f1 = at(x1);
                    } else {
                        lo = x1;
                        (x1, f1) = (x2, f2);
                        x2 = lo + r * (hi - lo);
                        f2 = at(x2);
                    }
                }
                let (xm, fm) = if f1 < f2 { (x1, f1) } else { (x2, f2) };
                if fm < best {
                    best = fm;
                    bulges[g] = xm;
                } else {
                    bulges[g] = b0 + arg as f64 * h;
                }
            }
        }
    }

    /// The bisector scan: for each leg (the others straight), the leg's cost at
    /// `scan_steps` ratios over `[-scan_max, scan_max]`; its local minima (a flat run
    /// counts once, at its smallest ratio) are the distinct ways past the threats on that
    /// leg. Returns up to `scan_minima` ratios per leg, cheapest first (`counts[g]` of them).
    pub(super) fn scan(
        &self,
        settings: &SeedSettings,
        alt: Altitude,
    ) -> Option<([[f64; 16]; MAX_PHASES], [usize; MAX_PHASES])> {
        let n = settings.scan_steps;
        let end = self.scan_end()?;
        let mut out = [[0.0; 16]; MAX_PHASES];
        let mut counts = [0usize; MAX_PHASES];
        // Start time of each leg along the all-straight seed.
        let straight = self.geometry(&[0.0; MAX_PHASES], alt, &end)?;
        let mut t_start = self.t0;
        let mut costs = vec![0.0; n];
        let mut ratios = vec![0.0; n];
        for g in 0..self.legs {
            for (k, (c, r)) in costs.iter_mut().zip(ratios.iter_mut()).enumerate() {
                let b = -settings.scan_max + 2.0 * settings.scan_max * k as f64 / (n - 1) as f64;
                let mut bulges = [0.0; MAX_PHASES];
                bulges[g] = b;
                *r = b;
                *c = self
                    .geometry(&bulges, alt, &end)
                    .map_or(f64::INFINITY, |geo| self.leg_cost(&geo, g, t_start).0);
            }
            // Runs of equal cost; a run lower than both neighbouring runs is a minimum.
            let mut minima: Vec<(f64, f64)> = Vec::new();
            let mut a = 0;
            while a < n {
                let mut b = a;
                while b + 1 < n && (costs[b + 1] - costs[a]).abs() <= 1e-12 * costs[a].abs() {
                    b += 1;
                }
                let left_higher = a == 0 || costs[a - 1] > costs[a];
                let right_higher = b + 1 == n || costs[b + 1] > costs[a];
                if left_higher && right_higher && costs[a].is_finite() {
                    let pick = (a..=b)
                        .min_by(|&x, &y| ratios[x].abs().total_cmp(&ratios[y].abs()))
                        .unwrap_or(a);
                    minima.push((costs[a], ratios[pick]));
                }
                a = b + 1;
            }
            minima.sort_by(|x, y| x.0.total_cmp(&y.0));
            minima.truncate(settings.scan_minima.min(16));
            for (k, m) in minima.iter().enumerate() {
                out[g][k] = m.1;
            }
            counts[g] = minima.len().max(1);
            if minima.is_empty() {
                out[g][0] = 0.0;
            }
            let first = if g == 0 {
                0
            } else {
                straight.gate_nodes[g - 1]
            };
            let len: f64 = straight.seg_len[first..straight.gate_nodes[g]].iter().sum();
            t_start += len / self.speed;
        }
        Some((out, counts))
    }
}
