//! What the report computed: plain data, no computation and no output.

use crate::integrand::IntegrandSpec;
use crate::predict::Prediction;
use crate::rate::{ReferenceSpectrum, Study, StudyConfig};
use crate::render::{ComparisonConfig, ComparisonRow, PixelPowerParams, Reference, RenderParams};
use crate::sampler::SamplerKind;
use serde::Serialize;

/// The lattice form with the spectrum estimated at the target N itself, computed up to `max_n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct TargetSpectrum {
    /// The largest N at which it is computed.
    pub max_n: usize,
    /// Realizations of each spectrum.
    pub realizations: usize,
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
    /// The lattice form at the target N.
    pub target: TargetSpectrum,
    /// The ambient-occlusion renders.
    #[serde(skip)]
    pub ambient: ComparisonConfig,
}

/// The seed of the talk's year, used by the main job.
pub const DEFAULT_SEED: u64 = 2016;

impl Default for ReportConfig {
    fn default() -> Self {
        Self::full(DEFAULT_SEED)
    }
}

/// The report's two integrands: the disk of radius 1/4 and the Gaussian σ = 0.1, centred.
fn talk_integrands() -> Vec<IntegrandSpec> {
    vec![
        IntegrandSpec::Ball {
            radius: 0.25,
            height: 1.0,
            centre: None,
        },
        IntegrandSpec::Gaussian {
            sigma: 0.1,
            height: 1.0,
            centre: None,
        },
    ]
}

/// The samplers of the talk's table.
pub const TALK_SAMPLERS: [SamplerKind; 4] = [
    SamplerKind::Random,
    SamplerKind::Jitter,
    SamplerKind::PoissonDisk,
    SamplerKind::Ccvt,
];

impl ReportConfig {
    /// The full run with `seed`: N = 16 … 4096, spectra at 4096.
    pub fn full(seed: u64) -> Self {
        Self {
            quick: false,
            seed,
            study: StudyConfig {
                dimension: 2,
                samplers: TALK_SAMPLERS.to_vec(),
                integrands: talk_integrands(),
                ns: vec![16, 36, 64, 144, 256, 576, 1024, 2304, 4096],
                trials: 20_000,
                seed,
                reference: ReferenceSpectrum {
                    n: 4096,
                    kmax: 320,
                    realizations: 256,
                    costly_realizations: 16,
                },
            },
            target: TargetSpectrum {
                max_n: 256,
                realizations: 64,
            },
            ambient: ComparisonConfig {
                render: RenderParams {
                    seed,
                    ..Default::default()
                },
                ..Default::default()
            },
        }
    }

    /// The short run with `seed`: N = 16 … 1024, spectra at 1024, a 32 × 32 render.
    pub fn quick(seed: u64) -> Self {
        let full = Self::full(seed);
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
                ..full.study
            },
            target: TargetSpectrum {
                max_n: 64,
                realizations: 16,
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

/// Predictions beside a study series that the study itself does not make.
#[derive(Debug, Clone, Serialize)]
pub struct SeriesExtras {
    /// The polar form with the closed-form spectrum at each N (random and jitter; else empty).
    pub closed: Vec<Prediction>,
    /// The lattice form with the spectrum estimated at each N up to the target's `max_n`.
    pub at_target: Vec<Prediction>,
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
    /// Per study series, in its order: the closed-form and at-target predictions.
    pub extras: Vec<SeriesExtras>,
    /// Crossovers of one sampler's variance curve with another's.
    pub crossovers: Vec<Crossover>,
    /// The 1D illustration numbers.
    pub illustration: Illustration,
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
