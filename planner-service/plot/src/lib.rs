//! PNG plots for people (plotters, pure Rust, text with the bundled DejaVu Sans): a map of
//! the threat world with paths and markers, in kilometres east and north.

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;

use wingman_planning::problem::{Problem, Threats};

static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// Registers the bundled DejaVu Sans as plotters' `sans-serif` (once; other plots of the
/// workspace, e.g. the harness's, call it too).
pub fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bundled font is a valid TrueType file; a failure would only lose the text.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// How a path is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stroke {
    Thin,
    Dashed,
    Bold,
}

/// One path on a map: positions in metres.
#[derive(Debug, Clone)]
pub struct MapPath {
    pub label: Option<String>,
    pub color: RGBColor,
    pub stroke: Stroke,
    pub points: Vec<[f64; 2]>,
}

/// A labelled point on a map, in metres.
#[derive(Debug, Clone)]
pub struct MapMarker {
    pub label: String,
    pub color: RGBColor,
    pub at: [f64; 2],
}

/// A map: the problem's threats (footprints at ground level, F = 1), then paths and
/// markers, with a legend.
#[derive(Debug, Clone)]
pub struct MapPlot<'a> {
    pub title: String,
    pub problem: &'a Problem,
    /// Extra threat outlines (e.g. a moving threat's keep-out region at re-plan times).
    pub outlines: Vec<(String, RGBColor, Vec<[f64; 2]>)>,
    pub paths: Vec<MapPath>,
    pub markers: Vec<MapMarker>,
}

/// Boundary `F = 1` of a superquadric footprint, in metres.
pub fn footprint(center: [f64; 2], axes: [f64; 2], exponents: [f64; 2], yaw: f64) -> Vec<[f64; 2]> {
    let (s, c) = yaw.sin_cos();
    (0..=120)
        .map(|k| {
            let th = std::f64::consts::TAU * k as f64 / 120.0;
            let (st, ct) = th.sin_cos();
            let lx = axes[0] * ct.signum() * ct.abs().powf(2.0 / exponents[0]);
            let ly = axes[1] * st.signum() * st.abs().powf(2.0 / exponents[1]);
            [center[0] + c * lx - s * ly, center[1] + s * lx + c * ly]
        })
        .collect()
}

fn static_footprints(problem: &Problem) -> Vec<Vec<[f64; 2]>> {
    match &problem.threats {
        Threats::Planar { layout, .. } => layout
            .threats()
            .iter()
            .map(|t| footprint(*t.center(), *t.axes(), *t.exponents(), t.yaw()))
            .collect(),
        Threats::Spatial { layout, .. } => layout
            .threats()
            .iter()
            .map(|t| {
                let (c, a, p) = (t.center(), t.axes(), t.exponents());
                // Ground-level cut: the horizontal section through the centre scaled by
                // the height of the centre above ground (centres sit on the ground).
                footprint([c[0], c[1]], [a[0], a[1]], [p[0], p[1]], t.yaw())
            })
            .collect(),
    }
}

fn moving_roads(problem: &Problem) -> Vec<Vec<[f64; 2]>> {
    match &problem.threats {
        Threats::Planar { moving, .. } => moving
            .iter()
            .map(|m| m.road().points().iter().map(|p| [p[0], p[1]]).collect())
            .collect(),
        Threats::Spatial { moving, .. } => moving
            .iter()
            .map(|m| m.road().points().iter().map(|p| [p[0], p[1]]).collect())
            .collect(),
    }
}

/// Draws `plot` into a PNG of `size` pixels.
pub fn draw_map(
    path: &Path,
    plot: &MapPlot<'_>,
    size: (u32, u32),
) -> Result<(), Box<dyn std::error::Error>> {
    register_font();
    let footprints = static_footprints(plot.problem);
    let roads = moving_roads(plot.problem);
    // Extent: everything drawn, with a margin.
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut grow = |p: &[f64; 2]| {
        for i in 0..2 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    };
    plot.paths
        .iter()
        .flat_map(|p| &p.points)
        .for_each(&mut grow);
    plot.markers.iter().for_each(|m| grow(&m.at));
    footprints.iter().flatten().for_each(&mut grow);
    if !lo[0].is_finite() {
        lo = [-1000.0; 2];
        hi = [1000.0; 2];
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]) * 0.05 + 1000.0;
    let km = |v: f64| v / 1000.0;
    let (x0, x1, y0, y1) = (
        km(lo[0] - span),
        km(hi[0] + span),
        km(lo[1] - span),
        km(hi[1] + span),
    );

    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&plot.title, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc("east [km]")
        .y_desc("north [km]")
        .label_style(("sans-serif", 14))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;

    let threat_fill = RGBColor(230, 80, 60).mix(0.18);
    let threat_edge = RGBColor(200, 40, 30);
    for (k, fp) in footprints.iter().enumerate() {
        let pts: Vec<(f64, f64)> = fp.iter().map(|p| (km(p[0]), km(p[1]))).collect();
        chart.draw_series(std::iter::once(Polygon::new(
            pts.clone(),
            threat_fill.filled(),
        )))?;
        let series = chart.draw_series(std::iter::once(PathElement::new(
            pts,
            threat_edge.stroke_width(1),
        )))?;
        if k == 0 {
            series.label("static threat (F = 1)").legend(move |(x, y)| {
                Rectangle::new([(x, y - 5), (x + 16, y + 5)], threat_fill.filled())
            });
        }
    }
    for (k, road) in roads.iter().enumerate() {
        let pts: Vec<(f64, f64)> = road.iter().map(|p| (km(p[0]), km(p[1]))).collect();
        let s = chart.draw_series(std::iter::once(PathElement::new(
            pts,
            RGBColor(120, 80, 20).stroke_width(3),
        )))?;
        if k == 0 {
            s.label("road of a moving threat").legend(|(x, y)| {
                PathElement::new(
                    vec![(x, y), (x + 16, y)],
                    RGBColor(120, 80, 20).stroke_width(3),
                )
            });
        }
    }
    for (label, color, outline) in &plot.outlines {
        let pts: Vec<(f64, f64)> = outline.iter().map(|p| (km(p[0]), km(p[1]))).collect();
        let color = *color;
        let s = chart.draw_series(std::iter::once(PathElement::new(
            pts,
            color.stroke_width(2),
        )))?;
        if !label.is_empty() {
            s.label(label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
            });
        }
    }
    for p in &plot.paths {
        let pts: Vec<(f64, f64)> = p.points.iter().map(|q| (km(q[0]), km(q[1]))).collect();
        let color = p.color;
        let style = match p.stroke {
            Stroke::Thin => color.mix(0.35).stroke_width(1),
            Stroke::Dashed => color.stroke_width(2),
            Stroke::Bold => color.stroke_width(3),
        };
        let series = match p.stroke {
            Stroke::Dashed => chart.draw_series(DashedLineSeries::new(pts, 8, 6, style))?,
            _ => chart.draw_series(LineSeries::new(pts, style))?,
        };
        if let Some(label) = &p.label {
            series
                .label(label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], style));
        }
    }
    for m in &plot.markers {
        let color = m.color;
        chart.draw_series(std::iter::once(Circle::new(
            (km(m.at[0]), km(m.at[1])),
            5,
            color.filled(),
        )))?;
        chart.draw_series(std::iter::once(Text::new(
            m.label.clone(),
            (km(m.at[0]), km(m.at[1])),
            ("sans-serif", 14).into_font().color(&BLACK),
        )))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()?;
    root.present()?;
    Ok(())
}
