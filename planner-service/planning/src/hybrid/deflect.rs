//! Deflected starts of a warm re-plan: when a threat the plan in flight did not know (a
//! pop-up) lies across it, the plan solved again from itself stays in its old basin and
//! is only pushed out of the threat on whichever side the gradient points. Two more
//! starts, the plan bent around the threat on its left and on its right, give the NLP
//! both basins.
//!
//! A bend shifts the path sideways (across its heading where it is closest to the
//! threat) by as much as clears the threat, over the time the path is within that
//! clearance, with a half-cosine ramp before and after; the start and the end do not
//! move, and the heading is taken again from the bent positions. The times are kept: the
//! bent path is a little longer than the aircraft flies in them, which the NLP corrects.

use std::f64::consts::PI;

use crate::collocation::transcription::nearest_turn;
use crate::estimation::MovingThreat;
use crate::problem::{Problem, Threats};
use crate::threat::Superquadric;
use crate::trajectory::Trajectory;

/// A threat's horizontal clearance: its largest horizontal half-extent times this.
const CLEARANCE: f64 = 1.3;
/// The ramps into and out of a bend are this many clearances long (flown at the plan's
/// speed).
const RAMP: f64 = 1.5;

/// Where a path crosses a threat: its closest sample, the shift across its heading there
/// that clears the threat to the left (positive) and to the right (negative), and the
/// time it is within the clearance.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Crossing {
    closest: usize,
    normal: [f64; 2],
    shifts: [f64; 2],
    inside: (f64, f64),
    clearance: f64,
}

/// The starts bent around each threat of `problem` that `known` (the plan in flight's
/// threats) lacks and that `guess` passes through (`F < 1`): left, then right, per
/// threat in the layout's order.
pub(super) fn deflected(problem: &Problem, known: &Threats, guess: &Trajectory) -> Vec<Trajectory> {
    let crossings = match (&problem.threats, known) {
        (Threats::Planar { layout, .. }, Threats::Planar { layout: old, .. }) => {
            new_crossings(layout.threats(), old.threats(), guess)
        }
        (Threats::Spatial { layout, .. }, Threats::Spatial { layout: old, .. }) => {
            new_crossings(layout.threats(), old.threats(), guess)
        }
        _ => Vec::new(),
    };
    let h = problem.heading_index();
    crossings
        .iter()
        .flat_map(|c| c.shifts.map(|shift| bent(guess, c, shift, h)))
        .collect()
}

/// Whether `guess` comes within `F < near` of a threat of `problem` that `known` (the plan
/// in flight's threats) lacks: the world changed around the plan. A moving threat counts
/// at each sample's time, and as new whenever its estimate changed.
pub(super) fn near_new_threat(
    problem: &Problem,
    known: &Threats,
    guess: &Trajectory,
    near: f64,
) -> bool {
    match (&problem.threats, known) {
        (
            Threats::Planar { layout, moving },
            Threats::Planar {
                layout: l,
                moving: m,
            },
        ) => near_in(layout.threats(), moving, l.threats(), m, guess, near),
        (
            Threats::Spatial { layout, moving },
            Threats::Spatial {
                layout: l,
                moving: m,
            },
        ) => near_in(layout.threats(), moving, l.threats(), m, guess, near),
        _ => true,
    }
}

/// [`near_new_threat`] in `D` dimensions: static threats not among `known`, moving ones
/// not among `known_moving`.
fn near_in<const D: usize>(
    threats: &[Superquadric<D>],
    moving: &[MovingThreat<D>],
    known: &[Superquadric<D>],
    known_moving: &[MovingThreat<D>],
    guess: &Trajectory,
    near: f64,
) -> bool {
    let at = |k: usize| -> [f64; D] { std::array::from_fn(|i| guess.states[k][i]) };
    let samples = 0..guess.len();
    threats
        .iter()
        .filter(|t| !known.contains(t))
        .any(|t| samples.clone().any(|k| t.f(&at(k)) < near))
        || moving
            .iter()
            .filter(|t| !known_moving.contains(t))
            .any(|t| samples.clone().any(|k| t.f(&at(k), guess.times[k]) < near))
}

/// The crossings of `guess` through threats of `threats` not among `known`.
fn new_crossings<const D: usize>(
    threats: &[Superquadric<D>],
    known: &[Superquadric<D>],
    guess: &Trajectory,
) -> Vec<Crossing> {
    threats
        .iter()
        .filter(|t| !known.contains(t))
        .filter_map(|t| crossing(t, guess))
        .collect()
}

/// Where `guess` passes through `threat`, if it does.
fn crossing<const D: usize>(threat: &Superquadric<D>, guess: &Trajectory) -> Option<Crossing> {
    let n = guess.len();
    if n < 3 {
        return None;
    }
    let position = |k: usize| -> [f64; D] { std::array::from_fn(|i| guess.states[k][i]) };
    let (closest, f_min) = (0..n)
        .map(|k| (k, threat.f(&position(k))))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    if f_min >= 1.0 {
        return None;
    }
    let half = threat.cutoff_half_extents(1.0, false);
    let clearance = CLEARANCE * half[0].max(half[1]);
    let c = threat.center();
    let p = &guess.states[closest];
    let (a, b) = (closest.saturating_sub(1), (closest + 1).min(n - 1));
    let (dx, dy) = (
        guess.states[b][0] - guess.states[a][0],
        guess.states[b][1] - guess.states[a][1],
    );
    let len = dx.hypot(dy);
    if len <= 0.0 {
        return None;
    }
    let normal = [-dy / len, dx / len];
    // The threat's centre across the path from the closest sample: the path clears it
    // on the left by passing `clearance` beyond it, on the right `clearance` short of it.
    let offset = (c[0] - p[0]) * normal[0] + (c[1] - p[1]) * normal[1];
    let near = |k: &usize| {
        let q = &guess.states[*k];
        (q[0] - c[0]).hypot(q[1] - c[1]) < clearance
    };
    let first = (0..n).find(near)?;
    let last = (0..n).rev().find(near)?;
    Some(Crossing {
        closest,
        normal,
        shifts: [offset + clearance, offset - clearance],
        inside: (guess.times[first], guess.times[last]),
        clearance,
    })
}

/// `guess` shifted by `shift` along the crossing's normal over the time it is near the
/// threat, ramped in and out; the first and last samples stay; heading `h` re-taken from
/// the positions (continuous with the first sample's).
fn bent(guess: &Trajectory, c: &Crossing, shift: f64, h: usize) -> Trajectory {
    let n = guess.len();
    let (t_first, t_last) = (guess.times[0], guess.times[n - 1]);
    // The plan's speed where it is closest to the threat.
    let k = c.closest.min(n - 2);
    let (a, b) = (&guess.states[k], &guess.states[k + 1]);
    let dt = (guess.times[k + 1] - guess.times[k]).max(1e-9);
    let speed = ((b[0] - a[0]).hypot(b[1] - a[1]) / dt).max(1.0);
    let ramp = RAMP * c.clearance / speed;
    let (start, end) = (c.inside.0.max(t_first), c.inside.1.min(t_last));
    // The weight of the shift at time `t`: 1 inside, a half-cosine over each ramp, 0 at
    // the path's ends.
    let weight = |t: f64| -> f64 {
        let up = |from: f64, to: f64, t: f64| {
            if to <= from {
                return 1.0;
            }
            let s = ((t - from) / (to - from)).clamp(0.0, 1.0);
            0.5 - 0.5 * (PI * s).cos()
        };
        if t < start {
            up((start - ramp).max(t_first), start, t)
        } else if t > end {
            up((end + ramp).min(t_last), end, t)
        } else {
            1.0
        }
    };
    let mut out = guess.clone();
    for k in 1..n - 1 {
        let w = weight(guess.times[k]) * shift;
        out.states[k][0] += w * c.normal[0];
        out.states[k][1] += w * c.normal[1];
    }
    for k in 1..n {
        let (dx, dy) = (
            out.states[k][0] - out.states[k - 1][0],
            out.states[k][1] - out.states[k - 1][1],
        );
        if dx == 0.0 && dy == 0.0 {
            out.states[k][h] = out.states[k - 1][h];
            continue;
        }
        out.states[k][h] = nearest_turn(dy.atan2(dx), out.states[k - 1][h]);
    }
    // The last sample keeps its own heading (the end state may fix it).
    out.states[n - 1][h] = guess.states[n - 1][h];
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::threat::ThreatLayout;

    /// A straight path east along y = 0 at 200 m/s for 200 s, one sample a second.
    fn east() -> Trajectory {
        let mut tr = Trajectory::default();
        for k in 0..=200 {
            let t = k as f64;
            tr.push(t, [200.0 * t, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0; 2]);
        }
        tr.phase_ends = vec![200.0];
        tr
    }

    fn threats(list: &[Superquadric<2>]) -> Threats {
        Threats::Planar {
            layout: ThreatLayout::with_threats(30.0, list).expect("a layout"),
            moving: Vec::new(),
        }
    }

    fn problem_with(list: &[Superquadric<2>]) -> Problem {
        let sc = crate::scenario::bundled("2d-min-time-avoidable")
            .expect("bundled")
            .expect("valid");
        let mut p = Problem::from_scenario(&sc).expect("valid");
        p.threats = threats(list);
        p
    }

    #[test]
    fn a_new_threat_is_near_the_path_within_the_given_f() {
        // A 4 km circle whose edge is 1 km from the path (F = (5/4)^2 = 1.5625 there).
        let beside = Superquadric::ellipsoid([20_000.0, 5000.0], [4000.0, 4000.0]).expect("valid");
        let guess = east();
        let p = problem_with(&[beside]);
        assert!(near_new_threat(&p, &threats(&[]), &guess, 2.0));
        assert!(!near_new_threat(&p, &threats(&[]), &guess, 1.5));
        // Known to the plan: not new.
        assert!(!near_new_threat(&p, &threats(&[beside]), &guess, 2.0));
        // Far: 20 km to the side.
        let far = Superquadric::ellipsoid([20_000.0, 20_000.0], [4000.0, 4000.0]).expect("valid");
        assert!(!near_new_threat(
            &problem_with(&[far]),
            &threats(&[]),
            &guess,
            2.0
        ));
    }

    #[test]
    fn a_new_threat_across_the_path_gives_a_start_on_each_side_clear_of_it() {
        // A 4 km circle 500 m left of the path at x = 20 km.
        let popup = Superquadric::ellipsoid([20_000.0, 500.0], [4000.0, 4000.0]).expect("valid");
        let guess = east();
        let starts = deflected(&problem_with(&[popup]), &threats(&[]), &guess);
        assert_eq!(starts.len(), 2);
        for (start, side) in starts.iter().zip([1.0, -1.0]) {
            // The start and the end stay; at the threat the path is clear of it on `side`
            // (clearance 1.3 × 4 km = 5.2 km from the centre, within a metre).
            assert_eq!(start.states[0], guess.states[0]);
            assert_eq!(start.states[200], guess.states[200]);
            let at = start.states[100];
            assert!(
                (at[1] - 500.0 - side * 5200.0).abs() < 1.0,
                "{side}: {at:?}"
            );
            let f_min = start
                .states
                .iter()
                .map(|s| popup.f(&[s[0], s[1]]))
                .fold(f64::INFINITY, f64::min);
            assert!(f_min > 1.0, "{side}: min F {f_min}");
            // The heading follows the bent path: atan2 of the positions, within 1e-12.
            let k = 90;
            let want = (start.states[k][1] - start.states[k - 1][1])
                .atan2(start.states[k][0] - start.states[k - 1][0]);
            assert!((start.states[k][2] - want).abs() < 1e-12);
        }
    }

    #[test]
    fn a_known_threat_or_one_beside_the_path_gives_none() {
        let across = Superquadric::ellipsoid([20_000.0, 0.0], [4000.0, 4000.0]).expect("valid");
        let beside = Superquadric::ellipsoid([20_000.0, 6000.0], [4000.0, 4000.0]).expect("valid");
        let guess = east();
        assert!(deflected(&problem_with(&[across]), &threats(&[across]), &guess).is_empty());
        assert!(deflected(&problem_with(&[beside]), &threats(&[]), &guess).is_empty());
    }
}
