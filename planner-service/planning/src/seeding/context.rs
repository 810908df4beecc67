//! What every seed of one problem shares (start, targets, end or lead, speed), the
//! geometry of a seed before sampling (its spline and altitude profiles), and the
//! fixed-time and rendezvous fits of a seed's length.

use wingman_interfaces::{MAX_PHASES, Model, Objective};

use super::moving::MovingTable;
use super::seed::Altitude;
use super::settings::{SeedError, SeedSettings};
use super::spline::{MAX_NODES, Spline2, dist2};
use crate::lead::LeadPath;
use crate::problem::Problem;

/// Where a seed ends.
#[derive(Debug, Clone, Copy)]
pub(super) struct EndPoint {
    pub(super) p: [f64; 3],
    pub(super) heading: f64,
    pub(super) gamma: f64,
}

/// Piecewise-linear altitude over a leg's horizontal arc length.
#[derive(Debug, Clone, Copy)]
pub(super) struct Profile {
    pub(super) s: [f64; 4],
    pub(super) z: [f64; 4],
    pub(super) n: usize,
}

impl Profile {
    pub(super) fn z_at(&self, s: f64) -> f64 {
        if s <= self.s[0] {
            return self.z[0];
        }
        for k in 1..self.n {
            if s <= self.s[k] {
                let ds = self.s[k] - self.s[k - 1];
                let f = if ds > 0.0 {
                    (s - self.s[k - 1]) / ds
                } else {
                    1.0
                };
                return self.z[k - 1] + f * (self.z[k] - self.z[k - 1]);
            }
        }
        self.z[self.n - 1]
    }

    pub(super) fn length(&self) -> f64 {
        (1..self.n)
            .map(|k| (self.s[k] - self.s[k - 1]).hypot(self.z[k] - self.z[k - 1]))
            .sum()
    }
}

/// The geometry of one seed before sampling: the spline, its nodes and each leg's
/// altitude profile.
pub(super) struct Geometry {
    pub(super) spline: Spline2,
    /// Node index of each leg's end.
    pub(super) gate_nodes: [usize; MAX_PHASES],
    /// Horizontal length of each spline segment.
    pub(super) seg_len: [f64; MAX_NODES],
    pub(super) profiles: [Profile; MAX_PHASES],
    pub(super) length: f64,
}

/// What every seed of one problem shares.
pub(super) struct Context<'a> {
    pub(super) problem: &'a Problem,
    pub(super) spatial: bool,
    pub(super) legs: usize,
    pub(super) t0: f64,
    pub(super) speed: f64,
    pub(super) start: [f64; 3],
    pub(super) heading0: f64,
    pub(super) gamma0: f64,
    pub(super) targets: &'a [[f64; 3]],
    pub(super) end: Option<EndPoint>,
    pub(super) lead: Option<&'a LeadPath>,
    pub(super) fixed_time: Option<f64>,
    pub(super) tan_ramp: f64,
    pub(super) high_margin: f64,
    pub(super) points: usize,
    /// Moving threats' regions for the scan and the polish.
    pub(super) table: Option<MovingTable>,
    /// Straight-line estimate of the meeting time (rendezvous).
    pub(super) meet_estimate: f64,
    /// Rendezvous: horizontal length of the last leg at that estimate. The last leg's
    /// bulge is `b` times this fixed length: a bulge proportional to the leg's own length
    /// would grow faster than the wingman closes on the lead (at `b = 0.5` the path
    /// grows by ~1.6 m per metre the lead moves), and the seed would never meet it.
    pub(super) meet_leg: f64,
}

impl<'a> Context<'a> {
    pub(super) fn new(problem: &'a Problem, settings: &SeedSettings) -> Result<Self, SeedError> {
        let spatial = problem.model == Model::ThreeD;
        let x0 = &problem.x0;
        let start = [x0[0], x0[1], if spatial { x0[2] } else { 0.0 }];
        let (heading0, gamma0) = if spatial {
            (x0[4], x0[3])
        } else {
            (x0[2], 0.0)
        };
        let speed = problem.limits.speed;
        if !speed.is_finite()
            || speed <= 0.0
            || start.iter().any(|v| !v.is_finite())
            || !heading0.is_finite()
            || !problem.t0.is_finite()
        {
            return Err(SeedError::Problem("non-finite start or speed".into()));
        }
        if problem.targets.len() + 1 > MAX_PHASES {
            return Err(SeedError::Problem(format!(
                "at most {} targets",
                MAX_PHASES - 1
            )));
        }
        let mut targets_ok = true;
        for t in &problem.targets {
            targets_ok &= t.iter().all(|v| v.is_finite());
        }
        if !targets_ok {
            return Err(SeedError::Problem("non-finite target".into()));
        }
        let (end, lead, fixed_time) = match problem.objective {
            Objective::FixedTime | Objective::MinTime => {
                let Some(f) = &problem.final_state else {
                    return Err(SeedError::Problem(
                        "the objective needs a final state".into(),
                    ));
                };
                let end = if spatial {
                    EndPoint {
                        p: [f[0], f[1], f[2]],
                        heading: f[4],
                        gamma: f[3],
                    }
                } else {
                    EndPoint {
                        p: [f[0], f[1], 0.0],
                        heading: f[2],
                        gamma: 0.0,
                    }
                };
                if end.p.iter().any(|v| !v.is_finite()) || !end.heading.is_finite() {
                    return Err(SeedError::Problem("non-finite final state".into()));
                }
                let tf = if problem.objective == Objective::FixedTime {
                    match problem.final_time {
                        Some(tf) if tf.is_finite() && tf > problem.t0 => Some(tf),
                        _ => {
                            return Err(SeedError::Problem(
                                "a fixed-time objective needs a final time after t0".into(),
                            ));
                        }
                    }
                } else {
                    None
                };
                (Some(end), None, tf)
            }
            Objective::MinTimeRendezvous => match &problem.lead {
                Some(l) => (None, Some(l), None),
                None => return Err(SeedError::Problem("a rendezvous needs the lead".into())),
            },
        };
        let gamma_max = if spatial {
            problem.limits.gamma_max
        } else {
            0.0
        };
        let mut ctx = Context {
            problem,
            spatial,
            legs: problem.targets.len() + 1,
            t0: problem.t0,
            speed,
            start,
            heading0,
            gamma0,
            targets: &problem.targets,
            end,
            lead,
            fixed_time,
            tan_ramp: (settings.ramp_gamma_ratio * gamma_max).tan(),
            high_margin: settings.high_margin,
            points: settings.points_per_seed,
            meet_estimate: problem.t0,
            meet_leg: 0.0,
            table: None,
        };
        if let Some(lead) = lead {
            ctx.meet_estimate = ctx.straight_meeting_time(lead);
            let last = problem.targets.last().copied().unwrap_or(start);
            let meet = lead.at(ctx.meet_estimate).position;
            ctx.meet_leg = dist2(&Self::horizontal(&last), &Self::horizontal(&meet));
        }
        if problem.has_moving_threats() {
            // Long enough for any seed: four times the straight path (or the fixed time).
            let mut len = 0.0;
            let mut last = start;
            for t in &problem.targets {
                len += dist3(&last, t);
                last = *t;
            }
            if let Some(e) = &end {
                len += dist3(&last, &e.p);
            }
            let mut span = 4.0 * len / speed;
            if let Some(tf) = fixed_time {
                span = span.max(2.0 * (tf - problem.t0));
            }
            span = span.max(ctx.meet_estimate - problem.t0);
            ctx.table = MovingTable::new(problem, 2.0 * span);
        }
        Ok(ctx)
    }

    pub(super) fn horizontal(p: &[f64; 3]) -> [f64; 2] {
        [p[0], p[1]]
    }

    /// Straight-line meeting time: the first `t` with `|p_lead(t) - p_last| = V (t -
    /// t_last)`, `t_last` the time at the last target flying the straight legs at `V`
    /// (bisection on the increasing `V (t - t_last) - |p_lead(t) - p_last|` when the lead
    /// is slower; the time of closest reach otherwise).
    pub(super) fn straight_meeting_time(&self, lead: &LeadPath) -> f64 {
        let mut last = self.start;
        let mut len = 0.0;
        for t in self.targets {
            len += dist3(&last, t);
            last = *t;
        }
        let t_last = self.t0 + len / self.speed;
        let f = |t: f64| self.speed * (t - t_last) - dist3(&lead.at(t).position, &last);
        let mut lo = t_last;
        let mut hi = t_last + 1.0;
        let mut k = 0;
        while f(hi) < 0.0 && k < 60 {
            lo = hi;
            hi = t_last + 2.0 * (hi - t_last);
            k += 1;
        }
        if f(hi) < 0.0 {
            return hi;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if f(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-6 {
                break;
            }
        }
        0.5 * (lo + hi)
    }

    /// The end point of a rendezvous seed meeting the lead at `t`.
    pub(super) fn lead_end(&self, lead: &LeadPath, t: f64) -> EndPoint {
        let lp = lead.at(t);
        EndPoint {
            p: if self.spatial {
                lp.position
            } else {
                [lp.position[0], lp.position[1], 0.0]
            },
            heading: lp.heading,
            gamma: if self.spatial { lp.gamma } else { 0.0 },
        }
    }

    /// Altitude profile of one leg.
    pub(super) fn profile(&self, alt: Altitude, za: f64, zb: f64, len: f64) -> Profile {
        let direct = Profile {
            s: [0.0, len, len, len],
            z: [za, zb, zb, zb],
            n: 2,
        };
        if !self.spatial
            || alt == Altitude::Direct
            || self.tan_ramp.is_nan()
            || self.tan_ramp <= 0.0
        {
            return direct;
        }
        let t = self.tan_ramp;
        if matches!(alt, Altitude::Early | Altitude::Late) {
            let ramp = (zb - za).abs() / t;
            if ramp >= len || ramp <= 0.0 {
                return direct;
            }
            let bend = if alt == Altitude::Early {
                (ramp, zb)
            } else {
                (len - ramp, za)
            };
            return Profile {
                s: [0.0, bend.0, len, len],
                z: [za, bend.1, zb, zb],
                n: 3,
            };
        }
        let top = za.max(zb);
        let mut zp = top + self.high_margin * top.abs();
        if (zp - za) / t + (zp - zb) / t > len {
            zp = 0.5 * (len * t + za + zb);
        }
        if zp <= top {
            return direct;
        }
        let ra = (zp - za) / t;
        let rb = (zp - zb) / t;
        Profile {
            s: [0.0, ra, len - rb, len],
            z: [za, zp, zp, zb],
            n: 4,
        }
    }

    /// Spline and profiles of a seed with these bulges ending at `end`. `None` when the
    /// points are degenerate.
    pub(super) fn geometry(
        &self,
        bulges: &[f64; MAX_PHASES],
        alt: Altitude,
        end: &EndPoint,
    ) -> Option<Geometry> {
        let mut nodes = [[0.0; 2]; MAX_NODES];
        let mut n = 1;
        nodes[0] = Self::horizontal(&self.start);
        let mut gate_nodes = [0usize; MAX_PHASES];
        let mut leg_z = [[0.0; 2]; MAX_PHASES];
        let mut za = self.start[2];
        for g in 0..self.legs {
            let b3 = if g < self.targets.len() {
                self.targets[g]
            } else {
                end.p
            };
            let a = nodes[n - 1];
            let b = Self::horizontal(&b3);
            let d = dist2(&a, &b);
            if d >= 1.0 {
                let (ux, uy) = ((b[0] - a[0]) / d, (b[1] - a[1]) / d);
                let mid = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
                // Left normal of the leg (its direction turned +90 degrees).
                let scale = if self.lead.is_some() && g + 1 == self.legs {
                    self.meet_leg
                } else {
                    d
                };
                let off = bulges[g] * scale;
                nodes[n] = [mid[0] - off * uy, mid[1] + off * ux];
                nodes[n + 1] = b;
                n += 2;
            }
            gate_nodes[g] = n - 1;
            leg_z[g] = [za, b3[2]];
            za = b3[2];
        }
        if n < 2 {
            return None;
        }
        let spline = Spline2::new(&nodes[..n], self.heading0, end.heading)?;
        let mut seg_len = [0.0; MAX_NODES];
        for (i, l) in seg_len.iter_mut().enumerate().take(n - 1) {
            *l = spline.segment_length(i);
        }
        let placeholder = Profile {
            s: [0.0; 4],
            z: [0.0; 4],
            n: 1,
        };
        let mut profiles = [placeholder; MAX_PHASES];
        let mut length = 0.0;
        let mut first = 0;
        for g in 0..self.legs {
            let len: f64 = seg_len[first..gate_nodes[g]].iter().sum();
            profiles[g] = self.profile(alt, leg_z[g][0], leg_z[g][1], len);
            length += profiles[g].length();
            first = gate_nodes[g];
        }
        length.is_finite().then_some(Geometry {
            spline,
            gate_nodes,
            seg_len,
            profiles,
            length,
        })
    }

    /// The common bulge ratio whose path length matches `V (t_f - t_0)` for a sign
    /// pattern, by bisection on `[0, 2]` (`None` when even straight legs are too long).
    pub(super) fn fit_fixed_time(&self, signs: &[f64; MAX_PHASES], alt: Altitude) -> Option<f64> {
        let common = |b: f64| {
            let mut bulges = [0.0; MAX_PHASES];
            for g in 0..self.legs {
                bulges[g] = signs[g] * b;
            }
            bulges
        };
        self.fit_length(common, 2.0, alt)
    }

    /// The ratio `b` in `[0, hi]` whose path `bulges(b)` has the length `V (t_f - t_0)`, by
    /// bisection (the length grows with `b`); `None` when `bulges(0)` is already too long.
    pub(super) fn fit_length(
        &self,
        bulges: impl Fn(f64) -> [f64; MAX_PHASES],
        hi: f64,
        alt: Altitude,
    ) -> Option<f64> {
        let tf = self.fixed_time?;
        let end = self.end?;
        let want = self.speed * (tf - self.t0);
        let len = |b: f64| self.geometry(&bulges(b), alt, &end).map(|g| g.length);
        let l0 = len(0.0)?;
        if l0 >= want {
            return None;
        }
        let (mut lo, mut hi) = (0.0, hi);
        if len(hi)? <= want {
            return Some(hi);
        }
        for _ in 0..50 {
            let mid = 0.5 * (lo + hi);
            match len(mid) {
                Some(l) if l < want => lo = mid,
                Some(_) => hi = mid,
                None => return None,
            }
            if hi - lo < 1e-6 {
                break;
            }
        }
        Some(0.5 * (lo + hi))
    }

    /// The meeting time of a rendezvous seed: the root of the decreasing
    /// `g(t) = t0 + L(t) / V - t`, `L(t)` the seed's length ending at the lead's position at
    /// `t` (bracketed from the straight-line estimate, then Illinois false position).
    /// Returns the time and `|g|` there.
    pub(super) fn meeting_time(
        &self,
        lead: &LeadPath,
        bulges: &[f64; MAX_PHASES],
        alt: Altitude,
    ) -> Option<(f64, f64)> {
        let g = |t: f64| {
            self.geometry(bulges, alt, &self.lead_end(lead, t))
                .map(|geo| self.t0 + geo.length / self.speed - t)
        };
        // Bracket [a, b] with g(a) >= 0 >= g(b): g(t0) = L / V > 0; search upwards from
        // the straight-line estimate by doubling steps.
        let t_est = self.meet_estimate.max(self.t0);
        let g_est = g(t_est)?;
        let (mut a, mut ga, mut b, mut gb);
        if g_est >= 0.0 {
            (a, ga) = (t_est, g_est);
            let mut step = g_est.max(1.0);
            (b, gb) = (a + step, g(a + step)?);
            let mut k = 0;
            while gb > 0.0 && k < 40 {
                (a, ga) = (b, gb);
                step *= 2.0;
                b = a + step;
                gb = g(b)?;
                k += 1;
            }
            if gb > 0.0 {
                // No meeting (the lead is at least as fast): no seed of this shape.
                return None;
            }
        } else {
            (b, gb) = (t_est, g_est);
            (a, ga) = (self.t0, g(self.t0)?);
        }
        // Illinois false position on [a, b] with g(a) >= 0 >= g(b).
        let (mut fa, mut fb) = (ga, gb);
        let mut side = 0;
        let mut t = b;
        let mut ft = fb;
        for _ in 0..60 {
            t = if fa != fb {
                (a * fb - b * fa) / (fb - fa)
            } else {
                0.5 * (a + b)
            };
            ft = g(t)?;
            if ft.abs() < 1e-4 || (b - a).abs() < 1e-6 {
                break;
            }
            if ft * fb > 0.0 {
                b = t;
                fb = ft;
                if side == -1 {
                    fa *= 0.5;
                }
                side = -1;
            } else {
                a = t;
                fa = ft;
                if side == 1 {
                    fb *= 0.5;
                }
                side = 1;
            }
        }
        Some((t, ft.abs()))
    }
}

fn dist3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
}
