//! Plots: log-scale curves (plotters, SVG) and spectrum images (PNG, optionally wrapped in
//! SVG). Nothing here needs system fonts: SVG text is left to the viewer.

use crate::error::{Error, Result};
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

fn plot_error(e: impl std::fmt::Display) -> Error {
    Error::Io(format!("plot: {e}"))
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
    let xs = series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
    let ys = series.iter().flat_map(|s| {
        let bars = s.bars.iter().flatten().flat_map(|b| [b.0, b.1]);
        s.points.iter().map(|p| p.1).chain(bars)
    });
    let (x0, x1) = range(xs, axes.log_x);
    let (y0, y1) = range(ys, axes.log_y);
    let root = SVGBackend::new(path, (720, 500)).into_drawing_area();
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
    root.present().map_err(plot_error)
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

/// Encodes a `width × height` grid of values (row-major, top row first) as a grayscale PNG on
/// a log scale: white is the largest value, black is `max · 10^-decades` or below.
///
/// # Errors
/// Mismatched sizes.
pub fn heatmap_png(values: &[f64], width: usize, height: usize, decades: f64) -> Result<Vec<u8>> {
    if values.len() != width * height || width == 0 {
        return Err(Error::Mismatch(format!(
            "heatmap of {width} × {height} needs {} values, got {}",
            width * height,
            values.len()
        )));
    }
    let max = values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let floor = max * 10f64.powf(-decades);
    let pixels: Vec<u8> = values
        .iter()
        .map(|&v| {
            let t = if v > floor && max > 0.0 {
                (v / floor).log10() / decades
            } else {
                0.0
            };
            (t.clamp(0.0, 1.0) * 255.0).round() as u8
        })
        .collect();
    gray_png(&pixels, width, height)
}

/// Encodes 8-bit grey pixels (row-major, top row first) as PNG.
///
/// # Errors
/// A pixel count other than `width × height`.
pub fn gray_png(pixels: &[u8], width: usize, height: usize) -> Result<Vec<u8>> {
    if pixels.len() != width * height {
        return Err(Error::Mismatch(format!(
            "{} pixels for a {width} × {height} image",
            pixels.len()
        )));
    }
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, width as u32, height as u32);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(plot_error)?;
        writer.write_image_data(pixels).map_err(plot_error)?;
    }
    Ok(out)
}

/// One captioned image of a strip.
#[derive(Debug, Clone, PartialEq)]
pub struct StripPanel {
    /// First caption line (e.g. the sampler).
    pub title: String,
    /// Second caption line (e.g. the error).
    pub caption: String,
    /// The image, PNG-encoded.
    pub png: Vec<u8>,
    /// Its width in pixels.
    pub width: usize,
    /// Its height in pixels.
    pub height: usize,
}

/// Writes images side by side as SVG (PNGs embedded, shown at least 256 pixels wide with
/// nearest-neighbour scaling), each captioned underneath, under a title.
///
/// # Errors
/// An unwritable file.
pub fn image_strip(path: &Path, title: &str, panels: &[StripPanel]) -> Result<()> {
    let scale = panels
        .iter()
        .map(|p| (256.0 / p.width.max(1) as f64).max(1.0))
        .fold(1.0, f64::max);
    let gap = 12.0;
    let mut x = gap;
    let mut body = String::new();
    let mut tallest: f64 = 0.0;
    for p in panels {
        let (w, h) = (p.width as f64 * scale, p.height as f64 * scale);
        tallest = tallest.max(h);
        body.push_str(&format!(
            r#"<image x="{x}" y="36" width="{w}" height="{h}" style="image-rendering:pixelated" href="data:image/png;base64,{}"/>
<text x="{cx}" y="{t1}" text-anchor="middle" font-size="14">{}</text>
<text x="{cx}" y="{t2}" text-anchor="middle" font-size="12">{}</text>
"#,
            base64(&p.png),
            escape(&p.title),
            escape(&p.caption),
            cx = x + w / 2.0,
            t1 = 36.0 + h + 18.0,
            t2 = 36.0 + h + 34.0,
        ));
        x += w + gap;
    }
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{x}" height="{total}" font-family="sans-serif">
<rect width="100%" height="100%" fill="white"/>
<text x="{gap}" y="24" font-size="16">{}</text>
{body}</svg>
"#,
        escape(title),
        total = 36.0 + tallest + 44.0,
    );
    std::fs::write(path, svg).map_err(|e| Error::Io(format!("{}: {e}", path.display())))
}

/// Standard base64 (RFC 4648) with padding, for embedding images in SVG.
fn base64(data: &[u8]) -> String {
    const TABLE: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(data.len().div_ceil(3) * 4);
    for chunk in data.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for i in 0..4 {
            if i <= chunk.len() {
                out.push(TABLE[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Writes a square spectrum image (side × side values, DC in the centre) as SVG with the PNG
/// embedded, a title and the frequency range; or as a bare PNG if `path` ends in `.png`.
///
/// # Errors
/// Mismatched sizes or an unwritable file.
pub fn spectrum_image(
    path: &Path,
    title: &str,
    values: &[f64],
    side: usize,
    kmax: usize,
) -> Result<()> {
    let png = heatmap_png(values, side, side, 4.0)?;
    let write = |bytes: &[u8]| {
        std::fs::write(path, bytes).map_err(|e| Error::Io(format!("{}: {e}", path.display())))
    };
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return write(&png);
    }
    let size = 512;
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">
<rect width="100%" height="100%" fill="white"/>
<text x="{cx}" y="22" text-anchor="middle" font-family="sans-serif" font-size="16">{title}</text>
<image x="40" y="36" width="{size}" height="{size}" preserveAspectRatio="none" style="image-rendering:pixelated" href="data:image/png;base64,{data}"/>
<text x="40" y="{by}" font-family="sans-serif" font-size="12">k = -{kmax}</text>
<text x="{rx}" y="{by}" text-anchor="end" font-family="sans-serif" font-size="12">k = {kmax}</text>
<text x="{cx}" y="{ly}" text-anchor="middle" font-family="sans-serif" font-size="12">log scale, 4 decades; DC at the centre</text>
</svg>
"#,
        w = size + 80,
        h = size + 90,
        cx = 40 + size / 2,
        rx = 40 + size,
        by = 36 + size + 16,
        ly = 36 + size + 34,
        title = escape(title),
        data = base64(&png),
    );
    write(svg.as_bytes())
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        assert_eq!(base64(b""), "");
        assert_eq!(base64(b"f"), "Zg==");
        assert_eq!(base64(b"fo"), "Zm8=");
        assert_eq!(base64(b"foo"), "Zm9v");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }
}
