//! The swarm's per-run constants: [`Grid`] (time grid, bounds, targets, penalty weights,
//! caches of the lead's positions and the moving threats' regions at every sample time).

use wingman_interfaces::{MAX_TARGETS, Model, Objective};

use crate::dynamics::G0;
use crate::estimation::{TabledRegion, tabulate};
use crate::lead::LeadPath;
use crate::problem::{Problem, Threats};
use crate::threat::{ExposureAcc, ThreatLayout, cutoff_f};

/// The static threats, held inline: one per grid, read at every sample (a box would add
/// an indirection to the hot path for no saving).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
pub(super) enum Layout {
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
    pub(super) lead_pos: Vec<[f64; 3]>,
    layout: Layout,
    stiffness: f64,
    n_moving: usize,
    moving2: Vec<TabledRegion<2>>,
    moving3: Vec<TabledRegion<3>>,
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
        // The moving threats' regions at the sample times (`time(j)`).
        let (t0, h) = (self.t0, self.h);
        let times = (0..n).map(|j| t0 + j as f64 * h);
        match &problem.threats {
            Threats::Planar { layout, moving } => {
                self.layout = Layout::Planar(*layout);
                self.stiffness = layout.stiffness();
                self.n_moving = moving.len();
                tabulate(moving, times, cutoff_f(self.stiffness), &mut self.moving2);
            }
            Threats::Spatial { layout, moving } => {
                self.layout = Layout::Spatial(*layout);
                self.stiffness = layout.stiffness();
                self.n_moving = moving.len();
                tabulate(moving, times, cutoff_f(self.stiffness), &mut self.moving3);
            }
        }
    }

    /// Where the wingman at `p` meets the lead flying on from sample `j` at its velocity
    /// there: `L + v tau` with `|L + v tau - p| = V tau` (the positive root of the
    /// quadratic; the lead's position when the lead is not slower). `L` and `v` come from
    /// the cached lead positions at the sample times (`v` by their difference).
    #[inline]
    pub(super) fn intercept(&self, p: &[f64; 3], j: usize) -> [f64; 3] {
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
                    c.fold_value_into(&w, &mut acc, s);
                }
                acc.e.value
            }
            Layout::Spatial(layout) => {
                let mut acc = ExposureAcc::<3>::new();
                layout.fold_value_into(p, &mut acc);
                for c in &self.moving3[j * self.n_moving..(j + 1) * self.n_moving] {
                    c.fold_value_into(p, &mut acc, s);
                }
                acc.e.value
            }
        }
    }
}
