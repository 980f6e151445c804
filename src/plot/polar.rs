//! A polar plot of a quantity against a direction, as plain SVG: the variance of an edge
//! against its angle reads as a shape (a circle for an isotropic sampler, a cross for one that
//! stratifies the axes).

use crate::error::Result;
use std::fmt::Write as _;
use std::path::Path;

/// Values measured at angles, drawn as a closed curve or as markers with radial bars.
#[derive(Debug, Clone)]
pub struct PolarSeries {
    /// Legend label.
    pub label: String,
    /// `(angle in degrees, value)` pairs; each is also drawn at `angle + 180°` (an edge and
    /// its complement have the same variance).
    pub points: Vec<(f64, f64)>,
    /// Optional `(low, high)` per point, drawn as radial bars; the series is then markers.
    pub bars: Option<Vec<(f64, f64)>>,
}

/// An angle in degrees, its value, and the value's bar if any.
type Marked = (f64, f64, Option<(f64, f64)>);

const SIZE: f64 = 560.0;
const LEGEND: f64 = 260.0;
const COLOURS: [&str; 4] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"];

/// Writes a polar plot: radius linear from 0 to the largest value (bars included), four
/// labelled rings, spokes every 30°.
///
/// # Errors
/// An unwritable file.
pub fn polar_plot(path: &Path, title: &str, series: &[PolarSeries]) -> Result<()> {
    let top = series
        .iter()
        .flat_map(|s| {
            let bars = s.bars.iter().flatten().map(|b| b.1);
            s.points.iter().map(|p| p.1).chain(bars)
        })
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let (cx, cy, radius) = (SIZE / 2.0, SIZE / 2.0 + 20.0, SIZE / 2.0 - 50.0);
    let at = |angle: f64, value: f64| {
        let t = angle.to_radians();
        let r = radius * value / top;
        (cx + r * t.cos(), cy - r * t.sin())
    };
    let mut svg = String::new();
    let _ = write!(
        svg,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         font-family=\"sans-serif\"><rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\
         <text x=\"10\" y=\"22\" font-size=\"15\">{title}</text>",
        w = SIZE + LEGEND,
        h = SIZE + 40.0
    );
    for ring in 1..=4 {
        let v = top * ring as f64 / 4.0;
        let r = radius * ring as f64 / 4.0;
        let _ = write!(
            svg,
            "<circle cx=\"{cx}\" cy=\"{cy}\" r=\"{r}\" fill=\"none\" stroke=\"#ccc\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" fill=\"#555\">{v:.2e}</text>",
            cx + 3.0,
            cy - r - 3.0
        );
    }
    for spoke in 0..12 {
        let angle = spoke as f64 * 30.0;
        let (x, y) = at(angle, top * 1.05);
        let _ = write!(
            svg,
            "<line x1=\"{cx}\" y1=\"{cy}\" x2=\"{x:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" text-anchor=\"middle\">{angle}°</text>",
            cx + (x - cx) * 1.07,
            cy + (y - cy) * 1.07 + 4.0
        );
    }
    for (j, s) in series.iter().enumerate() {
        let colour = COLOURS[j % COLOURS.len()];
        let mut all: Vec<Marked> = Vec::new();
        for half in [0.0, 180.0] {
            for (i, &(a, v)) in s.points.iter().enumerate() {
                all.push((a + half, v, s.bars.as_ref().map(|b| b[i])));
            }
        }
        match &s.bars {
            None => {
                // Closed: the last angle joins the first again.
                let path: Vec<String> = all
                    .iter()
                    .chain(all.first())
                    .map(|&(a, v, _)| {
                        let (x, y) = at(a, v);
                        format!("{x:.1},{y:.1}")
                    })
                    .collect();
                let _ = write!(
                    svg,
                    "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\"/>",
                    path.join(" ")
                );
            }
            Some(_) => {
                for &(a, v, bar) in &all {
                    let (x, y) = at(a, v);
                    if let Some((lo, hi)) = bar {
                        let (x0, y0) = at(a, lo);
                        let (x1, y1) = at(a, hi);
                        let _ = write!(
                            svg,
                            "<line x1=\"{x0:.1}\" y1=\"{y0:.1}\" x2=\"{x1:.1}\" y2=\"{y1:.1}\" \
                             stroke=\"{colour}\" stroke-width=\"1.5\"/>"
                        );
                    }
                    let _ = write!(
                        svg,
                        "<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"3\" fill=\"{colour}\"/>"
                    );
                }
            }
        }
        let ly = 60.0 + 24.0 * j as f64;
        let _ = write!(
            svg,
            "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"18\" height=\"4\" fill=\"{colour}\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" font-size=\"12\">{}</text>",
            SIZE + 10.0,
            ly - 4.0,
            SIZE + 34.0,
            ly + 2.0,
            s.label
        );
    }
    let _ = write!(
        svg,
        "<text x=\"{:.1}\" y=\"{:.1}\" font-size=\"11\" fill=\"#555\">radius: variance (linear)</text></svg>",
        SIZE + 10.0,
        60.0 + 24.0 * series.len() as f64 + 10.0
    );
    crate::output::write_atomic(path, svg.as_bytes())
}
