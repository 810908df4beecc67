//! The transcription's derivatives against central differences of its own functions, and
//! its constraints against an independent computation on an exact trajectory.

use wingman_interfaces::Model;
use wingman_planning::collocation::{Mesh, Transcription, TranscriptionSettings};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::bundled;
use wingman_planning::trajectory::Trajectory;

/// A straight-segment guess start → targets → end at speed V (level flight), with a
/// deterministic wiggle so that derivatives are taken at a generic point.
fn guess(p: &Problem) -> Trajectory {
    let v = p.limits.speed;
    let mut points = vec![[p.x0[0], p.x0[1], if p.dim() == 3 { p.x0[2] } else { 0.0 }]];
    points.extend(p.targets.iter().copied());
    let end = match &p.final_state {
        Some(f) => [f[0], f[1], if p.dim() == 3 { f[2] } else { 0.0 }],
        None => p.lead.as_ref().unwrap().at(p.t0 + 600.0).position,
    };
    points.push(end);
    let mut tr = Trajectory::default();
    let mut t = p.t0;
    for (leg, w) in points.windows(2).enumerate() {
        let d = ((w[1][0] - w[0][0]).powi(2)
            + (w[1][1] - w[0][1]).powi(2)
            + (w[1][2] - w[0][2]).powi(2))
        .sqrt();
        let heading = (w[1][1] - w[0][1]).atan2(w[1][0] - w[0][0]);
        let steps = 20;
        for i in 0..steps {
            let f = i as f64 / steps as f64;
            let pos = [0, 1, 2].map(|c| w[0][c] + f * (w[1][c] - w[0][c]));
            let wiggle = 0.01 * ((tr.len() as f64) * 0.7).sin();
            let state = match p.model {
                Model::TwoD => [pos[0], pos[1], heading + wiggle, 0.0, 0.0, 0.0, 0.0],
                Model::ThreeD => [
                    pos[0],
                    pos[1],
                    pos[2],
                    0.01 + wiggle,
                    heading,
                    1.0 + wiggle,
                    0.05 * wiggle,
                ],
            };
            tr.push(t + f * d / v, state, [0.001 + 0.1 * wiggle, -0.002]);
        }
        t += d / v;
        let _ = leg;
        tr.phase_ends.push(t);
    }
    let last = *tr.states.last().unwrap();
    tr.push(t, last, [0.0, 0.0]);
    tr
}

fn transcription(name: &str, wind: [f64; 3]) -> (Transcription, Vec<f64>) {
    let sc = bundled(name).unwrap().unwrap();
    let mut p = Problem::from_scenario(&sc).unwrap();
    p.wind = wind;
    let g = guess(&p);
    let durations: Vec<f64> = {
        let mut prev = p.t0;
        g.phase_ends
            .iter()
            .map(|&e| {
                let d = e - prev;
                prev = e;
                d
            })
            .collect()
    };
    let mesh = Mesh::uniform(5, &durations, 150.0, 1);
    let mut t = Transcription::new(&p, &mesh, &g, &TranscriptionSettings::default());
    t.obj_scale = 0.37;
    let mut x = vec![0.0; t.n_vars()];
    t.initial_point(&g, &mut x);
    (t, x)
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Gradient, Jacobian and Hessian of the Lagrangian against central differences (step
/// 1e-6 in scaled variables): gradient and Jacobian within 1e-6 of the largest entry,
/// Hessian within 1e-5 of the largest entry.
fn check_derivatives(name: &str) {
    check_derivatives_in(name, [0.0; 3]);
}

/// [`check_derivatives`] in the steady wind `wind`.
fn check_derivatives_in(name: &str, wind: [f64; 3]) {
    let (mut t, x) = transcription(name, wind);
    let (n, m) = (t.n_vars(), t.n_cons());
    let h = 1e-6;

    let mut grad = vec![0.0; n];
    t.gradient(&x, &mut grad);
    let mut jac = vec![0.0; t.jac.len()];
    t.jacobian(&x, &mut jac);
    let mut dense_jac = vec![0.0; n * m];
    for (v, &(r, c)) in jac.iter().zip(&t.jac) {
        dense_jac[r * n + c] += v;
    }
    let lambda: Vec<f64> = (0..m).map(|r| ((r as f64) * 1.3).sin()).collect();
    let obj_factor = 0.8;
    let mut hv = vec![0.0; t.hess.len()];
    t.hessian(&x, obj_factor, &lambda, &mut hv);
    let mut dense_h = vec![0.0; n * n];
    for (v, &(r, c)) in hv.iter().zip(&t.hess) {
        assert!(
            r >= c,
            "{name}: Hessian entry ({r}, {c}) above the diagonal"
        );
        dense_h[r * n + c] += v;
        if r != c {
            dense_h[c * n + r] += v;
        }
    }

    let grad_scale = max_abs(&grad);
    let jac_scale = max_abs(&jac);
    let h_scale = max_abs(&dense_h);
    let mut g_plus = vec![0.0; m];
    let mut g_minus = vec![0.0; m];
    let mut gr_plus = vec![0.0; n];
    let mut gr_minus = vec![0.0; n];
    let mut j_plus = vec![0.0; t.jac.len()];
    let mut j_minus = vec![0.0; t.jac.len()];
    for i in 0..n {
        let mut xp = x.clone();
        let mut xm = x.clone();
        xp[i] += h;
        xm[i] -= h;
        let fd = (t.objective(&xp) - t.objective(&xm)) / (2.0 * h);
        assert!(
            (fd - grad[i]).abs() <= 1e-6 * grad_scale,
            "{name}: grad[{i}] {} vs fd {fd}",
            grad[i]
        );
        t.constraints(&xp, &mut g_plus);
        t.constraints(&xm, &mut g_minus);
        for r in 0..m {
            let fd = (g_plus[r] - g_minus[r]) / (2.0 * h);
            let an = dense_jac[r * n + i];
            assert!(
                (fd - an).abs() <= 1e-6 * jac_scale,
                "{name}: jac[{r}][{i}] {an} vs fd {fd}"
            );
        }
        // Gradient of the Lagrangian: obj_factor ∇f + Jᵀ λ.
        t.gradient(&xp, &mut gr_plus);
        t.gradient(&xm, &mut gr_minus);
        t.jacobian(&xp, &mut j_plus);
        t.jacobian(&xm, &mut j_minus);
        let mut lag_p = gr_plus.iter().map(|g| obj_factor * g).collect::<Vec<_>>();
        let mut lag_m = gr_minus.iter().map(|g| obj_factor * g).collect::<Vec<_>>();
        for (k, &(r, c)) in t.jac.iter().enumerate() {
            lag_p[c] += lambda[r] * j_plus[k];
            lag_m[c] += lambda[r] * j_minus[k];
        }
        for j in 0..n {
            let fd = (lag_p[j] - lag_m[j]) / (2.0 * h);
            let an = dense_h[j * n + i];
            assert!(
                (fd - an).abs() <= 1e-5 * h_scale,
                "{name}: H[{j}][{i}] {an} vs fd {fd} (scale {h_scale})"
            );
        }
    }
}

#[test]
fn derivatives_3d_rendezvous_with_a_moving_threat() {
    check_derivatives("3d-rendezvous-moving-threat");
}

#[test]
fn derivatives_2d_fixed_time() {
    check_derivatives("2d-fixed-time-unavoidable");
}

/// In a steady wind (the planner plans over the ground, FORMULATION.md §8) the
/// transcription's derivatives hold the same tolerances.
#[test]
fn derivatives_in_a_steady_wind() {
    check_derivatives_in("2d-fixed-time-unavoidable", [12.0, -9.0, 0.0]);
    check_derivatives_in("3d-rendezvous-moving-threat", [-10.0, 14.0, 1.5]);
}

#[test]
fn derivatives_2d_min_time_rendezvous() {
    check_derivatives("2d-min-time-rendezvous-avoidable");
}
