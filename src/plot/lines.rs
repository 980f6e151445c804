//! Line and marker plots on linear or log axes, as SVG (plotters): the legend in its own panel
//! beside the chart, so it never covers data; markers with capped error bars; dashed reference
//! lines labelled at their end.

use super::plot_error;
use crate::error::Result;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A polyline.
    Line,
    /// Markers, with optional vertical error bars (capped).
    Points,
    /// A thin dashed grey line labelled at its right end (a reference slope), not in the
    /// legend.
    Reference,
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
    /// Line, markers or a reference.
    pub style: Style,
    /// Palette index; series of one sampler share it.
    pub color: usize,
}

/// Axis scales and labels of a line plot.
#[derive(Debug, Clone, Default)]
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
    /// Values to label on the horizontal axis (default: the library's choice).
    pub x_ticks: Option<Vec<f64>>,
}

// Ten colours, so that the report's ten-sampler figures repeat none.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(40, 40, 40),
];

const REFERENCE_GREY: RGBColor = RGBColor(140, 140, 140);
const WIDTH: u32 = 940;
const HEIGHT: u32 = 520;
/// Width of the legend panel, from the longest label at about 7 px a character.
fn legend_width(series: &[Series]) -> u32 {
    let longest = series
        .iter()
        .filter(|s| s.style != Style::Reference)
        .map(|s| s.label.chars().count())
        .max()
        .unwrap_or(0);
    (longest as u32 * 7 + 50).clamp(120, 320)
}

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
    // References are drawn within the data's horizontal range but may extend the vertical one.
    let data = || series.iter().filter(|s| s.style != Style::Reference);
    let xs = data().flat_map(|s| s.points.iter().map(|p| p.0));
    let ys = series.iter().flat_map(|s| {
        let bars = s.bars.iter().flatten().flat_map(|b| [b.0, b.1]);
        s.points.iter().map(|p| p.1).chain(bars)
    });
    let (x0, x1) = range(xs, axes.log_x);
    let (y0, y1) = range(ys, axes.log_y);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let (plot_area, legend_area) = root.split_horizontally(WIDTH - legend_width(series));
        let mut builder = ChartBuilder::on(&plot_area);
        builder
            .caption(&axes.title, ("sans-serif", 17))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(72);
        // plotters types a log axis differently from a linear one: four cases, one drawing routine.
        match (axes.log_x, axes.log_y) {
            (true, true) => {
                let x = (x0..x1).log_scale().with_key_points(ticks(axes, x0, x1));
                let chart = builder
                    .build_cartesian_2d(x, (y0..y1).log_scale())
                    .map_err(plot_error)?;
                draw(chart, axes, series)
            }
            (true, false) => {
                let x = (x0..x1).log_scale().with_key_points(ticks(axes, x0, x1));
                let chart = builder.build_cartesian_2d(x, y0..y1).map_err(plot_error)?;
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
        legend(&legend_area, series)?;
        root.present().map_err(plot_error)?;
    }
    crate::output::write_atomic(path, svg.as_bytes())
}

/// The tick values of a log horizontal axis: those asked for within the range, else the
/// 1-2-5 sequence within it (so that every decade, and a narrow range, is labelled).
fn ticks(axes: &Axes, lo: f64, hi: f64) -> Vec<f64> {
    if let Some(t) = &axes.x_ticks {
        return t.iter().copied().filter(|v| *v >= lo && *v <= hi).collect();
    }
    let mut out = Vec::new();
    let mut decade = 10f64.powf(lo.log10().floor());
    while decade <= hi {
        for m in [1.0, 2.0, 5.0] {
            let v = m * decade;
            if v >= lo && v <= hi {
                out.push(v);
            }
        }
        decade *= 10.0;
    }
    out
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
    let (xr, yr) = (chart.x_range(), chart.y_range());
    let inside = |p: &(f64, f64)| {
        p.0.is_finite()
            && p.1.is_finite()
            && p.0 >= xr.start
            && p.0 <= xr.end
            && p.1 >= yr.start
            && p.1 <= yr.end
    };
    for s in series {
        let color = PALETTE[s.color % PALETTE.len()];
        match s.style {
            Style::Line => {
                let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| inside(p)).collect();
                chart
                    .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                    .map_err(plot_error)?;
            }
            Style::Points => {
                let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| inside(p)).collect();
                if let Some(bars) = &s.bars {
                    draw_bars(&mut chart, s, bars, color)?;
                }
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))
                    .map_err(plot_error)?;
            }
            Style::Reference => {
                let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| inside(p)).collect();
                let dashed = pts.windows(2).flat_map(|w| dashes(w[0], w[1], axes));
                chart
                    .draw_series(
                        dashed.map(|(a, b)| {
                            PathElement::new(vec![a, b], REFERENCE_GREY.stroke_width(1))
                        }),
                    )
                    .map_err(plot_error)?;
                if let Some(&end) = pts.last() {
                    chart
                        .draw_series(std::iter::once(Text::new(
                            s.label.clone(),
                            end,
                            ("sans-serif", 12).into_font().color(&REFERENCE_GREY),
                        )))
                        .map_err(plot_error)?;
                }
            }
        }
    }
    Ok(())
}

/// The dashes of a segment: eight per segment, on the axes' scales.
fn dashes(a: (f64, f64), b: (f64, f64), axes: &Axes) -> Vec<((f64, f64), (f64, f64))> {
    let lerp = |u: f64, v: f64, t: f64, log: bool| {
        if log {
            (u.ln() + (v.ln() - u.ln()) * t).exp()
        } else {
            u + (v - u) * t
        }
    };
    let point = |t: f64| (lerp(a.0, b.0, t, axes.log_x), lerp(a.1, b.1, t, axes.log_y));
    (0..16)
        .step_by(2)
        .map(|i| (point(i as f64 / 16.0), point((i + 1) as f64 / 16.0)))
        .collect()
}

/// Vertical bars with caps for each point's `(low, high)`.
fn draw_bars<'a, X, Y>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>,
    s: &Series,
    bars: &[(f64, f64)],
    color: RGBColor,
) -> Result<()>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let yr = chart.y_range();
    let clamp = |v: f64| v.clamp(yr.start, yr.end);
    let mut segments = Vec::new();
    for (p, b) in s.points.iter().zip(bars) {
        if !(p.0.is_finite() && b.0.is_finite() && b.1.is_finite() && b.0 > 0.0
            || b.0.is_finite() && b.0 <= 0.0 && b.1.is_finite())
        {
            continue;
        }
        let (lo, hi) = (clamp(b.0), clamp(b.1));
        segments.push(vec![(p.0, lo), (p.0, hi)]);
    }
    chart
        .draw_series(
            segments
                .iter()
                .map(|seg| PathElement::new(seg.clone(), color.stroke_width(2))),
        )
        .map_err(plot_error)?;
    // Caps: a short horizontal stroke at each end, in pixels.
    for seg in &segments {
        for &end in seg {
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(end)
                        + PathElement::new(vec![(-5, 0), (5, 0)], color.stroke_width(2)),
                ))
                .map_err(plot_error)?;
        }
    }
    Ok(())
}

/// The legend, in its own panel: a line swatch for lines, a marker (with a bar, if the series
/// has bars) for points; references are labelled on the chart instead.
fn legend(area: &DrawingArea<SVGBackend<'_>, Shift>, series: &[Series]) -> Result<()> {
    let mut y = 60;
    for s in series.iter().filter(|s| s.style != Style::Reference) {
        let color = PALETTE[s.color % PALETTE.len()];
        match s.style {
            Style::Line => area
                .draw(&PathElement::new(
                    vec![(8, y), (32, y)],
                    color.stroke_width(2),
                ))
                .map_err(plot_error)?,
            _ => {
                area.draw(&Circle::new((20, y), 4, color.filled()))
                    .map_err(plot_error)?;
                if s.bars.is_some() {
                    area.draw(&PathElement::new(
                        vec![(20, y - 8), (20, y + 8)],
                        color.stroke_width(2),
                    ))
                    .map_err(plot_error)?;
                }
            }
        }
        area.draw(&Text::new(s.label.clone(), (40, y - 7), ("sans-serif", 13)))
            .map_err(plot_error)?;
        y += 22;
    }
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
