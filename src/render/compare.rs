//! The comparison run: every sampler at one ray count, measured and predicted, with a table
//! and a side-by-side strip of the images.

use super::{
    measure_mse, predict_mse, predict_mse_per_pixel, render_ao, Frame, MseEstimate,
    PixelPowerParams, Reference, RenderParams,
};
use crate::error::{Error, Result};
use crate::plot::{image_strip, StripPanel};
use crate::predict::{LatticePower, Prediction};
use crate::progress::Progress;
use crate::render::AoImage;
use crate::sampler::SamplerKind;
use std::fmt::Write as _;
use std::path::Path;

/// The talk's measured MSE at 96 secondary rays on its own Cornell-box render.
pub const TALK_MSE: [(SamplerKind, f64); 4] = [
    (SamplerKind::Random, 4.74e-3),
    (SamplerKind::Jitter, 8.56e-4),
    (SamplerKind::PoissonDisk, 6.95e-4),
    (SamplerKind::Ccvt, 4.24e-4),
];

/// The talk's measured MSE for a sampler (NaN for a sampler the talk did not render).
pub fn talk_mse(sampler: SamplerKind) -> f64 {
    TALK_MSE
        .iter()
        .find(|t| t.0 == sampler)
        .map_or(f64::NAN, |t| t.1)
}

/// The ratio of two samplers' MSE in the talk's render, where it rendered both.
///
/// # Examples
/// ```
/// use specvar::render::talk_ratio;
/// use specvar::sampler::SamplerKind;
/// let r = talk_ratio(SamplerKind::Random, SamplerKind::Jitter).unwrap();
/// assert!((r - 5.54).abs() < 0.005);
/// assert!(talk_ratio(SamplerKind::Sobol, SamplerKind::Jitter).is_none());
/// ```
pub fn talk_ratio(a: SamplerKind, b: SamplerKind) -> Option<f64> {
    let ratio = talk_mse(a) / talk_mse(b);
    ratio.is_finite().then_some(ratio)
}

/// One sampler's render: measured and predicted MSE.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ComparisonRow {
    /// The sampler.
    pub sampler: SamplerKind,
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
    /// The gap between prediction and measurement beyond the prediction's systematic bounds
    /// (quadrature, truncation, model), in units of `σ`, the measured MSE's and the prediction's
    /// spectrum-noise standard errors combined; 0 when the bounds cover the gap.
    pub fn z_score(&self) -> f64 {
        let b = &self.predicted.budget;
        let sigma = self.measured.stderr.hypot(b.spectrum_noise);
        let gap = self.predicted.variance - self.measured.mse;
        let systematic = b.bounds();
        gap.signum() * (gap.abs() - systematic).max(0.0) / sigma
    }
}

/// Renders each sampler of `config.samplers` with `config.render`, measures it against
/// `reference`, and predicts it from `power` with a spectrum of `config.spectrum_realizations`
/// patterns of seed `config.render.seed + 1` (independent of the rendered patterns). Costly
/// patterns are kept in `config.cache_dir` ([`crate::cache::cached_sampler`]). `progress`
/// follows the rows.
///
/// # Errors
/// An unknown sampler or one that cannot produce `params.rays` points in 2D, or a reference of
/// another size.
pub fn compare(
    frame: &Frame,
    config: &ComparisonConfig,
    reference: &Reference,
    power: &LatticePower,
    progress: &dyn Progress,
) -> Result<Vec<ComparisonRow>> {
    let (params, cache) = (&config.render, config.cache_dir.as_deref());
    let spectrum_realizations = config.spectrum_realizations;
    config
        .samplers
        .iter()
        .map(|&kind| {
            let sampler =
                crate::cache::cached_sampler(kind, 2, cache, crate::cache::PATTERN_MEMORY)?;
            let stage = format!("rendering {kind} at {} rays", params.rays);
            progress.begin(&stage, frame.height() as u64);
            let rendering = render_ao(frame, sampler.as_ref(), params, progress)?;
            progress.end();
            let randomization = rendering.randomization;
            let shifted_law = kind.facts().randomness.why_shifted_variance(randomization);
            let predicted = match shifted_law {
                // Where the estimator has the shifted one's variance, the pixels' mean power
                // carries the whole image.
                Some(why) => {
                    progress.begin(&format!("spectrum of {kind} at N = {}", params.rays), 0);
                    let p = predict_mse(
                        sampler.as_ref(),
                        power,
                        params.rays,
                        spectrum_realizations,
                        params.seed.wrapping_add(1),
                    );
                    progress.end();
                    Prediction {
                        randomization,
                        reason: format!("{kind} {}: {why}", randomization.estimator()),
                        ..p?
                    }
                }
                None => {
                    progress.begin(
                        &format!("{kind} pixel by pixel, {}", randomization.estimator()),
                        0,
                    );
                    let p = predict_mse_per_pixel(
                        frame,
                        sampler.as_ref(),
                        randomization,
                        params.rays,
                        params.max_distance,
                        &config.pixel_power,
                        params.seed.wrapping_add(1),
                    );
                    progress.end();
                    p?
                }
            };
            Ok(ComparisonRow {
                sampler: kind,
                rays: params.rays,
                measured: measure_mse(&rendering, reference)?,
                predicted,
                talk: TALK_MSE.iter().find(|t| t.0 == kind).map(|t| t.1),
                image: rendering.image,
            })
        })
        .collect()
}

/// The ratio of two rows' measured MSE, if both are present.
pub fn measured_ratio(rows: &[ComparisonRow], a: SamplerKind, b: SamplerKind) -> Option<f64> {
    let find = |s: SamplerKind| rows.iter().find(|r| r.sampler == s);
    Some(find(a)?.measured.mse / find(b)?.measured.mse)
}

/// The comparison as a Markdown table.
pub fn comparison_table(rows: &[ComparisonRow]) -> String {
    let mut out = String::from(
        "| sampler | rays | measured MSE | ± stderr | predicted MSE | ± spectrum noise | \
         ± bounds | predicted / measured | z beyond the bounds | talk's MSE |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.4e} | {:.1e} | {:.4e} | {:.1e} | {:.1e} | {:.3} | {:+.1} | {} |",
            r.sampler,
            r.rays,
            r.measured.mse,
            r.measured.stderr,
            r.predicted.variance,
            r.predicted.budget.spectrum_noise,
            r.predicted.budget.bounds(),
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
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
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
            title: r.sampler.to_string(),
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
    let write =
        |name: &str, text: String| crate::output::write_atomic(&dir.join(name), text.as_bytes());
    write("comparison.md", comparison_table(rows))?;
    write(
        "comparison.json",
        serde_json::to_string_pretty(rows).map_err(|e| Error::format("comparison.json", e))?,
    )
}

/// Everything a comparison run needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ComparisonConfig {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// The samplers.
    pub samplers: Vec<SamplerKind>,
    /// Rays, distance, seed and pattern pool.
    pub render: RenderParams,
    /// Rays per pixel of the reference (cached in `cache_dir`).
    pub reference_rays: usize,
    /// The rasterization behind the prediction.
    pub pixel_power: PixelPowerParams,
    /// Realizations of each sampler's spectrum at N.
    pub spectrum_realizations: usize,
    /// Where the reference and the pixels' mean visibility power are cached
    /// ([`crate::cache::default_dir`] by default; `None`: they are computed every time).
    pub cache_dir: Option<std::path::PathBuf>,
}

impl Default for ComparisonConfig {
    fn default() -> Self {
        Self {
            width: 128,
            height: 128,
            samplers: samplers_for_rays(RenderParams::default().rays),
            render: RenderParams::default(),
            reference_rays: 16384,
            pixel_power: PixelPowerParams::default(),
            spectrum_realizations: 512,
            cache_dir: Some(crate::cache::default_dir()),
        }
    }
}

impl ComparisonConfig {
    /// Checks every parameter before any work: the render's, the samplers' ray count, the
    /// prediction's grid, stride, lattice and realizations, and the work the reference and the
    /// renders imply (about 60 ns a ray) against the default budget.
    ///
    /// # Errors
    /// The first parameter out of range.
    pub fn check(&self) -> Result<()> {
        self.render.check()?;
        for kind in &self.samplers {
            kind.build(2)?.check_count(self.render.rays)?;
        }
        self.pixel_power.check()?;
        if self.spectrum_realizations < 2 {
            return Err(crate::error::invalid(
                "spectrum realizations",
                self.spectrum_realizations,
                "at least 2, so that the prediction's noise can be estimated",
            ));
        }
        if self.reference_rays < 2 {
            return Err(crate::error::invalid(
                "reference rays",
                self.reference_rays,
                "at least 2",
            ));
        }
        // In floating point: products of usizes could wrap and pass the budget.
        let pixels = self.width as f64 * self.height as f64;
        let rays = pixels
            * (self.reference_rays as f64 + self.render.rays as f64 * self.samplers.len() as f64);
        // The per-pixel route's grids, as fine as the tabulation of the structured samplers'
        // pixels asks.
        let resolution = self
            .pixel_power
            .tabulation_resolution(self.render.rays, crate::sampler::AxisStrata::Spacing)?;
        let grids = pixels / (self.pixel_power.stride as f64).powi(2) * (resolution as f64).powi(2);
        let needs = crate::budget::Needs {
            // Each distinct pattern's points, kept while the image renders.
            memory_bytes: self.render.patterns as f64 * self.render.rays as f64 * 16.0,
            work_seconds: (rays + grids) * 60e-9,
        };
        crate::budget::Budget::default().check(
            "the render",
            needs,
            "lower the image size or the rays",
        )
    }
}

/// Every sampler that works in 2D.
pub fn all_2d_samplers() -> Vec<SamplerKind> {
    SamplerKind::in_dimension(2)
}

/// Every 2D sampler that can draw `rays` points (the Fibonacci lattice only at Fibonacci
/// numbers, strata at their counts): the samplers a render at `rays` compares.
pub fn samplers_for_rays(rays: usize) -> Vec<SamplerKind> {
    all_2d_samplers()
        .into_iter()
        .filter(|k| k.nearest_count(rays, 2) == rays)
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

/// Runs a comparison: traces the frame, loads or renders the reference, loads or rasterizes
/// the pixels' visibilities (once for every sampler), then renders, measures and predicts
/// every sampler, reporting each stage to `progress`.
///
/// # Errors
/// As [`compare`], [`super::cached_reference`] and [`super::cached_pixel_power`].
pub fn run_comparison(config: &ComparisonConfig, progress: &dyn Progress) -> Result<Comparison> {
    // Every request is checked before the expensive reference.
    config.check()?;
    let frame = Frame::new(
        super::geometry::Scene::cornell_box(),
        config.width,
        config.height,
    )?;
    let stage = format!("reference ({} rays per pixel)", config.reference_rays);
    progress.begin(&stage, config.height as u64);
    let (reference, reference_cached) = match &config.cache_dir {
        Some(dir) => super::cached_reference(
            dir,
            &frame,
            config.reference_rays,
            config.render.max_distance,
            config.render.seed,
            progress,
        )?,
        None => (
            super::render_reference(
                &frame,
                config.reference_rays,
                config.render.max_distance,
                config.render.seed,
                progress,
            )?,
            false,
        ),
    };
    progress.end();
    let stride = config.pixel_power.stride;
    let stage = format!(
        "visibility grids ({}² per pixel)",
        config.pixel_power.resolution
    );
    progress.begin(&stage, config.height.div_ceil(stride) as u64);
    let (max_distance, grids) = (config.render.max_distance, &config.pixel_power);
    let power = match &config.cache_dir {
        Some(dir) => super::cached_pixel_power(dir, &frame, max_distance, grids, progress)?.0,
        None => super::pixel_power(&frame, max_distance, grids, progress)?,
    };
    progress.end();
    let rows = compare(&frame, config, &reference, &power, progress)?;
    Ok(Comparison {
        rows,
        reference,
        reference_cached,
        power_label: power.label,
    })
}
