//! Variance and bias predicted from spectra.
//!
//! [`predict`] is the one call: given a [`Problem`] (a sampler or your own point sets, an
//! integrand, N) it chooses a valid route, estimates what spectrum it needs, and returns a
//! [`Prediction`] that says which route it took, why, and what its error budget is. The routes
//! themselves are public too:
//!
//! - [`predict_polar`] (module `polar`): one radial integral, for isotropic integrands, with
//!   the DC term;
//! - [`predict_lattice`] and [`predict_from_power`] (module `lattice`): the sum over integer
//!   frequencies, exact on the torus;
//! - [`bias_of_pattern`] and [`regular_grid_bias`] (module `bias`): the bias of a fixed
//!   pattern.

mod bias;
mod lattice;
mod polar;

pub use bias::{bias_of_pattern, regular_grid_bias};
pub use lattice::{predict_from_power, predict_lattice, LatticePower};
pub use polar::{predict_polar, PolarParams};

use crate::error::{finite, invalid, Error, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::progress::{stage, Progress, Silent};
use crate::sampler::Sampler;
use crate::spectrum::{
    estimate, estimate_from_sets, ClosedForm, Engine, SpectrumEstimate, SpectrumParams,
};
use serde::Serialize;
use std::fmt;

/// Where a sampler's expected spectrum comes from, for either form.
#[derive(Debug, Clone, Copy)]
pub enum SpectrumSource<'a> {
    /// A closed form, exact at every N (the lattice form reads it at integer frequencies, the
    /// polar form its radial mean).
    Closed(ClosedForm),
    /// An estimate at some N: the polar form reads its radial spectrum at `ν = ρ/N^{1/d}` (any
    /// N, for a scale-invariant sampler); the lattice form needs it at the target N.
    Estimated(&'a SpectrumEstimate),
}

impl SpectrumSource<'_> {
    /// What the source is, as an owned typed value.
    pub fn origin(&self) -> SpectrumOrigin {
        match self {
            SpectrumSource::Closed(c) => SpectrumOrigin::Closed(*c),
            SpectrumSource::Estimated(e) => SpectrumOrigin::Estimated {
                n: e.lattice.n,
                realizations: e.lattice.realizations,
                kmax: e.lattice.lattice.kmax,
            },
        }
    }

    /// `P̆_S(ν)` in dimension `d`: the radial (angular-mean) spectrum.
    pub fn radial_power(&self, d: usize, nu: f64) -> f64 {
        match self {
            SpectrumSource::Closed(c) => c.radial(d, nu),
            SpectrumSource::Estimated(e) => e.radial.power_at(nu),
        }
    }

    /// `P̆_S(0⁺)`.
    pub fn dc_limit(&self) -> f64 {
        match self {
            SpectrumSource::Closed(c) => c.dc_limit(),
            SpectrumSource::Estimated(e) => e.radial.dc_limit,
        }
    }

    /// The `ν` beyond which the radial spectrum is taken as white (`P̆_S = 1`), if it ever is.
    fn white_beyond_radially(&self) -> Option<f64> {
        match self {
            SpectrumSource::Closed(ClosedForm::WhiteNoise) => Some(0.0),
            SpectrumSource::Closed(ClosedForm::Jitter) => None,
            SpectrumSource::Estimated(e) => Some(e.radial.max_nu()),
        }
    }
}

/// Where the spectrum of a prediction came from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SpectrumOrigin {
    /// A closed form.
    Closed(ClosedForm),
    /// Estimated from `realizations` patterns of `n` points on the lattice `|k_i| ≤ kmax`.
    Estimated {
        /// The N of the patterns.
        n: usize,
        /// Patterns averaged.
        realizations: usize,
        /// The lattice extent.
        kmax: usize,
    },
}

impl fmt::Display for SpectrumOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SpectrumOrigin::Closed(c) => write!(f, "closed form ({})", c.name()),
            SpectrumOrigin::Estimated {
                n,
                realizations,
                kmax,
            } => write!(
                f,
                "estimated at N = {n} ({realizations} realizations, |k_i| ≤ {kmax})"
            ),
        }
    }
}

/// The two forms of the variance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Form {
    /// The radial integral (isotropic integrands).
    Polar,
    /// The sum over the integer lattice (exact on the torus).
    Lattice,
}

impl fmt::Display for Form {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Form::Polar => "polar form",
            Form::Lattice => "lattice form",
        })
    }
}

/// A route of prediction: a form and a spectrum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Route {
    /// The form.
    pub form: Form,
    /// The spectrum.
    pub spectrum: SpectrumOrigin,
}

impl fmt::Display for Route {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}, spectrum {}", self.form, self.spectrum)
    }
}

/// The uncertainty of a predicted variance, by source, each in units of the variance.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ErrorBudget {
    /// One standard error from the noise of an estimated spectrum (0 for closed forms).
    pub spectrum_noise: f64,
    /// The quadrature's error estimate (polar form).
    pub quadrature: f64,
    /// A bound on what the truncation of the sum or integral leaves out.
    pub truncation: f64,
    /// A systematic term from the route's model (e.g. the gap to another valid route).
    pub model: f64,
}

impl ErrorBudget {
    /// The half-width of an interval around the prediction at `z` standard errors of the noise:
    /// `z · noise + quadrature + truncation + model` (the bounds add linearly).
    pub fn half_width(&self, z: f64) -> f64 {
        z * self.spectrum_noise + self.quadrature + self.truncation + self.model
    }
}

/// Another route's value for the same problem, reported beside the chosen one.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Alternative {
    /// The route.
    pub route: Route,
    /// Its variance.
    pub variance: f64,
    /// Its budget.
    pub budget: ErrorBudget,
}

/// A predicted variance of the homogenized estimator.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prediction {
    /// `Var[μ_N]`.
    pub variance: f64,
    /// The route that produced it.
    pub route: Route,
    /// Why this route (empty for a route called directly).
    pub reason: String,
    /// Its uncertainty.
    pub budget: ErrorBudget,
    /// Points per pattern.
    pub n: usize,
    /// Dimension.
    pub dimension: usize,
    /// The DC term `P̆_S(0⁺) I² / N` already subtracted (0 for the lattice form).
    pub dc_term: f64,
    /// Integrand or spectrum evaluations spent.
    pub evaluations: u64,
    /// Other valid routes computed for comparison.
    pub alternatives: Vec<Alternative>,
}

pub(crate) fn check_n(n: usize) -> Result<()> {
    if n == 0 {
        return Err(invalid("N", 0, "at least 1"));
    }
    Ok(())
}

/// The dimensions in which spectra, and so predictions, are computed.
pub const PREDICTION_DIMENSIONS: std::ops::RangeInclusive<usize> = 1..=3;

pub(crate) fn check_dimension(d: usize) -> Result<()> {
    if PREDICTION_DIMENSIONS.contains(&d) {
        Ok(())
    } else {
        Err(invalid(
            "dimension",
            d,
            "1 to 3 for spectra and predictions",
        ))
    }
}

/// The patterns of a problem: a sampler, or point sets of one's own.
#[derive(Clone, Copy)]
pub enum Patterns<'a> {
    /// Realizations of a sampler.
    Sampler(&'a dyn Sampler),
    /// Given point sets (e.g. read from a file), all of one N and dimension: the sampler is
    /// whatever produced them.
    PointSets(&'a [PointSet]),
}

/// What to predict: the variance of `integrand`'s estimator with `n` points from `patterns`.
#[derive(Clone, Copy)]
pub struct Problem<'a> {
    /// The patterns.
    pub patterns: Patterns<'a>,
    /// The integrand.
    pub integrand: &'a dyn Integrand,
    /// Points per pattern.
    pub n: usize,
}

impl<'a> Problem<'a> {
    /// A sampler's problem.
    ///
    /// # Errors
    /// Mismatched dimensions, or an N the sampler cannot produce.
    pub fn new(sampler: &'a dyn Sampler, integrand: &'a dyn Integrand, n: usize) -> Result<Self> {
        check_dimensions(sampler.dimension(), integrand)?;
        sampler.check_count(n)?;
        Ok(Self {
            patterns: Patterns::Sampler(sampler),
            integrand,
            n,
        })
    }

    /// The problem of given point sets (all of one N and dimension).
    ///
    /// # Errors
    /// No sets, sets of different sizes, or a dimension other than the integrand's.
    pub fn from_point_sets(sets: &'a [PointSet], integrand: &'a dyn Integrand) -> Result<Self> {
        let first = sets
            .first()
            .ok_or_else(|| invalid("point sets", 0, "at least one"))?;
        if sets
            .iter()
            .any(|s| s.len() != first.len() || s.dimension() != first.dimension())
        {
            return Err(Error::Mismatch(
                "all point sets must have the same dimension and number of points".into(),
            ));
        }
        check_dimensions(first.dimension(), integrand)?;
        Ok(Self {
            patterns: Patterns::PointSets(sets),
            integrand,
            n: first.len(),
        })
    }

    /// The dimension.
    pub fn dimension(&self) -> usize {
        self.integrand.dimension()
    }
}

fn check_dimensions(d: usize, f: &dyn Integrand) -> Result<()> {
    check_dimension(f.dimension())?;
    if d != f.dimension() {
        return Err(Error::Mismatch(format!(
            "patterns of dimension {d} for an integrand of dimension {}",
            f.dimension()
        )));
    }
    Ok(())
}

/// Which spectrum [`predict`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SpectrumChoice {
    /// A closed form (random and jitter).
    Closed,
    /// Estimated from realizations.
    #[default]
    Estimated,
}

/// Parameters of [`predict`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictParams {
    /// Closed form or estimate.
    pub spectrum: SpectrumChoice,
    /// The N at which the spectrum is estimated (`None`: [`default_reference_n`], or N itself
    /// where the route needs the spectrum at N).
    pub reference_n: Option<usize>,
    /// Realizations of the estimate.
    pub realizations: usize,
    /// Seed of the realizations.
    pub seed: u64,
    /// The polar form's quadrature.
    pub polar: PolarParams,
}

impl Default for PredictParams {
    fn default() -> Self {
        Self {
            spectrum: SpectrumChoice::default(),
            reference_n: None,
            realizations: 32,
            seed: 0,
            polar: PolarParams::default(),
        }
    }
}

/// The default reference N for estimated spectra: 4096 in 1D and 2D, 32768 in 3D.
pub fn default_reference_n(d: usize) -> usize {
    if d == 3 {
        32768
    } else {
        4096
    }
}

/// The default lattice extent for an estimate at `n_ref`: `ν` up to 5.
pub fn default_kmax(n_ref: usize, d: usize) -> usize {
    (5.0 * (n_ref as f64).powf(1.0 / d as f64)).round() as usize
}

/// Predicts the variance of the homogenized estimator, choosing the route (see
/// [`predict_with`], which also reports progress).
///
/// # Errors
/// As [`predict_with`].
///
/// # Examples
/// ```
/// use specvar::integrand::Ball;
/// use specvar::predict::{predict, PredictParams, Problem, SpectrumChoice};
/// use specvar::sampler::Jitter;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let jitter = Jitter::new(2)?;
/// let problem = Problem::new(&jitter, &disk, 256)?;
/// let params = PredictParams { spectrum: SpectrumChoice::Closed, ..Default::default() };
/// let p = predict(&problem, &params)?;
/// println!("{:.4e} by the {} ({})", p.variance, p.route, p.reason);
/// assert!(p.variance > 0.0 && p.budget.spectrum_noise == 0.0);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn predict(problem: &Problem<'_>, params: &PredictParams) -> Result<Prediction> {
    predict_with(problem, params, &Silent)
}

/// Predicts the variance of the homogenized estimator, reporting the spectrum estimate's
/// progress to `progress`.
///
/// The route: an isotropic integrand gets the polar form (with the spectrum rescaled from a
/// reference N for scale-invariant samplers) and, when the spectrum is at N itself or closed,
/// the lattice form as an alternative. An anisotropic integrand (a grid) gets the lattice form
/// with the spectrum at N.
///
/// # Errors
/// A closed form asked for a sampler without one; a rescaled spectrum for a sampler that is
/// not scale invariant at N; bad parameters; a sampler error.
pub fn predict_with(
    problem: &Problem<'_>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    route_and_predict(problem, params, progress).and_then(finite_prediction)
}

fn route_and_predict(
    problem: &Problem<'_>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let f = problem.integrand;
    let (n, d) = (problem.n, problem.dimension());
    let kind = match problem.patterns {
        Patterns::Sampler(s) => s.kind(),
        Patterns::PointSets(_) => None,
    };
    let isotropic = f.is_isotropic();
    match (params.spectrum, problem.patterns) {
        (SpectrumChoice::Closed, _) => {
            let closed = kind.and_then(|k| k.closed_form(n, d)).ok_or_else(|| {
                invalid(
                    "spectrum",
                    "closed",
                    "a sampler with a closed form (random; jitter with strata at N); use the \
                     estimated spectrum",
                )
            })?;
            let source = SpectrumSource::Closed(closed);
            let kmax = ((8.0 * (n as f64).powf(1.0 / d as f64)).ceil() as usize).max(64);
            let lattice = predict_lattice(f, &source, n, kmax)?;
            if !isotropic {
                return Ok(with_reason(
                    lattice,
                    "the integrand is anisotropic: lattice form",
                ));
            }
            let mut polar = predict_polar(f, &source, n, &params.polar)?;
            polar.alternatives.push(alternative(&lattice));
            Ok(with_reason(
                polar,
                "closed form; isotropic integrand: polar form",
            ))
        }
        (SpectrumChoice::Estimated, Patterns::PointSets(sets)) => {
            let spectrum = SpectrumParams {
                kmax: default_kmax(n, d),
                realizations: sets.len(),
                seed: params.seed,
                engine: Engine::Auto,
                bin_width: 1.0,
            };
            let est = stage(progress, "spectrum of the point sets", 0, || {
                estimate_from_sets(sets, &spectrum)
            })?;
            from_estimate(f, &est, n, true, params, "the given point sets")
        }
        (SpectrumChoice::Estimated, Patterns::Sampler(sampler)) => {
            let default_ref = if isotropic { default_reference_n(d) } else { n };
            let n_ref = params.reference_n.unwrap_or(default_ref);
            if !isotropic && n_ref != n {
                return Err(invalid(
                    "reference N",
                    n_ref,
                    format!("N = {n} for an anisotropic integrand (the lattice form needs the spectrum at N)"),
                ));
            }
            let invariant = kind.is_some_and(|k| k.is_scale_invariant_at(n, d));
            if n_ref != n && !invariant {
                return Err(invalid(
                    "sampler",
                    sampler.name(),
                    format!(
                        "a scale-invariant sampler for a spectrum rescaled from N = {n_ref} \
                         (random, poisson, bridson, ccvt; jitter at N = m^d), or reference N = {n}"
                    ),
                ));
            }
            sampler.check_count(n_ref)?;
            let spectrum = SpectrumParams {
                kmax: default_kmax(n_ref, d),
                realizations: params.realizations,
                seed: params.seed,
                engine: Engine::Auto,
                bin_width: 1.0,
            };
            let label = format!("spectrum of {} at N = {n_ref}", sampler.name());
            let est = stage(progress, &label, 0, || estimate(sampler, n_ref, &spectrum))?;
            let why = format!("{} at N = {n_ref}", sampler.name());
            from_estimate(f, &est, n, n_ref == n, params, &why)
        }
    }
}

/// The prediction from an estimate: the polar form for an isotropic integrand, the lattice form
/// (which needs the estimate at N) otherwise or beside it.
fn from_estimate(
    f: &dyn Integrand,
    est: &SpectrumEstimate,
    n: usize,
    at_n: bool,
    params: &PredictParams,
    what: &str,
) -> Result<Prediction> {
    let source = SpectrumSource::Estimated(est);
    let lattice = at_n
        .then(|| predict_lattice(f, &source, n, est.lattice.lattice.kmax))
        .transpose()?;
    match lattice {
        Some(l) if !f.is_isotropic() => Ok(with_reason(
            l,
            &format!("anisotropic integrand: lattice form with the spectrum of {what}"),
        )),
        lattice => {
            let mut polar = predict_polar(f, &source, n, &params.polar)?;
            polar.alternatives.extend(lattice.as_ref().map(alternative));
            Ok(with_reason(
                polar,
                &format!("isotropic integrand: polar form with the radial spectrum of {what}"),
            ))
        }
    }
}

fn with_reason(mut p: Prediction, reason: &str) -> Prediction {
    p.reason = reason.to_string();
    p
}

/// `p` if its variance and budget are finite numbers; otherwise an error that says so.
fn finite_prediction(p: Prediction) -> Result<Prediction> {
    let b = &p.budget;
    for (what, v) in [
        ("variance", p.variance),
        ("spectrum noise", b.spectrum_noise),
        ("quadrature error", b.quadrature),
        ("truncation bound", b.truncation),
        ("model term", b.model),
    ] {
        finite(v, || format!("the {what} of the {} is {v}", p.route))?;
    }
    Ok(p)
}

fn alternative(p: &Prediction) -> Alternative {
    Alternative {
        route: p.route,
        variance: p.variance,
        budget: p.budget,
    }
}
