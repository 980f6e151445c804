//! Variance against orientation: an edge through the square at a range of angles, each
//! predicted by the default route (the lattice form with the sampler's full 2D spectrum) and
//! measured by Monte Carlo on the same patterns.

use crate::crosscheck::beside_monte_carlo;
use crate::error::{invalid, Result};
use crate::integrand::{Integrand, Polygon};
use crate::montecarlo::{McParams, McResult, Z_99};
use crate::predict::{PredictParams, Prediction};
use crate::progress::Progress;
use crate::randomization::Randomization;
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

/// The orientation curve as polar-plot series: the prediction as a line, Monte Carlo as
/// markers with its 99% intervals.
pub fn polar_series(rows: &[OrientationRow]) -> [crate::plot::PolarSeries; 2] {
    [
        crate::plot::PolarSeries {
            label: "predicted".into(),
            points: rows
                .iter()
                .map(|r| (r.angle, r.predicted.variance))
                .collect(),
            bars: None,
        },
        crate::plot::PolarSeries {
            label: "Monte Carlo (99%)".into(),
            points: rows
                .iter()
                .map(|r| (r.angle, r.measured.variance))
                .collect(),
            bars: Some(
                rows.iter()
                    .map(|r| (r.measured.ci_low, r.measured.ci_high))
                    .collect(),
            ),
        },
    ]
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
    if config.trials < crate::montecarlo::MIN_UNITS {
        return Err(invalid(
            "trials",
            config.trials,
            format!(
                "at least {}, for a 99% interval from the trials",
                crate::montecarlo::MIN_UNITS
            ),
        ));
    }
    let edges = config
        .angles
        .iter()
        .map(|&a| Polygon::edge(a, config.offset, 1.0))
        .collect::<Result<Vec<_>>>()?;
    let fs: Vec<&dyn Integrand> = edges.iter().map(|e| e as &dyn Integrand).collect();
    let mut mc = McParams::pooled(kind, config.trials, config.seed, Randomization::Shift);
    mc.budget = config.predict.budget;
    let stage = format!("orientation: monte carlo of {kind}");
    let results = beside_monte_carlo(
        sampler,
        &fs,
        config.n,
        &mc,
        &config.predict,
        (&stage, progress),
    )?;
    Ok(config
        .angles
        .iter()
        .zip(results)
        .map(|(&angle, (measured, predicted))| OrientationRow {
            angle,
            z: predicted.z_beyond_bounds(&measured),
            predicted,
            measured,
        })
        .collect())
}

/// The variance of one edge against N: predicted and measured at each N, with the log-log
/// slopes of both.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EdgeRate {
    /// The edge's normal angle, in degrees.
    pub angle: f64,
    /// The N values.
    pub ns: Vec<usize>,
    /// The rows at each N.
    pub rows: Vec<OrientationRow>,
    /// The slope of the predicted variances (weighted by their budgets).
    pub predicted: crate::rate::SlopeFit,
    /// The slope of the Monte Carlo variances with its 99% interval.
    pub measured: crate::rate::SlopeFit,
}

/// Rates of edges against N: for each N of `ns`, [`variance_against_orientation`] at
/// `config.angles` (its `n` ignored), then the log-log slopes per angle. Mitchell (1996)
/// measured `N^{-1.5}` for stratified pixels crossed by an edge; the lattice form says which
/// angles reach it.
///
/// # Errors
/// Fewer than two N, or any error of the predictions and Monte Carlo.
pub fn edge_rates(
    sampler: &dyn Sampler,
    kind: SamplerKind,
    ns: &[usize],
    config: &OrientationConfig,
    progress: &dyn Progress,
) -> Result<Vec<EdgeRate>> {
    if ns.len() < 2 {
        return Err(invalid("N values", ns.len(), "at least two"));
    }
    let by_n = ns
        .iter()
        .map(|&n| {
            let at_n = OrientationConfig {
                n,
                ..config.clone()
            };
            variance_against_orientation(sampler, kind, &at_n, progress)
        })
        .collect::<Result<Vec<_>>>()?;
    let x: Vec<f64> = ns.iter().map(|&n| n as f64).collect();
    config
        .angles
        .iter()
        .enumerate()
        .map(|(a, &angle)| {
            let rows: Vec<OrientationRow> = by_n.iter().map(|r| r[a].clone()).collect();
            let predicted: Vec<f64> = rows.iter().map(|r| r.predicted.variance).collect();
            let predicted_rel: Vec<f64> = rows
                .iter()
                .map(|r| r.predicted.budget.half_width(1.0) / r.predicted.variance)
                .collect();
            let measured: Vec<f64> = rows.iter().map(|r| r.measured.variance).collect();
            let measured_rel: Vec<f64> = rows
                .iter()
                .map(|r| {
                    (r.measured.ci_high - r.measured.ci_low) / (2.0 * Z_99 * r.measured.variance)
                })
                .collect();
            Ok(EdgeRate {
                angle,
                ns: ns.to_vec(),
                predicted: crate::rate::loglog_slope(&x, &predicted, Some(&predicted_rel))?,
                measured: crate::rate::loglog_slope(&x, &measured, Some(&measured_rel))?,
                rows,
            })
        })
        .collect()
}

fn bad_angles(text: &str) -> crate::Error {
    crate::Error::InvalidParameter {
        name: "angles",
        value: text.to_string(),
        allowed: format!(
            "START:END:STEP in degrees with STEP > 0 (e.g. 0:90:5) or a comma list, at most \
             {MAX_ANGLES} angles"
        ),
    }
}

/// Angles in degrees from `START:END:STEP` (`0:90:5`: both ends included, the end kept
/// against rounding of the steps) or a comma list (`0,30,45`), at most [`MAX_ANGLES`].
///
/// # Errors
/// Text of neither form, a step that is not positive, an end below the start, or too many
/// angles.
///
/// # Examples
/// ```
/// use specvar::anisotropy::parse_angles;
/// assert_eq!(parse_angles("0:90:45")?, vec![0.0, 45.0, 90.0]);
/// assert_eq!(parse_angles("0, 30")?, vec![0.0, 30.0]);
/// assert!(parse_angles("0:90:0").is_err());
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn parse_angles(text: &str) -> Result<Vec<f64>> {
    let number = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    let parts: Vec<&str> = text.split(':').collect();
    if let [start, end, step] = parts.as_slice() {
        let (start, end, step) = number(start)
            .zip(number(end))
            .zip(number(step))
            .map(|((a, b), c)| (a, b, c))
            .ok_or_else(|| bad_angles(text))?;
        // A step count a rounding below an integer still reaches the end: 0:1:0.1 has 11.
        let count = ((end - start) / step + 1e-9).floor() + 1.0;
        if !(step > 0.0 && end >= start && count <= MAX_ANGLES as f64) {
            return Err(bad_angles(text));
        }
        return Ok((0..count as usize)
            .map(|i| start + i as f64 * step)
            .collect());
    }
    let list = text
        .split(',')
        .map(|s| number(s).ok_or_else(|| bad_angles(text)))
        .collect::<Result<Vec<_>>>()?;
    if list.is_empty() || list.len() > MAX_ANGLES {
        return Err(bad_angles(text));
    }
    Ok(list)
}
