//! The randomly shifted estimator of a sampler with cells (multi-jitter, CMJ, orthogonal
//! arrays, PMJ02): the cell form of each pattern on the shifted integrand, averaged over
//! patterns and shifts.
//!
//! With `x_j` a pattern whose points are independent and uniform in their cells once the cells
//! are known, and `t` an independent uniform shift, `μ = (1/N) Σ_j f(x_j + t mod 1)`. The
//! sampler is unbiased (its points' mean density is uniform), so `E[μ | t] = I` for every `t`,
//! and given the pattern's cells and `t` the error has the exact conditional second moment
//!
//! `(1/N²) Σ_j V_{c_j}(f_t) + (M_t − I)²`, `M_t = (1/N) Σ_j F_{c_j}(f_t)`,
//!
//! with `F_c(f_t)`, `V_c(f_t)` the mean and inner variance of the shifted integrand over cell
//! `c` (a box wrapped across the faces: up to `2^d` boxes of the cube). The variance is the
//! mean of these terms over independent (pattern, shift) pairs: unbiased, its standard error
//! from their spread, nothing truncated. The lattice form of the same estimator counts the
//! energy beyond its lattice as white, while these samplers' spectra along the axes are far
//! below white (their projections are stratified), which overestimates integrands that jump
//! across the faces, more so as N grows (`docs/theory.md`, "Strata under a shift").
//!
//! CMJ on a separable integrand needs no patterns: each shift's variance is exact (its pairs
//! in closed form on the shifted integrand's rows of cells), and only the mean over shifts is
//! estimated ([`predict_shifted_shuffles`]).

use super::cell_moments::{check_box_moments, shifted_cell_mean_and_variance};
use super::cells::{cell_of, CellOrigin, Occupancy};
use crate::budget::Needs;
use crate::costs::CELL_SECONDS;
use crate::costs::SEPARABLE_CELL_SECONDS;
use crate::error::{Error, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::predict::digits::shifted_gains::{mean_over_shifts, shifted_prediction};
use crate::predict::term_mean::{mean_to_target_noise, terms_within_budget};
use crate::predict::{PredictParams, Prediction};
use crate::progress::Progress;
use crate::quadrature::CompensatedSum;
use crate::randomization::toroidal_shift;
use crate::sampler::{CellLaw, Sampler, SamplerKind};

/// (Pattern, shift) pairs the average starts with.
const INITIAL_PAIRS: usize = 64;
/// Pairs the average never exceeds.
const MAX_PAIRS: usize = 1 << 16;

/// One pair's exact conditional second moment of the error.
fn pair_term(f: &dyn Integrand, pattern: &PointSet, grid: &[usize], t: &[f64]) -> f64 {
    let nf = pattern.len() as f64;
    let integral = f.integral();
    let (mut deviation, mut within) = (CompensatedSum::default(), CompensatedSum::default());
    for x in pattern.points() {
        let (m, v) = shifted_cell_mean_and_variance(f, grid, cell_of(x, grid), t);
        deviation.add(m - integral);
        within.add(v);
    }
    let m = deviation.value() / nf;
    within.value() / (nf * nf) + m * m
}

/// The randomly shifted variance of `sampler` (of kind `kind`, whose cells at `n` are `grid`)
/// on `f`: the mean over independent patterns and shifts of each pair's exact conditional
/// second moment, pairs added until the relative standard error reaches `params.target_noise`
/// or the work budget ends.
///
/// # Errors
/// An integrand without moments over boxes, a sampler error, or work beyond the budget.
pub(crate) fn predict_shifted_cells(
    f: &dyn Integrand,
    (sampler, kind): (&dyn Sampler, SamplerKind),
    grid: &[usize],
    n: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    check_box_moments(f)?;
    let d = f.dimension();
    if grid.len() != d {
        return Err(Error::Mismatch(format!(
            "cells of dimension {} for an integrand of dimension {d}",
            grid.len()
        )));
    }
    // Each point's cell wrapped across the faces: up to 2^d boxes' moments.
    let per_pair =
        n as f64 * (kind.cost_per_point_ns_at(n, d) * 1e-9 + CELL_SECONDS * (1u32 << d) as f64);
    let (initial, max) = terms_within_budget(params, per_pair, (INITIAL_PAIRS, MAX_PAIRS));
    params.budget.check(
        "the occupancy estimate under shifts",
        Needs {
            memory_bytes: 8.0 * max as f64 + 16.0 * n as f64 * d as f64,
            work_seconds: initial as f64 * per_pair,
        },
        "lower N or the realizations",
    )?;
    let estimate = mean_to_target_noise(
        "occupancy of the cells under shifts",
        (initial.max(2), max.max(2)),
        params.target_noise,
        0.0,
        |i| {
            let pattern = sampler.sample(n, params.seed, i as u64)?;
            let t = toroidal_shift(d, params.seed, i as u64);
            Ok(pair_term(f, &pattern, grid, &t[..d]))
        },
        progress,
    )?;
    let strata = crate::predict::grid_label(grid);
    let reason = format!(
        "{}, randomly shifted: its points are independent and uniform in the cells of the \
         {strata} grid once their cells are known, so each pattern under each shift has its \
         error's exact second moment from the shifted integrand's cells (wrapped across the \
         faces), and the variance is their mean over {} independent patterns and shifts \
         (unbiased; the noise is its standard error; nothing is truncated, so jumps at the faces \
         cost nothing extra)",
        sampler.name(),
        estimate.patterns
    );
    let origin = CellOrigin {
        cells_per_axis: grid.iter().copied().max().unwrap_or(1),
        cells: grid.iter().product(),
        occupancy: Occupancy::EstimatedOverShifts {
            patterns: estimate.patterns,
        },
    };
    let evaluations = (estimate.patterns * n) as u64;
    Ok(shifted_prediction(
        &estimate,
        origin,
        reason,
        (n, d),
        evaluations,
    ))
}

/// Shifts the exact average of the multi-jittered samplers starts with.
const INITIAL_SHIFTS: usize = 16;
/// Shifts it never exceeds.
const MAX_SHIFTS: usize = 1 << 14;

/// Whether CMJ (or an orthogonal array, which in 2D is CMJ on p × p cells) on `f` is predicted
/// under a shift by its exact variance at each shift: a product of functions of one coordinate
/// each, in 2D. Multi-jitter has the same closed form per
/// shift, but its variance spreads over shifts (by about 36% of the mean on a Gaussian cut by
/// the faces, against CMJ's 0.6%), so that the lattice form with a measured tail costs less
/// per unit of noise (N = 65536: 1.7% in 1.9 s against 1.3% in 7.6 s).
pub(crate) fn shuffles_over_shifts(f: &dyn Integrand, kind: SamplerKind) -> bool {
    matches!(
        kind.facts().cell_law,
        CellLaw::CorrelatedShuffles | CellLaw::OrthogonalArray
    ) && f.dimension() == 2
        && f.shifted_separable_cells(&[1, 1], &[0.0, 0.0]).is_some()
}

/// The randomly shifted variance of multi-jitter or CMJ (`kind`) at `n` points on a separable
/// `f`: every shift's variance exact (the pairs of the N-rooks permutations in closed form on
/// the shifted integrand's rows of cells, `O(N)`), averaged over independent uniform shifts
/// until the relative standard error reaches `params.target_noise` or the work budget ends.
///
/// # Errors
/// An integrand that is not separable, or work beyond the budget.
pub(crate) fn predict_shifted_shuffles(
    f: &dyn Integrand,
    kind: SamplerKind,
    n: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let d = f.dimension();
    // Two rows per axis, each cell up to two pieces.
    let per_shift = 8.0 * n as f64 * SEPARABLE_CELL_SECONDS;
    params.budget.check(
        "the multi-jittered samplers' rows over shifts",
        Needs {
            memory_bytes: 64.0 * n as f64,
            work_seconds: INITIAL_SHIFTS as f64 * per_shift,
        },
        "lower N",
    )?;
    let estimate = mean_over_shifts(
        "exact variances over shifts",
        (d, params),
        per_shift,
        (INITIAL_SHIFTS, MAX_SHIFTS),
        |t| {
            super::cell_pairs::shifted_shuffles_variance(f, kind, n, t).ok_or_else(|| {
                Error::Mismatch(format!(
                    "{} is not a product of one-axis factors",
                    f.label()
                ))
            })
        },
        progress,
    )?;
    let alias = match kind.facts().cell_law {
        CellLaw::OrthogonalArray => " (in 2D an orthogonal array is CMJ on p × p cells)",
        _ => "",
    };
    let reason = format!(
        "{kind}, randomly shifted{alias}: each shift of the integrand has its exact variance (the \
         N-rooks permutations' pairs of cells in closed form, from one row of cells per axis of \
         the shifted product), and the variance is their mean over {} independent uniform \
         shifts (unbiased; the noise is its standard error; nothing is truncated, so jumps at \
         the faces cost nothing extra)",
        estimate.patterns
    );
    let origin = CellOrigin {
        cells_per_axis: n,
        cells: 2 * n,
        occupancy: Occupancy::PermutationsOverShifts {
            shifts: estimate.patterns,
        },
    };
    let mut p = shifted_prediction(
        &estimate,
        origin,
        reason,
        (n, d),
        (2 * n * estimate.patterns) as u64,
    );
    p.budget.quadrature = estimate.rounding;
    Ok(p)
}
