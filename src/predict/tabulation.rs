//! Grids that tabulate a finer function: a rendered pixel, an image of a scene, any function
//! known only through its values on cells. Every analysis predicts such a grid exactly *as a
//! piecewise-constant function*, and once the sampler resolves finer than the cells that is the
//! wrong function: a triangle tabulated on `64²` cells at `N = 1024` loses half of jitter's
//! variance and nearly all of an unscrambled net's.
//!
//! The prediction for the finer function comes from the grid itself. Its averages on cells
//! twice and four times as wide are the tabulations at those resolutions (cell averages of cell
//! averages), and the three predictions `V₀, V₁, V₂` at cell sides `h₀ < h₁ < h₂` converge to
//! the function's variance as `h → 0`. For bounded integrands with jumps (edges, shadows) the
//! gap falls like `h`: the energy the cells remove lies in the cells that the jumps cross,
//! `O(1/h)` cells of `O(h²)` each; smooth integrands converge faster. The prediction is the
//! linear extrapolation `R₀ = V₀ + (V₀ − V₁) h₀ / (h₁ − h₀)` (Richardson's, of the slowest
//! order), and the budget's tabulation term is the largest of the correction itself, the last
//! step between levels, and the gap between the extrapolations from the two finest and the two
//! coarsest levels, `t = max(|R₀ − V₀|, |V₀ − V₁|, |R₀ − R₁|)` (the first two agree where the
//! sides halve exactly): at order `h` exactly the correction is the whole gap and
//! `R₁ = R₀`; at higher orders the correction overshoots by less than itself; and where the
//! levels are not yet in their asymptotic regime the two extrapolations disagree by as much as
//! they are off.
//!
//! The extrapolation holds only where every level resolves what the sampler resolves, and it
//! is refused elsewhere, naming the resolution needed:
//! - the coarsest level must hold [`MIN_COARSE_CELLS_PER_SPACING`] cells per point spacing
//!   `N^{-1/2}` along each axis (independent points have no spacing and need no more than the
//!   three levels);
//! - for samplers whose every axis's projection is stratified into about `N` intervals
//!   (N-rooks, nets, radical inverses, lattices) and a tabulation that is smooth at its cells'
//!   scale ([`SMOOTH_RATIO`], [`SMOOTH_STEP_RATIO`]), the coarsest level must resolve those `N` intervals: the
//!   variance of a smooth integrand under such samplers comes from within the projections'
//!   intervals, which cells as wide as them hide from every level alike (correlated
//!   multi-jitter on a tabulated Gaussian: 55% of its variance at 1024 cells per axis with
//!   `N = 1024`, the levels agreeing to 1%);
//! - every level's prediction must be positive: a level that a net or a grid of strata
//!   integrates exactly says nothing of the function (independent points integrate none
//!   exactly; for them a level of variance 0 is a constant, and its variance is still the
//!   tabulation's).
//!
//! A grid that is the function itself ([`GridMeaning::Exact`]) keeps the exact prediction.

use super::{ErrorBudget, Prediction, Problem};
use crate::error::{Error, Result};
use crate::integrand::{GridIntegrand, Integrand};
use crate::sampler::{AxisStrata, CellRule};

/// The cells of the coarsest level per point spacing `N^{-1/2}` along each axis, at least:
/// two, so that the finest level holds 8 cells per spacing (64 cells per sample). On a
/// triangle tabulated at 16 cells per sample the levels of Poisson disk patterns (1 cell per
/// sample at the coarsest) were not yet monotone; at 64 every built-in sampler's levels fell
/// like the cells' size.
pub const MIN_COARSE_CELLS_PER_SPACING: f64 = 2.0;

/// The ratio of successive within-cell energies `w₁ / w₂` below which a tabulation is smooth at
/// its cells' scale: `2^{-3/2}`, the geometric mean of `1/2` (jumps: the energy the cells
/// remove halves with their side) and `1/4` (a smooth function: it falls as the side squared).
pub const SMOOTH_RATIO: f64 = 0.353_553_390_593_273_8;

/// The ratio of the largest steps between neighbouring cells at successive levels below which a
/// tabulation is smooth at its cells' scale: `2^{-1/2}`, the geometric mean of `1/2` (a smooth
/// function: the step falls with the side) and 1 (a jump keeps its height). With
/// [`SMOOTH_RATIO`], it keeps a binary image with small features (whose energies may fall
/// fast between two levels) from passing for smooth.
pub const SMOOTH_STEP_RATIO: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// The coarser averages of a tabulated grid that its prediction is extrapolated from.
pub(super) struct Levels {
    /// The averages on cells about twice and four times as wide.
    pub(super) coarser: [GridIntegrand; 2],
    /// The cell sides `h = 1/√(width · height)` of the grid and of each coarser level.
    sides: [f64; 3],
    /// The scale at which the patterns are structured.
    strata: AxisStrata,
    /// The grid's label, for refusals.
    label: String,
    /// The sizes, for the reason.
    sizes: [(usize, usize); 3],
}

/// The levels of `problem`'s integrand if it is a grid that tabulates a finer function and not
/// a constant; `None` for every other integrand.
///
/// # Errors
/// [`Error::TabulationTooCoarse`] where the grid is too coarse for the sampler at N, naming the
/// resolution needed.
pub(super) fn levels(problem: &Problem<'_>) -> Result<Option<Levels>> {
    let Some(grid) = problem.integrand.tabulation() else {
        return Ok(None);
    };
    if grid.is_constant() {
        return Ok(None);
    }
    let (w, h) = (grid.width(), grid.height());
    let strata = axis_strata(problem);
    let needed = min_tabulation_cells(problem.n, strata) as f64;
    check_resolution(grid, problem, needed, "its points' spacing")?;
    let first = grid.coarser(w / 2, h / 2)?;
    let second = grid.coarser(w / 4, h / 4)?;
    if strata == AxisStrata::Projections {
        // Smooth: the energy the cells remove falls as their side squared, and so (a jump
        // would keep it) does the largest step between neighbouring cells fall with the side.
        let smooth = within_energy(grid, &first) < SMOOTH_RATIO * within_energy(&first, &second)
            && largest_step(grid) < SMOOTH_STEP_RATIO * largest_step(&first);
        if smooth {
            check_resolution(
                grid,
                problem,
                4.0 * problem.n as f64,
                "the N intervals of its projections (the grid is smooth at its cells' scale)",
            )?;
        }
    }
    let side = |g: &GridIntegrand| 1.0 / ((g.width() * g.height()) as f64).sqrt();
    Ok(Some(Levels {
        sides: [side(grid), side(&first), side(&second)],
        strata,
        label: grid.label(),
        sizes: [(w, h), (w / 2, h / 2), (w / 4, h / 4)],
        coarser: [first, second],
    }))
}

/// The fewest cells per axis of a 2D tabulation whose coarser levels resolve the spacing of `n`
/// points structured as `strata` says: four times [`MIN_COARSE_CELLS_PER_SPACING`] `√n`
/// (rounded up), and 4 for independent points (three levels). Smooth tabulations under
/// samplers with stratified projections need more (`4 n`).
///
/// # Examples
/// ```
/// use specvar::predict::min_tabulation_cells;
/// use specvar::sampler::AxisStrata;
/// assert_eq!(min_tabulation_cells(1024, AxisStrata::Spacing), 256);
/// assert_eq!(min_tabulation_cells(1024, AxisStrata::Independent), 4);
/// ```
pub fn min_tabulation_cells(n: usize, strata: AxisStrata) -> usize {
    match strata {
        AxisStrata::Independent => 4,
        _ => 4 * (MIN_COARSE_CELLS_PER_SPACING * (n as f64).sqrt()).ceil() as usize,
    }
}

/// The scale at which `problem`'s patterns are structured along an axis: the sampler's fact,
/// for point sets the cells declared (unknown sets as the finest, the projections').
fn axis_strata(problem: &Problem<'_>) -> AxisStrata {
    if let Some(kind) = problem.kind() {
        return kind.facts().axis_strata;
    }
    match problem.cells {
        Some(CellRule::Whole) => AxisStrata::Independent,
        Some(CellRule::Strata) => AxisStrata::Spacing,
        _ => AxisStrata::Projections,
    }
}

/// Refuses `grid` where its narrower side has fewer than `needed` cells.
fn check_resolution(
    grid: &GridIntegrand,
    problem: &Problem<'_>,
    needed: f64,
    what: &str,
) -> Result<()> {
    let cells = grid.width().min(grid.height());
    if (cells as f64) < needed {
        return Err(Error::TabulationTooCoarse {
            grid: grid.label(),
            n: problem.n,
            cells,
            what: what.into(),
            needed: needed as usize,
        });
    }
    Ok(())
}

/// `∫ (fine − coarse)²` over the square: the energy that averaging `fine` onto `coarse`'s cells
/// removes, summed over the pieces that a fine and a coarse cell share.
fn within_energy(fine: &GridIntegrand, coarse: &GridIntegrand) -> f64 {
    let columns = GridIntegrand::shares(coarse.width(), fine.width());
    let rows = GridIntegrand::shares(coarse.height(), fine.height());
    let area = 1.0 / (coarse.width() * coarse.height()) as f64;
    let (values, coarse_values) = (fine.values(), coarse.values());
    let mut total = crate::quadrature::CompensatedSum::default();
    for (j, row) in rows.iter().enumerate() {
        for (i, column) in columns.iter().enumerate() {
            let mean = coarse_values[j * coarse.width() + i];
            let mut sum = 0.0;
            for &(y, wy) in row {
                for &(x, wx) in column {
                    let d = values[y * fine.width() + x] - mean;
                    sum += wx * wy * d * d;
                }
            }
            total.add(sum * area);
        }
    }
    total.value()
}

/// The largest difference between two cells of `grid` that share a side.
fn largest_step(grid: &GridIntegrand) -> f64 {
    let (w, values) = (grid.width(), grid.values());
    let across = values
        .chunks_exact(w)
        .flat_map(|row| row.windows(2).map(|p| (p[1] - p[0]).abs()));
    let up = values.iter().zip(&values[w..]).map(|(a, b)| (b - a).abs());
    across.chain(up).fold(0.0, f64::max)
}

/// The prediction for the function that `levels` tabulate, from the grid's own prediction
/// `fine` and its coarser levels' `coarser`.
///
/// # Errors
/// [`Error::TabulationTooCoarse`] where a level's variance is 0 (a level that the sampler
/// integrates exactly says nothing of the function).
pub(super) fn extrapolate(
    fine: Prediction,
    coarser: [Prediction; 2],
    levels: &Levels,
) -> Result<Prediction> {
    let v = [fine.variance, coarser[0].variance, coarser[1].variance];
    let [h0, h1, h2] = levels.sides;
    // Independent points integrate no level exactly: a level of variance 0 is a constant,
    // whose variance `Var(g)/N` is still the tabulation's at that resolution.
    let zero = v.iter().position(|&x| x <= 0.0);
    if let Some(i) = zero.filter(|_| levels.strata != AxisStrata::Independent) {
        let (w, h) = levels.sizes[i];
        let cells = levels.sizes[0].0.min(levels.sizes[0].1);
        return Err(Error::TabulationTooCoarse {
            grid: levels.label.clone(),
            n: fine.n,
            cells,
            what: format!(
                "what the sampler does not integrate exactly (its average on {w} × {h} cells \
                 has variance 0, so the levels say nothing of the function)"
            ),
            needed: 4 * cells,
        });
    }
    let r0 = v[0] + (v[0] - v[1]) * h0 / (h1 - h0);
    let r1 = v[1] + (v[1] - v[2]) * h1 / (h2 - h1);
    let term = (r0 - v[0])
        .abs()
        .max((r0 - r1).abs())
        .max((v[0] - v[1]).abs());
    let variance = r0.max(0.0);
    let sizes = levels
        .sizes
        .iter()
        .map(|(w, h)| format!("{w}×{h}"))
        .collect::<Vec<_>>()
        .join(", ");
    let reason = format!(
        "{}; the grid tabulates a finer function: extrapolated from its averages on {sizes} \
         cells (variances {:.4e}, {:.4e}, {:.4e})",
        fine.reason, v[0], v[1], v[2]
    );
    Ok(Prediction {
        variance,
        reason,
        budget: ErrorBudget {
            tabulation: term.max(variance - r0),
            ..fine.budget
        },
        evaluations: fine.evaluations + coarser[0].evaluations + coarser[1].evaluations,
        ..fine
    })
}

/// The same problem on another integrand (a coarser level of its grid).
pub(super) fn on<'a>(problem: &Problem<'a>, integrand: &'a dyn Integrand) -> Problem<'a> {
    Problem {
        integrand,
        ..*problem
    }
}
