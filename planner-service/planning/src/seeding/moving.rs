//! Moving threats' regions tabled at fixed times for the bisector scan and the polish.

use crate::estimation::{TabledRegion, tabulate};
use crate::problem::{Problem, Threats};
use crate::threat::{ExposureAcc, cutoff_f};

/// Moving threats' regions at fixed times for the scan and the polish, which evaluate the
/// exposure tens of thousands of times: propagating the estimate for every point would
/// dominate the seeds' cost. A point's time is rounded to the table's step (5 s: the
/// threats of the scenarios move under 100 m in that time).
pub(super) struct MovingTable {
    pub(super) t0: f64,
    pub(super) step: f64,
    pub(super) times: usize,
    pub(super) per_time: usize,
    pub(super) planar: Vec<TabledRegion<2>>,
    pub(super) spatial: Vec<TabledRegion<3>>,
}

impl MovingTable {
    pub(super) const STEP: f64 = 5.0;

    /// The table over `[t0, t0 + span]`, `None` without moving threats.
    pub(super) fn new(problem: &Problem, span: f64) -> Option<Self> {
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
        let times = (0..times).map(|k| t0 + k as f64 * Self::STEP);
        match &problem.threats {
            Threats::Planar { layout, moving } if !moving.is_empty() => {
                table.per_time = moving.len();
                tabulate(
                    moving,
                    times,
                    cutoff_f(layout.stiffness()),
                    &mut table.planar,
                );
                Some(table)
            }
            Threats::Spatial { layout, moving } if !moving.is_empty() => {
                table.per_time = moving.len();
                tabulate(
                    moving,
                    times,
                    cutoff_f(layout.stiffness()),
                    &mut table.spatial,
                );
                Some(table)
            }
            _ => None,
        }
    }

    /// `E` at `p` and (rounded) `t`: the static layout, then the tabled regions.
    pub(super) fn exposure(&self, problem: &Problem, p: &[f64; 3], t: f64) -> f64 {
        let k = (((t - self.t0) / self.step).round().max(0.0) as usize).min(self.times - 1);
        let range = k * self.per_time..(k + 1) * self.per_time;
        match &problem.threats {
            Threats::Planar { layout, .. } => {
                let w = [p[0], p[1]];
                let mut acc = ExposureAcc::<2>::new();
                layout.fold_value_into(&w, &mut acc);
                for r in &self.planar[range] {
                    r.fold_value_into(&w, &mut acc, layout.stiffness());
                }
                acc.e.value
            }
            Threats::Spatial { layout, .. } => {
                let mut acc = ExposureAcc::<3>::new();
                layout.fold_value_into(p, &mut acc);
                for r in &self.spatial[range] {
                    r.fold_value_into(p, &mut acc, layout.stiffness());
                }
                acc.e.value
            }
        }
    }
}
