//! Where a path passes the targets and the end ([`Pass`]), found segment by segment while
//! the particle is flown ([`Passes`]).

use wingman_interfaces::{MAX_PHASES, Objective};

use super::grid::{End, Grid};

/// Where a path passes a point: on the segment from sample `seg` to `seg + 1`, at fraction
/// `frac` of it, `dist` away.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pass {
    pub seg: usize,
    pub frac: f64,
    pub dist: f64,
}

impl Default for Pass {
    fn default() -> Self {
        Pass {
            seg: 0,
            frac: 0.0,
            dist: f64::INFINITY,
        }
    }
}

impl Pass {
    #[inline]
    pub(crate) fn time(&self, g: &Grid) -> f64 {
        g.time(self.seg) + self.frac * g.h
    }
}

/// Distance from `p` to the segment `a`–`b` and the fraction along it of the closest point.
#[inline(always)]
pub(super) fn seg_point(a: &[f64; 3], b: &[f64; 3], p: &[f64; 3]) -> (f64, f64) {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let w = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let f = if dd > 0.0 {
        ((w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e = [w[0] - f * d[0], w[1] - f * d[1], w[2] - f * d[2]];
    ((e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt(), f)
}

#[inline(always)]
pub(super) fn sub3(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Finds the passes segment by segment while the particle is flown, so that flying stops
/// as soon as the final pass is known.
///
/// A target's pass is the closest approach inside the first run of segments (from the
/// previous pass on) that come within `D*` — a later loop back, e.g. in the unused tail,
/// cannot steal it; without such a run, the closest approach overall, infeasible. The
/// final point's (min-time) and the lead's pass likewise (the lead's: closest approach of
/// the relative motion, eq. 4.8's `D_Rend`). For a fixed final time, every run within `D*`
/// offers its closest approach and the one with the least `w_d dist + w_t |t - t_fixed|`
/// wins; flying stops once a run has closed after `t_fixed`, or when `w_t (t - t_fixed)`
/// alone exceeds the best offer.
pub(super) struct Passes {
    phase: usize,
    from: usize,
    inside: bool,
    best: Pass,
    global: Pass,
    global_score: f64,
    offer: Pass,
    offer_score: f64,
    pub(super) passes: [Pass; MAX_PHASES],
    pub(super) ok: [bool; MAX_PHASES],
}

impl Passes {
    pub(super) fn new() -> Self {
        Passes {
            phase: 0,
            from: 0,
            inside: false,
            best: Pass::default(),
            global: Pass::default(),
            global_score: f64::INFINITY,
            offer: Pass::default(),
            offer_score: f64::INFINITY,
            passes: [Pass::default(); MAX_PHASES],
            ok: [false; MAX_PHASES],
        }
    }

    #[inline(always)]
    fn fixed_final(&self, g: &Grid) -> bool {
        self.phase == g.n_targets && g.objective == Objective::FixedTime
    }

    #[inline(always)]
    fn offer_score(&self, g: &Grid, q: &Pass) -> f64 {
        g.w_dist * q.dist + g.w_time * (q.time(g) - g.fixed_time).abs()
    }

    /// Distance (and fraction) on segment `k` to what the current phase passes.
    #[inline(always)]
    fn dist(&self, g: &Grid, pos: &[[f64; 3]], k: usize) -> (f64, f64) {
        if self.phase < g.n_targets {
            seg_point(&pos[k], &pos[k + 1], &g.targets[self.phase])
        } else {
            match g.end {
                End::Point { p, .. } => seg_point(&pos[k], &pos[k + 1], &p),
                End::Lead => {
                    let a = sub3(&pos[k], &g.lead_pos[k]);
                    let b = sub3(&pos[k + 1], &g.lead_pos[k + 1]);
                    seg_point(&a, &b, &[0.0; 3])
                }
            }
        }
    }

    /// Looks at segment `k` for the current phase; true when the phase's pass is known.
    #[inline(always)]
    fn observe(&mut self, g: &Grid, pos: &[[f64; 3]], k: usize) -> bool {
        let (d, f) = self.dist(g, pos, k);
        let q = Pass {
            seg: k,
            frac: f,
            dist: d,
        };
        if self.fixed_final(g) {
            let sq = self.offer_score(g, &q);
            if sq < self.global_score {
                self.global = q;
                self.global_score = sq;
            }
            if d <= g.d_star {
                if !self.inside || d < self.best.dist {
                    self.best = q;
                }
                self.inside = true;
                false
            } else {
                if self.inside {
                    self.inside = false;
                    let sb = self.offer_score(g, &self.best);
                    if sb < self.offer_score {
                        self.offer = self.best;
                        self.offer_score = sb;
                    }
                    if q.time(g) >= g.fixed_time {
                        return true;
                    }
                }
                g.w_time * (q.time(g) - g.fixed_time) > self.offer_score
            }
        } else {
            if d < self.global.dist {
                self.global = q;
            }
            if d <= g.d_star {
                self.inside = true;
                if d < self.best.dist {
                    self.best = q;
                }
                false
            } else {
                self.inside
            }
        }
    }

    /// Settles the current phase's pass; true when it was the last phase.
    fn complete(&mut self, g: &Grid) -> bool {
        let (p, ok) = if self.fixed_final(g) {
            if self.inside {
                let sb = self.offer_score(g, &self.best);
                if sb < self.offer_score {
                    self.offer = self.best;
                    self.offer_score = sb;
                }
            }
            if self.offer_score.is_finite() {
                (self.offer, true)
            } else {
                (self.global, false)
            }
        } else if self.inside {
            (self.best, true)
        } else {
            (self.global, false)
        };
        self.passes[self.phase] = p;
        self.ok[self.phase] = ok;
        if self.phase == g.n_targets {
            return true;
        }
        self.phase += 1;
        self.from = p.seg;
        self.inside = false;
        self.best = Pass::default();
        self.global = Pass::default();
        self.global_score = f64::INFINITY;
        false
    }

    /// Feeds segment `k` (every earlier one was fed); true when the final pass is known.
    pub(super) fn feed(&mut self, g: &Grid, pos: &[[f64; 3]], k: usize) -> bool {
        let mut s = k;
        loop {
            if self.observe(g, pos, s) {
                if self.complete(g) {
                    return true;
                }
                // The next phase starts at the pass just found: look again from there.
                s = self.from;
            } else if s >= k {
                return false;
            } else {
                s += 1;
            }
        }
    }

    /// The horizon ended after `segs` segments: settles every open phase.
    pub(super) fn finish(&mut self, g: &Grid, pos: &[[f64; 3]], segs: usize) {
        while !self.complete(g) {
            let mut s = self.from;
            while s < segs {
                if self.observe(g, pos, s) {
                    if self.complete(g) {
                        return;
                    }
                    s = self.from;
                } else {
                    s += 1;
                }
            }
        }
    }
}
