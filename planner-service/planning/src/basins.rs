//! Starts for the NLP from distinct basins. A gradient method only finds the optimum of
//! the basin it starts in, and with threats the basins are (mostly) the homotopy classes
//! of the path: on which side it passes each threat. The swarm's best is one start; the
//! best seeds that pass some threat on the *other* side are the others (the reference
//! optimum itself was found by a multistart over such left/right arc combinations).

use wingman_interfaces::{Model, Objective};

use crate::dynamics::{ReducedPath, Spatial, lift_reduced_path, wrap_angle};
use crate::problem::{Problem, Threats};
use crate::seeding::Seed;
use crate::trajectory::Trajectory;

/// Side on which a path passes each threat it comes near: +1 left, -1 right, 0 far or
/// through it (crossing a threat, e.g. to reach a target inside it, has no side).
pub type Signature = Vec<i8>;

/// Threat centres (horizontal) and a "near" radius (twice the largest horizontal axis).
fn threat_discs(problem: &Problem) -> Vec<([f64; 2], f64)> {
    match &problem.threats {
        Threats::Planar { layout, .. } => layout
            .threats()
            .iter()
            .map(|t| (*t.center(), 2.0 * t.axes()[0].max(t.axes()[1])))
            .collect(),
        Threats::Spatial { layout, .. } => layout
            .threats()
            .iter()
            .map(|t| {
                (
                    [t.center()[0], t.center()[1]],
                    2.0 * t.axes()[0].max(t.axes()[1]),
                )
            })
            .collect(),
    }
}

/// `F` of static threat `i` at `p` (`[x, y, z]`, z ignored in 2-D).
fn threat_f(problem: &Problem, i: usize, p: &[f64; 3]) -> f64 {
    match &problem.threats {
        Threats::Planar { layout, .. } => layout.threats()[i].f(&[p[0], p[1]]),
        Threats::Spatial { layout, .. } => layout.threats()[i].f(p),
    }
}

/// The side on which the path `points` (`[x, y, z]`) passes each threat.
pub fn signature(problem: &Problem, points: &[[f64; 3]]) -> Signature {
    threat_discs(problem)
        .into_iter()
        .enumerate()
        .map(|(i, (c, near))| {
            let mut best = (f64::INFINITY, 0usize);
            for (k, p) in points.iter().enumerate() {
                let d = (p[0] - c[0]).hypot(p[1] - c[1]);
                if d < best.0 {
                    best = (d, k);
                }
            }
            if best.0 > near || points.len() < 2 || threat_f(problem, i, &points[best.1]) < 1.0 {
                return 0;
            }
            let k = best.1.min(points.len() - 2);
            let dir = [
                points[k + 1][0] - points[k][0],
                points[k + 1][1] - points[k][1],
            ];
            let to_c = [c[0] - points[k][0], c[1] - points[k][1]];
            // The threat is on the right of the path when the path passes on its left.
            let cross = dir[0] * to_c[1] - dir[1] * to_c[0];
            if cross < 0.0 { 1 } else { -1 }
        })
        .collect()
}

/// Whether two signatures may be the same class: they agree on every threat both pass
/// near (a far threat, 0, may be passed either way once the NLP moves the path).
pub fn same_class(a: &Signature, b: &Signature) -> bool {
    a.iter().zip(b).all(|(x, y)| *x == 0 || *y == 0 || x == y)
}

/// A seed flown at the vehicle's speed as a full-model trajectory (3-D: lifted with eqs.
/// 5.13–5.15), with its targets' pass times as phase ends.
pub fn path_of_seed(problem: &Problem, seed: &Seed) -> Option<Trajectory> {
    let pts = seed.points();
    let n = pts.len();
    if n < 3 {
        return None;
    }
    let v = problem.limits.speed;
    let mut times = Vec::with_capacity(n);
    let mut t = problem.t0;
    times.push(t);
    for k in 1..n {
        let d = ((pts[k][0] - pts[k - 1][0]).powi(2)
            + (pts[k][1] - pts[k - 1][1]).powi(2)
            + (pts[k][2] - pts[k - 1][2]).powi(2))
        .sqrt();
        t += (d / v).max(1e-3);
        times.push(t);
    }
    let h0 = problem.x0[problem.heading_index()];
    let mut chi = Vec::with_capacity(n);
    let mut gamma = Vec::with_capacity(n);
    for k in 0..n {
        let (a, b) = if k + 1 < n {
            (pts[k], pts[k + 1])
        } else {
            (pts[k - 1], pts[k])
        };
        let heading = (b[1] - a[1]).atan2(b[0] - a[0]);
        let prev = chi.last().copied().unwrap_or(h0);
        chi.push(prev + wrap_angle(heading - prev));
        gamma.push((b[2] - a[2]).atan2((b[0] - a[0]).hypot(b[1] - a[1])));
    }
    let mut tr = Trajectory::default();
    match problem.model {
        Model::TwoD => {
            for k in 0..n {
                let u = if k + 1 < n {
                    (chi[k + 1] - chi[k]) / (times[k + 1] - times[k])
                } else {
                    0.0
                };
                let u = u.clamp(-problem.limits.turn_rate_max, problem.limits.turn_rate_max);
                tr.push(
                    times[k],
                    [pts[k][0], pts[k][1], chi[k], 0.0, 0.0, 0.0, 0.0],
                    [u, 0.0],
                );
            }
        }
        Model::ThreeD => {
            let gmax = problem.limits.gamma_max;
            let gamma: Vec<f64> = gamma.iter().map(|g| g.clamp(-gmax, gmax)).collect();
            let model = Spatial::new(v).ok()?;
            let mut states = vec![[0.0; 7]; n];
            let mut controls = vec![[0.0; 2]; n];
            let path = ReducedPath {
                times: &times,
                positions: pts,
                gamma: &gamma,
                chi: &chi,
            };
            lift_reduced_path(&model, &path, &mut states, &mut controls).ok()?;
            let l = &problem.limits;
            for k in 0..n {
                let mut s = states[k];
                s[4] = chi[k];
                s[5] = s[5].clamp(l.nz_min, l.nz_max);
                s[6] = s[6].clamp(-l.mu_max, l.mu_max);
                tr.push(times[k], s, controls[k]);
            }
        }
    }
    tr.phase_ends = seed.gates().iter().map(|&g| times[g.min(n - 1)]).collect();
    tr.phase_ends.truncate(problem.phases());
    (tr.phase_ends.len() == problem.phases() && tr.is_valid()).then_some(tr)
}

/// How the seeds are ranked as starts of a plan with a fixed final time.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StartRanking {
    /// The seeds that arrive on time first (the deployment default).
    #[default]
    OnTimeFirst,
    /// The starts by cost alone, as if the time did not matter (`count` with the swarm's
    /// best, of distinct classes), then up to `count - 1` more with the seeds that arrive
    /// on time first (the yardstick: the picks of both rankings, but for on-time seeds too
    /// near a start already taken).
    Both,
}

/// Up to `count` starts (`2 count - 1` with [`StartRanking::Both`]): `first` (the swarm's
/// best), then the cheapest seeds whose signature differs from every start taken so far,
/// ranked by `cost`. The seeds' paths and costs are computed on `threads` threads (the
/// same result for any number).
///
/// With a fixed final time two things differ. A seed that arrives at another time is no
/// measure of its basin (a short one is cheap only because it is short), so the seeds that
/// arrive within [`FITTED_TIME_TOL`] of it rank first (`ranking`). And where the spare
/// length goes is a basin of its own that the threat sides do not tell apart (a wide loop
/// far from every threat has no side), so a seed of a taken class is distinct too when its
/// path is [`SLACK_SEPARATION_M`] from that start's.
pub fn candidates(
    problem: &Problem,
    first: &Trajectory,
    seeds: &[Seed],
    count: usize,
    threads: usize,
    ranking: StartRanking,
    cost: impl Fn(&Trajectory) -> f64 + Sync,
) -> Vec<Trajectory> {
    more_candidates(
        problem,
        std::slice::from_ref(first),
        seeds,
        count,
        threads,
        ranking,
        cost,
    )
}

/// [`candidates`] after the starts already `taken` (a plan's waves, after its global
/// search's starts): `taken` first, then up to `count` in all (`2 count - 1` with
/// [`StartRanking::Both`]) chosen as [`candidates`] chooses them, distinct from `taken`
/// too.
pub fn more_candidates(
    problem: &Problem,
    taken: &[Trajectory],
    seeds: &[Seed],
    count: usize,
    threads: usize,
    ranking: StartRanking,
    cost: impl Fn(&Trajectory) -> f64 + Sync,
) -> Vec<Trajectory> {
    let mut taken: Vec<(Signature, Trajectory)> = taken
        .iter()
        .map(|tr| (signature(problem, &positions(problem, tr)), tr.clone()))
        .collect();
    let more = count.saturating_sub(taken.len());
    if more == 0 {
        return taken.into_iter().map(|(_, tr)| tr).collect();
    }
    let fixed_time = problem.objective == Objective::FixedTime;
    // Each seed's path with its cost, index, and whether it arrives off time.
    let mut ranked: Vec<(f64, usize, bool, Trajectory)> =
        ranked_seeds(problem, seeds, threads, &cost)
            .into_iter()
            .filter(|(c, _, _)| c.is_finite())
            .map(|(c, i, tr)| (c, i, fixed_time && !arrives_on_time(problem, &tr), tr))
            .collect();
    let by_cost = |a: &(f64, usize, bool, Trajectory), b: &(f64, usize, bool, Trajectory)| {
        a.0.total_cmp(&b.0).then(a.1.cmp(&b.1))
    };
    if fixed_time && ranking == StartRanking::Both {
        ranked.sort_by(by_cost);
        pick(problem, &ranked, more, None, &mut taken);
    }
    ranked.sort_by(|a, b| a.2.cmp(&b.2).then(by_cost(a, b)));
    let apart = fixed_time.then_some(SLACK_SEPARATION_M);
    pick(problem, &ranked, more, apart, &mut taken);
    taken.into_iter().map(|(_, tr)| tr).collect()
}

/// Takes up to `more` seeds of `ranked` in order into `taken`: a seed whose class differs
/// from every start taken (or, with `apart`, whose path is that far from the start of its
/// class), then, with fewer classes than slots (e.g. paths that must cross threats, where
/// only the crossing point differs), the others geometrically apart from every start
/// taken (mean horizontal distance over the path's fraction).
fn pick(
    problem: &Problem,
    ranked: &[(f64, usize, bool, Trajectory)],
    more: usize,
    apart: Option<f64>,
    taken: &mut Vec<(Signature, Trajectory)>,
) {
    let upto = taken.len() + more;
    let mut rest = Vec::new();
    for (_, _, _, tr) in ranked {
        if taken.len() >= upto {
            break;
        }
        let sig = signature(problem, &positions(problem, tr));
        let distinct = taken
            .iter()
            .all(|(t, o)| !same_class(t, &sig) || apart.is_some_and(|far| separation(o, tr) > far));
        if distinct {
            taken.push((sig, tr.clone()));
        } else {
            rest.push((sig, tr));
        }
    }
    for (sig, tr) in rest {
        if taken.len() >= upto {
            break;
        }
        if taken
            .iter()
            .all(|(_, o)| separation(o, tr) > MIN_SEPARATION_M)
        {
            taken.push((sig, tr.clone()));
        }
    }
}

/// The positions (`[x, y, z]`) of a path's samples.
fn positions(problem: &Problem, tr: &Trajectory) -> Vec<[f64; 3]> {
    tr.states.iter().map(|s| problem.position(s)).collect()
}

/// How far from a fixed final time, as a fraction of the time the plan has (`t_f - t_0`),
/// a seed may arrive to rank among the seeds that fit it.
pub const FITTED_TIME_TOL: f64 = 0.02;

/// Mean horizontal distance that makes two fixed-time paths of one class distinct starts.
pub const SLACK_SEPARATION_M: f64 = 10_000.0;

/// Whether `tr` ends within [`FITTED_TIME_TOL`] of the time the problem has, `t_f - t_0`,
/// from its fixed final time (always, without one).
fn arrives_on_time(problem: &Problem, tr: &Trajectory) -> bool {
    match (problem.final_time, tr.times.last()) {
        (Some(tf), Some(end)) => (end - tf).abs() <= FITTED_TIME_TOL * (tf - problem.t0).max(1.0),
        _ => true,
    }
}

/// Every seed's path with its cost and index (seeds without a path left out), computed
/// on up to `threads` threads: the seeds are dealt out in turn (their paths differ in
/// length), each thread keeps its own, and the order is the caller's to set.
fn ranked_seeds(
    problem: &Problem,
    seeds: &[Seed],
    threads: usize,
    cost: &(impl Fn(&Trajectory) -> f64 + Sync),
) -> Vec<(f64, usize, Trajectory)> {
    let path = |i: usize| path_of_seed(problem, &seeds[i]).map(|tr| (cost(&tr), i, tr));
    let threads = threads.clamp(1, seeds.len().max(1));
    let share = |t: usize| (t..seeds.len()).step_by(threads).filter_map(path);
    if threads == 1 {
        return share(0).collect();
    }
    std::thread::scope(|scope| {
        let others: Vec<_> = (1..threads)
            .map(|t| scope.spawn(move || share(t).collect::<Vec<_>>()))
            .collect();
        let mut all: Vec<_> = share(0).collect();
        for other in others {
            // A panic there is a bug: raise it here.
            all.extend(
                other
                    .join()
                    .unwrap_or_else(|e| std::panic::resume_unwind(e)),
            );
        }
        all
    })
}

/// Mean horizontal distance that makes two paths of one class distinct starts (or two
/// ranked solutions distinct finalists).
pub const MIN_SEPARATION_M: f64 = 3000.0;

/// Mean horizontal distance between two paths at the same fractions of their samples (32
/// points); infinite if either is empty.
pub fn separation(a: &Trajectory, b: &Trajectory) -> f64 {
    if a.is_empty() || b.is_empty() {
        return f64::INFINITY;
    }
    let n = 32;
    (0..n)
        .map(|k| {
            let f = (k as f64 + 0.5) / n as f64;
            let pa = &a.states[((a.len() - 1) as f64 * f) as usize];
            let pb = &b.states[((b.len() - 1) as f64 * f) as usize];
            (pa[0] - pb[0]).hypot(pa[1] - pb[1])
        })
        .sum::<f64>()
        / n as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::bundled;
    use crate::seeding::{SeedSettings, seeds};

    /// The starts, their order included, are the same bits on one, two and three threads
    /// (the seeds' paths and costs are dealt out to the threads), in 2-D and 3-D.
    #[test]
    fn candidates_do_not_depend_on_the_threads() {
        for name in [
            "2d-min-time-unavoidable",
            "3d-min-time-rendezvous-avoidable",
        ] {
            let (problem, all, first) = seeded(name);
            assert!(all.len() > 8, "{name}: {} seeds", all.len());
            let cost = |tr: &Trajectory| crate::hybrid::trajectory_cost(&problem, tr);
            let one = candidates(
                &problem,
                &first,
                &all,
                5,
                1,
                StartRanking::OnTimeFirst,
                cost,
            );
            assert!(one.len() >= 3, "{name}: {} starts", one.len());
            for threads in [2, 3] {
                let more = candidates(
                    &problem,
                    &first,
                    &all,
                    5,
                    threads,
                    StartRanking::OnTimeFirst,
                    cost,
                );
                assert_eq!(one, more, "{name}: {threads} threads differ from one");
            }
        }
    }

    /// The bundled `name`'s problem, its default seeds, and the first seed's path (the
    /// swarm's best stand-in).
    fn seeded(name: &str) -> (Problem, Vec<Seed>, Trajectory) {
        let problem = Problem::from_scenario(&bundled(name).unwrap().unwrap()).unwrap();
        let mut all = Vec::new();
        seeds(&problem, &SeedSettings::default(), &mut all).unwrap();
        let first = path_of_seed(&problem, &all[0]).expect("a path");
        (problem, all, first)
    }

    /// With a fixed final time the starts after the swarm's best are seeds that arrive
    /// within 2 % of it (the bundled mission has more such seeds, of distinct classes or
    /// 10 km apart, than starts); on time means within 2 %, not 2.1 %.
    #[test]
    fn fixed_time_starts_arrive_on_time() {
        let (problem, all, first) = seeded("2d-fixed-time-avoidable");
        let tf = problem.final_time.unwrap();
        let t = tf - problem.t0;
        let late = all
            .iter()
            .filter_map(|s| path_of_seed(&problem, s))
            .filter(|tr| !arrives_on_time(&problem, tr))
            .count();
        assert!(late > 0, "some seeds arrive early or late");
        let cost = |tr: &Trajectory| crate::hybrid::trajectory_cost(&problem, tr);
        let starts = candidates(
            &problem,
            &first,
            &all,
            5,
            1,
            StartRanking::OnTimeFirst,
            cost,
        );
        assert_eq!(starts.len(), 5);
        for s in &starts[1..] {
            let end = *s.times.last().unwrap();
            assert!(
                (end - tf).abs() <= 0.02 * t,
                "a start ends at {end} s, not {tf} s"
            );
        }
        let ending_at = |end: f64| {
            let mut tr = first.clone();
            let scale = (end - problem.t0) / (tr.times.last().unwrap() - problem.t0);
            for time in tr.times.iter_mut() {
                *time = problem.t0 + (*time - problem.t0) * scale;
            }
            tr
        };
        assert!(arrives_on_time(&problem, &ending_at(tf - 0.019 * t)));
        assert!(arrives_on_time(&problem, &ending_at(tf + 0.019 * t)));
        assert!(!arrives_on_time(&problem, &ending_at(tf - 0.021 * t)));
        assert!(!arrives_on_time(&problem, &ending_at(tf + 0.021 * t)));
    }

    /// The yardstick's ranking takes the starts by cost alone first (on the bundled
    /// mission some of them arrive early: cheap because short), then more with the seeds
    /// on time first, beyond `count`.
    #[test]
    fn both_rankings_take_the_cheap_early_seeds_and_the_on_time_ones() {
        let (problem, all, first) = seeded("2d-fixed-time-avoidable");
        let cost = |tr: &Trajectory| crate::hybrid::trajectory_cost(&problem, tr);
        let both = candidates(&problem, &first, &all, 5, 1, StartRanking::Both, cost);
        assert!(both.len() > 5, "{} starts", both.len());
        assert!(both.len() <= 9, "{} starts", both.len());
        let early = both[1..5]
            .iter()
            .filter(|s| !arrives_on_time(&problem, s))
            .count();
        assert!(early > 0, "the cheapest seeds by cost alone arrive early");
        assert!(
            both[5..].iter().all(|s| arrives_on_time(&problem, s)),
            "the rest arrive on time"
        );
    }
}
