//! The campaign report's PNG charts: empirical CDFs of one or more series (each series's
//! values sorted, the share at or below each), on a linear or a log axis.

use std::path::Path;

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use crate::plots::{PALETTE, PlotResult, boxed};

type ChartResult = PlotResult<()>;

/// One labelled series of a CDF chart.
pub struct Series {
    pub label: String,
    pub values: Vec<f64>,
}

/// A CDF chart: the series' empirical distributions, with vertical marks at `marks`
/// (label, x). `log_x`: a log axis (values at or below zero are left out).
pub struct Cdf<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub series: Vec<Series>,
    pub marks: Vec<(String, f64)>,
    pub log_x: bool,
}

/// Draws `chart` into `path` (1100 × 650 px).
pub fn draw_cdf(path: &Path, chart: &Cdf) -> ChartResult {
    wingman_plot::register_font();
    let series: Vec<(String, Vec<f64>)> = chart
        .series
        .iter()
        .map(|s| {
            let mut v: Vec<f64> = s
                .values
                .iter()
                .copied()
                .filter(|x| x.is_finite() && (!chart.log_x || *x > 0.0))
                .collect();
            v.sort_by(f64::total_cmp);
            (s.label.clone(), v)
        })
        .filter(|(_, v)| !v.is_empty())
        .collect();
    let all = series.iter().flat_map(|(_, v)| v.iter().copied());
    let (lo, hi) = all
        .chain(chart.marks.iter().map(|m| m.1))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    let (lo, hi) = if lo.is_finite() && hi > lo {
        (lo, hi)
    } else if lo.is_finite() {
        (
            lo - 1.0f64.max(lo.abs() * 0.1),
            lo + 1.0f64.max(lo.abs() * 0.1),
        )
    } else {
        (0.0, 1.0)
    };
    let root = BitMapBackend::new(path, (1100, 650)).into_drawing_area();
    root.fill(&WHITE).map_err(boxed)?;
    let mut builder = ChartBuilder::on(&root);
    builder
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(60)
        .caption(chart.title, ("sans-serif", 22));
    if chart.log_x {
        let lo = lo.max(1e-9);
        let mut c = builder
            .build_cartesian_2d((lo * 0.8..hi * 1.25).log_scale(), 0.0..1.02)
            .map_err(boxed)?;
        fill(&mut c, chart, &series)?;
    } else {
        let pad = 0.03 * (hi - lo);
        let mut c = builder
            .build_cartesian_2d(lo - pad..hi + pad, 0.0..1.02)
            .map_err(boxed)?;
        fill(&mut c, chart, &series)?;
    }
    root.present().map_err(boxed)?;
    Ok(())
}

/// The axes, the step lines of the series, the marks and the legend.
fn fill<'a, X>(
    c: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<X, RangedCoordf64>>,
    chart: &Cdf,
    series: &[(String, Vec<f64>)],
) -> ChartResult
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    c.configure_mesh()
        .x_desc(chart.x_label)
        .y_desc("share of missions at or below")
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(boxed)?;
    for (k, (label, v)) in series.iter().enumerate() {
        let color = PALETTE[k % PALETTE.len()];
        let n = v.len() as f64;
        let mut points = Vec::with_capacity(2 * v.len());
        for (i, x) in v.iter().enumerate() {
            points.push((*x, i as f64 / n));
            points.push((*x, (i + 1) as f64 / n));
        }
        c.draw_series(LineSeries::new(points, color.stroke_width(2)))
            .map_err(boxed)?
            .label(format!("{label} ({} missions)", v.len()))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
            });
    }
    for (label, x) in &chart.marks {
        let grey = RGBColor(120, 120, 120);
        c.draw_series(DashedLineSeries::new(
            vec![(*x, 0.0), (*x, 1.02)],
            6,
            4,
            grey.stroke_width(1),
        ))
        .map_err(boxed)?
        .label(label.clone())
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], grey));
    }
    c.configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(boxed)?;
    Ok(())
}
