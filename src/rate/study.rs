//! The rate study: samplers × integrands × N, with the theoretical, predicted and measured
//! convergence rates. `specvar rates` and the report both run [`run_study`].

use super::{fit_alpha, loglog_slope, loglog_slope_with_weights, theory_rate, AlphaFit, SlopeFit};
use crate::cache::PATTERN_MEMORY;
use crate::error::{invalid, Result};
use crate::integrand::{Integrand, IntegrandSpec};
use crate::montecarlo::{
    errors_of_patterns, result_from_errors, McParams, McResult, PatternErrors, Z_99,
};
use crate::predict::{predict_many, PredictParams, Prediction, Problem};
use crate::progress::{stage, Progress};
use crate::randomization::{Randomization, RandomizationChoice};
use crate::sampler::SamplerKind;
use crate::spectrum::{estimate, Engine, SpectrumEstimate, SpectrumParams};
use serde::Serialize;

/// The spectrum each sampler's predictions are rescaled from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpectrum {
    /// The reference N.
    pub n: usize,
    /// The lattice extent `K`.
    pub kmax: usize,
    /// Realizations for cheap samplers.
    pub realizations: usize,
    /// Realizations for costly samplers ([`SamplerKind::is_costly`]: CCVT, Gaussian blue noise;
    /// by default [`crate::sampler::costly_realizations`] of the cheap ones).
    pub costly_realizations: usize,
}

impl ReferenceSpectrum {
    /// The realizations of `kind`'s reference spectrum: the costly ones' for a costly sampler
    /// ([`SamplerKind::is_costly`]).
    pub fn realizations_for(&self, kind: SamplerKind) -> usize {
        if kind.is_costly() {
            self.costly_realizations
        } else {
            self.realizations
        }
    }
}

/// What a rate study computes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StudyConfig {
    /// Dimension (1 to 3).
    pub dimension: usize,
    /// Samplers.
    pub samplers: Vec<SamplerKind>,
    /// Integrands.
    pub integrands: Vec<IntegrandSpec>,
    /// The N values (at least two distinct).
    pub ns: Vec<usize>,
    /// Monte Carlo estimator evaluations per N (pools for costly samplers:
    /// [`SamplerKind::pool`]).
    pub trials: usize,
    /// Seed of the spectra; the predictions' and the Monte Carlo patterns use independent
    /// streams of it.
    pub seed: u64,
    /// The reference spectrum (for `α` and the plots; predictions estimate what they need).
    pub reference: ReferenceSpectrum,
    /// How each pattern is randomized: the estimator predicted and measured (by default the
    /// random shift, the talk's homogenized estimator; `Native`: each sampler as it is used).
    pub randomization: RandomizationChoice,
    /// The predictions' parameters (their seed is the study's prediction stream).
    #[serde(skip)]
    pub predict: PredictParams,
    /// Where costly patterns are kept between runs ([`crate::cache::cached_sampler`]); `None`:
    /// in memory only.
    #[serde(skip)]
    pub patterns_cache: Option<std::path::PathBuf>,
}

impl Default for StudyConfig {
    fn default() -> Self {
        Self::in_dimension(2)
    }
}

impl StudyConfig {
    /// The default study in dimension `d`: random, jitter, Poisson disk and CCVT on the ball of
    /// radius 1/4 and the Gaussian σ = 0.1, N = 16 … 1024, spectra at the default reference N
    /// of [`crate::predict::default_reference_n`] with `ν` up to 5.
    pub fn in_dimension(d: usize) -> Self {
        let n_ref = crate::predict::default_reference_n(d);
        Self {
            dimension: d,
            samplers: vec![
                SamplerKind::Random,
                SamplerKind::Jitter,
                SamplerKind::PoissonDisk,
                SamplerKind::Ccvt,
            ],
            integrands: IntegrandSpec::talk_pair(),
            ns: rate_ns(16, 1024, d),
            trials: 4000,
            seed: 0,
            reference: ReferenceSpectrum {
                n: n_ref,
                kmax: crate::predict::default_kmax(n_ref, d),
                realizations: 64,
                costly_realizations: crate::sampler::costly_realizations(64),
            },
            randomization: RandomizationChoice::Given(Randomization::Shift),
            predict: PredictParams::default(),
            patterns_cache: None,
        }
    }
}

/// A study as text describes it (JSON from Python, or a file), with the library's defaults
/// ([`StudyConfig::in_dimension`]) for what it leaves out: the one schema of a study outside
/// Rust.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudyDescription {
    /// Dimension (1 to 3).
    pub dimension: usize,
    /// Samplers, by name.
    pub samplers: Vec<SamplerKind>,
    /// Integrands, as specification text.
    pub integrands: Vec<IntegrandSpec>,
    /// The N values.
    pub ns: Vec<usize>,
    /// Monte Carlo evaluations per N.
    pub trials: usize,
    /// Seed.
    pub seed: u64,
    /// The reference spectrum (`null`: the default for the dimension).
    #[serde(default)]
    pub reference: Option<ReferenceSpectrum>,
    /// The estimator (`native`, `shift`, `digital-shift` or `none`; by default `shift`).
    #[serde(default = "shifted")]
    pub randomization: RandomizationChoice,
    /// Whether costly patterns are kept in the cache directory between runs.
    #[serde(default)]
    pub cache: bool,
}

fn shifted() -> RandomizationChoice {
    RandomizationChoice::Given(Randomization::Shift)
}

impl StudyDescription {
    /// Parses a description from JSON.
    ///
    /// # Errors
    /// Text that is not such a description: malformed JSON, an unknown field, an unknown
    /// sampler or integrand.
    ///
    /// # Examples
    /// ```
    /// use specvar::rate::StudyDescription;
    /// let d = StudyDescription::from_json(
    ///     r#"{"dimension": 2, "samplers": ["jitter"], "integrands": ["disk:r=0.2"],
    ///         "ns": [16, 64], "trials": 400, "seed": 1}"#,
    /// )?;
    /// let config = d.into_config(specvar::budget::Budget::default());
    /// assert_eq!(config.samplers, vec![specvar::SamplerKind::Jitter]);
    /// assert!(StudyDescription::from_json(r#"{"dimension": 2, "sampler": []}"#).is_err());
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn from_json(text: &str) -> Result<Self> {
        serde_json::from_str(text)
            .map_err(|e| invalid("study description", e, "the fields of StudyDescription"))
    }

    /// The study it describes, under `budget`, with the library's defaults for the rest.
    pub fn into_config(self, budget: crate::budget::Budget) -> StudyConfig {
        let defaults = StudyConfig::in_dimension(self.dimension);
        StudyConfig {
            dimension: self.dimension,
            samplers: self.samplers,
            integrands: self.integrands,
            ns: self.ns,
            trials: self.trials,
            seed: self.seed,
            reference: self.reference.unwrap_or(defaults.reference),
            randomization: self.randomization,
            patterns_cache: self.cache.then(crate::cache::default_dir),
            predict: PredictParams {
                budget,
                ..defaults.predict
            },
        }
    }
}

/// The Monte Carlo patterns' seed, independent of the spectra's.
const MC_STREAM: u64 = 0x4D43;
/// The predictions' seed, independent of both.
const PREDICT_STREAM: u64 = 0x5052;

impl StudyConfig {
    /// Checks the configuration before any work.
    ///
    /// # Errors
    /// Fewer than two distinct N, a sampler that does not exist in the dimension or cannot
    /// produce some N, no samplers or integrands, or too few trials.
    pub fn check(&self) -> Result<()> {
        let d = self.dimension;
        let mut distinct = self.ns.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() < 2 || distinct[0] == 0 {
            return Err(invalid(
                "N values",
                format!("{:?}", self.ns),
                "at least two distinct positive N to fit a slope",
            ));
        }
        if self.samplers.is_empty() || self.integrands.is_empty() {
            return Err(invalid(
                "study",
                "no samplers or integrands",
                "at least one of each",
            ));
        }
        for &kind in &self.samplers {
            let sampler = kind.build(d)?;
            for &n in self.ns.iter().chain([&self.reference.n]) {
                sampler.check_count(n)?;
            }
        }
        for spec in &self.integrands {
            spec.build(d)?;
        }
        let largest = self
            .ns
            .iter()
            .copied()
            .max()
            .unwrap_or(0)
            .max(self.reference.n);
        for &kind in &self.samplers {
            let pool = self.mc_params(kind);
            let one = kind.pattern_needs(largest, d);
            let needs = crate::budget::Needs {
                memory_bytes: one.memory_bytes * rayon::current_num_threads().max(1) as f64,
                work_seconds: pool.patterns as f64 * one.work_seconds,
            };
            let what = format!("the study's Monte Carlo of {kind} at N = {largest}");
            self.predict
                .budget
                .check(&what, needs, "lower the largest N or the trials")?;
            if pool.patterns < crate::montecarlo::MIN_UNITS {
                return Err(invalid(
                    "trials",
                    self.trials,
                    format!(
                        "enough for {} independent patterns of {kind} ({} shifts each), which a \
                         99% interval needs",
                        crate::montecarlo::MIN_UNITS,
                        pool.shifts
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl StudyConfig {
    /// A sampler of the study, its costly patterns kept in memory (and on disk, with a cache).
    pub(crate) fn sampler(&self, kind: SamplerKind) -> Result<Box<dyn crate::sampler::Sampler>> {
        crate::cache::cached_sampler(
            kind,
            self.dimension,
            self.patterns_cache.as_deref(),
            PATTERN_MEMORY,
        )
    }
}

/// N values `m^d` between `lo` and `hi`, about five, log-spaced.
pub fn rate_ns(lo: usize, hi: usize, d: usize) -> Vec<usize> {
    let (a, b) = ((lo as f64).ln(), (hi as f64).ln());
    let mut ns: Vec<usize> = (0..5)
        .map(|i| {
            let target = (a + (b - a) * i as f64 / 4.0).exp();
            let m = target.powf(1.0 / d as f64).round().max(1.0) as usize;
            m.pow(d as u32)
        })
        .collect();
    ns.dedup();
    ns
}

/// One sampler's reference spectrum and its low-frequency exponent.
#[derive(Debug, Clone, Serialize)]
pub struct SamplerSpectrum {
    /// The sampler.
    pub sampler: SamplerKind,
    /// The estimate at the reference N (its lattice is left out of serialized output).
    #[serde(serialize_with = "radial_only")]
    pub estimate: SpectrumEstimate,
    /// The fitted `α`.
    pub alpha: AlphaFit,
}

fn radial_only<S: serde::Serializer>(
    e: &SpectrumEstimate,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    e.radial.serialize(s)
}

/// One sampler on one integrand over the N values.
#[derive(Debug, Clone, Serialize)]
pub struct StudySeries {
    /// The sampler.
    pub sampler: SamplerKind,
    /// The integrand's specification.
    pub integrand: IntegrandSpec,
    /// The integrand's label.
    pub label: String,
    /// The N values.
    pub ns: Vec<usize>,
    /// Predicted variance at each N.
    pub predicted: Vec<Prediction>,
    /// Monte Carlo at each N.
    pub measured: Vec<McResult>,
}

/// Where the `α` of a row comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AlphaSource {
    /// Known exactly for the sampler.
    Known,
    /// Fitted on the reference spectrum.
    Fitted,
    /// Fitted, but not a power law: a fixed rule's spectrum is peaks on a lattice (or the
    /// Fejér kernel of a sequence), with no low-frequency law for `α` to describe, so it gives
    /// no theoretical rate.
    NoPowerLaw,
}

/// A row of the rate table.
#[derive(Debug, Clone, Serialize)]
pub struct StudyRow {
    /// Sampler.
    pub sampler: SamplerKind,
    /// Integrand label.
    pub integrand: String,
    /// Dimension.
    pub dimension: usize,
    /// `α` used by the theory.
    pub alpha: f64,
    /// Where it comes from.
    pub alpha_source: AlphaSource,
    /// Theoretical asymptotic rate from `(α, β, d)`; `None` where the sampler has no power law
    /// at low frequencies ([`AlphaSource::NoPowerLaw`]).
    pub theory_rate: Option<f64>,
    /// Whether a `log N` factor applies.
    pub log_factor: bool,
    /// Log-log slope of the predicted variances over the N range, fitted with Monte Carlo's
    /// weights; its error propagated from the predictions' budgets.
    pub predicted_rate: SlopeFit,
    /// Log-log slope of the Monte Carlo variances, weighted by their intervals.
    pub empirical_rate: SlopeFit,
    /// The first N of the study at which the variance reaches the floor of double precision
    /// (the prediction's rounding or quadrature bound is half its value or more, or a variance
    /// is not positive): both fits stop below it. `None` where every N is resolved.
    pub floor_n: Option<usize>,
}

/// A prediction whose rounding or quadrature bound reaches this fraction of its value is at the
/// floor of the arithmetic: what it says of the variance is its bound, not a value.
pub const FLOOR_FRACTION: f64 = 0.5;

/// The first index at which the series reaches the floor of the arithmetic: a prediction whose
/// bound `quadrature` is [`FLOOR_FRACTION`] of its value or more, or a variance that is not
/// positive (the exact sum cancelled to 0, or Monte Carlo measured no spread).
fn floor_index(series: &StudySeries) -> Option<usize> {
    series
        .predicted
        .iter()
        .zip(&series.measured)
        .position(|(p, m)| {
            !(p.variance > 0.0 && m.variance > 0.0)
                || p.budget.quadrature >= FLOOR_FRACTION * p.variance
        })
}

/// A finished study.
#[derive(Debug, Clone, Serialize)]
pub struct Study {
    /// What was asked.
    pub config: StudyConfig,
    /// One per sampler, in the order of the configuration.
    pub spectra: Vec<SamplerSpectrum>,
    /// Sampler-major, then integrand, in the order of the configuration.
    pub series: Vec<StudySeries>,
    /// One per series, in the same order.
    pub rows: Vec<StudyRow>,
}

impl Study {
    /// The series of `sampler` on the integrand at `index` of the configuration.
    pub fn series_of(&self, sampler: SamplerKind, index: usize) -> Option<&StudySeries> {
        let s = self.config.samplers.iter().position(|&k| k == sampler)?;
        self.series.get(s * self.config.integrands.len() + index)
    }
}

/// Runs the study: per sampler, its spectrum at the reference N and its `α`; per N, one Monte
/// Carlo run shared by all integrands and the one-call prediction ([`predict_many`], the route
/// valid at that N) for each; and the slopes.
///
/// # Errors
/// As [`StudyConfig::check`], or any failure of the computations.
///
/// # Examples
/// ```
/// use specvar::integrand::IntegrandSpec;
/// use specvar::progress::Silent;
/// use specvar::rate::{run_study, ReferenceSpectrum, StudyConfig};
/// use specvar::sampler::SamplerKind;
/// let config = StudyConfig {
///     samplers: vec![SamplerKind::Random, SamplerKind::Jitter],
///     integrands: vec![IntegrandSpec::Gaussian { sigma: 0.1, height: 1.0, centre: None }],
///     ns: vec![16, 64, 256],
///     trials: 4000,
///     reference: ReferenceSpectrum { n: 1024, kmax: 96, realizations: 16, costly_realizations: 4 },
///     ..Default::default()
/// };
/// let study = run_study(&config, &Silent)?;
/// let jitter = &study.rows[1];
/// assert!((jitter.theory_rate.unwrap() + 2.0).abs() < 1e-12); // N^-2 on a Gaussian
/// assert!(jitter.empirical_rate.slope < -1.5);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn run_study(config: &StudyConfig, progress: &dyn Progress) -> Result<Study> {
    config.check()?;
    let mut done = Vec::new();
    for &kind in &config.samplers {
        let blocks: Vec<McBlock> = config
            .mc_blocks(usize::MAX)
            .into_iter()
            .filter(|b| b.sampler == kind)
            .collect();
        let total = blocks.iter().map(|b| b.count as u64).sum();
        stage(progress, &format!("monte carlo: {kind}"), total, || {
            for block in blocks {
                let errors = config.run_mc_block(&block, progress)?;
                done.push((block, errors));
            }
            Ok::<_, crate::Error>(())
        })?;
    }
    finish_study(config, &done, progress)
}

/// A block of one sampler's Monte Carlo patterns at one N: the unit a study's Monte Carlo is
/// split into, to run anywhere (on the workers of a cluster, say). A block's errors depend on
/// the configuration and the block alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct McBlock {
    /// The sampler.
    pub sampler: SamplerKind,
    /// Points per pattern.
    pub n: usize,
    /// The first pattern.
    pub start: usize,
    /// Patterns in the block.
    pub count: usize,
}

/// The errors of a block's patterns, `[pattern][integrand]` ([`StudyConfig::run_mc_block`]).
pub type BlockErrors = Vec<Vec<PatternErrors>>;

impl StudyConfig {
    /// The Monte Carlo parameters of `kind`'s runs (the same at every N).
    fn mc_params(&self, kind: SamplerKind) -> McParams {
        McParams {
            budget: self.predict.budget,
            ..McParams::pooled(
                kind,
                self.trials,
                self.seed ^ MC_STREAM,
                self.randomization.resolve(kind.native_randomization()),
            )
        }
    }

    /// The study's Monte Carlo split into blocks of at most `patterns_per_block` patterns
    /// (at least 1): sampler-major, then N, then pattern.
    pub fn mc_blocks(&self, patterns_per_block: usize) -> Vec<McBlock> {
        let size = patterns_per_block.max(1);
        let mut blocks = Vec::new();
        for &sampler in &self.samplers {
            let patterns = self.mc_params(sampler).patterns;
            for &n in &self.ns {
                blocks.extend((0..patterns).step_by(size).map(|start| McBlock {
                    sampler,
                    n,
                    start,
                    count: size.min(patterns - start),
                }));
            }
        }
        blocks
    }

    /// Runs one block of the study's Monte Carlo, every integrand on each pattern, advancing
    /// `progress` by one per pattern.
    ///
    /// # Errors
    /// A block outside the study, or as [`errors_of_patterns`].
    pub fn run_mc_block(&self, block: &McBlock, progress: &dyn Progress) -> Result<BlockErrors> {
        if !self.samplers.contains(&block.sampler) || !self.ns.contains(&block.n) {
            return Err(invalid(
                "block",
                format!("{} at N = {}", block.sampler, block.n),
                "a sampler and an N of the study",
            ));
        }
        let fs = self.build_integrands()?;
        let f_refs: Vec<&dyn Integrand> = fs.iter().map(|f| f.as_ref()).collect();
        let sampler = self.sampler(block.sampler)?;
        let params = self.mc_params(block.sampler);
        let range = block.start..block.start.saturating_add(block.count);
        errors_of_patterns(sampler.as_ref(), &f_refs, block.n, &params, range, progress)
    }

    fn build_integrands(&self) -> Result<Vec<Box<dyn Integrand>>> {
        self.integrands
            .iter()
            .map(|s| s.build(self.dimension))
            .collect()
    }
}

/// Completes a study from its Monte Carlo blocks (in any order, computed anywhere): the
/// reference spectra, the predictions, the Monte Carlo results from the blocks' errors in
/// pattern order, and the rate table. The same blocks give the same bits as [`run_study`],
/// however the work was split.
///
/// # Errors
/// Blocks that do not cover every sampler's patterns at every N exactly once, or as
/// [`run_study`].
pub fn finish_study(
    config: &StudyConfig,
    blocks: &[(McBlock, BlockErrors)],
    progress: &dyn Progress,
) -> Result<Study> {
    config.check()?;
    let fs = config.build_integrands()?;
    let f_refs: Vec<&dyn Integrand> = fs.iter().map(|f| f.as_ref()).collect();
    let d = config.dimension;
    let mut study = Study {
        config: config.clone(),
        spectra: Vec::new(),
        series: Vec::new(),
        rows: Vec::new(),
    };
    for &kind in &config.samplers {
        let spectrum = reference_spectrum(kind, config, progress)?;
        let measured = config
            .ns
            .iter()
            .map(|&n| measured_from_blocks(config, kind, n, f_refs.len(), blocks))
            .collect::<Result<Vec<_>>>()?;
        let sampler = config.sampler(kind)?;
        let params = PredictParams {
            seed: config.seed ^ PREDICT_STREAM,
            ..config.predict
        };
        // `[n][integrand]`: the integrands share each N's patterns.
        let mut by_n = config
            .ns
            .iter()
            .map(|&n| {
                let problems = f_refs
                    .iter()
                    .map(|f| {
                        Problem::new(sampler.as_ref(), *f, n).map(|p| {
                            p.with_randomization(
                                config.randomization.resolve(kind.native_randomization()),
                            )
                        })
                    })
                    .collect::<Result<Vec<_>>>()?;
                predict_many(&problems, &params, progress)
            })
            .collect::<Result<Vec<_>>>()?;
        for (j, f) in f_refs.iter().enumerate() {
            let predicted = by_n.iter_mut().map(|row| row[j].clone()).collect();
            let series = StudySeries {
                sampler: kind,
                integrand: config.integrands[j].clone(),
                label: f.label(),
                ns: config.ns.clone(),
                predicted,
                measured: measured.iter().map(|m| m[j].clone()).collect(),
            };
            study.rows.push(row(&series, &spectrum, *f, d)?);
            study.series.push(series);
        }
        study.spectra.push(spectrum);
    }
    Ok(study)
}

/// The Monte Carlo results of `kind` at `n`, one per integrand, from the blocks that cover its
/// patterns.
fn measured_from_blocks(
    config: &StudyConfig,
    kind: SamplerKind,
    n: usize,
    integrands: usize,
    blocks: &[(McBlock, BlockErrors)],
) -> Result<Vec<McResult>> {
    let params = config.mc_params(kind);
    let mut mine: Vec<&(McBlock, BlockErrors)> = blocks
        .iter()
        .filter(|(b, _)| b.sampler == kind && b.n == n)
        .collect();
    mine.sort_by_key(|(b, _)| b.start);
    let mut rows: Vec<&Vec<PatternErrors>> = Vec::with_capacity(params.patterns);
    for (block, errors) in mine {
        if block.start != rows.len() || errors.len() != block.count {
            return Err(crate::Error::Mismatch(format!(
                "the Monte Carlo blocks of {kind} at N = {n} must cover patterns 0..{} once,                  in blocks whose errors match their counts; found a block at {} with {}                  patterns' errors after {} patterns",
                params.patterns,
                block.start,
                errors.len(),
                rows.len()
            )));
        }
        rows.extend(errors.iter());
    }
    if rows.len() != params.patterns || rows.iter().any(|r| r.len() != integrands) {
        return Err(crate::Error::Mismatch(format!(
            "the Monte Carlo blocks of {kind} at N = {n} hold {} patterns' errors for {}              integrands; the study needs {} patterns",
            rows.len(),
            integrands,
            params.patterns
        )));
    }
    (0..integrands)
        .map(|j| {
            let column: Vec<PatternErrors> = rows.iter().map(|r| r[j]).collect();
            result_from_errors(n, &params, &column)
        })
        .collect()
}

fn reference_spectrum(
    kind: SamplerKind,
    config: &StudyConfig,
    progress: &dyn Progress,
) -> Result<SamplerSpectrum> {
    let r = config.reference;
    let realizations = r.realizations_for(kind);
    let params = SpectrumParams {
        kmax: r.kmax,
        realizations,
        seed: config.seed,
        engine: Engine::Auto,
        bin_width: 1.0,
        budget: config.predict.budget,
    };
    let sampler = config.sampler(kind)?;
    let label = format!(
        "spectrum of {kind} at N = {} ({realizations} realizations)",
        r.n
    );
    let estimate = stage(progress, &label, 0, || {
        estimate(sampler.as_ref(), r.n, &params)
    })?;
    let alpha = fit_alpha(&estimate.radial, 0.0, 0.3)?;
    Ok(SamplerSpectrum {
        sampler: kind,
        estimate,
        alpha,
    })
}

/// Relative standard error of a Monte Carlo variance, from the width of its 99% interval.
pub(crate) fn rel_stderr(r: &McResult) -> f64 {
    (r.ci_high - r.ci_low) / (2.0 * Z_99 * r.variance)
}

fn row(
    series: &StudySeries,
    spectrum: &SamplerSpectrum,
    f: &dyn Integrand,
    d: usize,
) -> Result<StudyRow> {
    let ns: Vec<f64> = series.ns.iter().map(|&n| n as f64).collect();
    let (alpha, alpha_source) = match series.sampler.known_alpha() {
        Some(a) => (a, AlphaSource::Known),
        None if series.sampler.is_deterministic() => {
            (spectrum.alpha.alpha, AlphaSource::NoPowerLaw)
        }
        None => (spectrum.alpha.alpha, AlphaSource::Fitted),
    };
    let (theory, log_factor) = match alpha_source {
        AlphaSource::NoPowerLaw => (None, false),
        _ => {
            let (rate, log) = theory_rate(alpha, f.decay_exponent(), d);
            (Some(rate), log)
        }
    };
    let resolved = floor_index(series).unwrap_or(ns.len());
    if resolved < 2 {
        return Err(invalid(
            "N range",
            format!("{:?} for {} on {}", series.ns, series.sampler, series.label),
            format!(
                "at least two N below the floor of double precision, which the variance reaches \
                 at N = {} (the prediction {:.3e} against its rounding bound {:.1e}); choose \
                 smaller N",
                series.ns[resolved],
                series.predicted[resolved].variance,
                series.predicted[resolved].budget.quadrature
            ),
        ));
    }
    let ns = &ns[..resolved];
    let predicted: Vec<f64> = series.predicted[..resolved]
        .iter()
        .map(|p| p.variance)
        .collect();
    // One standard error of each prediction, its bounds counted as such.
    let predicted_rel: Vec<f64> = series.predicted[..resolved]
        .iter()
        .map(|p| p.budget.half_width(1.0) / p.variance)
        .collect();
    let mc: Vec<f64> = series.measured[..resolved]
        .iter()
        .map(|r| r.variance)
        .collect();
    let rel: Vec<f64> = series.measured[..resolved].iter().map(rel_stderr).collect();
    Ok(StudyRow {
        sampler: series.sampler,
        integrand: series.label.clone(),
        dimension: d,
        alpha,
        alpha_source,
        theory_rate: theory,
        log_factor,
        // Fitted with Monte Carlo's weights, so that the two slopes weigh the N alike.
        predicted_rate: loglog_slope_with_weights(ns, &predicted, &rel, &predicted_rel)?,
        empirical_rate: loglog_slope(ns, &mc, Some(&rel))?,
        floor_n: (resolved < series.ns.len()).then(|| series.ns[resolved]),
    })
}
