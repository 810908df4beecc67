//! h-adaptive mesh refinement: measure how well each interval's polynomial flies, and split
//! the intervals that do not.
//!
//! An interval's error is the integration defect of its own solution: the dynamics are
//! integrated (RK4) from the interval's first node with the interval's controls (linear
//! between its collocation nodes, held after the last) and compared with the polynomial's
//! end state, position in metres and angles in radians scaled to metres by the distance
//! flown in one second (`V`); and how far the interpolated path leaves the bounds between
//! nodes. Intervals over the tolerance are split into equal parts, more parts for larger
//! errors (the LGR error falls at least with the square of the interval length).
//!
//! Before a finalist's first solve, [`split_crossings`] splits the intervals where its
//! starting path crosses a threat's edge, which the round would otherwise split after it.

use super::mesh::Mesh;
use super::transcription::Transcription;
use crate::problem::Problem;
use crate::trajectory::Trajectory;
use wingman_interfaces::Model;

/// Samples per interval (plus one) at which [`split_crossings`] reads the exposure.
const CROSSING_SAMPLES: usize = 12;

/// Settings of the refinement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineSettings {
    /// Largest acceptable integration defect of an interval, in metres (angles count as
    /// metres after multiplication by the speed times one second).
    pub defect_tol_m: f64,
    /// Most parts one interval is split into in one round.
    pub max_split: usize,
    /// Most intervals in one phase.
    pub max_intervals_per_phase: usize,
}

impl Default for RefineSettings {
    fn default() -> Self {
        RefineSettings {
            // 6 m: on the 15 canonical scenarios (seeds 1-5) the refined meshes are
            // smaller than at 3 m and the plans 1-5 % faster; judged, the costs and the
            // final misses stay within their limits (docs/decisions/0011-refinement-rounds-and-tolerance.md).
            defect_tol_m: 6.0,
            max_split: 4,
            max_intervals_per_phase: 64,
        }
    }
}

/// The error of every interval (see the module documentation), in mesh order.
pub fn interval_errors(tr: &Transcription, x: &[f64], out: &mut Vec<f64>) {
    out.clear();
    let phys: Vec<f64> = x.iter().zip(&tr.scale).map(|(v, s)| v * s).collect();
    let n_pts = tr.layout.lgr.len();
    let mut times = Vec::new();
    tr.node_times(x, &mut times);
    let speed = tr.problem.limits.speed;
    let l = &tr.problem.limits;
    let mut first = 0;
    while first < tr.layout.control_nodes() {
        let state = |k: usize| -> [f64; 7] {
            let mut s = [0.0; 7];
            for (c, v) in s.iter_mut().enumerate().take(tr.nx) {
                *v = phys[tr.state(k, c)];
            }
            s
        };
        let control = |k: usize| -> [f64; 2] {
            let mut u = [0.0; 2];
            for (e, v) in u.iter_mut().enumerate().take(tr.nu) {
                *v = phys[tr.control(k, e)];
            }
            u
        };
        // Integrate node to node with the controls linear between collocation nodes.
        let mut xk = state(first);
        for j in 0..n_pts {
            let (ta, tb) = (times[first + j], times[first + j + 1]);
            let ua = control(first + j);
            let ub = if j + 1 < n_pts {
                control(first + j + 1)
            } else {
                ua
            };
            xk = tr.vehicle.integrate_linear(&xk, &ua, &ub, tb - ta, 4);
        }
        let end = state(first + n_pts);
        let mut err: f64 = 0.0;
        for c in 0..tr.nx {
            let d = (xk[c] - end[c]).abs();
            let in_m = if c < tr.dim { d } else { d * speed };
            err = err.max(in_m);
        }
        // Bounds between nodes: the polynomial at the midpoints of the node gaps.
        if tr.problem.model == Model::ThreeD {
            let mut basis = vec![0.0; n_pts + 1];
            for j in 0..n_pts {
                let tau = (tr.layout.lgr.support[j] + tr.layout.lgr.support[j + 1]) / 2.0;
                tr.layout.lgr.basis(tau, &mut basis);
                let mut s = [0.0; 7];
                for (b, w) in basis.iter().enumerate() {
                    for (c, v) in s.iter_mut().enumerate() {
                        *v += w * phys[tr.state(first + b, c)];
                    }
                }
                let over = [
                    s[3].abs() - l.gamma_max,
                    s[6].abs() - l.mu_max,
                    s[5] - l.nz_max,
                    l.nz_min - s[5],
                ]
                .into_iter()
                .fold(0.0f64, f64::max);
                err = err.max(over * speed * 10.0);
                err = err.max(l.z_min - s[2]);
            }
        }
        out.push(err);
        first += n_pts;
    }
}

/// The refined mesh, or `None` when every interval is within tolerance (or no phase may
/// grow any more).
pub fn refine(mesh: &Mesh, errors: &[f64], settings: &RefineSettings) -> Option<Mesh> {
    let mut changed = false;
    let mut phases = Vec::with_capacity(mesh.phases.len());
    let mut k = 0;
    for fractions in &mesh.phases {
        let mut next = Vec::with_capacity(fractions.len() * 2);
        let mut budget = settings
            .max_intervals_per_phase
            .saturating_sub(fractions.len());
        for &frac in fractions {
            let err = errors.get(k).copied().unwrap_or(0.0);
            k += 1;
            if err > settings.defect_tol_m && budget > 0 {
                let ratio = err / settings.defect_tol_m;
                let parts = (ratio.sqrt().ceil() as usize)
                    .clamp(2, settings.max_split)
                    .min(budget + 1);
                budget -= parts - 1;
                next.extend(std::iter::repeat_n(frac / parts as f64, parts));
                changed = true;
            } else {
                next.push(frac);
            }
        }
        phases.push(next);
    }
    changed.then_some(Mesh {
        points: mesh.points,
        phases,
    })
}

/// `mesh` with every interval of the phases before the last split in two where `path`
/// crosses the edge of a threat: where the exposure along it, read at
/// `CROSSING_SAMPLES + 1` evenly spaced times of the interval, varies by more than
/// `threshold` (the exposure is in `[0, 1]` and steps across a threat's edge). The phase
/// times are `path`'s (its phase ends, from `problem.t0`), as the mesh was cut on them.
/// `None` when no interval is split.
///
/// A finalist's solve starts from its ranked path anyway, so splitting there the intervals
/// that the refinement round would split after it costs the final little, while the round
/// no longer has to re-converge across the threat's edge: on the canonical scenarios the
/// rounds of 2d-min-time-unavoidable fell from 16–22 iterations to 4–5
/// (docs/decisions/0029-finals-mesh-crossing-split.md). The last phase is left alone: split there too, the finals of
/// 2d-min-time-rendezvous-unavoidable took up to twice the iterations.
pub fn split_crossings(
    mesh: &Mesh,
    problem: &Problem,
    path: &Trajectory,
    threshold: f64,
) -> Option<Mesh> {
    let mut changed = false;
    let mut phases = mesh.phases.clone();
    let last = phases.len().saturating_sub(1);
    let mut t_start = problem.t0;
    for (p, fractions) in phases.iter_mut().enumerate().take(last) {
        let t_end = path.phase_ends.get(p).copied().unwrap_or(t_start);
        let duration = t_end - t_start;
        let mut next = Vec::with_capacity(fractions.len() + 4);
        let mut begin = 0.0;
        for &frac in fractions.iter() {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for q in 0..=CROSSING_SAMPLES {
                let t = t_start + duration * (begin + frac * q as f64 / CROSSING_SAMPLES as f64);
                if let Some((state, _)) = path.at(t) {
                    let e = problem.exposure(&problem.position(&state), t);
                    lo = lo.min(e);
                    hi = hi.max(e);
                }
            }
            if hi - lo > threshold {
                next.extend([frac / 2.0, frac / 2.0]);
                changed = true;
            } else {
                next.push(frac);
            }
            begin += frac;
        }
        *fractions = next;
        t_start = t_end;
    }
    changed.then_some(Mesh {
        points: mesh.points,
        phases,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::bundled;

    /// Straight legs from the start through the target to the final point at the
    /// vehicle's speed, sampled every second, and the exposure's largest change within
    /// `[a, b]` read from those samples.
    struct Legs {
        path: Trajectory,
        problem: Problem,
    }

    impl Legs {
        fn new(name: &str) -> Legs {
            let problem = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
            let speed = problem.limits.speed;
            let start = [problem.x0[0], problem.x0[1]];
            let target = [problem.targets[0][0], problem.targets[0][1]];
            let last = problem.final_state.expect("a final point");
            let end = [last[0], last[1]];
            let mut path = Trajectory::default();
            let mut t = problem.t0;
            for (a, b) in [(start, target), (target, end)] {
                let length = (b[0] - a[0]).hypot(b[1] - a[1]);
                let steps = (length / speed).ceil() as usize;
                let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
                for k in 0..steps {
                    let f = k as f64 / steps as f64;
                    let mut x = [0.0; 7];
                    x[0] = a[0] + f * (b[0] - a[0]);
                    x[1] = a[1] + f * (b[1] - a[1]);
                    x[2] = heading;
                    path.push(t, x, [0.0; 2]);
                    t += length / speed / steps as f64;
                }
                path.phase_ends.push(t);
            }
            let mut x = [0.0; 7];
            x[0] = end[0];
            x[1] = end[1];
            path.push(t, x, [0.0; 2]);
            Legs { path, problem }
        }

        fn variation(&self, a: f64, b: f64) -> f64 {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut t = a;
            while t <= b {
                let (x, _) = self.path.at(t).unwrap();
                let e = self.problem.exposure(&self.problem.position(&x), t);
                (lo, hi) = (lo.min(e), hi.max(e));
                t += 0.25;
            }
            hi - lo
        }
    }

    /// Each interval's `[start, end]` times, per phase.
    fn spans(mesh: &Mesh, t0: f64, ends: &[f64]) -> Vec<Vec<(f64, f64)>> {
        let mut begin_t = t0;
        let mut out = Vec::new();
        for (p, fractions) in mesh.phases.iter().enumerate() {
            let d = ends[p] - begin_t;
            let mut s = 0.0;
            out.push(
                fractions
                    .iter()
                    .map(|f| {
                        let span = (begin_t + d * s, begin_t + d * (s + f));
                        s += f;
                        span
                    })
                    .collect(),
            );
            begin_t = ends[p];
        }
        out
    }

    #[test]
    fn crossings_of_a_threat_edge_are_split_before_the_last_phase_only() {
        // The target of 2d-min-time-unavoidable lies inside a threat: the straight legs
        // cross its edge before and after it. Checked against the exposure read every
        // quarter second: an interval with a full crossing (a change over 0.9) before the
        // last phase is split in two, no interval with a change under 0.3 is, and the last
        // phase is left as it was.
        let legs = Legs::new("2d-min-time-unavoidable");
        let ends = legs.path.phase_ends.clone();
        let t0 = legs.problem.t0;
        let durations = [ends[0] - t0, ends[1] - ends[0]];
        let mesh = Mesh::uniform(6, &durations, 25.0, 2);
        let split = split_crossings(&mesh, &legs.problem, &legs.path, 0.3).expect("a crossing");
        assert_eq!(split.phases[1], mesh.phases[1]);
        for p in &split.phases {
            assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
        let before = &spans(&mesh, t0, &ends)[0];
        let mut next = split.phases[0].iter();
        let mut crossings = 0;
        for (&frac, &(a, b)) in mesh.phases[0].iter().zip(before) {
            let variation = legs.variation(a, b);
            let first = *next.next().unwrap();
            let was_split = first < frac - 1e-12;
            if was_split {
                assert_eq!(*next.next().unwrap(), frac / 2.0);
                assert!(
                    variation > 0.3,
                    "split at {a}-{b} with a change of {variation}"
                );
            }
            if variation > 0.9 {
                crossings += 1;
                assert!(
                    was_split,
                    "not split at {a}-{b} with a change of {variation}"
                );
            }
        }
        assert!(next.next().is_none());
        assert!(
            crossings > 0,
            "the legs cross no threat edge before the target"
        );
        // A threshold above any change splits nothing.
        assert_eq!(split_crossings(&mesh, &legs.problem, &legs.path, 1.5), None);
    }

    #[test]
    fn splits_only_the_intervals_over_tolerance() {
        let mesh = Mesh {
            points: 6,
            phases: vec![vec![0.5, 0.5], vec![1.0]],
        };
        let s = RefineSettings::default();
        assert_eq!(refine(&mesh, &[0.1, 0.2, 1.0], &s), None);
        let m = refine(
            &mesh,
            &[0.1, 4.0 * s.defect_tol_m, 100.0 * s.defect_tol_m],
            &s,
        )
        .unwrap();
        assert_eq!(m.phases[0], vec![0.5, 0.25, 0.25]);
        assert_eq!(m.phases[1], vec![0.25; 4]);
        for p in &m.phases {
            assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
    }
}
