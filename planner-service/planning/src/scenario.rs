//! Scenario files (`scenarios/FORMAT.md`): one TOML file holds a mission's tasking, the
//! vehicle, the threat world and the events of one flight.
//!
//! [`Scenario::load`] returns a typed scenario in SI units and radians, or refuses the file
//! with one [`ScenarioError`] that names the file, the key and the problem. Positions are
//! stored as `[x, y, z]` with `z = 0` in 2-D. Unknown keys are refused too, so a typo
//! cannot silently drop a setting.

pub mod messages;

use std::fmt;
use std::path::Path;

use toml::{Table, Value};
use wingman_interfaces::{
    MAX_ROAD_POINTS, MAX_ROUTE_POINTS, MAX_TARGETS, Model, Objective, VehicleLimits, Weights,
};

const DEG: f64 = std::f64::consts::PI / 180.0;

/// A scenario file that breaks the format.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{file}: key `{key}`: {problem}")]
pub struct ScenarioError {
    /// The file as it was named to the loader.
    pub file: String,
    /// Dotted path of the offending key (`threats[2].axes_m`), or `(file)` / `(toml)` when
    /// the file cannot be read or parsed.
    pub key: String,
    /// What is wrong, in words.
    pub problem: String,
}

/// Where the wingman starts (level, unbanked flight in 3-D: `Nz = 1`, `mu = 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct Start {
    pub time_s: f64,
    pub position_m: [f64; 3],
    pub heading_rad: f64,
    pub gamma_rad: f64,
}

impl Start {
    /// The start state in model order, zero-padded to 7 (3-D: level, unbanked flight).
    pub fn state(&self, model: Model) -> [f64; 7] {
        let p = &self.position_m;
        match model {
            Model::TwoD => [p[0], p[1], self.heading_rad, 0.0, 0.0, 0.0, 0.0],
            Model::ThreeD => [p[0], p[1], p[2], self.gamma_rad, self.heading_rad, 1.0, 0.0],
        }
    }
}

/// The final point of `fixed-time` and `min-time` missions.
#[derive(Debug, Clone, PartialEq)]
pub struct FinalPoint {
    pub position_m: [f64; 3],
    pub heading_rad: f64,
    pub gamma_rad: f64,
    /// Final load factor (3-D), 1 unless the file says otherwise.
    pub nz: f64,
    /// Final bank angle (3-D), 0 unless the file says otherwise.
    pub mu_rad: f64,
    /// Fixed final time (`fixed-time` only).
    pub time_s: Option<f64>,
}

impl FinalPoint {
    /// The final state in model order, zero-padded to 7.
    pub fn state(&self, model: Model) -> [f64; 7] {
        let p = &self.position_m;
        match model {
            Model::TwoD => [p[0], p[1], self.heading_rad, 0.0, 0.0, 0.0, 0.0],
            Model::ThreeD => [
                p[0],
                p[1],
                p[2],
                self.gamma_rad,
                self.heading_rad,
                self.nz,
                self.mu_rad,
            ],
        }
    }
}

/// The lead's route for a rendezvous: flown at constant speed from `start.time_s`.
#[derive(Debug, Clone, PartialEq)]
pub struct LeadSpec {
    pub route_m: Vec<[f64; 3]>,
    pub speed_mps: f64,
}

/// A static superquadric threat.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticThreatSpec {
    pub name: String,
    pub center_m: [f64; 3],
    /// Semi-axes; the third is 0 in 2-D.
    pub axes_m: [f64; 3],
    /// Exponents per axis (default 2); the third is 0 in 2-D.
    pub exponents: [f64; 3],
    pub yaw_rad: f64,
    /// A pop-up reported at this time; `None`: known before take-off.
    pub appears_at_s: Option<f64>,
}

/// The onboard sensor's fixes of a moving threat.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorSpec {
    pub rate_hz: f64,
    pub sigma_m: f64,
}

/// A threat moving along a known road (FORMULATION.md §5).
#[derive(Debug, Clone, PartialEq)]
pub struct MovingThreatSpec {
    pub name: String,
    pub road_m: Vec<[f64; 3]>,
    /// Keep-out semi-axes when the position is certain: along the road, across, up.
    pub axes_m: [f64; 3],
    pub initial_distance_m: f64,
    pub initial_speed_mps: f64,
    pub accel_sigma_mps2: f64,
    pub accel_tau_s: f64,
    /// Standard deviations of `[d, v, a]` at `start.time_s`.
    pub initial_sigma: [f64; 3],
    pub appears_at_s: f64,
    pub sensor: SensorSpec,
    /// Seed of the harness's random truth motion.
    pub truth_seed: u64,
}

/// A change of tasking in flight.
#[derive(Debug, Clone, PartialEq)]
pub enum EventKind {
    /// The lead flies a new route from the event's time on.
    LeadRoute {
        route_m: Vec<[f64; 3]>,
        speed_mps: f64,
    },
    /// A new list of remaining targets.
    Targets { targets_m: Vec<[f64; 3]> },
    /// A new final point.
    Final(FinalPoint),
}

/// An event of the flight.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    pub at_s: f64,
    pub kind: EventKind,
}

/// A checked scenario in SI units and radians.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    pub name: String,
    pub summary: String,
    /// The file it was read from, as named to the loader.
    pub source: String,
    pub model: Model,
    pub objective: Objective,
    /// Vehicle limits; the fields of the other model are zero.
    pub vehicle: VehicleLimits,
    pub weights: Weights,
    pub start: Start,
    pub targets: Vec<[f64; 3]>,
    /// For `fixed-time` and `min-time`.
    pub final_point: Option<FinalPoint>,
    /// For `min-time-rendezvous`.
    pub lead: Option<LeadSpec>,
    pub threats: Vec<StaticThreatSpec>,
    pub moving_threats: Vec<MovingThreatSpec>,
    pub events: Vec<Event>,
}

impl Scenario {
    /// Reads and checks a scenario file.
    pub fn load(path: impl AsRef<Path>) -> Result<Scenario, ScenarioError> {
        let path = path.as_ref();
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ScenarioError {
            file: file.clone(),
            key: "(file)".into(),
            problem: format!("cannot be read: {e}"),
        })?;
        Scenario::parse(&text, &file)
    }

    /// Checks scenario text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Scenario, ScenarioError> {
        let root: Table = text.parse().map_err(|e: toml::de::Error| ScenarioError {
            file: file.to_string(),
            key: "(toml)".into(),
            problem: format!("not valid TOML: {}", e.message()),
        })?;
        Reader { file }.scenario(&root)
    }

    /// Number of position coordinates (2 or 3).
    pub fn dim(&self) -> usize {
        self.model.position_dim()
    }

    /// Static threats known before take-off (no `appears_at_s` after `start.time_s`).
    pub fn known_static_threats(&self) -> impl Iterator<Item = &StaticThreatSpec> {
        let t0 = self.start.time_s;
        self.threats
            .iter()
            .filter(move |t| t.appears_at_s.is_none_or(|a| a <= t0))
    }

    /// Moving threats known before take-off.
    pub fn known_moving_threats(&self) -> impl Iterator<Item = &MovingThreatSpec> {
        let t0 = self.start.time_s;
        self.moving_threats
            .iter()
            .filter(move |m| m.appears_at_s <= t0)
    }

    /// Whether the scenario only makes sense flown end to end (events or pop-ups after
    /// take-off), as the reference's `is_closed_loop`.
    pub fn is_closed_loop(&self) -> bool {
        let t0 = self.start.time_s;
        !self.events.is_empty()
            || self
                .threats
                .iter()
                .any(|t| t.appears_at_s.is_some_and(|a| a > t0))
            || self.moving_threats.iter().any(|m| m.appears_at_s > t0)
    }
}

/// Walks the TOML tree, naming every key it reads in its errors.
struct Reader<'a> {
    file: &'a str,
}

type Res<T> = Result<T, ScenarioError>;

fn join(ctx: &str, key: &str) -> String {
    if ctx.is_empty() {
        key.to_string()
    } else {
        format!("{ctx}.{key}")
    }
}

fn type_name(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a float",
        Value::Boolean(_) => "a boolean",
        Value::Datetime(_) => "a date-time",
        Value::Array(_) => "an array",
        Value::Table(_) => "a table",
    }
}

/// Bounds on a number.
#[derive(Clone, Copy)]
enum Sign {
    Any,
    Positive,
    NonNegative,
}

impl Reader<'_> {
    fn fail<T>(&self, key: impl Into<String>, problem: impl Into<String>) -> Res<T> {
        Err(ScenarioError {
            file: self.file.to_string(),
            key: key.into(),
            problem: problem.into(),
        })
    }

    /// Refuses keys of `t` that are not in `allowed`.
    fn only(&self, t: &Table, ctx: &str, allowed: &[&str]) -> Res<()> {
        match t.keys().find(|k| !allowed.contains(&k.as_str())) {
            Some(k) => self.fail(
                join(ctx, k),
                format!("unknown key (allowed here: {})", allowed.join(", ")),
            ),
            None => Ok(()),
        }
    }

    fn get<'t>(&self, t: &'t Table, ctx: &str, key: &str) -> Res<&'t Value> {
        match t.get(key) {
            Some(v) => Ok(v),
            None => self.fail(join(ctx, key), "missing"),
        }
    }

    fn table<'t>(&self, t: &'t Table, ctx: &str, key: &str) -> Res<&'t Table> {
        match self.get(t, ctx, key)? {
            Value::Table(inner) => Ok(inner),
            other => self.fail(
                join(ctx, key),
                format!("must be a table, got {}", type_name(other)),
            ),
        }
    }

    fn string(&self, t: &Table, ctx: &str, key: &str) -> Res<String> {
        match self.get(t, ctx, key)? {
            Value::String(s) if !s.trim().is_empty() => Ok(s.clone()),
            Value::String(_) => self.fail(join(ctx, key), "must not be empty"),
            other => self.fail(
                join(ctx, key),
                format!("must be a string, got {}", type_name(other)),
            ),
        }
    }

    fn value_number(&self, v: &Value, name: &str, sign: Sign) -> Res<f64> {
        let x = match v {
            Value::Float(f) => *f,
            Value::Integer(i) => *i as f64,
            other => return self.fail(name, format!("must be a number, got {}", type_name(other))),
        };
        if !x.is_finite() {
            return self.fail(name, format!("must be finite, got {x}"));
        }
        match sign {
            Sign::Positive if x <= 0.0 => self.fail(name, format!("must be positive, got {x}")),
            Sign::NonNegative if x < 0.0 => {
                self.fail(name, format!("must not be negative, got {x}"))
            }
            _ => Ok(x),
        }
    }

    fn number(&self, t: &Table, ctx: &str, key: &str, sign: Sign) -> Res<f64> {
        let v = self.get(t, ctx, key)?;
        self.value_number(v, &join(ctx, key), sign)
    }

    fn number_or(&self, t: &Table, ctx: &str, key: &str, default: f64, sign: Sign) -> Res<f64> {
        match t.get(key) {
            Some(v) => self.value_number(v, &join(ctx, key), sign),
            None => Ok(default),
        }
    }

    /// A list of exactly `n` numbers, zero-padded to 3.
    fn value_vector(&self, v: &Value, n: usize, name: &str, sign: Sign) -> Res<[f64; 3]> {
        let items = match v {
            Value::Array(a) if a.len() == n => a,
            Value::Array(a) => {
                return self.fail(
                    name,
                    format!("must be a list of {n} numbers, got {} items", a.len()),
                );
            }
            other => {
                return self.fail(
                    name,
                    format!("must be a list of {n} numbers, got {}", type_name(other)),
                );
            }
        };
        let mut out = [0.0; 3];
        for (slot, item) in out.iter_mut().zip(items) {
            *slot = self.value_number(item, name, sign)?;
        }
        Ok(out)
    }

    fn vector(&self, t: &Table, ctx: &str, key: &str, n: usize, sign: Sign) -> Res<[f64; 3]> {
        let v = self.get(t, ctx, key)?;
        self.value_vector(v, n, &join(ctx, key), sign)
    }

    /// A polyline of 2..=`max` points whose consecutive points differ horizontally.
    fn polyline(
        &self,
        t: &Table,
        ctx: &str,
        key: &str,
        dim: usize,
        max: usize,
    ) -> Res<Vec<[f64; 3]>> {
        let name = join(ctx, key);
        let items = match self.get(t, ctx, key)? {
            Value::Array(a) if (2..=max).contains(&a.len()) => a,
            Value::Array(a) => {
                return self.fail(
                    name,
                    format!("must be a list of 2 to {max} points, got {}", a.len()),
                );
            }
            other => {
                return self.fail(
                    name,
                    format!("must be a list of points, got {}", type_name(other)),
                );
            }
        };
        let points = items
            .iter()
            .map(|p| self.value_vector(p, dim, &name, Sign::Any))
            .collect::<Res<Vec<_>>>()?;
        if points
            .windows(2)
            .any(|w| w[0][0] == w[1][0] && w[0][1] == w[1][1])
        {
            return self.fail(name, "consecutive points must differ horizontally");
        }
        Ok(points)
    }

    fn tables<'t>(&self, t: &'t Table, key: &str) -> Res<Vec<&'t Table>> {
        match t.get(key) {
            None => Ok(Vec::new()),
            Some(Value::Array(items)) => items
                .iter()
                .enumerate()
                .map(|(i, v)| match v {
                    Value::Table(inner) => Ok(inner),
                    other => self.fail(
                        format!("{key}[{i}]"),
                        format!("must be a table, got {}", type_name(other)),
                    ),
                })
                .collect(),
            Some(other) => self.fail(
                key,
                format!("must be an array of tables, got {}", type_name(other)),
            ),
        }
    }

    fn above_floor(&self, name: &str, p: &[f64; 3], model: Model, v: &VehicleLimits) -> Res<()> {
        if model == Model::ThreeD && p[2] < v.altitude_min_m {
            return self.fail(
                name,
                format!(
                    "altitude {} m is under vehicle.altitude_min_m {} m",
                    p[2], v.altitude_min_m
                ),
            );
        }
        Ok(())
    }

    fn scenario(&self, root: &Table) -> Res<Scenario> {
        self.only(
            root,
            "",
            &[
                "name",
                "summary",
                "model",
                "objective",
                "vehicle",
                "weights",
                "start",
                "targets",
                "final",
                "lead",
                "threats",
                "moving_threats",
                "events",
            ],
        )?;
        let name = self.string(root, "", "name")?;
        let summary = match root.get("summary") {
            None => String::new(),
            Some(Value::String(s)) => s.clone(),
            Some(other) => {
                return self.fail(
                    "summary",
                    format!("must be a string, got {}", type_name(other)),
                );
            }
        };
        let model = match self.string(root, "", "model")?.as_str() {
            "2d" => Model::TwoD,
            "3d" => Model::ThreeD,
            other => return self.fail("model", format!("must be \"2d\" or \"3d\", got {other:?}")),
        };
        let objective = match self.string(root, "", "objective")?.as_str() {
            "fixed-time" => Objective::FixedTime,
            "min-time" => Objective::MinTime,
            "min-time-rendezvous" => Objective::MinTimeRendezvous,
            other => {
                return self.fail(
                    "objective",
                    format!(
                        "unknown objective {other:?} (expected \"fixed-time\", \"min-time\" or \
                         \"min-time-rendezvous\")"
                    ),
                );
            }
        };
        let dim = model.position_dim();
        let vehicle = self.vehicle(self.table(root, "", "vehicle")?, model)?;
        let weights = self.weights(self.table(root, "", "weights")?)?;
        let start = self.start(self.table(root, "", "start")?, model, &vehicle)?;

        let target_tables = self.tables(root, "targets")?;
        if target_tables.len() > MAX_TARGETS {
            return self.fail(
                "targets",
                format!("at most {MAX_TARGETS} targets, got {}", target_tables.len()),
            );
        }
        let mut targets = Vec::with_capacity(target_tables.len());
        for (i, t) in target_tables.iter().enumerate() {
            let ctx = format!("targets[{i}]");
            self.only(t, &ctx, &["position_m"])?;
            let p = self.vector(t, &ctx, "position_m", dim, Sign::Any)?;
            self.above_floor(&join(&ctx, "position_m"), &p, model, &vehicle)?;
            targets.push(p);
        }

        let (final_point, lead) = match objective {
            Objective::FixedTime | Objective::MinTime => {
                if root.contains_key("lead") {
                    return self.fail("lead", "only a min-time-rendezvous mission has a lead");
                }
                let f = self.table(root, "", "final")?;
                let fp = self.final_point(f, "final", model, objective, &vehicle, start.time_s)?;
                (Some(fp), None)
            }
            Objective::MinTimeRendezvous => {
                if root.contains_key("final") {
                    return self.fail(
                        "final",
                        "a min-time-rendezvous mission ends at the lead, not a final point",
                    );
                }
                let l = self.table(root, "", "lead")?;
                self.only(l, "lead", &["route_m", "speed_mps"])?;
                let lead = LeadSpec {
                    route_m: self.polyline(l, "lead", "route_m", dim, MAX_ROUTE_POINTS)?,
                    speed_mps: self.number(l, "lead", "speed_mps", Sign::Positive)?,
                };
                (None, Some(lead))
            }
        };

        let mut threats = Vec::new();
        for (i, t) in self.tables(root, "threats")?.iter().enumerate() {
            threats.push(self.static_threat(t, &format!("threats[{i}]"), dim)?);
        }
        let mut moving_threats = Vec::new();
        for (i, m) in self.tables(root, "moving_threats")?.iter().enumerate() {
            moving_threats.push(self.moving_threat(
                m,
                &format!("moving_threats[{i}]"),
                dim,
                start.time_s,
            )?);
        }
        let mut events = Vec::new();
        for (i, e) in self.tables(root, "events")?.iter().enumerate() {
            let ctx = format!("events[{i}]");
            let event = self.event(e, &ctx, model, objective, &vehicle, start.time_s)?;
            if events.last().is_some_and(|p: &Event| event.at_s < p.at_s) {
                return self.fail(join(&ctx, "at_s"), "events must be in time order");
            }
            events.push(event);
        }
        Ok(Scenario {
            name,
            summary,
            source: self.file.to_string(),
            model,
            objective,
            vehicle,
            weights,
            start,
            targets,
            final_point,
            lead,
            threats,
            moving_threats,
            events,
        })
    }

    fn vehicle(&self, v: &Table, model: Model) -> Res<VehicleLimits> {
        let ctx = "vehicle";
        let mut out = VehicleLimits {
            speed_mps: 0.0,
            turn_rate_max_rps: 0.0,
            gamma_max_rad: 0.0,
            nz_min: 0.0,
            nz_max: 0.0,
            bank_max_rad: 0.0,
            nz_rate_max_per_s: 0.0,
            bank_rate_max_rps: 0.0,
            altitude_min_m: 0.0,
        };
        match model {
            Model::TwoD => {
                self.only(v, ctx, &["speed_mps", "turn_rate_max_dps"])?;
                out.speed_mps = self.number(v, ctx, "speed_mps", Sign::Positive)?;
                out.turn_rate_max_rps =
                    self.number(v, ctx, "turn_rate_max_dps", Sign::Positive)? * DEG;
            }
            Model::ThreeD => {
                self.only(
                    v,
                    ctx,
                    &[
                        "speed_mps",
                        "gamma_max_deg",
                        "nz_min",
                        "nz_max",
                        "bank_max_deg",
                        "nz_rate_max_per_s",
                        "bank_rate_max_dps",
                        "altitude_min_m",
                    ],
                )?;
                out.speed_mps = self.number(v, ctx, "speed_mps", Sign::Positive)?;
                let gamma_max = self.number(v, ctx, "gamma_max_deg", Sign::Positive)?;
                if gamma_max >= 90.0 {
                    return self.fail(
                        "vehicle.gamma_max_deg",
                        format!("must be below 90, got {gamma_max}"),
                    );
                }
                out.gamma_max_rad = gamma_max * DEG;
                out.nz_min = self.number(v, ctx, "nz_min", Sign::Any)?;
                out.nz_max = self.number(v, ctx, "nz_max", Sign::Any)?;
                if !(out.nz_min < 1.0 && 1.0 < out.nz_max) {
                    return self.fail(
                        "vehicle.nz_min",
                        format!(
                            "level flight (Nz = 1) must lie strictly inside [nz_min, nz_max] = [{}, {}]",
                            out.nz_min, out.nz_max
                        ),
                    );
                }
                let bank_max = self.number(v, ctx, "bank_max_deg", Sign::Positive)?;
                if bank_max >= 90.0 {
                    return self.fail(
                        "vehicle.bank_max_deg",
                        format!("must be below 90, got {bank_max}"),
                    );
                }
                out.bank_max_rad = bank_max * DEG;
                out.nz_rate_max_per_s = self.number(v, ctx, "nz_rate_max_per_s", Sign::Positive)?;
                out.bank_rate_max_rps =
                    self.number(v, ctx, "bank_rate_max_dps", Sign::Positive)? * DEG;
                out.altitude_min_m = self.number(v, ctx, "altitude_min_m", Sign::Any)?;
            }
        }
        Ok(out)
    }

    fn weights(&self, w: &Table) -> Res<Weights> {
        let ctx = "weights";
        self.only(w, ctx, &["alpha", "beta", "stiffness"])?;
        let unit = |key: &str| -> Res<f64> {
            let x = self.number(w, ctx, key, Sign::Any)?;
            if !(0.0..=1.0).contains(&x) {
                return self.fail(join(ctx, key), format!("must be in [0, 1], got {x}"));
            }
            Ok(x)
        };
        Ok(Weights {
            alpha: unit("alpha")?,
            beta: unit("beta")?,
            stiffness: self.number(w, ctx, "stiffness", Sign::Positive)?,
        })
    }

    fn start(&self, s: &Table, model: Model, vehicle: &VehicleLimits) -> Res<Start> {
        let ctx = "start";
        let dim = model.position_dim();
        match model {
            Model::TwoD => self.only(s, ctx, &["time_s", "position_m", "heading_deg"])?,
            Model::ThreeD => self.only(
                s,
                ctx,
                &["time_s", "position_m", "heading_deg", "gamma_deg"],
            )?,
        }
        let position_m = self.vector(s, ctx, "position_m", dim, Sign::Any)?;
        self.above_floor("start.position_m", &position_m, model, vehicle)?;
        let gamma_rad = match model {
            Model::TwoD => 0.0,
            Model::ThreeD => self.gamma(s, ctx, vehicle)?,
        };
        Ok(Start {
            time_s: self.number(s, ctx, "time_s", Sign::Any)?,
            position_m,
            heading_rad: self.number(s, ctx, "heading_deg", Sign::Any)? * DEG,
            gamma_rad,
        })
    }

    /// Optional `gamma_deg` (default 0) within the vehicle's bound.
    fn gamma(&self, t: &Table, ctx: &str, vehicle: &VehicleLimits) -> Res<f64> {
        let g = self.number_or(t, ctx, "gamma_deg", 0.0, Sign::Any)? * DEG;
        if g.abs() > vehicle.gamma_max_rad + 1e-12 {
            return self.fail(join(ctx, "gamma_deg"), "exceeds vehicle.gamma_max_deg");
        }
        Ok(g)
    }

    fn final_point(
        &self,
        f: &Table,
        ctx: &str,
        model: Model,
        objective: Objective,
        vehicle: &VehicleLimits,
        t0: f64,
    ) -> Res<FinalPoint> {
        let dim = model.position_dim();
        match model {
            Model::TwoD => self.only(f, ctx, &["position_m", "heading_deg", "time_s"])?,
            Model::ThreeD => self.only(
                f,
                ctx,
                &[
                    "position_m",
                    "heading_deg",
                    "gamma_deg",
                    "nz",
                    "mu_deg",
                    "time_s",
                ],
            )?,
        }
        let position_m = self.vector(f, ctx, "position_m", dim, Sign::Any)?;
        self.above_floor(&join(ctx, "position_m"), &position_m, model, vehicle)?;
        let time_s = match objective {
            Objective::FixedTime => {
                let t = self.number(f, ctx, "time_s", Sign::Any)?;
                if t <= t0 {
                    return self.fail(
                        join(ctx, "time_s"),
                        format!("must be after start.time_s, got {t}"),
                    );
                }
                Some(t)
            }
            _ if f.contains_key("time_s") => {
                return self.fail(
                    join(ctx, "time_s"),
                    "only a fixed-time mission has a final time",
                );
            }
            _ => None,
        };
        let (gamma_rad, nz, mu_rad) = match model {
            Model::TwoD => (0.0, 0.0, 0.0),
            Model::ThreeD => {
                let nz = self.number_or(f, ctx, "nz", 1.0, Sign::Any)?;
                if !(vehicle.nz_min..=vehicle.nz_max).contains(&nz) {
                    return self.fail(join(ctx, "nz"), "outside [vehicle.nz_min, vehicle.nz_max]");
                }
                let mu = self.number_or(f, ctx, "mu_deg", 0.0, Sign::Any)? * DEG;
                if mu.abs() > vehicle.bank_max_rad {
                    return self.fail(join(ctx, "mu_deg"), "exceeds vehicle.bank_max_deg");
                }
                (self.gamma(f, ctx, vehicle)?, nz, mu)
            }
        };
        Ok(FinalPoint {
            position_m,
            heading_rad: self.number(f, ctx, "heading_deg", Sign::Any)? * DEG,
            gamma_rad,
            nz,
            mu_rad,
            time_s,
        })
    }

    fn static_threat(&self, t: &Table, ctx: &str, dim: usize) -> Res<StaticThreatSpec> {
        self.only(
            t,
            ctx,
            &[
                "name",
                "center_m",
                "axes_m",
                "exponents",
                "yaw_deg",
                "appears_at_s",
            ],
        )?;
        let exponents = match t.get("exponents") {
            Some(v) => self.value_vector(v, dim, &join(ctx, "exponents"), Sign::Positive)?,
            None if dim == 2 => [2.0, 2.0, 0.0],
            None => [2.0, 2.0, 2.0],
        };
        let appears_at_s = match t.get("appears_at_s") {
            Some(v) => Some(self.value_number(v, &join(ctx, "appears_at_s"), Sign::Any)?),
            None => None,
        };
        Ok(StaticThreatSpec {
            name: self.name_or(t, ctx, ctx)?,
            center_m: self.vector(t, ctx, "center_m", dim, Sign::Any)?,
            axes_m: self.vector(t, ctx, "axes_m", dim, Sign::Positive)?,
            exponents,
            yaw_rad: self.number_or(t, ctx, "yaw_deg", 0.0, Sign::Any)? * DEG,
            appears_at_s,
        })
    }

    fn name_or(&self, t: &Table, ctx: &str, default: &str) -> Res<String> {
        if t.contains_key("name") {
            self.string(t, ctx, "name")
        } else {
            Ok(default.to_string())
        }
    }

    fn moving_threat(&self, m: &Table, ctx: &str, dim: usize, t0: f64) -> Res<MovingThreatSpec> {
        self.only(
            m,
            ctx,
            &[
                "name",
                "road_m",
                "axes_m",
                "initial_distance_m",
                "initial_speed_mps",
                "accel_sigma_mps2",
                "accel_tau_s",
                "initial_sigma",
                "appears_at_s",
                "sensor",
                "truth",
            ],
        )?;
        let sensor_ctx = join(ctx, "sensor");
        let sensor = self.table(m, ctx, "sensor")?;
        self.only(sensor, &sensor_ctx, &["rate_hz", "sigma_m"])?;
        let truth_seed = match m.get("truth") {
            None => 0,
            Some(Value::Table(truth)) => {
                let truth_ctx = join(ctx, "truth");
                self.only(truth, &truth_ctx, &["seed"])?;
                match self.get(truth, &truth_ctx, "seed")? {
                    Value::Integer(s) if *s >= 0 => *s as u64,
                    other => {
                        return self.fail(
                            join(&truth_ctx, "seed"),
                            format!("must be a non-negative integer, got {other}"),
                        );
                    }
                }
            }
            Some(other) => {
                return self.fail(
                    join(ctx, "truth"),
                    format!("must be a table, got {}", type_name(other)),
                );
            }
        };
        let appears_at_s = self.number_or(m, ctx, "appears_at_s", t0, Sign::Any)?;
        if appears_at_s < t0 {
            return self.fail(join(ctx, "appears_at_s"), "must not be before start.time_s");
        }
        Ok(MovingThreatSpec {
            name: self.name_or(m, ctx, ctx)?,
            road_m: self.polyline(m, ctx, "road_m", dim, MAX_ROAD_POINTS)?,
            axes_m: self.vector(m, ctx, "axes_m", dim, Sign::Positive)?,
            initial_distance_m: self.number(m, ctx, "initial_distance_m", Sign::Any)?,
            initial_speed_mps: self.number(m, ctx, "initial_speed_mps", Sign::Any)?,
            accel_sigma_mps2: self.number(m, ctx, "accel_sigma_mps2", Sign::NonNegative)?,
            accel_tau_s: self.number(m, ctx, "accel_tau_s", Sign::Positive)?,
            initial_sigma: self.vector(m, ctx, "initial_sigma", 3, Sign::NonNegative)?,
            appears_at_s,
            sensor: SensorSpec {
                rate_hz: self.number(sensor, &sensor_ctx, "rate_hz", Sign::Positive)?,
                sigma_m: self.number(sensor, &sensor_ctx, "sigma_m", Sign::Positive)?,
            },
            truth_seed,
        })
    }

    fn event(
        &self,
        e: &Table,
        ctx: &str,
        model: Model,
        objective: Objective,
        vehicle: &VehicleLimits,
        t0: f64,
    ) -> Res<Event> {
        let dim = model.position_dim();
        let at_s = self.number(e, ctx, "at_s", Sign::Any)?;
        if at_s < t0 {
            return self.fail(join(ctx, "at_s"), "must not be before start.time_s");
        }
        let kind = match self.string(e, ctx, "kind")?.as_str() {
            "lead-route" => {
                self.only(e, ctx, &["at_s", "kind", "route_m", "speed_mps"])?;
                if objective != Objective::MinTimeRendezvous {
                    return self.fail(
                        join(ctx, "kind"),
                        "a lead-route event needs a min-time-rendezvous mission",
                    );
                }
                EventKind::LeadRoute {
                    route_m: self.polyline(e, ctx, "route_m", dim, MAX_ROUTE_POINTS)?,
                    speed_mps: self.number(e, ctx, "speed_mps", Sign::Positive)?,
                }
            }
            "targets" => {
                self.only(e, ctx, &["at_s", "kind", "targets_m"])?;
                let name = join(ctx, "targets_m");
                let items = match self.get(e, ctx, "targets_m")? {
                    Value::Array(a) if a.len() <= MAX_TARGETS => a,
                    Value::Array(a) => {
                        return self.fail(
                            name,
                            format!("at most {MAX_TARGETS} targets, got {}", a.len()),
                        );
                    }
                    other => {
                        return self.fail(
                            name,
                            format!("must be a list of points, got {}", type_name(other)),
                        );
                    }
                };
                let mut targets_m = Vec::with_capacity(items.len());
                for item in items {
                    let p = self.value_vector(item, dim, &name, Sign::Any)?;
                    self.above_floor(&name, &p, model, vehicle)?;
                    targets_m.push(p);
                }
                EventKind::Targets { targets_m }
            }
            "final" => {
                if objective == Objective::MinTimeRendezvous {
                    return self.fail(join(ctx, "kind"), "a rendezvous mission has no final point");
                }
                let mut point = e.clone();
                point.remove("at_s");
                point.remove("kind");
                EventKind::Final(self.final_point(&point, ctx, model, objective, vehicle, at_s)?)
            }
            other => {
                return self.fail(
                    join(ctx, "kind"),
                    format!(
                        "unknown kind {other:?} (expected \"lead-route\", \"targets\" or \"final\")"
                    ),
                );
            }
        };
        Ok(Event { at_s, kind })
    }
}

impl fmt::Display for Scenario {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let model = match self.model {
            Model::TwoD => "2d",
            Model::ThreeD => "3d",
        };
        let objective = match self.objective {
            Objective::FixedTime => "fixed-time",
            Objective::MinTime => "min-time",
            Objective::MinTimeRendezvous => "min-time-rendezvous",
        };
        write!(
            f,
            "{} ({model}, {objective}): {} target(s), {} static threat(s), {} moving threat(s), {} event(s)",
            self.name,
            self.targets.len(),
            self.threats.len(),
            self.moving_threats.len(),
            self.events.len()
        )
    }
}

macro_rules! bundled {
    ($name:literal) => {
        (
            $name,
            include_str!(concat!("../../../scenarios/", $name, ".toml")),
        )
    };
}

/// The canonical scenarios shipped with the project (`scenarios/*.toml`), by name.
pub const BUNDLED: &[(&str, &str)] = &[
    bundled!("2d-fixed-time-avoidable"),
    bundled!("2d-fixed-time-unavoidable"),
    bundled!("2d-min-time-avoidable"),
    bundled!("2d-min-time-rendezvous-avoidable"),
    bundled!("2d-min-time-rendezvous-unavoidable"),
    bundled!("2d-min-time-unavoidable"),
    bundled!("3d-fixed-time-avoidable"),
    bundled!("3d-fixed-time-unavoidable"),
    bundled!("3d-min-time-avoidable"),
    bundled!("3d-min-time-moving-threat"),
    bundled!("3d-min-time-rendezvous-avoidable"),
    bundled!("3d-min-time-rendezvous-unavoidable"),
    bundled!("3d-min-time-unavoidable"),
    bundled!("3d-rendezvous-moving-threat"),
    bundled!("3d-replan-popups"),
];

/// A bundled scenario by name.
pub fn bundled(name: &str) -> Option<Result<Scenario, ScenarioError>> {
    BUNDLED
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(n, text)| Scenario::parse(text, &format!("scenarios/{n}.toml (bundled)")))
}

/// Loads `arg` as a file path if it names a file, else as a bundled scenario's name.
pub fn load_by_path_or_name(arg: &str) -> Result<Scenario, ScenarioError> {
    let path = Path::new(arg);
    if path.exists() || arg.ends_with(".toml") {
        return Scenario::load(path);
    }
    bundled(arg).unwrap_or_else(|| {
        Err(ScenarioError {
            file: arg.to_string(),
            key: "(file)".into(),
            problem: format!(
                "no such file, and no bundled scenario of that name (bundled: {})",
                BUNDLED
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })
    })
}
