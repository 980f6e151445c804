//! The standard error of a mean estimated from the spread of its terms, widened where the terms
//! are heavy-tailed.
//!
//! An estimated prediction is the mean of independent terms (one per pattern, or per shift),
//! and its noise is the standard error `s / √R`. The sample deviation `s` is itself estimated:
//! its relative standard error is about `√((κ − 1) / (4R))` for terms of kurtosis `κ`, which
//! is small for normal terms (`κ = 3`) but not for the skewed per-pattern variances of nets and
//! of integrands that jump, whose few large terms a short run may miss, so that `s` comes out
//! low and the interval too narrow. The standard error used is therefore `s / √R` times
//! `1 + z_s √((κ̂ − 1) / (4R))`, an upper bound of the deviation at `z_s` of its own standard
//! errors, with `κ̂` the terms' sample kurtosis.

use crate::quadrature::CompensatedSum;

/// Standard errors of the sample deviation by which the deviation is raised: a one-sided
/// bound that holds about 84% of the time on its own, and makes the noise term cover skewed
/// terms without doubling it for normal ones (`1 + 0.71/√R`).
pub(crate) const SPREAD_UPPER_Z: f64 = 1.0;

/// The mean of `terms` (summed in order, compensated) and its standard error from their spread,
/// widened for their sample kurtosis. The standard error is `NaN` for fewer than 2 terms.
pub(crate) fn mean_and_standard_error(terms: &[f64]) -> (f64, f64) {
    let r = terms.len() as f64;
    let mut sum = CompensatedSum::default();
    terms.iter().for_each(|&t| sum.add(t));
    let mean = sum.value() / r;
    (mean, standard_error_about(terms, mean))
}

/// The widened standard error of the mean `mean` of `terms` (see the module notes).
pub(crate) fn standard_error_about(terms: &[f64], mean: f64) -> f64 {
    let r = terms.len() as f64;
    if terms.len() < 2 {
        return f64::NAN;
    }
    let (mut m2, mut m4) = (0.0, 0.0);
    for &t in terms {
        let d2 = (t - mean) * (t - mean);
        m2 += d2;
        m4 += d2 * d2;
    }
    if m2 == 0.0 {
        return 0.0;
    }
    let kurtosis = m4 * r / (m2 * m2);
    let se = (m2 / (r - 1.0) / r).sqrt();
    se * (1.0 + SPREAD_UPPER_Z * ((kurtosis - 1.0).max(0.0) / (4.0 * r)).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Normal-like terms are widened by about `1 + 0.71/√R`; a heavy tail widens more; equal
    /// terms have no spread.
    #[test]
    fn heavy_tails_widen_the_standard_error() {
        let symmetric: Vec<f64> = (0..100)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let (mean, se) = mean_and_standard_error(&symmetric);
        assert_eq!(mean, 0.0);
        // Two equal masses have kurtosis 1: no widening beyond s/√R.
        let plain = (100.0f64 / 99.0 / 100.0).sqrt();
        assert!((se - plain).abs() < 1e-15, "{se} vs {plain}");
        let mut tail = vec![1.0; 99];
        tail.push(50.0);
        let (m, se_tail) = mean_and_standard_error(&tail);
        let s = (tail.iter().map(|t| (t - m).powi(2)).sum::<f64>() / 99.0 / 100.0).sqrt();
        assert!(se_tail > 1.4 * s, "{se_tail} vs {s}");
        assert_eq!(mean_and_standard_error(&[2.0; 5]).1, 0.0);
        assert!(mean_and_standard_error(&[2.0]).1.is_nan());
    }
}
