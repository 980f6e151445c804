//! The unshifted estimator of a sampler whose points are independent and uniform in their cells
//! once the cells are known ([`CellRule`]): jittered strata, N-rooks (Latin hypercube,
//! multi-jitter, orthogonal arrays) and Owen-scrambled base-2 nets, used as drawn.
//!
//! With `C` cells of volume `v = 1/|C|`, `Φ_c = ∫_c f`, `Ψ_c = ∫_c f²`, the cell mean
//! `F_c = Φ_c / v` and the variance inside a cell `V_c = Ψ_c / v − F_c²`, and `Z_c` the number of
//! points in cell `c`, the estimator `μ = (1/N) Σ_j f(x_j)` has, given the occupancy `Z`, the
//! mean `M = (1/N) Σ_c Z_c F_c` and the variance `(1/N²) Σ_c Z_c V_c`. The intensity is uniform
//! (`E Z_c = N v`, so `E M = I`), hence exactly
//!
//! `Var μ = (1/N²) Σ_c E[Z_c] V_c + E[(M − I)²]`.
//!
//! No Fourier series enters: a jump along the cube's faces (a pixel's edge) costs nothing more
//! than any other, and nothing is truncated. The second term is zero for fixed strata (jitter:
//! the per-stratum form `(1/N²) Σ_c V_c`), a sum over pairs of cells for Latin hypercube
//! (computed exactly, by inclusion–exclusion over the axes the pair shares), and otherwise
//! estimated from patterns, each contributing its exact conditional terms (a Rao–Blackwellized
//! estimate: no noise from the points' positions inside their cells). `docs/theory.md`,
//! "Strata in space", derives it and relates it to the aliased Fourier pairs.

use super::cell_moments::{
    check_box_moments, check_cells, chunked_sum, seconds_per_cell, separable_row_bytes,
    CellMoments, CellSum, CellTable, CELL_ROUNDING, EXACT_CELL_BUDGET,
};
use crate::budget::{Budget, Needs};
use crate::costs::CELL_SECONDS;
use crate::error::{Error, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::predict::term_mean::{mean_of_exact_terms, terms_within_budget, OccupancyEstimate};
use crate::predict::{
    ErrorBudget, Form, FormChoice, Prediction, Route, SpectrumChoice, SpectrumOrigin,
};
use crate::progress::{stage, Progress};
use crate::quadrature::CompensatedSum;
use crate::randomization::Randomization;
use crate::sampler::{CellLaw, CellRule, Sampler, SamplerKind};
use crate::spectrum::PatternSource;
use serde::Serialize;
use std::fmt;

/// Patterns an estimated occupancy starts with.
const INITIAL_PATTERNS: usize = 64;
/// Patterns an estimated occupancy never exceeds.
const MAX_PATTERNS: usize = 1 << 16;
/// The most cells the estimate tabulates (8 bytes each): `2^24`.
const TABLE_CELLS: usize = 1 << 24;
/// How the occupancy of the cells is known.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Occupancy {
    /// Fixed: the same number of points in every cell (jitter's strata, or one cell).
    Fixed,
    /// Independent uniform permutations of the rows of every axis (Latin hypercube): its pair
    /// probabilities in closed form.
    Permutations,
    /// Nested uniform scrambling of a base-2 net: its pairs of points by Owen's gains, in
    /// closed form given the net's cell counts on dyadic grids.
    Gains,
    /// The N-rooks permutations' pairs in closed form under a random shift: the exact variance
    /// of each shifted integrand, averaged over `shifts` independent uniform shifts.
    PermutationsOverShifts {
        /// Shifts averaged.
        shifts: usize,
    },
    /// Owen's gains of a scrambled base-2 net under a random shift: the exact variance of each
    /// shifted integrand, averaged over `shifts` independent uniform shifts.
    GainsOverShifts {
        /// Shifts averaged.
        shifts: usize,
    },
    /// Owen's gains of a net whose law nested uniform scrambling leaves unchanged, averaged
    /// over `patterns` patterns whose pair counts differ.
    GainsOverPatterns {
        /// Patterns averaged.
        patterns: usize,
    },
    /// Estimated from `patterns` patterns of the sampler.
    Estimated {
        /// Patterns drawn.
        patterns: usize,
    },
    /// Estimated from `patterns` patterns of the sampler, each under its own random shift of
    /// the integrand (the shifted estimator of a sampler with cells).
    EstimatedOverShifts {
        /// Patterns drawn, each with one shift.
        patterns: usize,
    },
}

/// The cells of a prediction in space.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct CellOrigin {
    /// The most cells on one axis ([`CellRule`] grids are square, except jitter's rectangular
    /// strata).
    pub cells_per_axis: usize,
    /// Cells in all.
    pub cells: usize,
    /// How their occupancy is known.
    pub occupancy: Occupancy,
}

impl fmt::Display for CellOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.occupancy {
            Occupancy::Fixed => write!(f, "fixed occupancy of {} cells", self.cells),
            Occupancy::Permutations => write!(
                f,
                "occupancy of N-rooks permutations in closed form ({} cells)",
                self.cells
            ),
            Occupancy::Gains => write!(
                f,
                "nested uniform scrambling by Owen's gains ({} cells of dyadic grids)",
                self.cells
            ),
            Occupancy::PermutationsOverShifts { shifts } => write!(
                f,
                "N-rooks permutations in closed form averaged over {shifts} random shifts ({} \
                 cells of rows each)",
                self.cells
            ),
            Occupancy::GainsOverShifts { shifts } => write!(
                f,
                "Owen's gains averaged over {shifts} random shifts ({} cells of dyadic grids \
                 each)",
                self.cells
            ),
            Occupancy::GainsOverPatterns { patterns } => write!(
                f,
                "Owen's gains averaged over {patterns} patterns ({} cells of dyadic grids)",
                self.cells
            ),
            Occupancy::Estimated { patterns } => write!(
                f,
                "occupancy estimated from {patterns} patterns ({} cells)",
                self.cells
            ),
            Occupancy::EstimatedOverShifts { patterns } => write!(
                f,
                "occupancy estimated from {patterns} patterns, each under a random shift ({} \
                 cells)",
                self.cells
            ),
        }
    }
}

/// The index of the cell of `grid` holding `x`.
pub(crate) fn cell_of(x: &[f64], grid: &[usize]) -> usize {
    let mut index = 0;
    for a in (0..grid.len()).rev() {
        let m = grid[a];
        index = index * m + ((x[a] * m as f64) as usize).min(m - 1);
    }
    index
}

/// The per-axis coordinates of cell `index` of `grid` (at most 3 axes), the inverse of
/// [`cell_of`]'s numbering (axis 0 the fastest).
pub(crate) fn cell_coordinates(index: usize, grid: &[usize]) -> [usize; 3] {
    let mut at = [0; 3];
    let mut rest = index;
    for (x, &m) in at.iter_mut().zip(grid) {
        *x = rest % m;
        rest /= m;
    }
    at
}

/// The variance of the unshifted estimator with `n` points spread evenly over the cells of
/// `grid`, independent and uniform inside them (jitter's strata with one point each; one cell
/// for independent points): `(1/N²) Σ_c (N/|C|) V_c`, exactly.
///
/// # Errors
/// An integrand without box moments, a grid whose cells do not divide `n`, or one beyond the
/// budget.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::predict::fixed_strata_variance;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// // One cell: independent points, (∫f² − I²)/N.
/// let white = fixed_strata_variance(&disk, &[1, 1], 16, &Default::default())?;
/// let exact = (disk.integral_of_square() - disk.integral().powi(2)) / 16.0;
/// assert!((white.variance - exact).abs() < 1e-15);
/// // 16 × 16 strata: only the cells the circle crosses contribute.
/// let jitter = fixed_strata_variance(&disk, &[16, 16], 256, &Default::default())?;
/// assert!(jitter.variance < 0.1 * exact / 16.0);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn fixed_strata_variance(
    f: &dyn Integrand,
    grid: &[usize],
    n: usize,
    budget: &Budget,
) -> Result<CellSum> {
    check_box_moments(f)?;
    let cells: usize = grid.iter().product();
    if grid.len() != f.dimension() || cells == 0 || !n.is_multiple_of(cells) {
        return Err(crate::error::invalid(
            "strata",
            format!("{grid:?} for N = {n}"),
            format!("{} axes whose cells divide N", f.dimension()),
        ));
    }
    let per_cell = (n / cells) as f64;
    let norm = per_cell / (n as f64 * n as f64);
    // Beyond the cells a sum visits, the integrand's own sums over the grid, where it has them.
    if cells > EXACT_CELL_BUDGET {
        budget.check(
            "the per-stratum sum over the crossed cells",
            Needs {
                memory_bytes: 0.0,
                work_seconds: 8.0 * f.cell_sums_visits(grid) * CELL_SECONDS,
            },
            "lower N",
        )?;
        // Sums whose `Σ_c V_c` is only bounded (a smooth integrand's) are no answer here, where
        // that sum is the variance.
        if let Some(sums) = f.cell_sums(grid).filter(|s| s.within_error == 0.0) {
            let rounding = sums
                .within_rounding
                .unwrap_or(CELL_ROUNDING * (sums.within + sums.mean_square));
            return Ok(CellSum {
                variance: sums.within * norm,
                rounding: rounding * norm,
            });
        }
    }
    check_cells("the per-stratum sum", cells, budget)?;
    let moments = CellMoments::new(f, grid);
    let (sum, scale) = chunked_sum(cells, |i| {
        let (mean, var) = moments.mean_and_variance(i);
        (var, var + mean * mean)
    });
    Ok(CellSum {
        variance: sum * norm,
        rounding: CELL_ROUNDING * scale * norm,
    })
}

/// What one pattern contributes, whose mean over patterns is the unshifted variance: with a
/// table, `(M − I)²` (the within-cell term is added once, exactly); without, also the pattern's
/// own within-cell term `(1/N²) Σ_j V_{c_j}`.
pub(crate) fn pattern_term(
    moments: &CellMoments,
    pattern: &PointSet,
    grid: &[usize],
    table: Option<&CellTable>,
) -> CellSum {
    let n = pattern.len();
    let nf = n as f64;
    let integral = moments.integral();
    let mut deviation = CompensatedSum::default();
    let mut within = CompensatedSum::default();
    // Each deviation `F_c − I` is within `CELL_ROUNDING (|F_c − I| + 2|I|)` of itself.
    let mut magnitude = CompensatedSum::default();
    let mut add = |d: f64| {
        deviation.add(d);
        magnitude.add(d.abs());
    };
    match table {
        Some(t) => pattern
            .points()
            .for_each(|x| add(t.deviation[cell_of(x, grid)])),
        None => {
            for x in pattern.points() {
                let (m, v) = moments.mean_and_variance(cell_of(x, grid));
                add(m - integral);
                within.add(v);
            }
        }
    }
    let m = deviation.value() / nf;
    let off = CELL_ROUNDING * (magnitude.value() / nf + 2.0 * integral.abs());
    let inner = within.value() / (nf * nf);
    CellSum {
        variance: inner + m * m,
        // `m²` within `2|m| δ + δ²`: where the occupied cells' mean is I exactly, all that is
        // left is this rounding.
        rounding: CELL_ROUNDING * inner + 2.0 * m.abs() * off + off * off,
    }
}

/// The unshifted variance of the estimator of `patterns`, estimated from their occupancy of
/// `grid` (cells in which their points are independent and uniform once their cells are
/// known): the mean over patterns of `(1/N²) Σ_j V_{c_j} + (M − I)²`, unbiased, each term exact
/// given the pattern's cells. A sampler's realizations `0, 1, …`: `counts.0` first, then as
/// many as the first ones' spread says the relative standard error `target_noise` needs, up to
/// `counts.1`; given sets: all of them.
///
/// # Errors
/// An integrand without box moments, a sampler error, or a grid of another dimension.
///
/// # Examples
/// ```
/// use specvar::integrand::Gaussian;
/// use specvar::predict::{fixed_strata_variance, occupancy_variance};
/// use specvar::progress::Silent;
/// use specvar::sampler::Jitter;
/// use specvar::spectrum::PatternSource;
/// // Jitter's strata, its occupancy fixed: every pattern gives the exact value.
/// let bump = Gaussian::new(0.15, vec![0.4, 0.6], 1.0)?;
/// let jitter = Jitter::new(2)?;
/// let patterns = PatternSource::Sampler { sampler: &jitter, n: 64, seed: 1 };
/// let e = occupancy_variance(&bump, patterns, &[8, 8], (4, 4), 0.01, &Silent)?;
/// let exact = fixed_strata_variance(&bump, &[8, 8], 64, &Default::default())?;
/// assert!((e.variance - exact.variance).abs() < 1e-9 * exact.variance);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn occupancy_variance(
    f: &dyn Integrand,
    patterns: PatternSource<'_>,
    grid: &[usize],
    counts: (usize, usize),
    target_noise: f64,
    progress: &dyn Progress,
) -> Result<OccupancyEstimate> {
    check_box_moments(f)?;
    patterns.check()?;
    let n = patterns.points();
    let (initial, max_patterns) = match patterns.available() {
        Some(sets) => (sets, sets),
        None => counts,
    };
    if grid.len() != f.dimension() || patterns.dimension() != f.dimension() {
        return Err(Error::Mismatch(format!(
            "cells of dimension {} for an integrand of dimension {}",
            grid.len(),
            f.dimension()
        )));
    }
    let max_patterns = max_patterns.max(2);
    let cells = grid.iter().try_fold(1usize, |a, &m| a.checked_mul(m));
    let moments = CellMoments::new(f, grid);
    let table = cells
        .filter(|&c| c <= TABLE_CELLS && c <= max_patterns.saturating_mul(n))
        .map(|_| stage(progress, "cell means", 0, || CellTable::new(&moments, n)));
    let within = table.as_ref().map_or(0.0, |t| t.within);
    let mut estimate = mean_of_exact_terms(
        "occupancy of the cells",
        (initial.clamp(2, max_patterns), max_patterns),
        target_noise,
        within,
        |i| {
            patterns
                .realization(i)
                .map(|p| pattern_term(&moments, &p, grid, table.as_ref()))
        },
        progress,
    )?;
    estimate.variance += within;
    estimate.rounding += CELL_ROUNDING * within;
    Ok(estimate)
}

/// How a scrambled net's pair counts are known.
#[derive(Clone, Copy)]
pub(crate) enum NetPairs {
    /// Scrambling permutes one fixed net's cells: any pattern has its counts.
    OneNet,
    /// Every pattern is a `(0,m,2)`-net, whose counts the net property fixes: any such net
    /// has them.
    EveryNet,
    /// The counts differ between patterns, each drawn at this many nanoseconds a point.
    PerPattern(f64),
}

/// The dyadic grids of at most `4N` cells whose pair counts a pattern of `N` points is read on.
fn dyadic_grids(n: usize) -> f64 {
    let m = (usize::BITS - n.leading_zeros()) as f64;
    (m + 2.0) * (m + 3.0) / 2.0
}

/// Patterns Owen's gains over patterns start from: their spread is small, so fewer than the
/// occupancy estimate's.
const INITIAL_NETS: usize = 16;

/// Whose patterns a cell-form prediction is for: a sampler of this crate (its cells from its
/// facts) or given point sets with the cells their producer declares.
#[derive(Clone, Copy)]
pub(crate) enum CellSource<'a> {
    /// A sampler of this crate.
    Sampler(&'a dyn Sampler, SamplerKind),
    /// Given point sets whose points are, by declaration, uniform in the cells of `rule`.
    Sets(&'a [PointSet], CellRule),
}

impl CellSource<'_> {
    fn rule(&self) -> CellRule {
        match self {
            CellSource::Sampler(_, kind) => kind.facts().cells,
            CellSource::Sets(_, rule) => *rule,
        }
    }

    /// How the points occupy the cells: a sampler's law, none for given sets (their occupancy
    /// is read from the sets).
    fn law(&self) -> CellLaw {
        match self {
            CellSource::Sampler(_, kind) => kind.facts().cell_law,
            CellSource::Sets(..) => CellLaw::NoCells,
        }
    }

    fn name(&self) -> String {
        match self {
            CellSource::Sampler(_, kind) => kind.to_string(),
            CellSource::Sets(sets, rule) => {
                format!("{} given point sets (declared cells: {rule})", sets.len())
            }
        }
    }
}

/// How close to a cell's face, in cell widths, a point may lie and still be counted in the cell
/// across it: points stored in single precision round `(r + u)/m` with `u` near 1 up to the face
/// `(r + 1)/m`, or near 0 down below `r/m` (Mitsuba's multi-jittered and orthogonal-array points
/// do), 6e-8 of the unit away at most.
const FACE_SLACK: f64 = 1e-5;

/// Errors where `sets` cannot be independent draws with points independent across cells: two
/// identical sets, or a set of more than one point whose points all sit at one offset within
/// their cells of `grid`.
fn check_sets_drawn(sets: &[PointSet], rule: CellRule, grid: &[usize]) -> Result<()> {
    if rule == CellRule::None {
        return Ok(());
    }
    let refuse = |what: String| {
        Err(crate::error::invalid(
            "cells",
            rule,
            format!(
                "point sets drawn independently, with independent points in their cells; {what}"
            ),
        ))
    };
    // Each set's bits hashed, and compared in full only where two hashes agree: no copy of the
    // sets is held.
    let hash = |set: &PointSet| {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        set.points()
            .flatten()
            .for_each(|x| x.to_bits().hash(&mut h));
        h.finish()
    };
    let same = |a: &PointSet, b: &PointSet| {
        a.points()
            .flatten()
            .zip(b.points().flatten())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    };
    let mut seen: std::collections::HashMap<u64, Vec<usize>> = std::collections::HashMap::new();
    for (i, set) in sets.iter().enumerate() {
        let earlier = seen.entry(hash(set)).or_default();
        let twin = earlier.iter().copied().find(|&j| same(&sets[j], set));
        earlier.push(i);
        if let Some(j) = twin {
            return refuse(format!(
                "sets {j} and {i} are identical, so their estimator has no variance of its own \
                 (measure it with `specvar mc --input`)"
            ));
        }
    }
    if rule == CellRule::Whole
        && let Some(what) = dependence(sets)
    {
        return refuse(what);
    }
    for (i, set) in sets.iter().enumerate() {
        if set.len() > 1 && rule != CellRule::Whole && one_offset(set, grid) {
            return refuse(format!(
                "the points of set {i} all sit at one offset within their cells (a shifted or \
                 fixed grid), not independently"
            ));
        }
    }
    Ok(())
}

/// How far, in standard errors, the points' counts in cells may stray from those of independent
/// uniform points before sets declared `whole` are refused: 5, a two-sided normal tail of
/// `5.7e-7`, so that independent sets are refused about once in 1.7 million.
const INDEPENDENCE_Z: f64 = 5.0;

/// Where sets declared to hold independent uniform points do not: their counts in the cubic
/// grid of about `N` cells (strata) and in the `N` rows of each axis (N-rooks, nets) are
/// dispersed unlike independent points' (Pearson's `X² = Σ (c − e)²/e` summed over the sets,
/// `χ²` with `sets · (K − 1)` degrees of freedom, read as a normal score by Wilson and
/// Hilferty's cube root), too evenly (stratified points) or too unevenly. `None` where they
/// pass, or where the grids have fewer than two cells.
fn dependence(sets: &[PointSet]) -> Option<String> {
    let (n, d) = (sets[0].len(), sets[0].dimension());
    let side = (n as f64).powf(1.0 / d as f64).floor() as usize;
    let all: Vec<usize> = (0..d).collect();
    let mut grids: Vec<(Vec<usize>, Vec<usize>)> = vec![(vec![side; d], all)];
    grids.extend((0..d).map(|a| (vec![n], vec![a])));
    grids.into_iter().find_map(|(grid, axes)| {
        let cells: usize = grid.iter().product();
        if cells < 2 {
            return None;
        }
        let expected = n as f64 / cells as f64;
        let mut count = vec![0usize; cells];
        let mut statistic = 0.0;
        for set in sets {
            count.iter_mut().for_each(|c| *c = 0);
            for x in set.points() {
                let index = axes.iter().zip(&grid).rev().fold(0, |index, (&a, &m)| {
                    index * m + ((x[a] * m as f64) as usize).min(m - 1)
                });
                count[index] += 1;
            }
            statistic += count
                .iter()
                .map(|&c| (c as f64 - expected).powi(2) / expected)
                .sum::<f64>();
        }
        let df = (sets.len() * (cells - 1)) as f64;
        let spread = 2.0 / (9.0 * df);
        let z = ((statistic / df).cbrt() - (1.0 - spread)) / spread.sqrt();
        (z.abs() > INDEPENDENCE_Z).then(|| {
            let cells = if axes.len() == 1 {
                format!("the {n} rows of axis {}", axes[0])
            } else {
                format!("the {} cells", crate::predict::grid_label(&grid))
            };
            format!(
                "their points' counts in {cells} are {} than independent uniform points' \
                 (z = {z:.1}, against |z| ≤ {INDEPENDENCE_Z}): declare the cells they are \
                 stratified in (strata, rows, dyadic), or give them without --cells",
                if z < 0.0 { "more even" } else { "less even" }
            )
        })
    })
}

/// Whether every point of `set` lies at the same offset within its cell of `grid`, to a
/// millionth of a cell.
fn one_offset(set: &PointSet, grid: &[usize]) -> bool {
    let offset = |x: &[f64]| -> Vec<f64> {
        x.iter()
            .zip(grid)
            .map(|(&v, &m)| (v * m as f64).fract())
            .collect()
    };
    let mut points = set.points();
    let Some(first) = points.next().map(offset) else {
        return false;
    };
    points.all(|x| {
        offset(x).iter().zip(&first).all(|(a, b)| {
            let gap = (a - b).abs();
            gap.min(1.0 - gap) < 1e-6
        })
    })
}

/// The points' counts in the cells of `grid` (the coordinates `axes` of each point), a point
/// on a cell's face moved across it where that fills an empty cell from a crowded one.
fn settled_counts<'a>(
    points: impl Iterator<Item = &'a [f64]>,
    grid: &[usize],
    axes: &[usize],
) -> Vec<usize> {
    let mut count = vec![0usize; grid.iter().product()];
    let mut on_faces = Vec::new();
    for x in points {
        let mut index = 0;
        let mut stride = 1;
        let mut faces = Vec::new();
        for (&a, &m) in axes.iter().zip(grid) {
            let t = x[a] * m as f64;
            let row = (t as usize).min(m - 1);
            let frac = t - row as f64;
            if row > 0 && frac < FACE_SLACK {
                faces.push((stride, false));
            }
            if row + 1 < m && frac > 1.0 - FACE_SLACK {
                faces.push((stride, true));
            }
            index += row * stride;
            stride *= m;
        }
        count[index] += 1;
        on_faces.extend(
            faces
                .into_iter()
                .map(|(s, up)| (index, if up { index + s } else { index - s })),
        );
    }
    for (from, to) in on_faces {
        if count[from] > 1 && count[to] == 0 {
            count[from] -= 1;
            count[to] += 1;
        }
    }
    count
}

/// Errors unless every set has the occupancy `rule` implies on `grid` (one point per stratum
/// for strata, one per row of every axis for rows, at most one per row of every axis for
/// dyadic) and the sets look drawn as the rule says: no two sets identical (the cell form
/// averages over independent draws), and within a set the points not all at one offset in
/// their cells (a shifted grid fills every stratum, but its points move together).
pub(crate) fn check_sets_occupy(sets: &[PointSet], rule: CellRule, grid: &[usize]) -> Result<()> {
    check_sets_drawn(sets, rule, grid)?;
    let all: Vec<usize> = (0..grid.len()).collect();
    for (i, set) in sets.iter().enumerate() {
        let bad = |what: String| {
            Err(crate::error::invalid(
                "cells",
                rule,
                format!("point sets whose points occupy the cells as declared; set {i} has {what}"),
            ))
        };
        match rule {
            CellRule::None | CellRule::Whole => {}
            CellRule::Strata => {
                let count = settled_counts(set.points(), grid, &all);
                if let Some(c) = count.iter().position(|&k| k != 1) {
                    return bad(format!("{} points in stratum {c}", count[c]));
                }
            }
            CellRule::Rows | CellRule::Dyadic => {
                for (axis, &m) in grid.iter().enumerate() {
                    let count = settled_counts(set.points(), &[m], &[axis]);
                    let exact = rule == CellRule::Rows;
                    if let Some(r) = count.iter().position(|&k| k > 1 || (exact && k == 0)) {
                        return bad(format!("{} points in row {r} of axis {axis}", count[r]));
                    }
                }
            }
        }
    }
    Ok(())
}

/// How the cell form computes a problem's occupancy term: the analyses of strata in space.
#[derive(Clone, Copy)]
pub(crate) enum CellMethod {
    /// Fixed occupancy (strata, or independent points): the per-stratum form.
    Fixed,
    /// An N-rooks sampler's pairs of occupied cells in closed form, by its law.
    Rooks(CellLaw),
    /// A scrambled net's pairs of points by Owen's gains, read from one net.
    Gains(NetPairs),
    /// Owen's gains averaged over patterns whose pair counts differ (drawn at this many
    /// nanoseconds a point).
    GainsOverPatterns(f64),
    /// The occupancy estimated from patterns.
    Estimated,
}

/// Which [`CellMethod`] predicts `source` at `n` on `f`, and its grid of cells, decided from the
/// problem alone (no pattern is drawn).
///
/// # Errors
/// No grid of cells at N, an integrand without moments over boxes, sets that do not occupy
/// their declared cells, or a choice (a lattice extent, the polar form, a closed spectrum) that
/// belongs to the shifted estimator.
pub(crate) fn cell_method(
    f: &dyn Integrand,
    source: CellSource<'_>,
    n: usize,
    params: &crate::predict::PredictParams,
) -> Result<(CellMethod, Vec<usize>)> {
    let d = f.dimension();
    let (rule, name) = (source.rule(), source.name());
    let grid = rule.grid(n, d).ok_or_else(|| Error::OutsideValidity {
        route: "the cell form of the unshifted estimator".into(),
        reason: format!("{name} has no grid of cells at N = {n} in {d}D"),
    })?;
    check_box_moments(f)?;
    if let CellSource::Sets(sets, _) = source {
        check_sets_occupy(sets, rule, &grid)?;
    }
    // Latin hypercube and the multi-jittered samplers have their pairs of cells in closed form.
    let law = source.law();
    let pairs = law.is_rooks().then_some(law).filter(|&law| {
        // A separable integrand's sums factor by axis, and a disk's or a polygon's Latin
        // hypercube needs only the cells its boundary crosses: exact at any N. Multi-jitter
        // reads boxes besides, within the work an estimate would spend. Otherwise the table of
        // cells.
        let tabulated = n
            .checked_pow(d as u32)
            .is_some_and(|c| c <= EXACT_CELL_BUDGET);
        match law {
            CellLaw::Permutations => super::cell_pairs::latin_hypercube_at_any_n(f) || tabulated,
            CellLaw::IndependentShuffles => {
                let boxes = super::shuffle_cells::multi_jitter_box_needs(f, n)
                    .is_some_and(|needs| needs.work_seconds <= params.work_budget_seconds);
                super::cell_pairs::shuffles_at_any_n(f) || boxes || (d == 2 && tabulated)
            }
            // In 2D an orthogonal array with its offsets is CMJ on p × p cells.
            _ => super::cell_pairs::shuffles_at_any_n(f) || (d == 2 && tabulated),
        }
    });
    // Owen-scrambled Sobol' has its pairs of points by Owen's gains, read from any one
    // pattern. So has PMJ02, whose law nested uniform scrambling leaves unchanged: from one
    // pattern at a power of two (every such prefix is a (0,m,2)-net, whose pair counts the net
    // property fixes), from the mean over patterns between two.
    let scrambled = match (source, law) {
        (CellSource::Sampler(..), CellLaw::OwenScrambledNet) => Some(NetPairs::OneNet),
        (CellSource::Sampler(..), CellLaw::ProgressiveNet) if n.is_power_of_two() => {
            Some(NetPairs::EveryNet)
        }
        (CellSource::Sampler(_, kind), CellLaw::ProgressiveNet) => {
            Some(NetPairs::PerPattern(kind.cost_per_point_ns_at(n, 2)))
        }
        _ => None,
    }
    .filter(|_| params.spectrum != SpectrumChoice::Estimated);
    let exact = params.spectrum != SpectrumChoice::Estimated
        && (rule.is_fixed()
            || pairs.is_some()
            || scrambled.is_some_and(|p| !matches!(p, NetPairs::PerPattern(_))));
    check_choices(params, &name, exact)?;
    let method = match (exact, scrambled, pairs) {
        (true, _, _) if rule.is_fixed() => CellMethod::Fixed,
        (_, Some(NetPairs::PerPattern(cost_ns)), _) => CellMethod::GainsOverPatterns(cost_ns),
        (true, Some(net), _) => CellMethod::Gains(net),
        (true, None, Some(law)) => CellMethod::Rooks(law),
        _ => CellMethod::Estimated,
    };
    Ok((method, grid))
}

/// What a cell method needs before it answers: the pattern it reads Owen's gains from, or the
/// first patterns of an estimate; the tables of cells check their own sizes as they are built.
pub(crate) fn cell_method_needs(
    method: CellMethod,
    source: CellSource<'_>,
    n: usize,
    d: usize,
) -> Needs {
    let pattern = |kind: SamplerKind| kind.pattern_needs(n, d);
    match (method, source) {
        // Any (0,m,2)-net's pair counts are read from a scrambled Sobol' net, the quickest drawn.
        (CellMethod::Gains(NetPairs::EveryNet), _) => sobol_net_needs(n, d),
        (CellMethod::Gains(_), CellSource::Sampler(_, kind)) => pattern(kind),
        (CellMethod::GainsOverPatterns(_) | CellMethod::Estimated, CellSource::Sampler(_, k)) => {
            let one = pattern(k);
            Needs {
                memory_bytes: one.memory_bytes,
                work_seconds: one.work_seconds * INITIAL_PATTERNS as f64,
            }
        }
        _ => Needs::default(),
    }
}

/// What drawing one scrambled Sobol' net of `n` points needs (any `(0,m,2)`-net's pair counts
/// are read from one).
fn sobol_net_needs(n: usize, d: usize) -> Needs {
    crate::sampler::Sobol::new(d)
        .ok()
        .and_then(|s| s.kind())
        .map_or(Needs::default(), |k| k.pattern_needs(n, d))
}

/// The unshifted estimator's prediction for `source` by `method` on `grid` ([`cell_method`]).
pub(crate) fn predict_cells(
    f: &dyn Integrand,
    source: CellSource<'_>,
    (method, grid): (CellMethod, Vec<usize>),
    n: usize,
    params: &crate::predict::PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let d = f.dimension();
    let (rule, name) = (source.rule(), source.name());
    let cells: usize = grid.iter().product();
    let strata = crate::predict::grid_label(&grid);
    let sampler = match source {
        CellSource::Sampler(sampler, _) => Some(sampler),
        CellSource::Sets(..) => None,
    };
    let (variance, budget, occupancy, evaluations, reason) = match (method, sampler) {
        (CellMethod::Fixed, _) => {
            let s = fixed_strata_variance(f, &grid, n, &params.budget)?;
            let why = match rule {
                CellRule::Whole => format!(
                "{name}: independent uniform points, (∫f² − I²)/N from the integrand's own moments"
            ),
                _ => format!(
                    "{name}: one uniform point in each of the {strata} strata, unshifted; the \
                 per-stratum form (1/N²) Σ_c Var_c f, exact (each stratum's moments in closed \
                 form, jumps at the faces included)"
                ),
            };
            (
                s.variance,
                rounding(s.rounding),
                Occupancy::Fixed,
                cells,
                why,
            )
        }
        (CellMethod::GainsOverPatterns(cost_ns), Some(sampler)) => {
            gains_over_patterns(f, (sampler, name.as_str()), n, cost_ns, params, progress)?
        }
        (CellMethod::Gains(pairs), Some(sampler)) => {
            // Every (0,m,2)-net has the same pair counts: Sobol''s is drawn in a fraction of
            // PMJ02's time (3.6 s at 2^20).
            let pattern = match pairs {
                NetPairs::EveryNet => crate::sampler::Sobol::new(d)?.sample(n, params.seed, 0)?,
                _ => sampler.sample(n, params.seed, 0)?,
            };
            let (s, read) = crate::predict::digits::owen_gains::scrambled_net_variance(
                f,
                &pattern,
                &params.budget,
            )?;
            let whose = match pairs {
                NetPairs::EveryNet => format!(
                "{name}, as drawn: every prefix of 2^m points is a (0,m,2)-net, whose pair counts \
                 on dyadic grids the net property fixes (read from a scrambled Sobol' net, one \
                 such net), and the sequence's law is unchanged by nested uniform scrambling, so \
                 its variance is that of any such net scrambled"
            ),
                _ => format!("{name}, as drawn: a net under nested uniform scrambling"),
            };
            let why = format!(
            "{whose}: Owen's gains (read from the net's pair counts on dyadic grids) times the \
             integrand's variance at each dyadic level (from its cells' integrals; for a \
             product of axis factors, from each factor's masses level by level and its \
             variance within the finest cells), exact: nothing is truncated, every level left \
             out has gain 1"
        );
            (
                s.variance,
                rounding(s.rounding),
                Occupancy::Gains,
                read,
                why,
            )
        }
        (CellMethod::Rooks(law), _) => {
            let s = match law {
                CellLaw::IndependentShuffles => {
                    super::cell_pairs::multi_jitter_variance(f, n, &params.budget)?
                }
                CellLaw::CorrelatedShuffles | CellLaw::OrthogonalArray => {
                    super::cell_pairs::correlated_multi_jitter_variance(f, n, &params.budget)?
                }
                _ => super::cell_pairs::latin_hypercube_variance(f, n, &params.budget)?,
            };
            let alias = match law {
                CellLaw::OrthogonalArray => {
                    " (in 2D Bose's array with its offsets is correlated multi-jitter on p × p \
                 cells: relabelling the strata leaves one uniform permutation of the \
                 sub-columns and one of the sub-rows)"
                }
                _ => "",
            };
            let bounded = if super::cell_pairs::bounded_cell_sums(f)
                && matches!(law, CellLaw::Permutations | CellLaw::IndependentShuffles)
            {
                "; where the cells are not tabulated, the smooth integrand's variance within them \
             bounded by Poincaré's inequality, its bound in the budget"
            } else {
                ""
            };
            let why = format!(
                "{name}, unshifted{alias}: the cell form over the {n}^{d} cells, its pairs of \
             occupied cells in closed form (exact{bounded})"
            );
            (
                s.variance,
                rounding(s.rounding),
                Occupancy::Permutations,
                cells,
                why,
            )
        }
        (CellMethod::Estimated, _) => {
            let (e, note) = estimate_occupancy(f, source, &grid, n, params, progress)?;
            let why = format!(
                "{name}, unshifted: the points are independent and uniform in the cells of the \
             {strata} grid once their cells are known, so the variance is the cells' inner \
             variance plus the variance of the occupied cells' mean, estimated from {} patterns \
             with each pattern's terms exact{note} (no Fourier series: jumps at the faces cost \
             nothing extra)",
                e.patterns
            );
            let budget = ErrorBudget {
                tabulation: 0.0,
                spectrum_noise: e.standard_error,
                quadrature: e.rounding,
                ..Default::default()
            };
            let occupancy = Occupancy::Estimated {
                patterns: e.patterns,
            };
            (e.variance, budget, occupancy, e.patterns * n, why)
        }
        (CellMethod::Gains(_) | CellMethod::GainsOverPatterns(_), None) => {
            return Err(Error::Mismatch(
                "Owen's gains of point sets without their sampler".into(),
            ))
        }
    };
    Ok(Prediction {
        variance,
        randomization: Randomization::None,
        route: Route {
            form: Form::Cells,
            spectrum: SpectrumOrigin::Cells(CellOrigin {
                cells_per_axis: grid.iter().copied().max().unwrap_or(1),
                // Owen's gains read the cells of many dyadic grids.
                cells: if matches!(
                    occupancy,
                    Occupancy::Gains | Occupancy::GainsOverPatterns { .. }
                ) {
                    evaluations
                } else {
                    cells
                },
                occupancy,
            }),
        },
        reason,
        budget,
        n,
        dimension: d,
        dc_term: 0.0,
        evaluations: evaluations as u64,
        alternatives: Vec::new(),
        analysis: None,
    })
}

/// Errors for the choices that belong to the shifted estimator's routes: the polar form, a
/// closed spectrum where the cell form is estimated, a lattice extent.
fn check_choices(params: &crate::predict::PredictParams, name: &str, exact: bool) -> Result<()> {
    if let Some(kmax) = params.kmax {
        return Err(crate::error::invalid(
            "kmax",
            kmax,
            "no lattice extent for the cell form of the unshifted estimator, which sums over \
             cells in space (the lattice forms are the shifted estimator's: --randomization \
             shift)",
        ));
    }
    if params.form == FormChoice::Polar || (params.spectrum == SpectrumChoice::Closed && !exact) {
        let route = if params.form == FormChoice::Polar {
            "the polar form"
        } else {
            "a closed form"
        };
        let how = if exact {
            ", exactly"
        } else {
            ", its occupancy estimated from patterns"
        };
        return Err(Error::OutsideValidity {
            route: route.into(),
            reason: format!(
                "{name} used as drawn (unshifted) is predicted by the cell form{how}; the polar \
                 form and the closed spectra are for the shifted estimator (--randomization \
                 shift)"
            ),
        });
    }
    Ok(())
}

/// The occupancy estimate of `source` within the work budget, and what the reason adds about
/// its method.
fn estimate_occupancy(
    f: &dyn Integrand,
    source: CellSource<'_>,
    grid: &[usize],
    n: usize,
    params: &crate::predict::PredictParams,
    progress: &dyn Progress,
) -> Result<(OccupancyEstimate, &'static str)> {
    let cells: usize = grid.iter().product();
    // CMJ (beyond its table, or estimated on request): its permutations alone, with a control
    // variate. In 2D an orthogonal array with its offsets has CMJ's law on its p × p cells.
    let cmj_law = match source.law() {
        CellLaw::CorrelatedShuffles => Some(CONTROLLED_NOTE),
        CellLaw::OrthogonalArray if grid.len() == 2 => Some(ARRAY_CONTROLLED_NOTE),
        _ => None,
    };
    if let Some(note) = cmj_law {
        let e = super::cmj_control::controlled_cmj_variance(f, n, params, progress)?;
        return Ok((e, note));
    }
    let (patterns, cost_ns) = match source {
        CellSource::Sampler(sampler, kind) => (
            PatternSource::Sampler {
                sampler,
                n,
                seed: params.seed,
            },
            kind.cost_per_point_ns_at(n, grid.len()),
        ),
        CellSource::Sets(sets, _) => {
            if sets.len() < 2 {
                return Err(crate::error::invalid(
                    "point sets",
                    sets.len(),
                    "at least 2 sets, whose spread gives the estimate's noise",
                ));
            }
            (PatternSource::Sets(sets), 0.0)
        }
    };
    // A separable integrand's cells cost a few products each (its rows: one erf difference a
    // cell of each axis, and their memory).
    let per_cell = seconds_per_cell(f, grid);
    let per_pattern = n as f64 * (cost_ns * 1e-9 + per_cell);
    let (initial, max) = terms_within_budget(params, per_pattern, (INITIAL_PATTERNS, MAX_PATTERNS));
    params.budget.check(
        "the occupancy estimate",
        Needs {
            memory_bytes: 8.0 * (max + cells.min(TABLE_CELLS)) as f64
                + 16.0 * n as f64
                + separable_row_bytes(grid),
            work_seconds: initial as f64 * per_pattern + cells.min(TABLE_CELLS) as f64 * per_cell,
        },
        "lower N or the realizations",
    )?;
    let e = occupancy_variance(
        f,
        patterns,
        grid,
        (initial, max),
        params.target_noise,
        progress,
    )?;
    Ok((e, ""))
}

/// How a controlled occupancy estimate says so in its reason.
const CONTROLLED_NOTE: &str = " (read from each pattern's two permutations at the blocks where \
    the integrand varies), less a bilinear surrogate of each block's cell means whose variance \
    is exact (a control variate: the same mean, a smaller spread where the integrand is smooth \
    on the blocks' scale)";
/// The same for a 2D orthogonal array, whose law is CMJ's on its `p × p` cells.
const ARRAY_CONTROLLED_NOTE: &str = " (the patterns are CMJ's on the p × p cells, whose law the \
    array with its offsets has, each read from its two permutations at the blocks where the \
    integrand varies), less a bilinear surrogate of each block's cell means whose variance is \
    exact (a control variate)";

/// PMJ02 as drawn between two powers of two: the mean over patterns of each one's scrambled
/// variance by Owen's gains ([`crate::predict::digits::owen_gains::scrambled_law_variance`]), each pattern drawn
/// at `cost_ns` a point; the cell form's variance, budget, occupancy, cells read and reason.
fn gains_over_patterns(
    f: &dyn Integrand,
    (sampler, name): (&dyn Sampler, &str),
    n: usize,
    cost_ns: f64,
    params: &crate::predict::PredictParams,
    progress: &dyn Progress,
) -> Result<(f64, ErrorBudget, Occupancy, usize, String)> {
    let per_pattern =
        n as f64 * (cost_ns * 1e-9 + crate::costs::PAIR_COUNT_SECONDS * dyadic_grids(n));
    let counts = terms_within_budget(params, per_pattern, (INITIAL_NETS, MAX_PATTERNS));
    params.budget.check(
        "Owen's gains over patterns",
        Needs {
            memory_bytes: 48.0 * n as f64,
            work_seconds: counts.0 as f64 * per_pattern,
        },
        "lower N or the realizations",
    )?;
    let law = crate::predict::digits::owen_gains::scrambled_law_variance(
        f,
        |i| sampler.sample(n, params.seed, i as u64),
        counts,
        params.target_noise,
        &params.budget,
        progress,
    )?;
    let e = law.estimate;
    let why = format!(
        "{name}, as drawn: a progressive (0,2) sequence whose law nested uniform scrambling \
         leaves unchanged, so its variance is the mean over patterns of each one's \
         scrambled variance, Owen's gains (from its pair counts on dyadic grids) times the \
         integrand's variance at each dyadic level, exact given the pattern; the mean of {} \
         patterns (their pair counts differ between powers of two), nothing truncated",
        e.patterns
    );
    let budget = ErrorBudget {
        tabulation: 0.0,
        spectrum_noise: e.standard_error,
        quadrature: law.estimate.rounding,
        ..Default::default()
    };
    let occupancy = Occupancy::GainsOverPatterns {
        patterns: e.patterns,
    };
    Ok((e.variance, budget, occupancy, law.cells, why))
}

fn rounding(bound: f64) -> ErrorBudget {
    ErrorBudget {
        tabulation: 0.0,
        quadrature: bound,
        ..Default::default()
    }
}
