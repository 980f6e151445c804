//! Variance against orientation: an edge through the square at a range of angles, each
//! predicted by the default route (the lattice form with the sampler's full 2D spectrum) and
//! measured by Monte Carlo on the same patterns.

use crate::error::{invalid, Result};
use crate::integrand::{Integrand, Polygon};
use crate::montecarlo::{empirical_variances, McParams, McResult, Z_99};
use crate::predict::{predict_many, PredictParams, Prediction, Problem};
use crate::progress::Progress;
use crate::sampler::{Sampler, SamplerKind};
use serde::Serialize;

/// The most angles one study takes.
pub const MAX_ANGLES: usize = 361;

/// An orientation study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationConfig {
    /// Points per pattern.
    pub n: usize,
    /// The edges' normal angles, in degrees.
    pub angles: Vec<f64>,
    /// Where the edge crosses the square, as a fraction of its extent along the normal (0.5:
    /// through the centre).
    pub offset: f64,
    /// Monte Carlo evaluations.
    pub trials: usize,
    /// Seed of Monte Carlo and of the predictions' patterns.
    pub seed: u64,
    /// The predictions' parameters.
    #[serde(skip)]
    pub predict: PredictParams,
}

/// One angle: the prediction beside Monte Carlo.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrientationRow {
    /// The edge's normal angle, in degrees.
    pub angle: f64,
    /// The default prediction.
    pub predicted: Prediction,
    /// Monte Carlo with its 99% interval.
    pub measured: McResult,
    /// The gap beyond the prediction's bounds, in combined standard errors.
    pub z: f64,
}

impl OrientationRow {
    /// Whether the prediction agrees with Monte Carlo at 99%.
    pub fn agrees(&self) -> bool {
        self.z.abs() <= Z_99
    }
}

/// Predicts and measures the variance of an edge at every angle of `config` with `sampler`
/// (2D): one spectrum estimate serves every angle (the integrands share the sampler and N),
/// and one Monte Carlo run evaluates every edge on the same patterns.
///
/// # Errors
/// A sampler not in 2D, no angles or more than [`MAX_ANGLES`], a bad offset, or any error of
/// the prediction or Monte Carlo (budget, count rule).
///
/// # Examples
/// ```
/// use specvar::anisotropy::{variance_against_orientation, OrientationConfig};
/// use specvar::sampler::{Jitter, SamplerKind};
/// let config = OrientationConfig {
///     n: 64, angles: vec![0.0, 45.0], offset: 0.5, trials: 2000, seed: 1,
///     predict: Default::default(),
/// };
/// let rows = variance_against_orientation(&Jitter::new(2)?, SamplerKind::Jitter, &config,
///     &specvar::progress::Silent)?;
/// assert!(rows[1].predicted.variance > rows[0].predicted.variance); // jitter: 45° is worse
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn variance_against_orientation(
    sampler: &dyn Sampler,
    kind: SamplerKind,
    config: &OrientationConfig,
    progress: &dyn Progress,
) -> Result<Vec<OrientationRow>> {
    if sampler.dimension() != 2 {
        return Err(invalid(
            "dimension",
            sampler.dimension(),
            "2 (edges live in the square)",
        ));
    }
    if config.angles.is_empty() || config.angles.len() > MAX_ANGLES {
        return Err(invalid(
            "angles",
            config.angles.len(),
            format!("1 to {MAX_ANGLES} angles"),
        ));
    }
    let edges = config
        .angles
        .iter()
        .map(|&a| Polygon::edge(a, config.offset, 1.0))
        .collect::<Result<Vec<_>>>()?;
    let fs: Vec<&dyn Integrand> = edges.iter().map(|e| e as &dyn Integrand).collect();
    let mut mc = McParams::pooled(kind, config.trials, config.seed, true);
    mc.budget = config.predict.budget;
    progress.begin(
        &format!("orientation: monte carlo of {kind}"),
        mc.patterns as u64,
    );
    let measured = empirical_variances(sampler, &fs, config.n, &mc, progress)?;
    progress.end();
    let problems = fs
        .iter()
        .map(|f| Problem::new(sampler, *f, config.n))
        .collect::<Result<Vec<_>>>()?;
    let predictions = predict_many(&problems, &config.predict, progress)?;
    Ok(config
        .angles
        .iter()
        .zip(measured)
        .zip(predictions)
        .map(|((&angle, measured), predicted)| OrientationRow {
            angle,
            z: predicted.z_beyond_bounds(&measured),
            predicted,
            measured,
        })
        .collect())
}
