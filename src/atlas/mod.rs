//! The sampler atlas: for every 2D sampler, its points, spectrum, low-frequency exponent,
//! effective Nyquist frequency, pair correlation function and discrepancies, and its predicted
//! variance on the disk and the Gaussian beside Monte Carlo: the page a researcher sends to a
//! colleague.

mod write;

pub use write::{atlas_markdown, write_atlas};

use crate::error::{Error, Result};
use crate::integrand::{Integrand, IntegrandSpec};
use crate::metrics::{
    discrepancy_means, distance_summary, effective_nyquist, pair_correlation, DiscrepancyKind,
    Distances, Mean, Pcf, PcfParams,
};
use crate::montecarlo::{empirical_variances, McParams, McResult, Z_99};
use crate::pointset::PointSet;
use crate::predict::{predict_many, PredictParams, Prediction, Problem};
use crate::progress::{Progress, Silent};
use crate::randomization::{Randomization, RandomizationChoice};
use crate::rate::{fit_alpha, theory_rate, AlphaFit};
use crate::sampler::{Sampler, SamplerKind};
use crate::spectrum::{estimate_with_progress, PatternSource, SpectrumEstimate, SpectrumParams};
use rayon::prelude::*;
use serde::Serialize;

/// What the atlas computes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AtlasConfig {
    /// Samplers (2D).
    pub samplers: Vec<SamplerKind>,
    /// Points per pattern for the pictures, metrics, predictions and Monte Carlo (the nearest
    /// valid count for samplers with a count rule).
    pub n: usize,
    /// Patterns for the spectrum and the metrics (costly samplers: a quarter).
    pub realizations: usize,
    /// Points per pattern for the fit of `α` (many rings below `ν = 0.3`).
    pub alpha_n: usize,
    /// Monte Carlo evaluations per sampler.
    pub trials: usize,
    /// Seed of every stream.
    pub seed: u64,
    /// The estimator of the predictions and Monte Carlo: each sampler under the shift (the
    /// talk's homogenized estimator, the default), as it is used (`Native`), or under one
    /// randomization for all.
    pub randomization: RandomizationChoice,
    /// Where costly patterns are cached.
    #[serde(skip)]
    pub cache: Option<std::path::PathBuf>,
    /// What predictions and Monte Carlo may spend.
    #[serde(skip)]
    pub budget: crate::budget::Budget,
}

impl AtlasConfig {
    /// Every 2D sampler at N = 256, 64 patterns, α fitted at N = 4096, 20 000 trials.
    pub fn full(seed: u64) -> Self {
        Self {
            samplers: SamplerKind::in_dimension(2),
            n: 256,
            realizations: 64,
            alpha_n: 4096,
            trials: 20_000,
            seed,
            randomization: RandomizationChoice::Given(Randomization::Shift),
            cache: None,
            budget: crate::budget::Budget::default(),
        }
    }

    /// A short run: 16 patterns, α at N = 1024, 4000 trials.
    pub fn quick(seed: u64) -> Self {
        Self {
            realizations: 16,
            alpha_n: 1024,
            trials: 4000,
            ..Self::full(seed)
        }
    }

    /// Errors unless the configuration can be computed: N in [`ATLAS_N`].
    ///
    /// # Errors
    /// An N outside [`ATLAS_N`].
    pub fn check(&self) -> Result<()> {
        if !ATLAS_N.contains(&self.n) {
            return Err(crate::error::invalid(
                "N",
                self.n,
                format!(
                    "{} to {} (the metrics cost N² per pattern)",
                    ATLAS_N.start(),
                    ATLAS_N.end()
                ),
            ));
        }
        Ok(())
    }
}

/// The upper end of the band where `α` is fitted.
pub const ALPHA_BAND: f64 = 0.3;

/// One integrand's prediction beside Monte Carlo.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AtlasRow {
    /// The integrand.
    pub integrand: String,
    /// The default prediction, or `None` where the estimator has no route.
    pub predicted: Option<Prediction>,
    /// Why there is no prediction.
    pub unpredicted: Option<String>,
    /// Monte Carlo (`None` for a fixed pattern used as drawn: every trial is the same
    /// pattern, with a bias and no variance to measure).
    pub measured: Option<McResult>,
    /// The gap beyond the prediction's bounds, in combined standard errors.
    pub z: Option<f64>,
    /// The estimator: how each pattern was randomized.
    pub randomization: Randomization,
    /// The asymptotic rate from `α` (known, else fitted) and the integrand's decay, with
    /// whether a `log N` factor multiplies it: for the shifted estimator, whose variance the
    /// spectrum's low-frequency law decides.
    pub rate: Option<(f64, bool)>,
}

/// One sampler's page.
#[derive(Debug, Clone, Serialize)]
pub struct AtlasEntry {
    /// The sampler.
    pub sampler: SamplerKind,
    /// Points per pattern.
    pub n: usize,
    /// Realization 0, for the picture.
    #[serde(skip)]
    pub points: PointSet,
    /// The expected spectrum at `n`.
    #[serde(skip)]
    pub spectrum: SpectrumEstimate,
    /// `α` fitted on `ν ≤ 0.3` at `alpha_n` points, or why it could not be.
    pub alpha_fit: std::result::Result<AlphaFit, String>,
    /// `α` as the sampler's facts give it, if known.
    pub known_alpha: Option<f64>,
    /// The effective Nyquist frequency.
    pub effective_nyquist: Option<f64>,
    /// The pair correlation function.
    pub pcf: Pcf,
    /// Squared discrepancies: mean over the patterns and standard error.
    pub discrepancies: Vec<(DiscrepancyKind, Mean)>,
    /// The smallest distance over the patterns and the mean nearest-neighbour distance,
    /// relative to the densest packing's.
    pub distances: Distances,
    /// Predictions beside Monte Carlo.
    pub rows: Vec<AtlasRow>,
}

/// The atlas.
#[derive(Debug, Clone, Serialize)]
pub struct Atlas {
    /// What was computed.
    pub config: AtlasConfig,
    /// One entry per sampler.
    pub entries: Vec<AtlasEntry>,
}

/// Computes every sampler's entry.
///
/// # Errors
/// A sampler that cannot be drawn, or any computation's error (budgets, validity).
pub fn compute_atlas(config: &AtlasConfig, progress: &dyn Progress) -> Result<Atlas> {
    config.check()?;
    let fs: Vec<Box<dyn Integrand>> = IntegrandSpec::talk_pair()
        .iter()
        .map(|s| s.build(2))
        .collect::<Result<_>>()?;
    // Each entry draws from its own seeds, so the samplers run side by side with the same
    // result; the progress is one step per sampler (the stages inside would interleave).
    progress.begin("atlas: samplers", config.samplers.len() as u64);
    let entries = config
        .samplers
        .par_iter()
        .map(|&kind| {
            let e = entry(kind, config, &fs);
            progress.advance(1);
            e
        })
        .collect::<Result<_>>();
    progress.end();
    let entries = entries?;
    Ok(Atlas {
        config: config.clone(),
        entries,
    })
}

fn entry(kind: SamplerKind, config: &AtlasConfig, fs: &[Box<dyn Integrand>]) -> Result<AtlasEntry> {
    let sampler = crate::cache::cached_sampler(
        kind,
        2,
        config.cache.as_deref(),
        crate::cache::PATTERN_MEMORY,
    )?;
    let n = kind.nearest_count(config.n, 2);
    let realizations = kind.spectrum_realizations(config.realizations);
    let patterns = (0..realizations as u64)
        .into_par_iter()
        .map(|r| sampler.sample(n, config.seed, r))
        .collect::<Result<Vec<_>>>()?;
    let spectrum = spectrum_of(&patterns, n)?;
    let alpha_fit = alpha_at(sampler.as_ref(), kind, config);
    let known_alpha = kind.known_alpha();
    let alpha = known_alpha.or(alpha_fit.as_ref().ok().map(|f| f.alpha));
    Ok(AtlasEntry {
        sampler: kind,
        n,
        effective_nyquist: effective_nyquist(&spectrum.radial),
        pcf: pair_correlation(&patterns, &PcfParams::default().within_torus(n, 2))?,
        discrepancies: discrepancy_means(&patterns)?,
        distances: distance_summary(&patterns, &Default::default())?,
        rows: rows(sampler.as_ref(), kind, n, alpha, config, fs)?,
        points: patterns[0].clone(),
        spectrum,
        alpha_fit,
        known_alpha,
    })
}

/// The points per pattern an atlas can show: enough for a spectrum, few enough for the pair
/// metrics, which cost N² per pattern.
pub const ATLAS_N: std::ops::RangeInclusive<usize> = 16..=65_536;

/// How far in `ν` the atlas draws each spectrum: past the blue-noise peaks and the first
/// replicas of the strata and lattices.
const SPECTRUM_NU: f64 = 3.0;

/// The spectrum at N up to [`SPECTRUM_NU`].
fn spectrum_of(patterns: &[PointSet], n: usize) -> Result<SpectrumEstimate> {
    let params = SpectrumParams {
        kmax: crate::spectrum::kmax_at_nu(n, 2, SPECTRUM_NU),
        ..SpectrumParams::default()
    };
    estimate_with_progress(PatternSource::Sets(patterns), &params, &Silent)
}

/// `α` fitted on the rings below [`ALPHA_BAND`] at `alpha_n` points, or the reason it cannot be
/// (a spectrum that is zero near DC, as a lattice's, has no power law to fit).
fn alpha_at(
    sampler: &dyn Sampler,
    kind: SamplerKind,
    config: &AtlasConfig,
) -> std::result::Result<AlphaFit, String> {
    if kind.is_deterministic() {
        return Err(
            "a fixed pattern: every realization has the same spectrum (no sampling \
                    noise to weigh a fit), made of peaks (its lattice's or the Fejér kernel's), \
                    not a power law near DC"
                .into(),
        );
    }
    let n = kind.nearest_count(config.alpha_n, 2);
    let realizations = kind.spectrum_realizations(config.realizations);
    let params = SpectrumParams {
        kmax: crate::spectrum::kmax_at_nu(n, 2, 2.0 * ALPHA_BAND),
        realizations,
        seed: config.seed,
        budget: config.budget,
        ..SpectrumParams::default()
    };
    let source = PatternSource::Sampler {
        sampler,
        n,
        seed: config.seed,
    };
    let estimate = estimate_with_progress(source, &params, &Silent).map_err(|e| e.to_string())?;
    fit_alpha(&estimate.radial, 0.0, ALPHA_BAND).map_err(|e| e.to_string())
}

fn rows(
    sampler: &dyn Sampler,
    kind: SamplerKind,
    n: usize,
    alpha: Option<f64>,
    config: &AtlasConfig,
    fs: &[Box<dyn Integrand>],
) -> Result<Vec<AtlasRow>> {
    let f_refs: Vec<&dyn Integrand> = fs.iter().map(|f| f.as_ref()).collect();
    let randomization = config.randomization.resolve(kind.native_randomization());
    let mut mc = McParams::pooled(
        kind,
        config.trials,
        config.seed ^ ATLAS_MC_STREAM,
        randomization,
    );
    mc.budget = config.budget;
    let params = PredictParams {
        seed: config.seed ^ ATLAS_PREDICT_STREAM,
        budget: config.budget,
        ..PredictParams::default()
    };
    // A fixed rule used as drawn integrates every trial with the same pattern: its estimator
    // has a bias (`specvar bias`) and no variance, so there is nothing to measure.
    let fixed = kind.is_deterministic() && randomization == Randomization::None;
    let measured: Vec<Option<McResult>> = if fixed {
        vec![None; f_refs.len()]
    } else {
        empirical_variances(sampler, &f_refs, n, &mc, &Silent)?
            .into_iter()
            .map(Some)
            .collect()
    };
    let problems = f_refs
        .iter()
        .map(|f| Problem::new(sampler, *f, n).map(|p| p.with_randomization(randomization)))
        .collect::<Result<Vec<_>>>()?;
    // An estimator without a route is measured alone, with the reason.
    let (predictions, unpredicted) = match predict_many(&problems, &params, &Silent) {
        Ok(p) => (p.into_iter().map(Some).collect(), None),
        Err(e @ Error::OutsideValidity { .. }) => (vec![None; f_refs.len()], Some(e.to_string())),
        Err(e) => return Err(e),
    };
    Ok(f_refs
        .iter()
        .zip(measured)
        .zip(predictions)
        .map(|((f, measured), predicted)| AtlasRow {
            integrand: f.label(),
            z: predicted
                .as_ref()
                .zip(measured.as_ref())
                .map(|(p, m)| p.z_beyond_bounds(m)),
            randomization,
            rate: alpha
                .filter(|_| randomization == Randomization::Shift)
                .map(|a| theory_rate(a, f.decay_exponent(), 2)),
            unpredicted: unpredicted.clone(),
            predicted,
            measured,
        })
        .collect())
}

/// The atlas's Monte Carlo and prediction streams, independent of the report's.
const ATLAS_MC_STREAM: u64 = 0xA71A_5000_0000_0001;
const ATLAS_PREDICT_STREAM: u64 = 0xA71A_5000_0000_0002;

impl AtlasRow {
    /// Whether the prediction agrees with Monte Carlo at 99% (`None` without a prediction).
    pub fn agrees(&self) -> Option<bool> {
        self.z.map(|z| z.abs() <= Z_99)
    }
}
