//! Vehicle models (FORMULATION.md §2): RK4 against analytic solutions, the lift of a
//! reduced path (eqs. 5.13–5.15) flown by the full model, and the analytic first and second
//! derivatives against central finite differences.

// Index loops over matrix and vector entries read like the formulas they check.
#![allow(clippy::needless_range_loop)]

use nalgebra::SMatrix;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wingman_planning::dynamics::{
    DynamicsError, G0, Limits, OdeModel, Planar, Reduced, ReducedPath, Spatial, SpatialLimits,
    idx3, lift_reduced_path, rk4_integrate, rk4_step, rk4_trajectory,
};

/// Largest entry of `|a - b|` over the largest entry of `|a|` (norm-wise relative error).
fn rel_err<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>, b: &SMatrix<f64, R, C>) -> f64 {
    let scale = a.amax().max(1e-300);
    (a - b).amax() / scale
}

/// 2-D turn at constant rate u: the analytic circle
/// `x = x0 + V/u (sin psi - sin psi0)`, `y = y0 - V/u (cos psi - cos psi0)`, `psi = psi0 + u t`.
#[test]
fn planar_constant_turn_matches_circle() {
    let v = 200.0;
    let u = 0.05;
    let model = Planar::new(v).unwrap();
    let x0 = [100.0, -50.0, 0.3];
    let dt = 0.01;
    let radius = v / u;
    let mut x = x0;
    for step in 1..=6000 {
        x = rk4_step(&model, &x, &[u], dt);
        if step % 500 == 0 {
            let t = step as f64 * dt;
            let psi = x0[2] + u * t;
            let ex = x0[0] + radius * (psi.sin() - x0[2].sin());
            let ey = x0[1] - radius * (psi.cos() - x0[2].cos());
            let pos_err = (x[0] - ex).hypot(x[1] - ey);
            // tolerance: 1e-6 relative to the turn radius (RK4, dt = 0.01 s)
            assert!(
                pos_err <= 1e-6 * radius,
                "t = {t}: position error {pos_err} m"
            );
            assert!(
                (x[2] - psi).abs() <= 1e-6 * (u * t),
                "t = {t}: heading error {}",
                x[2] - psi
            );
        }
    }
}

/// Level coordinated turn: `Nz = 1/cos mu`, `gamma = 0` keeps `gamma' = 0`, so altitude is
/// constant, and `chi' = g tan mu / V`; the ground track is a circle of radius
/// `V² / (g tan mu)`.
#[test]
fn spatial_level_coordinated_turn() {
    let v = 250.0;
    let model = Spatial::new(v).unwrap();
    for mu_deg in [-60.0_f64, -20.0, 30.0, 45.0] {
        let mu = mu_deg.to_radians();
        let x0 = [1000.0, 2000.0, 5000.0, 0.0, 0.7, 1.0 / mu.cos(), mu];
        let rate = G0 * mu.tan() / v;
        let radius = v / rate.abs();
        let dt = 0.05;
        let steps = 2400; // 120 s
        let xf = rk4_integrate(&model, 0.0, &x0, dt, steps, |_, _| [0.0, 0.0]);
        let t = dt * steps as f64;
        // altitude and gamma: tolerance 1e-6 m and 1e-12 rad (the motion is exactly level)
        assert!(
            (xf[idx3::Z] - x0[2]).abs() <= 1e-6,
            "mu {mu_deg}: dz = {}",
            xf[2] - x0[2]
        );
        assert!(
            xf[idx3::GAMMA].abs() <= 1e-12,
            "mu {mu_deg}: gamma = {}",
            xf[3]
        );
        // heading: g tan mu / V, tolerance 1e-9 relative to the turned angle
        let chi = x0[4] + rate * t;
        assert!(
            (xf[idx3::CHI] - chi).abs() <= 1e-9 * (rate * t).abs(),
            "mu {mu_deg}: chi {} vs {chi}",
            xf[4]
        );
        // position on the analytic circle, tolerance 1e-6 relative to the radius
        let s = rate.signum();
        let cx = x0[0] - s * radius * x0[4].sin();
        let cy = x0[1] + s * radius * x0[4].cos();
        let ex = cx + s * radius * chi.sin();
        let ey = cy - s * radius * chi.cos();
        let err = (xf[0] - ex).hypot(xf[1] - ey);
        assert!(err <= 1e-6 * radius, "mu {mu_deg}: position error {err} m");
    }
}

/// A smooth reduced path (climbing, weaving turn) sampled every `dt_s`, lifted with eqs.
/// (5.13)–(5.15), then flown open loop by the full 7-state model from the lifted first
/// state with the lifted controls held over each step. The lift's difference quotients are
/// first order, so the flown path returns to the reduced one with an error `O(dt_s)`.
fn lift_round_trip_error(dt_s: f64) -> f64 {
    let v = 200.0;
    let reduced = Reduced::new(v).unwrap();
    let full = Spatial::new(v).unwrap();
    let gamma = |t: f64| 0.08 * (2.0 * std::f64::consts::PI * t / 40.0).sin();
    let chi = |t: f64| 3.0 + 0.03 * t + 0.25 * (2.0 * std::f64::consts::PI * t / 30.0).sin();
    let duration = 60.0;
    let n = (duration / dt_s).round() as usize + 1;
    // the reduced path, integrated finely (RK4, 100 sub-steps per sample) with gamma(t),
    // chi(t) as continuous "controls"
    let mut times = vec![0.0; n];
    let mut pos = vec![[0.0; 3]; n];
    let mut g = vec![0.0; n];
    let mut c = vec![0.0; n];
    pos[0] = [0.0, 0.0, 3000.0];
    for i in 0..n {
        times[i] = i as f64 * dt_s;
        g[i] = gamma(times[i]);
        c[i] = chi(times[i]) % std::f64::consts::TAU; // wrapped: the lift must unwrap
        if i + 1 < n {
            pos[i + 1] = rk4_integrate(&reduced, times[i], &pos[i], dt_s / 100.0, 100, |t, _| {
                [gamma(t), chi(t)]
            });
        }
    }
    let path = ReducedPath {
        times: &times,
        positions: &pos,
        gamma: &g,
        chi: &c,
    };
    let mut states = vec![[0.0; 7]; n];
    let mut controls = vec![[0.0; 2]; n];
    lift_reduced_path(&full, &path, &mut states, &mut controls).unwrap();
    let mut x = states[0];
    let mut worst = 0.0_f64;
    for i in 0..n - 1 {
        let u = controls[i];
        x = rk4_integrate(&full, times[i], &x, dt_s / 10.0, 10, |_, _| u);
        let p = pos[i + 1];
        let err = ((x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2) + (x[2] - p[2]).powi(2)).sqrt();
        worst = worst.max(err);
    }
    worst
}

#[test]
fn lift_of_reduced_path_flies_back_to_it() {
    // The forward quotients of (5.14) hold over [t_i, t_i+1] the rates of the mid-step,
    // so the flown heading leads by about chi' dt/2 and the position error grows linearly
    // in time: measured 29.0 m, 14.5 m, 7.2 m for dt = 0.1, 0.05, 0.025 s.
    let e1 = lift_round_trip_error(0.1);
    let e2 = lift_round_trip_error(0.05);
    let e3 = lift_round_trip_error(0.025);
    // tolerance: with 0.1 s samples the 12 km path is flown back within 0.3 % of its
    // length (36 m) ...
    assert!(e1 <= 36.0, "max deviation {e1} m with 0.1 s samples");
    // ... and the error is first order: halving the step halves it (within 10 %)
    for (coarse, fine) in [(e1, e2), (e2, e3)] {
        let ratio = fine / coarse;
        assert!(
            (0.45..=0.55).contains(&ratio),
            "{fine} m / {coarse} m = {ratio}: not first order"
        );
    }
}

/// The lift inverts the model exactly for a steady level turn: every lifted state has
/// `Nz = 1/cos mu` and `mu = atan(V chi' / g)`.
#[test]
fn lift_of_steady_turn_gives_coordinated_turn() {
    let v = 150.0;
    let full = Spatial::new(v).unwrap();
    let rate = -0.04;
    let n = 11;
    let times: Vec<f64> = (0..n).map(|i| i as f64 * 0.5).collect();
    let chi: Vec<f64> = times.iter().map(|t| 1.0 + rate * t).collect();
    let gamma = vec![0.0; n];
    let pos = vec![[0.0, 0.0, 1000.0]; n];
    let mut states = vec![[0.0; 7]; n];
    let mut controls = vec![[9.0; 2]; n];
    lift_reduced_path(
        &full,
        &ReducedPath {
            times: &times,
            positions: &pos,
            gamma: &gamma,
            chi: &chi,
        },
        &mut states,
        &mut controls,
    )
    .unwrap();
    let mu = (v * rate / G0).atan();
    for (x, u) in states.iter().zip(&controls) {
        // tolerance 1e-12: closed-form inversion, no discretisation error for a steady turn
        assert!(
            (x[idx3::MU] - mu).abs() <= 1e-12,
            "mu {} vs {mu}",
            x[idx3::MU]
        );
        assert!(
            (x[idx3::NZ] - 1.0 / mu.cos()).abs() <= 1e-12,
            "Nz {}",
            x[idx3::NZ]
        );
        assert!(u[0].abs() <= 1e-9 && u[1].abs() <= 1e-9, "controls {u:?}");
    }
}

#[test]
fn lift_rejects_bad_paths() {
    let full = Spatial::new(100.0).unwrap();
    static T: [f64; 3] = [0.0, 1.0, 1.0];
    let t = &T;
    let p = [[0.0; 3]; 3];
    let a = [0.0; 3];
    let mut s = [[0.0; 7]; 3];
    let mut u = [[0.0; 2]; 3];
    let path = |times: &'static [f64]| ReducedPath {
        times,
        positions: &p[..times.len()],
        gamma: &a[..times.len()],
        chi: &a[..times.len()],
    };
    let e = lift_reduced_path(&full, &path(t), &mut s, &mut u);
    assert_eq!(e, Err(DynamicsError::TimesNotIncreasing { index: 2 }));
    let e = lift_reduced_path(&full, &path(&t[..1]), &mut s[..1], &mut u[..1]);
    assert_eq!(e, Err(DynamicsError::TooFewSamples { need: 2, got: 1 }));
    let e = lift_reduced_path(&full, &path(&[0.0, 1.0, 2.0]), &mut s[..2], &mut u[..2]);
    assert!(matches!(e, Err(DynamicsError::LengthMismatch { .. })));
    let nan = [0.0, f64::NAN, 2.0];
    let bad = ReducedPath {
        times: &[0.0, 1.0, 2.0],
        positions: &p,
        gamma: &nan,
        chi: &a,
    };
    assert_eq!(
        lift_reduced_path(&full, &bad, &mut s, &mut u),
        Err(DynamicsError::NonFiniteSample { index: 1 })
    );
}

#[test]
fn limits_are_validated() {
    let ok = SpatialLimits {
        speed: 250.0,
        gamma_max: 0.5,
        nz_min: -1.0,
        nz_max: 4.0,
        mu_max: 1.2,
        nz_rate_max: 1.0,
        mu_rate_max: 0.5,
        z_min: 500.0,
    };
    let l = Limits::spatial(ok).unwrap();
    assert_eq!(l.turn_rate_max, f64::INFINITY);
    assert!(matches!(
        Limits::spatial(SpatialLimits { nz_min: 1.0, ..ok }),
        Err(DynamicsError::LevelFlightOutsideNz { .. })
    ));
    assert!(matches!(
        Limits::spatial(SpatialLimits {
            gamma_max: 1.6,
            ..ok
        }),
        Err(DynamicsError::AngleTooLarge { .. })
    ));
    assert!(matches!(
        Limits::spatial(SpatialLimits { speed: -1.0, ..ok }),
        Err(DynamicsError::NotPositive { field: "speed", .. })
    ));
    assert!(matches!(
        Limits::spatial(SpatialLimits {
            z_min: f64::NAN,
            ..ok
        }),
        Err(DynamicsError::NotFinite { .. })
    ));
    assert!(Limits::planar(100.0, 0.0).is_err());
    assert!(Planar::new(f64::INFINITY).is_err());
    assert!(Spatial::new(0.0).is_err());
    assert!(Reduced::new(-3.0).is_err());
}

#[test]
fn rk4_trajectory_matches_step_by_step() {
    let model = Planar::new(120.0).unwrap();
    let mut out = [[0.0; 3]; 11];
    rk4_trajectory(
        &model,
        2.0,
        &[1.0, 2.0, 0.1],
        0.2,
        |t, _| [0.01 * t],
        &mut out,
    );
    let mut x = [1.0, 2.0, 0.1];
    for (k, row) in out.iter().enumerate() {
        assert_eq!(*row, x, "step {k}");
        x = rk4_integrate(&model, 2.0 + 0.2 * k as f64, &x, 0.2, 1, |t, _| [0.01 * t]);
    }
}

/// Central differences of `f` wrt `z` (step `h (1 + |z_j|)`), as a matrix `R x C`.
fn fd_jac<const R: usize, const C: usize>(
    z: &[f64; C],
    mut f: impl FnMut(&[f64; C]) -> [f64; R],
) -> SMatrix<f64, R, C> {
    let mut j = SMatrix::<f64, R, C>::zeros();
    for c in 0..C {
        let h = 1e-6 * (1.0 + z[c].abs());
        let mut zp = *z;
        let mut zm = *z;
        zp[c] += h;
        zm[c] -= h;
        let (fp, fm) = (f(&zp), f(&zm));
        for r in 0..R {
            j[(r, c)] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    j
}

fn split<const N: usize, const M: usize, const Z: usize>(z: &[f64; Z]) -> ([f64; N], [f64; M]) {
    (
        std::array::from_fn(|i| z[i]),
        std::array::from_fn(|i| z[N + i]),
    )
}

/// Still air, and a steady wind of 25 m/s with a vertical part (the 2-D model keeps the
/// horizontal part).
const WINDS: [[f64; 3]; 2] = [[0.0; 3], [15.0, -20.0, 3.0]];

#[test]
fn jacobians_match_central_differences() {
    for wind in WINDS {
        jacobians_match_central_differences_in(wind);
    }
}

fn jacobians_match_central_differences_in(wind: [f64; 3]) {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_0001);
    let planar = Planar::new(180.0).unwrap().with_wind(wind);
    let spatial = Spatial::new(230.0).unwrap().with_wind(wind);
    let reduced = Reduced::new(230.0).unwrap().with_wind(wind);
    for _ in 0..50 {
        // 2-D
        let x: [f64; 3] = [
            rng.random_range(-1e4..1e4),
            rng.random_range(-1e4..1e4),
            rng.random_range(-7.0..7.0),
        ];
        let u = [rng.random_range(-0.2..0.2)];
        let jx = fd_jac(&x, |x| planar.rhs(x, &u));
        let ju = fd_jac(&u, |u| planar.rhs(&x, u));
        // tolerance: 1e-6 relative to the largest entry
        assert!(rel_err(&planar.jac_x(&x, &u), &jx) <= 1e-6);
        assert!(rel_err(&planar.jac_u(&x, &u), &ju) <= 1e-6);
        // 3-D
        let x: [f64; 7] = [
            rng.random_range(-1e4..1e4),
            rng.random_range(-1e4..1e4),
            rng.random_range(500.0..1e4),
            rng.random_range(-0.5..0.5),
            rng.random_range(-4.0..4.0),
            rng.random_range(-1.0..4.0),
            rng.random_range(-1.2..1.2),
        ];
        let u = [rng.random_range(-1.0..1.0), rng.random_range(-0.5..0.5)];
        let jx = fd_jac(&x, |x| spatial.rhs(x, &u));
        let ju = fd_jac(&u, |u| spatial.rhs(&x, u));
        let ex = rel_err(&spatial.jac_x(&x, &u), &jx);
        assert!(ex <= 1e-6, "3-D df/dx relative error {ex}");
        assert!(rel_err(&spatial.jac_u(&x, &u), &ju) <= 1e-6);
        // reduced
        let xr = [x[0], x[1], x[2]];
        let ur = [x[3], x[4]];
        let ju = fd_jac(&ur, |u| reduced.rhs(&xr, u));
        assert!(rel_err(&reduced.jac_u(&xr, &ur), &ju) <= 1e-6);
        assert_eq!(reduced.jac_x(&xr, &ur), SMatrix::<f64, 3, 3>::zeros());
    }
}

#[test]
fn second_derivatives_match_central_differences() {
    for wind in WINDS {
        second_derivatives_match_central_differences_in(wind);
    }
}

fn second_derivatives_match_central_differences_in(wind: [f64; 3]) {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_0002);
    let spatial = Spatial::new(230.0).unwrap().with_wind(wind);
    let planar = Planar::new(180.0).unwrap().with_wind(wind);
    let reduced = Reduced::new(230.0).unwrap().with_wind(wind);
    for _ in 0..50 {
        let z: [f64; 9] = [
            rng.random_range(-1e4..1e4),
            rng.random_range(-1e4..1e4),
            rng.random_range(500.0..1e4),
            rng.random_range(-0.5..0.5),
            rng.random_range(-4.0..4.0),
            rng.random_range(-1.0..4.0),
            rng.random_range(-1.2..1.2),
            rng.random_range(-1.0..1.0),
            rng.random_range(-0.5..0.5),
        ];
        let (x, u) = split::<7, 2, 9>(&z);
        let hs = spatial.hessians(&x, &u);
        // the Jacobian of row k of [df/dx df/du] by central differences is d²f_k/dz²
        for (k, h) in hs.iter().enumerate() {
            let fd = fd_jac(&z, |z| {
                let (x, u) = split::<7, 2, 9>(z);
                let (jx, ju) = (spatial.jac_x(&x, &u), spatial.jac_u(&x, &u));
                std::array::from_fn(|c| if c < 7 { jx[(k, c)] } else { ju[(k, c - 7)] })
            });
            let scale = h.amax().max(1e-3);
            let err = (h - fd).amax() / scale;
            // tolerance: 1e-6 relative to the largest entry of the component's Hessian
            assert!(err <= 1e-6, "3-D component {k}: relative error {err}");
        }
        // the weighted sum is the sum of the components
        let lambda: [f64; 7] = std::array::from_fn(|i| (i as f64) - 2.5);
        let w = spatial.hessian_weighted(&x, &u, &lambda);
        let sum = hs
            .iter()
            .zip(&lambda)
            .fold(SMatrix::<f64, 9, 9>::zeros(), |a, (h, l)| a + h * *l);
        assert!((w - sum).amax() <= 1e-9 * sum.amax().max(1.0));

        let zp: [f64; 4] = [z[0], z[1], z[4], z[7]];
        for (k, h) in planar
            .hessians(&[zp[0], zp[1], zp[2]], &[zp[3]])
            .iter()
            .enumerate()
        {
            let fd = fd_jac(&zp, |z| {
                let (x, u) = split::<3, 1, 4>(z);
                let (jx, ju) = (planar.jac_x(&x, &u), planar.jac_u(&x, &u));
                std::array::from_fn(|c| if c < 3 { jx[(k, c)] } else { ju[(k, 0)] })
            });
            assert!(
                (h - fd).amax() <= 1e-6 * h.amax().max(1e-3),
                "2-D component {k}"
            );
        }
        let zr: [f64; 5] = [z[0], z[1], z[2], z[3], z[4]];
        for k in 0..3 {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            let h = reduced.hessian_weighted(&[z[0], z[1], z[2]], &[z[3], z[4]], &e);
            let fd = fd_jac(&zr, |z| {
                let (x, u) = split::<3, 2, 5>(z);
                let ju = reduced.jac_u(&x, &u);
                std::array::from_fn(|c| if c < 3 { 0.0 } else { ju[(k, c - 3)] })
            });
            assert!(
                (h - fd).amax() <= 1e-6 * h.amax().max(1e-3),
                "reduced component {k}"
            );
        }
    }
}

/// In a steady wind every model's position rates are its still-air rates plus the wind
/// (the 2-D model's horizontal part), its other rates unchanged, to rounding (1e-12).
#[test]
fn a_steady_wind_adds_to_the_position_rates() {
    let w = WINDS[1];
    let (x2, u2) = ([100.0, -50.0, 0.7], [0.03]);
    let still = Planar::new(180.0).unwrap().rhs(&x2, &u2);
    let windy = Planar::new(180.0).unwrap().with_wind(w).rhs(&x2, &u2);
    let expected = [still[0] + w[0], still[1] + w[1], still[2]];
    for i in 0..3 {
        assert!((windy[i] - expected[i]).abs() <= 1e-12, "2-D {i}");
    }
    let x3 = [0.0, 0.0, 5000.0, 0.1, 1.2, 1.3, 0.4];
    let u3 = [0.2, -0.1];
    let still = Spatial::new(230.0).unwrap().rhs(&x3, &u3);
    let windy = Spatial::new(230.0).unwrap().with_wind(w).rhs(&x3, &u3);
    for i in 0..7 {
        let expected = still[i] + if i < 3 { w[i] } else { 0.0 };
        assert!((windy[i] - expected).abs() <= 1e-12, "3-D {i}");
    }
    let still = Reduced::new(230.0).unwrap().rhs(&[0.0; 3], &[0.1, 1.2]);
    let windy = Reduced::new(230.0)
        .unwrap()
        .with_wind(w)
        .rhs(&[0.0; 3], &[0.1, 1.2]);
    for i in 0..3 {
        assert!((windy[i] - still[i] - w[i]).abs() <= 1e-12, "reduced {i}");
    }
}
