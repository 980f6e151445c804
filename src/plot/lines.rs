//! Line and marker plots on linear or log axes, as SVG (plotters).

use super::plot_error;
use crate::error::Result;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use std::path::Path;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A polyline.
    Line,
    /// Markers, with optional vertical error bars.
    Points,
}

/// One data series of a plot.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// `(x, y)` pairs.
    pub points: Vec<(f64, f64)>,
    /// Optional `(low, high)` per point: drawn as error bars.
    pub bars: Option<Vec<(f64, f64)>>,
    /// Line or markers.
    pub style: Style,
    /// Palette index; series of one sampler share it.
    pub color: usize,
}

/// Axis scales and labels of a line plot.
#[derive(Debug, Clone)]
pub struct Axes {
    /// Title above the plot.
    pub title: String,
    /// Horizontal axis label.
    pub x_label: String,
    /// Vertical axis label.
    pub y_label: String,
    /// Logarithmic horizontal axis.
    pub log_x: bool,
    /// Logarithmic vertical axis.
    pub log_y: bool,
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// The range covered by the finite (and, on a log axis, positive) values, padded.
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && (!log || *v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (if log { 0.1 } else { 0.0 }, 1.0);
    }
    if log {
        (lo / 1.5, hi * 1.5)
    } else {
        let pad = ((hi - lo) * 0.05).max(1e-12);
        (lo - pad, hi + pad)
    }
}

/// Writes a line/marker plot as SVG.
///
/// # Errors
/// The file cannot be written.
pub fn line_plot(path: &Path, axes: &Axes, series: &[Series]) -> Result<()> {
    let xs = series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
    let ys = series.iter().flat_map(|s| {
        let bars = s.bars.iter().flatten().flat_map(|b| [b.0, b.1]);
        s.points.iter().map(|p| p.1).chain(bars)
    });
    let (x0, x1) = range(xs, axes.log_x);
    let (y0, y1) = range(ys, axes.log_y);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (720, 500)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let mut builder = ChartBuilder::on(&root);
        builder
            .caption(&axes.title, ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(72);
        // plotters types a log axis differently from a linear one: four cases, one drawing routine.
        match (axes.log_x, axes.log_y) {
            (true, true) => {
                let chart = builder
                    .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                    .map_err(plot_error)?;
                draw(chart, axes, series)
            }
            (true, false) => {
                let chart = builder
                    .build_cartesian_2d((x0..x1).log_scale(), y0..y1)
                    .map_err(plot_error)?;
                draw(chart, axes, series)
            }
            (false, true) => {
                let chart = builder
                    .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
                    .map_err(plot_error)?;
                draw(chart, axes, series)
            }
            (false, false) => {
                let chart = builder
                    .build_cartesian_2d(x0..x1, y0..y1)
                    .map_err(plot_error)?;
                draw(chart, axes, series)
            }
        }?;
        root.present().map_err(plot_error)?;
    }
    crate::output::write_atomic(path, svg.as_bytes())
}

fn draw<'a, X, Y>(
    mut chart: ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>,
    axes: &Axes,
    series: &[Series],
) -> Result<()>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(axes.x_label.as_str())
        .y_desc(axes.y_label.as_str())
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .draw()
        .map_err(plot_error)?;
    for s in series {
        let color = PALETTE[s.color % PALETTE.len()];
        let keep =
            |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite() && (!axes.log_y || p.1 > 0.0);
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(keep).collect();
        let anno = match s.style {
            Style::Line => chart
                .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                .map_err(plot_error)?,
            Style::Points => chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))
                .map_err(plot_error)?,
        };
        anno.label(s.label.as_str()).legend(move |(x, y)| {
            PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
        });
        if let Some(bars) = &s.bars {
            let segments = s.points.iter().zip(bars).filter(|(p, b)| {
                p.0.is_finite() && b.0.is_finite() && b.1.is_finite() && (!axes.log_y || b.0 > 0.0)
            });
            chart
                .draw_series(segments.map(|(p, b)| {
                    PathElement::new(vec![(p.0, b.0), (p.0, b.1)], color.stroke_width(1))
                }))
                .map_err(plot_error)?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(plot_error)?;
    Ok(())
}

/// A short tick label: plain for moderate values, scientific otherwise.
fn tick(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-2..1e4).contains(&a) {
        format!("{v:.0e}")
    } else {
        let text = format!("{v:.3}");
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}
