//! How many samples: for each sampler, the smallest count whose estimator reaches a target
//! error, found from the predictions themselves.
//!
//! A prediction's variance falls with N along a rate and a constant, `Var(N) ≈ c N^r` locally.
//! The search predicts at a first count, extrapolates along the local rate (measured between
//! the last two predictions) to the count where `c N^r` meets the target, predicts there, and
//! closes the bracket around the crossing by interpolation in `log N`, `log Var`: a handful of
//! predictions instead of one per candidate. Only the sampler's balanced counts are candidates
//! ([`SamplerFacts::balanced_counts`](crate::sampler::SamplerFacts): powers of two for nets,
//! strata for jitter, squares of primes for orthogonal arrays, any N for random points), and
//! the answer is the smallest balanced count whose predicted variance is at most the target's
//! square, to within [`COUNT_RESOLUTION`] of the count below it that misses.
//!
//! Each prediction is for the estimator the sampler is used with (its native randomization,
//! unless another is asked for) and carries its route and error budget; the plan reports them,
//! with the RMSE's interval at the budget's 99% width. A variance that is not monotone in N
//! (strata of different shapes on an edge) makes "smallest" mean the smallest among the counts
//! predicted near the crossing.
//!
//! [`plan_pixels`] plans an image: the samples per pixel whose image RMSE, the root of the mean
//! of the pixels' variances, reaches the target. [`plan_many`] and [`plan_pixels_many`] plan
//! several samplers, a sampler out of reach being a row that says so, and one whose estimator
//! has no valid route a [`Refusal`].

use crate::error::{invalid, Error, Result};
use crate::integrand::Integrand;
use crate::montecarlo::Z_99;
use crate::pixels::{pixel_params, predict_pixels, PixelStack};
use crate::predict::{predict_with, Form, PredictParams, Prediction, Problem};
use crate::progress::Progress;
use crate::randomization::{Randomization, RandomizationChoice};
use crate::sampler::{CountRule, Sampler, SamplerKind};
use serde::Serialize;
use std::fmt;

/// The first count the search predicts at (or the balanced count just above it).
const FIRST_N: usize = 64;
/// Predictions one sampler's search may make. On a variance smooth in N, extrapolation and
/// a straddled interpolation settle in six to ten; where it is not (strata of different
/// shapes on a rough integrand), more predictions only trade one count near the crossing for
/// another, and the search returns the smallest count found to reach the target.
const MAX_PREDICTIONS: usize = 12;
/// How far the first extrapolation, along [`ASSUMED_RATE`], may go before a second
/// prediction measures the rate: a factor of four in N.
const FIRST_STEP: f64 = 4.0;
/// The relative gap between the answer and the largest count known to miss the target at
/// which the search stops on a dense ladder (any N): N to 1%, and so the RMSE to about 1% or
/// better at every rate up to `N^{-2}` in variance, within the predictions' own noise.
pub const COUNT_RESOLUTION: f64 = 0.01;
/// The local rate assumed before two predictions measure one: that of independent points,
/// which every unbiased estimator here matches or beats.
const ASSUMED_RATE: f64 = -1.0;
/// The steepest and the flattest local rates an extrapolation uses. A measured rate outside
/// (a prediction at the floor of the arithmetic, two noisy values close together) would jump
/// too far or not at all.
const RATE_RANGE: (f64, f64) = (-4.0, -0.25);
/// How far from the planned N a prediction may lie to enter the reported rate: a factor of
/// four either way (farther ones may sit at the floor of the arithmetic, or before the
/// asymptotic regime).
const RATE_SPAN: f64 = 4.0;
/// The largest factor one extrapolation may move N by.
const MAX_STEP: f64 = 1024.0;
/// The work one prediction may spend on an estimated spectrum or occupancy, in seconds of one
/// core: a plan makes several, and answers in seconds.
pub const PREDICTION_WORK_SECONDS: f64 = 2.0;

/// The largest N a plan considers by default: `2^20` in 1D and 2D, `2^18` in 3D.
pub fn default_max_n(d: usize) -> usize {
    if d >= 3 {
        1 << 18
    } else {
        1 << 20
    }
}

/// The samplers a plan compares by default: a renderer's staples, each with a route for its
/// native estimator: random, jitter, correlated multi-jitter and Owen-scrambled Sobol' in 2D;
/// random, jitter and Sobol' in other dimensions.
pub fn default_samplers(d: usize) -> Vec<SamplerKind> {
    let mut kinds = vec![SamplerKind::Random, SamplerKind::Jitter];
    if d == 2 {
        kinds.push(SamplerKind::Cmj);
    }
    kinds.push(SamplerKind::Sobol);
    kinds
}

/// The error a plan aims at.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// A root-mean-square error.
    Rmse(f64),
    /// A root-mean-square error relative to the magnitude of the integral.
    RelativeRmse(f64),
}

impl Target {
    /// An RMSE of `rmse`, relative to the integral's magnitude where `relative`.
    pub fn new(rmse: f64, relative: bool) -> Self {
        if relative {
            Target::RelativeRmse(rmse)
        } else {
            Target::Rmse(rmse)
        }
    }

    /// The RMSE it asks of an integrand whose integral is `integral`.
    ///
    /// # Errors
    /// A target that is not a positive finite number, or a relative target for an integral of
    /// zero.
    pub fn rmse(self, integral: f64) -> Result<f64> {
        let (value, scale) = match self {
            Target::Rmse(r) => (r, 1.0),
            Target::RelativeRmse(r) => (r, integral.abs()),
        };
        if !(value > 0.0 && value.is_finite()) {
            return Err(invalid("target RMSE", value, "a positive finite number"));
        }
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(invalid(
                "relative target",
                value,
                "an absolute RMSE: the integral is 0, so a relative error has no scale",
            ));
        }
        let rmse = value * scale;
        if rmse * rmse > 0.0 && (rmse * rmse).is_finite() {
            Ok(rmse)
        } else {
            Err(invalid(
                "target RMSE",
                rmse,
                "an RMSE whose square is a positive finite double",
            ))
        }
    }
}

impl fmt::Display for Target {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Target::Rmse(r) => write!(f, "RMSE {r:e}"),
            Target::RelativeRmse(r) => write!(f, "relative RMSE {r:e}"),
        }
    }
}

/// Parameters of [`plan`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanParams {
    /// The error to reach.
    pub target: Target,
    /// The estimator: each sampler's native randomization by default.
    pub randomization: RandomizationChoice,
    /// The largest N to consider (`None`: [`default_max_n`]).
    pub max_n: Option<usize>,
    /// The predictions' parameters (by default the library's, with
    /// [`PREDICTION_WORK_SECONDS`] of work for each estimated one).
    pub predict: PredictParams,
}

impl PlanParams {
    /// A plan for `target` with the library's defaults.
    pub fn new(target: Target) -> Self {
        Self {
            target,
            randomization: RandomizationChoice::Native,
            max_n: None,
            predict: PredictParams {
                work_budget_seconds: PREDICTION_WORK_SECONDS,
                ..PredictParams::default()
            },
        }
    }
}

/// A predicted count at a neighbouring candidate: the count and its predicted RMSE.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CountRmse {
    /// N.
    pub n: usize,
    /// The predicted RMSE there.
    pub rmse: f64,
}

/// One sampler's plan: the smallest balanced N whose predicted RMSE reaches the target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plan {
    /// The sampler's name.
    pub sampler: String,
    /// The planned N.
    pub n: usize,
    /// The predicted RMSE at N (the square root of the predicted variance).
    pub rmse: f64,
    /// The RMSE's interval from the prediction's error budget at 99%.
    pub rmse_interval: (f64, f64),
    /// The interval's half-width.
    pub budget: f64,
    /// The target RMSE (absolute).
    pub target: f64,
    /// The form of the prediction at N.
    pub form: Form,
    /// Its route, in words.
    pub route: String,
    /// Why that route.
    pub reason: String,
    /// The estimator planned for.
    pub randomization: Randomization,
    /// The counts the sampler's estimator is at its best at, among which N was chosen.
    pub counts: CountRule,
    /// The largest candidate below N that was predicted, which misses the target: the next
    /// balanced count down, or one within [`COUNT_RESOLUTION`] of N on a dense ladder.
    pub below: Option<CountRmse>,
    /// The rate `r` of `Var ∝ N^r` near N, fitted to the search's predictions within a factor
    /// of four of N (least squares in `log N`, `log Var`), where they span a factor of two.
    pub rate: Option<f64>,
    /// Predictions made.
    pub predictions: usize,
    /// Whether N reaches the target. Only the rows of [`plan_many`] and [`plan_pixels_many`]
    /// can be `false`: no count up to the limit reaches the target, and N is the largest count
    /// predicted, with its RMSE.
    pub reached: bool,
    /// What kept the search from reaching the target, in words (`None` when it did).
    pub limit: Option<String>,
}

/// Plans the number of samples for `sampler` on `integrand`: the smallest balanced count whose
/// estimator (the sampler's native one unless `params` says otherwise) has a predicted RMSE at
/// most the target.
///
/// # Errors
/// A target that is not a positive finite number ([`Target::rmse`]); a sampler that is not one
/// of specvar's own (its balanced counts are unknown); an estimator without a prediction route;
/// a target no count up to the largest N (or the largest the budget lets a prediction reach)
/// attains, as [`Error::Unreachable`] with that N and its RMSE; a prediction's own errors.
///
/// # Examples
/// ```
/// use specvar::integrand::Ball;
/// use specvar::plan::{plan, PlanParams, Target};
/// use specvar::progress::Silent;
/// use specvar::sampler::Jitter;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let jitter = Jitter::new(2)?;
/// let p = plan(&jitter, &disk, &PlanParams::new(Target::Rmse(1e-3)), &Silent)?;
/// assert!(p.rmse <= 1e-3);
/// // The count just below misses the target.
/// assert!(p.below.is_some_and(|b| b.n < p.n && b.rmse > 1e-3));
/// println!("jitter: N = {} (RMSE {:.3e}, by the {})", p.n, p.rmse, p.route);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn plan(
    sampler: &dyn Sampler,
    integrand: &dyn Integrand,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plan> {
    reached(plan_row(sampler, integrand, params, progress)?)
}

/// [`plan`]'s row, reached or not.
fn plan_row(
    sampler: &dyn Sampler,
    integrand: &dyn Integrand,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plan> {
    let (kind, randomization) = resolve(sampler, params)?;
    plan_by(
        (kind, sampler.dimension()),
        integrand.integral(),
        params,
        |n| {
            let problem = Problem::new(sampler, integrand, n)?.with_randomization(randomization);
            predict_with(&problem, &params.predict, progress)
        },
    )
}

/// Plans the number of samples per pixel for `sampler` on an image: the smallest balanced count
/// whose predicted image RMSE, the root of the mean of the pixels' variances
/// ([`crate::pixels::predict_pixels`]), reaches the target; a relative target is relative to
/// the image's mean value. Each pixel's prediction has the parameters of
/// [`crate::pixels::pixel_params`].
///
/// # Errors
/// As [`plan`], and a pixel without a prediction route.
pub fn plan_pixels(
    sampler: &dyn Sampler,
    stack: &PixelStack,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plan> {
    reached(plan_pixels_row(sampler, stack, params, progress)?)
}

/// [`plan_pixels`]'s row, reached or not.
fn plan_pixels_row(
    sampler: &dyn Sampler,
    stack: &PixelStack,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plan> {
    let (kind, randomization) = resolve(sampler, params)?;
    let count = stack.pixels().len() as f64;
    let mean = stack.pixels().iter().map(|f| f.integral()).sum::<f64>() / count;
    let pixel = pixel_params(&params.predict);
    plan_by((kind, sampler.dimension()), mean, params, |n| {
        let image = predict_pixels(
            stack,
            sampler,
            n,
            RandomizationChoice::Given(randomization),
            &pixel,
            progress,
        )?;
        Ok(image.as_prediction())
    })
}

/// The kind of `sampler` (its balanced counts are known) and the estimator `params` ask for.
pub(crate) fn resolve(
    sampler: &dyn Sampler,
    params: &PlanParams,
) -> Result<(SamplerKind, Randomization)> {
    let kind = sampler.kind().ok_or_else(|| {
        invalid(
            "sampler",
            sampler.name(),
            "one of specvar's samplers, whose balanced counts are known",
        )
    })?;
    let randomization = params.randomization.resolve(kind.native_randomization());
    crate::predict::check_unbiased(kind, randomization)?;
    Ok((kind, randomization))
}

/// The search of [`plan`] for a sampler of `kind` in dimension `d` on the predictions of
/// `predict_at`, for an integral of `integral`.
pub(crate) fn plan_by(
    (kind, d): (SamplerKind, usize),
    integral: f64,
    params: &PlanParams,
    mut predict_at: impl FnMut(usize) -> Result<Prediction>,
) -> Result<Plan> {
    let target = params.target.rmse(integral)?;
    let max_n = params.max_n.unwrap_or_else(|| default_max_n(d));
    let counts = kind.facts().balanced_counts;
    let ladder = Ladder { counts, d, max_n };
    let probe = |n: usize| predict_at(n).map(|p| (p.variance, p));
    match search(&ladder, target * target, probe)? {
        Outcome::Reached {
            hit,
            below,
            rate,
            probes,
        } => Ok(describe(
            kind.name(),
            target,
            counts,
            (hit, below),
            rate,
            probes,
        )),
        Outcome::Short {
            largest,
            limit,
            probes,
        } => {
            let limit = match limit {
                Limit::MaxN => {
                    format!("N ≤ {max_n} (raise the largest N: --max-n, max_n in Python)")
                }
                Limit::Budget => "the budget (raise --budget-memory or --budget-seconds)".into(),
                Limit::Tabulation => "the tabulated grid's resolution (tabulate the function \
                                      more finely: at N its coarser averages must resolve the \
                                      points' spacing, 8 √N cells per axis)"
                    .into(),
                Limit::Predictions => format!("{MAX_PREDICTIONS} predictions"),
            };
            Ok(Plan {
                reached: false,
                limit: Some(limit),
                ..describe(kind.name(), target, counts, (largest, None), None, probes)
            })
        }
    }
}

/// `plan` if it reaches its target, else the error that says how far it got.
pub(crate) fn reached(plan: Plan) -> Result<Plan> {
    if plan.reached {
        Ok(plan)
    } else {
        Err(unreachable(&plan))
    }
}

/// The error of a plan that does not reach its target.
fn unreachable(plan: &Plan) -> Error {
    Error::Unreachable {
        sampler: plan.sampler.clone(),
        target: plan.target,
        limit: plan.limit.clone().unwrap_or_default(),
        largest_n: plan.n,
        rmse: plan.rmse,
    }
}

/// A sampler that a plan of several has no prediction for: the estimator asked for has no
/// route (Halton used as drawn) or is one a plan refuses (Gaussian jitter as drawn, biased).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Refusal {
    /// The sampler's name.
    pub sampler: String,
    /// The refusal, in the words of its error: what is not valid and what to do instead.
    pub reason: String,
}

/// The rows of a plan of several samplers: those planned (reached or not), in order, and those
/// refused.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Plans {
    /// The samplers planned, in the order given.
    pub rows: Vec<Plan>,
    /// The samplers refused, in the order given.
    pub refused: Vec<Refusal>,
}

/// The rows of `samplers` planned by `row`: a sampler whose estimator has no valid route is a
/// refusal beside the others. An error when no sampler is planned (the first refusal's) or
/// none reaches the target (the first row's), or any other error of a row.
fn plan_rows(
    samplers: &[&dyn Sampler],
    row: impl Fn(&dyn Sampler) -> Result<Plan>,
) -> Result<Plans> {
    let (mut rows, mut refused, mut first_refusal) = (Vec::new(), Vec::new(), None);
    for sampler in samplers {
        match row(*sampler) {
            Ok(plan) => rows.push(plan),
            Err(e @ Error::OutsideValidity { .. }) => {
                refused.push(Refusal {
                    sampler: sampler.name().to_string(),
                    reason: e.to_string(),
                });
                first_refusal.get_or_insert(e);
            }
            Err(e) => return Err(e),
        }
    }
    if let (true, Some(e)) = (rows.is_empty(), first_refusal) {
        return Err(e);
    }
    if !rows.is_empty() && !rows.iter().any(|p| p.reached) {
        return Err(unreachable(&rows[0]));
    }
    Ok(Plans { rows, refused })
}

/// Plans several samplers on one integrand ([`plan`] for each, in order). A sampler that does
/// not reach the target within the limit is a row with `reached: false` (its largest N and
/// the RMSE there), and one whose estimator has no valid route is a [`Refusal`], so that the
/// others still answer.
///
/// # Errors
/// As [`plan`], except that a target out of reach is an error only when no sampler reaches it,
/// and a refusal only when every sampler is refused.
///
/// # Examples
/// ```
/// use specvar::integrand::Ball;
/// use specvar::plan::{plan_many, PlanParams, Target};
/// use specvar::progress::Silent;
/// use specvar::sampler::{GaussianJitter, Jitter, Sampler};
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let (gjitter, jitter) = (GaussianJitter::new(2)?, Jitter::new(2)?);
/// let samplers: [&dyn Sampler; 2] = [&gjitter, &jitter];
/// let plans = plan_many(&samplers, &disk, &PlanParams::new(Target::Rmse(1e-3)), &Silent)?;
/// // Gaussian jitter used as drawn is biased: a refusal with its reason; jitter is planned.
/// assert_eq!(plans.refused[0].sampler, "gjitter");
/// assert!(plans.rows[0].sampler == "jitter" && plans.rows[0].rmse <= 1e-3);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn plan_many(
    samplers: &[&dyn Sampler],
    integrand: &dyn Integrand,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plans> {
    plan_rows(samplers, |s| plan_row(s, integrand, params, progress))
}

/// Plans several samplers on an image ([`plan_pixels`] for each), rows as [`plan_many`]'s.
///
/// # Errors
/// As [`plan_many`].
pub fn plan_pixels_many(
    samplers: &[&dyn Sampler],
    stack: &PixelStack,
    params: &PlanParams,
    progress: &dyn Progress,
) -> Result<Plans> {
    plan_rows(samplers, |s| plan_pixels_row(s, stack, params, progress))
}

/// The plan whose prediction at N is `hit`'s (reached unless the caller says otherwise).
fn describe(
    sampler: &str,
    target: f64,
    counts: CountRule,
    (hit, below): (Probe<Prediction>, Option<Probe<Prediction>>),
    rate: Option<f64>,
    probes: usize,
) -> Plan {
    let p = hit.payload;
    let rmse = p.variance.max(0.0).sqrt();
    let half = p.budget.half_width(Z_99);
    let low = (p.variance - half).max(0.0).sqrt();
    let high = (p.variance + half).sqrt();
    Plan {
        sampler: sampler.to_string(),
        n: hit.n,
        rmse,
        rmse_interval: (low, high),
        budget: (high - low) / 2.0,
        target,
        form: p.route.form,
        route: p.route.to_string(),
        reason: p.reason,
        randomization: p.randomization,
        counts,
        below: below.map(|b| CountRmse {
            n: b.n,
            rmse: b.variance.max(0.0).sqrt(),
        }),
        rate,
        predictions: probes,
        reached: true,
        limit: None,
    }
}

/// The candidates: the balanced counts up to `max_n`.
#[derive(Debug, Clone, Copy)]
struct Ladder {
    counts: CountRule,
    d: usize,
    max_n: usize,
}

impl Ladder {
    /// The least candidate `≥ n`, if one is at most `max_n`.
    fn at_least(&self, n: usize) -> Option<usize> {
        self.counts.at_least(n, self.d).filter(|&c| c <= self.max_n)
    }

    /// The greatest candidate `≤ n`.
    fn at_most(&self, n: usize) -> Option<usize> {
        self.counts
            .below(n.min(self.max_n).saturating_add(1), self.d)
    }

    /// The candidate strictly between `lo` and `hi` nearest `x` on `side` (or the nearest
    /// one on the other side where there is none), if any lies between them.
    fn inside(&self, x: f64, lo: usize, hi: usize, side: Side) -> Option<usize> {
        let first = self.at_least(lo + 1).filter(|&c| c < hi)?;
        let last = self.counts.below(hi, self.d).filter(|&c| c > lo)?;
        let x = x.clamp(first as f64, last as f64);
        let up = self.at_least(x.ceil() as usize).filter(|&c| c <= last);
        let down = self.at_most(x.floor() as usize).filter(|&c| c >= first);
        match side {
            Side::Above => up.or(down),
            Side::Below => down.or(up),
        }
    }
}

/// Which side of a value a candidate is wanted on.
#[derive(Debug, Clone, Copy)]
enum Side {
    Above,
    Below,
}

/// One prediction made by the search: N, its variance, and what else the caller keeps.
#[derive(Debug, Clone)]
struct Probe<T> {
    n: usize,
    variance: f64,
    payload: T,
}

/// What limited a search that fell short of the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Limit {
    /// The largest N considered.
    MaxN,
    /// The memory or work budget of a prediction.
    Budget,
    /// The resolution of a tabulated integrand, too coarse for larger N.
    Tabulation,
    /// The number of predictions a search may make.
    Predictions,
}

/// How a search ended.
#[derive(Debug)]
enum Outcome<T> {
    /// The smallest candidate found to reach the target, and the largest one predicted below
    /// it (which misses it).
    Reached {
        hit: Probe<T>,
        below: Option<Probe<T>>,
        rate: Option<f64>,
        probes: usize,
    },
    /// No candidate up to the limit reaches the target; the largest one predicted.
    Short {
        largest: Probe<T>,
        limit: Limit,
        probes: usize,
    },
}

/// Whether `e` refuses this N for a reason a smaller N may not have: the budget, or a
/// tabulation too coarse for it.
fn is_ceiling_error(e: &Error) -> bool {
    matches!(
        e,
        Error::TooLarge { .. } | Error::OutOfMemory { .. } | Error::TabulationTooCoarse { .. }
    )
}

/// The rate `r` of `Var ∝ N^r` near `n`: fitted to the positive predictions within a factor
/// of [`RATE_SPAN`] of it (least squares in `log N`, `log Var`), where they span at least a
/// factor of two.
fn fitted_rate<T>(made: &[Probe<T>], n: usize) -> Option<f64> {
    let near: Vec<&Probe<T>> = made
        .iter()
        .filter(|p| p.variance > 0.0)
        .filter(|p| (p.n as f64 / n as f64).ln().abs() <= RATE_SPAN.ln())
        .collect();
    let lo = near.iter().map(|p| p.n).min()?;
    let hi = near.iter().map(|p| p.n).max()?;
    if hi < 2 * lo {
        return None;
    }
    let x: Vec<f64> = near.iter().map(|p| (p.n as f64).ln()).collect();
    let y: Vec<f64> = near.iter().map(|p| p.variance.ln()).collect();
    crate::rate::weighted_line(&x, &y, None)
        .ok()
        .map(|fit| fit.slope)
        .filter(|r| r.is_finite())
}

/// The local rate `log(v₁/v₀)/log(n₁/n₀)` of two predictions, where it is a number.
fn local_rate<T>(a: &Probe<T>, b: &Probe<T>) -> Option<f64> {
    let r = (b.variance / a.variance).ln() / (b.n as f64 / a.n as f64).ln();
    (r.is_finite() && a.n != b.n).then_some(r)
}

/// Finds the smallest candidate whose variance (from `predict`) is at most `target`.
fn search<T>(
    ladder: &Ladder,
    target: f64,
    mut predict: impl FnMut(usize) -> Result<(f64, T)>,
) -> Result<Outcome<T>> {
    let first = ladder
        .at_least(FIRST_N.min(ladder.max_n))
        .or_else(|| ladder.at_most(ladder.max_n))
        .ok_or_else(|| {
            invalid(
                "largest N",
                ladder.max_n,
                format!("at least the smallest balanced count ({})", ladder.counts),
            )
        })?;
    let mut made: Vec<Probe<T>> = Vec::new();
    let mut refused: Option<(usize, Error)> = None; // the smallest N refused (budget, tabulation)
    let mut pending = vec![first];
    while let Some(next) = pending.pop() {
        if made.len() >= MAX_PREDICTIONS {
            break;
        }
        match predict(next) {
            Ok((variance, payload)) => made.push(Probe {
                n: next,
                variance,
                payload,
            }),
            Err(e) if is_ceiling_error(&e) => {
                if refused.as_ref().is_none_or(|(n, _)| next < *n) {
                    refused = Some((next, e));
                }
            }
            Err(e) => return Err(e),
        }
        if !pending.is_empty() {
            continue;
        }
        let measured = made
            .len()
            .checked_sub(2)
            .and_then(|i| local_rate(&made[i], &made[i + 1]));
        let (rate, max_step) = match measured {
            Some(r) => (r.clamp(RATE_RANGE.0, RATE_RANGE.1), MAX_STEP),
            None => (ASSUMED_RATE, FIRST_STEP),
        };
        let ceiling = refused.as_ref().map_or(usize::MAX, |(n, _)| *n);
        let step = match bracket(&made, target) {
            (Some(m), Some(h)) => between(ladder, m, h, target),
            (Some(m), None) => upward(ladder, m, target, (rate, max_step), ceiling),
            (None, Some(h)) => downward(ladder, h, target, rate),
            // Only refusals so far: halve log N below the smallest refused.
            (None, None) => match ladder.counts.below(ceiling, ladder.d) {
                Some(smaller) if refused.is_some() => Step::Predict(
                    ladder
                        .at_most(geometric_mean(1, smaller))
                        .unwrap_or(smaller),
                ),
                _ => Step::Done,
            },
        };
        match step {
            Step::Predict(n) => pending.push(n),
            Step::Straddle(below, above) => pending.extend([above, below]),
            Step::Done => break,
        }
    }
    let limit = if let Some((_, e)) = &refused {
        match e {
            Error::TabulationTooCoarse { .. } => Limit::Tabulation,
            _ => Limit::Budget,
        }
    } else if made.len() >= MAX_PREDICTIONS {
        Limit::Predictions
    } else {
        Limit::MaxN
    };
    conclude(made, target, refused, limit)
}

/// The bracket of the crossing: the largest N predicted above the target below the smallest
/// one predicted at or below it, and that one. A variance that is not monotone in N (strata
/// of different shapes, noise) leaves misses above the smallest hit, which bound nothing.
fn bracket<T>(made: &[Probe<T>], target: f64) -> (Option<&Probe<T>>, Option<&Probe<T>>) {
    let hit = made
        .iter()
        .filter(|p| p.variance <= target)
        .min_by_key(|p| p.n);
    let bound = hit.map_or(usize::MAX, |h| h.n);
    let miss = made
        .iter()
        .filter(|p| p.variance > target && p.n < bound)
        .max_by_key(|p| p.n);
    (miss, hit)
}

/// The outcome of a search that stopped with these predictions.
fn conclude<T>(
    mut made: Vec<Probe<T>>,
    target: f64,
    refused: Option<(usize, Error)>,
    limit: Limit,
) -> Result<Outcome<T>> {
    let probes = made.len();
    let (miss, hit) = bracket(&made, target);
    let rate = hit.and_then(|h| fitted_rate(&made, h.n));
    let (miss, hit) = (miss.map(|p| p.n), hit.map(|p| p.n));
    let mut take = |n: Option<usize>| {
        n.and_then(|n| made.iter().position(|p| p.n == n))
            .map(|i| made.swap_remove(i))
    };
    let (below, hit) = (take(miss), take(hit));
    match (below, hit) {
        (below, Some(hit)) => Ok(Outcome::Reached {
            hit,
            below,
            rate,
            probes,
        }),
        (Some(largest), None) => Ok(Outcome::Short {
            largest,
            limit,
            probes,
        }),
        (None, None) => Err(refused.map_or_else(
            || invalid("plan", "no prediction", "a count the budget allows"),
            |(_, e)| e,
        )),
    }
}

/// The search's next move.
enum Step {
    /// Predict at this N.
    Predict(usize),
    /// Predict at both: just below and just above an interpolated crossing, so that a smooth
    /// variance closes the bracket in one round.
    Straddle(usize, usize),
    /// Stop: the bracket is closed, or no candidate is left in the direction needed.
    Done,
}

/// `√(a b)`, rounded.
fn geometric_mean(a: usize, b: usize) -> usize {
    ((a as f64) * (b as f64)).sqrt().round() as usize
}

/// Both sides known: stop when no candidate lies between them (or the gap is within the
/// resolution), else interpolate the crossing in `log N`, `log Var` and straddle it (the
/// interpolation kept inside the bracket's inner 90%, so that a curved or noisy variance still
/// narrows it; bisection where it cannot be trusted, as with a variance of 0).
fn between<T>(ladder: &Ladder, miss: &Probe<T>, hit: &Probe<T>, target: f64) -> Step {
    let (lo, hi) = (miss.n, hit.n);
    if hi < lo || (hi as f64) <= (lo as f64) * (1.0 + COUNT_RESOLUTION) {
        return Step::Done;
    }
    let (x0, x1) = ((lo as f64).ln(), (hi as f64).ln());
    let (y0, y1) = (miss.variance.ln(), hit.variance.ln());
    let fraction = (target.ln() - y0) / (y1 - y0);
    let x = if fraction.is_finite() {
        (x0 + fraction.clamp(0.05, 0.95) * (x1 - x0)).exp()
    } else {
        ((x0 + x1) / 2.0).exp()
    };
    let above = ladder.inside(x, lo, hi, Side::Above);
    let below = ladder.inside(x / (1.0 + COUNT_RESOLUTION), lo, hi, Side::Below);
    match (below, above) {
        (Some(b), Some(a)) if b < a => Step::Straddle(b, a),
        (_, Some(a)) => Step::Predict(a),
        (Some(b), None) => Step::Predict(b),
        (None, None) => Step::Done,
    }
}

/// Every prediction so far misses: extrapolate up along the local rate, below the smallest N
/// the budget refused (`ceiling`), bisecting toward it when the extrapolation passes it.
fn upward<T>(
    ladder: &Ladder,
    miss: &Probe<T>,
    target: f64,
    (rate, max_step): (f64, f64),
    ceiling: usize,
) -> Step {
    let refused = ceiling < usize::MAX;
    if refused && (ceiling as f64) <= miss.n as f64 * (1.0 + COUNT_RESOLUTION) {
        return Step::Done;
    }
    let cap = ladder.max_n.min(ceiling.saturating_sub(1));
    let factor = (target / miss.variance)
        .powf(1.0 / rate)
        .clamp(2.0, max_step);
    let wanted = (miss.n as f64 * factor).min(cap as f64) as usize;
    let wanted = if refused && wanted >= geometric_mean(miss.n, ceiling) {
        geometric_mean(miss.n, ceiling)
    } else {
        wanted
    };
    let next = ladder
        .at_least(wanted)
        .filter(|&n| n <= cap)
        .or_else(|| ladder.at_most(cap));
    match next {
        Some(n) if n > miss.n => Step::Predict(n),
        _ => Step::Done,
    }
}

/// Every prediction so far reaches the target: extrapolate down along the local rate.
fn downward<T>(ladder: &Ladder, hit: &Probe<T>, target: f64, rate: f64) -> Step {
    let factor = (target / hit.variance)
        .powf(1.0 / rate)
        .clamp(1.0 / MAX_STEP, 0.5);
    let wanted = ((hit.n as f64 * factor) as usize).max(1);
    match ladder.at_most(wanted).or_else(|| ladder.at_least(1)) {
        Some(n) if n < hit.n => Step::Predict(n),
        _ => Step::Done,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Searches `c N^r` (a power law, exact) on `counts`; returns the answer and the
    /// predictions made.
    fn run(counts: CountRule, c: f64, r: f64, target: f64, max_n: usize) -> (Outcome<()>, usize) {
        let ladder = Ladder {
            counts,
            d: 2,
            max_n,
        };
        let mut made = 0;
        let out = search(&ladder, target, |n| {
            made += 1;
            Ok((c * (n as f64).powf(r), ()))
        })
        .unwrap();
        (out, made)
    }

    /// The smallest admitted N with `c N^r ≤ target`: from the closed-form crossing, a step
    /// back and a walk up the ladder (whose steps `tests/suite/sampler_facts.rs` checks).
    fn walked(counts: CountRule, c: f64, r: f64, target: f64) -> usize {
        let crossing = (target / c).powf(1.0 / r) * (1.0 - 1e-9);
        let mut n = counts.below(crossing as usize, 2).unwrap_or(1);
        while !(counts.admits(n, 2) && c * (n as f64).powf(r) <= target) {
            n = counts.at_least(n + 1, 2).unwrap();
        }
        n
    }

    /// The search's answer for `c N^r` on `counts` is the smallest count that reaches the
    /// target, or one within the resolution of a count that misses, in a few predictions.
    fn check_ladder(counts: CountRule, max_predictions: usize) {
        for (c, r) in [(0.3, -1.0), (0.05, -1.5), (2.0, -2.0), (1e-3, -0.6)] {
            for target in [1e-3, 3e-5, 1e-7] {
                let expected = walked(counts, c, r, target);
                let (out, made) = run(counts, c, r, target, 1 << 40);
                let case = format!("{counts:?}: c = {c}, r = {r}, target {target}");
                let Outcome::Reached { hit, below, .. } = out else {
                    panic!("{case}: short")
                };
                assert!(c * (hit.n as f64).powf(r) <= target, "{case}");
                assert!(hit.n >= expected, "{case}: {} < {expected}", hit.n);
                if hit.n > expected {
                    let b = below.expect("a count below that misses").n;
                    let adjacent = counts.below(hit.n, 2) == Some(b);
                    let gap = hit.n as f64 / b as f64 - 1.0;
                    assert!(adjacent || gap <= COUNT_RESOLUTION, "{case}: gap {gap}");
                }
                assert!(made <= max_predictions, "{case}: {made} predictions");
            }
        }
    }

    #[test]
    fn power_laws_land_on_the_smallest_count_that_reaches() {
        for counts in [
            CountRule::PowerOfTwo,
            CountRule::Strata,
            CountRule::PrimeSquare,
            CountRule::Fibonacci,
            CountRule::Any,
        ] {
            check_ladder(counts, 12);
        }
    }

    #[test]
    fn a_target_beyond_the_largest_n_is_short_with_its_variance() {
        let (out, _) = run(CountRule::PowerOfTwo, 1.0, -1.0, 1e-9, 1 << 20);
        let Outcome::Short { largest, limit, .. } = out else {
            panic!("reached")
        };
        assert_eq!((largest.n, limit), (1 << 20, Limit::MaxN));
        assert_eq!(largest.variance, 1.0 / (1 << 20) as f64);
    }

    #[test]
    fn a_budget_that_refuses_large_n_bounds_the_search() {
        let ladder = Ladder {
            counts: CountRule::Any,
            d: 2,
            max_n: 1 << 30,
        };
        let out = search(&ladder, 1e-9, |n| {
            if n > 5000 {
                Err(Error::TooLarge {
                    what: "test".into(),
                    needed: "much".into(),
                    budget: "little".into(),
                    advice: "none".into(),
                })
            } else {
                Ok((1.0 / n as f64, ()))
            }
        })
        .unwrap();
        let Outcome::Short { largest, limit, .. } = out else {
            panic!("reached")
        };
        assert_eq!(limit, Limit::Budget);
        assert!(largest.n <= 5000 && largest.n as f64 >= 5000.0 * (1.0 - 0.1));
    }

    #[test]
    fn targets_must_be_positive_and_finite() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-200] {
            assert!(Target::Rmse(bad).rmse(1.0).is_err(), "{bad}");
        }
        assert!(Target::RelativeRmse(0.01).rmse(0.0).is_err());
        assert_eq!(Target::RelativeRmse(0.01).rmse(-2.0).unwrap(), 0.02);
    }
}
