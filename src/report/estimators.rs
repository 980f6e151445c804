//! The report's section on the estimator as used: every stratified sampler and scrambled net on
//! an integrand that jumps at the square's faces (a pixel's light falloff cut by its edges),
//! shifted (the talk's homogenized estimator) and as used (the sampler's native randomization,
//! a renderer's: as drawn, or a digital shift for the unscrambled net), each predicted by its own
//! route and measured by Monte Carlo of the same estimator.

use crate::crosscheck::beside_monte_carlo;
use crate::error::Result;
use crate::integrand::IntegrandSpec;
use crate::montecarlo::{McParams, McResult};
use crate::predict::{PredictParams, Prediction};
use crate::progress::Silent;
use crate::randomization::Randomization;
use crate::sampler::SamplerKind;
use serde::Serialize;

/// The section's seed streams, independent of the others.
const PREDICT_STREAM: u64 = 0xE1;
const MC_STREAM: u64 = 0xE2;

/// What the section computes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EstimatorsConfig {
    /// Samplers (each with a cell form or the aliased-pair form as drawn, or fixed under a
    /// digital shift).
    pub samplers: Vec<SamplerKind>,
    /// The integrand.
    pub integrand: IntegrandSpec,
    /// N values (the valid count nearest each, for samplers with a count rule).
    pub ns: Vec<usize>,
    /// Monte Carlo evaluations per sampler, N and estimator.
    pub trials: usize,
    /// The predictions' parameters.
    #[serde(skip)]
    pub predict: PredictParams,
}

impl EstimatorsConfig {
    /// Jitter, Gaussian jitter, Latin hypercube, multi-jitter, CMJ, orthogonal arrays, Sobol',
    /// PMJ02 and the digitally shifted Sobol' net on the
    /// Gaussian of σ = 0.3 centred at (0.7, 0.2), which the square's faces cut at a tenth to a
    /// half of its peak, at N = 16 … 1024; 4000 evaluations; predictions to 5% noise.
    pub fn standard() -> Self {
        Self {
            samplers: vec![
                SamplerKind::Jitter,
                SamplerKind::GaussianJitter,
                SamplerKind::LatinHypercube,
                SamplerKind::MultiJitter,
                SamplerKind::Cmj,
                SamplerKind::OrthogonalArray,
                SamplerKind::Sobol,
                SamplerKind::Pmj02,
                SamplerKind::SobolNet,
            ],
            integrand: IntegrandSpec::Gaussian {
                sigma: 0.3,
                height: 1.0,
                centre: Some(vec![0.7, 0.2]),
            },
            ns: vec![16, 64, 256, 1024],
            trials: 4000,
            predict: PredictParams {
                target_noise: 0.05,
                ..PredictParams::default()
            },
        }
    }
}

/// One sampler at one N under one estimator.
#[derive(Debug, Clone, Serialize)]
pub struct EstimatorRow {
    /// The sampler.
    pub sampler: SamplerKind,
    /// N.
    pub n: usize,
    /// The estimator.
    pub randomization: Randomization,
    /// Its default prediction.
    pub prediction: Prediction,
    /// Monte Carlo of the same estimator.
    pub measured: McResult,
    /// The difference beyond the prediction's bounds in combined standard errors.
    pub z: f64,
}

/// The section, computed.
#[derive(Debug, Clone, Serialize)]
pub struct EstimatorsSection {
    /// The integrand's label.
    pub integrand: String,
    /// Every row: per sampler and N, the shifted estimator then the one as used.
    pub rows: Vec<EstimatorRow>,
}

/// Runs the section.
///
/// # Errors
/// A sampler, prediction or Monte Carlo error.
pub fn compute(config: &EstimatorsConfig, seed: u64) -> Result<EstimatorsSection> {
    let f = config.integrand.build(2)?;
    let params = PredictParams {
        seed: seed ^ PREDICT_STREAM,
        ..config.predict
    };
    let mut rows = Vec::new();
    for &kind in &config.samplers {
        let sampler = kind.build(2)?;
        let ns = kind.nearest_counts(&config.ns, 2);
        for n in ns {
            for randomization in [Randomization::Shift, kind.native_randomization()] {
                let mut mc = McParams::pooled(kind, config.trials, seed ^ MC_STREAM, randomization);
                mc.budget = config.predict.budget;
                let pairs = beside_monte_carlo(
                    sampler.as_ref(),
                    &[f.as_ref()],
                    n,
                    &mc,
                    &params,
                    ("", &Silent),
                )?;
                for (measured, prediction) in pairs {
                    rows.push(EstimatorRow {
                        sampler: kind,
                        n,
                        randomization,
                        z: prediction.z_beyond_bounds(&measured),
                        prediction,
                        measured,
                    });
                }
            }
        }
    }
    Ok(EstimatorsSection {
        integrand: f.label(),
        rows,
    })
}

/// The shifted row and the row as used of each sampler and N, in order.
pub fn pairs(section: &EstimatorsSection) -> impl Iterator<Item = (&EstimatorRow, &EstimatorRow)> {
    section
        .rows
        .chunks_exact(2)
        .map(|pair| (&pair[0], &pair[1]))
}
