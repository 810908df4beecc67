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

mod cost;
mod flight;
mod from_seed;
mod grid;
mod output;
mod passes;

pub(crate) use cost::{Report, Score, evaluate};
pub(crate) use from_seed::track;
pub(crate) use grid::{Grid, GridParams};
pub(crate) use output::{OutBuffers, write_trajectory};

#[cfg(doc)]
use crate::trajectory::Trajectory;

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
