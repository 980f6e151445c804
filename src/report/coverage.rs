//! The report's coverage of the budgets: estimated predictions against exact truths of the same
//! problem.
//!
//! Every estimated route says how far it may be from the variance it estimates (its noise at 99%
//! plus its bounds). Where the same estimator also has an exact route (a closed-form spectrum,
//! the per-pair sums of Latin hypercube and multi-jitter, Owen's gains, a fixed pattern's pair
//! sum), the exact value is a truth with no noise of its own, and the fraction of estimates
//! whose interval misses it measures the budgets' coverage directly: at 99% it should be about
//! 1%. The matrix crosses samplers and estimators with integrands that jump (a disk, an edge,
//! an axis-aligned square) and one cut by the faces (a seam), at N from 64 to 1024.

use crate::error::{Error, Result};
use crate::integrand::{Integrand, IntegrandSpec};
use crate::montecarlo::Z_99;
use crate::predict::{predict, predict_many, PredictParams, Prediction, Problem, SpectrumChoice};
use crate::progress::Silent;
use crate::randomization::Randomization;
use crate::sampler::{Sampler, SamplerKind};
use rayon::prelude::*;
use serde::Serialize;

/// The section's seed stream, independent of the others.
const PREDICT_STREAM: u64 = 0xD1;
/// The largest share of estimates whose 99% interval may miss the exact value: the nominal 1%
/// with room for a binomial count over a matrix of about a hundred cases.
pub const MAX_MISS_FRACTION: f64 = 0.02;

/// One estimator whose estimated route is checked: a sampler under a randomization, where the
/// default route is exact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CoverageCase {
    /// The sampler.
    pub sampler: SamplerKind,
    /// The estimator.
    pub randomization: Randomization,
}

/// What the section computes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CoverageConfig {
    /// The estimators.
    pub cases: Vec<CoverageCase>,
    /// The integrands.
    pub integrands: Vec<IntegrandSpec>,
    /// N values (the valid count nearest each, for samplers with a count rule).
    pub ns: Vec<usize>,
    /// The estimated predictions' parameters (their spectrum is set to estimated).
    #[serde(skip)]
    pub predict: PredictParams,
}

impl CoverageConfig {
    /// Random, jitter and Latin hypercube shifted (closed-form spectra), Latin hypercube,
    /// multi-jitter, CMJ and Owen-scrambled Sobol' as drawn (pairs in closed form, Owen's
    /// gains; CMJ's estimate is the one it takes beyond its table, from its permutations with
    /// a control variate), and the unscrambled Sobol' net shifted (its pair sum), each
    /// estimated from patterns; on a
    /// disk, a Gaussian cut by the faces, an edge at 30° and an axis-aligned square; at N = 64,
    /// 256 and 1024. Estimates aim at 2% noise.
    pub fn standard() -> Self {
        let case = |sampler, randomization| CoverageCase {
            sampler,
            randomization,
        };
        Self {
            cases: vec![
                case(SamplerKind::Random, Randomization::Shift),
                case(SamplerKind::Jitter, Randomization::Shift),
                case(SamplerKind::LatinHypercube, Randomization::Shift),
                case(SamplerKind::LatinHypercube, Randomization::None),
                case(SamplerKind::MultiJitter, Randomization::None),
                case(SamplerKind::Cmj, Randomization::None),
                case(SamplerKind::Sobol, Randomization::None),
                case(SamplerKind::SobolNet, Randomization::Shift),
            ],
            integrands: vec![
                IntegrandSpec::Ball {
                    radius: 0.25,
                    height: 1.0,
                    centre: None,
                    wrap: false,
                },
                IntegrandSpec::Gaussian {
                    sigma: 0.2,
                    height: 1.0,
                    centre: Some(vec![0.2, 0.7]),
                },
                IntegrandSpec::Edge {
                    theta: 30.0,
                    offset: 0.5,
                    height: 1.0,
                },
                IntegrandSpec::Polygon {
                    vertices: vec![[0.2, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]],
                },
            ],
            ns: vec![64, 256, 1024],
            predict: PredictParams::default(),
        }
    }
}

/// One estimate against its exact truth.
#[derive(Debug, Clone, Serialize)]
pub struct CoverageRow {
    /// The estimator.
    pub case: CoverageCase,
    /// The integrand's label.
    pub integrand: String,
    /// N.
    pub n: usize,
    /// The exact prediction (the default route).
    pub truth: Prediction,
    /// The estimated prediction, with its budget.
    pub estimate: Prediction,
    /// Whether the estimate's 99% interval (widened by the truth's rounding) holds the truth.
    pub covered: bool,
}

/// The section, computed.
#[derive(Debug, Clone, Serialize)]
pub struct CoverageSection {
    /// Every case, integrand and N.
    pub rows: Vec<CoverageRow>,
    /// Estimates whose interval misses the truth.
    pub misses: usize,
    /// Their share of the rows.
    pub miss_fraction: f64,
    /// The median over rows of the interval's half-width relative to the truth.
    pub median_relative_width: f64,
}

/// One estimator and count, every integrand: their exact truths, and their estimates drawn
/// from the same patterns (each row's interval is its own; the patterns they share make the
/// misses of one estimator and count dependent, which moves the spread of the miss count, not
/// its expectation).
fn coverage_rows(
    case: CoverageCase,
    sampler: &dyn Sampler,
    n: usize,
    fs: &[&dyn Integrand],
    exact: &PredictParams,
    estimated: &PredictParams,
) -> Result<Vec<CoverageRow>> {
    let problems = fs
        .iter()
        .map(|f| Ok(Problem::new(sampler, *f, n)?.with_randomization(case.randomization)))
        .collect::<Result<Vec<_>>>()?;
    let truths = problems
        .iter()
        .map(|problem| predict(problem, exact))
        .collect::<Result<Vec<_>>>()?;
    if let Some((truth, f)) = truths
        .iter()
        .zip(fs)
        .find(|(truth, _)| truth.budget.spectrum_noise != 0.0)
    {
        return Err(Error::Mismatch(format!(
            "{} {} at N = {n} on {}: the default route ({}) has noise, so it is no truth",
            case.sampler,
            case.randomization,
            f.label(),
            truth.route
        )));
    }
    let estimates = predict_many(&problems, estimated, &Silent)?;
    Ok(truths
        .into_iter()
        .zip(estimates)
        .zip(fs)
        .map(|((truth, estimate), f)| {
            let allowed = estimate.budget.half_width(Z_99) + truth.budget.half_width(0.0);
            CoverageRow {
                case,
                integrand: f.label(),
                n,
                covered: (estimate.variance - truth.variance).abs() <= allowed,
                truth,
                estimate,
            }
        })
        .collect())
}

/// Runs the section.
///
/// # Errors
/// A sampler or prediction error, or a default route that is not exact (a truth with noise).
pub fn compute(config: &CoverageConfig, seed: u64) -> Result<CoverageSection> {
    let exact = PredictParams {
        seed: seed ^ PREDICT_STREAM,
        ..config.predict
    };
    let estimated = PredictParams {
        spectrum: SpectrumChoice::Estimated,
        ..exact
    };
    let fs = config
        .integrands
        .iter()
        .map(|s| s.build(2))
        .collect::<Result<Vec<_>>>()?;
    // Every row is deterministic on its own, so they run side by side (one row's sequential
    // steps overlapping another's parallel ones) and are kept in the matrix's order.
    let samplers = config
        .cases
        .iter()
        .map(|case| case.sampler.build(2))
        .collect::<Result<Vec<_>>>()?;
    let f_refs: Vec<&dyn Integrand> = fs.iter().map(|f| f.as_ref()).collect();
    let mut cells = Vec::new();
    for (c, case) in config.cases.iter().enumerate() {
        cells.extend(
            case.sampler
                .nearest_counts(&config.ns, 2)
                .into_iter()
                .map(|n| (c, n)),
        );
    }
    let rows: Vec<CoverageRow> = cells
        .par_iter()
        .map(|&(c, n)| {
            let case = config.cases[c];
            coverage_rows(case, samplers[c].as_ref(), n, &f_refs, &exact, &estimated)
        })
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let misses = rows.iter().filter(|r| !r.covered).count();
    let mut widths: Vec<f64> = rows
        .iter()
        .map(|r| r.estimate.budget.half_width(Z_99) / r.truth.variance)
        .collect();
    widths.sort_by(f64::total_cmp);
    Ok(CoverageSection {
        miss_fraction: misses as f64 / rows.len().max(1) as f64,
        median_relative_width: widths.get(widths.len() / 2).copied().unwrap_or(f64::NAN),
        misses,
        rows,
    })
}
