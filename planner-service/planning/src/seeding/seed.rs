//! A seed and its name: the family, the bulge ratio of each leg and the altitude profile.

use std::fmt;

use wingman_interfaces::MAX_PHASES;

/// Altitude profile of a 3-D seed (2-D seeds are [`Altitude::Direct`] at z = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Altitude {
    /// Constant climb or descent angle over each leg.
    #[default]
    Direct,
    /// A plateau above both ends of each leg: climb early, descend late.
    High,
    /// Reach the leg's end altitude first (at the ramp angle), then hold it: descend or
    /// climb early.
    Early,
    /// Hold the leg's start altitude, then reach the end's at the ramp angle: descend or
    /// climb late.
    Late,
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
        if self.spatial {
            match self.altitude {
                Altitude::Direct => {}
                Altitude::High => write!(f, "/high")?,
                Altitude::Early => write!(f, "/early")?,
                Altitude::Late => write!(f, "/late")?,
            }
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
    pub(super) label: SeedLabel,
    pub(super) points: Vec<[f64; 3]>,
    pub(super) arc: Vec<f64>,
    pub(super) gates: [usize; MAX_PHASES],
    pub(super) n_gates: usize,
    pub(super) length: f64,
    pub(super) end_heading: f64,
    pub(super) end_gamma: f64,
    pub(super) start_heading: f64,
    pub(super) start_gamma: f64,
    pub(super) rendezvous_time: Option<f64>,
    pub(super) rendezvous_residual: f64,
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

    pub(super) fn reset(&mut self) {
        self.points.clear();
        self.arc.clear();
        self.n_gates = 0;
        self.rendezvous_time = None;
        self.rendezvous_residual = 0.0;
    }
}
