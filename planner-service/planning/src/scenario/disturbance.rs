//! The disturbances of a flight: the wind (`[wind]`: a mean vector and seeded gusts) and
//! how the real aircraft differs from the planner's model (`[aircraft]`: its response to
//! commands and the noise of its navigation solution). The harness flies them (its truth
//! model); a scenario without these tables flies the planner's model in still air.

use toml::Table;
use wingman_interfaces::{Model, VehicleLimits};

use super::reader::{DEG, Reader, Res, Sign, join};

/// Turbulence intensities and their gust standard deviation per axis, m/s (medium and
/// high altitude, after the Dryden model's probability-of-exceedance tables).
pub const GUSTS: [(&str, f64); 4] = [
    ("none", 0.0),
    ("light", 1.5),
    ("moderate", 3.0),
    ("severe", 6.0),
];

/// Scale length of the gusts when the file gives none, m (Dryden, above 2 000 ft).
pub const GUST_LENGTH_M: f64 = 533.4;

/// The wind over the whole flight: a steady mean plus first-order Gauss–Markov gusts.
#[derive(Debug, Clone, PartialEq)]
pub struct WindSpec {
    /// Mean wind `[x, y, z]`, m/s (the air mass moves this way); `z` is 0 in 2-D.
    pub mean_mps: [f64; 3],
    /// Standard deviation of each gust component, m/s (0: a steady wind).
    pub gust_sigma_mps: f64,
    /// Scale length of the gusts, m: their correlation time is this over the airspeed.
    pub gust_length_m: f64,
    /// Seed of the gusts' random stream.
    pub seed: u64,
}

/// The real aircraft's response to the tracker's commands and its navigation errors.
#[derive(Debug, Clone, PartialEq)]
pub struct AircraftSpec {
    /// Time constant of the first-order lag between a command and the response, s
    /// (0: at once).
    pub response_s: f64,
    /// 2-D: the most the turn rate changes per second, rad/s² (infinite: no limit).
    pub turn_accel_max: f64,
    /// 3-D: the aircraft's own limit on the load factor's rate, 1/s (default: the
    /// vehicle's `nz_rate_max_per_s`).
    pub nz_rate_max: f64,
    /// 3-D: the aircraft's own limit on the bank rate, rad/s (default: the vehicle's).
    pub mu_rate_max: f64,
    /// Standard deviation of the navigation solution's position error per axis, m.
    pub nav_sigma_m: f64,
    /// Standard deviation of its heading error, rad.
    pub nav_heading_sigma: f64,
    /// Correlation time of the navigation errors (first-order Gauss–Markov), s.
    pub nav_tau_s: f64,
    /// Seed of the navigation errors' random stream.
    pub seed: u64,
}

impl WindSpec {
    /// Still air.
    pub fn still() -> WindSpec {
        WindSpec {
            mean_mps: [0.0; 3],
            gust_sigma_mps: 0.0,
            gust_length_m: GUST_LENGTH_M,
            seed: 0,
        }
    }
}

impl AircraftSpec {
    /// The planner's model: an immediate response within the vehicle's limits, exact
    /// navigation.
    pub fn ideal(vehicle: &VehicleLimits) -> AircraftSpec {
        AircraftSpec {
            response_s: 0.0,
            turn_accel_max: f64::INFINITY,
            nz_rate_max: vehicle.nz_rate_max_per_s,
            mu_rate_max: vehicle.bank_rate_max_rps,
            nav_sigma_m: 0.0,
            nav_heading_sigma: 0.0,
            nav_tau_s: 1.0,
            seed: 0,
        }
    }
}

impl Reader<'_> {
    /// The optional `[wind]` and `[aircraft]` of `root`.
    pub(super) fn disturbances(
        &self,
        root: &Table,
        model: Model,
        vehicle: &VehicleLimits,
    ) -> Res<(Option<WindSpec>, Option<AircraftSpec>)> {
        let wind = match root.get("wind") {
            None => None,
            Some(_) => Some(self.wind(self.table(root, "", "wind")?, model)?),
        };
        let aircraft = match root.get("aircraft") {
            None => None,
            Some(_) => Some(self.aircraft(self.table(root, "", "aircraft")?, model, vehicle)?),
        };
        Ok((wind, aircraft))
    }

    /// `[wind]`.
    pub(super) fn wind(&self, w: &Table, model: Model) -> Res<WindSpec> {
        let ctx = "wind";
        self.only(
            w,
            ctx,
            &[
                "mean_mps",
                "gusts",
                "gust_sigma_mps",
                "gust_length_m",
                "seed",
            ],
        )?;
        let dim = model.position_dim();
        let mean_mps = match w.get("mean_mps") {
            None => [0.0; 3],
            Some(_) if dim == 3 && self.len_of(w, "mean_mps") == Some(2) => {
                self.vector(w, ctx, "mean_mps", 2, Sign::Any)?
            }
            Some(_) => self.vector(w, ctx, "mean_mps", dim, Sign::Any)?,
        };
        let gust_sigma_mps = match (w.get("gusts"), w.get("gust_sigma_mps")) {
            (Some(_), Some(_)) => {
                return self.fail(
                    join(ctx, "gust_sigma_mps"),
                    "give either gusts (an intensity) or gust_sigma_mps, not both",
                );
            }
            (Some(_), None) => {
                let name = self.string(w, ctx, "gusts")?;
                match GUSTS.iter().find(|(n, _)| *n == name) {
                    Some((_, sigma)) => *sigma,
                    None => {
                        return self.fail(
                            join(ctx, "gusts"),
                            format!(
                                "unknown intensity {name:?} (expected \"none\", \"light\", \
                                 \"moderate\" or \"severe\")"
                            ),
                        );
                    }
                }
            }
            (None, _) => self.number_or(w, ctx, "gust_sigma_mps", 0.0, Sign::NonNegative)?,
        };
        Ok(WindSpec {
            mean_mps,
            gust_sigma_mps,
            gust_length_m: self.number_or(
                w,
                ctx,
                "gust_length_m",
                GUST_LENGTH_M,
                Sign::Positive,
            )?,
            seed: self.seed_or(w, ctx, "seed", 0)?,
        })
    }

    /// `[aircraft]`.
    pub(super) fn aircraft(
        &self,
        a: &Table,
        model: Model,
        vehicle: &VehicleLimits,
    ) -> Res<AircraftSpec> {
        let ctx = "aircraft";
        let model_keys: &[&str] = match model {
            Model::TwoD => &["turn_accel_max_dps2"],
            Model::ThreeD => &["nz_rate_max_per_s", "bank_rate_max_dps"],
        };
        let common = [
            "response_s",
            "nav_sigma_m",
            "nav_heading_sigma_deg",
            "nav_tau_s",
            "seed",
        ];
        let allowed: Vec<&str> = common.iter().chain(model_keys).copied().collect();
        self.only(a, ctx, &allowed)?;
        let ideal = AircraftSpec::ideal(vehicle);
        let turn_accel =
            self.number_or(a, ctx, "turn_accel_max_dps2", f64::INFINITY, Sign::Positive);
        Ok(AircraftSpec {
            response_s: self.number_or(a, ctx, "response_s", 0.0, Sign::NonNegative)?,
            turn_accel_max: turn_accel? * DEG,
            nz_rate_max: self.number_or(
                a,
                ctx,
                "nz_rate_max_per_s",
                ideal.nz_rate_max,
                Sign::Positive,
            )?,
            mu_rate_max: self.number_or(
                a,
                ctx,
                "bank_rate_max_dps",
                ideal.mu_rate_max / DEG,
                Sign::Positive,
            )? * DEG,
            nav_sigma_m: self.number_or(a, ctx, "nav_sigma_m", 0.0, Sign::NonNegative)?,
            nav_heading_sigma: self.number_or(
                a,
                ctx,
                "nav_heading_sigma_deg",
                0.0,
                Sign::NonNegative,
            )? * DEG,
            nav_tau_s: self.number_or(a, ctx, "nav_tau_s", ideal.nav_tau_s, Sign::Positive)?,
            seed: self.seed_or(a, ctx, "seed", 0)?,
        })
    }

    /// The length of `t[key]` if it is a list.
    fn len_of(&self, t: &Table, key: &str) -> Option<usize> {
        t.get(key).and_then(|v| v.as_array()).map(Vec::len)
    }
}
