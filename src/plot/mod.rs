//! Plots: spectrum images and image strips (PNG, wrapped in SVG), and with the `plot` feature,
//! line plots on linear or log axes (plotters, SVG). Nothing here needs system fonts: SVG text
//! is left to the viewer.

#[cfg(feature = "plot")]
mod lines;

#[cfg(feature = "plot")]
pub use lines::{line_plot, Axes, Series, Style};

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
    let write = |bytes: &[u8]| write_file(path, bytes);
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
