//! PNG plots of a flight (plotters, text in the bundled DejaVu Sans):
//!
//! - `map.png`: the threats (static footprints, pop-ups named with their time, roads),
//!   each moving threat's true path and its estimated keep-out region at each re-plan,
//!   the lead's routes, every plan, the flown path, the targets and the end;
//! - `timeline.png`: exposure `E` along the flown path, the tracker's deviation from the
//!   plan it flies, and the re-plans (one line each, labelled with its trigger);
//! - `side.png` (3-D): altitude against mission time, flown and planned, with the floor.

use std::error::Error;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use wingman_interfaces::{Model, Objective, Trigger};
use wingman_planning::estimation::{GaussMarkov, MovingThreat, Road};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::Scenario;
use wingman_planning::tracking::Deviation;
use wingman_plot::{self as plot, MapMarker, MapPath, MapPlot, Stroke};

use crate::mission::Flight;
use crate::report::{Report, exposure_series};

pub(crate) type PlotResult<T> = Result<T, Box<dyn Error + Send + Sync>>;

pub(crate) fn boxed(e: impl ToString) -> Box<dyn Error + Send + Sync> {
    e.to_string().into()
}

/// Colours of successive plans.
pub(crate) const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(23, 190, 207),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
    RGBColor(140, 86, 75),
];

fn plan_color(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

fn trigger_name(t: Option<Trigger>) -> &'static str {
    t.map_or("?", Trigger::name)
}

/// Draws every plot into `out`; returns the file names written.
pub fn draw_all(flight: &Flight, report: &Report, out: &Path) -> PlotResult<Vec<String>> {
    plot::register_font();
    let mut written = Vec::new();
    map(flight, &out.join("map.png"))?;
    written.push("map.png".to_string());
    timeline(flight, report, &out.join("timeline.png"))?;
    written.push("timeline.png".to_string());
    if flight.scenario.model == Model::ThreeD {
        side(flight, &out.join("side.png"))?;
        written.push("side.png".to_string());
    }
    Ok(written)
}

/// The map.
pub fn map(flight: &Flight, path: &Path) -> PlotResult<()> {
    let sc = &flight.scenario;
    let problem = truth_problem(sc)?;
    let mut paths = lead_paths(flight);
    paths.extend(moving_threat_paths(flight));
    paths.extend(plan_paths(flight));
    paths.push(MapPath {
        label: Some("flown path".into()),
        color: BLACK,
        stroke: Stroke::Bold,
        // One point a second: a thick line through every 0.1 s step renders jagged.
        points: decimated(flight)
            .map(|s| [s.state[0], s.state[1]])
            .collect(),
    });
    let outlines = keep_out_outlines(flight);
    let mut markers = map_markers(flight);
    markers.extend(legend_room(sc, &paths, &markers));
    let title = format!(
        "{} — {} plan(s), flown with the {} clock{}",
        sc.name,
        flight.plans.len(),
        flight.clock,
        resumed_note(flight)
    );
    let plot = MapPlot {
        title,
        problem: &problem,
        outlines,
        paths,
        markers,
    };
    plot::draw_map(path, &plot, (1400, 1200)).map_err(boxed)
}

/// The problem of every threat of the truth: pop-ups and moving threats as if known.
fn truth_problem(sc: &Scenario) -> PlotResult<Problem> {
    let mut all = sc.clone();
    for t in &mut all.threats {
        t.appears_at_s = None;
    }
    for m in &mut all.moving_threats {
        m.appears_at_s = sc.start.time_s;
    }
    all.events.clear();
    Problem::from_scenario(&all).map_err(boxed)
}

/// The lead's routes, each where the lead flew it (announced or not): from its time to
/// the next route's or the end.
fn lead_paths(flight: &Flight) -> Vec<MapPath> {
    let routes = flight.datalink.flown_routes();
    let mut paths = Vec::new();
    for (k, r) in routes.iter().enumerate() {
        let until = routes
            .get(k + 1)
            .map_or(flight.end_s, |next| next.at_s)
            .max(r.at_s);
        let n = (((until - r.at_s) / 5.0).ceil() as usize).clamp(1, 10_000);
        let pts = (0..=n)
            .map(|j| {
                let p = r.path.at(r.at_s + (until - r.at_s) * j as f64 / n as f64);
                [p.position[0], p.position[1]]
            })
            .collect();
        paths.push(MapPath {
            label: Some(format!(
                "lead, route {} ({:.0}-{:.0} s)",
                r.message.revision, r.at_s, until
            )),
            color: if k == 0 {
                RGBColor(90, 90, 200)
            } else {
                RGBColor(30, 30, 120)
            },
            stroke: Stroke::Dashed,
            points: pts,
        });
    }
    paths
}

/// Each moving threat's true path from its appearance.
fn moving_threat_paths(flight: &Flight) -> Vec<MapPath> {
    let sc = &flight.scenario;
    let mut paths = Vec::new();
    for (i, truth) in flight.truth.iter().enumerate() {
        let appears = sc.moving_threats[i].appears_at_s;
        let pts: Vec<[f64; 2]> = truth
            .iter()
            .filter(|(t, _)| *t >= appears)
            .map(|(_, p)| [p[0], p[1]])
            .collect();
        if pts.len() >= 2 {
            paths.push(MapPath {
                label: Some(format!("{} true path", sc.moving_threats[i].name)),
                color: RGBColor(150, 60, 0),
                stroke: Stroke::Bold,
                points: pts,
            });
        }
    }
    paths
}

/// Every plan, in its colour.
fn plan_paths(flight: &Flight) -> Vec<MapPath> {
    let mut paths = Vec::new();
    for (k, p) in flight.plans.iter().enumerate() {
        let plan = &p.plan;
        let pts = plan
            .samples()
            .iter()
            .map(|s| [s.state[0], s.state[1]])
            .collect();
        paths.push(MapPath {
            label: Some(format!(
                "plan {} ({}, {:.0} s)",
                plan.plan_id,
                trigger_name(plan.trigger()),
                plan.created_at_s
            )),
            color: plan_color(k),
            stroke: Stroke::Dashed,
            points: pts,
        });
    }
    paths
}

/// A moving threat's keep-out region as estimated at each plan, in the plan's colour.
fn keep_out_outlines(flight: &Flight) -> Vec<(String, RGBColor, Vec<[f64; 2]>)> {
    let sc = &flight.scenario;
    let mut outlines = Vec::new();
    for (n, e) in flight.estimates.iter().enumerate() {
        let Some(m) = sc.moving_threats.get(e.threat) else {
            continue;
        };
        let Ok(region) = keep_out(m, e) else {
            continue;
        };
        let k = flight
            .plans
            .iter()
            .position(|p| p.plan.plan_id == e.plan_id)
            .unwrap_or(0);
        let label = if n == 0 {
            format!(
                "{} keep-out estimated at each plan (the plan's colour)",
                m.name
            )
        } else {
            String::new()
        };
        outlines.push((label, plan_color(k), region));
    }
    outlines
}

/// The start, the targets, the end, the final point and the static threats' names.
fn map_markers(flight: &Flight) -> Vec<MapMarker> {
    let sc = &flight.scenario;
    let mut markers = vec![MapMarker {
        label: " start".into(),
        color: BLACK,
        at: [sc.start.position_m[0], sc.start.position_m[1]],
    }];
    for (k, t) in sc.targets.iter().enumerate() {
        markers.push(MapMarker {
            label: format!(" target {}", k + 1),
            color: RGBColor(0, 130, 0),
            at: [t[0], t[1]],
        });
    }
    if let Some(last) = flight.samples.last() {
        let label = match sc.objective {
            Objective::MinTimeRendezvous => format!(" rendezvous {:.0} s", last.t),
            _ => format!(" end {:.0} s", last.t),
        };
        markers.push(MapMarker {
            label,
            color: RGBColor(200, 0, 0),
            at: [last.state[0], last.state[1]],
        });
    }
    if let Some(f) = &sc.final_point {
        markers.push(MapMarker {
            label: " final point".into(),
            color: RGBColor(120, 0, 120),
            at: [f.position_m[0], f.position_m[1]],
        });
    }
    for t in &sc.threats {
        let name = match t.appears_at_s {
            Some(a) if a > sc.start.time_s => format!("{} (pop-up {a:.0} s)", t.name),
            _ => t.name.clone(),
        };
        markers.push(MapMarker {
            label: name,
            color: RGBColor(200, 40, 30),
            at: [t.center_m[0], t.center_m[1]],
        });
    }
    markers
}

/// Invisible markers that make room for the legend in the upper left corner (a point
/// beyond the drawing) and for the labels of points on the right edge; none for an empty
/// map.
fn legend_room(sc: &Scenario, paths: &[MapPath], markers: &[MapMarker]) -> Vec<MapMarker> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in paths
        .iter()
        .flat_map(|p| &p.points)
        .chain(markers.iter().map(|m| &m.at))
    {
        for i in 0..2 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    for t in &sc.threats {
        lo[0] = lo[0].min(t.center_m[0] - t.axes_m[0].max(t.axes_m[1]));
        hi[1] = hi[1].max(t.center_m[1] + t.axes_m[0].max(t.axes_m[1]));
    }
    if !lo[0].is_finite() {
        return Vec::new();
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    vec![
        MapMarker {
            label: String::new(),
            color: WHITE,
            at: [lo[0] - 0.32 * span, hi[1] + 0.05 * span],
        },
        MapMarker {
            label: String::new(),
            color: WHITE,
            at: [hi[0] + 0.1 * span, lo[1]],
        },
    ]
}

/// Footprint of the keep-out region a snapshot's estimate gives at its time.
fn keep_out(
    m: &wingman_planning::scenario::MovingThreatSpec,
    e: &crate::mission::EstimateSnapshot,
) -> PlotResult<Vec<[f64; 2]>> {
    let road: Vec<[f64; 2]> = m.road_m.iter().map(|p| [p[0], p[1]]).collect();
    let road = Road::<2>::new(&road).map_err(boxed)?;
    let model = GaussMarkov::new(m.accel_tau_s, m.accel_sigma_mps2).map_err(boxed)?;
    let threat =
        MovingThreat::new(road, [m.axes_m[0], m.axes_m[1]], model, e.estimate).map_err(boxed)?;
    let r = threat.region_at(e.at_s);
    let q = r.shape;
    Ok(plot::footprint(
        *q.center(),
        *q.axes(),
        *q.exponents(),
        q.yaw(),
    ))
}

/// A resumed flight's note for the titles (empty otherwise).
fn resumed_note(flight: &Flight) -> String {
    flight.resumed.map_or(String::new(), |r| {
        format!(" (resumed at {:.1} s)", r.point.t_s)
    })
}

/// The timeline: exposure, deviation, re-plans, and the wind when the scenario has one.
pub fn timeline(flight: &Flight, report: &Report, path: &Path) -> PlotResult<()> {
    let times: Vec<f64> = flight.samples.iter().map(|s| s.t).collect();
    let exposure = exposure_series(flight).map_err(boxed)?;
    let span = (
        times.first().copied().unwrap_or(0.0),
        times.last().copied().unwrap_or(1.0).max(1.0),
    );
    let root = BitMapBackend::new(path, (1400, 1000)).into_drawing_area();
    root.fill(&WHITE).map_err(boxed)?;
    let root = root
        .titled(
            &format!(
                "{} — exposure, deviation and re-plans along the flight{}",
                flight.scenario.name,
                resumed_note(flight)
            ),
            ("sans-serif", 24),
        )
        .map_err(boxed)?;
    let windy = flight.scenario.wind.is_some();
    let panels = root.split_evenly((if windy { 4 } else { 3 }, 1));
    exposure_panel(&panels[0], flight, report, (&times, &exposure), span)?;
    deviation_panel(&panels[1], flight, span)?;
    plans_panel(&panels[2], flight, span)?;
    if windy {
        wind_panel(&panels[3], flight, span)?;
    }
    root.present().map_err(boxed)?;
    Ok(())
}

/// One panel of the timeline over mission time `t0..t1`: its chart with the caption and
/// the axes drawn.
fn timeline_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: impl AsRef<str>,
    (t0, t1): (f64, f64),
    y: std::ops::Range<f64>,
    y_desc: &str,
) -> PlotResult<Chart<'a, DB>>
where
    DB::ErrorType: 'static,
{
    let mut c = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(70)
        .caption(caption, ("sans-serif", 18))
        .build_cartesian_2d(t0..t1, y)
        .map_err(boxed)?;
    c.configure_mesh()
        .x_desc("mission time [s]")
        .y_desc(y_desc)
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(boxed)?;
    Ok(c)
}

/// Panel 1: exposure `E` along the flown path (`times`, `exposure`).
fn exposure_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    flight: &Flight,
    report: &Report,
    (times, exposure): (&[f64], &[f64]),
    span: (f64, f64),
) -> PlotResult<()>
where
    DB::ErrorType: 'static,
{
    let e_max = exposure.iter().copied().fold(0.0, f64::max).max(1e-3) * 1.15;
    let caption = format!(
        "exposure E along the flown path (integral {:.3} s)",
        report.exposure_integral
    );
    let mut c = timeline_chart(area, caption, span, 0.0..e_max, "E [-]")?;
    c.draw_series(LineSeries::new(
        times.iter().copied().zip(exposure.iter().copied()),
        RGBColor(200, 40, 30).stroke_width(2),
    ))
    .map_err(boxed)?
    .label("E (truth: every static threat, moving threats at their true position)")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], RGBColor(200, 40, 30)));
    replan_lines(&mut c, flight, (0.0, e_max))?;
    legend(&mut c)
}

/// Panel 2: the tracker's deviation from the plan it flies (cross-track, along-track, and
/// vertical in 3-D), with the holds shaded.
fn deviation_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    flight: &Flight,
    (t0, t1): (f64, f64),
) -> PlotResult<()>
where
    DB::ErrorType: 'static,
{
    let three_d = flight.scenario.model == Model::ThreeD;
    let d_max = flight
        .samples
        .iter()
        .flat_map(|s| {
            let d = s.deviation;
            [d.cross_m.abs(), d.along_m.abs(), d.vertical_m.abs()]
        })
        .fold(1.0, f64::max)
        * 1.15;
    let mut c = timeline_chart(
        area,
        "tracker's deviation from the plan it flies",
        (t0, t1),
        -d_max..d_max,
        "deviation [m]",
    )?;
    type Axis = fn(&Deviation) -> f64;
    let axes: [(&str, RGBColor, u32, Axis); 3] = [
        ("cross-track (left +)", RGBColor(31, 119, 180), 2, |d| {
            d.cross_m
        }),
        ("along-track (ahead +)", RGBColor(110, 110, 110), 1, |d| {
            d.along_m
        }),
        ("vertical (above +)", RGBColor(44, 160, 44), 2, |d| {
            d.vertical_m
        }),
    ];
    for (label, color, width, axis) in axes.into_iter().take(if three_d { 3 } else { 2 }) {
        c.draw_series(LineSeries::new(
            flight.samples.iter().map(|s| (s.t, axis(&s.deviation))),
            color.stroke_width(width),
        ))
        .map_err(boxed)?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
    }
    let holds: Vec<(f64, f64)> = flight
        .holds
        .iter()
        .map(|h| (h.from_s, h.to_s.unwrap_or(t1)))
        .collect();
    for (a, b) in &holds {
        c.draw_series(std::iter::once(Rectangle::new(
            [(*a, -d_max), (*b, d_max)],
            RGBColor(255, 200, 0).mix(0.3).filled(),
        )))
        .map_err(boxed)?;
    }
    replan_lines(&mut c, flight, (-d_max, d_max))?;
    legend(&mut c)
}

/// Panel 4 (a scenario with `[wind]`): the wind at the aircraft, each component.
fn wind_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    flight: &Flight,
    span: (f64, f64),
) -> PlotResult<()>
where
    DB::ErrorType: 'static,
{
    let axes = flight.scenario.model.position_dim();
    let w_max = flight
        .samples
        .iter()
        .flat_map(|s| s.wind[..axes].iter().map(|w| w.abs()))
        .fold(1.0, f64::max)
        * 1.15;
    let mut c = timeline_chart(
        area,
        "wind at the aircraft (truth: mean and gusts)",
        span,
        -w_max..w_max,
        "wind [m/s]",
    )?;
    let colors = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
    ];
    for (i, (name, color)) in ["x", "y", "z"].iter().zip(colors).take(axes).enumerate() {
        c.draw_series(LineSeries::new(
            flight.samples.iter().map(|s| (s.t, s.wind[i])),
            color.stroke_width(1),
        ))
        .map_err(boxed)?
        .label(format!("wind {name}"))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
    }
    legend(&mut c)
}

/// Panel 3: the plans, which one is flown and the compute time of each. Plan ids need not
/// start at 1 (a resumed flight, a restarted planner).
fn plans_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    flight: &Flight,
    span: (f64, f64),
) -> PlotResult<()>
where
    DB::ErrorType: 'static,
{
    let ids = flight.plans.iter().map(|p| p.plan.plan_id);
    let id_lo = ids.clone().min().unwrap_or(1) as f64;
    let id_hi = ids.max().unwrap_or(1) as f64;
    let mut c = timeline_chart(
        area,
        "plan flown (bars: trigger time to start; label: trigger, compute time, quality)",
        span,
        (id_lo - 1.0)..(id_hi + 1.0),
        "plan id",
    )?;
    c.draw_series(LineSeries::new(
        flight.samples.iter().map(|s| (s.t, s.plan_id as f64)),
        BLACK.stroke_width(2),
    ))
    .map_err(boxed)?;
    for (k, p) in flight.plans.iter().enumerate() {
        let plan = &p.plan;
        let y = plan.plan_id as f64;
        let color = plan_color(k);
        c.draw_series(std::iter::once(Rectangle::new(
            [
                (plan.created_at_s, y - 0.2),
                (plan.start_time_s.max(plan.created_at_s + 0.5), y + 0.2),
            ],
            color.filled(),
        )))
        .map_err(boxed)?;
        c.draw_series(std::iter::once(Text::new(
            format!(
                "  {} {:.0} ms {}",
                trigger_name(plan.trigger()),
                plan.compute_ms,
                plan.quality().map_or("?", |q| q.name())
            ),
            (plan.start_time_s, y + 0.45),
            ("sans-serif", 14).into_font().color(&BLACK),
        )))
        .map_err(boxed)?;
    }
    Ok(())
}

/// The chart of the timeline and the side view.
type Chart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The legend, upper right.
fn legend<'a, DB: DrawingBackend + 'a>(c: &mut Chart<'a, DB>) -> PlotResult<()>
where
    DB::ErrorType: 'static,
{
    c.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| boxed(format!("{e:?}")))
}

/// A dotted vertical line at each re-plan's trigger time.
fn replan_lines<DB: DrawingBackend>(
    c: &mut Chart<'_, DB>,
    flight: &Flight,
    (lo, hi): (f64, f64),
) -> PlotResult<()>
where
    DB::ErrorType: 'static,
{
    let grey = RGBColor(120, 120, 120);
    let mut first = true;
    for p in flight.plans.iter().skip(1) {
        let t = p.plan.created_at_s;
        let s = c
            .draw_series(DashedLineSeries::new(
                vec![(t, lo), (t, hi)],
                4,
                4,
                grey.stroke_width(1),
            ))
            .map_err(|e| boxed(format!("{e:?}")))?;
        if first {
            first = false;
            s.label("re-plan (trigger time)")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], grey));
        }
    }
    Ok(())
}

/// The side view: altitude against mission time.
pub fn side(flight: &Flight, path: &Path) -> PlotResult<()> {
    let sc = &flight.scenario;
    let z_min = sc.vehicle.altitude_min_m;
    let t0 = flight.samples.first().map_or(0.0, |s| s.t);
    let t1 = flight
        .plans
        .iter()
        .map(|p| p.plan.final_time_s)
        .chain(flight.samples.last().map(|s| s.t))
        .fold(t0 + 1.0, f64::max);
    let mut lo = z_min;
    let mut hi = z_min + 1000.0;
    for s in &flight.samples {
        hi = hi.max(s.state[2]);
        lo = lo.min(s.state[2]);
    }
    for p in &flight.plans {
        for s in p.plan.samples() {
            hi = hi.max(s.state[2]);
        }
    }
    for t in &sc.targets {
        hi = hi.max(t[2]);
    }
    let margin = 0.08 * (hi - lo);
    let km = |v: f64| v / 1000.0;
    let root = BitMapBackend::new(path, (1400, 700)).into_drawing_area();
    root.fill(&WHITE).map_err(boxed)?;
    let mut c = ChartBuilder::on(&root)
        .margin(14)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .caption(
            format!(
                "{} — side view: altitude against mission time{}",
                sc.name,
                resumed_note(flight)
            ),
            ("sans-serif", 22),
        )
        .build_cartesian_2d(t0..t1, km(lo - margin - 200.0)..km(hi + margin))
        .map_err(boxed)?;
    c.configure_mesh()
        .x_desc("mission time [s]")
        .y_desc("altitude [km]")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(boxed)?;
    let red = RGBColor(200, 40, 30);
    c.draw_series(LineSeries::new(
        vec![(t0, km(z_min)), (t1, km(z_min))],
        red.stroke_width(2),
    ))
    .map_err(boxed)?
    .label(format!("altitude floor {z_min:.0} m"))
    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], red));
    for (k, p) in flight.plans.iter().enumerate() {
        let color = plan_color(k);
        c.draw_series(DashedLineSeries::new(
            p.plan.samples().iter().map(|s| (s.t_s, km(s.state[2]))),
            8,
            6,
            color.stroke_width(2),
        ))
        .map_err(boxed)?
        .label(format!(
            "plan {} ({}, {:.0} s)",
            p.plan.plan_id,
            trigger_name(p.plan.trigger()),
            p.plan.created_at_s
        ))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2)));
    }
    c.draw_series(LineSeries::new(
        decimated(flight).map(|s| (s.t, km(s.state[2]))),
        BLACK.stroke_width(3),
    ))
    .map_err(boxed)?
    .label("flown")
    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK.stroke_width(3)));
    // Targets at the time the flown path passes them.
    let green = RGBColor(0, 130, 0);
    for (k, t) in sc.targets.iter().enumerate() {
        let best = flight
            .samples
            .iter()
            .min_by(|a, b| dist(&a.state, t).total_cmp(&dist(&b.state, t)));
        if let Some(s) = best {
            c.draw_series(std::iter::once(Circle::new(
                (s.t, km(t[2])),
                6,
                green.filled(),
            )))
            .map_err(boxed)?;
            c.draw_series(std::iter::once(Text::new(
                format!(" target {}", k + 1),
                (s.t, km(t[2])),
                ("sans-serif", 14).into_font().color(&BLACK),
            )))
            .map_err(boxed)?;
        }
    }
    legend(&mut c)?;
    root.present().map_err(boxed)?;
    Ok(())
}

fn dist(x: &[f64; 7], t: &[f64; 3]) -> f64 {
    ((x[0] - t[0]).powi(2) + (x[1] - t[1]).powi(2) + (x[2] - t[2]).powi(2)).sqrt()
}

/// The flown samples about one a second (and the last).
fn decimated(flight: &Flight) -> impl Iterator<Item = &crate::tracker::TrackerSample> {
    let n = flight.samples.len();
    flight
        .samples
        .iter()
        .enumerate()
        .filter(move |(k, _)| k % 10 == 0 || k + 1 == n)
        .map(|(_, s)| s)
}
