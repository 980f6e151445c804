//! Predictions beside Monte Carlo: the cross-check every study runs, above both the
//! predictions and the Monte Carlo it compares.

use crate::error::Result;
use crate::integrand::Integrand;
use crate::montecarlo::{empirical_variances, McParams, McResult};
use crate::predict::{predict_many, PredictParams, Prediction, Problem};
use crate::progress::Progress;
use crate::sampler::Sampler;

/// Every integrand's default prediction beside Monte Carlo, for one sampler at `n` and the
/// estimator `mc` randomizes: one Monte Carlo run shared by the integrands (shown as the stage `stage` of `progress`) and one
/// prediction of them all ([`predict_many`]), in the integrands' order.
///
/// # Errors
/// As [`empirical_variances`] and [`predict_many`].
pub(crate) fn beside_monte_carlo(
    sampler: &dyn Sampler,
    integrands: &[&dyn Integrand],
    n: usize,
    mc: &McParams,
    params: &PredictParams,
    (stage, progress): (&str, &dyn Progress),
) -> Result<Vec<(McResult, Prediction)>> {
    progress.begin(stage, mc.patterns as u64);
    let measured = empirical_variances(sampler, integrands, n, mc, progress);
    progress.end();
    let measured = measured?;
    let problems = integrands
        .iter()
        .map(|f| Problem::new(sampler, *f, n).map(|p| p.with_randomization(mc.randomization)))
        .collect::<Result<Vec<_>>>()?;
    let predictions = predict_many(&problems, params, progress)?;
    Ok(measured.into_iter().zip(predictions).collect())
}
