//! The seed families as specs (bulge ratio per leg, altitude profile, family), in the order
//! they are built: the bisector scan's combinations, the arcs, the fixed-time fits, the
//! random curves (see the module documentation of [`crate::seeding`]).

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use wingman_interfaces::{MAX_PHASES, Objective};

use super::context::Context;
use super::seed::{Altitude, SeedKind};
use super::settings::SeedSettings;

/// What to build one seed from.
#[derive(Debug, Clone, Copy)]
pub(super) struct Spec {
    pub(super) bulges: [f64; MAX_PHASES],
    pub(super) altitude: Altitude,
    pub(super) kind: SeedKind,
}

/// The specs of every family, most promising first, at most `max_seeds` of them. The
/// arcs (with too many legs for every combination) and the random curves draw from `rng`,
/// in that order.
pub(super) fn specs(ctx: &Context, settings: &SeedSettings, rng: &mut ChaCha8Rng) -> Vec<Spec> {
    let legs = ctx.legs;
    let mut altitudes = vec![Altitude::Direct];
    if ctx.spatial && settings.high_profile {
        altitudes.push(Altitude::High);
    }
    if ctx.spatial && settings.early_late_profiles {
        altitudes.extend([Altitude::Early, Altitude::Late]);
    }
    let altitudes = altitudes.as_slice();
    let fit = settings.fit_fixed_time && ctx.problem.objective == Objective::FixedTime;
    let n_signs = 3usize.saturating_pow(legs as u32) - 1;
    let fit_budget = if fit {
        n_signs.min(26) * altitudes.len()
    } else {
        0
    };
    // Fixed time: all the spare length on one leg, each leg on either side.
    let one_leg_budget = if fit { 2 * legs * altitudes.len() } else { 0 };

    let mut specs: Vec<Spec> = Vec::new();
    scan_specs(ctx, settings, altitudes, &mut specs);
    // The scan's combinations (up to 27 per profile) come out of the arcs' share when the
    // fits follow them: otherwise the truncation to `max_seeds` cut the fits of 3-leg
    // missions to 7 of 26. (Without fits, the arcs keep their share: those plans stay
    // what they were.)
    let scanned = if fit { specs.len() } else { 0 };
    let arc_budget = settings
        .max_seeds
        .saturating_sub(settings.random_seeds)
        .saturating_sub(fit_budget + one_leg_budget + scanned)
        .max(1);
    arc_specs(settings, legs, altitudes, arc_budget, rng, &mut specs);
    if fit {
        fit_specs(ctx, n_signs, altitudes, &mut specs);
        one_leg_specs(ctx, altitudes, &mut specs);
    }
    random_specs(settings, legs, altitudes, rng, &mut specs);
    specs.truncate(settings.max_seeds);
    specs
}

/// Bisector scan: every combination of each leg's local minima (at most 27), cheapest
/// first, the cheapest `scan_polish` polished in context.
fn scan_specs(
    ctx: &Context,
    settings: &SeedSettings,
    altitudes: &[Altitude],
    specs: &mut Vec<Spec>,
) {
    let legs = ctx.legs;
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
}

/// Arcs: every combination of the options per leg `[0, +b1, -b1, +b2, -b2, ...]`, or
/// with too many legs for every combination, the uniform patterns and distinct
/// combinations drawn at random; the same patterns for each altitude profile.
fn arc_specs(
    settings: &SeedSettings,
    legs: usize,
    altitudes: &[Altitude],
    arc_budget: usize,
    rng: &mut ChaCha8Rng,
    specs: &mut Vec<Spec>,
) {
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
}

/// Fixed-time fits: the sign patterns in {L, S, R}^legs except all straight (four
/// alternating patterns when there are more than 26), each with its length-matching ratio.
fn fit_specs(ctx: &Context, n_signs: usize, altitudes: &[Altitude], specs: &mut Vec<Spec>) {
    let legs = ctx.legs;
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

/// Fixed-time slack on one leg: the scan's cheapest combination on the other legs (they
/// pass the threats where it is cheapest), and on that leg, left or right, the one bulge
/// (bisected from straight, up to 4 times the leg) that takes all the spare length. (With
/// the other legs straight it repeats a common-ratio fit; where 4 legs' worth is still too
/// short it arrives early, ranked as such.) A turn of radius `R` costs `u^2 = (V/R)^2`,
/// so one wide loop through open space is cheaper than the same length spread as tighter
/// bulges over every leg (the common-ratio fits), which is where the yardstick found the
/// better plans of slack fixed-time missions.
fn one_leg_specs(ctx: &Context, altitudes: &[Altitude], specs: &mut Vec<Spec>) {
    let legs = ctx.legs;
    for &alt in altitudes {
        let base = specs
            .iter()
            .find(|s| s.kind == SeedKind::Scan && s.altitude == alt)
            .map_or([0.0; MAX_PHASES], |s| s.bulges);
        for g in 0..legs {
            for side in [1.0, -1.0] {
                let at = |b: f64| {
                    let mut bulges = base;
                    bulges[g] = side * b;
                    bulges
                };
                if let Some(b) = ctx.fit_length(at, 4.0, alt) {
                    specs.push(Spec {
                        bulges: at(b),
                        altitude: alt,
                        kind: SeedKind::FixedTimeFit,
                    });
                }
            }
        }
    }
}

/// Random curves: a ratio per leg drawn uniformly from `[-random_bulge_max,
/// random_bulge_max]`, then (with several profiles) a random profile.
fn random_specs(
    settings: &SeedSettings,
    legs: usize,
    altitudes: &[Altitude],
    rng: &mut ChaCha8Rng,
    specs: &mut Vec<Spec>,
) {
    for i in 0..settings.random_seeds {
        let mut bulges = [0.0; MAX_PHASES];
        for b in bulges[..legs].iter_mut() {
            *b = settings.random_bulge_max * (2.0 * rng.random::<f64>() - 1.0);
        }
        let altitude = match altitudes.len() {
            1 => Altitude::Direct,
            // Two profiles: a coin, as it always was (the default's seeds stay the same).
            2 if rng.random::<f64>() < 0.5 => altitudes[1],
            2 => altitudes[0],
            n => altitudes[rng.random_range(0..n)],
        };
        specs.push(Spec {
            bulges,
            altitude,
            kind: SeedKind::Random(i as u32),
        });
    }
}

/// Mixed-radix decoding of a combination index into a bulge per leg.
pub(super) fn decode(mut idx: usize, options: &[f64], legs: usize) -> [f64; MAX_PHASES] {
    let mut p = [0.0; MAX_PHASES];
    for v in p[..legs].iter_mut().rev() {
        *v = options[idx % options.len()];
        idx /= options.len();
    }
    p
}
