//! Walking the TOML tree: key checks, typed values with their bounds, and the
//! conversion of degrees to radians; every error names the file and the key.

use toml::{Table, Value};
use wingman_interfaces::{Model, VehicleLimits};

use super::error::ScenarioError;

pub(super) const DEG: f64 = std::f64::consts::PI / 180.0;

/// Walks the TOML tree, naming every key it reads in its errors.
pub(super) struct Reader<'a> {
    pub(super) file: &'a str,
}

pub(super) type Res<T> = Result<T, ScenarioError>;

pub(super) fn join(ctx: &str, key: &str) -> String {
    if ctx.is_empty() {
        key.to_string()
    } else {
        format!("{ctx}.{key}")
    }
}

pub(super) fn type_name(v: &Value) -> &'static str {
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
pub(super) enum Sign {
    Any,
    Positive,
    NonNegative,
}

impl Reader<'_> {
    pub(super) fn fail<T>(&self, key: impl Into<String>, problem: impl Into<String>) -> Res<T> {
        Err(ScenarioError {
            file: self.file.to_string(),
            key: key.into(),
            problem: problem.into(),
        })
    }

    /// Refuses keys of `t` that are not in `allowed`.
    pub(super) fn only(&self, t: &Table, ctx: &str, allowed: &[&str]) -> Res<()> {
        match t.keys().find(|k| !allowed.contains(&k.as_str())) {
            Some(k) => self.fail(
                join(ctx, k),
                format!("unknown key (allowed here: {})", allowed.join(", ")),
            ),
            None => Ok(()),
        }
    }

    pub(super) fn get<'t>(&self, t: &'t Table, ctx: &str, key: &str) -> Res<&'t Value> {
        match t.get(key) {
            Some(v) => Ok(v),
            None => self.fail(join(ctx, key), "missing"),
        }
    }

    pub(super) fn table<'t>(&self, t: &'t Table, ctx: &str, key: &str) -> Res<&'t Table> {
        match self.get(t, ctx, key)? {
            Value::Table(inner) => Ok(inner),
            other => self.fail(
                join(ctx, key),
                format!("must be a table, got {}", type_name(other)),
            ),
        }
    }

    pub(super) fn string(&self, t: &Table, ctx: &str, key: &str) -> Res<String> {
        match self.get(t, ctx, key)? {
            Value::String(s) if !s.trim().is_empty() => Ok(s.clone()),
            Value::String(_) => self.fail(join(ctx, key), "must not be empty"),
            other => self.fail(
                join(ctx, key),
                format!("must be a string, got {}", type_name(other)),
            ),
        }
    }

    pub(super) fn value_number(&self, v: &Value, name: &str, sign: Sign) -> Res<f64> {
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

    pub(super) fn number(&self, t: &Table, ctx: &str, key: &str, sign: Sign) -> Res<f64> {
        let v = self.get(t, ctx, key)?;
        self.value_number(v, &join(ctx, key), sign)
    }

    pub(super) fn number_or(
        &self,
        t: &Table,
        ctx: &str,
        key: &str,
        default: f64,
        sign: Sign,
    ) -> Res<f64> {
        match t.get(key) {
            Some(v) => self.value_number(v, &join(ctx, key), sign),
            None => Ok(default),
        }
    }

    /// A non-negative integer seed `t[key]`.
    pub(super) fn seed(&self, t: &Table, ctx: &str, key: &str) -> Res<u64> {
        match self.get(t, ctx, key)? {
            Value::Integer(s) if *s >= 0 => Ok(*s as u64),
            other => self.fail(
                join(ctx, key),
                format!("must be a non-negative integer, got {other}"),
            ),
        }
    }

    /// [`Reader::seed`], or `default` when `t` has no `key`.
    pub(super) fn seed_or(&self, t: &Table, ctx: &str, key: &str, default: u64) -> Res<u64> {
        if t.contains_key(key) {
            self.seed(t, ctx, key)
        } else {
            Ok(default)
        }
    }

    /// A list of exactly `n` numbers, zero-padded to 3.
    pub(super) fn value_vector(
        &self,
        v: &Value,
        n: usize,
        name: &str,
        sign: Sign,
    ) -> Res<[f64; 3]> {
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

    pub(super) fn vector(
        &self,
        t: &Table,
        ctx: &str,
        key: &str,
        n: usize,
        sign: Sign,
    ) -> Res<[f64; 3]> {
        let v = self.get(t, ctx, key)?;
        self.value_vector(v, n, &join(ctx, key), sign)
    }

    /// A polyline of 2..=`max` points whose consecutive points differ horizontally.
    pub(super) fn polyline(
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

    pub(super) fn tables<'t>(&self, t: &'t Table, key: &str) -> Res<Vec<&'t Table>> {
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

    pub(super) fn above_floor(
        &self,
        name: &str,
        p: &[f64; 3],
        model: Model,
        v: &VehicleLimits,
    ) -> Res<()> {
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
}
