//! Deterministic spline seeds of the particle swarm (dissertation appendices A and B,
//! FORMULATION.md §7.1).
//!
//! A seed is a smooth candidate path from the start over every target to the end: a
//! clamped cubic spline through the start, one point on the perpendicular bisector of each
//! leg (the *bulge* point, `b · d` to the left (`b > 0`) or right (`b < 0`) of the leg's
//! midpoint, `d` the leg's horizontal length) and the leg's end, leaving the start along
//! the initial heading and arriving along the final heading (appendix A). The spline is
//! centripetal-parameterised (Lee's scheme, MATLAB `cscvn`). The swarm flies each seed with
//! its own model to turn it into a particle (a control vector), see [`crate::swarm`].
//!
//! In 3-D (appendix B) the bulge points are the horizontal diameter of appendix B's
//! concentric circles around the leg, and the vertical dimension is an *altitude profile*
//! along the horizontal arc length, one per leg: [`Altitude::Direct`] (a constant climb
//! or descent angle over the leg) or [`Altitude::High`] (climb at the leg's start to a
//! plateau above both ends and descend late, with a ramp angle of `ramp_gamma_ratio ·
//! gamma_max`). Points of appendix B's circles above or below the leg would put a 100 km
//! leg's bulge tens of kilometres up or underground; the profiles cover the vertical
//! choices that matter (overfly the threats, which are rooted on the ground, or not) and
//! keep `|gamma|` within its bound and `z >= z_min` by construction.
//!
//! The families (`winning_start` in `tools/judge/costs.toml` shows the optimum's basin
//! is often one of them):
//! - **arcs**: every combination of straight / left / right per leg for each ratio in
//!   `bulge_ratios` (`LR@0.5` = left on leg 1, right on leg 2, ratio 0.5), times each
//!   altitude profile in 3-D;
//! - **fixed-time fits** (`fixed-time` only): for each left/straight/right pattern, the
//!   common ratio whose path length is `V (t_f - t_0)`, found by bisection, so the seed
//!   flown at `V` arrives on time;
//! - **random**: `random_seeds` curves with a ratio per leg drawn uniformly from
//!   `[-random_bulge_max, random_bulge_max]` (and a random profile in 3-D);
//! - **bisector scan** (listed first): for each leg, with the other legs straight, the
//!   leg's cost (`alpha` times its duration plus `(1 - alpha) beta ∫E dt` along the spline,
//!   moving threats at each point's time) at `scan_steps` ratios over
//!   `[-scan_max, scan_max]`; each local minimum is a distinct way past the threats on that
//!   leg, e.g. through a gap between two threats that no fixed ratio hits. Every
//!   combination of the legs' cheapest minima is a seed, the cheapest `scan_polish` of them
//!   polished in context (each leg's ratio searched again with the other legs bent).
//!
//! For a rendezvous the end of the spline is the lead's position at a predicted meeting
//! time: first the straight-line estimate solving `|p_lead(t) - p_last| = V (t - t_last)`,
//! then, per seed, the time `t` at which the seed's own length equals `V (t - t_0)` with
//! the spline ending at `p_lead(t)` along the lead's heading (a safeguarded false
//! position on a decreasing function; [`Seed::rendezvous_residual`] reports how well it
//! closed). The last leg's bulge is `b` times that leg's length at the straight-line
//! estimate: a bulge proportional to the leg's own (growing) length never meets the lead.
//!
//! Building the seeds runs once per plan, before the swarm's loop: it allocates small
//! working lists, and seeds only when `out` must grow (a re-plan reuses their buffers).

mod spline;

use std::fmt;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wingman_interfaces::{MAX_PHASES, Model, Objective};

use crate::lead::LeadPath;
use crate::problem::{Problem, Threats};
use crate::threat::{ExposureAcc, Superquadric, cutoff_f};
use spline::{MAX_NODES, Spline2, dist2};

/// Bad seed settings or a problem the seeds cannot be built for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SeedError {
    /// A setting is out of range.
    #[error("seed settings: {0}")]
    Settings(String),
    /// The problem lacks what its objective needs, or holds non-finite numbers.
    #[error("seed problem: {0}")]
    Problem(String),
}

/// Settings of the seed families (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct SeedSettings {
    /// Bulge ratios `b` (bulge point `b · d` off the leg's midpoint), each used to the left
    /// and to the right. Default `[0.25, 0.5]` (the reference's multistart ratios).
    pub bulge_ratios: Vec<f64>,
    /// Number of random seeds. Default 8.
    pub random_seeds: usize,
    /// Largest random bulge ratio. Default 0.6.
    pub random_bulge_max: f64,
    /// Add the length-matched family for `fixed-time` objectives. Default true.
    pub fit_fixed_time: bool,
    /// Add the [`Altitude::High`] profile in 3-D. Default true.
    pub high_profile: bool,
    /// Plateau of the high profile above the higher end of a leg, as a fraction of that
    /// end's altitude. Default 0.1 (15 km ends: a 16.5 km plateau, above threats topping
    /// out at 15 km).
    pub high_margin: f64,
    /// Ramp angle of the high profile as a fraction of `gamma_max`. Default 0.6.
    pub ramp_gamma_ratio: f64,
    /// Most seeds produced; with many legs the arc combinations are subsampled. Default 128.
    pub max_seeds: usize,
    /// Points of each seed's polyline. Default 384.
    pub points_per_seed: usize,
    /// Bisector scan: bulge ratios tried per leg, evenly over `[-scan_max, scan_max]`
    /// (0 turns the scan off). Default 65.
    pub scan_steps: usize,
    /// Largest ratio of the scan. Default 0.8.
    pub scan_max: f64,
    /// Local minima kept per leg (the cheapest). Default 3.
    pub scan_minima: usize,
    /// Scanned combinations (cheapest first) polished in context. Default 8.
    pub scan_polish: usize,
    /// Seed of the random families (ChaCha8).
    pub rng_seed: u64,
}

impl Default for SeedSettings {
    fn default() -> Self {
        SeedSettings {
            bulge_ratios: vec![0.25, 0.5],
            random_seeds: 8,
            random_bulge_max: 0.6,
            fit_fixed_time: true,
            high_profile: true,
            high_margin: 0.1,
            ramp_gamma_ratio: 0.6,
            max_seeds: 128,
            points_per_seed: 384,
            scan_steps: 65,
            scan_max: 0.8,
            scan_minima: 3,
            scan_polish: 8,
            rng_seed: 0x5eed,
        }
    }
}

impl SeedSettings {
    /// Sets [`SeedSettings::bulge_ratios`].
    pub fn with_bulge_ratios(mut self, ratios: &[f64]) -> Self {
        self.bulge_ratios = ratios.to_vec();
        self
    }
    /// Sets [`SeedSettings::random_seeds`].
    pub fn with_random_seeds(mut self, n: usize) -> Self {
        self.random_seeds = n;
        self
    }
    /// Sets [`SeedSettings::random_bulge_max`].
    pub fn with_random_bulge_max(mut self, b: f64) -> Self {
        self.random_bulge_max = b;
        self
    }
    /// Sets [`SeedSettings::fit_fixed_time`].
    pub fn with_fit_fixed_time(mut self, on: bool) -> Self {
        self.fit_fixed_time = on;
        self
    }
    /// Sets [`SeedSettings::high_profile`].
    pub fn with_high_profile(mut self, on: bool) -> Self {
        self.high_profile = on;
        self
    }
    /// Sets [`SeedSettings::high_margin`].
    pub fn with_high_margin(mut self, m: f64) -> Self {
        self.high_margin = m;
        self
    }
    /// Sets [`SeedSettings::max_seeds`].
    pub fn with_max_seeds(mut self, n: usize) -> Self {
        self.max_seeds = n;
        self
    }
    /// Sets [`SeedSettings::points_per_seed`].
    pub fn with_points_per_seed(mut self, n: usize) -> Self {
        self.points_per_seed = n;
        self
    }
    /// Sets [`SeedSettings::scan_steps`].
    pub fn with_scan_steps(mut self, n: usize) -> Self {
        self.scan_steps = n;
        self
    }
    /// Sets [`SeedSettings::scan_minima`].
    pub fn with_scan_minima(mut self, n: usize) -> Self {
        self.scan_minima = n;
        self
    }
    /// Sets [`SeedSettings::rng_seed`].
    pub fn with_rng_seed(mut self, seed: u64) -> Self {
        self.rng_seed = seed;
        self
    }

    /// Checks every setting is in range.
    pub fn validate(&self) -> Result<(), SeedError> {
        let bad = |m: &str| Err(SeedError::Settings(m.to_string()));
        if self.bulge_ratios.len() > 8
            || self
                .bulge_ratios
                .iter()
                .any(|b| !(b.is_finite() && *b > 0.0 && *b <= 4.0))
        {
            return bad("bulge_ratios: at most 8 ratios, each in (0, 4]");
        }
        if !(self.random_bulge_max.is_finite() && (0.0..=4.0).contains(&self.random_bulge_max)) {
            return bad("random_bulge_max must be in [0, 4]");
        }
        if !(self.high_margin.is_finite() && (0.0..=10.0).contains(&self.high_margin)) {
            return bad("high_margin must be in [0, 10]");
        }
        if !(self.ramp_gamma_ratio.is_finite()
            && self.ramp_gamma_ratio > 0.0
            && self.ramp_gamma_ratio <= 1.0)
        {
            return bad("ramp_gamma_ratio must be in (0, 1]");
        }
        if self.max_seeds == 0 || self.max_seeds > 4096 {
            return bad("max_seeds must be in 1..=4096");
        }
        if !(16..=100_000).contains(&self.points_per_seed) {
            return bad("points_per_seed must be in 16..=100000");
        }
        if self.scan_steps == 1 || self.scan_steps > 1001 {
            return bad("scan_steps must be 0 or in 2..=1001");
        }
        if !(self.scan_max.is_finite() && self.scan_max > 0.0 && self.scan_max <= 4.0) {
            return bad("scan_max must be in (0, 4]");
        }
        if self.scan_minima > 16 {
            return bad("scan_minima must be at most 16");
        }
        if self.random_seeds > self.max_seeds {
            return bad("random_seeds must not exceed max_seeds");
        }
        Ok(())
    }
}

/// Altitude profile of a 3-D seed (2-D seeds are [`Altitude::Direct`] at z = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Altitude {
    /// Constant climb or descent angle over each leg.
    #[default]
    Direct,
    /// A plateau above both ends of each leg: climb early, descend late.
    High,
}

/// Which family a seed belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeedKind {
    /// A combination of the bulge ratios.
    #[default]
    Arc,
    /// Length-matched to a fixed final time.
    FixedTimeFit,
    /// Random ratios; the number counts the random seeds.
    Random(u32),
    /// Each leg's ratio a local minimum of that leg's cost along its bisector.
    Scan,
}

/// Names a seed: family, bulge ratio of each leg (positive left), altitude profile.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SeedLabel {
    pub kind: SeedKind,
    /// Number of legs (targets + 1).
    pub legs: usize,
    /// Bulge ratio of each leg (first `legs` entries).
    pub bulges: [f64; MAX_PHASES],
    pub altitude: Altitude,
    /// 3-D (the altitude profile is part of the name).
    pub spatial: bool,
}

impl fmt::Display for SeedLabel {
    /// `LR@0.5`, `SL@0.25/high`, `fit:RR@0.71`, `rand3` (as `winning_start` in the
    /// reference), `L0.25R0.5` when the legs' ratios differ.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let legs = &self.bulges[..self.legs.min(MAX_PHASES)];
        match self.kind {
            SeedKind::Random(i) => write!(f, "rand{i}")?,
            kind => {
                if kind == SeedKind::FixedTimeFit {
                    write!(f, "fit:")?;
                }
                if kind == SeedKind::Scan {
                    write!(f, "scan:")?;
                }
                let side = |b: f64| {
                    if b.abs() < 1e-12 {
                        'S'
                    } else if b > 0.0 {
                        'L'
                    } else {
                        'R'
                    }
                };
                let mags: Vec<f64> = legs
                    .iter()
                    .filter(|b| b.abs() >= 1e-12)
                    .map(|b| b.abs())
                    .collect();
                let common = mags.windows(2).all(|w| (w[0] - w[1]).abs() < 1e-9);
                if common {
                    for &b in legs {
                        write!(f, "{}", side(b))?;
                    }
                    if let Some(m) = mags.first() {
                        write!(f, "@{}", round_label(*m))?;
                    }
                } else {
                    for &b in legs {
                        write!(f, "{}", side(b))?;
                        if b.abs() >= 1e-12 {
                            write!(f, "{}", round_label(b.abs()))?;
                        }
                    }
                }
            }
        }
        if self.spatial && self.altitude == Altitude::High {
            write!(f, "/high")?;
        }
        Ok(())
    }
}

fn round_label(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

/// One seed: a polyline of the spline path with its horizontal arc length, the polyline
/// index of each target and of the end (the *gates*), and its 3-D length.
#[derive(Debug, Clone, Default)]
pub struct Seed {
    label: SeedLabel,
    points: Vec<[f64; 3]>,
    arc: Vec<f64>,
    gates: [usize; MAX_PHASES],
    n_gates: usize,
    length: f64,
    end_heading: f64,
    end_gamma: f64,
    start_heading: f64,
    start_gamma: f64,
    rendezvous_time: Option<f64>,
    rendezvous_residual: f64,
}

impl Seed {
    /// The seed's name.
    pub fn label(&self) -> &SeedLabel {
        &self.label
    }

    /// Points of the path `[x, y, z]` (z = 0 in 2-D), from the start to the end.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Horizontal arc length at each point (0 at the start).
    pub fn arc_lengths(&self) -> &[f64] {
        &self.arc
    }

    /// Index into [`Seed::points`] of each target, then of the end.
    pub fn gates(&self) -> &[usize] {
        &self.gates[..self.n_gates]
    }

    /// Length of the path (3-D in 3-D), m.
    pub fn length(&self) -> f64 {
        self.length
    }

    /// Heading along which the path leaves the start (the initial heading), rad.
    pub fn start_heading(&self) -> f64 {
        self.start_heading
    }

    /// Flight-path angle at the start (the initial one), rad.
    pub fn start_gamma(&self) -> f64 {
        self.start_gamma
    }

    /// Heading along which the path arrives at its end, rad.
    pub fn end_heading(&self) -> f64 {
        self.end_heading
    }

    /// Flight-path angle wanted at the end (the final state's or the lead's), rad.
    pub fn end_gamma(&self) -> f64 {
        self.end_gamma
    }

    /// For a rendezvous: the predicted meeting time (the spline ends at the lead's position
    /// then).
    pub fn rendezvous_time(&self) -> Option<f64> {
        self.rendezvous_time
    }

    /// For a rendezvous: `|t0 + length / V - t_meet|` in seconds, the closure of the
    /// meeting-time prediction (0 for other objectives).
    pub fn rendezvous_residual(&self) -> f64 {
        self.rendezvous_residual
    }

    /// Position at horizontal arc length `s` (linear between points; beyond the end, along
    /// the end heading and flight-path angle).
    pub fn point_at_arc(&self, s: f64) -> [f64; 3] {
        let n = self.points.len();
        if n == 0 {
            return [0.0; 3];
        }
        let last = self.arc[n - 1];
        if s >= last {
            let e = self.points[n - 1];
            let ds = s - last;
            let (sc, cc) = self.end_heading.sin_cos();
            return [
                e[0] + ds * cc,
                e[1] + ds * sc,
                e[2] + ds * self.end_gamma.tan(),
            ];
        }
        if s <= 0.0 {
            return self.points[0];
        }
        let k = self
            .arc
            .partition_point(|&a| a <= s)
            .saturating_sub(1)
            .min(n - 2);
        let (a, b) = (self.arc[k], self.arc[k + 1]);
        let f = if b > a { (s - a) / (b - a) } else { 0.0 };
        let (p, q) = (&self.points[k], &self.points[k + 1]);
        std::array::from_fn(|c| p[c] + f * (q[c] - p[c]))
    }

    fn reset(&mut self) {
        self.points.clear();
        self.arc.clear();
        self.n_gates = 0;
        self.rendezvous_time = None;
        self.rendezvous_residual = 0.0;
    }
}

/// Builds the seeds of `problem` into `out` (replacing its contents, reusing its buffers).
pub fn seeds(
    problem: &Problem,
    settings: &SeedSettings,
    out: &mut Vec<Seed>,
) -> Result<(), SeedError> {
    seeds_until(problem, settings, out, &|| false)
}

/// [`seeds`], but once `stop()` says so (checked before each seed is built, after the
/// first) the seeds not yet built are left out: the most promising come first (the
/// scan's, cheapest first, then the arcs, the fixed-time fits, the random curves).
pub fn seeds_until(
    problem: &Problem,
    settings: &SeedSettings,
    out: &mut Vec<Seed>,
    stop: &dyn Fn() -> bool,
) -> Result<(), SeedError> {
    settings.validate()?;
    let ctx = Context::new(problem, settings)?;
    let mut rng = ChaCha8Rng::seed_from_u64(settings.rng_seed);
    let legs = ctx.legs;
    let altitudes: &[Altitude] = if ctx.spatial && settings.high_profile {
        &[Altitude::Direct, Altitude::High]
    } else {
        &[Altitude::Direct]
    };
    let fit = settings.fit_fixed_time && problem.objective == Objective::FixedTime;
    let n_signs = 3usize.saturating_pow(legs as u32) - 1;
    let fit_budget = if fit {
        n_signs.min(26) * altitudes.len()
    } else {
        0
    };
    let arc_budget = settings
        .max_seeds
        .saturating_sub(settings.random_seeds)
        .saturating_sub(fit_budget)
        .max(1);

    let mut specs: Vec<Spec> = Vec::new();
    // Bisector scan: every combination of each leg's local minima (at most 27).
    if settings.scan_steps >= 2 && settings.scan_minima > 0 {
        for &alt in altitudes {
            if let (Some((mins, counts)), Some(end)) = (ctx.scan(settings, alt), ctx.scan_end()) {
                let total: usize = counts[..legs].iter().product();
                let mut combos: Vec<(f64, [f64; MAX_PHASES])> = (0..total.min(27))
                    .map(|idx| {
                        let mut bulges = [0.0; MAX_PHASES];
                        let mut r = idx;
                        for g in (0..legs).rev() {
                            bulges[g] = mins[g][r % counts[g]];
                            r /= counts[g];
                        }
                        (ctx.path_cost(&bulges, alt, &end), bulges)
                    })
                    .collect();
                combos.sort_by(|a, b| a.0.total_cmp(&b.0));
                let step = 2.0 * settings.scan_max / (settings.scan_steps - 1) as f64;
                for (k, (_, mut bulges)) in combos.into_iter().enumerate() {
                    if k < settings.scan_polish {
                        ctx.polish(step, &mut bulges, alt, &end);
                    }
                    specs.push(Spec {
                        bulges,
                        altitude: alt,
                        kind: SeedKind::Scan,
                    });
                }
            }
        }
    }
    // Arcs: options per leg [0, +b1, -b1, +b2, -b2, ...].
    let mut options = vec![0.0];
    for &b in &settings.bulge_ratios {
        options.push(b);
        options.push(-b);
    }
    let per_alt = (arc_budget / altitudes.len()).max(1);
    let combos = options.len().checked_pow(legs as u32).unwrap_or(usize::MAX);
    let mut patterns: Vec<[f64; MAX_PHASES]> = Vec::new();
    if combos <= per_alt {
        for idx in 0..combos {
            patterns.push(decode(idx, &options, legs));
        }
    } else {
        // Too many legs for every combination: the uniform patterns, then distinct
        // combinations drawn at random.
        for &o in &options {
            let mut p = [0.0; MAX_PHASES];
            p[..legs].fill(o);
            patterns.push(p);
        }
        let mut tries = 0;
        while patterns.len() < per_alt && tries < 100 * per_alt {
            tries += 1;
            let idx = rng.random_range(0..combos);
            let p = decode(idx, &options, legs);
            if !patterns.contains(&p) {
                patterns.push(p);
            }
        }
        patterns.truncate(per_alt);
    }
    for &alt in altitudes {
        for p in &patterns {
            specs.push(Spec {
                bulges: *p,
                altitude: alt,
                kind: SeedKind::Arc,
            });
        }
    }
    // Fixed-time fits: the sign patterns in {L, S, R}^legs except all straight.
    if fit {
        let mut signs: Vec<[f64; MAX_PHASES]> = Vec::new();
        if n_signs <= 26 {
            for idx in 1..=n_signs {
                signs.push(decode(idx, &[0.0, 1.0, -1.0], legs));
            }
        } else {
            for (a, b) in [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)] {
                let mut p = [0.0; MAX_PHASES];
                for (g, v) in p[..legs].iter_mut().enumerate() {
                    *v = if g % 2 == 0 { a } else { b };
                }
                signs.push(p);
            }
        }
        for &alt in altitudes {
            for s in &signs {
                if let Some(b) = ctx.fit_fixed_time(s, alt) {
                    let mut bulges = [0.0; MAX_PHASES];
                    for g in 0..legs {
                        bulges[g] = s[g] * b;
                    }
                    specs.push(Spec {
                        bulges,
                        altitude: alt,
                        kind: SeedKind::FixedTimeFit,
                    });
                }
            }
        }
    }
    // Random curves.
    for i in 0..settings.random_seeds {
        let mut bulges = [0.0; MAX_PHASES];
        for b in bulges[..legs].iter_mut() {
            *b = settings.random_bulge_max * (2.0 * rng.random::<f64>() - 1.0);
        }
        let altitude = if altitudes.len() > 1 && rng.random::<f64>() < 0.5 {
            Altitude::High
        } else {
            Altitude::Direct
        };
        specs.push(Spec {
            bulges,
            altitude,
            kind: SeedKind::Random(i as u32),
        });
    }
    specs.truncate(settings.max_seeds);

    let mut count = 0;
    for spec in &specs {
        if count > 0 && stop() {
            break;
        }
        if out.len() <= count {
            out.push(Seed::default());
        }
        if ctx.build_seed(spec, &mut out[count]) {
            count += 1;
        }
    }
    out.truncate(count);
    if count == 0 {
        return Err(SeedError::Problem(
            "no seed could be built (coincident start, targets and end?)".into(),
        ));
    }
    Ok(())
}

/// Mixed-radix decoding of a combination index into a bulge per leg.
fn decode(mut idx: usize, options: &[f64], legs: usize) -> [f64; MAX_PHASES] {
    let mut p = [0.0; MAX_PHASES];
    for v in p[..legs].iter_mut().rev() {
        *v = options[idx % options.len()];
        idx /= options.len();
    }
    p
}

#[derive(Debug, Clone, Copy)]
struct Spec {
    bulges: [f64; MAX_PHASES],
    altitude: Altitude,
    kind: SeedKind,
}

/// Where a seed ends.
#[derive(Debug, Clone, Copy)]
struct EndPoint {
    p: [f64; 3],
    heading: f64,
    gamma: f64,
}

/// Piecewise-linear altitude over a leg's horizontal arc length.
#[derive(Debug, Clone, Copy)]
struct Profile {
    s: [f64; 4],
    z: [f64; 4],
    n: usize,
}

impl Profile {
    fn z_at(&self, s: f64) -> f64 {
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

    fn length(&self) -> f64 {
        (1..self.n)
            .map(|k| (self.s[k] - self.s[k - 1]).hypot(self.z[k] - self.z[k - 1]))
            .sum()
    }
}

/// The geometry of one seed before sampling: the spline, its nodes and each leg's
/// altitude profile.
struct Geometry {
    spline: Spline2,
    /// Node index of each leg's end.
    gate_nodes: [usize; MAX_PHASES],
    /// Horizontal length of each spline segment.
    seg_len: [f64; MAX_NODES],
    profiles: [Profile; MAX_PHASES],
    length: f64,
}

/// Moving threats' regions at fixed times for the scan and the polish, which evaluate the
/// exposure tens of thousands of times: propagating the estimate for every point would
/// dominate the seeds' cost. A point's time is rounded to the table's step (5 s: the
/// threats of the scenarios move under 100 m in that time).
struct MovingTable {
    t0: f64,
    step: f64,
    times: usize,
    per_time: usize,
    planar: Vec<(Superquadric<2>, [f64; 2], bool)>,
    spatial: Vec<(Superquadric<3>, [f64; 3], bool)>,
}

impl MovingTable {
    const STEP: f64 = 5.0;

    /// The table over `[t0, t0 + span]`, `None` without moving threats.
    fn new(problem: &Problem, span: f64) -> Option<Self> {
        let t0 = problem.t0;
        let times = ((span / Self::STEP).ceil() as usize + 1).clamp(2, 100_000);
        let mut table = MovingTable {
            t0,
            step: Self::STEP,
            times,
            per_time: 0,
            planar: Vec::new(),
            spatial: Vec::new(),
        };
        match &problem.threats {
            Threats::Planar { layout, moving } if !moving.is_empty() => {
                let fc = cutoff_f(layout.stiffness());
                table.per_time = moving.len();
                for k in 0..times {
                    let t = t0 + k as f64 * Self::STEP;
                    for m in moving {
                        let r = m.region_at(t);
                        table.planar.push((
                            r.shape,
                            r.shape.cutoff_half_extents(fc, true),
                            m.is_active(t),
                        ));
                    }
                }
                Some(table)
            }
            Threats::Spatial { layout, moving } if !moving.is_empty() => {
                let fc = cutoff_f(layout.stiffness());
                table.per_time = moving.len();
                for k in 0..times {
                    let t = t0 + k as f64 * Self::STEP;
                    for m in moving {
                        let r = m.region_at(t);
                        table.spatial.push((
                            r.shape,
                            r.shape.cutoff_half_extents(fc, true),
                            m.is_active(t),
                        ));
                    }
                }
                Some(table)
            }
            _ => None,
        }
    }

    /// `E` at `p` and (rounded) `t`: the static layout, then the tabled regions.
    fn exposure(&self, problem: &Problem, p: &[f64; 3], t: f64) -> f64 {
        let k = (((t - self.t0) / self.step).round().max(0.0) as usize).min(self.times - 1);
        let range = k * self.per_time..(k + 1) * self.per_time;
        match &problem.threats {
            Threats::Planar { layout, .. } => {
                let w = [p[0], p[1]];
                let mut acc = ExposureAcc::<2>::new();
                layout.fold_value_into(&w, &mut acc);
                for (shape, half, active) in &self.planar[range] {
                    if *active && !shape.outside_box(&w, half) {
                        acc.fold_value(shape.f(&w), layout.stiffness());
                    }
                }
                acc.e.value
            }
            Threats::Spatial { layout, .. } => {
                let mut acc = ExposureAcc::<3>::new();
                layout.fold_value_into(p, &mut acc);
                for (shape, half, active) in &self.spatial[range] {
                    if *active && !shape.outside_box(p, half) {
                        acc.fold_value(shape.f(p), layout.stiffness());
                    }
                }
                acc.e.value
            }
        }
    }
}

/// What every seed of one problem shares.
struct Context<'a> {
    problem: &'a Problem,
    spatial: bool,
    legs: usize,
    t0: f64,
    speed: f64,
    start: [f64; 3],
    heading0: f64,
    gamma0: f64,
    targets: &'a [[f64; 3]],
    end: Option<EndPoint>,
    lead: Option<&'a LeadPath>,
    fixed_time: Option<f64>,
    tan_ramp: f64,
    high_margin: f64,
    points: usize,
    /// Moving threats' regions for the scan and the polish.
    table: Option<MovingTable>,
    /// Straight-line estimate of the meeting time (rendezvous).
    meet_estimate: f64,
    /// Rendezvous: horizontal length of the last leg at that estimate. The last leg's
    /// bulge is `b` times this fixed length: a bulge proportional to the leg's own length
    /// would grow faster than the wingman closes on the lead (at `b = 0.5` the path
    /// grows by ~1.6 m per metre the lead moves), and the seed would never meet it.
    meet_leg: f64,
}

impl<'a> Context<'a> {
    fn new(problem: &'a Problem, settings: &SeedSettings) -> Result<Self, SeedError> {
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

    fn horizontal(p: &[f64; 3]) -> [f64; 2] {
        [p[0], p[1]]
    }

    /// Straight-line meeting time: the first `t` with `|p_lead(t) - p_last| = V (t -
    /// t_last)`, `t_last` the time at the last target flying the straight legs at `V`
    /// (bisection on the increasing `V (t - t_last) - |p_lead(t) - p_last|` when the lead
    /// is slower; the time of closest reach otherwise).
    fn straight_meeting_time(&self, lead: &LeadPath) -> f64 {
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
    fn lead_end(&self, lead: &LeadPath, t: f64) -> EndPoint {
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
    fn profile(&self, alt: Altitude, za: f64, zb: f64, len: f64) -> Profile {
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
        let top = za.max(zb);
        let mut zp = top + self.high_margin * top.abs();
        let t = self.tan_ramp;
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
    fn geometry(
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
    fn fit_fixed_time(&self, signs: &[f64; MAX_PHASES], alt: Altitude) -> Option<f64> {
        let tf = self.fixed_time?;
        let end = self.end?;
        let want = self.speed * (tf - self.t0);
        let len = |b: f64| {
            let mut bulges = [0.0; MAX_PHASES];
            for g in 0..self.legs {
                bulges[g] = signs[g] * b;
            }
            self.geometry(&bulges, alt, &end).map(|g| g.length)
        };
        let l0 = len(0.0)?;
        if l0 >= want {
            return None;
        }
        let (mut lo, mut hi) = (0.0, 2.0);
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
    fn meeting_time(
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

    /// Where the seeds end for the scan: the final point, or the lead at the straight-line
    /// meeting estimate.
    fn scan_end(&self) -> Option<EndPoint> {
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
    fn leg_cost(&self, geo: &Geometry, g: usize, t_start: f64) -> (f64, f64) {
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
    fn path_cost(&self, bulges: &[f64; MAX_PHASES], alt: Altitude, end: &EndPoint) -> f64 {
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
    fn polish(&self, step: f64, bulges: &mut [f64; MAX_PHASES], alt: Altitude, end: &EndPoint) {
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
    fn scan(
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

    /// Builds one seed into `seed`; false when its geometry is degenerate.
    fn build_seed(&self, spec: &Spec, seed: &mut Seed) -> bool {
        seed.reset();
        let (end, meet) = match (self.end, self.lead) {
            (Some(e), _) => (e, None),
            (None, Some(lead)) => match self.meeting_time(lead, &spec.bulges, spec.altitude) {
                Some((t, r)) => (self.lead_end(lead, t), Some((t, r))),
                None => return false,
            },
            (None, None) => return false,
        };
        let Some(geo) = self.geometry(&spec.bulges, spec.altitude, &end) else {
            return false;
        };
        let nodes = geo.spline.nodes();
        let total: f64 = geo.seg_len[..nodes - 1].iter().sum();
        // Sample each segment with a share of the points proportional to its length.
        let mut node_index = [0usize; MAX_NODES];
        let mut s_acc = 0.0;
        for (i, index) in node_index.iter_mut().enumerate().take(nodes - 1) {
            let share = if total > 0.0 {
                geo.seg_len[i] / total
            } else {
                1.0 / (nodes - 1) as f64
            };
            let count = ((self.points as f64 * share).round() as usize).max(2);
            *index = seed.points.len();
            let (p0, _) = geo.spline.eval(i, 0.0);
            let mut prev = p0;
            for j in 0..count {
                let (p, _) = geo.spline.eval(i, j as f64 / count as f64);
                s_acc += dist2(&prev, &p);
                prev = p;
                seed.points.push([p[0], p[1], 0.0]);
                seed.arc.push(s_acc);
            }
            let (p1, _) = geo.spline.eval(i, 1.0);
            s_acc += dist2(&prev, &p1);
        }
        let (pe, _) = geo.spline.eval(nodes - 2, 1.0);
        node_index[nodes - 1] = seed.points.len();
        seed.points.push([pe[0], pe[1], 0.0]);
        seed.arc.push(s_acc);
        // Altitudes from each leg's profile over the leg's own arc length.
        let mut first = 0;
        for g in 0..self.legs {
            let last = node_index[geo.gate_nodes[g]];
            let s0 = seed.arc[first];
            let prof = &geo.profiles[g];
            let scale = {
                // The profile was built on the spline's exact length; map the polyline's.
                let poly = seed.arc[last] - s0;
                if poly > 0.0 {
                    prof.s[prof.n - 1] / poly
                } else {
                    1.0
                }
            };
            for k in first..=last {
                seed.points[k][2] = if self.spatial {
                    prof.z_at((seed.arc[k] - s0) * scale)
                } else {
                    0.0
                };
            }
            seed.gates[g] = last;
            first = last;
        }
        seed.n_gates = self.legs;
        seed.length = geo.length;
        seed.start_heading = self.heading0;
        seed.start_gamma = self.gamma0;
        seed.end_heading = end.heading;
        seed.end_gamma = end.gamma;
        seed.label = SeedLabel {
            kind: spec.kind,
            legs: self.legs,
            bulges: spec.bulges,
            altitude: spec.altitude,
            spatial: self.spatial,
        };
        if let Some((t, r)) = meet {
            seed.rendezvous_time = Some(t);
            seed.rendezvous_residual = r;
        }
        seed.points.iter().flatten().all(|v| v.is_finite())
    }
}

fn dist3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_read_like_the_reference() {
        let mut l = SeedLabel {
            kind: SeedKind::Arc,
            legs: 2,
            bulges: [0.0; MAX_PHASES],
            altitude: Altitude::Direct,
            spatial: false,
        };
        l.bulges[0] = 0.5;
        l.bulges[1] = -0.5;
        assert_eq!(l.to_string(), "LR@0.5");
        l.bulges[0] = 0.0;
        l.bulges[1] = 0.25;
        l.spatial = true;
        l.altitude = Altitude::High;
        assert_eq!(l.to_string(), "SL@0.25/high");
        l.bulges[0] = -0.5;
        assert_eq!(l.to_string(), "R0.5L0.25/high");
        l.kind = SeedKind::Random(3);
        assert_eq!(l.to_string(), "rand3/high");
    }

    #[test]
    fn decode_enumerates_every_combination() {
        let opts = [0.0, 1.0, -1.0];
        let all: Vec<_> = (0..9).map(|i| decode(i, &opts, 2)).collect();
        for a in &opts {
            for b in &opts {
                assert!(all.iter().any(|p| p[0] == *a && p[1] == *b));
            }
        }
    }
}
