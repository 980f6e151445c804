//! Plots: spectrum images and image strips (PNG, wrapped in SVG), and with the `plot` feature,
//! line plots on linear or log axes (plotters, SVG). Nothing here needs system fonts: SVG text
//! is left to the viewer.

#[cfg(feature = "plot")]
mod lines;
mod polar;

#[cfg(feature = "plot")]
pub use lines::{line_plot, Axes, Series, Style};
pub use polar::{polar_plot, PolarSeries};

use crate::error::{Error, Result};
#[cfg(feature = "plot")]
use crate::spectrum::SpectrumEstimate;
use std::path::Path;

fn plot_error(e: impl std::fmt::Display) -> Error {
    Error::format("plot", e)
}

#[cfg(feature = "plot")]
/// Plots a spectrum estimate: the radial curve (with ±2 standard errors) or, for the lattice,
/// the 2D image with DC in the centre (1D: the curve over k; 3D: the slice `k_2 = 0`).
///
/// # Errors
/// An unwritable file.
pub fn spectrum_plot(path: &Path, label: &str, est: &SpectrumEstimate, radial: bool) -> Result<()> {
    let lattice = est.lattice.lattice;
    let title = format!(
        "{label}: N = {}, {} realizations",
        est.lattice.n, est.lattice.realizations
    );
    if radial || lattice.dimension == 1 {
        let (points, bars) = if radial {
            let bins = &est.radial.bins;
            (
                bins.iter().map(|b| (b.nu, b.power)).collect(),
                Some(
                    bins.iter()
                        .map(|b| (b.power - 2.0 * b.stderr, b.power + 2.0 * b.stderr))
                        .collect(),
                ),
            )
        } else {
            let k = lattice.kmax;
            let nu = |i: usize| (i as f64 - k as f64) / est.lattice.n as f64;
            let pts = (k + 1..lattice.len())
                .map(|i| (nu(i), est.lattice.mean[i]))
                .collect();
            (pts, None)
        };
        let series = Series {
            label: label.to_string(),
            points,
            bars,
            style: Style::Line,
            color: 0,
        };
        let axes = Axes {
            title: format!("radial power spectrum, {title}"),
            x_label: "ν = ρ / N^(1/d)".into(),
            y_label: "power".into(),
            log_x: false,
            log_y: false,
            x_ticks: None,
        };
        return line_plot(path, &axes, &[series]);
    }
    let side = lattice.side();
    let plane = side * side;
    // 3D: the central plane k_0 = 0 holds k_1, k_2; 2D: the whole lattice.
    let start = if lattice.dimension == 3 {
        lattice.kmax * plane
    } else {
        0
    };
    let mut values = est.lattice.mean[start..start + plane].to_vec();
    // DC (value N) would swamp the scale; show it at the level of its neighbours' maximum.
    let centre = plane / 2;
    values[centre] = 0.0;
    spectrum_image(
        path,
        &format!("power spectrum, {title}"),
        &values,
        side,
        lattice.kmax,
    )
}

/// Checks that a plot's file name says what will be written: `.svg`, or `.png` where a bare
/// image is allowed (a 2D spectrum).
///
/// # Errors
/// Any other extension.
pub fn check_plot_path(path: &Path, png_allowed: bool) -> Result<()> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "svg" => Ok(()),
        "png" if png_allowed => Ok(()),
        _ => Err(crate::error::invalid(
            "plot file",
            path.display(),
            if png_allowed {
                "a name ending in .svg or .png"
            } else {
                "a name ending in .svg"
            },
        )),
    }
}

/// Writes `bytes` to `path`.
fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::output::write_atomic(path, bytes)
}

/// Anchors of the viridis colour map (perceptually uniform, readable in grey), from 0 to 1.
const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// The colour of `t` in `[0, 1]` on the viridis map (linear between anchors).
fn viridis(t: f64) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let mix = |a: u8, b: u8| (a as f64 + (b as f64 - a as f64) * f).round() as u8;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    [mix(a[0], b[0]), mix(a[1], b[1]), mix(a[2], b[2])]
}

/// The position of `v` on a log colour scale of `decades` below `max`, in `[0, 1]`.
fn log_position(v: f64, max: f64, decades: f64) -> f64 {
    let floor = max * 10f64.powf(-decades);
    if v > floor && max > 0.0 {
        ((v / floor).log10() / decades).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Encodes a `width × height` grid of values (row-major, top row first) as a colour PNG on a
/// log scale (viridis): yellow is `max`, dark violet `max · 10^-decades` or below. With
/// `max = None`, the largest finite value.
///
/// # Errors
/// Mismatched sizes.
pub fn heatmap_png(
    values: &[f64],
    width: usize,
    height: usize,
    decades: f64,
    max: Option<f64>,
) -> Result<Vec<u8>> {
    if values.len() != width * height || width == 0 {
        return Err(Error::Mismatch(format!(
            "heatmap of {width} × {height} needs {} values, got {}",
            width * height,
            values.len()
        )));
    }
    let max = max.unwrap_or_else(|| {
        values
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max)
    });
    let pixels: Vec<u8> = values
        .iter()
        .flat_map(|&v| viridis(log_position(v, max, decades)))
        .collect();
    rgb_png(&pixels, width, height)
}

/// Encodes 8-bit RGB pixels (row-major, top row first) as PNG.
///
/// # Errors
/// A pixel count other than `width × height`.
pub fn rgb_png(pixels: &[u8], width: usize, height: usize) -> Result<Vec<u8>> {
    if pixels.len() != 3 * width * height {
        return Err(Error::Mismatch(format!(
            "{} RGB bytes for a {width} × {height} image",
            pixels.len()
        )));
    }
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, width as u32, height as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(plot_error)?;
        writer.write_image_data(pixels).map_err(plot_error)?;
    }
    Ok(out)
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

/// Writes images as a grid that reads at page width (940 px, four a row, nearest-neighbour
/// scaling), each captioned underneath, under a title, as SVG with the PNGs embedded.
///
/// # Errors
/// An unwritable file.
pub fn image_strip(path: &Path, title: &str, panels: &[StripPanel]) -> Result<()> {
    const PAGE: f64 = 940.0;
    const COLUMNS: usize = 4;
    let gap = 12.0;
    let cell = (PAGE - gap * (COLUMNS as f64 + 1.0)) / COLUMNS as f64;
    let tallest = panels
        .iter()
        .map(|p| p.height as f64 / p.width.max(1) as f64)
        .fold(1.0f64, f64::max)
        * cell;
    let row_height = tallest + 44.0;
    let mut body = String::new();
    for (i, p) in panels.iter().enumerate() {
        let (col, row) = ((i % COLUMNS) as f64, (i / COLUMNS) as f64);
        let x = gap + col * (cell + gap);
        let y = 36.0 + row * (row_height + gap);
        let h = cell * p.height as f64 / p.width.max(1) as f64;
        body.push_str(&format!(
            r#"<image x="{x}" y="{y}" width="{cell}" height="{h}" style="image-rendering:pixelated" href="data:image/png;base64,{}"/>
<text x="{cx}" y="{t1}" text-anchor="middle" font-size="14">{}</text>
<text x="{cx}" y="{t2}" text-anchor="middle" font-size="12">{}</text>
"#,
            base64(&p.png),
            escape(&p.title),
            escape(&p.caption),
            cx = x + cell / 2.0,
            t1 = y + h + 18.0,
            t2 = y + h + 34.0,
        ));
    }
    let rows = panels.len().div_ceil(COLUMNS).max(1) as f64;
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{PAGE}" height="{total}" font-family="sans-serif">
<rect width="100%" height="100%" fill="white"/>
<text x="{gap}" y="24" font-size="16">{}</text>
{body}</svg>
"#,
        escape(title),
        total = 36.0 + rows * (row_height + gap),
    );
    write_file(path, svg.as_bytes())
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

/// Writes a square spectrum image (side × side values, DC in the centre) on a log colour scale
/// of four decades: as SVG with the whole lattice, a zoom on the low frequencies
/// (`|k_i| ≤ max(4, K/8)`, where the samplers differ) and a colour bar labelled in powers; or as
/// a bare PNG of the whole lattice if `path` ends in `.png`.
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
    const DECADES: f64 = 4.0;
    let max = values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let png = heatmap_png(values, side, side, DECADES, Some(max))?;
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        return write_file(path, &png);
    }
    let zoom = (kmax / 8).max(4).min(kmax);
    let zside = 2 * zoom + 1;
    let first = kmax - zoom;
    let zvalues: Vec<f64> = (0..zside)
        .flat_map(|r| {
            values[(first + r) * side + first..(first + r) * side + first + zside].to_vec()
        })
        .collect();
    let zpng = heatmap_png(&zvalues, zside, zside, DECADES, Some(max))?;
    let bar: Vec<f64> = (0..256)
        .rev()
        .map(|i| max * 10f64.powf(-DECADES * (1.0 - i as f64 / 255.0)))
        .collect();
    let bar_png = heatmap_png(&bar, 1, 256, DECADES, Some(max))?;
    let size = 420;
    let gap = 40;
    let zx = 40 + size + gap;
    let bx = zx + size + 30;
    let mut labels = String::new();
    for d in 0..=DECADES as usize {
        let y = 48 + size - (size as f64 * d as f64 / DECADES) as usize;
        let v = max * 10f64.powi(d as i32 - DECADES as i32);
        labels.push_str(&format!(
            r#"<text x="{}" y="{}" font-size="12">{}</text>
"#,
            bx + 24,
            y + 4,
            short(v)
        ));
    }
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif">
<rect width="100%" height="100%" fill="white"/>
<text x="{cx}" y="24" text-anchor="middle" font-size="16">{title}</text>
<image x="40" y="48" width="{size}" height="{size}" preserveAspectRatio="none" style="image-rendering:pixelated" href="data:image/png;base64,{full}"/>
<text x="40" y="{by}" font-size="12">k = -{kmax}</text>
<text x="{rx}" y="{by}" text-anchor="end" font-size="12">k = {kmax}</text>
<text x="{fcx}" y="{ly}" text-anchor="middle" font-size="12">the whole lattice, DC at the centre</text>
<rect x="{zbx}" y="{zby}" width="{zbw}" height="{zbw}" fill="none" stroke="white" stroke-width="1"/>
<image x="{zx}" y="48" width="{size}" height="{size}" preserveAspectRatio="none" style="image-rendering:pixelated" href="data:image/png;base64,{zoomed}"/>
<text x="{zx}" y="{by}" font-size="12">k = -{zoom}</text>
<text x="{zrx}" y="{by}" text-anchor="end" font-size="12">k = {zoom}</text>
<text x="{zcx}" y="{ly}" text-anchor="middle" font-size="12">zoom: |k_i| ≤ {zoom} (the white square)</text>
<image x="{bx}" y="48" width="20" height="{size}" preserveAspectRatio="none" href="data:image/png;base64,{bar}"/>
{labels}<text x="{bx}" y="{ly}" font-size="12">power (log)</text>
</svg>
"#,
        w = bx + 90,
        h = size + 100,
        cx = (bx + 90) / 2,
        rx = 40 + size,
        by = 48 + size + 16,
        ly = 48 + size + 34,
        fcx = 40 + size / 2,
        zbx = 40.0 + size as f64 * first as f64 / side as f64,
        zby = 48.0 + size as f64 * first as f64 / side as f64,
        zbw = size as f64 * zside as f64 / side as f64,
        zrx = zx + size,
        zcx = zx + size / 2,
        title = escape(title),
        full = base64(&png),
        zoomed = base64(&zpng),
        bar = base64(&bar_png),
    );
    write_file(path, svg.as_bytes())
}

/// A compact number for a colour bar.
fn short(v: f64) -> String {
    if (0.01..1000.0).contains(&v.abs()) {
        let t = format!("{v:.3}");
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
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
