//! The image's mean squared error: measured against the reference, and predicted from the
//! pixels' visibility spectra.

use super::{Frame, Reference, Rendering};
use crate::error::{invalid, Result};
use crate::predict::{
    predict, predict_on_patterns, LatticePower, PatternPlan, PredictParams, Prediction, Problem,
};
use crate::progress::Progress;
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};
use crate::sampler::Sampler;
use crate::spectrum::{Engine, Lattice, PatternSource, SpectrumParams};
use rand::Rng;
use rayon::prelude::*;

/// A measured MSE with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MseEstimate {
    /// `mean_p [(I_p - R_p)² - v_p]`: the squared error against the reference minus the
    /// reference's own estimated pixel variance `v_p`, an unbiased estimate of the image's MSE
    /// against the exact ambient occlusion.
    pub mse: f64,
    /// Its standard error: the spread of the per-pixel terms, with the pixels that share a
    /// pattern summed into one independent unit first (`√(Σ_g S_g²)/P` over the pattern
    /// groups `g` of the deviations' sums `S_g`, with the factor `G/(G-1)`).
    pub stderr: f64,
    /// `mean_p (I_p - R_p)²`, before the reference's noise is removed.
    pub raw_mse: f64,
    /// `mean_p v_p`: what the reference's own noise adds to `raw_mse`.
    pub reference_noise: f64,
    /// Pixels.
    pub pixels: usize,
    /// Independent units (patterns in use).
    pub groups: usize,
}

/// Measures a rendering's MSE against the reference.
///
/// # Errors
/// Images of different sizes or a reference of fewer than 2 rays.
pub fn measure_mse(rendering: &Rendering, reference: &Reference) -> Result<MseEstimate> {
    reference.check_size(&rendering.image)?;
    let pixels = rendering.image.values.len();
    let mut raw = 0.0;
    let mut noise = 0.0;
    let terms: Vec<f64> = (0..pixels)
        .map(|p| {
            let e = rendering.image.values[p] - reference.image.values[p];
            let v = reference.pixel_variance(p);
            raw += e * e;
            noise += v;
            e * e - v
        })
        .collect();
    let count = pixels as f64;
    let mse = terms.iter().sum::<f64>() / count;
    let groups = rendering
        .pattern
        .iter()
        .copied()
        .max()
        .map_or(0, |m| m as usize + 1);
    let mut sums = vec![0.0; groups];
    let mut used = vec![false; groups];
    for (p, t) in terms.iter().enumerate() {
        let g = rendering.pattern[p] as usize;
        sums[g] += t - mse;
        used[g] = true;
    }
    let units = used.iter().filter(|&&u| u).count();
    let correction = units as f64 / (units as f64 - 1.0).max(1.0);
    let variance = sums.iter().map(|s| s * s).sum::<f64>() / (count * count) * correction;
    Ok(MseEstimate {
        mse,
        stderr: variance.sqrt(),
        raw_mse: raw / count,
        reference_noise: noise / count,
        pixels,
        groups: units,
    })
}

/// How the pixels' visibilities are rasterized for the prediction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelPowerParams {
    /// Cells per side of each pixel's visibility grid in primary sample space (one ray per
    /// cell centre). Default 64.
    pub resolution: usize,
    /// The lattice `|k_i| ≤ kmax` on which the power is kept; beyond it the sampler is taken as
    /// white. Default 64 (`ν = k/√N` up to 6.5 at N = 96).
    pub kmax: usize,
    /// Every `stride`-th pixel along each axis, from pixel (0, 0), enters the mean. Default 1
    /// (every pixel).
    pub stride: usize,
}

/// The most cells per side of a pixel's visibility grid: 4096 (16.8 million rays a pixel).
const MAX_PIXEL_RESOLUTION: usize = 4096;

/// The largest lattice of a pixel's power: `2^22` frequencies (every thread keeps one).
const PIXEL_LATTICE_BUDGET: usize = 1 << 22;

impl PixelPowerParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// A zero resolution, stride or `kmax`, a resolution above 4096, or a lattice above 2^22
    /// frequencies.
    pub fn check(&self) -> Result<()> {
        for (name, v) in [
            ("grid resolution", self.resolution),
            ("stride", self.stride),
            ("kmax", self.kmax),
        ] {
            if v == 0 {
                return Err(invalid(name, 0, "at least 1"));
            }
        }
        if self.resolution > MAX_PIXEL_RESOLUTION {
            return Err(invalid(
                "grid resolution",
                self.resolution,
                "at most 4096 cells per side",
            ));
        }
        if (2 * self.kmax + 1).pow(2) > PIXEL_LATTICE_BUDGET {
            return Err(invalid(
                "kmax",
                self.kmax,
                format!(
                    "at most {} (a lattice of 2^22 frequencies)",
                    (((PIXEL_LATTICE_BUDGET as f64).sqrt() - 1.0) / 2.0) as usize
                ),
            ));
        }
        Ok(())
    }
}

impl PixelPowerParams {
    /// The cells per side of each pixel's visibility grid for the per-pixel route at `n` rays
    /// of a sampler structured as `strata` says: `resolution`, raised where the grid, a
    /// tabulation of the pixel's rays, would be too coarse for the extrapolation over its
    /// coarser levels ([`crate::predict::min_tabulation_cells`]).
    ///
    /// # Errors
    /// An `n` whose tabulation needs more than 4096 cells per side.
    pub fn tabulation_resolution(
        &self,
        n: usize,
        strata: crate::sampler::AxisStrata,
    ) -> Result<usize> {
        let needed = crate::predict::min_tabulation_cells(n, strata);
        if needed > MAX_PIXEL_RESOLUTION {
            return Err(invalid(
                "rays per pixel",
                n,
                format!(
                    "at most {} for the per-pixel prediction, whose visibility grids, \
                     tabulations of the pixels' rays, need {needed} cells per side at N = {n} \
                     (at most {MAX_PIXEL_RESOLUTION})",
                    MAX_PIXEL_RESOLUTION * MAX_PIXEL_RESOLUTION / 64
                ),
            ));
        }
        Ok(self.resolution.max(needed))
    }
}

impl Default for PixelPowerParams {
    fn default() -> Self {
        Self {
            resolution: 64,
            kmax: 64,
            stride: 1,
        }
    }
}

/// The mean over pixels of `|V̂_p(k)|²` on the lattice `|k_i| ≤ kmax`, with the mean energy
/// beyond it: the image's integrand for the lattice-form prediction of its MSE
/// ([`crate::predict::predict_from_power`]). Pixels whose primary ray leaves the scene have no
/// variance and enter with zero power. Advances `progress` once per pixel row visited.
///
/// # Errors
/// A zero resolution, stride or `kmax`, or a non-positive maximum distance.
pub fn pixel_power(
    frame: &Frame,
    max_distance: f64,
    params: &PixelPowerParams,
    progress: &dyn Progress,
) -> Result<LatticePower> {
    params.check()?;
    super::check_max_distance(max_distance)?;
    let lattice = Lattice {
        dimension: 2,
        kmax: params.kmax,
    };
    let rows: Vec<usize> = (0..frame.height()).step_by(params.stride).collect();
    let columns: Vec<usize> = (0..frame.width()).step_by(params.stride).collect();
    // Rows are summed in order afterwards, so the result does not depend on the thread count.
    let per_row: Vec<(Vec<f64>, f64, f64)> = rows
        .par_iter()
        .map(|&y| {
            let mut power = vec![0.0; lattice.len()];
            let (mut beyond, mut axis_beyond) = (0.0, 0.0);
            for &x in &columns {
                let Some(point) = frame.point(y * frame.width() + x) else {
                    continue;
                };
                let grid = point.visibility_grid(frame.scene(), params.resolution, max_distance)?;
                let part = LatticePower::of(&grid, lattice)?;
                power.iter_mut().zip(&part.power).for_each(|(a, p)| *a += p);
                beyond += part.beyond;
                axis_beyond += part.axis_beyond;
            }
            progress.advance(1);
            Ok((power, beyond, axis_beyond))
        })
        .collect::<Result<_>>()?;
    let mut power = vec![0.0; lattice.len()];
    let (mut beyond, mut axis_beyond) = (0.0, 0.0);
    for (row_power, row_beyond, row_axis) in per_row {
        power.iter_mut().zip(&row_power).for_each(|(a, p)| *a += p);
        beyond += row_beyond;
        axis_beyond += row_axis;
    }
    let count = (rows.len() * columns.len()) as f64;
    Ok(LatticePower {
        lattice,
        power: power.into_iter().map(|p| p / count).collect(),
        beyond: beyond / count,
        axis_beyond: axis_beyond / count,
        label: format!(
            "mean visibility power of {} of {} × {} pixels ({}² grid per pixel)",
            rows.len() * columns.len(),
            frame.width(),
            frame.height(),
            params.resolution
        ),
    })
}

/// The image MSE predicted for `sampler` with `n` rays: the lattice form against the pixels'
/// mean power, pattern by pattern over `realizations` patterns of seed `seed` on `power`'s
/// lattice (the noise from their spread; weights averaged over the cube's symmetries where the
/// sampler has them).
///
/// # Errors
/// A sampler that cannot produce `n` points in 2D, or fewer than 2 realizations.
pub fn predict_mse(
    sampler: &dyn Sampler,
    power: &LatticePower,
    n: usize,
    realizations: usize,
    seed: u64,
) -> Result<Prediction> {
    if realizations < 2 {
        return Err(invalid("spectrum realizations", realizations, "at least 2"));
    }
    let plan = PatternPlan {
        initial: realizations,
        target_noise: f64::INFINITY,
        max_realizations: realizations,
        spectrum: SpectrumParams {
            kmax: power.lattice.kmax,
            realizations,
            seed,
            engine: Engine::Auto,
            bin_width: 1.0,
            budget: crate::budget::Budget::default(),
        },
        symmetric: sampler.kind().is_some_and(|k| k.is_symmetric_at(n, 2)),
        low_band: sampler
            .kind()
            .and_then(|k| crate::predict::LowBand::for_sampler(k, n, 2)),
    };
    let source = PatternSource::Sampler { sampler, n, seed };
    predict_on_patterns(power, source, &plan, &crate::progress::Silent)
}

/// The relative noise each pixel's estimated prediction aims at: the pixels draw independent
/// patterns, so the image's mean averages their noise down by the square root of their count.
const RENDER_PIXEL_TARGET_NOISE: f64 = 0.2;
/// The work one pixel's estimated prediction may spend, in seconds of one core.
const RENDER_PIXEL_WORK_SECONDS: f64 = 0.05;

/// The image MSE predicted for `sampler` with `n` rays under `randomization` pixel by pixel:
/// each visited pixel's visibility grid predicted as an integrand by its own default route for
/// that estimator (the cell form for strata and nets as drawn, Owen's gains, the Walsh form for
/// a digital shift), with its own seed, and the mean taken over the pixels (those whose primary
/// ray leaves the scene with no variance). The noise is the pixels' independent noises combined,
/// the bounds their mean. The grids are as fine as `grid` asks and at least as fine as the
/// tabulation's extrapolation needs at `n` ([`crate::predict::min_tabulation_cells`]). This is
/// the route for estimators other than the shift, whose cross
/// terms between frequencies do not vanish, so that no mean power over the pixels can carry them.
///
/// # Errors
/// A sampler that cannot produce `n` points in 2D, invalid grid parameters, or a pixel whose
/// estimator has no route.
pub fn predict_mse_per_pixel(
    frame: &Frame,
    sampler: &dyn Sampler,
    randomization: Randomization,
    n: usize,
    max_distance: f64,
    grid: &PixelPowerParams,
    seed: u64,
) -> Result<Prediction> {
    grid.check()?;
    super::check_max_distance(max_distance)?;
    if let Some(kind) = sampler.kind() {
        crate::predict::check_unbiased(kind, randomization)?;
    }
    let pixels: Vec<usize> = (0..frame.height())
        .step_by(grid.stride)
        .flat_map(|y| {
            (0..frame.width())
                .step_by(grid.stride)
                .map(move |x| y * frame.width() + x)
        })
        .collect();
    let strata = sampler
        .kind()
        .map_or(crate::sampler::AxisStrata::Projections, |k| {
            k.facts().axis_strata
        });
    let resolution = grid.tabulation_resolution(n, strata)?;
    let params = PredictParams {
        target_noise: RENDER_PIXEL_TARGET_NOISE,
        work_budget_seconds: RENDER_PIXEL_WORK_SECONDS,
        ..PredictParams::default()
    };
    let per_pixel: Vec<Option<Prediction>> = pixels
        .par_iter()
        .map(|&p| {
            let Some(point) = frame.point(p) else {
                return Ok(None);
            };
            let visibility = point.visibility_grid(frame.scene(), resolution, max_distance)?;
            let problem = Problem::new(sampler, &visibility, n)?.with_randomization(randomization);
            let own = PredictParams {
                seed: realization_rng(seed, p as u64, Stream::Trial).next_u64(),
                ..params
            };
            predict(&problem, &own).map(Some)
        })
        .collect::<Result<_>>()?;
    let predicted: Vec<&Prediction> = per_pixel.iter().flatten().collect();
    let first = predicted
        .first()
        .ok_or_else(|| invalid("image", "no pixel sees the scene", "at least one"))?;
    let (variance, budget) = crate::pixels::mean_of(&predicted);
    Ok(Prediction {
        variance,
        randomization,
        route: first.route,
        reason: format!(
            "the mean over {} pixels ({} seeing the scene) of each pixel's own prediction for \
             the {} estimator on its {}² visibility grid ({})",
            pixels.len(),
            predicted.len(),
            randomization.estimator(),
            grid.resolution,
            first.route
        ),
        budget,
        n,
        dimension: 2,
        dc_term: 0.0,
        evaluations: predicted.iter().map(|p| p.evaluations).sum(),
        alternatives: Vec::new(),
        analysis: None,
    })
}
