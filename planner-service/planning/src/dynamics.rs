//! Vehicle models of FORMULATION.md §2: the 2-D model (eq. 3.8), the 3-D model
//! (eqs. 2.4/5.5), the reduced 3-D model of the particle swarm (eq. 5.11), their analytic
//! first and second derivatives, a fixed-step RK4 integrator and the lift of a reduced path
//! to the full 7-state path with controls (eqs. 5.13–5.15).
//!
//! States and controls are plain arrays in model order (see the index constants); Jacobians
//! and Hessians are `nalgebra` static matrices. Nothing here allocates or panics on finite
//! input. The 3-D model divides by `cos gamma`: it is singular at `gamma = ±90°`, which the
//! bound `|gamma| <= gamma_max < 90°` keeps out of reach (non-finite values result there,
//! never a panic).

use nalgebra::SMatrix;
use thiserror::Error;

/// Standard gravity `g` (FORMULATION.md §1), m/s².
pub const G0: f64 = 9.80665;

/// State indices of the 2-D model: `x, y, psi`.
pub mod idx2 {
    /// East position, m.
    pub const X: usize = 0;
    /// North position, m.
    pub const Y: usize = 1;
    /// Heading `psi`, rad (counter-clockwise from +x).
    pub const PSI: usize = 2;
}

/// State indices of the 3-D model: `x, y, z, gamma, chi, Nz, mu`.
pub mod idx3 {
    /// East position, m.
    pub const X: usize = 0;
    /// North position, m.
    pub const Y: usize = 1;
    /// Altitude, m (up).
    pub const Z: usize = 2;
    /// Flight-path angle `gamma`, rad (positive climbing).
    pub const GAMMA: usize = 3;
    /// Heading `chi`, rad (counter-clockwise from +x).
    pub const CHI: usize = 4;
    /// Load factor `Nz`, g.
    pub const NZ: usize = 5;
    /// Bank angle `mu`, rad.
    pub const MU: usize = 6;
    /// Control `u1 = Nz'` (index in the control vector).
    pub const U1: usize = 0;
    /// Control `u2 = mu'` (index in the control vector).
    pub const U2: usize = 1;
}

/// State of the 2-D model `[x, y, psi]`.
pub type State2 = [f64; 3];
/// Control of the 2-D model `[u]` (turn rate).
pub type Control2 = [f64; 1];
/// State of the 3-D model `[x, y, z, gamma, chi, Nz, mu]`.
pub type State3 = [f64; 7];
/// Control of the 3-D model `[u1, u2] = [Nz', mu']`.
pub type Control3 = [f64; 2];
/// State of the reduced 3-D model `[x, y, z]`.
pub type StateReduced = [f64; 3];
/// "Control" of the reduced 3-D model `[gamma, chi]`.
pub type ControlReduced = [f64; 2];

/// Bad input to a model constructor, the limits or the lift.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum DynamicsError {
    /// A quantity that must be finite and positive is not.
    #[error("{field} must be finite and positive, got {value}")]
    NotPositive {
        /// Name of the field.
        field: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A quantity that must be finite is not.
    #[error("{field} must be finite, got {value}")]
    NotFinite {
        /// Name of the field.
        field: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// Level flight `Nz = 1` is not strictly inside `[nz_min, nz_max]`.
    #[error("level flight needs nz_min < 1 < nz_max, got [{nz_min}, {nz_max}]")]
    LevelFlightOutsideNz {
        /// Lower bound on `Nz`.
        nz_min: f64,
        /// Upper bound on `Nz`.
        nz_max: f64,
    },
    /// An angle bound is not below 90°.
    #[error("{field} must be below pi/2, got {value}")]
    AngleTooLarge {
        /// Name of the field.
        field: &'static str,
        /// The rejected value, rad.
        value: f64,
    },
    /// Fewer samples than the operation needs.
    #[error("need at least {need} samples, got {got}")]
    TooFewSamples {
        /// Minimum count.
        need: usize,
        /// Given count.
        got: usize,
    },
    /// Input and output slices differ in length.
    #[error("slice lengths differ: {what}")]
    LengthMismatch {
        /// Which slices.
        what: &'static str,
    },
    /// Sample times are not finite and strictly increasing.
    #[error("times must be finite and strictly increasing (sample {index})")]
    TimesNotIncreasing {
        /// First offending sample.
        index: usize,
    },
    /// A sample holds a non-finite number.
    #[error("non-finite value at sample {index}")]
    NonFiniteSample {
        /// First offending sample.
        index: usize,
    },
}

fn positive(field: &'static str, value: f64) -> Result<f64, DynamicsError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(DynamicsError::NotPositive { field, value })
    }
}

fn finite(field: &'static str, value: f64) -> Result<f64, DynamicsError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(DynamicsError::NotFinite { field, value })
    }
}

/// The vehicle limits in SI units and radians, as the models use them (FORMULATION.md §2,
/// scenario `[vehicle]`; the tasking carries them as `wingman_interfaces::VehicleLimits`).
///
/// The 2-D model uses `speed` and `turn_rate_max`; the 3-D model uses the others. Limits a
/// model does not use are infinite when built by [`Limits::planar`] or
/// [`Limits::spatial`], so a bound check on them never fires.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Constant airspeed `V`, m/s.
    pub speed: f64,
    /// 2-D: bound on `|u| = |psi'|`, rad/s.
    pub turn_rate_max: f64,
    /// 3-D: bound on `|gamma|`, rad (below π/2).
    pub gamma_max: f64,
    /// 3-D: lower bound on `Nz`.
    pub nz_min: f64,
    /// 3-D: upper bound on `Nz`.
    pub nz_max: f64,
    /// 3-D: bound on `|mu|`, rad.
    pub mu_max: f64,
    /// 3-D: bound on `|u1| = |Nz'|`, 1/s.
    pub nz_rate_max: f64,
    /// 3-D: bound on `|u2| = |mu'|`, rad/s.
    pub mu_rate_max: f64,
    /// 3-D: lowest altitude, m.
    pub z_min: f64,
}

/// The 3-D part of [`Limits`], for [`Limits::spatial`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpatialLimits {
    /// Constant airspeed `V`, m/s.
    pub speed: f64,
    /// Bound on `|gamma|`, rad.
    pub gamma_max: f64,
    /// Lower bound on `Nz`.
    pub nz_min: f64,
    /// Upper bound on `Nz`.
    pub nz_max: f64,
    /// Bound on `|mu|`, rad.
    pub mu_max: f64,
    /// Bound on `|Nz'|`, 1/s.
    pub nz_rate_max: f64,
    /// Bound on `|mu'|`, rad/s.
    pub mu_rate_max: f64,
    /// Lowest altitude, m.
    pub z_min: f64,
}

impl Limits {
    /// Limits of the 2-D model; the 3-D limits are set to "unbounded".
    pub fn planar(speed: f64, turn_rate_max: f64) -> Result<Self, DynamicsError> {
        Ok(Self {
            speed: positive("speed", speed)?,
            turn_rate_max: positive("turn_rate_max", turn_rate_max)?,
            gamma_max: f64::INFINITY,
            nz_min: f64::NEG_INFINITY,
            nz_max: f64::INFINITY,
            mu_max: f64::INFINITY,
            nz_rate_max: f64::INFINITY,
            mu_rate_max: f64::INFINITY,
            z_min: f64::NEG_INFINITY,
        })
    }

    /// Limits of the 3-D model, checked as the scenario format requires:
    /// all finite, positive where they are magnitudes, `gamma_max < π/2`,
    /// `nz_min < 1 < nz_max`. The 2-D turn-rate limit is set to "unbounded".
    pub fn spatial(l: SpatialLimits) -> Result<Self, DynamicsError> {
        positive("speed", l.speed)?;
        positive("gamma_max", l.gamma_max)?;
        if l.gamma_max >= std::f64::consts::FRAC_PI_2 {
            return Err(DynamicsError::AngleTooLarge {
                field: "gamma_max",
                value: l.gamma_max,
            });
        }
        finite("nz_min", l.nz_min)?;
        finite("nz_max", l.nz_max)?;
        if !(l.nz_min < 1.0 && 1.0 < l.nz_max) {
            return Err(DynamicsError::LevelFlightOutsideNz {
                nz_min: l.nz_min,
                nz_max: l.nz_max,
            });
        }
        positive("mu_max", l.mu_max)?;
        positive("nz_rate_max", l.nz_rate_max)?;
        positive("mu_rate_max", l.mu_rate_max)?;
        finite("z_min", l.z_min)?;
        Ok(Self {
            speed: l.speed,
            turn_rate_max: f64::INFINITY,
            gamma_max: l.gamma_max,
            nz_min: l.nz_min,
            nz_max: l.nz_max,
            mu_max: l.mu_max,
            nz_rate_max: l.nz_rate_max,
            mu_rate_max: l.mu_rate_max,
            z_min: l.z_min,
        })
    }
}

/// An ODE `x' = f(x, u)` with `NX` states and `NU` controls, and its analytic Jacobians.
pub trait OdeModel<const NX: usize, const NU: usize> {
    /// Right-hand side `f(x, u)`.
    fn rhs(&self, x: &[f64; NX], u: &[f64; NU]) -> [f64; NX];
    /// Jacobian `df/dx` (row `i` = derivative of `f_i`).
    fn jac_x(&self, x: &[f64; NX], u: &[f64; NU]) -> SMatrix<f64, NX, NX>;
    /// Jacobian `df/du`.
    fn jac_u(&self, x: &[f64; NX], u: &[f64; NU]) -> SMatrix<f64, NX, NU>;
}

// -------------------------------------------------------------------------------------------
// 2-D model
// -------------------------------------------------------------------------------------------

/// The 2-D model, eq. (3.8): `x' = V cos psi + w_x, y' = V sin psi + w_y, psi' = u`, with
/// `psi` the heading through the air and `w` a steady wind (0 unless set, `with_wind`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Planar {
    speed: f64,
    wind: [f64; 3],
}

impl Planar {
    /// A 2-D model flying at `speed` (finite, positive) in still air.
    pub fn new(speed: f64) -> Result<Self, DynamicsError> {
        Ok(Self {
            speed: positive("speed", speed)?,
            wind: [0.0; 3],
        })
    }

    /// The model in the steady wind `wind` (m/s; its vertical part is ignored).
    pub fn with_wind(self, wind: [f64; 3]) -> Self {
        Self {
            wind: [wind[0], wind[1], 0.0],
            ..self
        }
    }

    /// The constant speed `V`.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// `sum_k lambda_k d²f_k/dz²` with `z = (x, y, psi, u)`: the model's contribution to
    /// the Hessian of an NLP Lagrangian with multipliers `lambda`.
    pub fn hessian_weighted(
        &self,
        x: &State2,
        _u: &Control2,
        lambda: &[f64; 3],
    ) -> SMatrix<f64, 4, 4> {
        let (s, c) = x[idx2::PSI].sin_cos();
        let mut h = SMatrix::<f64, 4, 4>::zeros();
        h[(2, 2)] = -self.speed * (lambda[0] * c + lambda[1] * s);
        h
    }

    /// `d²f_k/dz²` for every component `k`, `z = (x, y, psi, u)`.
    pub fn hessians(&self, x: &State2, u: &Control2) -> [SMatrix<f64, 4, 4>; 3] {
        std::array::from_fn(|k| {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            self.hessian_weighted(x, u, &e)
        })
    }
}

impl OdeModel<3, 1> for Planar {
    fn rhs(&self, x: &State2, u: &Control2) -> State2 {
        let (s, c) = x[idx2::PSI].sin_cos();
        let mut f = [self.speed * c, self.speed * s, u[0]];
        drift(&mut f, &self.wind);
        f
    }

    fn jac_x(&self, x: &State2, _u: &Control2) -> SMatrix<f64, 3, 3> {
        let (s, c) = x[idx2::PSI].sin_cos();
        let mut j = SMatrix::<f64, 3, 3>::zeros();
        j[(0, 2)] = -self.speed * s;
        j[(1, 2)] = self.speed * c;
        j
    }

    fn jac_u(&self, _x: &State2, _u: &Control2) -> SMatrix<f64, 3, 1> {
        SMatrix::<f64, 3, 1>::new(0.0, 0.0, 1.0)
    }
}

// -------------------------------------------------------------------------------------------
// 3-D model
// -------------------------------------------------------------------------------------------

/// The 3-D point-mass model, eqs. (2.4)/(5.5):
///
/// ```text
/// x' = V cos gamma cos chi      gamma' = g (Nz cos mu - cos gamma) / V
/// y' = V cos gamma sin chi      chi'   = g Nz sin mu / (V cos gamma)
/// z' = V sin gamma              Nz' = u1,   mu' = u2
/// ```
///
/// with `chi` the heading and `gamma` the flight-path angle through the air; a steady wind
/// `w` (0 unless set, `with_wind`) adds to `x', y', z'`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spatial {
    speed: f64,
    g: f64,
    wind: [f64; 3],
}

impl Spatial {
    /// A 3-D model flying at `speed` (finite, positive) with `g = G0`, in still air.
    pub fn new(speed: f64) -> Result<Self, DynamicsError> {
        Ok(Self {
            speed: positive("speed", speed)?,
            g: G0,
            wind: [0.0; 3],
        })
    }

    /// The model in the steady wind `wind` (m/s).
    pub fn with_wind(self, wind: [f64; 3]) -> Self {
        Self { wind, ..self }
    }

    /// The constant speed `V`.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Gravity used by the model.
    pub fn gravity(&self) -> f64 {
        self.g
    }

    /// `sum_k lambda_k d²f_k/dz²` with `z = (x, y, z, gamma, chi, Nz, mu, u1, u2)`: the
    /// model's contribution to the Hessian of an NLP Lagrangian. Only the
    /// `(gamma, chi, Nz, mu)` block is non-zero.
    pub fn hessian_weighted(
        &self,
        x: &State3,
        _u: &Control3,
        lambda: &[f64; 7],
    ) -> SMatrix<f64, 9, 9> {
        use idx3::{CHI, GAMMA, MU, NZ};
        let v = self.speed;
        let k = self.g / v;
        let (sg, cg) = x[GAMMA].sin_cos();
        let (sc, cc) = x[CHI].sin_cos();
        let (sm, cm) = x[MU].sin_cos();
        let nz = x[NZ];
        let sec = 1.0 / cg;
        let tan = sg * sec;
        let [l0, l1, l2, l3, l4, ..] = *lambda;

        let mut h = SMatrix::<f64, 9, 9>::zeros();
        // f0 = V cg cc, f1 = V cg sc, f2 = V sg
        let gg = -v * cg * (l0 * cc + l1 * sc) - v * sg * l2
            // f3 = k (Nz cm - cg)
            + l3 * k * cg
            // f4 = k Nz sm sec
            + l4 * k * nz * sm * sec * (tan * tan + sec * sec);
        let gc = v * sg * (l0 * sc - l1 * cc);
        let cchi = -v * cg * (l0 * cc + l1 * sc);
        let gn = l4 * k * sm * sec * tan;
        let gm = l4 * k * nz * cm * sec * tan;
        let nm = -l3 * k * sm + l4 * k * cm * sec;
        let mm = -l3 * k * nz * cm - l4 * k * nz * sm * sec;
        h[(GAMMA, GAMMA)] = gg;
        h[(GAMMA, CHI)] = gc;
        h[(CHI, GAMMA)] = gc;
        h[(CHI, CHI)] = cchi;
        h[(GAMMA, NZ)] = gn;
        h[(NZ, GAMMA)] = gn;
        h[(GAMMA, MU)] = gm;
        h[(MU, GAMMA)] = gm;
        h[(NZ, MU)] = nm;
        h[(MU, NZ)] = nm;
        h[(MU, MU)] = mm;
        h
    }

    /// `d²f_k/dz²` for every component `k`, `z = (states, u1, u2)`.
    pub fn hessians(&self, x: &State3, u: &Control3) -> [SMatrix<f64, 9, 9>; 7] {
        std::array::from_fn(|k| {
            let mut e = [0.0; 7];
            e[k] = 1.0;
            self.hessian_weighted(x, u, &e)
        })
    }

    /// Velocity over the ground `(x', y', z')` of a state: through the air, plus the wind.
    pub fn velocity(&self, x: &State3) -> [f64; 3] {
        let (sg, cg) = x[idx3::GAMMA].sin_cos();
        let (sc, cc) = x[idx3::CHI].sin_cos();
        let mut v = [self.speed * cg * cc, self.speed * cg * sc, self.speed * sg];
        drift(&mut v, &self.wind);
        v
    }
}

impl OdeModel<7, 2> for Spatial {
    fn rhs(&self, x: &State3, u: &Control3) -> State3 {
        use idx3::{GAMMA, MU, NZ};
        let v = self.speed;
        let cg = x[GAMMA].cos();
        let (sm, cm) = x[MU].sin_cos();
        let [vx, vy, vz] = self.velocity(x);
        [
            vx,
            vy,
            vz,
            self.g * (x[NZ] * cm - cg) / v,
            self.g * x[NZ] * sm / (v * cg),
            u[idx3::U1],
            u[idx3::U2],
        ]
    }

    fn jac_x(&self, x: &State3, _u: &Control3) -> SMatrix<f64, 7, 7> {
        use idx3::{CHI, GAMMA, MU, NZ};
        let v = self.speed;
        let k = self.g / v;
        let (sg, cg) = x[GAMMA].sin_cos();
        let (sc, cc) = x[CHI].sin_cos();
        let (sm, cm) = x[MU].sin_cos();
        let nz = x[NZ];
        let sec = 1.0 / cg;
        let mut j = SMatrix::<f64, 7, 7>::zeros();
        j[(0, GAMMA)] = -v * sg * cc;
        j[(0, CHI)] = -v * cg * sc;
        j[(1, GAMMA)] = -v * sg * sc;
        j[(1, CHI)] = v * cg * cc;
        j[(2, GAMMA)] = v * cg;
        j[(3, GAMMA)] = k * sg;
        j[(3, NZ)] = k * cm;
        j[(3, MU)] = -k * nz * sm;
        j[(4, GAMMA)] = k * nz * sm * sec * sec * sg;
        j[(4, NZ)] = k * sm * sec;
        j[(4, MU)] = k * nz * cm * sec;
        j
    }

    fn jac_u(&self, _x: &State3, _u: &Control3) -> SMatrix<f64, 7, 2> {
        let mut j = SMatrix::<f64, 7, 2>::zeros();
        j[(idx3::NZ, idx3::U1)] = 1.0;
        j[(idx3::MU, idx3::U2)] = 1.0;
        j
    }
}

// -------------------------------------------------------------------------------------------
// Reduced 3-D model
// -------------------------------------------------------------------------------------------

/// The reduced 3-D model of the swarm, eq. (5.11): states `x, y, z`, "controls"
/// `gamma, chi`: `x' = V cos gamma cos chi, y' = V cos gamma sin chi, z' = V sin gamma`,
/// plus a steady wind (0 unless set, `with_wind`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reduced {
    speed: f64,
    wind: [f64; 3],
}

impl Reduced {
    /// A reduced model flying at `speed` (finite, positive), in still air.
    pub fn new(speed: f64) -> Result<Self, DynamicsError> {
        Ok(Self {
            speed: positive("speed", speed)?,
            wind: [0.0; 3],
        })
    }

    /// The model in the steady wind `wind` (m/s).
    pub fn with_wind(self, wind: [f64; 3]) -> Self {
        Self { wind, ..self }
    }

    /// The constant speed `V`.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// `sum_k lambda_k d²f_k/dz²` with `z = (x, y, z, gamma, chi)`.
    pub fn hessian_weighted(
        &self,
        _x: &StateReduced,
        u: &ControlReduced,
        lambda: &[f64; 3],
    ) -> SMatrix<f64, 5, 5> {
        let v = self.speed;
        let (sg, cg) = u[0].sin_cos();
        let (sc, cc) = u[1].sin_cos();
        let [l0, l1, l2] = *lambda;
        let mut h = SMatrix::<f64, 5, 5>::zeros();
        h[(3, 3)] = -v * cg * (l0 * cc + l1 * sc) - v * sg * l2;
        h[(3, 4)] = v * sg * (l0 * sc - l1 * cc);
        h[(4, 3)] = h[(3, 4)];
        h[(4, 4)] = -v * cg * (l0 * cc + l1 * sc);
        h
    }
}

impl OdeModel<3, 2> for Reduced {
    fn rhs(&self, _x: &StateReduced, u: &ControlReduced) -> StateReduced {
        let (sg, cg) = u[0].sin_cos();
        let (sc, cc) = u[1].sin_cos();
        let mut f = [self.speed * cg * cc, self.speed * cg * sc, self.speed * sg];
        drift(&mut f, &self.wind);
        f
    }

    fn jac_x(&self, _x: &StateReduced, _u: &ControlReduced) -> SMatrix<f64, 3, 3> {
        SMatrix::<f64, 3, 3>::zeros()
    }

    fn jac_u(&self, _x: &StateReduced, u: &ControlReduced) -> SMatrix<f64, 3, 2> {
        let v = self.speed;
        let (sg, cg) = u[0].sin_cos();
        let (sc, cc) = u[1].sin_cos();
        SMatrix::<f64, 3, 2>::new(
            -v * sg * cc,
            -v * cg * sc,
            -v * sg * sc,
            v * cg * cc,
            v * cg,
            0.0,
        )
    }
}

/// Adds a steady wind to the position rates `f[..3]` (nothing in still air, so that a
/// still-air model computes exactly what it did before winds existed). A constant wind
/// leaves every Jacobian and Hessian of the models unchanged.
#[inline]
fn drift<const N: usize>(f: &mut [f64; N], wind: &[f64; 3]) {
    if *wind != [0.0; 3] {
        for (fi, w) in f.iter_mut().zip(wind) {
            *fi += w;
        }
    }
}

// -------------------------------------------------------------------------------------------
// RK4
// -------------------------------------------------------------------------------------------

#[inline]
fn axpy<const N: usize>(x: &[f64; N], a: f64, k: &[f64; N]) -> [f64; N] {
    std::array::from_fn(|i| x[i] + a * k[i])
}

/// One classical RK4 step of length `dt` from `(t, x)`, the control given by
/// `control(t, x)` at each stage (so zero-order hold, interpolated and feedback controls
/// all fit).
#[inline]
pub fn rk4_step_with<M, C, const NX: usize, const NU: usize>(
    model: &M,
    t: f64,
    x: &[f64; NX],
    dt: f64,
    control: &mut C,
) -> [f64; NX]
where
    M: OdeModel<NX, NU>,
    C: FnMut(f64, &[f64; NX]) -> [f64; NU],
{
    let h2 = 0.5 * dt;
    let k1 = model.rhs(x, &control(t, x));
    let x2 = axpy(x, h2, &k1);
    let k2 = model.rhs(&x2, &control(t + h2, &x2));
    let x3 = axpy(x, h2, &k2);
    let k3 = model.rhs(&x3, &control(t + h2, &x3));
    let x4 = axpy(x, dt, &k3);
    let k4 = model.rhs(&x4, &control(t + dt, &x4));
    std::array::from_fn(|i| x[i] + dt / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]))
}

/// One RK4 step of length `dt` with the control `u` held constant.
#[inline]
pub fn rk4_step<M, const NX: usize, const NU: usize>(
    model: &M,
    x: &[f64; NX],
    u: &[f64; NU],
    dt: f64,
) -> [f64; NX]
where
    M: OdeModel<NX, NU>,
{
    rk4_step_with(model, 0.0, x, dt, &mut |_, _| *u)
}

/// `steps` RK4 steps of length `dt` from `(t0, x0)`; returns the final state.
pub fn rk4_integrate<M, C, const NX: usize, const NU: usize>(
    model: &M,
    t0: f64,
    x0: &[f64; NX],
    dt: f64,
    steps: usize,
    mut control: C,
) -> [f64; NX]
where
    M: OdeModel<NX, NU>,
    C: FnMut(f64, &[f64; NX]) -> [f64; NU],
{
    let mut x = *x0;
    for k in 0..steps {
        x = rk4_step_with(model, t0 + k as f64 * dt, &x, dt, &mut control);
    }
    x
}

/// RK4 from `(t0, x0)` writing the state after every step into `out` (`out[0] = x0`,
/// `out[k]` at `t0 + k dt`); the number of steps is `out.len() - 1`. Allocation-free.
pub fn rk4_trajectory<M, C, const NX: usize, const NU: usize>(
    model: &M,
    t0: f64,
    x0: &[f64; NX],
    dt: f64,
    mut control: C,
    out: &mut [[f64; NX]],
) where
    M: OdeModel<NX, NU>,
    C: FnMut(f64, &[f64; NX]) -> [f64; NU],
{
    let Some(first) = out.first_mut() else {
        return;
    };
    *first = *x0;
    for k in 1..out.len() {
        out[k] = rk4_step_with(
            model,
            t0 + (k - 1) as f64 * dt,
            &out[k - 1],
            dt,
            &mut control,
        );
    }
}

// -------------------------------------------------------------------------------------------
// Lift of a reduced path (eqs. 5.13–5.15)
// -------------------------------------------------------------------------------------------

/// A path of the reduced model: sample times, positions and the "controls" `gamma`, `chi`
/// at the samples (all the same length).
#[derive(Debug, Clone, Copy)]
pub struct ReducedPath<'a> {
    /// Sample times, strictly increasing.
    pub times: &'a [f64],
    /// Positions `(x, y, z)`.
    pub positions: &'a [[f64; 3]],
    /// Flight-path angle at each sample, rad.
    pub gamma: &'a [f64],
    /// Heading at each sample, rad (wrapped or continuous: differences are taken mod 2π).
    pub chi: &'a [f64],
}

/// Wraps an angle to `(-π, π]`.
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let r = a.rem_euclid(TAU);
    if r > PI { r - TAU } else { r }
}

/// Lifts a reduced path to full 3-D states and controls, eqs. (5.13)–(5.15), written into
/// `states` and `controls` (same length as the path).
///
/// For each step `i -> i+1` (`dt_i = t_{i+1} - t_i`, any spacing), with
/// `gamma'_i = (gamma_{i+1} - gamma_i)/dt_i`, `chi'_i = wrap(chi_{i+1} - chi_i)/dt_i`:
///
/// ```text
/// mu_i = atan( chi'_i cos gamma_i / (gamma'_i + g cos gamma_i / V) )        (5.14a)
/// Nz_i = (gamma'_i V / g + cos gamma_i) / cos mu_i                          (5.14b)
/// u1_i = (Nz_{i+1} - Nz_i)/dt_i,   u2_i = (mu_{i+1} - mu_i)/dt_i            (5.15)
/// ```
///
/// `atan` keeps `|mu| <= 90°` as the dissertation does (a push-over gives `Nz < 0`); it
/// is evaluated as `atan2(num·sign(den), |den|)` and `Nz` as the projection
/// `(V/g)(num sin mu + den cos mu)`, equal to (5.14b) without its division by `cos mu`.
/// The dissertation's difference quotients give `N - 1` values of `Nz, mu` and `N - 2`
/// controls; here the last sample holds `Nz, mu` of the one before and the controls of
/// the last two samples are zero, so every output has `N` entries. Positions, `gamma`
/// and `chi` are copied as given.
pub fn lift_reduced_path(
    model: &Spatial,
    path: &ReducedPath<'_>,
    states: &mut [State3],
    controls: &mut [Control3],
) -> Result<(), DynamicsError> {
    let n = path.times.len();
    if n < 2 {
        return Err(DynamicsError::TooFewSamples { need: 2, got: n });
    }
    if path.positions.len() != n || path.gamma.len() != n || path.chi.len() != n {
        return Err(DynamicsError::LengthMismatch {
            what: "path times/positions/gamma/chi",
        });
    }
    if states.len() != n || controls.len() != n {
        return Err(DynamicsError::LengthMismatch {
            what: "path and output states/controls",
        });
    }
    for i in 0..n {
        let p = &path.positions[i];
        if !(path.times[i].is_finite()
            && p.iter().all(|v| v.is_finite())
            && path.gamma[i].is_finite()
            && path.chi[i].is_finite())
        {
            return Err(DynamicsError::NonFiniteSample { index: i });
        }
        if i > 0 && path.times[i] <= path.times[i - 1] {
            return Err(DynamicsError::TimesNotIncreasing { index: i });
        }
    }
    let v = model.speed;
    let g = model.g;
    for (i, (st, p)) in states.iter_mut().zip(path.positions).enumerate() {
        *st = [p[0], p[1], p[2], path.gamma[i], path.chi[i], 1.0, 0.0];
    }
    for (i, st) in states.iter_mut().enumerate().take(n - 1) {
        let dt = path.times[i + 1] - path.times[i];
        let gdot = (path.gamma[i + 1] - path.gamma[i]) / dt;
        let cdot = wrap_angle(path.chi[i + 1] - path.chi[i]) / dt;
        let cg = path.gamma[i].cos();
        let num = cdot * cg;
        let den = gdot + g * cg / v;
        let mu = (num * den.signum()).atan2(den.abs());
        let (sm, cm) = mu.sin_cos();
        st[idx3::MU] = mu;
        st[idx3::NZ] = v / g * (num * sm + den * cm);
    }
    states[n - 1][idx3::MU] = states[n - 2][idx3::MU];
    states[n - 1][idx3::NZ] = states[n - 2][idx3::NZ];
    for (i, u) in controls.iter_mut().enumerate().take(n - 1) {
        let dt = path.times[i + 1] - path.times[i];
        *u = [
            (states[i + 1][idx3::NZ] - states[i][idx3::NZ]) / dt,
            (states[i + 1][idx3::MU] - states[i][idx3::MU]) / dt,
        ];
    }
    controls[n - 1] = [0.0, 0.0];
    Ok(())
}
