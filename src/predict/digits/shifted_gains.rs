//! The randomly shifted estimator of an Owen-scrambled net: Owen's gains averaged over shifts.
//!
//! With `x_j` a nested uniform scrambling of a base-2 net and `t` an independent uniform shift,
//! `μ = (1/N) Σ_j f(x_j + t mod 1)`. Each scrambled point is uniform, so `E[μ | t] = I` for
//! every `t`, and the variance is the mean over shifts of the scrambled net's variance on the
//! shifted integrand `f_t(x) = f(x + t mod 1)`:
//!
//! `Var μ = E_t Var[μ | t] = E_t (1/N) [(∫f² − I²) + Σ_{k∈K} (Γ_k − 1) σ²_k(f_t)]`,
//!
//! where the gains `Γ_k` belong to the net alone and each `σ²_k(f_t)` is exact
//! ([`super::owen_gains`]). Only the average over `t` is estimated, from independent uniform
//! shifts: every term is an exact conditional variance (nothing truncated, no Fourier series),
//! so the estimate is unbiased and its standard error, from the terms' spread, is its whole
//! uncertainty. The lattice form of the same estimator counts the energy beyond its lattice as
//! white, while a net's spectrum along the axes is far below white (its one-dimensional
//! projections are stratified): it overestimates integrands that jump across the cube's faces,
//! more so as N grows (`docs/theory.md`, "Scrambled nets under a shift").

use super::owen_gains::ScrambledNet;
use crate::error::Result;
use crate::integrand::Integrand;
use crate::predict::strata::cell_moments::CellSum;
use crate::predict::strata::cell_moments::{check_box_moments, seconds_per_grid_cell};
use crate::predict::strata::cells::{CellOrigin, Occupancy};
use crate::predict::term_mean::{mean_of_exact_terms, terms_within_budget, OccupancyEstimate};
use crate::predict::{ErrorBudget, Form, PredictParams, Prediction, Route, SpectrumOrigin};
use crate::progress::Progress;
use crate::randomization::{toroidal_shift, Randomization};
use crate::sampler::{CellLaw, CellRule, Sampler};

/// Shifts the average starts with: enough for the spread that decides how many more it needs.
const INITIAL_SHIFTS: usize = 16;
/// Shifts the average never exceeds.
const MAX_SHIFTS: usize = 4096;

/// The randomly shifted variance of `sampler`'s Owen-scrambled net at `n` points on `f`, the
/// mean of the exact scrambled variances of `f` under independent uniform shifts, shifts added
/// until the relative standard error reaches `params.target_noise` or the work budget ends.
///
/// # Errors
/// An integrand without moments over boxes or of more than 3 axes, a sampler error, or work
/// beyond the budget.
pub(crate) fn predict_shifted_net(
    f: &dyn Integrand,
    sampler: &dyn Sampler,
    n: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    check_box_moments(f)?;
    let d = f.dimension();
    // PMJ02 comes here at a power of two only, where every pattern is a (0,m,2)-net with the
    // pair counts of every such net: Sobol''s is drawn in a fraction of its time.
    let progressive = sampler
        .kind()
        .is_some_and(|k| k.facts().cell_law == CellLaw::ProgressiveNet);
    let pattern = if progressive {
        crate::sampler::Sobol::new(d)?.sample(n, params.seed, 0)?
    } else {
        sampler.sample(n, params.seed, 0)?
    };
    let cell_seconds = seconds_per_grid_cell(f);
    let net = ScrambledNet::new(&pattern, d, cell_seconds, &params.budget)?;
    let per_shift = net.cells as f64 * cell_seconds;
    let estimate = mean_over_shifts(
        "Owen's gains over shifts",
        (d, params),
        per_shift,
        (INITIAL_SHIFTS, MAX_SHIFTS),
        |t| net.variance(f, t),
        progress,
    )?;
    let whose = if progressive {
        " (every prefix of 2^m points is a (0,m,2)-net, whose pair counts the net property \
         fixes, and its law is unchanged by scrambling)"
    } else {
        ""
    };
    let reason = format!(
        "{}, randomly shifted{whose}: each shift of the integrand has its exact variance under \
         nested uniform scrambling by Owen's gains (the net's pair counts on dyadic grids times the \
         shifted integrand's variance at each dyadic level, from its cells' integrals or, for a \
         product of axis factors, level by level from each factor's masses), and the \
         variance is their mean over {} independent uniform shifts (unbiased; the noise is its \
         standard error; nothing is truncated, so jumps at the faces cost nothing extra)",
        sampler.name(),
        estimate.patterns
    );
    let origin = CellOrigin {
        cells_per_axis: CellRule::Dyadic
            .grid(n, d)
            .and_then(|g| g.into_iter().max())
            .unwrap_or(1),
        cells: net.cells,
        occupancy: Occupancy::GainsOverShifts {
            shifts: estimate.patterns,
        },
    };
    let evaluations = (net.cells * estimate.patterns) as u64;
    let mut p = shifted_prediction(&estimate, origin, reason, (n, d), evaluations);
    p.budget.quadrature = estimate.rounding;
    Ok(p)
}

/// The mean over independent uniform shifts `t` of an exact conditional variance `at(t)`
/// (with its rounding bound), shifts added from `counts.0` until the relative standard error
/// reaches `params.target_noise` or the work budget, at `per_shift` seconds each, ends: the
/// estimate, its rounding the largest rounding bound of a term.
///
/// # Errors
/// The first term's error.
pub(crate) fn mean_over_shifts(
    label: &str,
    (d, params): (usize, &PredictParams),
    per_shift: f64,
    counts: (usize, usize),
    at: impl Fn(&[f64]) -> Result<CellSum> + Sync,
    progress: &dyn Progress,
) -> Result<OccupancyEstimate> {
    let (initial, max) = terms_within_budget(params, per_shift, counts);
    mean_of_exact_terms(
        label,
        (initial.max(2), max.max(2)),
        params.target_noise,
        0.0,
        |i| at(&toroidal_shift(d, params.seed, i as u64)[..d]),
        progress,
    )
}

/// The prediction of a randomly shifted estimator whose variance is `estimate`, a mean of exact
/// conditional terms over shifts: the cell form, its noise the estimate's standard error and
/// no other term.
pub(crate) fn shifted_prediction(
    estimate: &OccupancyEstimate,
    origin: CellOrigin,
    reason: String,
    (n, d): (usize, usize),
    evaluations: u64,
) -> Prediction {
    Prediction {
        variance: estimate.variance,
        randomization: Randomization::Shift,
        route: Route {
            form: Form::Cells,
            spectrum: SpectrumOrigin::Cells(origin),
        },
        reason,
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise: estimate.standard_error,
            ..Default::default()
        },
        n,
        dimension: d,
        dc_term: 0.0,
        evaluations,
        alternatives: Vec::new(),
        analysis: None,
    }
}
