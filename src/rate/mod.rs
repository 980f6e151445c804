//! Convergence rates: from theory, from spectra, and from Monte Carlo.
//!
//! With `P̆_S(ν) ≈ c ν^α` near 0 and `P̆_f(ρ) ~ ρ^{-β}`, the variance falls like
//! `N^{-1 - min(α, β - d)/d}`, with a `log N` factor when `α = β - d`. A rate here is the
//! exponent `r` in `Var ∝ N^r`.
//!
//! [`fit_alpha`] measures `α` from an estimated spectrum; [`run_study`] is the whole rate
//! study (samplers × integrands × N: theory, predicted and Monte Carlo slopes) that both
//! `specvar rates` and the report run.

mod alpha;
mod study;

pub use alpha::{fit_alpha, fit_low_band, AlphaFit, LowBandFit};
pub use study::{
    finish_study, rate_ns, run_study, AlphaSource, BlockErrors, McBlock, ReferenceSpectrum,
    SamplerSpectrum, Study, StudyConfig, StudyDescription, StudyRow, StudySeries, FLOOR_FRACTION,
};

use crate::error::{invalid, Result};
use crate::montecarlo::Z_99;
use serde::Serialize;

/// The asymptotic rate and whether a `log N` factor multiplies it.
///
/// # Examples
/// ```
/// use specvar::rate::theory_rate;
/// assert_eq!(theory_rate(2.0, 3.0, 2), (-1.5, false));           // jitter, disk
/// assert_eq!(theory_rate(2.0, f64::INFINITY, 2), (-2.0, false)); // jitter, Gaussian
/// assert_eq!(theory_rate(1.0, 3.0, 2), (-1.5, true));            // log case
/// ```
pub fn theory_rate(alpha: f64, beta: f64, d: usize) -> (f64, bool) {
    let excess = beta - d as f64;
    let exponent = alpha.min(excess);
    (-1.0 - exponent / d as f64, (alpha - excess).abs() < 1e-9)
}

/// A weighted least-squares line `y = a + slope · x`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SlopeFit {
    /// The slope.
    pub slope: f64,
    /// Its standard error.
    pub stderr: f64,
    /// 99% interval: `slope ± z_{0.995} · stderr`.
    pub ci: (f64, f64),
    /// The intercept.
    pub intercept: f64,
    /// Points used.
    pub points: usize,
}

/// Fits `y = a + b x` by weighted least squares with known variances of `y` (weights `1/var`).
/// With `variances = None` the points weigh equally and the standard error comes from the
/// residuals.
///
/// # Errors
/// Fewer than two points, mismatched lengths, or all `x` equal.
pub fn weighted_line(x: &[f64], y: &[f64], variances: Option<&[f64]>) -> Result<SlopeFit> {
    if x.len() != y.len() || x.len() < 2 || variances.is_some_and(|v| v.len() != x.len()) {
        return Err(invalid(
            "fit points",
            x.len(),
            "at least two, with matching lengths",
        ));
    }
    let w: Vec<f64> = match variances {
        Some(v) => v.iter().map(|v| 1.0 / v.max(f64::MIN_POSITIVE)).collect(),
        None => vec![1.0; x.len()],
    };
    let sw: f64 = w.iter().sum();
    let xm = x.iter().zip(&w).map(|(x, w)| x * w).sum::<f64>() / sw;
    let ym = y.iter().zip(&w).map(|(y, w)| y * w).sum::<f64>() / sw;
    let sxx: f64 = x.iter().zip(&w).map(|(x, w)| w * (x - xm).powi(2)).sum();
    if sxx <= 0.0 {
        return Err(invalid(
            "fit abscissae",
            "all equal",
            "at least two distinct values",
        ));
    }
    let sxy: f64 = x
        .iter()
        .zip(y)
        .zip(&w)
        .map(|((x, y), w)| w * (x - xm) * (y - ym))
        .sum();
    let slope = sxy / sxx;
    let intercept = ym - slope * xm;
    let stderr = match variances {
        Some(_) => (1.0 / sxx).sqrt(),
        None => {
            let dof = (x.len() as f64 - 2.0).max(1.0);
            let rss: f64 = x
                .iter()
                .zip(y)
                .map(|(x, y)| (y - intercept - slope * x).powi(2))
                .sum();
            (rss / dof / sxx).sqrt()
        }
    };
    Ok(SlopeFit {
        slope,
        stderr,
        ci: (slope - Z_99 * stderr, slope + Z_99 * stderr),
        intercept,
        points: x.len(),
    })
}

/// A theoretical rate as tables print it, with `digits` decimals: "no power law" for none
/// (a fixed rule's spectrum has no low-frequency law to give one).
///
/// # Examples
/// ```
/// use specvar::rate::theory_text;
/// assert_eq!(theory_text(Some(-1.5), 2), "-1.50");
/// assert_eq!(theory_text(None, 2), "no power law");
/// ```
pub fn theory_text(rate: Option<f64>, digits: usize) -> String {
    rate.map_or_else(|| "no power law".to_string(), |r| format!("{r:.digits$}"))
}

/// The log-log slope of `values` against `ns` fitted with the weights `1/rel_weights²` (another
/// series' relative errors), its standard error propagated from `values`' own relative errors
/// `rel_errors`: the slope is `Σ c_i ln v_i`, so its variance is `Σ c_i² rel_i²`. Two series
/// fitted with the same weights have slopes that differ only where their values do, even when
/// the curve they follow is not a power law. Where it is not, the slope over the range is no
/// rate either: the weighted scatter of the values about the line, `s² = Σ w_i r_i² / (n − 2)`
/// over `Σ w_i (x_i − x̄)²`, is added to that variance, so that exact values that bend still
/// carry an interval as wide as their departure from a power law.
///
/// # Errors
/// As [`loglog_slope`].
pub fn loglog_slope_with_weights(
    ns: &[f64],
    values: &[f64],
    rel_weights: &[f64],
    rel_errors: &[f64],
) -> Result<SlopeFit> {
    let mut fit = loglog_slope(ns, values, Some(rel_weights))?;
    let x: Vec<f64> = ns.iter().map(|n| n.ln()).collect();
    let w: Vec<f64> = rel_weights
        .iter()
        .map(|r| 1.0 / (r * r).max(f64::MIN_POSITIVE))
        .collect();
    let sw: f64 = w.iter().sum();
    let xm = x.iter().zip(&w).map(|(x, w)| x * w).sum::<f64>() / sw;
    let sxx: f64 = x.iter().zip(&w).map(|(x, w)| w * (x - xm).powi(2)).sum();
    let variance: f64 = x
        .iter()
        .zip(&w)
        .zip(rel_errors)
        .map(|((x, w), e)| (w * (x - xm) / sxx * e).powi(2))
        .sum();
    let bend = if x.len() > 2 {
        let scatter: f64 = x
            .iter()
            .zip(values)
            .zip(&w)
            .map(|((x, v), w)| w * (v.ln() - fit.intercept - fit.slope * x).powi(2))
            .sum::<f64>()
            / (x.len() - 2) as f64;
        scatter / sxx
    } else {
        0.0
    };
    fit.stderr = (variance + bend).sqrt();
    fit.ci = (fit.slope - Z_99 * fit.stderr, fit.slope + Z_99 * fit.stderr);
    Ok(fit)
}

/// The log-log slope of `values` against `ns`, with relative standard errors `rel_stderr` if
/// known (the variance of `ln v` is `rel_stderr²`).
///
/// # Errors
/// As [`weighted_line`], or a non-positive value.
pub fn loglog_slope(ns: &[f64], values: &[f64], rel_stderr: Option<&[f64]>) -> Result<SlopeFit> {
    if values.iter().chain(ns).any(|v| v.is_nan() || *v <= 0.0) {
        return Err(invalid(
            "log-log data",
            "a non-positive value",
            "positive N and values",
        ));
    }
    let x: Vec<f64> = ns.iter().map(|n| n.ln()).collect();
    let y: Vec<f64> = values.iter().map(|v| v.ln()).collect();
    let var: Option<Vec<f64>> = rel_stderr.map(|r| r.iter().map(|s| s * s).collect());
    weighted_line(&x, &y, var.as_deref())
}

/// Where two curves sampled at the same `ns` cross: the N (log-log interpolated) at which
/// `a - b` changes sign first, or `None`.
pub fn crossover(ns: &[f64], a: &[f64], b: &[f64]) -> Option<f64> {
    let diff: Vec<f64> = a.iter().zip(b).map(|(a, b)| a.ln() - b.ln()).collect();
    (1..ns.len()).find_map(|i| {
        let (d0, d1) = (diff[i - 1], diff[i]);
        (d0.signum() != d1.signum() && d0.is_finite() && d1.is_finite()).then(|| {
            let t = d0 / (d0 - d1);
            (ns[i - 1].ln() + t * (ns[i].ln() - ns[i - 1].ln())).exp()
        })
    })
}
