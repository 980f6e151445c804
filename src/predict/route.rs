//! Which route [`super::predict`] takes, and why: every decision of substance about a prediction
//! (closed form or estimate, form, reference N, lattice extent, realizations) is made here.

use super::fourier::lattice::{white_noise, LatticePower, PatternEstimate, PatternPlan};
use super::fourier::low_band::LowBand;
use super::fourier::space::{
    autocorrelation_seconds, kronecker_variance, rank1_lattice_variance, regular_grid_variance,
    sets_shift_variance,
};
use super::{
    predict_from_power, predict_polar, ErrorBudget, Form, FormChoice, Patterns, PredictParams,
    Prediction, Problem, Route, SpectrumChoice, SpectrumOrigin, SpectrumSource,
};
use crate::budget::{Budget, Needs};
use crate::error::{Error, Result};
use crate::integrand::Integrand;
use crate::progress::{stage, Progress};
use crate::randomization::Randomization;
use crate::sampler::{perfect_root, strata, CellLaw, CellRule, Randomness, Sampler, SamplerKind};
use crate::spectrum::{estimate, ClosedForm, Engine, Lattice, PatternSource, SpectrumParams};

/// The default reference N for a rescaled spectrum: 4096 in 1D and 2D, 32768 in 3D.
pub fn default_reference_n(d: usize) -> usize {
    if d == 3 {
        32768
    } else {
        4096
    }
}

/// Largest lattice of a closed-form sum: `2^22` frequencies (tables make each one cheap).
const CLOSED_LATTICE_BUDGET: usize = 1 << 22;
/// Largest lattice of a per-pattern estimate: `2^20` frequencies (one transform per pattern).
const ESTIMATED_LATTICE_BUDGET: usize = 1 << 20;
/// The tail bound a closed-form route accepts, relative to the variance, before it widens.
const CLOSED_TAIL_SHARE: f64 = 1e-3;
/// The same for an estimated spectrum, whose noise is larger anyway.
const ESTIMATED_TAIL_SHARE: f64 = 1e-2;
/// Realizations an estimate starts with.
pub(super) const INITIAL_REALIZATIONS: usize = 32;
/// Realizations an adaptive estimate never exceeds.
const MAX_REALIZATIONS: usize = 4096;
/// Relative full-space leak below which an integrand counts as contained in the cube.
const CONTAINED_LEAK: f64 = 1e-9;

/// The largest `K` with `(2K+1)^d ≤ budget`.
fn largest_kmax(d: usize, budget: usize) -> usize {
    (((budget as f64).powf(1.0 / d as f64) - 1.0) / 2.0)
        .floor()
        .max(1.0) as usize
}

/// The default lattice extent for an estimate at `n_ref`: `ν` up to 5, within the lattice
/// budget of a per-pattern estimate.
pub fn default_kmax(n_ref: usize, d: usize) -> usize {
    let k = (5.0 * (n_ref as f64).powf(1.0 / d as f64)).round() as usize;
    k.clamp(1, largest_kmax(d, ESTIMATED_LATTICE_BUDGET))
}

/// The initial lattice extent of a route: `ν = K/N^{1/d}` up to `nu`, at least 16.
fn initial_kmax(n: usize, d: usize, nu: f64, budget: usize) -> usize {
    crate::spectrum::kmax_at_nu(n, d, nu)
        .max(16)
        .min(largest_kmax(d, budget))
}

/// The largest model error the polar form may carry, relative to its variance.
const POLAR_MODEL_SHARE: f64 = 1e-2;

/// Checks the polar form's assumptions for `f` and patterns whose correlations reach `range`
/// (largest component), and returns its model error at N. The radial integral uses the
/// full-space transform, so `f` must be isotropic and contained in the cube; by Poisson summation
/// it differs from the lattice sum by the images of the autocorrelation (convolved with the
/// pattern's correlations) at the `2d` nearest non-zero integer offsets and beyond, at most
/// `2 · 2d · sup_{|r|∞ ≥ 1 - range} |a(r)| / N`.
///
/// # Errors
/// [`Error::OutsideValidity`] naming the assumption that fails.
pub fn polar_validity(f: &dyn Integrand, range: f64, n: usize) -> Result<f64> {
    let fail = |reason: String| {
        Err(Error::OutsideValidity {
            route: "the polar form".into(),
            reason,
        })
    };
    if !f.is_isotropic() {
        return fail(format!(
            "{} is not isotropic; use the lattice form",
            f.label()
        ));
    }
    if f.full_space_leak() > CONTAINED_LEAK {
        return fail(format!(
            "{} is not contained in the cube (its full-space energy differs from the torus's \
             by {:.1e}): Monte Carlo sees a truncated function; use the lattice form",
            f.label(),
            f.full_space_leak()
        ));
    }
    match f.autocorrelation_beyond(1.0 - range) {
        Some(bound) => Ok(4.0 * f.dimension() as f64 * bound / n as f64),
        None => fail(format!(
            "the autocorrelation of {} reaches past 1 - {range:.3} (the pattern's correlations \
             included): its images on the torus overlap, and the radial integral is not the \
             lattice sum; use the lattice form",
            f.label()
        )),
    }
}

/// Puts the polar form's model error into `p`'s budget, or refuses it when the error exceeds
/// [`POLAR_MODEL_SHARE`] of the variance.
fn with_model(mut p: Prediction, model: f64) -> Result<Prediction> {
    if model > POLAR_MODEL_SHARE * p.variance {
        return Err(Error::OutsideValidity {
            route: "the polar form".into(),
            reason: format!(
                "the autocorrelation's images on the torus may move the variance by {model:.2e}, \
                 {:.1}% of it; use the lattice form",
                100.0 * model / p.variance
            ),
        });
    }
    p.budget.model = model;
    Ok(p)
}

/// How far a sampler's pair correlations reach at N (largest component): the sampler's own
/// reach ([`SamplerKind::correlation_range`]), or two mean spacings for patterns of unknown
/// origin.
fn correlation_range(kind: Option<SamplerKind>, n: usize, d: usize) -> f64 {
    match kind {
        Some(k) => k.correlation_range(n, d),
        None => 2.0 * (n as f64).powf(-1.0 / d as f64),
    }
}

/// Errors unless the routes, which predict the shifted (homogenized) estimator, predict
/// `problem`'s: the shift itself, or a randomization under which the sampler's patterns
/// integrate with the same variance
/// ([`Randomness::has_shifted_variance`](crate::sampler::Randomness::has_shifted_variance)). Point sets of
/// unknown law are predicted only under the shift.
pub(crate) fn check_estimator(problem: &Problem<'_>) -> Result<()> {
    let r = problem.randomization;
    if r == Randomization::Shift {
        return Ok(());
    }
    let kind = problem.kind();
    if uses_cells(problem)
        || uses_walsh(problem)
        || gaussian_jitter_as_drawn(problem).is_some()
        || halton_as_drawn(problem).is_some()
        || halton_through_level(problem)
        || drawn_under_digital_shift(problem)
    {
        return Ok(());
    }
    match kind {
        Some(k) if k.facts().randomness.has_shifted_variance(r) => Ok(()),
        Some(k) if k.is_deterministic() && r == Randomization::None => {
            Err(Error::OutsideValidity {
                route: "a spectral route".into(),
                reason: format!(
                    "{k} draws one fixed pattern: used as drawn, its estimator has a bias and no \
                 variance (`specvar bias`); randomize it with shift"
                ),
            })
        }
        Some(k)
            if k.facts().randomness == Randomness::PermutedDigits && r == Randomization::None =>
        {
            Err(Error::OutsideValidity {
                route: "a spectral route".into(),
                reason: format!(
                    "halton used as drawn is predicted in 1 to 3 axes, and in {} axes only on \
                 integrands that are a product of one factor per axis (Gaussians, axis-aligned \
                 boxes), which {} is not; measure it with `specvar mc --randomization none`, or \
                 predict with --randomization shift",
                    problem.integrand.dimension(),
                    problem.integrand.label()
                ),
            })
        }
        None if matches!(problem.patterns, Patterns::PointSets(_)) => Err(Error::OutsideValidity {
            route: "a spectral route".into(),
            reason: format!(
                "given point sets of unknown law used {} have no route: the cell form needs the \
                 cells in which their points are uniform (declare them with --cells strata, rows \
                 or dyadic, if their sampler guarantees it), and the shifted routes predict \
                 another estimator; measure these sets with `specvar mc --input …`, or predict \
                 the shifted estimator with --randomization shift",
                match r {
                    Randomization::None => "as given",
                    _ => "under a digital shift",
                }
            ),
        }),
        _ => Err(Error::OutsideValidity {
            route: "a spectral route".into(),
            reason: format!(
                "every route predicts the randomly shifted estimator, and {} patterns {} \
                 integrate with another variance; measure it with `specvar mc --randomization \
                 {r}`, or predict with --randomization shift",
                kind.map_or("given".to_string(), |k| k.to_string()),
                match r {
                    Randomization::None => "used as drawn",
                    _ => "under a digital shift",
                }
            ),
        }),
    }
}

/// Whether `problem` is the unshifted estimator of a sampler whose law a shift would change and
/// whose points are independent and uniform in known cells: the cell form predicts it. A
/// digital shift of an Owen-scrambled net is again nested uniform scrambling: its law as drawn.
pub(super) fn uses_cells(problem: &Problem<'_>) -> bool {
    if scrambling_absorbs_shift(problem) {
        return true;
    }
    problem.randomization == Randomization::None
        && match problem.patterns {
            Patterns::PointSets(_) => problem.cells.is_some(),
            Patterns::Sampler(_) => problem.kind().is_some_and(|k| {
                let facts = k.facts();
                facts.cells != CellRule::None && !facts.randomness.is_stationary()
            }),
        }
}

/// Gaussian jitter used as drawn, with its closed form and strata: independent points with
/// known densities, whose variance the aliased-pair form gives exactly.
pub(super) fn gaussian_jitter_as_drawn(
    problem: &Problem<'_>,
) -> Option<(crate::sampler::ClosedForm, Vec<usize>)> {
    let Patterns::Sampler(sampler) = problem.patterns else {
        return None;
    };
    let form @ ClosedForm::GaussianJitter { .. } = sampler.closed_form(problem.n)? else {
        return None;
    };
    if problem.randomization != Randomization::None {
        return None;
    }
    let strata = crate::sampler::strata(problem.n, problem.integrand.dimension())?;
    Some((form, strata))
}

/// Halton used as drawn on a product integrand, whose variance the pairs of its points' digit
/// agreements give exactly.
fn halton_as_drawn(problem: &Problem<'_>) -> Option<crate::integrand::ProductForm> {
    halton_drawn(problem)
        .then(|| problem.integrand.product_form())
        .flatten()
}

/// Halton's sampler used as drawn.
fn halton_drawn(problem: &Problem<'_>) -> bool {
    problem.randomization == Randomization::None
        && matches!(problem.patterns, Patterns::Sampler(_))
        && problem
            .kind()
            .is_some_and(|k| k.facts().randomness == Randomness::PermutedDigits)
}

/// Halton used as drawn in 1 to 3 axes, on any integrand: through a level of digit cells, the
/// finer digits measured ([`super::digits::permuted_level`]).
fn halton_through_level(problem: &Problem<'_>) -> bool {
    halton_drawn(problem)
        && problem.integrand.dimension() <= super::digits::permuted_level::MAX_LEVEL_AXES
}

/// How Halton as drawn is predicted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum HaltonMethod {
    /// Its pairs of points on a product integrand.
    Pairs,
    /// Through a level of digit cells.
    Level,
}

/// Which method predicts Halton as drawn: on a product integrand its pairs of points exactly
/// while they fit the work budget, else (and on any other integrand in 1 to 3 axes) through a
/// level of digit cells with the finer digits measured; `None` for another problem.
///
/// # Errors
/// A form, closed spectrum or lattice extent asked for, which belong to the shifted estimator.
pub(super) fn halton_analysis(
    problem: &Problem<'_>,
    params: &PredictParams,
) -> Result<Option<HaltonMethod>> {
    if !halton_drawn(problem) {
        return Ok(None);
    }
    if params.kmax.is_some()
        || params.form != FormChoice::Auto
        || params.spectrum == SpectrumChoice::Closed
    {
        return Err(Error::OutsideValidity {
            route: "the lattice, polar or cell form, a closed spectrum or a lattice extent".into(),
            reason: "halton used as drawn is predicted by the Walsh form over its digit supports; \
                     the lattice and polar forms, the closed spectra and the lattice extent are \
                     for the toroidal shift (--randomization shift)"
                .into(),
        });
    }
    let (n, d) = (problem.n, problem.integrand.dimension());
    let pairs_fit =
        super::digits::permuted_digits::pair_work_seconds(n, d) <= params.work_budget_seconds;
    let level = halton_through_level(problem);
    Ok(match halton_as_drawn(problem) {
        Some(_) if pairs_fit || !level => Some(HaltonMethod::Pairs),
        _ if level => Some(HaltonMethod::Level),
        _ => None,
    })
}

/// Whether `problem` is Owen-scrambled Sobol' under a digital shift, whose law is Owen's
/// scrambling as drawn (each node's flip composed with the shift's digit is again a uniform
/// flip, independent across nodes), or PMJ02 under one, whose law no fixed flip of digits
/// changes.
pub(crate) fn scrambling_absorbs_shift(problem: &Problem<'_>) -> bool {
    problem.randomization == Randomization::DigitalShift
        && matches!(problem.patterns, Patterns::Sampler(_))
        && problem
            .kind()
            .is_some_and(|k| k.facts().cell_law.is_scrambled_net())
}

/// Owen-scrambled Sobol' (and PMJ02 at a power of two) under a random shift, on an integrand
/// with moments over boxes of at most 3 axes, by default: Owen's gains averaged over shifts
/// predict it without truncation (the estimated spectrum stays available as a check).
pub(super) fn shifted_scrambled_net<'a>(
    problem: &Problem<'a>,
    params: &PredictParams,
) -> Option<&'a dyn Sampler> {
    let d = problem.integrand.dimension();
    match problem.patterns {
        Patterns::Sampler(sampler)
            if cell_form_allowed(params)
                && problem.randomization == Randomization::Shift
                && problem.kind().is_some_and(|k| match k.facts().cell_law {
                    CellLaw::OwenScrambledNet => true,
                    // Every 2^m prefix of a progressive net is a (0,m,2)-net, whose gains every
                    // pattern has.
                    CellLaw::ProgressiveNet => problem.n.is_power_of_two(),
                    _ => false,
                })
                && d <= 3
                && super::strata::cell_moments::check_box_moments(problem.integrand).is_ok() =>
        {
            Some(sampler)
        }
        _ => None,
    }
}

/// Whether the parameters leave the route to the cell form: no spectrum, lattice extent or
/// other form asked for.
fn cell_form_allowed(params: &PredictParams) -> bool {
    params.spectrum == SpectrumChoice::Auto
        && matches!(params.form, FormChoice::Auto | FormChoice::Cells)
        && params.kmax.is_none()
}

/// A random sampler with cells and no closed-form spectrum under a random shift, on an
/// integrand with moments over boxes of at most 3 axes, with the route left to the cell form.
pub(super) fn shifted_strata<'a>(
    problem: &Problem<'a>,
    params: &PredictParams,
) -> Option<(&'a dyn Sampler, SamplerKind, Vec<usize>)> {
    let d = problem.integrand.dimension();
    let Patterns::Sampler(sampler) = problem.patterns else {
        return None;
    };
    let kind = problem.kind()?;
    let facts = kind.facts();
    let eligible = cell_form_allowed(params)
        && problem.randomization == Randomization::Shift
        && facts.cell_law != CellLaw::OwenScrambledNet
        && !kind.is_deterministic()
        && !facts.randomness.is_stationary()
        && sampler.closed_form(problem.n).is_none()
        && d <= 3
        && super::strata::cell_moments::check_box_moments(problem.integrand).is_ok();
    let grid = facts.cells.grid(problem.n, d).filter(|_| eligible)?;
    Some((sampler, kind, grid))
}

/// A random sampler (its patterns drawn anew) under a digital shift whose law the shift
/// changes: not white noise (whose law it keeps) and not an Owen-scrambled net (which absorbs
/// it); the mean over patterns of each one's Walsh sum predicts it.
pub(super) fn drawn_under_digital_shift(problem: &Problem<'_>) -> bool {
    let r = problem.randomization;
    r == Randomization::DigitalShift
        && matches!(problem.patterns, Patterns::Sampler(_))
        && problem
            .kind()
            .is_some_and(|k| !k.is_deterministic() && !k.facts().randomness.has_shifted_variance(r))
        && !scrambling_absorbs_shift(problem)
}

/// Whether `problem` is fixed patterns under a digital shift (a deterministic sampler's, or
/// given sets): the Walsh form predicts it.
pub(super) fn uses_walsh(problem: &Problem<'_>) -> bool {
    problem.randomization == Randomization::DigitalShift
        && match problem.patterns {
            Patterns::PointSets(_) => true,
            Patterns::Sampler(_) => problem.kind().is_some_and(|k| k.is_deterministic()),
        }
}

/// The default for strata under a shift: the lattice form with a measured tail. Their
/// spectra along the axes are far below white (their projections are stratified), which a
/// white tail overcounts, and per unit of noise it costs 5 to 60 times less than their cell
/// form averaged over patterns and shifts (`--form cells`, the alternative route).
pub(super) fn shifted_strata_measured(
    problem: &Problem<'_>,
    (sampler, kind): (&dyn Sampler, SamplerKind),
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let (n, d) = (problem.n, problem.dimension());
    let source = PatternSource::Sampler {
        sampler,
        n,
        seed: params.seed,
    };
    let kmax = initial_kmax(n, d, 6.0, ESTIMATED_LATTICE_BUDGET);
    let p = super::fourier::measured_tail::predict_measured_tail(
        problem.integrand,
        source,
        kmax,
        params,
        progress,
    )?;
    let SpectrumOrigin::MeasuredTail {
        kmax,
        patterns,
        shifts,
        ..
    } = p.route.spectrum
    else {
        return Err(Error::Mismatch("a measured tail of another origin".into()));
    };
    let reason = format!(
        "{kind} under a random shift has no closed form: the lattice form on |k_i| ≤ {kmax} \
         with each of {patterns} patterns' own transform, and beyond it the mean square, at \
         {shifts} uniform shifts, of each pattern's error less its lattice part (unbiased, \
         nothing modelled beyond the lattice: a white tail would overcount its axes, along \
         which its projections are stratified); noise from the patterns' spread; the cell form \
         under shifts is --form cells"
    );
    Ok(with_reason(p, reason))
}

fn with_reason(mut p: Prediction, reason: String) -> Prediction {
    p.reason = reason;
    p
}

/// Whether a stratified sampler's shifted spectrum may be summed in space over its offsets'
/// difference (the strata's tent, or Gaussian jitter's weight): in 1D or 2D, for an integrand
/// with a closed-form autocorrelation.
fn weighs_in_space(f: &dyn Integrand, d: usize) -> bool {
    d <= 2 && f.autocorrelation(&vec![0.0; d]).is_some()
}

/// Gaussian jitter under a shift, its closed form summed exactly: by Parseval in frequency,
/// whose frequencies grow like N, or in space over the offsets' difference, at the same cost at
/// any N (1D and 2D, a closed-form autocorrelation): space first where it is the cheaper, and
/// where the frequencies exceed the budget.
pub(super) fn gaussian_jitter_shifted(
    f: &dyn Integrand,
    form: ClosedForm,
    strata: &[usize],
    params: &PredictParams,
) -> Result<Prediction> {
    let parseval = || {
        super::fourier::gaussian_jitter::predict_gaussian_jitter_shifted(
            f,
            form,
            strata,
            &params.budget,
        )
    };
    let in_space = || {
        super::fourier::jitter_tent::predict_gaussian_jitter_in_space(
            f,
            form,
            strata,
            &params.budget,
        )
    };
    let d = strata.len();
    if !weighs_in_space(f, d) {
        return parseval();
    }
    if super::fourier::gaussian_jitter::shifted_frequency_seconds(f, form, strata)
        > super::fourier::jitter_tent::typical_weight_seconds(f)
    {
        let space = match in_space() {
            Err(Error::TooLarge { .. }) => None,
            other => Some(other?),
        };
        return tighter_in_space(space, parseval);
    }
    match parseval() {
        Err(Error::TooLarge { .. }) => in_space(),
        other => other,
    }
}

/// The lattice form with a closed form: exact, with an exact tail bound.
pub(super) fn closed_lattice(
    problem: &Problem<'_>,
    closed: ClosedForm,
    kind: Option<SamplerKind>,
    params: &PredictParams,
) -> Result<Prediction> {
    // Jitter's spectrum is exact in space over one stratum's width, at any N: alone where its
    // quadrature keeps its digits, else beside the other routes, the narrower budget answering.
    let tent = if params.form == FormChoice::Auto
        && params.kmax.is_none()
        && closed == ClosedForm::Jitter
        && !widest_closed_lattice(problem).1
    {
        jitter_tent(problem, params)?
    } else {
        None
    };
    tighter_in_space(tent, || {
        closed_lattice_or_polar(problem, closed, kind, params)
    })
}

/// An exact sum in space (`space`, `None` where it was not taken or its budget refused it),
/// alone where its quadrature keeps its digits (a budget within [`TENT_ROUNDING_SHARE`] of
/// the value), else beside the routes in frequency (`other`), the narrower budget answering.
fn tighter_in_space(
    space: Option<Prediction>,
    other: impl FnOnce() -> Result<Prediction>,
) -> Result<Prediction> {
    let width = |p: &Prediction| p.budget.half_width(crate::montecarlo::Z_99);
    match space {
        Some(space) if width(&space) <= TENT_ROUNDING_SHARE * space.variance => Ok(space),
        Some(space) => match other() {
            Ok(other) if width(&other) < width(&space) => Ok(other),
            _ => Ok(space),
        },
        None => other(),
    }
}

/// The widest lattice extent a closed form may take within its budget, and whether it reaches
/// `ν = 1` (the strata's frequencies) at the problem's N.
fn widest_closed_lattice(problem: &Problem<'_>) -> (usize, bool) {
    let (n, d) = (problem.n, problem.dimension());
    let widest = largest_kmax(d, CLOSED_LATTICE_BUDGET);
    (widest, widest as f64 >= (n as f64).powf(1.0 / d as f64))
}

/// [`closed_lattice`] without the strata's tent.
fn closed_lattice_or_polar(
    problem: &Problem<'_>,
    closed: ClosedForm,
    kind: Option<SamplerKind>,
    params: &PredictParams,
) -> Result<Prediction> {
    let n = problem.n;
    let name = kind.map_or("the sampler".to_string(), |k| k.to_string());
    // A lattice that cannot reach ν = 1 within its budget leaves most of the variance to its
    // tail bound: where the polar form is valid it answers alone.
    let (widest, reaches_one) = widest_closed_lattice(problem);
    if params.form == FormChoice::Auto
        && params.kmax.is_none()
        && closed.is_scale_invariant()
        && closed != ClosedForm::WhiteNoise
        && !reaches_one
        && let Ok(polar) = closed_polar(problem, closed, kind, params)
    {
        let reason = format!(
            "{}; the lattice form was not computed: the widest lattice it may take, \
                 |k_i| ≤ {widest}, does not reach ν = 1 at N = {n}, and its tail bound would be \
                 most of the variance",
            polar.reason
        );
        return Ok(with_reason(polar, reason));
    }
    let p = lattice_with_closed_form(problem, closed, &name, params);
    if params.form == FormChoice::Auto
        && closed.is_scale_invariant()
        && let Ok(polar) = closed_polar(problem, closed, kind, params)
    {
        return match p {
            Ok(p) => Ok(tighter_of(p, polar)),
            // The polar form's work does not grow with N: it answers where the default
            // lattice would exceed the budget (a lattice asked for is refused as asked).
            Err(Error::TooLarge { what, needed, .. }) if params.kmax.is_none() => Ok(with_reason(
                polar.clone(),
                format!(
                    "{}; the lattice form was not computed ({what} would need {needed}, \
                         above the budget)",
                    polar.reason
                ),
            )),
            Err(e) => Err(e),
        };
    }
    p
}

/// Jitter under a shift by the strata's tent in space, where the integrand has a closed-form
/// autocorrelation in 1D or 2D and the budget affords the quadrature (`None` otherwise).
fn jitter_tent(problem: &Problem<'_>, params: &PredictParams) -> Result<Option<Prediction>> {
    let (n, d) = (problem.n, problem.dimension());
    let f = problem.integrand;
    let Some(strata) = crate::sampler::strata(n, d) else {
        return Ok(None);
    };
    if !weighs_in_space(f, d) {
        return Ok(None);
    }
    // The tent's work is bounded for the coarsest strata; a budget below that bound leaves
    // the other routes to answer.
    let tent = match super::fourier::jitter_tent::predict_jitter_tent(f, &strata, &params.budget) {
        Err(Error::TooLarge { .. }) => return Ok(None),
        other => other?,
    };
    let reason = format!(
        "{}; the lattice form's widest lattice, |k_i| ≤ {}, does not reach ν = 1 at N = {n}",
        tent.reason,
        widest_closed_lattice(problem).0
    );
    Ok(Some(with_reason(tent, reason)))
}

/// The lattice form with a closed form (white noise by Parseval; the regular grid, rank-1
/// lattices and Kronecker summed in space; the others on a lattice widened while the tail bound
/// exceeds [`CLOSED_TAIL_SHARE`] of the variance and the lattice budget allows).
fn lattice_with_closed_form(
    problem: &Problem<'_>,
    closed: ClosedForm,
    name: &str,
    params: &PredictParams,
) -> Result<Prediction> {
    let f = problem.integrand;
    let (n, d) = (problem.n, problem.dimension());
    Ok(match closed {
        ClosedForm::WhiteNoise => with_reason(
            white_noise(f, n)?,
            format!("{name} is white noise: (∫f² - I²)/N exactly, by Parseval"),
        ),
        ClosedForm::RegularGrid
        | ClosedForm::Rank1Lattice { .. }
        | ClosedForm::Kronecker { .. } => summed_in_space(f, n, closed, name, &params.budget)?,
        _ => {
            let mut kmax = params
                .kmax
                .unwrap_or_else(|| initial_kmax(n, d, 8.0, CLOSED_LATTICE_BUDGET));
            let source = SpectrumSource::Closed(closed);
            let mut p = predict_from_power(
                &LatticePower::of_within(f, lattice(d, kmax), &params.budget)?,
                &source,
                n,
            )?;
            while params.kmax.is_none()
                && p.budget.truncation > CLOSED_TAIL_SHARE * p.variance
                && Lattice::len(&lattice(d, 2 * kmax)) <= CLOSED_LATTICE_BUDGET
            {
                kmax *= 2;
                p = predict_from_power(
                    &LatticePower::of_within(f, lattice(d, kmax), &params.budget)?,
                    &source,
                    n,
                )?;
            }
            with_reason(
                p,
                format!(
                    "{name} has a closed form at N = {n} ({}): the lattice form, exact on the \
                 torus, on |k_i| ≤ {kmax}, its tail bounded by the closed form",
                    closed.name()
                ),
            )
        }
    })
}

/// The lattice form `lattice`, with `polar` as its alternative, unless the lattice's budget is
/// above its target share of the variance (a lattice the budget cannot widen enough, at large N)
/// and the polar form's is tighter: then the polar form, with the lattice as the alternative.
fn tighter_of(mut lattice: Prediction, mut polar: Prediction) -> Prediction {
    let width = |p: &Prediction| p.budget.half_width(crate::montecarlo::Z_99);
    let lattice_share = width(&lattice) / lattice.variance;
    if lattice_share <= CLOSED_TAIL_SHARE || width(&polar) >= width(&lattice) {
        lattice.alternatives.push(polar.as_alternative());
        return lattice;
    }
    polar.reason = format!(
        "{}; chosen over the lattice form, whose budget is {:.2}% of its value (the lattice \
         cannot be widened enough at this N) against {:.2e}% here",
        polar.reason,
        100.0 * lattice_share,
        100.0 * width(&polar) / polar.variance
    );
    polar.alternatives.push(lattice.as_alternative());
    polar
}

fn lattice(d: usize, kmax: usize) -> Lattice {
    Lattice { dimension: d, kmax }
}

/// The most pairs of points the exact pair sum over given sets visits (`2^22`: seconds for the
/// costliest autocorrelations, a polygon's clips); beyond, their spectrum is estimated.
const EXACT_PAIRS: usize = 1 << 22;

/// Fixed patterns under the shift (given sets, or a deterministic sampler's one pattern),
/// exactly: each set's own periodogram summed in space, `(1/N²) Σ_{i,j} a_f(x_i − x_j) − I²`,
/// averaged over the sets, where the integrand has a closed-form autocorrelation and the pairs
/// are within [`EXACT_PAIRS`]; `None` otherwise.
fn fixed_sets_in_space(
    f: &dyn Integrand,
    sets: &[crate::pointset::PointSet],
    kind: Option<SamplerKind>,
    params: &PredictParams,
) -> Result<Option<Prediction>> {
    let d = f.dimension();
    let n = sets.first().map_or(0, |s| s.len());
    let pairs = sets.len().saturating_mul(n.saturating_mul(n));
    if pairs > EXACT_PAIRS || f.autocorrelation(&vec![0.0; d]).is_none() {
        return Ok(None);
    }
    params.budget.check(
        "the pair sum over the given sets",
        Needs {
            memory_bytes: 8.0 * n as f64,
            work_seconds: pairs as f64 * autocorrelation_seconds(f),
        },
        "fewer or smaller sets",
    )?;
    let Some((variance, rounding)) = sets_shift_variance(f, sets)? else {
        return Ok(None);
    };
    Ok(Some(Prediction {
        variance,
        randomization: Randomization::Shift,
        route: Route {
            form: Form::Lattice,
            spectrum: SpectrumOrigin::Pairs { sets: sets.len() },
        },
        reason: format!(
            "{} under a random shift: the lattice form with each set's own periodogram is, by \
             Poisson summation, (1/N²) Σ_(i,j) a_f(x_i − x_j) − I² over its {} pairs, with the \
             integrand's autocorrelation in closed form: exact, nothing truncated",
            match kind {
                Some(k) => format!("{k}'s fixed pattern"),
                None => format!("{} given point sets", sets.len()),
            },
            n * n
        ),
        budget: ErrorBudget {
            tabulation: 0.0,
            quadrature: rounding,
            ..Default::default()
        },
        n,
        dimension: d,
        dc_term: 0.0,
        evaluations: pairs as u64,
        alternatives: Vec::new(),
        analysis: None,
    }))
}

/// The fixed sets of `problem` whose pairs [`fixed_sets_in_space`] sums: given sets, or a
/// deterministic sampler's one pattern (counted, not drawn); their count and N.
fn fixed_sets_shape(problem: &Problem<'_>) -> Option<(usize, usize)> {
    match (problem.patterns, problem.kind()) {
        (Patterns::PointSets(sets), _) => Some((sets.len(), problem.n)),
        (Patterns::Sampler(_), Some(k)) if k.is_deterministic() => Some((1, problem.n)),
        _ => None,
    }
}

/// Whether `problem`'s fixed sets are summed exactly over their pairs: within [`EXACT_PAIRS`],
/// on an integrand with a closed-form autocorrelation.
pub(super) fn fixed_pairs_fit(problem: &Problem<'_>) -> bool {
    let f = problem.integrand;
    fixed_sets_shape(problem).is_some_and(|(sets, n)| {
        sets.saturating_mul(n.saturating_mul(n)) <= EXACT_PAIRS
            && f.autocorrelation(&vec![0.0; f.dimension()]).is_some()
    })
}

/// What the pair sum over `problem`'s fixed sets needs: one autocorrelation value a pair.
pub(super) fn fixed_pairs_needs(problem: &Problem<'_>) -> Needs {
    let (sets, n) = fixed_sets_shape(problem).unwrap_or((0, 0));
    Needs {
        memory_bytes: 8.0 * n as f64,
        work_seconds: sets as f64 * (n as f64).powi(2) * autocorrelation_seconds(problem.integrand),
    }
}

/// The pair sum over `problem`'s fixed sets ([`fixed_pairs_fit`] holds).
///
/// # Errors
/// The budget, or an integrand whose autocorrelation is not in closed form.
pub(super) fn fixed_pairs(problem: &Problem<'_>, params: &PredictParams) -> Result<Prediction> {
    let drawn;
    let sets: &[crate::pointset::PointSet] = match problem.patterns {
        Patterns::PointSets(sets) => sets,
        Patterns::Sampler(s) => {
            drawn = [s.sample(problem.n, params.seed, 0)?];
            &drawn
        }
    };
    fixed_sets_in_space(problem.integrand, sets, problem.kind(), params)?.ok_or_else(|| {
        Error::Mismatch(format!(
            "{} has no autocorrelation in closed form",
            problem.integrand.label()
        ))
    })
}

/// Pairs of points per pattern up to which the patterns of a sampler without a closed form may
/// be summed in space under the shift: for a disk 13 ms a pattern of 256 points, about a
/// transform of the widest lattice an integrand that jumps asks for there.
const PATTERN_PAIRS: usize = 1 << 16;

/// The share of the variance up to which the strata's tent answers alone: beyond it (smooth
/// integrands, whose autocorrelation falls only quadratically over a fine stratum, and 1D at
/// the finest strata, so that `a_f(0) − a_f(r)` keeps few digits) the lattice and polar forms
/// are tried beside it.
const TENT_ROUNDING_SHARE: f64 = 1e-6;

/// The sampler of `problem` ([`pattern_pairs`]) if its patterns are summed in space for less
/// than their transforms on `lattice` cost: `N²` pairs at [`autocorrelation_seconds`] against the
/// `(2(2K+1))^d` cells of the oversampled grid. `None` otherwise.
fn cheaper_pairs<'a>(
    problem: &Problem<'a>,
    lattice: Lattice,
    params: &PredictParams,
) -> Option<&'a dyn Sampler> {
    let pairs = (problem.n as f64).powi(2) * autocorrelation_seconds(problem.integrand);
    let transform = crate::costs::TRANSFORM_CELL_SECONDS
        * (2.0 * lattice.side() as f64).powi(lattice.dimension as i32);
    pattern_pairs(problem, params).filter(|_| pairs < transform)
}

/// The sampler of a problem whose shifted variance may be the mean over its patterns of each
/// pattern's own variance summed exactly in space ([`patterns_in_space`]): a stochastic
/// sampler with no closed form at N, an integrand with a closed-form autocorrelation in at
/// most 3D, at most [`PATTERN_PAIRS`] pairs a pattern, and neither a spectrum, a form nor a
/// lattice asked for. `None` otherwise. Asked only by the per-pattern lattice form, which the
/// problems of the cell and Walsh forms never reach.
fn pattern_pairs<'a>(problem: &Problem<'a>, params: &PredictParams) -> Option<&'a dyn Sampler> {
    let Patterns::Sampler(sampler) = problem.patterns else {
        return None;
    };
    let f = problem.integrand;
    let d = f.dimension();
    let n = problem.n;
    let defaults = params.spectrum == SpectrumChoice::Auto
        && params.form == FormChoice::Auto
        && params.kmax.is_none();
    let stochastic = problem.kind().is_some_and(|k| !k.is_deterministic());
    (defaults
        && stochastic
        && n.checked_mul(n).is_some_and(|pairs| pairs <= PATTERN_PAIRS)
        && d <= 3
        && sampler.closed_form(n).is_none()
        && f.autocorrelation(&vec![0.0; d]).is_some())
    .then_some(sampler)
}

/// The shifted variance of `sampler`'s patterns at `n` points on `f`: each pattern's variance
/// under the shift is, by Poisson summation, its own lattice form summed in space,
/// `(1/N²) Σ_(i,j) a_f(x_i − x_j) − I²`, exact; their mean over patterns, drawn until its
/// standard error (from their spread) reaches the target noise, is unbiased for the
/// estimator's. Nothing is truncated or modelled.
fn patterns_in_space(
    f: &dyn Integrand,
    sampler: &dyn Sampler,
    n: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let d = f.dimension();
    let pairs = (n * n) as f64;
    let draw = sampler
        .kind()
        .map_or(0.0, |k| k.pattern_needs(n, d).work_seconds);
    let per_pattern = draw + pairs * autocorrelation_seconds(f);
    let counts = super::term_mean::terms_within_budget(
        params,
        per_pattern,
        (INITIAL_REALIZATIONS, MAX_REALIZATIONS),
    );
    params.budget.check(
        "the pair sums over the patterns",
        Needs {
            memory_bytes: 8.0 * (n * d) as f64,
            work_seconds: counts.0 as f64 * per_pattern,
        },
        "lower N",
    )?;
    let label = format!("pair sums of {} at N = {n}", sampler.name());
    let estimate = super::term_mean::mean_of_exact_terms(
        &label,
        counts,
        params.target_noise,
        0.0,
        |i| {
            let pattern = sampler.sample(n, params.seed, i as u64)?;
            let (variance, rounding) = super::fourier::space::pattern_shift_variance(f, &pattern)?
                .ok_or_else(|| {
                    Error::Mismatch(format!(
                        "{} has no autocorrelation in closed form",
                        f.label()
                    ))
                })?;
            Ok(super::strata::cell_moments::CellSum { variance, rounding })
        },
        progress,
    )?;
    let patterns = estimate.patterns;
    Ok(Prediction {
        variance: estimate.variance,
        randomization: Randomization::Shift,
        route: Route {
            form: Form::Lattice,
            spectrum: SpectrumOrigin::PatternPairs { n, patterns },
        },
        reason: format!(
            "{} has no closed form at N = {n}: each pattern's variance under the shift is its \
             own lattice form, by Poisson summation (1/N²) Σ_(i,j) a_f(x_i − x_j) − I² over its \
             {} pairs with the integrand's autocorrelation in closed form, exact; their mean \
             over {patterns} patterns, noise from their spread, nothing truncated",
            sampler.name(),
            n * n
        ),
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise: estimate.standard_error,
            quadrature: estimate.rounding,
            ..Default::default()
        },
        n,
        dimension: d,
        dc_term: 0.0,
        evaluations: (patterns * n * n) as u64,
        alternatives: Vec::new(),
        analysis: None,
    })
}

/// The lattice forms whose peaks continue beyond any lattice (the regular grid's replicas, a
/// rank-1 lattice's dual lattice, a Kronecker sequence's Fejér peaks), summed exactly in space
/// through the integrand's autocorrelation.
fn summed_in_space(
    f: &dyn Integrand,
    n: usize,
    closed: ClosedForm,
    name: &str,
    budget: &Budget,
) -> Result<Prediction> {
    // One autocorrelation value (8 bytes) per point or lag, at its integrand's cost.
    budget.check(
        &format!("the lattice form summed in space over N = {n} terms"),
        Needs {
            memory_bytes: 8.0 * n as f64,
            work_seconds: n as f64 * autocorrelation_seconds(f),
        },
        "lower N",
    )?;
    let (exact, reason) = match closed {
        ClosedForm::RegularGrid => (
            regular_grid_variance(f, n)?,
            format!(
                "{name} at N = {n} has power N on its replicas m Z^d and 0 elsewhere: the \
                 lattice form summed exactly in space, (1/N) Σ_g a_f(g) - I² over the grid \
                 vectors g"
            ),
        ),
        ClosedForm::Rank1Lattice { generator } => (
            rank1_lattice_variance(f, n, generator)?,
            format!(
                "{name} at N = {n} (generating vector (1, {generator})) has power N on its dual \
                 lattice and 0 elsewhere: the lattice form summed exactly in space, \
                 (1/N) Σ_i a_f(x_i) - I² over its points"
            ),
        ),
        ClosedForm::Kronecker { alpha } => (
            kronecker_variance(f, n, &alpha)?,
            format!(
                "{name} at N = {n} has the Fejér kernel of k·α as its spectrum: the lattice form \
                 summed exactly in space, (1/N²) Σ_j (N - |j|) a_f(jα) - I² over its lags"
            ),
        ),
        other => {
            return Err(Error::OutsideValidity {
                route: "the lattice form summed in space".into(),
                reason: format!(
                    "{} has a tail bound and is summed on the lattice instead",
                    other.name()
                ),
            })
        }
    };
    let (value, rounding) = exact.ok_or_else(|| Error::OutsideValidity {
        route: format!("the lattice form with the {}'s spectrum", closed.name()),
        reason: format!(
            "its peaks (power up to N) continue beyond any lattice, and {} has no closed-form \
             autocorrelation to sum them in space; estimate the spectrum instead",
            f.label()
        ),
    })?;
    let space = in_space(f, n, closed, (value, rounding), reason);
    // At the floor of the arithmetic the space sum says only its bound: a smooth integrand's
    // power summed over the dual lattice, in positive terms, may say more.
    let dual = (rounding > CLOSED_TAIL_SHARE * value)
        .then(|| over_dual_lattice(f, n, closed, name))
        .flatten();
    Ok(match dual {
        Some(mut dual) if dual.budget.half_width(0.0) < rounding => {
            dual.alternatives.push(space.as_alternative());
            dual
        }
        Some(dual) => {
            let mut space = space;
            space.alternatives.push(dual.as_alternative());
            space
        }
        None => space,
    })
}

/// Jitter's strata as drawn beyond its table of cells, on a smooth integrand whose own sums over
/// a grid's cells are not exact (an anisotropic Gaussian), with the form left to the route:
/// where [`jitter_by_aliasing`] applies. `None` otherwise.
fn jitter_strata_beyond_table(problem: &Problem<'_>, params: &PredictParams) -> Option<Vec<usize>> {
    let (f, n) = (problem.integrand, problem.n);
    let d = f.dimension();
    f.smooth_decay()?;
    let kind = problem.kind()?;
    let grid = (kind.closed_form(n, d) == Some(ClosedForm::Jitter)
        && problem.randomization == Randomization::None
        && params.form == FormChoice::Auto)
        .then(|| kind.facts().cells.grid(n, d))
        .flatten()?;
    let beyond_table = grid
        .iter()
        .try_fold(1usize, |a, &m| a.checked_mul(m))
        .is_none_or(|c| c > super::strata::cell_moments::EXACT_CELL_BUDGET);
    // One cell per axis asks at no cost whether the integrand's own sums are exact (they then
    // answer through the cell form at any N).
    let exact_sums =
        f.cell_sums(&vec![1; d]).is_some() && !super::strata::cell_pairs::bounded_cell_sums(f);
    (beyond_table && !exact_sums).then_some(grid)
}

/// Whether [`jitter_by_aliasing`] applies to `problem`.
pub(super) fn jitter_aliasing_applies(problem: &Problem<'_>, params: &PredictParams) -> bool {
    jitter_strata_beyond_table(problem, params).is_some()
}

/// Jitter as drawn beyond the table of its strata, on a smooth integrand without exact sums
/// over a grid's cells of its own (an anisotropic Gaussian): the shifted estimator's variance,
/// which its closed form gives at any N, with the distance between the two estimators bounded
/// as the model term. That distance is `|‖Πf‖² − E_t ‖Πf_t‖²| / N` for the periodized `f_P`
/// ([`super::fourier::dual_lattice::strata_aliasing`]), and `f` differs from `f_P` by its images `E`,
/// which move either estimator's standard deviation by at most `E`; `None` where the bound is
/// above [`CLOSED_TAIL_SHARE`] of the value, or for another problem.
pub(super) fn jitter_by_aliasing(
    problem: &Problem<'_>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Option<Prediction>> {
    let (f, n) = (problem.integrand, problem.n);
    let (Some(decay), Some(grid)) = (
        f.smooth_decay(),
        jitter_strata_beyond_table(problem, params),
    ) else {
        return Ok(None);
    };
    let shifted = Problem {
        randomization: Randomization::Shift,
        ..*problem
    };
    let mut p = super::predict_planned(&shifted, params, progress)?;
    let images = decay.images;
    let spread = 2.0 * p.variance.sqrt() * images + images * images;
    let model =
        super::fourier::dual_lattice::strata_aliasing(&decay, &grid) / n as f64 + 2.0 * spread;
    if model > CLOSED_TAIL_SHARE * p.variance {
        return Ok(None);
    }
    p.budget.model += model;
    p.randomization = Randomization::None;
    p.reason = format!(
        "jitter as drawn ({} strata) on a smooth integrand: the shifted estimator's variance, \
         which differs from the unshifted one only through the pairs of frequencies k, k + mℓ \
         of the strata's replicas, bounded by the integrand's Gaussian decay, and its images \
         across the faces (the model term); the shifted one by {}",
        grid.iter()
            .map(|m| m.to_string())
            .collect::<Vec<_>>()
            .join(" × "),
        p.reason
    );
    Ok(Some(p))
}

/// The lattice form of a rank-1 lattice or a regular grid summed over its dual lattice, for a
/// smooth integrand contained in the cube ([`Integrand::smooth_decay`]); `None` otherwise.
fn over_dual_lattice(
    f: &dyn Integrand,
    n: usize,
    closed: ClosedForm,
    name: &str,
) -> Option<Prediction> {
    let d = f.dimension();
    let dual = match closed {
        ClosedForm::RegularGrid => crate::sampler::strata(n, d)
            .and_then(|cells| super::fourier::dual_lattice::grid_dual_variance(f, &cells)),
        ClosedForm::Rank1Lattice { generator } => {
            super::fourier::dual_lattice::rank1_dual_variance(f, n, generator)
        }
        _ => None,
    }?;
    let reason = format!(
        "{name} at N = {n} has power N on its dual lattice and 0 elsewhere: the lattice form \
         summed over the dual lattice within |k_i| ≤ {}, in positive terms (the sum in space \
         subtracts two numbers equal to within the variance), the vectors beyond bounded by \
         the integrand's Gaussian decay, and its images across the faces as the model term",
        dual.kmax
    );
    let mut p = in_space(f, n, closed, (dual.variance, dual.rounding), reason);
    p.budget.truncation = dual.truncation;
    p.budget.model = dual.model;
    p.evaluations = 0;
    Some(p)
}

/// A lattice form's prediction from its value and rounding bound.
fn in_space(
    f: &dyn Integrand,
    n: usize,
    closed: ClosedForm,
    (value, rounding): (f64, f64),
    reason: String,
) -> Prediction {
    Prediction {
        randomization: crate::randomization::Randomization::Shift,
        variance: value,
        route: Route {
            form: Form::Lattice,
            spectrum: SpectrumOrigin::Closed(closed),
        },
        reason,
        budget: ErrorBudget {
            tabulation: 0.0,
            quadrature: rounding,
            ..Default::default()
        },
        n,
        dimension: f.dimension(),
        dc_term: 0.0,
        evaluations: n as u64,
        alternatives: Vec::new(),
        analysis: None,
    }
}

/// The polar form with a closed form's radial mean.
pub(super) fn closed_polar(
    problem: &Problem<'_>,
    closed: ClosedForm,
    kind: Option<SamplerKind>,
    params: &PredictParams,
) -> Result<Prediction> {
    let (n, d) = (problem.n, problem.dimension());
    if !closed.is_scale_invariant()
        || (closed == ClosedForm::Jitter && perfect_root(n, d).is_none())
    {
        return Err(Error::OutsideValidity {
            route: "the polar form".into(),
            reason: format!(
                "the closed form ({}) at N = {n} is not a function of ν alone (strata {:?}); use \
                 the lattice form",
                closed.name(),
                strata(n, d)
            ),
        });
    }
    let model = polar_validity(problem.integrand, correlation_range(kind, n, d), n)?;
    let p = predict_polar(
        problem.integrand,
        &SpectrumSource::Closed(closed),
        n,
        &params.polar,
    )?;
    let p = with_model(p, model)?;
    Ok(with_reason(
        p,
        format!(
            "the closed form's radial mean ({}); the integrand is isotropic, contained, and its \
             autocorrelation fits in the torus",
            closed.name()
        ),
    ))
}

/// The polar form with a spectrum estimated at a reference N and rescaled.
pub(super) fn rescaled_polar(
    problem: &Problem<'_>,
    kind: Option<SamplerKind>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let (n, d) = (problem.n, problem.dimension());
    let Patterns::Sampler(sampler) = problem.patterns else {
        return Err(Error::OutsideValidity {
            route: "the polar form with a rescaled spectrum".into(),
            reason: "given point sets have one N; their spectrum is read at that N by the \
                     lattice form"
                .into(),
        });
    };
    let n_ref = params
        .reference_n
        .unwrap_or_else(|| default_reference_n(d).max(n));
    let invariant = |m| kind.is_some_and(|k| k.is_scale_invariant_at(m, d));
    if !invariant(n) || !invariant(n_ref) {
        return Err(Error::OutsideValidity {
            route: format!("a spectrum rescaled from N = {n_ref}"),
            reason: format!(
                "{} is not scale invariant at N = {n} and N = {n_ref} (its spectrum is not one \
                 function of ν there); use the lattice form with the spectrum at N",
                sampler.name()
            ),
        });
    }
    if n > n_ref {
        return Err(Error::OutsideValidity {
            route: format!("a spectrum rescaled from N = {n_ref}"),
            reason: format!(
                "N = {n} needs the spectrum below the estimate's first ring (ν = N_ref^(-1/d)); \
                 estimate at a reference N of at least {n}"
            ),
        });
    }
    let model = polar_validity(problem.integrand, correlation_range(kind, n, d), n)?;
    sampler.check_count(n_ref)?;
    let spectrum = SpectrumParams {
        kmax: default_kmax(n_ref, d),
        realizations: params
            .realizations
            .unwrap_or(kind.map_or(INITIAL_REALIZATIONS, |k| {
                k.spectrum_realizations(INITIAL_REALIZATIONS)
            })),
        seed: params.seed,
        engine: Engine::Auto,
        bin_width: 1.0,
        budget: params.budget,
    };
    let label = format!("spectrum of {} at N = {n_ref}", sampler.name());
    let est = stage(progress, &label, 0, || estimate(sampler, n_ref, &spectrum))?;
    let p = predict_polar(
        problem.integrand,
        &SpectrumSource::Estimated(&est),
        n,
        &params.polar,
    )?;
    let p = with_model(p, model)?;
    Ok(with_reason(
        p,
        format!(
            "the radial spectrum of {} estimated at N = {n_ref} and read at ν = ρ/N^(1/d): the \
             sampler is scale invariant there, the integrand isotropic and contained",
            sampler.name()
        ),
    ))
}

/// The lattice form with the spectrum estimated at N, pattern by pattern.
pub(super) fn estimated_lattice(
    problem: &Problem<'_>,
    kind: Option<SamplerKind>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let mut all = estimated_lattice_many(&[problem], kind, params, progress)?;
    all.pop()
        .ok_or_else(|| Error::Mismatch("no prediction for one problem".into()))
}

/// The lattice form with the spectrum estimated at N, pattern by pattern, for problems that
/// share their patterns: each lattice size's realizations serve every integrand that needs
/// that size (their weighted sums accumulated together), and a lattice is doubled only for the
/// integrands whose tail is still above [`ESTIMATED_TAIL_SHARE`] of their variance.
pub(super) fn estimated_lattice_many(
    problems: &[&Problem<'_>],
    kind: Option<SamplerKind>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Vec<Prediction>> {
    let Some(first) = problems.first() else {
        return Ok(Vec::new());
    };
    let (n, d) = (first.n, first.dimension());
    let (source, what) = match first.patterns {
        Patterns::Sampler(sampler) => (
            PatternSource::Sampler {
                sampler,
                n,
                seed: params.seed,
            },
            sampler.name().to_string(),
        ),
        Patterns::PointSets(sets) => (
            PatternSource::Sets(sets),
            format!("{} given point sets", sets.len()),
        ),
    };
    let initial = match source {
        PatternSource::Sets(sets) => sets.len(),
        PatternSource::Sampler { .. } => params.realizations.unwrap_or(INITIAL_REALIZATIONS),
    };
    let plan = |kmax| PatternPlan {
        initial,
        target_noise: params.target_noise,
        max_realizations: params
            .realizations
            .unwrap_or_else(|| affordable_realizations(kind, n, lattice(d, kmax), params)),
        spectrum: SpectrumParams {
            kmax,
            realizations: initial,
            seed: params.seed,
            engine: Engine::Auto,
            bin_width: 1.0,
            budget: params.budget,
        },
        symmetric: kind.is_some_and(|k| k.is_symmetric_at(n, d)),
        low_band: match source {
            PatternSource::Sampler { .. } => kind.and_then(|k| LowBand::for_sampler(k, n, d)),
            PatternSource::Sets(_) => None,
        },
    };
    let mut done: Vec<Option<Prediction>> = vec![None; problems.len()];
    let mut tail_tried = vec![false; problems.len()];
    // Whether a first look at the initial patterns can be cheaper than the full estimate: the
    // tail may be measured, and the realizations are not fixed.
    let may_probe = may_measure_tail(kind, params)
        && params.realizations.is_none()
        && matches!(source, PatternSource::Sampler { .. });
    // Lattice sizes still to estimate, each with the problems that need it.
    let mut queue = std::collections::BTreeMap::new();
    let first_kmax = params
        .kmax
        .unwrap_or_else(|| initial_kmax(n, d, 6.0, ESTIMATED_LATTICE_BUDGET));
    queue.insert(first_kmax, (0..problems.len()).collect::<Vec<usize>>());
    // A problem's estimate on a lattice is its answer, or it goes to the wider lattice its tail
    // asks for.
    let settle = |p: Prediction,
                  i: usize,
                  kmax: usize,
                  done: &mut Vec<Option<Prediction>>,
                  queue: &mut std::collections::BTreeMap<usize, Vec<usize>>| {
        match wider_lattice(&p, kmax, d, params) {
            Some(wider) => queue.entry(wider).or_default().push(i),
            None => done[i] = Some(p),
        }
    };
    while let Some((kmax, group)) = queue.pop_first() {
        // Where the first lattice left too much beyond it (an integrand that jumps, whose tail
        // falls slowly) and a pattern's pairs cost less than its transform on the wider one,
        // each pattern is summed in space instead: exact, with nothing to truncate. (On the
        // first lattice a smooth integrand's few frequencies are the cheaper route.)
        let mut on_lattice = Vec::new();
        for i in group {
            let paired = (kmax > first_kmax)
                .then(|| cheaper_pairs(problems[i], lattice(d, kmax), params))
                .flatten();
            match paired {
                Some(sampler) => {
                    let f = problems[i].integrand;
                    done[i] = Some(patterns_in_space(f, sampler, n, params, progress)?);
                }
                None => on_lattice.push(i),
            }
        }
        let group = on_lattice;
        if group.is_empty() {
            continue;
        }
        let powers = group
            .iter()
            .map(|&i| {
                LatticePower::of_within(problems[i].integrand, lattice(d, kmax), &params.budget)
            })
            .collect::<Result<Vec<_>>>()?;
        // A first look from the initial patterns alone decides whether to measure the tail;
        // the problems it does not settle are estimated in full on the same patterns after,
        // the first look's realizations kept.
        let probing = may_probe && group.iter().any(|&i| !tail_tried[i]);
        let mut estimate = PatternEstimate::new(&powers, source, &plan(kmax))?;
        if probing {
            estimate.limit_to(initial);
        }
        let everyone: Vec<usize> = (0..group.len()).collect();
        estimate.extend(&everyone, progress)?;
        let asked = params.spectrum == SpectrumChoice::Estimated;
        let mut unsettled = Vec::new();
        for (at, p) in estimate.predictions(&everyone)?.into_iter().enumerate() {
            let i = group[at];
            let p = estimated_reason(p, (kind, asked), &what, n, kmax);
            // A measured tail needs no wider lattice: it replaces the widening where the
            // budget allows it and its budget is the narrower (tried once per problem: its
            // lattice does not follow the widening).
            if !tail_tried[i] && needs_measured_tail(&p, kind, params) {
                tail_tried[i] = true;
                let why = why_estimated((kind, asked), &what, n);
                let tail = MeasuredTail { source, kmax, why };
                if let Some(m) =
                    with_measured_tail(problems[i].integrand, &tail, (&p, kind), params, progress)?
                {
                    done[i] = Some(m);
                    continue;
                }
            }
            if probing {
                tail_tried[i] = true;
                unsettled.push(at);
            } else {
                settle(p, i, kmax, &mut done, &mut queue);
            }
        }
        if !unsettled.is_empty() {
            estimate.lift_limit();
            estimate.extend(&unsettled, progress)?;
            for (&at, p) in unsettled.iter().zip(estimate.predictions(&unsettled)?) {
                let p = estimated_reason(p, (kind, asked), &what, n, kmax);
                settle(p, group[at], kmax, &mut done, &mut queue);
            }
        }
    }
    done.into_iter()
        .map(|p| p.ok_or_else(|| Error::Mismatch("a problem left unpredicted".into())))
        .collect()
}

/// The lattice to estimate `p` again on if its tail bound is above [`ESTIMATED_TAIL_SHARE`] of
/// its variance and a wider lattice fits: the tail of an integrand with a jump falls like
/// `1/K`, so the factor by which the bound is too large, rounded up to a power of 2, says how
/// much wider (at least twice, at most what the lattice budget allows).
fn wider_lattice(p: &Prediction, kmax: usize, d: usize, params: &PredictParams) -> Option<usize> {
    let excess = p.budget.truncation / (ESTIMATED_TAIL_SHARE * p.variance);
    let fits = |k: usize| lattice(d, k).len() <= ESTIMATED_LATTICE_BUDGET;
    let within = excess.is_nan() || excess <= 1.0;
    if params.kmax.is_some() || within || !fits(2 * kmax) {
        return None;
    }
    let mut wider = kmax << excess.log2().ceil().clamp(1.0, 16.0) as u32;
    while !fits(wider) {
        wider /= 2;
    }
    Some(wider)
}

/// Whether the white-tail bound of `p` is above [`ESTIMATED_TAIL_SHARE`] of its variance, no
/// lattice was asked for, and the sampler's patterns are cheap enough to measure the tail on
/// (not CCVT or Gaussian blue noise, whose few affordable patterns leave a measured tail
/// noisier than their bound, and whose spectra do settle to white): the tail is then measured
/// ([`with_measured_tail`]).
fn needs_measured_tail(p: &Prediction, kind: Option<SamplerKind>, params: &PredictParams) -> bool {
    may_measure_tail(kind, params) && p.budget.truncation > ESTIMATED_TAIL_SHARE * p.variance
}

/// Whether the tail may be measured at all: no lattice asked for, and patterns cheap enough.
fn may_measure_tail(kind: Option<SamplerKind>, params: &PredictParams) -> bool {
    params.kmax.is_none() && !kind.is_some_and(|k| k.is_costly())
}

/// A lattice form whose tail is to be measured: the patterns, the lattice extent, and why the
/// spectrum is estimated.
struct MeasuredTail<'a> {
    source: PatternSource<'a>,
    kmax: usize,
    why: String,
}

/// The lattice form with the energy beyond it measured at shifts of each pattern, `white`
/// (the lattice form with the white-tail bound) as its alternative; `None` where the
/// measurement would exceed the budget or its 99% budget is not the narrower (the white-tail
/// form is then widened as before), and, for a stationary sampler, untried where its least
/// half-width ([`least_half_width`](super::fourier::measured_tail::least_half_width)) is already the
/// wider.
fn with_measured_tail(
    f: &dyn Integrand,
    tail: &MeasuredTail<'_>,
    (white, kind): (&Prediction, Option<SamplerKind>),
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Option<Prediction>> {
    let width = |p: &Prediction| p.budget.half_width(crate::montecarlo::Z_99);
    // A stationary sampler's measured tail is not tried where the spread of its lattice
    // parts alone, the raw lattice form's, would leave it the wider.
    if kind.is_some_and(|k| k.facts().randomness.is_stationary()) {
        let raw = raw_lattice_noise(white);
        let least =
            super::fourier::measured_tail::least_half_width(tail.source, tail.kmax, params, raw);
        match least {
            Err(Error::TooLarge { .. }) => return Ok(None),
            Ok(Some(least)) if least >= width(white) => return Ok(None),
            other => {
                other?;
            }
        }
    }
    let measured = super::fourier::measured_tail::predict_measured_tail(
        f,
        tail.source,
        tail.kmax,
        params,
        progress,
    );
    let mut p = match measured {
        Err(Error::TooLarge { .. }) => return Ok(None),
        other => other?,
    };
    let SpectrumOrigin::MeasuredTail { kmax, .. } = p.route.spectrum else {
        return Err(Error::Mismatch("a measured tail of another origin".into()));
    };
    p.reason = format!(
        "{}: the lattice form on |k_i| ≤ {kmax}, each pattern's own transform there; beyond it, \
         where the white-tail bound is {:.0}% of the variance, the energy is measured rather \
         than the lattice widened: each pattern's variance under the shift is its lattice part \
         plus the mean square, at {} uniform shifts, of its error less that part (the modes are \
         orthogonal over shifts, so this is unbiased and nothing is modelled beyond the \
         lattice); noise from the patterns' spread",
        tail.why,
        100.0 * white.budget.truncation / white.variance,
        super::fourier::measured_tail::SHIFTS_PER_PATTERN,
    );
    if width(&p) >= width(white) {
        return Ok(None);
    }
    p.alternatives.push(white.as_alternative());
    Ok(Some(p))
}

/// The standard error of the raw per-pattern sums behind an estimated lattice form, and their
/// realizations: its own, or those of the raw sums beside a fitted low band.
fn raw_lattice_noise(p: &Prediction) -> (f64, usize) {
    let raw = |origin: &SpectrumOrigin| match origin {
        SpectrumOrigin::Estimated {
            realizations,
            low_band: None,
            ..
        } => Some(*realizations),
        _ => None,
    };
    if let Some(r) = raw(&p.route.spectrum) {
        return (p.budget.spectrum_noise, r);
    }
    p.alternatives
        .iter()
        .find_map(|a| raw(&a.route.spectrum).map(|r| (a.budget.spectrum_noise, r)))
        .unwrap_or((0.0, 0))
}

/// Why a spectrum is estimated: no closed form is known, or an estimate was asked for.
fn why_estimated((kind, asked): (Option<SamplerKind>, bool), what: &str, n: usize) -> String {
    match kind {
        None => format!("{what}: no closed form is known"),
        Some(k) if asked => format!("the estimated spectrum of {k} was asked for"),
        Some(k) => format!("{k} has no closed form at N = {n}"),
    }
}

fn estimated_reason(
    p: Prediction,
    (kind, asked): (Option<SamplerKind>, bool),
    what: &str,
    n: usize,
    kmax: usize,
) -> Prediction {
    let realizations = match p.route.spectrum {
        SpectrumOrigin::Estimated { realizations, .. } => realizations,
        SpectrumOrigin::MeasuredTail { patterns, .. } => patterns,
        SpectrumOrigin::Closed(_)
        | SpectrumOrigin::Cells(_)
        | SpectrumOrigin::Walsh(_)
        | SpectrumOrigin::WalshNet(_)
        | SpectrumOrigin::PermutedDigits(_)
        | SpectrumOrigin::PermutedLevel(_)
        | SpectrumOrigin::Pairs { .. }
        | SpectrumOrigin::PatternPairs { .. } => 0,
    };
    let why = why_estimated((kind, asked), what, n);
    let low_band = match p.route.spectrum {
        SpectrumOrigin::Estimated {
            low_band: Some(radius),
            ..
        } => format!(
            "; the low band |k| ≤ {radius:.1} read from a fit of each pattern's periodogram \
             linear in |k|² (the sampler's law is stationary and isotropic, its spectrum smooth \
             there), its model term the mean change a quadratic fit makes plus that change's \
             paired noise at 99%, and its mean departure from the raw sums within that \
             departure's paired noise at 99%"
        ),
        _ => String::new(),
    };
    with_reason(
        p,
        format!(
            "{why}: the lattice form with the spectrum of {realizations} patterns at N = {n}, \
             pattern by pattern, on |k_i| ≤ {kmax}{low_band}; noise from the patterns' spread, \
             tail bounded by the spectrum's deviation from white at the lattice's edge"
        ),
    )
}

/// What a closed form's lattice needs at most: [`CLOSED_LATTICE_BUDGET`] coefficients.
pub(super) fn closed_lattice_needs() -> Needs {
    let len = CLOSED_LATTICE_BUDGET as f64;
    Needs {
        memory_bytes: 8.0 * len,
        work_seconds: len * crate::costs::COEFFICIENT_SECONDS,
    }
}

/// What the closed-form routes of `problem` need first: the sums in space one autocorrelation
/// value per point or lag (their peaks continue beyond any lattice). White noise needs nothing,
/// and the lattice forms nothing before their first lattice, which checks its own size and
/// gives way to the polar form (whose work does not grow with N) where it is too large.
pub(super) fn closed_form_needs(problem: &Problem<'_>, closed: ClosedForm) -> Needs {
    let n = problem.n as f64;
    match closed {
        ClosedForm::RegularGrid
        | ClosedForm::Rank1Lattice { .. }
        | ClosedForm::Kronecker { .. } => Needs {
            memory_bytes: 8.0 * n,
            work_seconds: n * autocorrelation_seconds(problem.integrand),
        },
        _ => Needs::default(),
    }
}

/// What the first pass of a per-pattern lattice estimate needs: its initial patterns, drawn
/// and transformed on the initial lattice one at a time.
pub(super) fn estimated_lattice_needs(problem: &Problem<'_>) -> Needs {
    let (n, d) = (problem.n, problem.dimension());
    let lattice = lattice(d, initial_kmax(n, d, 6.0, ESTIMATED_LATTICE_BUDGET));
    let cells = (2.0 * lattice.side() as f64).powi(d as i32);
    let transform = Needs {
        // The oversampled grid of complex values and the lattice's weights.
        memory_bytes: 16.0 * cells + 8.0 * lattice.len() as f64,
        work_seconds: crate::costs::TRANSFORM_CELL_SECONDS * cells,
    };
    let (count, draw) = match (problem.patterns, problem.kind()) {
        (Patterns::PointSets(sets), _) => (sets.len(), Needs::default()),
        (_, Some(k)) => (
            k.spectrum_realizations(INITIAL_REALIZATIONS),
            k.pattern_needs(n, d),
        ),
        // A sampler of one's own: its cost is unknown; a microsecond a point.
        (_, None) => (
            INITIAL_REALIZATIONS,
            Needs {
                memory_bytes: 8.0 * (n * d) as f64,
                work_seconds: 1e-6 * n as f64,
            },
        ),
    };
    let one = draw.and(transform);
    Needs {
        memory_bytes: one.memory_bytes,
        work_seconds: one.work_seconds * count as f64,
    }
}

/// What the polar form's estimate at its reference N needs first.
pub(super) fn rescaled_polar_needs(problem: &Problem<'_>, params: &PredictParams) -> Needs {
    let d = problem.dimension();
    let n_ref = params
        .reference_n
        .unwrap_or_else(|| default_reference_n(d).max(problem.n));
    let realizations = params.realizations.unwrap_or(INITIAL_REALIZATIONS);
    problem.kind().map_or(Needs::default(), |k| {
        let one = k.pattern_needs(n_ref, d);
        Needs {
            memory_bytes: one.memory_bytes,
            work_seconds: one.work_seconds * realizations as f64,
        }
    })
}

/// How many realizations the work budget pays for: drawing each pattern (the sampler's measured
/// cost per point) and transforming it (about 30 ns per cell of the oversampled grid).
fn affordable_realizations(
    kind: Option<SamplerKind>,
    n: usize,
    lattice: Lattice,
    params: &PredictParams,
) -> usize {
    let draw = n as f64 * kind.map_or(1_000.0, |k| k.cost_per_point_ns_at(n, lattice.dimension));
    let transform = crate::costs::TRANSFORM_CELL_SECONDS
        * 1e9
        * (2.0 * lattice.side() as f64).powi(lattice.dimension as i32);
    let affordable = params.work_budget_seconds * 1e9 / (draw + transform);
    (affordable as usize).clamp(INITIAL_REALIZATIONS, MAX_REALIZATIONS)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::Ball;
    use crate::montecarlo::Z_99;
    use crate::progress::Silent;
    use crate::sampler::Jitter;

    /// The patterns summed in space estimate the mean of exact per-pattern variances; their
    /// noise term must cover the truth at its nominal rate. Jitter under a shift has that truth
    /// in closed form: 40 independent estimates of the disk's variance at N = 64 against it. At
    /// 99% about 0.4 misses are expected; P(3 or more) = 0.8%.
    #[test]
    fn patterns_in_space_cover_the_exact_value_at_their_nominal_rate() {
        let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
        let jitter = Jitter::new(2).unwrap();
        let problem = Problem::new(&jitter, &disk, 64)
            .unwrap()
            .with_randomization(Randomization::Shift);
        let exact = super::super::predict(&problem, &PredictParams::default()).unwrap();
        assert_eq!(exact.budget.spectrum_noise, 0.0, "{}", exact.route);
        let misses = (0..40)
            .filter(|&seed| {
                let params = PredictParams {
                    seed,
                    ..Default::default()
                };
                let p = patterns_in_space(&disk, &jitter, 64, &params, &Silent).unwrap();
                assert!(matches!(
                    p.route.spectrum,
                    SpectrumOrigin::PatternPairs { .. }
                ));
                !p.covers(exact.variance, Z_99)
            })
            .count();
        assert!(misses <= 2, "{misses} of 40 budgets miss the exact value");
    }
}
