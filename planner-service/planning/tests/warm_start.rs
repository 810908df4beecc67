//! Warm start across meshes (`collocation::warm`): the multipliers carried from a converged
//! solution to another mesh are checked against the first-order optimality conditions of
//! the new mesh's NLP, evaluated independently here from its gradient and Jacobian, and the
//! warm-started solve is checked to need fewer iterations than a cold one.

use std::sync::Arc;
use std::time::Duration;

use wingman_planning::clock::Deadline;
use wingman_planning::collocation::kkt::KktCache;
use wingman_planning::collocation::warm::{transfer, transfer_in_time};
use wingman_planning::collocation::{
    ExportSettings, Mesh, NlpSettings, NlpStatus, PrimalDual, SolveBudget, Transcription,
    TranscriptionSettings, export, solve, transcription::INF,
};
use wingman_planning::hybrid::phase_durations;
use wingman_planning::problem::Problem;
use wingman_planning::trajectory::Trajectory;

mod common;
use common::{clock, planned, transcribed};

/// A converged solve of `name` on a uniform mesh of `points` per `interval_s`, started
/// from the hybrid planner's own plan (a good guess in the right basin).
fn converged(name: &str, points: usize, interval_s: f64) -> (Problem, Transcription, PrimalDual) {
    let (p, guess) = planned(name);
    let mesh = Mesh::uniform(points, &phase_durations(p.t0, &guess), interval_s, 2);
    let (tr, sol) = solve_from(&p, &mesh, &guess, None);
    (p, tr, sol.expect("the reference solve converges"))
}

/// Solves `p` on `mesh` from `guess` (warm from `warm` if given); the transcription and
/// its primal-dual solution if it converged, and the iteration count.
fn solve_from(
    p: &Problem,
    mesh: &Mesh,
    guess: &Trajectory,
    warm: Option<(&Transcription, &PrimalDual)>,
) -> (Transcription, Option<PrimalDual>) {
    let (tr, out) = solve_counted(p, mesh, guess, warm);
    (tr, out.1)
}

fn solve_counted(
    p: &Problem,
    mesh: &Mesh,
    guess: &Trajectory,
    warm: Option<(&Transcription, &PrimalDual)>,
) -> (Transcription, (usize, Option<PrimalDual>)) {
    let (tr, x) = transcribed(p, mesh, guess);
    let mut start = PrimalDual::default();
    let is_warm = warm.is_some_and(|(from, d)| transfer(from, d, &tr, &mut start));
    start.x = x;
    let settings = NlpSettings {
        feral_static_pivoting: true,
        mu_init: (!is_warm).then_some(1e-3),
        ..NlpSettings::default()
    };
    let (tr, out) = solve(
        tr,
        start,
        is_warm,
        &settings,
        SolveBudget::until(Deadline::after(clock(), Duration::from_secs(60))),
        &Arc::new(KktCache::new()),
    )
    .unwrap();
    assert_eq!(out.status, NlpStatus::Converged, "{:?}", out.return_status);
    (tr, (out.iterations, out.warm))
}

/// `max |∇f + Jᵀλ - z_l + z_u|` over the free variables at `x` (Ipopt's dual infeasibility,
/// scaled problem).
fn dual_infeasibility(tr: &mut Transcription, x: &[f64], d: &PrimalDual) -> f64 {
    let mut r = vec![0.0; tr.n_vars()];
    tr.gradient(x, &mut r);
    let mut values = vec![0.0; tr.jac.len()];
    tr.jacobian(x, &mut values);
    for (k, &(row, col)) in tr.jac.iter().enumerate() {
        r[col] += values[k] * d.lambda[row];
    }
    (0..tr.n_vars())
        .filter(|&i| tr.x_lo[i] < tr.x_hi[i])
        .map(|i| (r[i] - d.z_l[i] + d.z_u[i]).abs())
        .fold(0.0, f64::max)
}

/// The mesh with every interval split in two.
fn halved(mesh: &Mesh, points: usize) -> Mesh {
    Mesh {
        points,
        phases: mesh
            .phases
            .iter()
            .map(|f| f.iter().flat_map(|&w| [w / 2.0, w / 2.0]).collect())
            .collect(),
    }
}

fn new_mesh_start(
    p: &Problem,
    tr: &Transcription,
    sol: &PrimalDual,
    mesh: &Mesh,
) -> (Transcription, Vec<f64>) {
    let mut guess = Trajectory::default();
    let settings = ExportSettings {
        closed_loop: false,
        max_step_s: 0.25,
        ..ExportSettings::default()
    };
    export(tr, &sol.x, &settings, &mut guess);
    let mut to = Transcription::new(p, mesh, &guess, &TranscriptionSettings::default());
    let mut x = vec![0.0; to.n_vars()];
    to.initial_point(&guess, &mut x);
    // A different objective scale than the source's, so that the rescaling is exercised.
    to.obj_scale = 2.5 * tr.obj_scale;
    (to, x)
}

/// On the same mesh the transfer is the identity (to 1e-12, relative), and the solution's
/// own multipliers satisfy stationarity (the solver's tolerance, 1e-6 on the scaled NLP):
/// this fixes the sign convention the transfer relies on.
#[test]
fn same_mesh_transfer_is_the_identity() {
    let (_, mut tr, sol) = converged("2d-min-time-avoidable", 5, 35.0);
    let residual = dual_infeasibility(&mut tr, &sol.x, &sol);
    assert!(residual < 1e-6, "stationarity residual {residual:.3e}");
    let mut out = PrimalDual::default();
    assert!(transfer(&tr, &sol, &tr, &mut out));
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
    for (a, b) in out.lambda.iter().zip(&sol.lambda) {
        assert!(close(*a, *b), "constraint multiplier {a} vs {b}");
    }
    // Bound multipliers of free variables with that bound; none elsewhere (a fixed
    // variable's "multiplier" is its reduced gradient, which no new mesh shares).
    for i in 0..tr.n_vars() {
        let free = tr.x_lo[i] < tr.x_hi[i];
        let (lo, hi) = (free && tr.x_lo[i] > -INF, free && tr.x_hi[i] < INF);
        assert!(
            close(out.z_l[i], if lo { sol.z_l[i] } else { 0.0 }),
            "z_l[{i}]"
        );
        assert!(
            close(out.z_u[i], if hi { sol.z_u[i] } else { 0.0 }),
            "z_u[{i}]"
        );
    }
}

/// Carried to a mesh with twice the intervals and one more point each, the multipliers
/// leave at most a fifth of the dual infeasibility that zero multipliers leave, in 2-D and
/// in 3-D (state bounds, two controls) — what is left is the costate's interpolation error
/// between the old nodes (measured: 1/30 in 2-D, 1/9 in 3-D); and the warm solve there converges in fewer
/// iterations than a cold one from the same primal point.
#[test]
fn transferred_multipliers_nearly_satisfy_the_new_mesh() {
    for name in ["2d-min-time-avoidable", "3d-min-time-avoidable"] {
        let (p, tr, sol) = converged(name, 5, 35.0);
        let coarse = Mesh::uniform(5, &phase_lengths(&tr, &sol.x), 35.0, 2);
        let fine = halved(&coarse, 6);
        let (mut to, x) = new_mesh_start(&p, &tr, &sol, &fine);
        let mut carried = PrimalDual::default();
        assert!(
            transfer(&tr, &sol, &to, &mut carried),
            "{name}: shapes match"
        );
        let zero = PrimalDual {
            x: Vec::new(),
            z_l: vec![0.0; to.n_vars()],
            z_u: vec![0.0; to.n_vars()],
            lambda: vec![0.0; to.n_cons()],
        };
        let (with, without) = (
            dual_infeasibility(&mut to, &x, &carried),
            dual_infeasibility(&mut to, &x, &zero),
        );
        assert!(
            with < 0.2 * without,
            "{name}: dual infeasibility {with:.3e} with the carried multipliers, {without:.3e} without"
        );
        let mut guess = Trajectory::default();
        export(
            &tr,
            &sol.x,
            &ExportSettings {
                closed_loop: false,
                max_step_s: 0.25,
                ..ExportSettings::default()
            },
            &mut guess,
        );
        let (_, (cold, _)) = solve_counted(&p, &fine, &guess, None);
        let (_, (warm, _)) = solve_counted(&p, &fine, &guess, Some((&tr, &sol)));
        assert!(warm < cold, "{name}: warm {warm} iterations, cold {cold}");
    }
}

/// In mission time, with the same start and phase times (the starting point is the
/// solution itself), the transfer is the same identity as by phase fraction.
#[test]
fn a_transfer_in_time_at_the_same_times_is_the_identity() {
    let (_, tr, sol) = converged("3d-min-time-avoidable", 5, 35.0);
    let mut by_fraction = PrimalDual::default();
    assert!(transfer(&tr, &sol, &tr, &mut by_fraction));
    let mut in_time = PrimalDual {
        x: sol.x.clone(),
        ..PrimalDual::default()
    };
    assert!(transfer_in_time(&tr, &sol, &tr, &mut in_time));
    let close = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .all(|(a, b)| (a - b).abs() <= 1e-12 * b.abs().max(1.0))
    };
    assert!(close(&in_time.lambda, &by_fraction.lambda));
    assert!(close(&in_time.z_l, &by_fraction.z_l));
    assert!(close(&in_time.z_u, &by_fraction.z_u));
}

/// A re-plan of the rest of the mission from a later start (a third of the way, on the
/// plan): the plan's multipliers taken at the same mission time leave at most a fifth of
/// the dual infeasibility that zero multipliers leave at the re-plan's starting point (the
/// cut plan), in 2-D and in 3-D; by phase fraction instead (the same fraction of a shorter
/// first phase is a later time) they leave more. Measured: 7.0e-4 in time, 3.0e-2 by
/// fraction, 8.8e-2 with none in 2-D; 6.2e-5, 1.1e-2 and 4.4e-2 in 3-D.
#[test]
fn a_plans_multipliers_carried_in_time_nearly_satisfy_its_re_plan() {
    for name in ["2d-min-time-avoidable", "3d-min-time-avoidable"] {
        let (p, tr, sol) = converged(name, 5, 35.0);
        let mut flown = Trajectory::default();
        let dense = ExportSettings {
            closed_loop: false,
            max_step_s: 0.25,
            ..ExportSettings::default()
        };
        export(&tr, &sol.x, &dense, &mut flown);
        let tf = flown.final_time().unwrap();
        let t_c = p.t0 + (tf - p.t0) / 3.0;
        let mut later = p.clone();
        later.t0 = t_c;
        later.x0 = flown.at(t_c).unwrap().0;
        let mut cut = Trajectory {
            phase_ends: flown.phase_ends.clone(),
            ..Trajectory::default()
        };
        for k in 0..flown.len() {
            if flown.times[k] >= t_c {
                cut.push(flown.times[k], flown.states[k], flown.controls[k]);
            }
        }
        let mesh = Mesh::uniform(5, &phase_durations(later.t0, &cut), 35.0, 2);
        let (mut to, x) = transcribed(&later, &mesh, &cut);
        let mut carried = PrimalDual {
            x: x.clone(),
            ..PrimalDual::default()
        };
        assert!(transfer_in_time(&tr, &sol, &to, &mut carried), "{name}");
        let mut by_fraction = PrimalDual::default();
        assert!(transfer(&tr, &sol, &to, &mut by_fraction), "{name}");
        let zero = PrimalDual {
            x: Vec::new(),
            z_l: vec![0.0; to.n_vars()],
            z_u: vec![0.0; to.n_vars()],
            lambda: vec![0.0; to.n_cons()],
        };
        let with = dual_infeasibility(&mut to, &x, &carried);
        let fraction = dual_infeasibility(&mut to, &x, &by_fraction);
        let without = dual_infeasibility(&mut to, &x, &zero);
        assert!(
            with < 0.2 * without && with < fraction,
            "{name}: dual infeasibility {with:.3e} in time, {fraction:.3e} by phase fraction, {without:.3e} with none"
        );
    }
}

/// Phase durations of a solution (from its phase-time variables).
fn phase_lengths(tr: &Transcription, x: &[f64]) -> Vec<f64> {
    let mut prev = tr.problem.t0;
    (0..tr.layout.phases())
        .map(|p| {
            let end = x[tr.time(p)] * tr.scale[tr.time(p)];
            let d = end - prev;
            prev = end;
            d
        })
        .collect()
}
