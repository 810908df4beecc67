//! The swarm's per-run constants ([`Grid`]: time grid, bounds, targets, penalty weights,
//! caches of the lead's positions and the moving threats' regions at every sample time)
//! and everything done to one particle: fly it and price it ([`evaluate`]: the flight,
//! the passes of the targets and the end found on the fly, the cost), turn a seed into a
//! particle ([`track`]), write a particle out as a full-model [`Trajectory`]
//! ([`write_trajectory`]).
//!
//! Particle layout (see the `swarm` module documentation): control step `k` of length
//! `dt` holds `nu` coordinates at `k * nu ..`, held over the step's `sub` samples of length
//! `h`; at every sample the control flown is the guidance command plus the coordinate
//! (guided) or the coordinate itself (direct), clamped:
//! - 2-D: a turn rate, flown as an exact circular arc per sample;
//! - 3-D: the flight-path angle at the sample's end (`gamma` linear over the sample) at
//!   index `2k`, the heading rate at `2k + 1`; the lifted `Nz`, `mu` (eqs. 5.13–5.14) are
//!   constant per sample.
//!
//! Nothing here allocates: every buffer lives in [`Grid`] or [`Scratch`], sized once.

use std::f64::consts::FRAC_PI_2;

use wingman_interfaces::{MAX_PHASES, MAX_TARGETS, Model, Objective};

use crate::dynamics::{self, G0, ReducedPath, Spatial, wrap_angle};
use crate::lead::LeadPath;
use crate::problem::{Problem, Threats};
use crate::seeding::Seed;
use crate::threat::{ExposureAcc, Superquadric, ThreatLayout, cutoff_f};
use crate::trajectory::Trajectory;

/// A moving threat's region at one sample time with its cut-off box.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CachedRegion<const D: usize> {
    shape: Superquadric<D>,
    half: [f64; D],
    active: bool,
}

/// The static threats, held inline: one per grid, read at every sample (a box would add
/// an indirection to the hot path for no saving).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
enum Layout {
    /// Before the first [`Grid::prepare`].
    Empty,
    Planar(ThreatLayout<2>),
    Spatial(ThreatLayout<3>),
}

/// Where the path must end.
#[derive(Debug, Clone, Copy)]
pub(crate) enum End {
    /// The final point (fixed-time, min-time).
    Point {
        p: [f64; 3],
        heading: f64,
        gamma: f64,
    },
    /// The lead (rendezvous).
    Lead,
}

/// What [`Grid::prepare`] needs besides the problem.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GridParams {
    pub dt: f64,
    pub substeps: usize,
    pub steps: usize,
    pub d_star: f64,
    pub miss_weight: f64,
    pub time_weight: f64,
    pub heading_weight: f64,
    pub velocity_limit: f64,
    pub guided: bool,
}

/// Per-run constants shared (read-only) by every thread.
#[derive(Debug)]
pub(crate) struct Grid {
    pub spatial: bool,
    /// Coordinates per control step (1 in 2-D, 2 in 3-D).
    pub nu: usize,
    pub steps: usize,
    pub sub: usize,
    pub dt: f64,
    /// Sample spacing `dt / sub`.
    pub h: f64,
    pub t0: f64,
    pub speed: f64,
    pub start: [f64; 3],
    pub heading0: f64,
    pub gamma0: f64,
    pub nz0: f64,
    pub mu0: f64,
    /// Bound on the turn rate (2-D) or heading rate (3-D).
    pub rate_max: f64,
    pub gamma_max: f64,
    pub z_min: f64,
    /// Bounds of each coordinate of a step.
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    /// Velocity bound of each coordinate of a step.
    pub vmax: [f64; 2],
    pub targets: [[f64; 3]; MAX_TARGETS],
    pub n_targets: usize,
    pub end: End,
    pub objective: Objective,
    pub fixed_time: f64,
    pub alpha: f64,
    pub beta: f64,
    /// Penalty per metre of miss (targets, end, lead, altitude floor).
    pub w_dist: f64,
    /// Penalty per second of `|tf - t_fixed|`.
    pub w_time: f64,
    /// Penalty per unit of `1 - cos(heading error)` (and of the flight-path angle's).
    pub w_head: f64,
    pub d_star: f64,
    /// Coordinates are offsets to the guidance command (else the commands themselves).
    pub guided: bool,
    pub lead: Option<LeadPath>,
    lead_pos: Vec<[f64; 3]>,
    layout: Layout,
    stiffness: f64,
    n_moving: usize,
    moving2: Vec<CachedRegion<2>>,
    moving3: Vec<CachedRegion<3>>,
}

impl Grid {
    /// An empty grid with room for `samples` sample times and `moving` moving threats.
    pub(crate) fn new(samples: usize, moving: usize) -> Self {
        Grid {
            spatial: false,
            nu: 1,
            steps: 0,
            sub: 1,
            dt: 1.0,
            h: 1.0,
            t0: 0.0,
            speed: 1.0,
            start: [0.0; 3],
            heading0: 0.0,
            gamma0: 0.0,
            nz0: 1.0,
            mu0: 0.0,
            rate_max: 0.0,
            gamma_max: 0.0,
            z_min: f64::NEG_INFINITY,
            lo: [0.0; 2],
            hi: [0.0; 2],
            vmax: [0.0; 2],
            targets: [[0.0; 3]; MAX_TARGETS],
            n_targets: 0,
            end: End::Lead,
            objective: Objective::MinTime,
            fixed_time: 0.0,
            alpha: 0.0,
            beta: 0.0,
            w_dist: 0.0,
            w_time: 0.0,
            w_head: 0.0,
            d_star: 0.0,
            guided: true,
            lead: None,
            lead_pos: Vec::with_capacity(samples),
            layout: Layout::Empty,
            stiffness: 1.0,
            n_moving: 0,
            moving2: Vec::with_capacity(samples * moving),
            moving3: Vec::with_capacity(samples * moving),
        }
    }

    /// Number of coordinates of a particle.
    #[inline]
    pub(crate) fn dim(&self) -> usize {
        self.steps * self.nu
    }

    /// Number of samples (`steps * sub + 1`).
    #[inline]
    pub(crate) fn samples(&self) -> usize {
        self.steps * self.sub + 1
    }

    /// Time of sample `j`.
    #[inline]
    pub(crate) fn time(&self, j: usize) -> f64 {
        self.t0 + j as f64 * self.h
    }

    /// Sets the grid up for `problem` (may grow the caches' buffers when a problem has more
    /// samples or moving threats than any before).
    pub(crate) fn prepare(&mut self, problem: &Problem, p: &GridParams) {
        let spatial = problem.model == Model::ThreeD;
        let l = &problem.limits;
        let x0 = &problem.x0;
        self.spatial = spatial;
        self.nu = if spatial { 2 } else { 1 };
        self.steps = p.steps;
        self.sub = p.substeps;
        self.dt = p.dt;
        self.h = p.dt / p.substeps as f64;
        self.t0 = problem.t0;
        self.speed = l.speed;
        if spatial {
            self.start = [x0[0], x0[1], x0[2]];
            self.heading0 = x0[4];
            self.gamma0 = x0[3];
            self.nz0 = x0[5];
            self.mu0 = x0[6];
            // Fastest coordinated level turn: bank at mu_max, or at the load factor limit.
            let tan_mu = l
                .mu_max
                .min(1.5)
                .tan()
                .min((l.nz_max * l.nz_max - 1.0).max(0.0).sqrt());
            self.rate_max = G0 * tan_mu / l.speed;
            self.gamma_max = l.gamma_max;
            self.z_min = l.z_min;
            self.lo = [-l.gamma_max, -self.rate_max];
            self.hi = [l.gamma_max, self.rate_max];
        } else {
            self.start = [x0[0], x0[1], 0.0];
            self.heading0 = x0[2];
            self.gamma0 = 0.0;
            self.nz0 = 1.0;
            self.mu0 = 0.0;
            self.rate_max = l.turn_rate_max;
            self.gamma_max = 0.0;
            self.z_min = f64::NEG_INFINITY;
            self.lo = [-l.turn_rate_max, 0.0];
            self.hi = [l.turn_rate_max, 0.0];
        }
        self.guided = p.guided;
        if p.guided {
            // An offset of twice the bound can override any guidance command.
            for c in 0..2 {
                self.lo[c] *= 2.0;
                self.hi[c] *= 2.0;
            }
        }
        for c in 0..2 {
            self.vmax[c] = p.velocity_limit * (self.hi[c] - self.lo[c]);
        }
        self.n_targets = problem.targets.len().min(MAX_TARGETS);
        for (slot, t) in self.targets.iter_mut().zip(&problem.targets) {
            *slot = [t[0], t[1], if spatial { t[2] } else { 0.0 }];
        }
        self.objective = problem.objective;
        self.end = match (&problem.final_state, problem.objective) {
            (Some(f), Objective::FixedTime | Objective::MinTime) => {
                if spatial {
                    End::Point {
                        p: [f[0], f[1], f[2]],
                        heading: f[4],
                        gamma: f[3],
                    }
                } else {
                    End::Point {
                        p: [f[0], f[1], 0.0],
                        heading: f[2],
                        gamma: 0.0,
                    }
                }
            }
            _ => End::Lead,
        };
        self.fixed_time = problem.final_time.unwrap_or(f64::NAN);
        let w = &problem.weights;
        self.alpha = w.alpha;
        self.beta = w.beta;
        // Penalties in the objective's currency: `c` is the cost of one second of flight
        // inside a threat at the turn-rate bound, so a miss of `m` metres costs as much as
        // `miss_weight * m / V` seconds spent inside a threat: no saving of time or
        // exposure can pay for missing a target (cutting the corner saves < 2 m / V).
        let alpha_t = if problem.objective == Objective::FixedTime {
            0.0
        } else {
            w.alpha
        };
        let c = (alpha_t + (1.0 - alpha_t) * (w.beta + (1.0 - w.beta) * self.rate_max.powi(2)))
            .max(1e-9);
        self.w_dist = p.miss_weight * c / l.speed;
        self.w_time = p.time_weight * c;
        self.w_head = p.heading_weight * c / self.rate_max.max(1e-6);
        self.d_star = p.d_star;
        self.lead = problem.lead;
        let n = self.samples();
        self.lead_pos.clear();
        if let Some(lead) = &problem.lead {
            for j in 0..n {
                let q = lead.at(self.time(j)).position;
                self.lead_pos
                    .push([q[0], q[1], if spatial { q[2] } else { 0.0 }]);
            }
        }
        self.moving2.clear();
        self.moving3.clear();
        match &problem.threats {
            Threats::Planar { layout, moving } => {
                self.layout = Layout::Planar(*layout);
                self.stiffness = layout.stiffness();
                self.n_moving = moving.len();
                let fc = cutoff_f(self.stiffness);
                for j in 0..n {
                    let t = self.time(j);
                    for m in moving {
                        let reg = m.region_at(t);
                        self.moving2.push(CachedRegion {
                            shape: reg.shape,
                            half: reg.shape.cutoff_half_extents(fc, true),
                            active: m.is_active(t),
                        });
                    }
                }
            }
            Threats::Spatial { layout, moving } => {
                self.layout = Layout::Spatial(*layout);
                self.stiffness = layout.stiffness();
                self.n_moving = moving.len();
                let fc = cutoff_f(self.stiffness);
                for j in 0..n {
                    let t = self.time(j);
                    for m in moving {
                        let reg = m.region_at(t);
                        self.moving3.push(CachedRegion {
                            shape: reg.shape,
                            half: reg.shape.cutoff_half_extents(fc, true),
                            active: m.is_active(t),
                        });
                    }
                }
            }
        }
    }

    /// Where the wingman at `p` meets the lead flying on from sample `j` at its velocity
    /// there: `L + v tau` with `|L + v tau - p| = V tau` (the positive root of the
    /// quadratic; the lead's position when the lead is not slower). `L` and `v` come from
    /// the cached lead positions at the sample times (`v` by their difference).
    #[inline]
    fn intercept(&self, p: &[f64; 3], j: usize) -> [f64; 3] {
        let n = self.lead_pos.len();
        if n < 2 {
            return *p;
        }
        let j = j.min(n - 2);
        let (l, l1) = (self.lead_pos[j], self.lead_pos[j + 1]);
        let v: [f64; 3] = std::array::from_fn(|k| (l1[k] - l[k]) / self.h);
        let r: [f64; 3] = std::array::from_fn(|k| l[k] - p[k]);
        let a = v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - self.speed * self.speed;
        let b = 2.0 * (r[0] * v[0] + r[1] * v[1] + r[2] * v[2]);
        let c = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        if a >= 0.0 {
            return l;
        }
        let tau = (b + (b * b - 4.0 * a * c).max(0.0).sqrt()) / (-2.0 * a);
        std::array::from_fn(|k| l[k] + v[k] * tau)
    }

    /// Exposure at sample `j` (time `t0 + j h`) and position `p`: the same arithmetic as
    /// [`Problem::exposure`] (static layout, then each moving threat's region at that time
    /// with the same cut-off), with the regions read from the cache.
    #[inline]
    pub(crate) fn exposure(&self, j: usize, p: &[f64; 3]) -> f64 {
        let s = self.stiffness;
        match &self.layout {
            Layout::Empty => 0.0,
            Layout::Planar(layout) => {
                let w = [p[0], p[1]];
                let mut acc = ExposureAcc::<2>::new();
                layout.fold_value_into(&w, &mut acc);
                for c in &self.moving2[j * self.n_moving..(j + 1) * self.n_moving] {
                    if c.active && !c.shape.outside_box(&w, &c.half) {
                        acc.fold_value(c.shape.f(&w), s);
                    }
                }
                acc.e.value
            }
            Layout::Spatial(layout) => {
                let mut acc = ExposureAcc::<3>::new();
                layout.fold_value_into(p, &mut acc);
                for c in &self.moving3[j * self.n_moving..(j + 1) * self.n_moving] {
                    if c.active && !c.shape.outside_box(p, &c.half) {
                        acc.fold_value(c.shape.f(p), s);
                    }
                }
                acc.e.value
            }
        }
    }
}

/// Per-thread buffers of one evaluation.
#[derive(Debug, Clone)]
pub(crate) struct Scratch {
    pub pos: Vec<[f64; 3]>,
    pub head: Vec<f64>,
    pub gam: Vec<f64>,
    /// Cumulative `integral |u|^2 dt` at each sample.
    pub effort: Vec<f64>,
    pub expo: Vec<f64>,
    /// 2-D: the turn rate flown from each sample to the next.
    pub ctrl: Vec<f64>,
}

impl Scratch {
    pub(crate) fn new(samples: usize) -> Self {
        Scratch {
            pos: vec![[0.0; 3]; samples],
            head: vec![0.0; samples],
            gam: vec![0.0; samples],
            effort: vec![0.0; samples],
            expo: vec![0.0; samples],
            ctrl: vec![0.0; samples],
        }
    }
}

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

/// A particle's swarm cost; infeasible (a pass beyond `D*`) ranks after every feasible.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Score {
    pub cost: f64,
    pub feasible: bool,
}

impl Default for Score {
    fn default() -> Self {
        Score {
            cost: f64::INFINITY,
            feasible: false,
        }
    }
}

impl Score {
    /// Strictly better: feasible first, then lower cost (NaN never better).
    #[inline]
    pub(crate) fn better_than(&self, other: &Score) -> bool {
        match (self.feasible, other.feasible) {
            (true, false) => !self.cost.is_nan(),
            (false, true) => false,
            _ => self.cost < other.cost || (other.cost.is_nan() && !self.cost.is_nan()),
        }
    }
}

/// Everything [`evaluate`] found about one path.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Report {
    pub score: Score,
    pub passes: [Pass; MAX_PHASES],
    pub n_passes: usize,
    pub tf: f64,
    pub objective: f64,
    pub exposure: f64,
    pub effort: f64,
    pub penalty: f64,
    pub heading_error: f64,
    pub gamma_error: f64,
    pub floor_violation: f64,
    /// Samples flown after the first (the horizon may be cut short at the final pass).
    pub flown: usize,
}

/// `sin(x) / x`.
#[inline]
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// `(sin x, cos x)` for the small angles of one sample step (a half turn-rate or
/// flight-path increment): Taylor series to `x^10` when `|x| <= 0.6` (error below 1e-10,
/// several times cheaper than `sin_cos`), `sin_cos` otherwise.
#[inline(always)]
fn sin_cos_small(x: f64) -> (f64, f64) {
    if x.abs() > 0.6 {
        return x.sin_cos();
    }
    // Horner form with the reciprocal factorial ratios as constants (no division).
    const S3: f64 = 1.0 / 6.0;
    const S5: f64 = 1.0 / 20.0;
    const S7: f64 = 1.0 / 42.0;
    const S9: f64 = 1.0 / 72.0;
    const C2: f64 = 0.5;
    const C4: f64 = 1.0 / 12.0;
    const C6: f64 = 1.0 / 30.0;
    const C8: f64 = 1.0 / 56.0;
    const C10: f64 = 1.0 / 90.0;
    let x2 = x * x;
    let s = x * (1.0 - x2 * S3 * (1.0 - x2 * S5 * (1.0 - x2 * S7 * (1.0 - x2 * S9))));
    let c = 1.0 - x2 * C2 * (1.0 - x2 * C4 * (1.0 - x2 * C6 * (1.0 - x2 * C8 * (1.0 - x2 * C10))));
    (s, c)
}

/// `atan(z)` within 1e-5 rad (minimax polynomial on `[-1, 1]`, `pi/2 - atan(1/z)`
/// beyond): for the guidance's flight-path angle and the effort estimate, not for output.
#[inline(always)]
fn atan_fast(z: f64) -> f64 {
    let (a, flip) = if z.abs() > 1.0 {
        (1.0 / z, true)
    } else {
        (z, false)
    };
    let a2 = a * a;
    let r = a
        * (0.999_977_26
            + a2 * (-0.332_623_47
                + a2 * (0.193_543_46
                    + a2 * (-0.116_432_87 + a2 * (0.052_653_32 - 0.011_721_20 * a2)))));
    if flip { FRAC_PI_2.copysign(z) - r } else { r }
}

/// `(sin, cos)` of `a + b` from those of `a` and `b`.
#[inline(always)]
fn rotate((sa, ca): (f64, f64), (sb, cb): (f64, f64)) -> (f64, f64) {
    (sa * cb + ca * sb, ca * cb - sa * sb)
}

/// The flown state: position, heading and flight-path angle with their sines and cosines
/// (advanced by exact rotations, so a step needs one or two `sin_cos`, not one per
/// sample).
#[derive(Debug, Clone, Copy)]
struct State {
    p: [f64; 3],
    head: f64,
    gam: f64,
    sc_head: (f64, f64),
    sc_gam: (f64, f64),
}

impl State {
    fn initial(g: &Grid) -> Self {
        State {
            p: g.start,
            head: g.heading0,
            gam: g.gamma0,
            sc_head: g.heading0.sin_cos(),
            sc_gam: g.gamma0.sin_cos(),
        }
    }
}

/// Flies one 2-D sample step (length `h`) with turn rate `u` (clamped) as an exact arc.
#[inline(always)]
fn step_planar(g: &Grid, s: &mut State, u: f64) {
    let uh = u * g.h;
    let half = sin_cos_small(0.5 * uh);
    let chord = g.speed
        * g.h
        * if uh.abs() < 2e-4 {
            sinc(0.5 * uh)
        } else {
            half.0 / (0.5 * uh)
        };
    let mid = rotate(s.sc_head, half);
    s.p[0] += chord * mid.1;
    s.p[1] += chord * mid.0;
    s.head += uh;
    s.sc_head = rotate(mid, half);
}

/// The 3-D sample step's effective controls from the commanded `gamma` at its end and the
/// heading rate at state `s`: clamped to their bounds, and `gamma` raised so that the step
/// ends above `z_min` (midpoint estimate) when it can.
#[inline(always)]
fn spatial_controls(g: &Grid, s: &State, gamma_cmd: f64, rate: f64) -> (f64, f64) {
    let w = rate.clamp(-g.rate_max, g.rate_max);
    let mut ge = gamma_cmd.clamp(-g.gamma_max, g.gamma_max);
    let need = (g.z_min - s.p[2]) / (g.speed * g.h);
    if need > -1.0 {
        let a = need.min(1.0).asin();
        ge = ge.max(2.0 * a - s.gam).min(g.gamma_max);
    }
    (ge, w)
}

/// Flies one 3-D sample step (reduced model, eq. 5.11): `gamma` from its value to `ge` and
/// `chi` at rate `w`, both linear in time, position by the midpoint rule.
#[inline(always)]
fn step_spatial(g: &Grid, s: &mut State, ge: f64, w: f64) {
    let dchi = w * g.h;
    let dgam = ge - s.gam;
    let (hc, hg) = (sin_cos_small(0.5 * dchi), sin_cos_small(0.5 * dgam));
    let mc = rotate(s.sc_head, hc);
    let mg = rotate(s.sc_gam, hg);
    let vh = g.speed * g.h;
    s.p[0] += vh * mg.1 * mc.1;
    s.p[1] += vh * mg.1 * mc.0;
    s.p[2] += vh * mg.0;
    s.head += dchi;
    s.gam = ge;
    s.sc_head = rotate(mc, hc);
    s.sc_gam = rotate(mg, hg);
}

/// `Nz`, `mu` of a 3-D sample step (eq. 5.14 as [`dynamics::lift_reduced_path`], in the
/// form `mu = atan(num / den)`, `Nz = sign(den) (V / g) sqrt(num² + den²)`, `atan` within
/// 1e-5 rad: for the swarm's effort term only).
#[inline(always)]
fn lift_step(g: &Grid, s: &State, ge: f64, w: f64) -> (f64, f64) {
    let gdot = (ge - s.gam) / g.h;
    let cg = s.sc_gam.1;
    let num = w * cg;
    let den = gdot + G0 * cg / g.speed;
    let r = (num * num + den * den).sqrt();
    if den == 0.0 {
        (0.0, num.signum() * FRAC_PI_2)
    } else {
        (den.signum() * g.speed / G0 * r, atan_fast(num / den))
    }
}

/// Pure pursuit of `aim` from `s`: the heading rate of the arc tangent to the heading
/// through `aim` (`2 V_h sin(e) / d`; the full rate towards it when it is behind) and, in
/// 3-D, the flight-path angle of the straight climb to it, both clamped to their bounds.
/// In 2-D the arc is flown exactly, so a reachable aim point is hit. An aim point inside
/// the tightest turning circle on its side cannot be reached by turning (pursuit would
/// orbit it for ever): the command is then to fly straight until it is outside. `turn`
/// remembers the side of a turn towards a point behind (hysteresis).
#[inline(always)]
fn pursuit(g: &Grid, s: &State, aim: &[f64; 3], turn: &mut i8) -> (f64, f64) {
    let (dx, dy) = (aim[0] - s.p[0], aim[1] - s.p[1]);
    let d2 = dx * dx + dy * dy;
    let (sh, ch) = s.sc_head;
    let cross = ch * dy - sh * dx; // d sin(e)
    let dot = ch * dx + sh * dy; // d cos(e)
    let vh = g.speed * s.sc_gam.1;
    // Radius of the tightest turn: the point is inside that circle (centre at `r` along the
    // normal on the point's side) when `d² < 2 r |cross|`.
    let radius = vh / g.rate_max;
    let rate = if d2 < 1.0 || d2 < 2.0 * radius * cross.abs() {
        0.0
    } else if dot < 0.0 {
        // Behind: turn towards it at the full rate; within 30 degrees of straight behind,
        // keep the side chosen before (else the side flips at every sample).
        if *turn == 0 || cross.abs() > 0.5 * d2.sqrt() {
            *turn = if cross >= 0.0 { 1 } else { -1 };
        }
        f64::from(*turn) * g.rate_max
    } else {
        *turn = 0;
        2.0 * vh * cross / d2
    };
    let gamma = if g.spatial {
        atan_fast((aim[2] - s.p[2]) / d2.sqrt().max(1.0))
    } else {
        0.0
    };
    (
        rate.clamp(-g.rate_max, g.rate_max),
        gamma.clamp(-g.gamma_max, g.gamma_max),
    )
}

/// The guidance of the guided parameterisation: pure pursuit of the next target not yet
/// passed, then of the final point or of the lead's intercept point. A target counts as
/// passed once it is within a quarter sample spacing, or behind and within two control
/// steps' flight.
#[derive(Debug, Clone, Copy, Default)]
struct Guide {
    gate: usize,
    turn: i8,
}

impl Guide {
    /// The guidance command (heading rate, flight-path angle) at state `s` at sample `j`.
    #[inline(always)]
    fn command(&mut self, g: &Grid, s: &State, j: usize) -> (f64, f64) {
        if !g.guided {
            return (0.0, 0.0);
        }
        let (sh, ch) = s.sc_head;
        let reach2 = (2.0 * g.speed * g.dt).powi(2);
        let near2 = (0.25 * g.speed * g.h).powi(2);
        while self.gate < g.n_targets {
            let q = &g.targets[self.gate];
            let (dx, dy) = (q[0] - s.p[0], q[1] - s.p[1]);
            let d2 = dx * dx + dy * dy;
            if d2 < near2 || (dx * ch + dy * sh <= 0.0 && d2 < reach2) {
                self.gate += 1;
            } else {
                break;
            }
        }
        let aim = if self.gate < g.n_targets {
            g.targets[self.gate]
        } else {
            match g.end {
                End::Point { p, .. } => p,
                End::Lead => g.intercept(&s.p, j),
            }
        };
        pursuit(g, s, &aim, &mut self.turn)
    }
}

/// Flies a particle control step by control step into a [`Scratch`].
struct Flyer {
    s: State,
    guide: Guide,
    /// Last sample written.
    j: usize,
    effort: f64,
    nz: f64,
    mu: f64,
}

impl Flyer {
    fn start(g: &Grid, sc: &mut Scratch) -> Self {
        let s = State::initial(g);
        sc.pos[0] = s.p;
        sc.head[0] = s.head;
        sc.gam[0] = s.gam;
        sc.effort[0] = 0.0;
        Flyer {
            s,
            guide: Guide::default(),
            j: 0,
            effort: 0.0,
            nz: g.nz0,
            mu: g.mu0,
        }
    }

    /// Flies control step `k` of particle `u` (its `sub` samples), writing the samples.
    #[inline(always)]
    fn step(&mut self, g: &Grid, u: &[f64], k: usize, sc: &mut Scratch) {
        for _ in 0..g.sub {
            let j = self.j;
            let (cr, cg) = self.guide.command(g, &self.s, j);
            if !g.spatial {
                let ue = (cr + u[k]).clamp(-g.rate_max, g.rate_max);
                sc.ctrl[j] = ue;
                step_planar(g, &mut self.s, ue);
                self.effort += ue * ue * g.h;
            } else {
                let (ge, w) = spatial_controls(g, &self.s, cg + u[2 * k], cr + u[2 * k + 1]);
                let (nz1, mu1) = lift_step(g, &self.s, ge, w);
                // (u1² + u2²) h with u = jump / h.
                self.effort += ((nz1 - self.nz).powi(2) + (mu1 - self.mu).powi(2)) / g.h;
                self.nz = nz1;
                self.mu = mu1;
                step_spatial(g, &mut self.s, ge, w);
            }
            self.j += 1;
            let j = self.j;
            sc.pos[j] = self.s.p;
            sc.head[j] = self.s.head;
            sc.gam[j] = self.s.gam;
            sc.effort[j] = self.effort;
        }
    }
}

/// Distance from `p` to the segment `a`–`b` and the fraction along it of the closest point.
#[inline(always)]
fn seg_point(a: &[f64; 3], b: &[f64; 3], p: &[f64; 3]) -> (f64, f64) {
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
fn sub3(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
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
struct Tracker {
    phase: usize,
    from: usize,
    inside: bool,
    best: Pass,
    global: Pass,
    global_score: f64,
    offer: Pass,
    offer_score: f64,
    passes: [Pass; MAX_PHASES],
    ok: [bool; MAX_PHASES],
}

impl Tracker {
    fn new() -> Self {
        Tracker {
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
    fn feed(&mut self, g: &Grid, pos: &[[f64; 3]], k: usize) -> bool {
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
    fn finish(&mut self, g: &Grid, pos: &[[f64; 3]], segs: usize) {
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

/// Flies and prices the particle `u`: the cost of FORMULATION.md §4 up to the final pass
/// plus the swarm's penalties (eqs. 4.5–4.8 in additive form, see the `swarm` module).
pub(crate) fn evaluate(g: &Grid, u: &[f64], sc: &mut Scratch) -> Report {
    let mut fly = Flyer::start(g, sc);
    let mut tr = Tracker::new();
    let mut fed = 0;
    let mut done = false;
    'steps: for k in 0..g.steps {
        fly.step(g, u, k, sc);
        while fed < fly.j {
            fed += 1;
            if tr.feed(g, &sc.pos, fed - 1) {
                done = true;
                break 'steps;
            }
        }
    }
    if !done {
        tr.finish(g, &sc.pos, fed);
    }
    let flown = fly.j;
    let mut rep = Report {
        n_passes: g.n_targets + 1,
        flown,
        ..Report::default()
    };
    let mut feasible = true;
    let mut penalty = 0.0;
    for i in 0..rep.n_passes {
        rep.passes[i] = tr.passes[i];
        feasible &= tr.ok[i];
        penalty += g.w_dist * tr.passes[i].dist;
    }
    let fin = rep.passes[g.n_targets];
    let (kf, f) = (fin.seg, fin.frac);
    let tf = fin.time(g);
    // Exposure (trapezoid on the samples) and control effort up to tf.
    let last = (kf + 1).min(flown);
    let mut zlow = f64::INFINITY;
    for j in 0..=last {
        sc.expo[j] = g.exposure(j, &sc.pos[j]);
        zlow = zlow.min(sc.pos[j][2]);
    }
    let mut e_int = 0.0;
    for j in 0..kf {
        e_int += sc.expo[j] + sc.expo[j + 1];
    }
    e_int *= 0.5 * g.h;
    let e_f = sc.expo[kf] + f * (sc.expo[last] - sc.expo[kf]);
    e_int += 0.5 * f * g.h * (sc.expo[kf] + e_f);
    let effort = sc.effort[kf] + f * (sc.effort[last] - sc.effort[kf]);
    let j_run = g.beta * e_int + (1.0 - g.beta) * effort;
    let objective = match g.objective {
        Objective::FixedTime => j_run,
        _ => g.alpha * tf + (1.0 - g.alpha) * j_run,
    };
    // Final heading (and flight-path angle) against the end's or the lead's.
    let head_f = sc.head[kf] + f * (sc.head[last] - sc.head[kf]);
    let gam_f = sc.gam[kf] + f * (sc.gam[last] - sc.gam[kf]);
    let (want_head, want_gam) = match (g.end, &g.lead) {
        (End::Point { heading, gamma, .. }, _) => (heading, gamma),
        (End::Lead, Some(lead)) => {
            let lp = lead.at(tf);
            (lp.heading, if g.spatial { lp.gamma } else { 0.0 })
        }
        (End::Lead, None) => (head_f, gam_f),
    };
    let he = wrap_angle(head_f - want_head);
    let ge = gam_f - want_gam;
    penalty += g.w_head * ((1.0 - he.cos()) + (1.0 - ge.cos()));
    if g.objective == Objective::FixedTime {
        penalty += g.w_time * (tf - g.fixed_time).abs();
    }
    let floor = if g.spatial {
        (g.z_min - zlow).max(0.0)
    } else {
        0.0
    };
    penalty += g.w_dist * floor;
    let cost = objective + penalty;
    rep.score = Score {
        cost: if cost.is_nan() { f64::INFINITY } else { cost },
        feasible: feasible && cost.is_finite(),
    };
    rep.tf = tf;
    rep.objective = objective;
    rep.exposure = e_int;
    rep.effort = effort;
    rep.penalty = penalty;
    rep.heading_error = he;
    rep.gamma_error = ge;
    rep.floor_violation = floor;
    rep
}

/// Turns a seed into a particle: flies the swarm's own model along the seed with a pure
/// pursuit controller. For each control step, a trial flight of its samples under pursuit
/// gives the commands, whose mean (guided: mean offset from the guidance command) is the
/// particle's coordinate for the step; the step is then flown again exactly as the
/// particle will fly it, and pursuit goes on from there, so the particle reproduces the
/// tracked path (clamps and altitude guard included). The aim point is `lookahead * V`
/// ahead along the seed (`lookahead` in seconds), but never past the next target or the
/// end until that is passed (pursuit then flies the arc through it).
pub(crate) fn track(g: &Grid, seed: &Seed, lookahead: f64, u: &mut [f64]) {
    let pts = seed.points();
    let arc = seed.arc_lengths();
    let gates = seed.gates();
    let n = pts.len();
    if n < 2 {
        u[..g.dim()].fill(0.0);
        return;
    }
    let mut s = State::initial(g);
    let step_len = g.speed * g.dt;
    let la = lookahead * g.speed;
    let mut i = 0;
    let mut gi = 0;
    let mut guide = Guide::default();
    let mut turn = 0i8;
    let dist = |a: &[f64; 3], p: &[f64; 3]| ((a[0] - p[0]).powi(2) + (a[1] - p[1]).powi(2)).sqrt();
    // The pursuit command at `st` (advancing the progress along the seed and its gates).
    let mut command = |st: &State| -> (f64, f64) {
        let mut best = i;
        let mut bd = dist(&pts[i], &st.p);
        let reach = arc[i] + 2.0 * la + step_len;
        let mut m = i + 1;
        while m < n && arc[m] <= reach {
            let d = dist(&pts[m], &st.p);
            if d < bd {
                bd = d;
                best = m;
            }
            m += 1;
        }
        i = best;
        // A gate is passed as the guidance passes a target (within a quarter sample, or
        // behind and within two steps), so that near a target both aim at it.
        let (sh, ch) = st.sc_head;
        while gi < gates.len() {
            let gp = pts[gates[gi]];
            let (dx, dy) = (gp[0] - st.p[0], gp[1] - st.p[1]);
            let d = (dx * dx + dy * dy).sqrt();
            let behind = dx * ch + dy * sh <= 0.0;
            if d < 0.25 * g.speed * g.h || (behind && d < 2.0 * step_len) {
                gi += 1;
                i = i.max(gates[gi - 1]);
            } else {
                break;
            }
        }
        let sq = arc[i] + la;
        let q = if gi < gates.len() && sq >= arc[gates[gi]] {
            pts[gates[gi]]
        } else {
            seed.point_at_arc(sq)
        };
        pursuit(g, st, &q, &mut turn)
    };
    for k in 0..g.steps {
        let j0 = k * g.sub;
        // Trial: pursuit over the step's samples; the mean offset is the coordinate.
        let (mut trial, mut tguide) = (s, guide);
        let (mut sum_r, mut sum_g) = (0.0, 0.0);
        let mut counted = 0;
        let mut passed = false;
        for q in 0..g.sub {
            let (rate, gamma_cmd) = command(&trial);
            let gate_before = tguide.gate;
            let (cr, cg) = tguide.command(g, &trial, j0 + q);
            if tguide.gate != gate_before && q > 0 {
                // The guidance passed a target: up to here both aimed at it, so the
                // offsets so far fly through it; the rest of the step would pull the
                // approach away.
                passed = true;
                break;
            }
            sum_r += rate - cr;
            sum_g += gamma_cmd - cg;
            counted += 1;
            if !g.spatial {
                step_planar(g, &mut trial, rate);
            } else {
                let (ge, w) = spatial_controls(g, &trial, gamma_cmd, rate);
                step_spatial(g, &mut trial, ge, w);
            }
        }
        let inv = 1.0 / counted.max(1) as f64;
        let (mut o_r, mut o_g) = (sum_r * inv, sum_g * inv);
        // The guidance varies within the step, so the mean offset does not reproduce the
        // trial: correct it (three passes) until the step ends with the trial's heading
        // (and flight-path angle).
        let clamp_r = |o: f64| o.clamp(g.lo[g.nu - 1], g.hi[g.nu - 1]);
        let clamp_g = |o: f64| o.clamp(g.lo[0], g.hi[0]);
        (o_r, o_g) = (clamp_r(o_r), clamp_g(o_g));
        for _ in 0..if passed { 0 } else { TRACK_PASSES } {
            let (mut probe, mut pguide) = (s, guide);
            fly_step(g, &mut probe, &mut pguide, j0, o_r, o_g);
            o_r = clamp_r(o_r + (trial.head - probe.head) / g.dt);
            o_g = clamp_g(o_g + (trial.gam - probe.gam));
        }
        if !g.spatial {
            u[k] = o_r;
        } else {
            u[2 * k] = o_g;
            u[2 * k + 1] = o_r;
        }
        // The step as the particle flies it.
        fly_step(g, &mut s, &mut guide, j0, o_r, o_g);
    }
}

/// Flies the `sub` samples of a control step from sample `j0` with constant offsets
/// (turn or heading rate `o_r`, flight-path angle `o_g`) to the guidance, as
/// [`Flyer::step`] does.
fn fly_step(g: &Grid, s: &mut State, guide: &mut Guide, j0: usize, o_r: f64, o_g: f64) {
    for q in 0..g.sub {
        let (cr, cg) = guide.command(g, s, j0 + q);
        if !g.spatial {
            step_planar(g, s, (cr + o_r).clamp(-g.rate_max, g.rate_max));
        } else {
            let (ge, w) = spatial_controls(g, s, cg + o_g, cr + o_r);
            step_spatial(g, s, ge, w);
        }
    }
}

/// Correction passes of the seed tracker's offsets (see [`track`]).
const TRACK_PASSES: usize = 1;

/// Output buffers of [`write_trajectory`] (3-D lift input).
#[derive(Debug, Clone, Default)]
pub(crate) struct OutBuffers {
    times: Vec<f64>,
    pos: Vec<[f64; 3]>,
    gamma: Vec<f64>,
    chi: Vec<f64>,
    rate: Vec<f64>,
}

/// A state of the output: position, heading, flight-path angle, 2-D turn rate.
type OutState = ([f64; 3], f64, f64, f64);

impl OutBuffers {
    fn clear(&mut self) {
        self.times.clear();
        self.pos.clear();
        self.gamma.clear();
        self.chi.clear();
        self.rate.clear();
    }

    fn push(&mut self, t: f64, s: OutState) {
        self.times.push(t);
        self.pos.push(s.0);
        self.chi.push(s.1);
        self.gamma.push(s.2);
        self.rate.push(s.3);
    }

    pub(crate) fn with_capacity(n: usize) -> Self {
        OutBuffers {
            times: Vec::with_capacity(n),
            pos: Vec::with_capacity(n),
            gamma: Vec::with_capacity(n),
            chi: Vec::with_capacity(n),
            rate: Vec::with_capacity(n),
        }
    }
}

/// Writes the path of particle `u` (already evaluated into `sc` with report `rep`) up to
/// its final time into `out`: every sample, plus a sample at each target's pass and at
/// the final time; full 3-D states lifted with eqs. (5.13)–(5.15). Phase ends: the pass
/// times.
pub(crate) fn write_trajectory(
    g: &Grid,
    sc: &Scratch,
    rep: &Report,
    buf: &mut OutBuffers,
    out: &mut Trajectory,
) -> Result<(), dynamics::DynamicsError> {
    buf.clear();
    out.clear();
    let eps = 1e-6 * g.h;
    let fin = rep.passes[rep.n_passes - 1];
    let segs = rep.flown;
    // The state at fraction `f` of segment `j`: one partial step of the same model.
    let partial = |j: usize, f: f64| -> OutState {
        let th = f * g.h;
        let a = sc.pos[j];
        if !g.spatial {
            let ue = sc.ctrl[j.min(segs.saturating_sub(1))];
            let chord = g.speed * th * sinc(0.5 * ue * th);
            let mid = sc.head[j] + 0.5 * ue * th;
            (
                [a[0] + chord * mid.cos(), a[1] + chord * mid.sin(), 0.0],
                sc.head[j] + ue * th,
                0.0,
                ue,
            )
        } else {
            let j1 = (j + 1).min(segs);
            let (g0, g1) = (sc.gam[j], sc.gam[j1]);
            let (c0, c1) = (sc.head[j], sc.head[j1]);
            let gm = g0 + 0.5 * f * (g1 - g0);
            let cm = c0 + 0.5 * f * (c1 - c0);
            let v = g.speed * th;
            (
                [
                    a[0] + v * gm.cos() * cm.cos(),
                    a[1] + v * gm.cos() * cm.sin(),
                    a[2] + v * gm.sin(),
                ],
                c0 + f * (c1 - c0),
                g0 + f * (g1 - g0),
                0.0,
            )
        }
    };
    let sample = |j: usize| -> OutState {
        let r = if g.spatial {
            0.0
        } else {
            sc.ctrl[j.min(segs.saturating_sub(1))]
        };
        (sc.pos[j], sc.head[j], sc.gam[j], r)
    };
    let mut next_pass = 0;
    for j in 0..=fin.seg {
        buf.push(g.time(j), sample(j));
        // Targets passed inside segment j (not at its ends, not after the final time).
        while next_pass + 1 < rep.n_passes && rep.passes[next_pass].seg == j {
            let p = rep.passes[next_pass];
            next_pass += 1;
            let inside = p.frac * g.h > eps && (1.0 - p.frac) * g.h > eps;
            if inside && !(j == fin.seg && p.frac >= fin.frac) {
                buf.push(p.time(g), partial(j, p.frac));
            }
        }
    }
    if fin.frac * g.h > eps {
        if (1.0 - fin.frac) * g.h > eps {
            buf.push(fin.time(g), partial(fin.seg, fin.frac));
        } else {
            let j = (fin.seg + 1).min(segs);
            buf.push(g.time(j), sample(j));
        }
    }
    if buf.times.len() < 2 {
        // A path that ends at once: two samples a sub-step apart.
        let j = 1.min(segs);
        buf.push(g.time(j), sample(j));
    }
    let OutBuffers {
        times,
        pos,
        gamma,
        chi,
        rate,
    } = buf;
    let n = times.len();
    // One allocation per buffer for a fresh trajectory, none for a large enough one.
    out.times.reserve_exact(n);
    out.states.reserve_exact(n);
    out.controls.reserve_exact(n);
    out.phase_ends.reserve_exact(rep.n_passes);
    if !g.spatial {
        for i in 0..n {
            let p = pos[i];
            out.push(
                times[i],
                [p[0], p[1], chi[i], 0.0, 0.0, 0.0, 0.0],
                [rate[i], 0.0],
            );
        }
    } else {
        let model = Spatial::new(g.speed)?;
        out.times.extend_from_slice(times);
        out.states.resize(n, [0.0; 7]);
        out.controls.resize(n, [0.0; 2]);
        dynamics::lift_reduced_path(
            &model,
            &ReducedPath {
                times,
                positions: pos,
                gamma,
                chi,
            },
            &mut out.states,
            &mut out.controls,
        )?;
        // The first sample is the initial state itself (its Nz, mu), the first controls
        // lead from it to the second sample's.
        out.states[0][dynamics::idx3::NZ] = g.nz0;
        out.states[0][dynamics::idx3::MU] = g.mu0;
        let dt0 = times[1] - times[0];
        out.controls[0] = [
            (out.states[1][dynamics::idx3::NZ] - g.nz0) / dt0,
            (out.states[1][dynamics::idx3::MU] - g.mu0) / dt0,
        ];
    }
    // Phase ends: the pass times, non-decreasing and within the trajectory.
    let (t_first, t_last) = (out.times[0], out.times[n - 1]);
    let mut prev = t_first;
    for p in &rep.passes[..rep.n_passes - 1] {
        prev = p.time(g).clamp(prev, t_last);
        out.phase_ends.push(prev);
    }
    out.phase_ends.push(t_last);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast trigonometry against libm: `sin_cos_small` within 1e-10 on `[-1, 1]`
    /// (series below 0.6, libm above), `atan_fast` within 1e-5 rad on `[-1e3, 1e3]`.
    #[test]
    fn fast_trigonometry_is_accurate() {
        for k in -1000..=1000 {
            let x = k as f64 * 1e-3;
            let (s, c) = sin_cos_small(x);
            assert!(
                (s - x.sin()).abs() < 1e-10 && (c - x.cos()).abs() < 1e-10,
                "{x}"
            );
        }
        for k in -20000..=20000 {
            let z = (k as f64 * 5e-4).powi(3);
            assert!((atan_fast(z) - z.atan()).abs() < 1e-5, "{z}");
        }
    }
}
