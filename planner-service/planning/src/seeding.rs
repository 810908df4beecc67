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
//!   flown at `V` arrives on time; and for each leg and side, the scan's cheapest
//!   combination with all the spare length on that one leg (one wide loop through open
//!   space is cheaper than the same length spread over every leg: a turn of radius `R`
//!   costs `(V/R)^2`);
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

mod context;
mod families;
mod moving;
mod path;
mod scan;
mod seed;
mod settings;
mod spline;
#[cfg(test)]
mod tests;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::problem::Problem;

use context::Context;
pub use seed::{Altitude, Seed, SeedKind, SeedLabel};
pub use settings::{SeedError, SeedSettings};

/// Builds the seeds of `problem` into `out` (replacing its contents, reusing its buffers).
pub fn seeds(
    problem: &Problem,
    settings: &SeedSettings,
    out: &mut Vec<Seed>,
) -> Result<(), SeedError> {
    seeds_until(problem, settings, out, &|_| false)
}

/// [`seeds`], but once `stop(tried)` says so (checked before each seed is built, after the
/// first; `tried`: the specs tried so far) the seeds not yet built are left out: the most promising come first (the
/// scan's, cheapest first, then the arcs, the fixed-time fits, the random curves).
pub fn seeds_until(
    problem: &Problem,
    settings: &SeedSettings,
    out: &mut Vec<Seed>,
    stop: &dyn Fn(u32) -> bool,
) -> Result<(), SeedError> {
    settings.validate()?;
    let ctx = Context::new(problem, settings)?;
    let mut rng = ChaCha8Rng::seed_from_u64(settings.rng_seed);
    let specs = families::specs(&ctx, settings, &mut rng);

    let mut count = 0;
    for (tried, spec) in specs.iter().enumerate() {
        if count > 0 && stop(tried as u32) {
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
