//! The comparison run: every sampler at one ray count, measured and predicted, with a table
//! and a side-by-side strip of the images.

use super::{
    measure_mse, predict_mse, render_ao, Frame, MseEstimate, PixelPowerParams, Reference,
    RenderParams,
};
use crate::error::{Error, Result};
use crate::plot::{image_strip, StripPanel};
use crate::predict::{LatticePower, Prediction};
use crate::render::AoImage;
use crate::sampler::SamplerKind;
use indicatif::ProgressBar;
use std::fmt::Write as _;
use std::path::Path;

/// The talk's measured MSE at 96 secondary rays on its own Cornell-box render.
pub const TALK_MSE: [(&str, f64); 4] = [
    ("random", 4.74e-3),
    ("jitter", 8.56e-4),
    ("poisson", 6.95e-4),
    ("ccvt", 4.24e-4),
];

/// One sampler's render: measured and predicted MSE.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ComparisonRow {
    /// Sampler name.
    pub sampler: String,
    /// Rays per pixel.
    pub rays: usize,
    /// The measured MSE.
    pub measured: MseEstimate,
    /// The lattice-form prediction from the sampler's spectrum at this N.
    pub predicted: Prediction,
    /// The talk's MSE for this sampler, where it gives one.
    pub talk: Option<f64>,
    /// The image.
    #[serde(skip)]
    pub image: AoImage,
}

impl ComparisonRow {
    /// `(predicted - measured) / σ`, with `σ` the measured MSE's and the prediction's spectrum
    /// noise standard errors combined.
    pub fn z_score(&self) -> f64 {
        let sigma = self.measured.stderr.hypot(self.predicted.spectrum_stderr);
        (self.predicted.variance - self.measured.mse) / sigma
    }
}

/// Renders each sampler in `names` with `params`, measures it against `reference`, and
/// predicts it from `power` with a spectrum of `spectrum_realizations` patterns of seed
/// `params.seed + 1` (independent of the rendered patterns). `progress` shows the rows.
///
/// # Errors
/// An unknown sampler or one that cannot produce `params.rays` points in 2D, or a reference of
/// another size.
pub fn compare(
    frame: &Frame,
    names: &[&str],
    params: &RenderParams,
    reference: &Reference,
    power: &LatticePower,
    spectrum_realizations: usize,
    progress: &ProgressBar,
) -> Result<Vec<ComparisonRow>> {
    names
        .iter()
        .map(|&name| {
            let sampler = SamplerKind::from_name(name)?.build(2)?;
            progress.set_message(format!("rendering {name} at {} rays", params.rays));
            progress.set_length(frame.height() as u64);
            progress.set_position(0);
            let rendering = render_ao(frame, sampler.as_ref(), params, &|| progress.inc(1))?;
            progress.set_message(format!("spectrum of {name} at N = {}", params.rays));
            let predicted = predict_mse(
                sampler.as_ref(),
                power,
                params.rays,
                spectrum_realizations,
                params.seed.wrapping_add(1),
            )?;
            Ok(ComparisonRow {
                sampler: name.to_string(),
                rays: params.rays,
                measured: measure_mse(&rendering, reference)?,
                predicted,
                talk: TALK_MSE.iter().find(|t| t.0 == name).map(|t| t.1),
                image: rendering.image,
            })
        })
        .collect()
}

/// The ratio of two rows' measured MSE, if both are present.
pub fn measured_ratio(rows: &[ComparisonRow], a: &str, b: &str) -> Option<f64> {
    let find = |s: &str| rows.iter().find(|r| r.sampler == s);
    Some(find(a)?.measured.mse / find(b)?.measured.mse)
}

/// The comparison as a Markdown table.
pub fn comparison_table(rows: &[ComparisonRow]) -> String {
    let mut out = String::from(
        "| sampler | rays | measured MSE | ± stderr | predicted MSE | ± spectrum noise | \
         predicted / measured | z | talk's MSE |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.4e} | {:.1e} | {:.4e} | {:.1e} | {:.3} | {:+.1} | {} |",
            r.sampler,
            r.rays,
            r.measured.mse,
            r.measured.stderr,
            r.predicted.variance,
            r.predicted.spectrum_stderr,
            r.predicted.variance / r.measured.mse,
            r.z_score(),
            r.talk.map_or("".into(), |t| format!("{t:.2e}")),
        );
    }
    out
}

/// Writes the comparison into `dir`: `ao-<sampler>.png` per sampler, `reference.png`,
/// `comparison.md` (the table), `comparison.json` and `strip.svg` (the images side by side).
///
/// # Errors
/// An unwritable directory or file.
pub fn write_comparison(dir: &Path, rows: &[ComparisonRow], reference: &Reference) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::Io(format!("{}: {e}", dir.display())))?;
    reference.image.write_png(&dir.join("reference.png"))?;
    let mut panels = vec![StripPanel {
        title: "reference".into(),
        caption: format!("{} random rays", reference.key.rays),
        png: reference.image.to_png()?,
        width: reference.image.width,
        height: reference.image.height,
    }];
    for r in rows {
        r.image
            .write_png(&dir.join(format!("ao-{}.png", r.sampler)))?;
        panels.push(StripPanel {
            title: r.sampler.clone(),
            caption: format!(
                "MSE {:.2e} (pred. {:.2e})",
                r.measured.mse, r.predicted.variance
            ),
            png: r.image.to_png()?,
            width: r.image.width,
            height: r.image.height,
        });
    }
    let rays = rows.first().map_or(0, |r| r.rays);
    image_strip(
        &dir.join("strip.svg"),
        &format!("Ambient occlusion, {rays} secondary rays per pixel"),
        &panels,
    )?;
    let write = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| Error::Io(format!("{}: {e}", path.display())))
    };
    write("comparison.md", comparison_table(rows))?;
    write(
        "comparison.json",
        serde_json::to_string_pretty(rows).map_err(|e| Error::Io(e.to_string()))?,
    )
}

/// Everything a comparison run needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonConfig {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// The samplers, by name.
    pub samplers: Vec<String>,
    /// Rays, distance, seed and pattern pool.
    pub render: RenderParams,
    /// Rays per pixel of the reference (cached in `cache_dir`).
    pub reference_rays: usize,
    /// The rasterization behind the prediction.
    pub pixel_power: PixelPowerParams,
    /// Realizations of each sampler's spectrum at N.
    pub spectrum_realizations: usize,
    /// Where the reference is cached.
    pub cache_dir: std::path::PathBuf,
}

impl Default for ComparisonConfig {
    fn default() -> Self {
        Self {
            width: 128,
            height: 128,
            samplers: all_2d_samplers(),
            render: RenderParams::default(),
            reference_rays: 16384,
            pixel_power: PixelPowerParams::default(),
            spectrum_realizations: 512,
            cache_dir: "render".into(),
        }
    }
}

/// The names of every sampler that works in 2D.
pub fn all_2d_samplers() -> Vec<String> {
    SamplerKind::ALL
        .iter()
        .filter(|k| k.build(2).is_ok())
        .map(|k| k.name().to_string())
        .collect()
}

/// A finished comparison run.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// One row per sampler.
    pub rows: Vec<ComparisonRow>,
    /// The reference.
    pub reference: Reference,
    /// Whether the reference came from the cache.
    pub reference_cached: bool,
    /// What the prediction's integrand is.
    pub power_label: String,
}

/// Runs a comparison: traces the frame, loads or renders the reference, rasterizes the pixels'
/// visibilities once, then renders, measures and predicts every sampler (progress on stderr).
///
/// # Errors
/// As [`compare`], [`super::cached_reference`] and [`super::pixel_power`].
pub fn run_comparison(config: &ComparisonConfig) -> Result<Comparison> {
    // Every request is checked before the expensive reference.
    config.render.check()?;
    for name in &config.samplers {
        SamplerKind::from_name(name)?
            .build(2)?
            .check_count(config.render.rays)?;
    }
    let frame = Frame::new(
        super::geometry::Scene::cornell_box(),
        config.width,
        config.height,
    )?;
    let bar = crate::progress::bar(
        config.height as u64,
        format!("reference ({} rays per pixel)", config.reference_rays),
    );
    let (reference, reference_cached) = super::cached_reference(
        &config.cache_dir,
        &frame,
        config.reference_rays,
        config.render.max_distance,
        config.render.seed,
        &|| bar.inc(1),
    )?;
    let stride = config.pixel_power.stride;
    bar.set_message(format!(
        "visibility grids ({}² per pixel)",
        config.pixel_power.resolution
    ));
    bar.set_length(config.height.div_ceil(stride) as u64);
    bar.set_position(0);
    let power = super::pixel_power(
        &frame,
        config.render.max_distance,
        &config.pixel_power,
        &|| bar.inc(1),
    )?;
    let names: Vec<&str> = config.samplers.iter().map(String::as_str).collect();
    let rows = compare(
        &frame,
        &names,
        &config.render,
        &reference,
        &power,
        config.spectrum_realizations,
        &bar,
    )?;
    bar.finish_and_clear();
    Ok(Comparison {
        rows,
        reference,
        reference_cached,
        power_label: power.label,
    })
}
