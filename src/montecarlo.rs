//! Empirical variance of Monte Carlo integration, with confidence intervals.
//!
//! Each trial integrates `f` with one point set: the estimator error is `e = μ_N - I`, with the
//! integrand's exact integral over the cube as `I`. The run's [`Randomization`] says which
//! estimator it measures: under a random shift (toroidal or digital) the estimator is unbiased,
//! so its variance is `E[e²]`, estimated by the mean of `e²` without subtracting an estimated
//! mean; patterns used as drawn give the sample variance about the mean error, and their bias.
//!
//! **Pools.** For samplers too slow to draw one pattern per trial (CCVT, Poisson disk at large
//! N) the trials come from P patterns, each used with S random shifts. The variance of the
//! shifted estimator is then the mean over patterns of `z_p = (1/S) Σ_s e_{p,s}²`, and the
//! `z_p` are independent: the confidence interval comes from the P patterns (a two-level
//! estimator), never from P·S trials as if they were independent. Cheap samplers are the case
//! S = 1.
//!
//! **Intervals (99%).** The `z` are non-negative and, for indicator or sharp integrands at small
//! N, heavily right-skewed: most trials miss the integrand's structure and a few carry the
//! variance. A percentile bootstrap then covers far less than it claims (90% for a nominal 99%
//! at 100 trials on a Gaussian of σ = 0.02), because it cannot know how often the few large
//! values should have appeared. The interval is therefore the studentized bootstrap
//! (bootstrap-t, 2000 resamples, a fixed seed), which corrects for skewness and widens the upper
//! end when few units carry the mean; with many units that carry it evenly (at least 5000 units
//! and an effective count `(Σz)²/Σz²` of 500), the central limit theorem on a log scale. Where
//! the data cannot support a 99% claim the run is refused with an error that says what to
//! raise: fewer than 20 independent units, an effective count below 10, or (shifted) every
//! unit giving the same squared error, which means no trial resolved the integrand.

use crate::error::{invalid, Result};
use crate::integrand::Integrand;
use crate::pointset::{wrap, PointSet, MAX_DIMENSION};
use crate::progress::{Progress, Silent};
use crate::randomization::{check_shifts, Randomization, UnitTransform};
use crate::rng::{realization_rng, Stream};
use crate::sampler::{Pool, Sampler, SamplerKind};
use rayon::prelude::*;
use serde::Serialize;

/// The two-sided normal quantile for 99% (`z_{0.995}`).
pub const Z_99: f64 = 2.575_829_303_548_901;

/// Units from which the central limit theorem is trusted (with [`CLT_EFFECTIVE_UNITS`]).
const CLT_UNITS: usize = 5000;
/// The effective number of units `(Σz)²/Σz²` the central limit theorem needs.
const CLT_EFFECTIVE_UNITS: f64 = 500.0;
const BOOTSTRAP_RESAMPLES: usize = 2000;
/// The fewest independent units a 99% interval rests on.
pub const MIN_UNITS: usize = 20;
/// The smallest effective number of units `(Σz)²/Σz²` a 99% interval rests on.
pub const MIN_EFFECTIVE_UNITS: f64 = 10.0;

/// Monte Carlo parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct McParams {
    /// Independent patterns (for cheap samplers: the trials).
    pub patterns: usize,
    /// Random shifts per pattern (1 for one fresh pattern per trial).
    pub shifts: usize,
    /// Seed; pattern `p` is realization `p` of it.
    pub seed: u64,
    /// How each pattern is randomized: the estimator measured. Patterns used as drawn
    /// ([`Randomization::None`]) take one trial each (`shifts` must be 1), and the variance is
    /// the sample variance about the mean error.
    pub randomization: Randomization,
    /// What the run may spend (checked before it starts).
    pub budget: crate::budget::Budget,
}

impl McParams {
    /// `trials` estimator evaluations spent as the sampler's cost asks ([`SamplerKind::pool`]):
    /// one fresh pattern per trial for cheap samplers, a pool of patterns under many shifts for
    /// costly ones; patterns used as drawn are one fresh pattern per trial, except for costly
    /// laws invariant under translation (Poisson disk, CCVT, Gaussian blue noise), whose
    /// estimator as drawn is the shifted one: they are measured under shifts (and say so).
    ///
    /// # Examples
    /// ```
    /// use specvar::montecarlo::McParams;
    /// use specvar::randomization::Randomization;
    /// use specvar::sampler::SamplerKind;
    /// let ccvt = McParams::pooled(SamplerKind::Ccvt, 8192, 0, Randomization::Shift);
    /// assert!(ccvt.shifts > 1 && ccvt.patterns * ccvt.shifts >= 8192);
    /// let jitter = McParams::pooled(SamplerKind::Jitter, 8192, 0, Randomization::Shift);
    /// assert_eq!(jitter.shifts, 1);
    /// ```
    pub fn pooled(
        kind: SamplerKind,
        trials: usize,
        seed: u64,
        randomization: Randomization,
    ) -> Self {
        // A law invariant under translation has the same estimator as drawn and shifted: a
        // costly one is measured under shifts, so that its patterns are reused.
        let stationary = kind.facts().randomness.is_stationary();
        let randomization = match randomization {
            Randomization::None if stationary && kind.pool(trials).shifts > 1 => {
                Randomization::Shift
            }
            r => r,
        };
        let pool = if randomization.reuses_patterns() {
            kind.pool(trials)
        } else {
            Pool {
                patterns: trials,
                shifts: 1,
            }
        };
        Self {
            patterns: pool.patterns,
            shifts: pool.shifts,
            seed,
            randomization,
            budget: crate::budget::Budget::default(),
        }
    }

    /// As [`pooled`](Self::pooled), or with `shifts` randomizations of each pattern where given
    /// (then `trials / shifts` patterns).
    pub fn for_sampler(
        kind: SamplerKind,
        trials: usize,
        shifts: Option<usize>,
        seed: u64,
        randomization: Randomization,
    ) -> Self {
        let pooled = Self::pooled(kind, trials, seed, randomization);
        match shifts {
            Some(shifts) => Self {
                shifts,
                patterns: trials / shifts.max(1),
                ..pooled
            },
            None => pooled,
        }
    }

    /// A run over `sets` given point sets, each one pattern under `shifts` randomizations
    /// (by default as many as spend `trials` evaluations, at least 1; exactly 1 for sets used
    /// as given).
    pub fn for_sets(
        sets: usize,
        trials: usize,
        shifts: Option<usize>,
        seed: u64,
        randomization: Randomization,
    ) -> Self {
        let default_shifts = if randomization.reuses_patterns() {
            (trials / sets.max(1)).max(1)
        } else {
            1
        };
        Self {
            patterns: sets,
            shifts: shifts.unwrap_or(default_shifts),
            seed,
            randomization,
            budget: crate::budget::Budget::default(),
        }
    }
}

impl Default for McParams {
    fn default() -> Self {
        Self {
            patterns: 10_000,
            shifts: 1,
            seed: 0,
            randomization: Randomization::Shift,
            budget: crate::budget::Budget::default(),
        }
    }
}

/// How a confidence interval was computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum IntervalMethod {
    /// Central limit theorem on the mean, on a log scale.
    LogNormal,
    /// Studentized (bootstrap-t) bootstrap.
    Bootstrap,
    /// No randomness: every fixed pattern gave the same error, and the variance is 0 exactly.
    Exact,
}

/// The result of a Monte Carlo run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct McResult {
    /// Points per pattern.
    pub n: usize,
    /// Total estimator evaluations (patterns × shifts).
    pub trials: usize,
    /// Independent patterns.
    pub patterns: usize,
    /// Shifts per pattern.
    pub shifts: usize,
    /// The estimated variance of `μ_N`.
    pub variance: f64,
    /// Lower end of the 99% interval.
    pub ci_low: f64,
    /// Upper end of the 99% interval.
    pub ci_high: f64,
    /// The mean error `E[μ_N] - I`.
    pub bias: f64,
    /// Standard error of `bias`.
    pub bias_stderr: f64,
    /// How the patterns were randomized: the estimator measured.
    pub randomization: Randomization,
    /// How the interval was computed.
    pub interval: IntervalMethod,
    /// The effective number of independent units, `(Σz)²/Σz²` over the units' mean squared
    /// errors `z`: how many carry the estimate.
    pub effective_units: f64,
}

/// The estimator `μ_N = (1/N) Σ f(x_k)`.
pub fn estimate_integral(f: &dyn Integrand, points: &PointSet) -> f64 {
    points.points().map(|x| f.eval(x)).sum::<f64>() / points.len() as f64
}

/// The estimator on `points` translated by `shift` modulo 1, without forming the translated set.
pub fn estimate_shifted(f: &dyn Integrand, points: &PointSet, shift: &[f64]) -> f64 {
    let d = points.dimension();
    let mut x = [0.0; MAX_DIMENSION];
    let sum: f64 = points
        .points()
        .map(|p| {
            for a in 0..d {
                x[a] = wrap(p[a] + shift[a]);
            }
            f.eval(&x[..d])
        })
        .sum();
    sum / points.len() as f64
}

/// Runs Monte Carlo integration of `f` with `sampler` at `n` points.
///
/// Parallel over patterns; the result is identical for any thread count (per-pattern values
/// are collected in order and reduced sequentially).
///
/// # Errors
/// A dimension mismatch, zero patterns or shifts, several shifts of patterns used as drawn, or a sampler
/// error.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::montecarlo::{empirical_variance, McParams};
/// use specvar::sampler::Random;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
/// let params = McParams { patterns: 4000, ..Default::default() };
/// let r = empirical_variance(&Random::new(2).unwrap(), &disk, 16, &params).unwrap();
/// let exact = (disk.integral_of_square() - disk.integral().powi(2)) / 16.0;
/// assert!(r.ci_low < exact && exact < r.ci_high);
/// ```
pub fn empirical_variance(
    sampler: &dyn Sampler,
    f: &dyn Integrand,
    n: usize,
    params: &McParams,
) -> Result<McResult> {
    empirical_variance_with(sampler, f, n, params, &Silent)
}

/// Monte Carlo for several integrands on the same patterns and shifts, advancing `progress` by
/// one step per pattern. Results are in the order of `integrands`.
///
/// # Errors
/// As [`empirical_variance`].
pub fn empirical_variances(
    sampler: &dyn Sampler,
    integrands: &[&dyn Integrand],
    n: usize,
    params: &McParams,
    progress: &dyn Progress,
) -> Result<Vec<McResult>> {
    check_sampler_run(sampler, integrands, n, params, params.patterns)?;
    run(integrands, n, params, progress, |p| {
        sampler.sample(n, params.seed, p as u64)
    })
}

/// Monte Carlo on given point sets (e.g. a renderer's patterns read from a file): every set is
/// one pattern, used under `params.shifts` random shifts of `params.seed` (`params.patterns`
/// is ignored: it is the number of sets), with the interval from the sets (two-level).
///
/// # Errors
/// Fewer than two sets, sets of different sizes, a dimension mismatch, or bad parameters.
///
/// # Examples
/// ```
/// use specvar::integrand::{Gaussian, Integrand};
/// use specvar::montecarlo::{empirical_variances_of_sets, McParams};
/// use specvar::sampler::{Jitter, Sampler};
/// let sets: Vec<_> = (0..64).map(|r| Jitter::new(2).unwrap().sample(64, 9, r).unwrap()).collect();
/// let f = Gaussian::new(0.1, vec![0.5, 0.5], 1.0)?;
/// let params = McParams { shifts: 32, ..Default::default() };
/// let r = &empirical_variances_of_sets(&sets, &[&f], &params, &specvar::progress::Silent)?[0];
/// assert_eq!((r.patterns, r.shifts), (64, 32));
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn empirical_variances_of_sets(
    sets: &[PointSet],
    integrands: &[&dyn Integrand],
    params: &McParams,
    progress: &dyn Progress,
) -> Result<Vec<McResult>> {
    let first = sets
        .first()
        .ok_or_else(|| invalid("point sets", 0, "at least two"))?;
    if sets
        .iter()
        .any(|s| s.len() != first.len() || s.dimension() != first.dimension())
    {
        return Err(crate::error::Error::Mismatch(
            "all point sets must have the same dimension and number of points".into(),
        ));
    }
    let params = McParams {
        patterns: sets.len(),
        ..*params
    };
    for f in integrands {
        check(first.dimension(), *f, &params)?;
    }
    check_budget(
        &params,
        crate::budget::Needs::default(),
        first.len(),
        integrands.len(),
    )?;
    run(integrands, first.len(), &params, progress, |p| {
        Ok(sets[p].clone())
    })
}

/// Checks a run of `patterns` patterns of `sampler` before it starts: dimensions, N,
/// parameters and the budget.
fn check_sampler_run(
    sampler: &dyn Sampler,
    integrands: &[&dyn Integrand],
    n: usize,
    params: &McParams,
    patterns: usize,
) -> Result<()> {
    for f in integrands {
        check(sampler.dimension(), *f, params)?;
    }
    sampler.check_count(n)?;
    let pattern = crate::sampler::pattern_needs(sampler, n);
    let run = McParams {
        patterns,
        ..*params
    };
    check_budget(&run, pattern, n, integrands.len())
}

/// Checks a run's memory (a pattern per thread, a few numbers per pattern) and work (drawing
/// the patterns, evaluating every integrand at every point of every shifted pattern).
fn check_budget(
    params: &McParams,
    pattern: crate::budget::Needs,
    n: usize,
    integrands: usize,
) -> Result<()> {
    let threads = rayon::current_num_threads().max(1) as f64;
    let p = params.patterns as f64;
    let needs = crate::budget::Needs {
        memory_bytes: threads * pattern.memory_bytes + p * integrands as f64 * 16.0,
        work_seconds: p * pattern.work_seconds
            + p * params.shifts as f64
                * n as f64
                * integrands as f64
                * crate::costs::SHIFTED_EVALUATION_SECONDS,
    };
    params
        .budget
        .check("the Monte Carlo run", needs, "lower the trials or N")
}

/// One pattern's errors `e = μ_N - I` under its shifts, for one integrand.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PatternErrors {
    /// The mean of `e` over the shifts.
    pub mean: f64,
    /// The mean of `e²` over the shifts.
    pub mean_square: f64,
}

/// The errors of patterns `patterns` (indices into the run `params` describes) of `sampler`
/// at `n` points, each under its `params.shifts` shifts, for every integrand: `[pattern]
/// [integrand]`. A pattern's errors depend on `(params.seed, pattern index)` alone, so a run
/// split into blocks of patterns, computed anywhere and concatenated in order, gives the same
/// [`McResult`] bits through [`result_from_errors`] as one [`empirical_variances`] call.
///
/// # Errors
/// As [`empirical_variances`]; a range beyond `params.patterns`.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::montecarlo::{empirical_variance, errors_of_patterns, result_from_errors, McParams};
/// use specvar::sampler::Jitter;
/// let (jitter, disk) = (Jitter::new(2)?, Ball::new(0.25, vec![0.5, 0.5], 1.0)?);
/// let params = McParams { patterns: 200, ..Default::default() };
/// let silent = &specvar::progress::Silent;
/// let mut errors = errors_of_patterns(&jitter, &[&disk], 64, &params, 0..120, silent)?;
/// errors.extend(errors_of_patterns(&jitter, &[&disk], 64, &params, 120..200, silent)?);
/// let column: Vec<_> = errors.iter().map(|e| e[0]).collect();
/// let blocks = result_from_errors(64, &params, &column)?;
/// assert_eq!(blocks, empirical_variance(&jitter, &disk, 64, &params)?);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn errors_of_patterns(
    sampler: &dyn Sampler,
    integrands: &[&dyn Integrand],
    n: usize,
    params: &McParams,
    patterns: std::ops::Range<usize>,
    progress: &dyn Progress,
) -> Result<Vec<Vec<PatternErrors>>> {
    if patterns.start > patterns.end || patterns.end > params.patterns {
        return Err(invalid(
            "pattern range",
            format!("{}..{}", patterns.start, patterns.end),
            format!("a range within 0..{}", params.patterns),
        ));
    }
    check_sampler_run(sampler, integrands, n, params, patterns.len())?;
    errors_in_range(integrands, params, patterns, progress, |p| {
        sampler.sample(n, params.seed, p as u64)
    })
}

/// Patterns a run with an integrand of one's own (evaluated outside the library, e.g. in
/// Python) draws at a time: it bounds the run's memory whatever its trials.
pub const TRIAL_BLOCK: usize = 64;

/// What a run of `patterns` trials of `sampler` at `n` points costs when its patterns are drawn
/// [`TRIAL_BLOCK`] at a time ([`trial_pattern`]) for an integrand of one's own: the block's
/// patterns (each and its randomized copy) and the drawing; the integrand's own cost is the
/// caller's to judge.
pub fn blocked_run_needs(sampler: &dyn Sampler, n: usize, patterns: usize) -> crate::budget::Needs {
    let one = crate::sampler::pattern_needs(sampler, n);
    let coordinates = n as f64 * sampler.dimension() as f64;
    crate::budget::Needs {
        memory_bytes: TRIAL_BLOCK as f64 * coordinates * 16.0 + one.memory_bytes,
        work_seconds: patterns as f64 * one.work_seconds,
    }
}

/// Trial `trial`'s point set as [`empirical_variances`] integrates it with one shift per
/// pattern: realization `trial` of `params.seed`, under its unit's randomization (none for
/// patterns used as drawn). Integrating a function of one's own on these sets, and passing the
/// estimates to [`result_from_estimates`], runs the same experiment as the built-in
/// integrands.
///
/// # Errors
/// A sampler error.
pub fn trial_pattern(
    sampler: &dyn Sampler,
    n: usize,
    params: &McParams,
    trial: usize,
) -> Result<PointSet> {
    shifted_pattern(
        &sampler.sample(n, params.seed, trial as u64)?,
        params,
        trial,
    )
}

/// `base` under the randomization of unit `unit` (pattern × shifts + shift) of
/// `params.seed`, as the Monte Carlo runs randomize it (unchanged for patterns used as drawn):
/// with one shift per pattern, given sets ([`empirical_variances_of_sets`]) are integrated on
/// `shifted_pattern(&sets[p], params, p)`.
///
/// # Errors
/// None in practice: the translated coordinates are wrapped into the unit cube.
pub fn shifted_pattern(base: &PointSet, params: &McParams, unit: usize) -> Result<PointSet> {
    let mut coords = vec![0.0; base.coords().len()];
    unit_transform(params, base.dimension(), unit).apply_into(base, &mut coords);
    PointSet::new(base.dimension(), coords)
}

/// The randomization in dimension `d` of unit `unit` (pattern × shifts + shift).
fn unit_transform(params: &McParams, d: usize, unit: usize) -> UnitTransform {
    params.randomization.draw(d, params.seed, unit as u64)
}

/// The shared core: patterns `range` from `pattern`, each under `params.shifts` shifts, every
/// integrand on each; parallel over patterns, collected in order.
fn errors_in_range(
    integrands: &[&dyn Integrand],
    params: &McParams,
    range: std::ops::Range<usize>,
    progress: &dyn Progress,
    pattern: impl Fn(usize) -> Result<PointSet> + Sync,
) -> Result<Vec<Vec<PatternErrors>>> {
    let truths: Vec<f64> = integrands.iter().map(|f| f.integral()).collect();
    let s = params.shifts;
    let per_pattern: Vec<Result<Vec<PatternErrors>>> = range
        .into_par_iter()
        .map(|p| {
            let base = pattern(p)?;
            let d = base.dimension();
            let mut sums = vec![PatternErrors::default(); integrands.len()];
            // The shifted pattern is computed once per shift and read by every integrand.
            let mut shifted = Vec::new();
            for shift in 0..s {
                // Patterns used as drawn are read in place rather than copied.
                let points = unit_transform(params, d, p * s + shift).applied(&base, &mut shifted);
                for (j, f) in integrands.iter().enumerate() {
                    let sum = f.sum_at(points);
                    let e = sum / base.len() as f64 - truths[j];
                    sums[j].mean += e / s as f64;
                    sums[j].mean_square += e * e / s as f64;
                }
            }
            progress.advance(1);
            Ok(sums)
        })
        .collect();
    per_pattern.into_iter().collect()
}

/// [`errors_in_range`] over all of `params.patterns`, summarized per integrand.
fn run(
    integrands: &[&dyn Integrand],
    n: usize,
    params: &McParams,
    progress: &dyn Progress,
    pattern: impl Fn(usize) -> Result<PointSet> + Sync,
) -> Result<Vec<McResult>> {
    let values = errors_in_range(integrands, params, 0..params.patterns, progress, pattern)?;
    (0..integrands.len())
        .map(|j| {
            let column: Vec<PatternErrors> = values.iter().map(|v| v[j]).collect();
            result_from_errors(n, params, &column)
        })
        .collect()
}

/// As [`empirical_variance`], advancing `progress` by one step per pattern.
///
/// # Errors
/// As [`empirical_variance`].
pub fn empirical_variance_with(
    sampler: &dyn Sampler,
    f: &dyn Integrand,
    n: usize,
    params: &McParams,
    progress: &dyn Progress,
) -> Result<McResult> {
    let mut results = empirical_variances(sampler, &[f], n, params, progress)?;
    Ok(results.remove(0))
}

/// The result of a run from its patterns' errors, in pattern order ([`errors_of_patterns`]).
///
/// # Errors
/// Fewer patterns than `params.patterns`, or data that cannot support a 99% interval (see the
/// module notes).
pub fn result_from_errors(
    n: usize,
    params: &McParams,
    errors: &[PatternErrors],
) -> Result<McResult> {
    if errors.len() != params.patterns {
        return Err(crate::error::Error::Mismatch(format!(
            "{} patterns' errors for a run of {} patterns",
            errors.len(),
            params.patterns
        )));
    }
    let means: Vec<f64> = errors.iter().map(|e| e.mean).collect();
    let (bias, bias_var) = mean_and_variance(&means);
    let count = means.len() as f64;
    let values: Vec<f64> = if params.randomization.reuses_patterns() {
        errors.iter().map(|e| e.mean_square).collect()
    } else {
        // Fixed patterns: the sample variance about the mean error.
        means
            .iter()
            .map(|e| (e - bias).powi(2) * count / (count - 1.0))
            .collect()
    };
    let variance = mean_and_variance(&values).0;
    let effective_units = effective_units(&values);
    let ((ci_low, ci_high), interval) = interval_of_mean(&values, params)?;
    Ok(McResult {
        n,
        trials: params.patterns * params.shifts,
        patterns: params.patterns,
        shifts: params.shifts,
        variance,
        ci_low,
        ci_high,
        bias,
        bias_stderr: (bias_var / count).sqrt(),
        randomization: params.randomization,
        interval,
        effective_units,
    })
}

/// The result of a run with one shift per pattern from its estimates `μ_N`, one per trial in
/// trial order (e.g. a function of one's own integrated on [`trial_pattern`]'s sets). With the
/// exact integral `truth` the errors are `μ_N - truth`, as for the built-in integrands. Without
/// it they are taken about the estimates' mean: the variance is the sample variance (unbiased
/// for a shifted estimator), and `bias` is 0 by construction.
///
/// # Errors
/// `params.shifts` other than 1, estimates that are not finite, fewer than `params.patterns`
/// estimates, or data that cannot support a 99% interval.
///
/// # Examples
/// ```
/// use specvar::montecarlo::{result_from_estimates, trial_pattern, McParams};
/// use specvar::sampler::Jitter;
/// let params = McParams { patterns: 2000, ..Default::default() };
/// let jitter = Jitter::new(2)?;
/// // f(x, y) = x y, with integral 1/4, integrated on the run's own shifted patterns.
/// let estimates = (0..params.patterns)
///     .map(|t| {
///         let set = trial_pattern(&jitter, 16, &params, t)?;
///         Ok(set.points().map(|p| p[0] * p[1]).sum::<f64>() / 16.0)
///     })
///     .collect::<specvar::Result<Vec<f64>>>()?;
/// let r = result_from_estimates(16, &params, &estimates, Some(0.25))?;
/// assert!(r.ci_low < r.variance && r.variance < r.ci_high);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn result_from_estimates(
    n: usize,
    params: &McParams,
    estimates: &[f64],
    truth: Option<f64>,
) -> Result<McResult> {
    if params.shifts != 1 {
        return Err(invalid(
            "shifts",
            params.shifts,
            "1 for a run from estimates",
        ));
    }
    if let Some(bad) = estimates.iter().position(|e| !e.is_finite()) {
        return Err(invalid(
            "estimate",
            format!("{} (trial {bad})", estimates[bad]),
            "a finite number: the integrand returned NaN or infinity",
        ));
    }
    let errors: Vec<PatternErrors> = match truth {
        Some(i) => estimates
            .iter()
            .map(|m| PatternErrors {
                mean: m - i,
                mean_square: (m - i) * (m - i),
            })
            .collect(),
        None => {
            let centre = mean_and_variance(estimates).0;
            estimates
                .iter()
                .map(|m| PatternErrors {
                    mean: m - centre,
                    mean_square: 0.0,
                })
                .collect()
        }
    };
    match truth {
        Some(_) => result_from_errors(n, params, &errors),
        None => {
            // The sample variance about the mean: the fixed-pattern summary.
            let about_mean = McParams {
                randomization: Randomization::None,
                ..*params
            };
            let r = result_from_errors(n, &about_mean, &errors)?;
            Ok(McResult {
                randomization: params.randomization,
                ..r
            })
        }
    }
}

/// `(Σz)²/Σz²`: how many of the units carry their sum (all, if they are equal; one, if one
/// dominates).
fn effective_units(z: &[f64]) -> f64 {
    let (s, s2) = z.iter().fold((0.0, 0.0), |(s, s2), v| (s + v, s2 + v * v));
    if s2 > 0.0 {
        s * s / s2
    } else {
        z.len() as f64
    }
}

fn check(d: usize, f: &dyn Integrand, params: &McParams) -> Result<()> {
    if d != f.dimension() {
        return Err(invalid(
            "dimension",
            d,
            format!("the integrand's dimension {}", f.dimension()),
        ));
    }
    if params.patterns < 2 {
        return Err(invalid("patterns", params.patterns, "at least 2"));
    }
    check_shifts(params.randomization, params.shifts)
}

/// Mean and unbiased variance, summed in order.
fn mean_and_variance(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, var)
}

/// A 99% interval for the mean of i.i.d. non-negative values, or an error where the values
/// cannot support one (see the module notes).
fn interval_of_mean(x: &[f64], params: &McParams) -> Result<((f64, f64), IntervalMethod)> {
    let n = x.len();
    let (mean, var) = mean_and_variance(x);
    let Some(&first) = x.first() else {
        return Err(invalid("patterns", 0, "at least one"));
    };
    if x.iter().all(|&v| v == first) {
        // Every estimate equal to the integral: the variance is zero (a constant integrand,
        // or one the pattern integrates exactly).
        if first == 0.0 {
            return Ok(((0.0, 0.0), IntervalMethod::Exact));
        }
        return Err(invalid(
            "trials",
            params.patterns * params.shifts,
            "more: every independent unit gave the same squared error, so no trial resolved \
             the integrand and the spread of the variance is unknown",
        ));
    }
    if n < MIN_UNITS {
        return Err(invalid(
            "patterns",
            n,
            format!("at least {MIN_UNITS} independent patterns for a 99% interval"),
        ));
    }
    let effective = effective_units(x);
    if effective < MIN_EFFECTIVE_UNITS {
        let wanted = (params.patterns as f64 * MIN_EFFECTIVE_UNITS / effective).ceil();
        return Err(invalid(
            "trials",
            params.patterns * params.shifts,
            format!(
                "more: the variance rests on {effective:.1} effective units of {n}, too few for a \
                 99% interval; raise the patterns to about {wanted}"
            ),
        ));
    }
    let se = (var / n as f64).sqrt();
    if n >= CLT_UNITS && effective >= CLT_EFFECTIVE_UNITS {
        let half = Z_99 * se / mean;
        return Ok((
            (mean * (-half).exp(), mean * half.exp()),
            IntervalMethod::LogNormal,
        ));
    }
    // Bootstrap-t: the spread of (mean* - mean) / se* over resamples, applied to this se.
    let mut rng = realization_rng(params.seed, n as u64, Stream::Trial);
    let mut t: Vec<f64> = (0..BOOTSTRAP_RESAMPLES)
        .map(|_| {
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..n {
                let v = x[crate::sampler::uniform_index(&mut rng, n)];
                s += v;
                s2 += v * v;
            }
            let m = s / n as f64;
            let se_b = ((s2 / n as f64 - m * m).max(0.0) / (n as f64 - 1.0)).sqrt();
            // A resample without spread says nothing about the spread: it counts as no shift.
            if se_b > 0.0 {
                (m - mean) / se_b
            } else {
                0.0
            }
        })
        .collect();
    t.sort_by(f64::total_cmp);
    let quantile =
        |q: f64| t[((q * BOOTSTRAP_RESAMPLES as f64) as usize).min(BOOTSTRAP_RESAMPLES - 1)];
    let lo = (mean - quantile(0.995) * se).max(0.0);
    let hi = mean - quantile(0.005) * se;
    Ok(((lo, hi), IntervalMethod::Bootstrap))
}
