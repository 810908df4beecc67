//! The scenario's sections read into their types: the vehicle, the weights, the start,
//! the end, the threats and the events, each checked against its neighbours.

use toml::{Table, Value};
use wingman_interfaces::{
    MAX_ROAD_POINTS, MAX_ROUTE_POINTS, MAX_TARGETS, Model, Objective, VehicleLimits, Weights,
};

use super::reader::{DEG, Reader, Res, Sign, join, type_name};
use super::types::{
    Event, EventKind, FinalPoint, LeadSpec, MovingThreatSpec, Scenario, SensorSpec, Start,
    StaticThreatSpec,
};

impl Reader<'_> {
    pub(super) fn scenario(&self, root: &Table) -> Res<Scenario> {
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
                "wind",
                "aircraft",
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

        let threats = self.static_threats(root, dim)?;
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
        let (wind, aircraft) = self.disturbances(root, model, &vehicle)?;
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
            wind,
            aircraft,
        })
    }

    /// `[[threats]]`: at most what the planner holds.
    fn static_threats(&self, root: &Table, dim: usize) -> Res<Vec<StaticThreatSpec>> {
        let mut threats = Vec::new();
        let tables = self.tables(root, "threats")?;
        if tables.len() > crate::threat::MAX_THREATS {
            // A planner holds at most this many static threats (pop-ups included): more
            // would fail the take-off plan or be dropped in flight.
            return self.fail(
                "threats",
                format!(
                    "{} static threats, more than the planner holds ({})",
                    tables.len(),
                    crate::threat::MAX_THREATS
                ),
            );
        }
        for (i, t) in tables.iter().enumerate() {
            threats.push(self.static_threat(t, &format!("threats[{i}]"), dim)?);
        }
        Ok(threats)
    }

    pub(super) fn vehicle(&self, v: &Table, model: Model) -> Res<VehicleLimits> {
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

    pub(super) fn weights(&self, w: &Table) -> Res<Weights> {
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

    pub(super) fn start(&self, s: &Table, model: Model, vehicle: &VehicleLimits) -> Res<Start> {
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
    pub(super) fn gamma(&self, t: &Table, ctx: &str, vehicle: &VehicleLimits) -> Res<f64> {
        let g = self.number_or(t, ctx, "gamma_deg", 0.0, Sign::Any)? * DEG;
        if g.abs() > vehicle.gamma_max_rad + 1e-12 {
            return self.fail(join(ctx, "gamma_deg"), "exceeds vehicle.gamma_max_deg");
        }
        Ok(g)
    }

    pub(super) fn final_point(
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

    pub(super) fn static_threat(&self, t: &Table, ctx: &str, dim: usize) -> Res<StaticThreatSpec> {
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

    pub(super) fn name_or(&self, t: &Table, ctx: &str, default: &str) -> Res<String> {
        if t.contains_key("name") {
            self.string(t, ctx, "name")
        } else {
            Ok(default.to_string())
        }
    }

    pub(super) fn moving_threat(
        &self,
        m: &Table,
        ctx: &str,
        dim: usize,
        t0: f64,
    ) -> Res<MovingThreatSpec> {
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
                self.seed(truth, &truth_ctx, "seed")?
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

    pub(super) fn event(
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
            kind @ ("lead-route" | "lead-off-route") => {
                self.only(e, ctx, &["at_s", "kind", "route_m", "speed_mps"])?;
                if objective != Objective::MinTimeRendezvous {
                    return self.fail(
                        join(ctx, "kind"),
                        format!("a {kind} event needs a min-time-rendezvous mission"),
                    );
                }
                let route_m = self.polyline(e, ctx, "route_m", dim, MAX_ROUTE_POINTS)?;
                let speed_mps = self.number(e, ctx, "speed_mps", Sign::Positive)?;
                if kind == "lead-route" {
                    EventKind::LeadRoute { route_m, speed_mps }
                } else {
                    EventKind::LeadOffRoute { route_m, speed_mps }
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
                        "unknown kind {other:?} (expected \"lead-route\", \"lead-off-route\", \
                         \"targets\" or \"final\")"
                    ),
                );
            }
        };
        Ok(Event { at_s, kind })
    }
}
