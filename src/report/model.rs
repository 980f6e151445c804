//! What the report computed: plain data, no computation and no output.

use crate::integrand::IntegrandSpec;
use crate::montecarlo::McResult;
use crate::predict::{PredictParams, Prediction};
use crate::randomization::Randomization;
use crate::rate::{LowBandFit, ReferenceSpectrum, Study, StudyConfig};
use crate::render::{ComparisonConfig, ComparisonRow, PixelPowerParams, Reference, RenderParams};
use crate::sampler::SamplerKind;
use serde::Serialize;

/// The closure table: every sampler on integrands off the talk's setup, the default
/// prediction against Monte Carlo.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClosureConfig {
    /// Samplers.
    pub samplers: Vec<SamplerKind>,
    /// Integrands.
    pub integrands: Vec<IntegrandSpec>,
    /// N values.
    pub ns: Vec<usize>,
    /// Monte Carlo evaluations per sampler and N (pools for costly samplers).
    pub trials: usize,
    /// The predictions' parameters (their seed is the report's closure stream).
    #[serde(skip)]
    pub predict: PredictParams,
}

impl ClosureConfig {
    /// Every 2D sampler on the disk and the Gaussian of the talk, a Gaussian off centre (whose
    /// jumps at the faces Monte Carlo sees), a wide one (σ = 0.3) and a wide disk (r = 0.45,
    /// whose autocorrelation wraps around the torus), at N = 16, 64, 256, 1024 (or the valid
    /// count nearest each, for samplers with a count rule).
    pub fn full() -> Self {
        let gaussian = |sigma: f64, centre: Option<Vec<f64>>| IntegrandSpec::Gaussian {
            sigma,
            height: 1.0,
            centre,
        };
        let disk = |radius: f64| IntegrandSpec::Ball {
            radius,
            height: 1.0,
            centre: None,
            wrap: false,
        };
        Self {
            samplers: SamplerKind::in_dimension(2),
            integrands: vec![
                disk(0.25),
                gaussian(0.1, None),
                gaussian(0.1, Some(vec![0.3, 0.6])),
                gaussian(0.3, None),
                disk(0.45),
            ],
            ns: vec![16, 64, 256, 1024],
            trials: 20_000,
            predict: PredictParams::default(),
        }
    }
}

/// Edges at any angle: the variance of an edge through the centre against its angle for
/// samplers that stratify the axes, and its rate against N at 0° and 45°.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EdgesConfig {
    /// Samplers.
    pub samplers: Vec<SamplerKind>,
    /// Points per pattern of the orientation curves.
    pub n: usize,
    /// The curves' angles, in degrees.
    pub angles: Vec<f64>,
    /// The N values of the rates (the curves' N among them is measured once more).
    pub rate_ns: Vec<usize>,
    /// The rates' angles.
    pub rate_angles: Vec<f64>,
    /// Monte Carlo evaluations per sampler and N.
    pub trials: usize,
    /// The predictions' parameters.
    #[serde(skip)]
    pub predict: PredictParams,
}

impl EdgesConfig {
    /// Jitter, Latin hypercube, CMJ and Sobol at N = 256, angles 0° to 165° every 15° (the
    /// half turn: each angle's complement is 180° away, and CMJ and Sobol are not symmetric
    /// under reflections), rates
    /// at 0° and 45° over N = 64, 256, 1024, 4000 evaluations, predictions to 5% noise.
    pub fn standard() -> Self {
        Self {
            samplers: vec![
                SamplerKind::Jitter,
                SamplerKind::LatinHypercube,
                SamplerKind::Cmj,
                SamplerKind::Sobol,
            ],
            n: 256,
            angles: (0..12).map(|i| 15.0 * i as f64).collect(),
            rate_ns: vec![64, 256, 1024],
            rate_angles: vec![0.0, 45.0],
            trials: 4000,
            predict: PredictParams {
                target_noise: 0.05,
                ..PredictParams::default()
            },
        }
    }
}

/// Edges at any angle, computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EdgesSection {
    /// Per sampler, the orientation curve.
    pub curves: Vec<(SamplerKind, Vec<crate::anisotropy::OrientationRow>)>,
    /// Per sampler, the rates at the configured angles.
    pub rates: Vec<(SamplerKind, Vec<crate::anisotropy::EdgeRate>)>,
}

/// What the report computes. [`Default`] is the full run; [`ReportConfig::quick`] the short one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReportConfig {
    /// The short run.
    pub quick: bool,
    /// Seed of every random stream.
    pub seed: u64,
    /// The rate study (spectra, predictions and Monte Carlo over N).
    pub study: StudyConfig,
    /// The closure table.
    pub closure: ClosureConfig,
    /// Edges at any angle.
    pub edges: EdgesConfig,
    /// The estimator as used: strata and nets shifted and as used, on a seam.
    pub estimators: super::EstimatorsConfig,
    /// The budgets' coverage: estimated routes against exact truths.
    pub coverage: super::CoverageConfig,
    /// The ambient-occlusion renders.
    #[serde(skip)]
    pub ambient: ComparisonConfig,
    /// Where costly patterns and the render's reference are kept between runs (`None`: in
    /// memory only).
    #[serde(skip)]
    pub cache: Option<std::path::PathBuf>,
}

/// The seed of the talk's year, used by the main job.
pub const DEFAULT_SEED: u64 = 2016;

impl Default for ReportConfig {
    fn default() -> Self {
        Self::full(DEFAULT_SEED)
    }
}

/// The samplers of the talk's table.
pub const TALK_SAMPLERS: [SamplerKind; 4] = [
    SamplerKind::Random,
    SamplerKind::Jitter,
    SamplerKind::PoissonDisk,
    SamplerKind::Ccvt,
];

impl ReportConfig {
    /// Keeps costly patterns and the render's reference under `dir` (or nowhere, with `None`).
    pub fn set_cache(&mut self, dir: Option<std::path::PathBuf>) {
        self.study.patterns_cache = dir.clone();
        self.ambient.cache_dir = dir.clone();
        self.cache = dir;
    }

    /// Sets the budget of every part.
    pub fn set_budget(&mut self, budget: crate::budget::Budget) {
        self.study.predict.budget = budget;
        self.closure.predict.budget = budget;
        self.edges.predict.budget = budget;
        self.estimators.predict.budget = budget;
        self.coverage.predict.budget = budget;
    }

    /// The full run with `seed`: N = 16 … 4096, spectra at 4096.
    pub fn full(seed: u64) -> Self {
        Self {
            quick: false,
            seed,
            study: StudyConfig {
                dimension: 2,
                samplers: TALK_SAMPLERS.to_vec(),
                integrands: IntegrandSpec::talk_pair(),
                ns: vec![16, 36, 64, 144, 256, 576, 1024, 2304, 4096],
                trials: 20_000,
                seed,
                reference: ReferenceSpectrum {
                    n: 4096,
                    kmax: 320,
                    realizations: 256,
                    costly_realizations: 16,
                },
                randomization: crate::randomization::RandomizationChoice::Given(
                    Randomization::Shift,
                ),
                predict: PredictParams::default(),
                patterns_cache: None,
            },
            closure: ClosureConfig::full(),
            edges: EdgesConfig::standard(),
            estimators: super::EstimatorsConfig::standard(),
            coverage: super::CoverageConfig::standard(),
            ambient: ComparisonConfig {
                render: RenderParams {
                    seed,
                    ..Default::default()
                },
                ..Default::default()
            },
            cache: None,
        }
    }

    /// The short run with `seed`: N = 16 … 1024, spectra at 1024, a 32 × 32 render; predictions
    /// aim at 5% noise within a second of work each (their budgets say what they reach).
    pub fn quick(seed: u64) -> Self {
        let full = Self::full(seed);
        let quick_predictions = PredictParams {
            target_noise: 0.05,
            work_budget_seconds: 1.0,
            ..PredictParams::default()
        };
        Self {
            quick: true,
            study: StudyConfig {
                ns: vec![16, 64, 256, 1024],
                trials: 4000,
                reference: ReferenceSpectrum {
                    n: 1024,
                    kmax: 160,
                    realizations: 32,
                    costly_realizations: 4,
                },
                predict: quick_predictions,
                ..full.study
            },
            closure: ClosureConfig {
                ns: vec![16, 64, 256],
                trials: 4000,
                predict: quick_predictions,
                ..ClosureConfig::full()
            },
            estimators: super::EstimatorsConfig {
                ns: vec![64, 256],
                trials: 2000,
                predict: quick_predictions,
                ..super::EstimatorsConfig::standard()
            },
            coverage: super::CoverageConfig {
                ns: vec![64],
                ..super::CoverageConfig::standard()
            },
            edges: EdgesConfig {
                samplers: vec![SamplerKind::Jitter, SamplerKind::LatinHypercube],
                angles: (0..8).map(|i| 22.5 * i as f64).collect(),
                rate_ns: vec![64, 256],
                ..EdgesConfig::standard()
            },
            ambient: ComparisonConfig {
                width: 32,
                height: 32,
                reference_rays: 4096,
                render: RenderParams {
                    patterns: 256,
                    ..full.ambient.render
                },
                pixel_power: PixelPowerParams {
                    resolution: 32,
                    kmax: 48,
                    stride: 1,
                },
                spectrum_realizations: 64,
                ..full.ambient
            },
            ..full
        }
    }
}

/// The polar form with the study's reference spectrum rescaled to one N, where it is valid.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PolarComparison {
    /// Valid there: its prediction.
    Valid(Prediction),
    /// Not valid there: why.
    Invalid(String),
}

/// Beside a study series: the old route, the polar form rescaled from one reference spectrum,
/// at each N.
#[derive(Debug, Clone, Serialize)]
pub struct SeriesExtras {
    /// One per N of the series.
    pub polar: Vec<PolarComparison>,
}

/// One row of the closure table.
#[derive(Debug, Clone, Serialize)]
pub struct ClosureRow {
    /// The sampler.
    pub sampler: SamplerKind,
    /// The integrand's label.
    pub integrand: String,
    /// N.
    pub n: usize,
    /// The default prediction.
    pub prediction: Prediction,
    /// Monte Carlo.
    pub measured: McResult,
    /// The difference beyond the prediction's bounds, in combined standard errors (the
    /// prediction's noise and Monte Carlo's): 0 when the bounds cover it.
    pub z: f64,
    /// Whether they agree at 99%: `|z| ≤ 2.576`.
    pub agrees: bool,
}

/// The closure table with its summary.
#[derive(Debug, Clone, Serialize)]
pub struct ClosureTable {
    /// Every row.
    pub rows: Vec<ClosureRow>,
    /// Rows that do not agree at 99%.
    pub misses: usize,
    /// Misses expected at the nominal 1%.
    pub expected_misses: f64,
    /// `P(X ≥ misses)` for `X ~ Binomial(rows, 0.01)`: the chance of this many misses or more
    /// if every budget and interval means what it says.
    pub binomial_p: f64,
    /// The largest `|z|`.
    pub max_abs_z: f64,
}

/// Where two samplers' variance curves cross.
#[derive(Debug, Clone, Serialize)]
pub struct Crossover {
    /// Which curves.
    pub what: String,
    /// The N from the predicted curves (dense in N), if they cross in range.
    pub predicted: Option<f64>,
    /// The N from the Monte Carlo points (log-log interpolated), if they cross in range.
    pub measured: Option<f64>,
}

/// One cross-check with its numbers.
#[derive(Debug, Clone, Serialize)]
pub struct Check {
    /// What is checked.
    pub what: String,
    /// Whether it passed.
    pub pass: bool,
    /// The numbers, in words.
    pub detail: String,
}

/// The numbers behind the talk's 1D figures.
#[derive(Debug, Clone, Serialize)]
pub struct Illustration {
    /// Points of the regular grid whose spectrum is shown.
    pub grid_n: usize,
    /// `(k, P_S(k))` of that grid for `|k| ≤ 48`: `N` at multiples of N (the replicas), 0 else.
    pub grid_spectrum: Vec<(i64, f64)>,
    /// The integrand.
    pub integrand: String,
    /// `(k, |f̂(k)|²)` on a fine grid of real `|k| ≤ 24` (beyond, below 1e-16 of the peak).
    pub integrand_spectrum: Vec<(f64, f64)>,
    /// `(N, error from the spectrum Σ f̂(Nq)* Ŝ(Nq), error μ_N - I measured directly)`.
    pub errors: Vec<(usize, f64, f64)>,
}

/// The rendering experiment as the report ran it.
#[derive(Debug, Clone, Serialize)]
pub struct AmbientSection {
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// Rays per pixel of the reference.
    pub reference_rays: usize,
    /// Distinct patterns per image.
    pub patterns: usize,
    /// What the prediction's integrand is.
    pub power_label: String,
    /// Spectrum realizations per sampler for the prediction.
    pub spectrum_realizations: usize,
    /// The lattice extent of the prediction.
    pub kmax: usize,
    /// One row per sampler (with its image).
    pub rows: Vec<ComparisonRow>,
    /// The reference image.
    #[serde(skip)]
    pub reference: Reference,
}

/// How long a stage took.
#[derive(Debug, Clone, Serialize)]
pub struct Timing {
    /// The stage.
    pub stage: String,
    /// Seconds.
    pub seconds: f64,
}

/// Everything the report computed.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// What was asked.
    pub config: ReportConfig,
    /// The rate study: spectra, predictions, Monte Carlo and rates.
    pub study: Study,
    /// Per study series, in its order: the polar form rescaled from the reference spectrum.
    pub extras: Vec<SeriesExtras>,
    /// Every sampler on integrands off the talk's setup.
    pub closure: ClosureTable,
    /// Crossovers of one sampler's variance curve with another's.
    pub crossovers: Vec<Crossover>,
    /// CCVT's low band `a ν² + b ν⁴` fitted on its reference spectrum, with the floor the
    /// capacity predicts (if CCVT is in the study).
    pub ccvt_low_band: Option<(LowBandFit, f64)>,
    /// The 1D illustration numbers.
    pub illustration: Illustration,
    /// Edges at any angle.
    pub edges: EdgesSection,
    /// The estimator as used: strata and nets shifted and as used, on a seam.
    pub estimators: super::EstimatorsSection,
    /// The budgets' coverage: estimated routes against exact truths.
    pub coverage: super::CoverageSection,
    /// The rendering experiment.
    pub ambient: AmbientSection,
    /// Every cross-check.
    pub checks: Vec<Check>,
    /// Seconds per stage.
    pub timings: Vec<Timing>,
}

impl Report {
    /// How many checks passed.
    pub fn passed(&self) -> usize {
        self.checks.iter().filter(|c| c.pass).count()
    }
}
