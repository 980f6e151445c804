//! Image-level predictions: every pixel of an image is its own integrand on `[0,1)²` (a
//! renderer's light-sample or lens-sample domain, tabulated on a grid), integrated with the
//! same sampler and N. Each pixel's variance is predicted by its own default route; the image's
//! MSE is their mean (each pixel's estimator is unbiased, so its MSE is its variance), with the
//! pixels' budgets combined: noise in quadrature (independent estimates), bounds added.

use crate::budget::Needs;
use crate::error::{invalid, Error, Result};
use crate::integrand::{grid_of_array, read_grid_file, GridIntegrand, Integrand};
use crate::npy::{read_npy, NpyArray};
use crate::predict::{
    plan_analysis, predict_with, ErrorBudget, Form, PredictParams, Prediction, Problem, Route,
};
use crate::progress::{stage, Progress, Silent};
use crate::randomization::{Randomization, RandomizationChoice};
use crate::rng::{realization_rng, Stream};
use crate::sampler::{sampler_native_randomization, Sampler};
use rand::Rng;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// The relative noise each pixel's estimated prediction aims at: the image's MSE averages
/// many, so its own noise is far below.
pub const PIXEL_TARGET_NOISE: f64 = 0.1;
/// The work each pixel's estimated prediction may spend, in seconds of one core.
pub const PIXEL_WORK_SECONDS: f64 = 0.2;
/// The most pixels a stack may hold.
pub const MAX_PIXELS: usize = 1 << 20;

/// An image's pixels, each a function tabulated on a grid of cells, in rows from the top.
#[derive(Debug, Clone)]
pub struct PixelStack {
    columns: usize,
    rows: usize,
    pixels: Vec<GridIntegrand>,
}

impl PixelStack {
    /// `pixels` in rows of `columns`, from the top left.
    ///
    /// # Errors
    /// No pixels, or a count that is not a whole number of rows.
    pub fn new(columns: usize, pixels: Vec<GridIntegrand>) -> Result<Self> {
        if pixels.is_empty() || columns == 0 || !pixels.len().is_multiple_of(columns) {
            return Err(invalid(
                "pixel stack",
                format!("{} pixels in rows of {columns}", pixels.len()),
                "at least one pixel, in whole rows",
            ));
        }
        if pixels.len() > MAX_PIXELS {
            return Err(invalid(
                "pixel stack",
                format!("{} pixels", pixels.len()),
                format!("at most {MAX_PIXELS}"),
            ));
        }
        Ok(Self {
            columns,
            rows: pixels.len() / columns,
            pixels,
        })
    }

    /// A stack from an array: `(pixels, height, width)`, one row of pixels, or
    /// `(rows, columns, height, width)`, an image; each pixel's cells `values[y, x]` with row
    /// 0 at `y = 0`, as for a `.npy` grid.
    ///
    /// # Errors
    /// An array of another rank, or an empty one.
    pub fn from_array(array: NpyArray) -> Result<Self> {
        let (rows, columns, height, width) = match *array.shape.as_slice() {
            [p, h, w] => (1, p, h, w),
            [r, c, h, w] => (r, c, h, w),
            _ => {
                return Err(Error::format(
                    "pixel stack",
                    format!(
                        "shape {:?}: (pixels, height, width) or (rows, columns, height, width)",
                        array.shape
                    ),
                ))
            }
        };
        let cells = height * width;
        if cells == 0 || rows * columns == 0 {
            return Err(invalid(
                "pixel stack",
                format!("{:?}", array.shape),
                "no empty axis",
            ));
        }
        let pixels = array
            .values
            .chunks_exact(cells)
            .map(|values| {
                grid_of_array(NpyArray {
                    shape: vec![height, width],
                    values: values.to_vec(),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        Self::new(columns, pixels)
    }

    /// Reads a stack: a `.npy` array ([`from_array`](Self::from_array)), or a directory of
    /// grid files (text, PNG or `.npy`), one pixel each in the order of their names, in one
    /// row.
    ///
    /// # Errors
    /// An unreadable path, a file that is not a grid, or an empty directory.
    pub fn read(path: &Path) -> Result<Self> {
        if path.is_dir() {
            let mut files: Vec<_> = std::fs::read_dir(path)
                .map_err(|e| Error::io(path, e))?
                .filter_map(|entry| entry.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && !is_hidden(p))
                .collect();
            files.sort();
            let pixels = files
                .iter()
                .map(|f| read_grid_file(f))
                .collect::<Result<Vec<_>>>()?;
            let columns = pixels.len();
            return Self::new(columns, pixels);
        }
        Self::from_array(read_npy(&crate::io::read_bounded(path)?)?)
    }

    /// The same pixels, every grid with `meaning` (by default a finer function's cell
    /// averages).
    pub fn with_meaning(self, meaning: crate::integrand::GridMeaning) -> Self {
        Self {
            pixels: self
                .pixels
                .into_iter()
                .map(|p| p.with_meaning(meaning))
                .collect(),
            ..self
        }
    }

    /// Pixels per row.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Rows of pixels.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The pixels, in rows from the top left.
    pub fn pixels(&self) -> &[GridIntegrand] {
        &self.pixels
    }
}

fn is_hidden(path: &Path) -> bool {
    path.file_name()
        .is_some_and(|n| n.to_string_lossy().starts_with('.'))
}

/// One pixel's predicted variance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PixelVariance {
    /// The predicted variance of the pixel's estimate.
    pub variance: f64,
    /// The half-width of its 99% budget.
    pub half_width: f64,
    /// The form that predicted it.
    pub form: Form,
}

/// The predicted variance of every pixel of an image, and the image's MSE.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImagePrediction {
    /// Samples per pixel.
    pub n: usize,
    /// The estimator.
    pub randomization: Randomization,
    /// Pixels per row.
    pub columns: usize,
    /// Rows.
    pub rows: usize,
    /// The pixels' predictions, in rows from the top left.
    pub pixels: Vec<PixelVariance>,
    /// The image's predicted MSE: the mean of the pixels' variances.
    pub mse: f64,
    /// Its budget (the pixels' noise in quadrature over the count, their bounds averaged).
    pub budget: ErrorBudget,
    /// The route of the first pixel (every pixel takes the default route for its own
    /// integrand).
    pub route: Route,
    /// Integrand evaluations spent over all pixels.
    pub evaluations: u64,
}

/// The mean of several predictions and its budget: the noise of independent estimates in
/// quadrature, the bounds (quadrature, truncation, model, tabulation) averaged.
pub(crate) fn mean_of(predictions: &[&Prediction]) -> (f64, ErrorBudget) {
    let count = predictions.len().max(1) as f64;
    let mut budget = ErrorBudget::default();
    let mut variance = 0.0;
    for p in predictions {
        variance += p.variance;
        budget.spectrum_noise += p.budget.spectrum_noise.powi(2);
        budget.quadrature += p.budget.quadrature;
        budget.truncation += p.budget.truncation;
        budget.model += p.budget.model;
        budget.tabulation += p.budget.tabulation;
    }
    budget.spectrum_noise = budget.spectrum_noise.sqrt() / count;
    budget.quadrature /= count;
    budget.truncation /= count;
    budget.model /= count;
    budget.tabulation /= count;
    (variance / count, budget)
}

/// The parameters of one pixel's prediction: `params` with [`PIXEL_TARGET_NOISE`] and
/// [`PIXEL_WORK_SECONDS`] (an image averages many pixels).
pub fn pixel_params(params: &PredictParams) -> PredictParams {
    PredictParams {
        target_noise: PIXEL_TARGET_NOISE,
        work_budget_seconds: PIXEL_WORK_SECONDS,
        ..*params
    }
}

/// Predicts every pixel of `stack` integrated with `n` points of `sampler` under
/// `randomization`, each by its default route with its own seed (realization `p` of
/// `params.seed`), and the image's MSE.
///
/// # Errors
/// A sampler that cannot draw `n` points in 2D, or a pixel whose estimator has no route (the
/// error names the pixel).
///
/// # Examples
/// ```
/// use specvar::integrand::GridIntegrand;
/// use specvar::pixels::{pixel_params, predict_pixels, PixelStack};
/// use specvar::predict::PredictParams;
/// use specvar::progress::Silent;
/// use specvar::randomization::RandomizationChoice;
/// use specvar::sampler::Jitter;
/// // Two pixels: an edge at x = 0.3 and one at x = 0.6, the averages of 64 × 64 cells (a
/// // tabulation fine enough for N = 64: each pixel is predicted for its edge).
/// let edge = |at: f64| {
///     let values = (0..4096).map(|i| ((i % 64) as f64 + 1.0 - at * 64.0).clamp(0.0, 1.0));
///     GridIntegrand::new(64, 64, values.collect()).unwrap()
/// };
/// let stack = PixelStack::new(2, vec![edge(0.3), edge(0.6)])?;
/// let params = pixel_params(&PredictParams::default());
/// let image =
///     predict_pixels(&stack, &Jitter::new(2)?, 64, RandomizationChoice::Native, &params, &Silent)?;
/// assert_eq!(image.pixels.len(), 2);
/// assert!(image.mse > 0.0 && image.budget.tabulation > 0.0);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn predict_pixels(
    stack: &PixelStack,
    sampler: &dyn Sampler,
    n: usize,
    randomization: RandomizationChoice,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<ImagePrediction> {
    let randomization = randomization.resolve(sampler_native_randomization(sampler));
    if let Some(kind) = sampler.kind() {
        crate::predict::check_unbiased(kind, randomization)?;
    }
    let count = stack.pixels.len();
    // Every pixel's plan first, and their needs together against the budget, before any
    // pixel's work; each pixel's adaptive work then shares what the budget leaves.
    let name_pixel = |p: usize, e: Error| match e {
        Error::OutsideValidity { .. } => {
            invalid("pixel", p, format!("a pixel with a prediction route: {e}"))
        }
        other => other,
    };
    let plans = stack
        .pixels
        .par_iter()
        .enumerate()
        .map(|(p, f)| {
            let problem =
                Problem::new(sampler, f as &dyn Integrand, n)?.with_randomization(randomization);
            plan_analysis(&problem, params).map_err(|e| name_pixel(p, e))
        })
        .collect::<Result<Vec<_>>>()?;
    params.budget.check(
        &format!("the plans of {count} pixels"),
        Needs {
            memory_bytes: plans.iter().map(|p| p.needs.bytes).fold(0.0, f64::max)
                * rayon::current_num_threads() as f64,
            work_seconds: plans.iter().map(|p| p.needs.seconds).sum(),
        },
        "fewer pixels or a lower N",
    )?;
    let share = params.budget.work_seconds / count.max(1) as f64;
    let params = &PredictParams {
        work_budget_seconds: params.work_budget_seconds.min(share),
        ..*params
    };
    let predictions = stage(
        progress,
        "predicting the pixels",
        stack.pixels.len() as u64,
        || {
            stack
                .pixels
                .par_iter()
                .enumerate()
                .map(|(p, f)| {
                    let problem = Problem::new(sampler, f as &dyn Integrand, n)?
                        .with_randomization(randomization);
                    let own = PredictParams {
                        seed: realization_rng(params.seed, p as u64, Stream::Trial).next_u64(),
                        ..*params
                    };
                    // A pixel without a route is named; other errors (a budget, a sampler)
                    // keep their kind, which callers such as a plan's search read.
                    let prediction =
                        predict_with(&problem, &own, &Silent).map_err(|e| name_pixel(p, e));
                    progress.advance(1);
                    prediction
                })
                .collect::<Result<Vec<Prediction>>>()
        },
    )?;
    let refs: Vec<&Prediction> = predictions.iter().collect();
    let (mse, budget) = mean_of(&refs);
    Ok(ImagePrediction {
        n,
        randomization,
        columns: stack.columns,
        rows: stack.rows,
        pixels: predictions
            .iter()
            .map(|p| PixelVariance {
                variance: p.variance,
                half_width: p.budget.half_width(crate::montecarlo::Z_99),
                form: p.route.form,
            })
            .collect(),
        mse,
        budget,
        route: predictions
            .first()
            .map(|p| p.route)
            .ok_or_else(|| invalid("pixel stack", 0, "at least one pixel"))?,
        evaluations: predictions.iter().map(|p| p.evaluations).sum(),
    })
}

impl ImagePrediction {
    /// The image's MSE as one prediction: its variance, budget and first pixel's route, and a
    /// reason saying it is a mean over the pixels.
    pub fn as_prediction(&self) -> Prediction {
        Prediction {
            variance: self.mse,
            randomization: self.randomization,
            route: self.route,
            reason: format!(
                "the mean over {} pixels of each pixel's own prediction (the first by the {})",
                self.pixels.len(),
                self.route
            ),
            budget: self.budget,
            n: self.n,
            dimension: 2,
            dc_term: 0.0,
            evaluations: self.evaluations,
            alternatives: Vec::new(),
            analysis: None,
        }
    }

    /// The image of predicted variance as an 8-bit grey PNG, one pixel per pixel: grey level
    /// `255 · variance / largest variance` (black where a pixel's estimate is exact).
    ///
    /// # Errors
    /// An encoder failure.
    pub fn variance_png(&self) -> Result<Vec<u8>> {
        let largest = self.pixels.iter().map(|p| p.variance).fold(0.0, f64::max);
        let grey: Vec<u8> = self
            .pixels
            .iter()
            .map(|p| {
                if largest > 0.0 {
                    (255.0 * (p.variance / largest).clamp(0.0, 1.0)).round() as u8
                } else {
                    0
                }
            })
            .collect();
        crate::plot::gray_png(&grey, self.columns, self.rows)
    }
}
