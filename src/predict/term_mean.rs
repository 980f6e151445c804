//! The mean of independent unbiased terms (a pattern's, a shift's, a pair's), drawn until
//! their spread says its standard error is a target share of the value: how every estimated
//! route of the prediction averages, with its noise from the terms themselves.

use super::strata::cell_moments::CellSum;
use crate::error::Result;
use crate::progress::{stage, Progress};
use rayon::prelude::*;
use std::sync::Mutex;

/// An estimate of the unshifted variance from the occupancy of patterns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OccupancyEstimate {
    /// The variance.
    pub variance: f64,
    /// Its standard error.
    pub standard_error: f64,
    /// Patterns drawn.
    pub patterns: usize,
    /// A bound on the rounding of the terms' mean (0 where the terms carry none).
    pub rounding: f64,
}

/// The fewest terms an estimate rests on when the work budget cannot afford its usual first
/// batch (a costly pattern at a large N): as many as a Monte Carlo interval rests on.
pub(crate) const MIN_TERMS: usize = crate::montecarlo::MIN_UNITS;

/// How many terms an estimate starts with and may reach: the ones `params.realizations` fixes,
/// else `initial` first and as many as `params.work_budget_seconds` affords at `per_term`
/// seconds each, within `[initial, most]`; where the budget affords fewer than `initial`,
/// as many as it affords, but never fewer than [`MIN_TERMS`].
pub(crate) fn terms_within_budget(
    params: &super::PredictParams,
    per_term: f64,
    (initial, most): (usize, usize),
) -> (usize, usize) {
    let affordable = (params.work_budget_seconds / per_term.max(f64::MIN_POSITIVE)) as usize;
    let initial = initial.min(affordable.max(MIN_TERMS));
    let max = params
        .realizations
        .unwrap_or_else(|| affordable.clamp(initial, most));
    (params.realizations.unwrap_or(initial).min(max), max)
}

/// The mean of `term(0), term(1), …` and its standard error: `counts.0` terms first, then as
/// many as the spread so far says the relative standard error `target_noise` of `offset` plus
/// the mean needs, up to `counts.1`. Terms are computed in parallel and kept in index order, so
/// the result depends only on the final count.
pub(crate) fn mean_to_target_noise(
    label: &str,
    (initial, max): (usize, usize),
    target_noise: f64,
    offset: f64,
    term: impl Fn(usize) -> Result<f64> + Sync,
    progress: &dyn Progress,
) -> Result<OccupancyEstimate> {
    let mut terms: Vec<f64> = Vec::new();
    let mut want = initial.min(max);
    loop {
        let start = terms.len();
        let more = stage(progress, label, (want - start) as u64, || {
            (start..want)
                .into_par_iter()
                .map(|i| {
                    let t = term(i);
                    progress.advance(1);
                    t
                })
                .collect::<Result<Vec<f64>>>()
        })?;
        terms.extend(more);
        let estimate = summarize(&terms);
        let relative = estimate.standard_error / (offset + estimate.variance);
        // A zero variance (relative NaN) needs no more terms.
        let quiet = relative.is_nan() || relative <= target_noise;
        if quiet || terms.len() >= max {
            return Ok(estimate);
        }
        // The standard error falls like 1/√R: ask for what the spread so far says is needed,
        // a tenth more, at least half again as many.
        let needed = terms.len() as f64 * (relative / target_noise).powi(2) * 1.1;
        want = (needed.ceil() as usize)
            .max(terms.len() + terms.len() / 2)
            .min(max);
    }
}

/// The mean of `terms` and its standard error (from their spread, widened for heavy tails).
fn summarize(terms: &[f64]) -> OccupancyEstimate {
    let (variance, standard_error) = crate::spread::mean_and_standard_error(terms);
    OccupancyEstimate {
        variance,
        standard_error,
        patterns: terms.len(),
        rounding: 0.0,
    }
}

/// [`mean_to_target_noise`] (`offset` as there) of exact terms that carry their own rounding
/// bound (a pattern's variance by Owen's gains, a shift's by a closed form): the estimate, its
/// rounding the largest rounding bound of a term, which bounds the mean's.
///
/// # Errors
/// The first term's error.
pub(crate) fn mean_of_exact_terms(
    label: &str,
    counts: (usize, usize),
    target_noise: f64,
    offset: f64,
    term: impl Fn(usize) -> Result<CellSum> + Sync,
    progress: &dyn Progress,
) -> Result<OccupancyEstimate> {
    let rounding = Mutex::new(0.0f64);
    let mut estimate = mean_to_target_noise(
        label,
        counts,
        target_noise,
        offset,
        |i| {
            let s = term(i)?;
            let mut largest = rounding.lock().unwrap_or_else(|e| e.into_inner());
            *largest = largest.max(s.rounding);
            Ok(s.variance)
        },
        progress,
    )?;
    estimate.rounding = rounding.into_inner().unwrap_or_else(|e| e.into_inner());
    Ok(estimate)
}
