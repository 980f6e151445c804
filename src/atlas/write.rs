//! The atlas as Markdown with its figures.

use super::{Atlas, AtlasEntry, ALPHA_BAND};
use crate::error::{Error, Result};
use crate::metrics::hexagonal_nyquist;
use std::fmt::Write as _;
use std::path::Path;

/// Side of a point-set picture, in pixels.
#[cfg(feature = "plot")]
const PICTURE: usize = 200;
/// The spectra pictures' colour scale: yellow at a power of 4 (above every blue-noise peak),
/// four decades down to dark violet.
#[cfg(feature = "plot")]
const SPECTRUM_MAX: f64 = 4.0;

/// Writes `atlas.md`, `atlas.json` and the figures into `dir`, replacing specvar's earlier
/// output there only once all of it is written (the user's own files stay).
///
/// # Errors
/// An unwritable directory or file.
pub fn write_atlas(atlas: &Atlas, dir: &Path) -> Result<()> {
    crate::output::write_dir(dir, |tmp| {
        #[cfg(feature = "plot")]
        figures(atlas, tmp)?;
        let json =
            serde_json::to_string_pretty(atlas).map_err(|e| Error::format("atlas.json", e))?;
        crate::output::write_atomic(&tmp.join("atlas.json"), json.as_bytes())?;
        crate::output::write_atomic(&tmp.join("atlas.md"), atlas_markdown(atlas).as_bytes())
    })
}

#[cfg(feature = "plot")]
fn figures(atlas: &Atlas, dir: &Path) -> Result<()> {
    use crate::plot::{
        gray_png, heatmap_png, image_strip, line_plot, Axes, Series, StripPanel, Style,
    };
    let mut points = Vec::new();
    let mut spectra = Vec::new();
    for e in &atlas.entries {
        points.push(StripPanel {
            title: e.sampler.to_string(),
            caption: format!("N = {}", e.n),
            png: gray_png(&picture(&e.points), PICTURE, PICTURE)?,
            width: PICTURE,
            height: PICTURE,
        });
        let side = e.spectrum.lattice.lattice.side();
        let mut values = e.spectrum.lattice.mean.clone();
        values[side * side / 2] = 0.0; // DC (N) would swamp the scale
        spectra.push(StripPanel {
            title: e.sampler.to_string(),
            caption: format!("|k_i| ≤ {}", e.spectrum.lattice.lattice.kmax),
            png: heatmap_png(&values, side, side, 4.0, Some(SPECTRUM_MAX))?,
            width: side,
            height: side,
        });
        let radial = Series {
            label: format!("{}, N = {}", e.sampler, e.n),
            points: e
                .spectrum
                .radial
                .bins
                .iter()
                .map(|b| (b.nu, b.power))
                .collect(),
            bars: Some(
                e.spectrum
                    .radial
                    .bins
                    .iter()
                    .map(|b| (b.power - 2.0 * b.stderr, b.power + 2.0 * b.stderr))
                    .collect(),
            ),
            style: Style::Points,
            color: 0,
        };
        let axes = Axes {
            title: format!(
                "radial power spectrum, {}: N = {}, {} patterns",
                e.sampler, e.n, e.spectrum.radial.realizations
            ),
            x_label: "ν = |k| / √N".into(),
            y_label: "power (±2 standard errors)".into(),
            ..Axes::default()
        };
        line_plot(
            &dir.join(format!("radial-{}.svg", e.sampler)),
            &axes,
            &[radial],
        )?;
        let pcf = Series {
            label: format!("{}, N = {}", e.sampler, e.n),
            points: e
                .pcf
                .radius_in_spacings
                .iter()
                .copied()
                .zip(e.pcf.g.iter().copied())
                .collect(),
            bars: None,
            style: Style::Line,
            color: 1,
        };
        let axes = Axes {
            title: format!(
                "pair correlation function, {}: N = {}, {} patterns",
                e.sampler, e.n, e.pcf.patterns
            ),
            x_label: "r / mean spacing".into(),
            y_label: "g(r)".into(),
            ..Axes::default()
        };
        line_plot(&dir.join(format!("pcf-{}.svg", e.sampler)), &axes, &[pcf])?;
    }
    image_strip(
        &dir.join("points.svg"),
        "one pattern of each sampler",
        &points,
    )?;
    image_strip(
        &dir.join("spectra.svg"),
        "expected power spectra (log scale: yellow 4, dark violet 4e-4; DC blanked)",
        &spectra,
    )
}

/// A white picture with each point as a black 3 × 3 dot.
#[cfg(feature = "plot")]
fn picture(points: &crate::PointSet) -> Vec<u8> {
    let mut pixels = vec![255u8; PICTURE * PICTURE];
    for p in points.points() {
        let (cx, cy) = (
            (p[0] * PICTURE as f64) as isize,
            ((1.0 - p[1]) * PICTURE as f64) as isize,
        );
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (x, y) = (cx + dx, cy + dy);
                if (0..PICTURE as isize).contains(&x) && (0..PICTURE as isize).contains(&y) {
                    pixels[y as usize * PICTURE + x as usize] = 0;
                }
            }
        }
    }
    pixels
}

fn alpha_text(e: &AtlasEntry) -> String {
    let fitted = match &e.alpha_fit {
        Ok(f) => format!("{:.2} [{:.2}, {:.2}]", f.alpha, f.ci.0, f.ci.1),
        Err(_) => "no fit".into(),
    };
    match e.known_alpha {
        Some(a) => format!("{a} (fit {fitted})"),
        None => fitted,
    }
}

fn rate_text(rate: Option<(f64, bool)>) -> String {
    match rate {
        Some((r, true)) => format!("N^{r:.2} log N"),
        Some((r, false)) => format!("N^{r:.2}"),
        None => "—".into(),
    }
}

/// The atlas as Markdown.
pub fn atlas_markdown(atlas: &Atlas) -> String {
    let c = &atlas.config;
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Sampler atlas\n\nEvery 2D sampler at N = {} (or its nearest valid count): one pattern, \
         the expected spectrum of {} patterns (a quarter for costly samplers), the low-frequency \
         exponent α fitted on ν ≤ {ALPHA_BAND} at N = {}, the effective Nyquist frequency \
         (the spectrum below 0.1 up to it; the hexagonal lattice's is {:.3}), the pair \
         correlation function, the squared discrepancies, and the default prediction of the \
         variance on the disk and the Gaussian of the talk beside Monte Carlo ({} evaluations, \
         99% intervals), both for the {} estimator ({}). The rate is the asymptotic one from α \
         and the integrand's decay, for the shifted estimator. Seed {}.\n",
        c.n,
        c.realizations,
        c.alpha_n,
        hexagonal_nyquist(),
        c.trials,
        c.randomization.estimator(),
        c.randomization.per_trial(),
        c.seed
    );
    md.push_str("![points](points.svg)\n\n![spectra](spectra.svg)\n\n");
    md.push_str(
        "| sampler | N | α | ν_eff | min / mean nearest distance | centred L2² | disk: predicted | Monte Carlo | z | Gaussian: predicted | Monte Carlo | z |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for e in &atlas.entries {
        let nu = e
            .effective_nyquist
            .map_or("—".into(), |v| format!("{v:.3}"));
        let cd = e
            .discrepancies
            .iter()
            .find(|d| d.0 == crate::metrics::DiscrepancyKind::Centred);
        let _ = write!(
            md,
            "| {} | {} | {} | {nu} | {:.3} / {:.3} | {} |",
            e.sampler,
            e.n,
            alpha_text(e),
            e.distances.min_distance,
            e.distances.mean_min_distance,
            cd.map_or("—".into(), |d| format!("{:.3e}", d.1.mean)),
        );
        for r in &e.rows {
            let _ = write!(
                md,
                " {} | {} | {}{} |",
                r.predicted
                    .as_ref()
                    .map_or("no route".into(), |p| format!("{:.4e}", p.variance)),
                measured_text(r.measured.as_ref()),
                r.z.map_or("—".into(), |z| format!("{z:+.2}")),
                if r.agrees() == Some(false) {
                    " **miss**"
                } else {
                    ""
                }
            );
        }
        md.push('\n');
    }
    for e in &atlas.entries {
        md.push_str(&entry_markdown(e));
    }
    md
}

fn entry_markdown(e: &AtlasEntry) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "\n## {}\n\n{}\n", e.sampler, e.sampler.description());
    let _ = writeln!(
        md,
        "![radial spectrum](radial-{0}.svg)\n![pair correlation](pcf-{0}.svg)\n",
        e.sampler
    );
    let _ = writeln!(md, "- α: {}", alpha_text(e));
    if let Err(reason) = &e.alpha_fit {
        let _ = writeln!(md, "  (no power law to fit: {reason})");
    }
    match e.effective_nyquist {
        Some(v) => {
            let _ = writeln!(
                md,
                "- effective Nyquist frequency: ν = {v:.3}, {:.0}% of the hexagonal lattice's",
                100.0 * v / hexagonal_nyquist()
            );
        }
        None => md.push_str("- effective Nyquist frequency: none (the first ring is above 0.1)\n"),
    }
    let _ = writeln!(
        md,
        "- nearest distances (of the densest packing's): smallest {:.3}, mean {:.3}",
        e.distances.min_distance, e.distances.mean_min_distance
    );
    for (kind, m) in &e.discrepancies {
        let _ = writeln!(
            md,
            "- {} discrepancy²: {:.4e} ± {:.1e}",
            kind.name(),
            m.mean,
            m.stderr
        );
    }
    for r in &e.rows {
        let predicted = match (&r.predicted, r.z) {
            (Some(p), Some(z)) => {
                format!("predicted {:.4e} ({}), z = {z:+.2}", p.variance, p.route)
            }
            _ => format!(
                "no prediction ({})",
                r.unpredicted.as_deref().unwrap_or("no route")
            ),
        };
        let _ = writeln!(
            md,
            "- {} ({}): {predicted}; Monte Carlo {}; rate {}",
            r.integrand,
            r.randomization.estimator(),
            measured_text(r.measured.as_ref()),
            rate_text(r.rate)
        );
    }
    md
}

/// A Monte Carlo variance with its 99% interval, or why there is none.
fn measured_text(m: Option<&crate::montecarlo::McResult>) -> String {
    m.map_or(
        "— (a fixed pattern as drawn: a bias, no variance)".into(),
        |m| format!("{:.4e} [{:.3e}, {:.3e}]", m.variance, m.ci_low, m.ci_high),
    )
}
