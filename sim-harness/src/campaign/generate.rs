//! Random well-posed missions in the scenario file format, one per index of a campaign,
//! each from its own stream (the campaign's seed and the index), so any slice of a
//! campaign draws the same missions as the whole.
//!
//! A mission is drawn in the order of its file: the kind (model, objective, how many
//! targets and threats, which features), the vehicle, the start, the targets, the final
//! point or the lead (and its change of route), the defended threat of an unavoidable
//! layout, the pop-ups (before the static threats fill the room near the legs), the
//! static threats, the moving threats, the final time, then the wind (drawn last, so that
//! a mission without one is the same as before the wind was drawn).
//! Well-posed means:
//! - threats keep clear of the start, the targets and the end by two turn radii, and of
//!   the lead's routes where a rendezvous may happen;
//! - the static threats and pop-ups keep a gap of 1.5 turn radii between their discs
//!   (see [`super::layout`]): a path outside every threat exists; in an unavoidable layout
//!   one target sits inside a defended threat, and only that threat must be crossed;
//! - at most 16 static threats, pop-ups included (what the planner holds);
//! - a pop-up appears where the aircraft cannot be yet (farther from the start than it can
//!   fly by then, with 15 km to spare);
//! - a moving threat's road keeps clear of the targets and the end;
//! - a fixed final time leaves 10–30 % over the length of a path that avoids every threat
//!   ([`super::layout::avoiding_length`]);
//! - the lead is slower than the wingman;
//! - a wind is 3–8 % of the airspeed, and a fixed final time is sized at the airspeed
//!   less the wind, so that a headwind still leaves the slack.

use std::f64::consts::PI;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use wingman_planning::threat::MAX_THREATS;

use super::kind::{Feature, Filter, MissionKind};

mod scenario_file;
use super::layout::{Footprint, along, avoiding_length, dist, segment_dist, xy};

/// One drawn mission.
#[derive(Debug, Clone)]
pub struct Drawn {
    pub index: usize,
    /// The scenario's name (and its file's stem).
    pub name: String,
    pub kind: MissionKind,
    /// The scenario file.
    pub text: String,
}

/// Longest the placement of one kind of threat tries before it gives up on the rest.
const TRIES: usize = 2000;

/// Draws of one mission before it gives up on a feature the filter requires.
const ATTEMPTS: u64 = 64;

/// Mission `index` of the campaign drawn from `seed` under `filter`. A feature the filter
/// requires that the layout had no room for (a pop-up, a moving threat, a defended
/// threat) is drawn again from a stream derived from the first, up to [`ATTEMPTS`] times.
pub fn draw(seed: u64, index: usize, filter: &Filter) -> Drawn {
    let mut drawn = draw_once(seed, index, 0, filter);
    for attempt in 1..ATTEMPTS {
        if filter.with.iter().all(|f| drawn.kind.has(*f)) {
            break;
        }
        drawn = draw_once(seed, index, attempt, filter);
    }
    drawn
}

/// One draw of mission `index`: attempt 0 from the mission's own stream, later attempts
/// from streams derived from it.
fn draw_once(seed: u64, index: usize, attempt: u64, filter: &Filter) -> Drawn {
    let stream = seed
        .wrapping_mul(0x9e37_79b9_7f4a_7c15)
        .wrapping_add(index as u64);
    let mut rng = ChaCha8Rng::seed_from_u64(if attempt == 0 {
        stream
    } else {
        stream ^ attempt.wrapping_mul(0xd6e8_feb8_6659_fd93)
    });
    let mut m = Mission::draw_kind(&mut rng, filter);
    m.draw_route(&mut rng);
    if m.unavoidable {
        m.draw_defended(&mut rng);
    }
    m.draw_popups(&mut rng);
    m.draw_threats(&mut rng);
    m.draw_moving(&mut rng);
    m.draw_final_time(&mut rng);
    m.draw_wind(&mut rng, filter);
    let kind = m.kind();
    let name = format!(
        "c{seed}-{index:04}-{}-{}",
        kind.model,
        kind.objective.replace("min-time-rendezvous", "rendezvous")
    );
    let text = m.to_toml(
        &name,
        &format!("campaign {seed}, mission {index}: {}", kind.describe()),
    );
    Drawn {
        index,
        name,
        kind,
        text,
    }
}

/// A static threat or pop-up.
#[derive(Debug, Clone)]
struct StaticThreat {
    footprint: Footprint,
    /// 3-D: its height and vertical exponent.
    height: f64,
    appears_at_s: Option<f64>,
}

/// A threat on a straight road.
#[derive(Debug, Clone)]
struct MovingThreat {
    road: [[f64; 2]; 2],
    axes: [f64; 3],
    initial_distance: f64,
    initial_speed: f64,
    accel_sigma: f64,
    appears_at_s: f64,
    sensor_sigma: f64,
    truth_seed: u64,
}

/// The wind of a windy mission and the aircraft the harness flies in it.
#[derive(Debug, Clone)]
struct Wind {
    mean: [f64; 2],
    /// `"none"` or `"light"`.
    gusts: &'static str,
    seed: u32,
    response_s: f64,
    nav_sigma_m: f64,
    nav_heading_sigma_deg: f64,
    aircraft_seed: u32,
}

/// A mission as it is drawn.
#[derive(Debug, Clone)]
struct Mission {
    three_d: bool,
    objective: &'static str,
    n_targets: usize,
    n_threats: usize,
    n_popups: usize,
    n_moving: usize,
    unavoidable: bool,
    lead_change: bool,
    speed: f64,
    turn_radius: f64,
    start: [f64; 3],
    heading_deg: f64,
    targets: Vec<[f64; 3]>,
    /// Fixed-time and min-time: position and heading.
    final_point: Option<([f64; 3], f64)>,
    final_time: Option<f64>,
    /// A fixed final time's length to fly: the avoiding path's, with its slack.
    time_length: Option<f64>,
    lead_speed: f64,
    /// The lead's change of route: when, the new heading (rad) and speed.
    lead_turn: Option<(f64, f64, f64)>,
    threats: Vec<StaticThreat>,
    popups: Vec<StaticThreat>,
    moving: Vec<MovingThreat>,
    wind: Option<Wind>,
}

impl Mission {
    /// The kind and the vehicle.
    fn draw_kind(rng: &mut ChaCha8Rng, filter: &Filter) -> Mission {
        let models = filter.models();
        let objectives = filter.objectives();
        let three_d = models[rng.random_range(0..models.len())] == "3d";
        let objective = objectives[rng.random_range(0..objectives.len())];
        let rendezvous = objective == "min-time-rendezvous";
        let n_targets = rng.random_range(1..=4usize);
        let n_threats = rng.random_range(3..=16usize);
        let mut feature = |f: Feature, p: f64| rng.random::<f64>() < filter.chance(f, p);
        let unavoidable = feature(Feature::Unavoidable, 0.25);
        let moving = feature(Feature::Moving, 0.3);
        let popups = feature(Feature::Popups, 0.3);
        let lead_change = feature(Feature::LeadChange, 0.5) && rendezvous;
        let n_moving = if moving {
            rng.random_range(1..=2usize)
        } else {
            0
        };
        let n_popups = if popups {
            rng.random_range(1..=2usize)
        } else {
            0
        };
        let (speed, turn_radius) = if three_d {
            let v: f64 = rng.random_range(200.0..260.0);
            (v, v * v / (9.81 * 70f64.to_radians().tan()))
        } else {
            let v: f64 = rng.random_range(150.0..220.0);
            (v, v / 5f64.to_radians())
        };
        Mission {
            three_d,
            objective,
            n_targets,
            n_threats,
            n_popups,
            n_moving,
            unavoidable,
            lead_change,
            speed,
            turn_radius,
            start: [0.0; 3],
            heading_deg: 0.0,
            targets: Vec::new(),
            final_point: None,
            final_time: None,
            time_length: None,
            lead_speed: 0.0,
            lead_turn: None,
            threats: Vec::new(),
            popups: Vec::new(),
            moving: Vec::new(),
            wind: None,
        }
    }

    /// The start, the targets (each 40–80 km on from the last, turning at most about 60°
    /// and heading on along +x), and the final point (40–70 km on) or the lead.
    fn draw_route(&mut self, rng: &mut ChaCha8Rng) {
        let altitude = |rng: &mut ChaCha8Rng, lo: f64| -> f64 { rng.random_range(lo..12000.0) };
        self.start[2] = if self.three_d {
            altitude(rng, 8000.0)
        } else {
            0.0
        };
        self.heading_deg = rng.random_range(-30.0..30.0);
        let mut p = self.start;
        let mut dir: f64 = rng.random_range(-0.9..0.9);
        for k in 0..self.n_targets {
            if k > 0 {
                dir = (dir + rng.random_range(-1.0..1.0)).clamp(-1.3, 1.3);
            }
            let r: f64 = rng.random_range(40_000.0..80_000.0);
            p = [p[0] + r * dir.cos(), p[1] + r * dir.sin(), 0.0];
            if self.three_d {
                p[2] = altitude(rng, 2000.0);
            }
            self.targets.push(p);
        }
        if self.objective == "min-time-rendezvous" {
            self.lead_speed = self.speed * rng.random_range(0.6..0.8);
            if self.lead_change {
                let at: f64 = rng.random_range(60.0..240.0);
                let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
                let turn: f64 = sign * rng.random_range(10.0f64..35.0).to_radians();
                let speed = (self.lead_speed * rng.random_range(0.9..1.1)).min(0.85 * self.speed);
                self.lead_turn = Some((at, turn, speed));
            }
        } else {
            let a: f64 = rng.random_range(-0.9..0.9);
            let r: f64 = rng.random_range(40_000.0..70_000.0);
            let mut f = [p[0] + r * a.cos(), p[1] + r * a.sin(), 0.0];
            if self.three_d {
                f[2] = altitude(rng, 3000.0);
            }
            self.final_point = Some((f, rng.random_range(-60.0..60.0)));
        }
    }

    /// The points a threat must keep a few turn radii from: the start, the targets, the
    /// final point.
    fn turn_points(&self) -> Vec<[f64; 2]> {
        let mut pts = vec![xy(&self.start)];
        pts.extend(self.targets.iter().map(xy));
        if let Some((f, _)) = &self.final_point {
            pts.push(xy(f));
        }
        pts
    }

    /// Where a rendezvous may happen: the lead's routes every 5 km, from the start to
    /// 150 km past the farthest target.
    fn route_points(&self) -> Vec<[f64; 2]> {
        if self.objective != "min-time-rendezvous" {
            return Vec::new();
        }
        let far = self.targets.iter().map(|t| t[0]).fold(0.0, f64::max) + 150_000.0;
        let mut pts = Vec::new();
        let mut x = 0.0;
        while x <= far {
            pts.push([x, 0.0]);
            x += 5000.0;
        }
        if let Some((at, turn, _)) = self.lead_turn {
            let from = [self.lead_speed * at, 0.0];
            let mut s = 0.0;
            while s <= far {
                pts.push([from[0] + s * turn.cos(), from[1] + s * turn.sin()]);
                s += 5000.0;
            }
        }
        pts
    }

    /// The legs the threats are placed along: start, targets, then the final point or a
    /// point on the lead's route 40 km past the last target.
    fn legs(&self) -> Vec<[f64; 3]> {
        let mut legs = vec![self.start];
        legs.extend(self.targets.iter().copied());
        match &self.final_point {
            Some((f, _)) => legs.push(*f),
            None => {
                let last = self.targets.last().copied().unwrap_or(self.start);
                legs.push([last[0] + 40_000.0, 0.0, self.start[2]]);
            }
        }
        legs
    }

    /// Whether `fp` keeps clear of the turn points (two turn radii and 2 km) and the
    /// lead's routes (5 km).
    fn clear(&self, fp: &Footprint, skip_target: Option<usize>) -> bool {
        let margin = 2.0 * self.turn_radius + 2000.0;
        let turns = self.turn_points();
        let skipped = skip_target.map(|k| xy(&self.targets[k]));
        turns
            .iter()
            .filter(|p| Some(**p) != skipped)
            .all(|p| fp.clear_of(*p, margin))
            && self.route_points().iter().all(|p| fp.clear_of(*p, 5000.0))
    }

    /// Whether `fp` keeps the avoidable gap (one and a half turn radii and 1.5 km) from
    /// every static threat and pop-up placed so far.
    fn apart(&self, fp: &Footprint) -> bool {
        let gap = 1.5 * self.turn_radius + 1500.0;
        self.threats
            .iter()
            .chain(&self.popups)
            .all(|t| t.footprint.apart(fp, gap))
    }

    /// The defended threat of an unavoidable layout: a target inside it (its centre within
    /// 30 % of the smaller axis from the target; in 3-D at least 30 % taller than the
    /// target's altitude), clear of the other points.
    fn draw_defended(&mut self, rng: &mut ChaCha8Rng) {
        for _ in 0..TRIES {
            let k = rng.random_range(0..self.targets.len());
            let t = self.targets[k];
            let axes: [f64; 2] = [
                rng.random_range(6000.0..14000.0),
                rng.random_range(6000.0..14000.0),
            ];
            let r = 0.3 * axes[0].min(axes[1]) * rng.random::<f64>();
            let a: f64 = rng.random_range(0.0..2.0 * PI);
            let fp = Footprint {
                center: [t[0] + r * a.cos(), t[1] + r * a.sin()],
                axes,
                exponent: 2.0,
                yaw_deg: rng.random_range(0.0..180.0),
            };
            let height = (1.3 * t[2]).max(6000.0) + rng.random_range(0.0..5000.0);
            if self.clear(&fp, Some(k)) {
                self.threats.push(StaticThreat {
                    footprint: fp,
                    height,
                    appears_at_s: None,
                });
                return;
            }
        }
        self.unavoidable = false;
    }

    /// A threat's footprint near a leg: 10–90 % along it, up to 15 km to either side, axes
    /// 2.5–8 km, mostly ellipses, some closer to rectangles.
    fn draw_footprint(&self, rng: &mut ChaCha8Rng, legs: &[[f64; 3]]) -> (Footprint, f64) {
        let leg = rng.random_range(0..legs.len() - 1);
        let center = along(
            xy(&legs[leg]),
            xy(&legs[leg + 1]),
            rng.random_range(0.1..0.9),
            rng.random_range(-15_000.0..15_000.0),
        );
        let shape: f64 = rng.random();
        let fp = Footprint {
            center,
            axes: [
                rng.random_range(2500.0..8000.0),
                rng.random_range(2500.0..8000.0),
            ],
            exponent: if shape < 0.7 {
                2.0
            } else if shape < 0.9 {
                4.0
            } else {
                8.0
            },
            yaw_deg: rng.random_range(0.0..180.0),
        };
        (fp, rng.random_range(4000.0..15000.0))
    }

    /// The static threats known before take-off, near the legs, clear and apart.
    fn draw_threats(&mut self, rng: &mut ChaCha8Rng) {
        let legs = self.legs();
        // The planner holds MAX_THREATS static threats, the defended one and the pop-ups
        // included.
        let room = MAX_THREATS.saturating_sub(self.popups.len());
        let wanted = (self.threats.len() + self.n_threats).min(room);
        for _ in 0..TRIES {
            if self.threats.len() >= wanted {
                break;
            }
            let (fp, height) = self.draw_footprint(rng, &legs);
            if self.clear(&fp, None) && self.apart(&fp) {
                self.threats.push(StaticThreat {
                    footprint: fp,
                    height,
                    appears_at_s: None,
                });
            }
        }
    }

    /// The pop-ups: as the static threats, appearing at 20–150 s (earlier when the
    /// aircraft could be there by then) where the aircraft cannot be yet.
    fn draw_popups(&mut self, rng: &mut ChaCha8Rng) {
        let legs = self.legs();
        for _ in 0..TRIES {
            if self.popups.len() >= self.n_popups {
                break;
            }
            let (fp, height) = self.draw_footprint(rng, &legs);
            // Appearing at 20–150 s, but no later than the aircraft could reach it.
            let latest = (dist(fp.center, xy(&self.start)) - fp.radius() - 15_000.0) / self.speed;
            let at = rng.random_range(20.0..150.0f64).min(latest);
            if at >= 20.0 && self.clear(&fp, None) && self.apart(&fp) {
                self.popups.push(StaticThreat {
                    footprint: fp,
                    height,
                    appears_at_s: Some((at * 10.0).round() / 10.0),
                });
            }
        }
    }

    /// The moving threats: each on a 120 km road across a leg, starting within 30 km of
    /// the crossing, the road clear of the targets and the end.
    fn draw_moving(&mut self, rng: &mut ChaCha8Rng) {
        let legs = self.legs();
        for _ in 0..TRIES {
            if self.moving.len() >= self.n_moving {
                break;
            }
            let leg = rng.random_range(0..legs.len() - 1);
            let (a, b) = (xy(&legs[leg]), xy(&legs[leg + 1]));
            let cross = along(a, b, rng.random_range(0.3..0.7), 0.0);
            let dir = (b[1] - a[1]).atan2(b[0] - a[0]) + PI / 2.0 + rng.random_range(-0.5..0.5);
            let half = 60_000.0;
            let road = [
                [cross[0] - half * dir.cos(), cross[1] - half * dir.sin()],
                [cross[0] + half * dir.cos(), cross[1] + half * dir.sin()],
            ];
            let axes = [
                rng.random_range(3000.0..6000.0),
                rng.random_range(3000.0..6000.0),
                rng.random_range(5000.0..12000.0),
            ];
            let m = MovingThreat {
                road,
                axes,
                initial_distance: rng.random_range(30_000.0..90_000.0),
                initial_speed: rng.random_range(5.0..20.0),
                accel_sigma: rng.random_range(0.2..0.5),
                appears_at_s: if rng.random::<bool>() {
                    0.0
                } else {
                    (rng.random_range(30.0f64..120.0) * 10.0).round() / 10.0
                },
                sensor_sigma: rng.random_range(100.0..300.0),
                truth_seed: rng.random_range(1..1_000_000u64),
            };
            let clearance = axes[0].max(axes[1]) + 3.0 * self.turn_radius + 8000.0;
            let turns = self.turn_points();
            if turns[1..]
                .iter()
                .all(|p| segment_dist(road[0], road[1], *p) >= clearance)
            {
                self.moving.push(m);
            }
        }
    }

    /// A fixed final time 10–30 % over an avoiding path's length at the vehicle's speed.
    fn draw_final_time(&mut self, rng: &mut ChaCha8Rng) {
        if self.objective != "fixed-time" {
            return;
        }
        let mut discs: Vec<([f64; 2], f64)> = self
            .threats
            .iter()
            .chain(&self.popups)
            .map(|t| (t.footprint.center, t.footprint.radius()))
            .collect();
        discs.extend(self.moving.iter().map(|m| {
            (
                along(m.road[0], m.road[1], 0.5, 0.0),
                m.axes[0].max(m.axes[1]),
            )
        }));
        let length = avoiding_length(&self.legs(), &discs, self.turn_radius);
        let slack: f64 = rng.random_range(1.1..1.3);
        self.time_length = Some(slack * length);
        self.final_time = Some((slack * length / self.speed).round());
    }

    /// Three missions in ten fly in a wind of 3–8 % of the airspeed from any direction,
    /// half of them with light gusts, with an aircraft that lags its commands by 0.3–0.8 s
    /// and navigates with 5–15 m and 0.1–0.3° errors. A fixed final time is sized again at
    /// the airspeed less the wind.
    fn draw_wind(&mut self, rng: &mut ChaCha8Rng, filter: &Filter) {
        if rng.random::<f64>() >= filter.chance(Feature::Wind, 0.3) {
            return;
        }
        let speed = self.speed * rng.random_range(0.03..0.08);
        let from = rng.random_range(0.0..2.0 * PI);
        let wind = Wind {
            mean: [speed * from.cos(), speed * from.sin()],
            gusts: if rng.random::<bool>() {
                "light"
            } else {
                "none"
            },
            seed: rng.random(),
            response_s: rng.random_range(0.3..0.8),
            nav_sigma_m: rng.random_range(5.0..15.0),
            nav_heading_sigma_deg: rng.random_range(0.1..0.3),
            aircraft_seed: rng.random(),
        };
        if let Some(length) = self.time_length {
            self.final_time = Some((length / (self.speed - speed)).round());
        }
        self.wind = Some(wind);
    }

    /// What the mission came out as.
    fn kind(&self) -> MissionKind {
        MissionKind {
            model: if self.three_d { "3d" } else { "2d" }.into(),
            objective: self.objective.into(),
            targets: self.targets.len(),
            threats: self.threats.len(),
            popups: self.popups.len(),
            moving: self.moving.len(),
            unavoidable: self.unavoidable,
            lead_change: self.lead_turn.is_some(),
            wind: self.wind.is_some(),
            // Placed first, it is `t0` (see `draw_defended`).
            defended: self.unavoidable.then(|| "t0".to_string()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wingman_planning::scenario::Scenario;

    /// F of a footprint at a point (the superellipse in its own frame).
    fn f_of(fp: &Footprint, p: [f64; 2]) -> f64 {
        let (s, c) = fp.yaw_deg.to_radians().sin_cos();
        let (dx, dy) = (p[0] - fp.center[0], p[1] - fp.center[1]);
        let (u, v) = (c * dx + s * dy, -s * dx + c * dy);
        (u / fp.axes[0]).abs().powf(fp.exponent) + (v / fp.axes[1]).abs().powf(fp.exponent)
    }

    #[test]
    fn every_drawn_mission_parses_and_is_the_same_again() {
        for index in 0..200 {
            let d = draw(7, index, &Filter::default());
            let sc = Scenario::parse(&d.text, &d.name)
                .unwrap_or_else(|e| panic!("{}: {e}\n{}", d.name, d.text));
            assert_eq!(sc.name, d.name);
            assert_eq!(sc.targets.len(), d.kind.targets);
            assert_eq!(draw(7, index, &Filter::default()).text, d.text);
        }
    }

    /// The wind is drawn last: a mission drawn without one is the mission drawn before the
    /// wind existed, and a windy one is that mission with its `[wind]` and `[aircraft]`
    /// tables added (a fixed final time sized at the airspeed less the wind instead).
    #[test]
    fn a_wind_is_added_to_the_mission_drawn_without_it() {
        let still_air = Filter {
            without: vec![Feature::Wind],
            ..Filter::default()
        };
        let mut windy = 0;
        for index in 0..200 {
            let d = draw(5, index, &Filter::default());
            let e = draw(5, index, &still_air);
            assert!(!e.kind.wind && !e.text.contains("[wind]"));
            // The summary line names the wind.
            let body = |t: &str| -> String {
                t.lines()
                    .filter(|l| !l.starts_with("summary = "))
                    .map(|l| format!("{l}\n"))
                    .collect()
            };
            let (d_body, e_body) = (body(&d.text), body(&e.text));
            if !d.kind.wind {
                assert_eq!(d.text, e.text, "{index}");
                continue;
            }
            windy += 1;
            let sc = Scenario::parse(&d.text, &d.name).unwrap();
            let w = sc.wind.as_ref().expect("a [wind] table").mean_mps;
            let speed = sc.vehicle.speed_mps;
            let ratio = w[0].hypot(w[1]) / speed;
            assert!((0.03..0.08).contains(&ratio), "{index}: {ratio}");
            assert!(sc.aircraft.as_ref().is_some_and(|a| a.response_s > 0.0));
            let still = Scenario::parse(&e.text, &e.name).unwrap();
            let time = |sc: &Scenario| sc.final_point.as_ref().and_then(|f| f.time_s);
            match (time(&sc), time(&still)) {
                (Some(t), Some(t_still)) => {
                    // Both rounded to 1 s.
                    let want = t_still / (1.0 - ratio);
                    assert!(
                        (t - want).abs() <= 1.0 + 1e-9,
                        "{index}: {t} against {want}"
                    );
                    // Up to the final time.
                    let head = &d_body[..d_body.rfind("\ntime_s = ").unwrap()];
                    assert!(e_body.starts_with(head), "{index}");
                }
                _ => assert!(d_body.starts_with(&e_body), "{index}"),
            }
        }
        assert!((40..=80).contains(&windy), "{windy} windy of 200");
    }

    #[test]
    fn the_draws_cover_every_kind_the_issue_names() {
        let kinds: Vec<MissionKind> = (0..300)
            .map(|i| draw(3, i, &Filter::default()).kind)
            .collect();
        for model in ["2d", "3d"] {
            for objective in super::super::kind::OBJECTIVES {
                assert!(
                    kinds
                        .iter()
                        .any(|k| k.model == model && k.objective == objective),
                    "{model} {objective}"
                );
            }
        }
        for f in Feature::ALL {
            assert!(kinds.iter().any(|k| k.has(f)), "{}", f.name());
        }
        assert!((1..=4).all(|n| kinds.iter().any(|k| k.targets == n)));
        assert!(kinds.iter().any(|k| k.threats >= 12));
        // The planner's capacity, pop-ups included.
        assert!(
            kinds
                .iter()
                .all(|k| k.threats >= 3 && k.threats + k.popups <= MAX_THREATS)
        );
    }

    #[test]
    fn filters_narrow_the_draw() {
        let filter = Filter {
            models: vec!["3d".into()],
            objectives: vec![],
            with: vec![Feature::LeadChange],
            without: vec![Feature::Moving],
        };
        for index in 0..40 {
            let k = draw(1, index, &filter).kind;
            assert_eq!(
                (k.model.as_str(), k.objective.as_str()),
                ("3d", "min-time-rendezvous")
            );
            assert!(k.lead_change && k.moving == 0);
        }
        // Required features the layout could not place are drawn again.
        let crowded = Filter {
            with: vec![Feature::Popups, Feature::Moving, Feature::Unavoidable],
            ..Filter::default()
        };
        for index in 0..40 {
            let k = draw(2, index, &crowded).kind;
            assert!(
                k.popups > 0 && k.moving > 0 && k.unavoidable,
                "{index}: {k:?}"
            );
        }
    }

    #[test]
    fn avoidable_layouts_leave_the_points_clear_and_unavoidable_ones_cover_a_target() {
        for index in 0..200 {
            let d = draw(11, index, &Filter::default());
            let sc = Scenario::parse(&d.text, &d.name).expect("parses");
            let mut points: Vec<[f64; 2]> = vec![[sc.start.position_m[0], sc.start.position_m[1]]];
            points.extend(sc.targets.iter().map(|t| [t[0], t[1]]));
            let inside: usize = points
                .iter()
                .filter(|p| {
                    sc.threats.iter().any(|t| {
                        let fp = Footprint {
                            center: [t.center_m[0], t.center_m[1]],
                            axes: [t.axes_m[0], t.axes_m[1]],
                            exponent: t.exponents[0],
                            yaw_deg: t.yaw_rad.to_degrees(),
                        };
                        f_of(&fp, **p) < 1.0
                    })
                })
                .count();
            assert_eq!(inside, usize::from(d.kind.unavoidable), "{}", d.name);
            if let Some(tf) = sc.final_point.as_ref().and_then(|f| f.time_s) {
                // At least the straight path's length over the speed.
                let mut legs: Vec<[f64; 3]> = vec![sc.start.position_m];
                legs.extend(sc.targets.iter().copied());
                legs.push(
                    sc.final_point
                        .as_ref()
                        .map(|f| f.position_m)
                        .unwrap_or_default(),
                );
                let straight = avoiding_length(&legs, &[], 0.0);
                assert!(tf * sc.vehicle.speed_mps > 1.1 * straight, "{}", d.name);
            }
        }
    }
}
