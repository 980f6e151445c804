//! The unshifted estimator of N-rooks samplers with their pairs of occupied cells in closed
//! form: Latin hypercube (independent permutations of every axis's rows) and multi-jitter
//! (Chiu et al.'s independent shuffles of each column's sub-columns and each row's sub-rows).
//! Both sum `E[(M − I)²]` over the `N^d` cells' means exactly (`docs/theory.md`, "Strata in
//! space"), at the cost of tabulating them.

use super::cell_moments::{
    check_box_moments, check_cells, CellMoments, CellSum, CellTable, CELL_ROUNDING,
    EXACT_CELL_BUDGET,
};
use crate::budget::Budget;
use crate::error::{Error, Result};
use crate::integrand::{Integrand, SeparableCells};
use crate::quadrature::CompensatedSum;

/// The cells of an exact pair sum, `n^d`, within [`EXACT_CELL_BUDGET`] and the budget.
fn exact_cells(what: &str, n: usize, d: usize, budget: &Budget) -> Result<usize> {
    let cells = n
        .checked_pow(d as u32)
        .filter(|&c| c <= EXACT_CELL_BUDGET)
        .ok_or_else(|| Error::TooLarge {
            what: format!("{what} over N^{d} cells at N = {n}"),
            needed: format!("{n}^{d} cells"),
            budget: format!("{EXACT_CELL_BUDGET} cells"),
            advice: "lower N, or let the occupancy be estimated".into(),
        })?;
    check_cells(what, cells, budget)?;
    Ok(cells)
}

/// The largest share of its value by which a sum from an integrand's bounded sums over grids'
/// cells ([`crate::integrand::CellSums::within_error`]: a smooth integrand's, on cells too many
/// to visit) may be off and still be taken where the table of cells fits and is exact.
const BOUNDED_SHARE: f64 = 1e-6;

/// Whether `f`'s sums over grids' cells bound its variance within the cells rather than
/// compute it ([`crate::integrand::CellSums::within_error`]).
pub(crate) fn bounded_cell_sums(f: &dyn Integrand) -> bool {
    f.cell_sums(&vec![1; f.dimension()])
        .is_some_and(|s| s.within_error > 0.0)
}

/// Whether `sum`, from sums over grids' cells, gives way to the table of the `n^d` cells: its
/// integrand's sums are bounded rather than computed, its bound is above [`BOUNDED_SHARE`] of
/// its value, and the table fits.
fn prefers_table(f: &dyn Integrand, n: usize, d: usize, sum: &CellSum) -> bool {
    let bounded = bounded_cell_sums(f);
    let tabulated = n
        .checked_pow(d as u32)
        .is_some_and(|c| c <= EXACT_CELL_BUDGET);
    bounded && tabulated && sum.rounding > BOUNDED_SHARE * sum.variance
}

/// The variance of the Latin hypercube estimator of `n` points in dimension `d`, unshifted,
/// exactly: the cells are the `N^d` grid, a pair of points occupies two cells that differ on
/// every axis with probability `N(N−1)/(N(N−1))^d` each, and the sum over such pairs is, by
/// inclusion–exclusion over the axes they share, `Σ_A (−1)^{|A|} Σ (marginal of G over the
/// axes outside A)²` with `G = F − I`.
///
/// A separable integrand ([`Integrand::separable_cells`]) is summed from its rows, and in 2D one
/// with its own sums over a grid's cells ([`Integrand::cell_sums`]: disks, tabulated grids) from
/// those and its slabs, at any N; the others over the table of the `N^d` cells.
///
/// # Errors
/// An integrand without box moments, or work beyond the budget; for an integrand summed over
/// its table, `N^d` cells above `2^24`.
///
/// # Examples
/// ```
/// use specvar::integrand::{Gaussian, Integrand};
/// use specvar::predict::latin_hypercube_variance;
/// // In 1D, Latin hypercube is jitter with N strata.
/// let bump = Gaussian::new(0.1, vec![0.4], 1.0)?;
/// let lhs = latin_hypercube_variance(&bump, 64, &Default::default())?;
/// let jitter = specvar::predict::fixed_strata_variance(&bump, &[64], 64, &Default::default())?;
/// assert!((lhs.variance - jitter.variance).abs() < 1e-12 * jitter.variance);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn latin_hypercube_variance(f: &dyn Integrand, n: usize, budget: &Budget) -> Result<CellSum> {
    check_box_moments(f)?;
    let d = f.dimension();
    match LatinHypercubeSum::of(f) {
        LatinHypercubeSum::Separable => {
            budget.check(
                "the Latin hypercube's rows",
                crate::budget::Needs {
                    memory_bytes: super::cell_moments::separable_row_bytes(&vec![n; d]),
                    work_seconds: (d * n) as f64 * crate::costs::CELL_SECONDS,
                },
                "lower N",
            )?;
            if let Some(rows) = f.separable_cells(&vec![n; d]) {
                return Ok(separable_latin_hypercube(&rows, n));
            }
        }
        // In 2D an integrand's own sums over the cells (a disk's crossed cells, a grid's
        // classes) replace the table of N² cells at every N, unless they were bounded rather
        // than computed and leave more than the table would.
        LatinHypercubeSum::Crossed => {
            let sum = crossed_latin_hypercube(f, n, budget)?;
            if !prefers_table(f, n, d, &sum) {
                return Ok(sum);
            }
        }
        LatinHypercubeSum::Table => {}
    }
    let cells = exact_cells("the Latin hypercube's pair sum", n, d, budget)?;
    let grid = vec![n; d];
    let integral = f.integral();
    let table = CellTable::new(&CellMoments::new(f, &grid), n);
    let nf = n as f64;
    let mut squares = CompensatedSum::default();
    let mut scale = 0.0;
    for &g in &table.deviation {
        squares.add(g * g);
        scale += (g + integral).powi(2);
    }
    // The within-cell sum, Σ_c V_c, from the table's (1/(N |C|)) Σ_c V_c.
    let within = table.within * nf * cells as f64;
    scale += within;
    // S = Σ_A (−1)^{|A|} Σ_{c_A} (Σ_{c: c_A fixed} G_c)², A the axes a pair shares.
    let mut pairs = CompensatedSum::default();
    for shared in 0..(1usize << d) {
        // Sharing every axis is the same cell: Σ G², without a copy of the grid.
        let sum: f64 = if shared == (1 << d) - 1 {
            squares.value()
        } else {
            marginal_sums(&table.deviation, n, d, shared)
                .iter()
                .map(|m| m * m)
                .sum()
        };
        let sign = if shared.count_ones() % 2 == 0 {
            1.0
        } else {
            -1.0
        };
        pairs.add(sign * sum);
    }
    Ok(latin_hypercube_sum(
        (n, d),
        within,
        squares.value(),
        pairs.value(),
        scale,
    ))
}

/// How [`latin_hypercube_variance`] sums over the `N^d` cells of an integrand.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LatinHypercubeSum {
    /// From one row of cells per axis, `O(dN)`: a product of functions of one coordinate.
    Separable,
    /// In 2D from the integrand's own sums over the cells and its `2N` slabs.
    Crossed,
    /// From the table of the `N^d` cells, within the cell budget.
    Table,
}

impl LatinHypercubeSum {
    fn of(f: &dyn Integrand) -> Self {
        let d = f.dimension();
        if f.separable_cells(&vec![1; d]).is_some() {
            Self::Separable
        } else if d == 2 && f.cell_sums(&[1, 1]).is_some() {
            Self::Crossed
        } else {
            Self::Table
        }
    }
}

/// Whether [`latin_hypercube_variance`] answers `f` at any N: separable, or in 2D with sums
/// over a grid's cells of its own ([`Integrand::cell_sums`]).
pub(crate) fn latin_hypercube_at_any_n(f: &dyn Integrand) -> bool {
    LatinHypercubeSum::of(f) != LatinHypercubeSum::Table
}

/// [`latin_hypercube_variance`] in 2D from the integrand's sums over the `N × N` cells
/// ([`Integrand::cell_sums`]: a disk visits only the cells its circle crosses) and its `2N`
/// slabs: with `G = F − I`, `Σ_c G_c² = Σ_c F_c² − N² I²`, and the pairs' sum is
/// `Σ_c G_c² − S_0 − S_1`, `S_a = Σ_i (Σ_{c in slab i of axis a} G_c)² = N² Σ_i (N M_i − I)²`
/// with `M_i` the slab's integral.
fn crossed_latin_hypercube(f: &dyn Integrand, n: usize, budget: &Budget) -> Result<CellSum> {
    budget.check(
        "the Latin hypercube's crossed cells",
        crate::budget::Needs {
            memory_bytes: 0.0,
            work_seconds: 10.0 * n as f64 * crate::costs::CELL_SECONDS,
        },
        "lower N",
    )?;
    let sums = f
        .cell_sums(&[n, n])
        .ok_or_else(|| Error::Mismatch(format!("{} has no sums over a grid's cells", f.label())))?;
    let nf = n as f64;
    let integral = f.integral();
    let slabs = |axis: usize| -> f64 {
        let mut sum = CompensatedSum::default();
        for i in 0..n {
            let (mut lo, mut hi) = ([0.0, 0.0], [1.0, 1.0]);
            lo[axis] = i as f64 / nf;
            hi[axis] = (i + 1) as f64 / nf;
            let mass = f.box_moments(&lo, &hi).map_or(0.0, |m| m.0);
            sum.add((nf * mass - integral).powi(2));
        }
        nf * nf * sum.value()
    };
    let squares = sums.mean_square - nf * nf * integral * integral;
    let pairs = squares - slabs(0) - slabs(1);
    let mut sum = latin_hypercube_sum(
        (n, 2),
        sums.within,
        squares,
        pairs,
        sums.mean_square + sums.within,
    );
    // An error `e` in `Σ V` moves `Σ F²` by `−e`: the cells' own terms keep their sum, and
    // the pairs' moves the variance by `e / (N² · N(N − 1))`.
    sum.rounding += sums.within_error / (nf * nf * nf * (nf - 1.0).max(1.0));
    Ok(sum)
}

/// The Latin hypercube's variance from its three sums over the `N^d` cells: the cells' inner
/// variances `Σ_c V_c`, `Σ_c G_c²`, and the pairs' inclusion–exclusion sum; `scale` bounds the
/// terms' size for the rounding.
fn latin_hypercube_sum(
    (n, d): (usize, usize),
    within: f64,
    squares: f64,
    pairs: f64,
    scale: f64,
) -> CellSum {
    let nf = n as f64;
    let norm = 1.0 / (nf * nf);
    let occupied = nf.powi(1 - d as i32);
    let pair_probability = nf * (nf - 1.0) * (nf * (nf - 1.0)).powi(-(d as i32));
    let variance = norm
        * (occupied * within
            + occupied * squares
            + if n > 1 { pair_probability * pairs } else { 0.0 });
    CellSum {
        variance: variance.max(0.0),
        rounding: CELL_ROUNDING * norm * scale * (1usize << d) as f64,
    }
}

/// [`latin_hypercube_variance`] for a separable integrand `f = h Π_a f_a`, from its rows alone
/// in `O(dN)`: with `μ_a(i)` the mean of `f_a` over row `i`, `I_a` their mean and
/// `R_a = Σ_i (μ_a(i) − I_a)²`, the sums over cells that agree on the axes `A` factor,
/// `Σ_{c_A} (Σ_{c ∖ c_A} G_c)² = N^{2(d−|A|)} h² Π_{a∉A} I_a² · E(A)` with
/// `E(A) = Π_{a∈A} Σ_i μ_a(i)² − Π_{a∈A} N I_a² = Σ_{∅≠T⊆A} Π_{a∈T} R_a Π_{a∈A∖T} N I_a²`
/// (a sum of positive terms, so no cancellation), and `Σ_c G_c² = h² E(all)`.
fn separable_latin_hypercube(rows: &SeparableCells, n: usize) -> CellSum {
    let d = rows.mass.len();
    let nf = n as f64;
    let h2 = rows.height * rows.height;
    // Per axis: I_a, R_a, Σ μ², Σ (mean of f_a² over the row).
    let axes: Vec<[f64; 4]> = rows
        .mass
        .iter()
        .zip(&rows.square)
        .map(|(mass, square)| {
            let (mut total, mut squares) = (CompensatedSum::default(), CompensatedSum::default());
            mass.iter().for_each(|&m| total.add(m));
            square.iter().for_each(|&q| squares.add(nf * q));
            let mean = total.value();
            let (mut spread, mut second) = (CompensatedSum::default(), CompensatedSum::default());
            for &m in mass {
                spread.add((nf * m - mean).powi(2));
                second.add((nf * m).powi(2));
            }
            [mean, spread.value(), second.value(), squares.value()]
        })
        .collect();
    let excess = |set: usize| -> f64 {
        let mut sum = CompensatedSum::default();
        for part in 1..=set {
            if part & !set != 0 || part & set != part {
                continue;
            }
            let term: f64 = (0..d)
                .filter(|a| set >> a & 1 == 1)
                .map(|a| {
                    if part >> a & 1 == 1 {
                        axes[a][1]
                    } else {
                        nf * axes[a][0] * axes[a][0]
                    }
                })
                .product();
            sum.add(term);
        }
        sum.value()
    };
    let all = (1usize << d) - 1;
    let squares = h2 * excess(all);
    let second: f64 = axes.iter().map(|a| a[2]).product();
    let within = h2 * (axes.iter().map(|a| a[3]).product::<f64>() - second);
    let mut pairs = CompensatedSum::default();
    for shared in 1..=all {
        let outside: f64 = (0..d)
            .filter(|a| shared >> a & 1 == 0)
            .map(|a| axes[a][0] * axes[a][0])
            .product();
        let k = d - shared.count_ones() as usize;
        let sign = if shared.count_ones() % 2 == 0 {
            1.0
        } else {
            -1.0
        };
        pairs.add(sign * nf.powi(2 * k as i32) * h2 * outside * excess(shared));
    }
    latin_hypercube_sum((n, d), within, squares, pairs.value(), h2 * second + within)
}

/// The sums of `G_c = F_c − I` (`deviation`) over the cells that agree on the axes in
/// `shared` (a bit set), one per value of those axes.
fn marginal_sums(deviation: &[f64], n: usize, d: usize, shared: usize) -> Vec<f64> {
    let kept: Vec<usize> = (0..d).filter(|a| shared >> a & 1 == 1).collect();
    let mut out = vec![0.0; n.pow(kept.len() as u32)];
    for (index, &g) in deviation.iter().enumerate() {
        let mut key = 0;
        for &a in kept.iter().rev() {
            key = key * n + (index / n.pow(a as u32)) % n;
        }
        out[key] += g;
    }
    out
}

/// The variance of the multi-jittered estimator of `n` points in 2D (Chiu et al.: `m × r`
/// cells, sub-columns shuffled in each column and sub-rows in each row, every shuffle
/// independent), unshifted, exactly. Point `(i, j)` falls uniformly in the `N` fine cells of its
/// block (column `i`'s `r` sub-columns × row `j`'s `m` sub-rows); two points in different
/// columns and rows are independent; two in one column take distinct sub-columns (a uniform
/// pair) and independent sub-rows, and two in one row the reverse. With `G = F − I` on the
/// `N × N` cells, its block means `Ḡ`, column profiles `A_ij(s)` (mean over the block's sub-rows)
/// and row profiles `B_ij(t)`, `N² E[(M − I)²] = (1/N) Σ G² + S_blocks + S_columns + S_rows`, each
/// a sum of squares of marginals by inclusion–exclusion. The block means and profiles are
/// integrals over boxes, so an integrand with its own sums over a grid's cells
/// ([`Integrand::cell_sums`]: disks, polygons, tabulated grids) is answered from those sums on
/// three grids and `3N` boxes at any N; a separable one from its rows; any other from the
/// table of its `N²` cells.
///
/// # Errors
/// A dimension other than 2, an integrand without box moments, or work beyond the budget; for
/// an integrand summed over its table, `N²` cells above `2^24`.
///
/// # Examples
/// ```
/// use specvar::integrand::Polygon;
/// use specvar::predict::{multi_jitter_variance, predict, PredictParams, Problem, SpectrumChoice};
/// use specvar::sampler::MultiJitter;
/// let edge = Polygon::edge(30.0, 0.4, 1.0)?;
/// let exact = multi_jitter_variance(&edge, 64, &Default::default())?;
/// // The occupancy estimated from patterns agrees within its noise.
/// let mj = MultiJitter::new(2)?;
/// let params = PredictParams { spectrum: SpectrumChoice::Estimated, ..Default::default() };
/// let e = predict(&Problem::new(&mj, &edge, 64)?, &params)?;
/// assert!((e.variance - exact.variance).abs() < 5.0 * e.budget.spectrum_noise);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn multi_jitter_variance(f: &dyn Integrand, n: usize, budget: &Budget) -> Result<CellSum> {
    check_box_moments(f)?;
    if f.dimension() != 2 {
        return Err(crate::error::invalid(
            "dimension",
            f.dimension(),
            "2 for multi-jitter",
        ));
    }
    if let Some(sum) = separable_shuffles(f, n, Shuffles::Independent, budget)? {
        return Ok(sum);
    }
    if let Some(sum) = super::shuffle_cells::multi_jitter_from_boxes(f, n, budget)?
        && !prefers_table(f, n, 2, &sum)
    {
        return Ok(sum);
    }
    exact_cells("the multi-jittered pair sum", n, 2, budget)?;
    Ok(super::shuffle_cells::multi_jitter_from_table(f, n))
}

/// The variance of Kensler's correlated multi-jittered estimator of `n` points in 2D,
/// unshifted, exactly. With `N = m × r` (`m` columns of `r` sub-columns, `r` rows of `m`
/// sub-rows), point `(i, j)` takes sub-column `σ(j)` of column `i` and sub-row `τ(i)` of row
/// `j`, for two uniform permutations `σ` and `τ` shared by every column and row: two points of
/// one column take distinct sub-columns and one sub-row position, two of one row the reverse,
/// two in different columns and rows distinct positions on both axes. Each pair's expectation
/// factors by axis, so for a separable integrand `f = h f_0(x) f_1(y)` (a Gaussian) the sum
/// over pairs is four products of sums over the rows of cells of each axis, at any N
/// (`docs/theory.md`, "Strata in space"). Any other integrand is summed over the table of its
/// `N²` cells, its pairs of blocks by inclusion–exclusion over the blocks' sums along each
/// column and row.
///
/// # Errors
/// A dimension other than 2, an integrand without box moments, or work beyond the budget; for
/// an integrand that is not separable, `N²` cells above `2^24` (its occupancy is estimated from
/// patterns instead).
///
/// # Examples
/// ```
/// use specvar::integrand::Gaussian;
/// use specvar::predict::{correlated_multi_jitter_variance, predict, PredictParams, Problem, SpectrumChoice};
/// use specvar::sampler::CorrelatedMultiJitter;
/// let bump = Gaussian::new(0.2, vec![0.2, 0.7], 1.0)?;
/// let exact = correlated_multi_jitter_variance(&bump, 96, &Default::default())?;
/// // The occupancy estimated from patterns agrees within its noise.
/// let cmj = CorrelatedMultiJitter::new(2)?;
/// let params = PredictParams { spectrum: SpectrumChoice::Estimated, ..Default::default() };
/// let e = predict(&Problem::new(&cmj, &bump, 96)?, &params)?;
/// assert!((e.variance - exact.variance).abs() < 5.0 * e.budget.spectrum_noise);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn correlated_multi_jitter_variance(
    f: &dyn Integrand,
    n: usize,
    budget: &Budget,
) -> Result<CellSum> {
    check_box_moments(f)?;
    if f.dimension() != 2 {
        return Err(crate::error::invalid(
            "dimension",
            f.dimension(),
            "2 for correlated multi-jitter",
        ));
    }
    if let Some(sum) = separable_shuffles(f, n, Shuffles::Correlated, budget)? {
        return Ok(sum);
    }
    exact_cells("correlated multi-jitter's pair sum", n, 2, budget)?;
    Ok(super::shuffle_cells::correlated_from_table(f, n))
}

/// Whether the multi-jittered samplers' pairs are in closed form for `f` at any N: a product
/// of functions of one coordinate each.
pub(crate) fn shuffles_at_any_n(f: &dyn Integrand) -> bool {
    f.dimension() == 2 && f.separable_cells(&[1, 1]).is_some()
}

/// How the two multi-jittered samplers shuffle their sub-strata.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shuffles {
    /// Chiu et al.: each column's sub-columns and each row's sub-rows independently.
    Independent,
    /// Kensler: one permutation for every column's sub-columns, one for every row's sub-rows.
    Correlated,
}

/// One axis of a separable integrand on the `N` fine cells of an N-rooks sampler, grouped in
/// `blocks` blocks of `size` positions (x: the columns' sub-columns; y: the rows' sub-rows):
/// the sums over pairs of cells that the pair expectations read, of the centred means
/// `ũ = u − ū` of the axis factor over the cells. Each sum comes with a bound on its magnitude
/// (its terms' absolute values), for the rounding bound.
struct AxisPairs {
    /// `Σ_{k, s} ũ(k, s)² / L`: one point with itself.
    own: f64,
    /// `Σ_{k≠k'} Σ_s ũ(k, s) ũ(k', s) / L`: two blocks, one position.
    same_position: (f64, f64),
    /// `Σ_k Σ_{s≠s'} ũ(k, s) ũ(k, s') / (L (L − 1))`: one block, distinct positions.
    same_block: (f64, f64),
    /// `Σ_{k≠k'} Σ_{s≠s'} ũ(k, s) ũ(k', s') / (L (L − 1))`: two blocks, distinct positions.
    distinct: (f64, f64),
    /// `Σ_{k≠k'} (Σ_s ũ(k, s)) (Σ_s ũ(k', s)) / L²`: two blocks, independent positions.
    independent: (f64, f64),
    /// `Σ u²` and `Σ w` over the cells, with `w` the factor's variance inside a cell: the
    /// within-cell term's parts.
    raw_squares: f64,
    inner: f64,
}

impl AxisPairs {
    /// From the integrals of the factor and of its square over the `blocks × size` cells
    /// (block `k`'s position `s` at `k · size + s`).
    fn new(mass: &[f64], square: &[f64], blocks: usize, size: usize) -> Self {
        let cells = (blocks * size) as f64;
        let means: Vec<f64> = mass.iter().map(|&m| m * cells).collect();
        let mut total = CompensatedSum::default();
        means.iter().for_each(|&u| total.add(u));
        let centre = total.value() / cells;
        let dev: Vec<f64> = means.iter().map(|&u| u - centre).collect();
        let sum_sq = |values: &mut dyn Iterator<Item = f64>| {
            let mut s = CompensatedSum::default();
            values.for_each(|v| s.add(v * v));
            s.value()
        };
        let squares = sum_sq(&mut dev.iter().copied());
        let block_squares = sum_sq(&mut dev.chunks(size).map(|b| b.iter().sum::<f64>()));
        let position_squares =
            sum_sq(&mut (0..size).map(|s| (0..blocks).map(|k| dev[k * size + s]).sum::<f64>()));
        let (l, pairs) = (size as f64, (size * size.saturating_sub(1)) as f64);
        // Σ_{k≠k'} U_k U_k' = (Σ U)² − Σ U², and Σ U = Σ ũ = 0.
        let per_pair = |value: f64, magnitude: f64| {
            if pairs == 0.0 {
                (0.0, 0.0)
            } else {
                (value / pairs, magnitude / pairs)
            }
        };
        let raw_squares = sum_sq(&mut means.iter().copied());
        let mut inner = CompensatedSum::default();
        for (&q, &u) in square.iter().zip(&means) {
            inner.add((q * cells - u * u).max(0.0));
        }
        Self {
            own: squares / l,
            same_position: (
                (position_squares - squares) / l,
                (position_squares + squares) / l,
            ),
            same_block: per_pair(block_squares - squares, block_squares + squares),
            distinct: per_pair(
                squares - block_squares - position_squares,
                squares + block_squares + position_squares,
            ),
            independent: (-block_squares / (l * l), block_squares / (l * l)),
            raw_squares,
            inner: inner.value(),
        }
    }
}

/// `Var[μ_N]` of the multi-jittered samplers' unshifted estimator for a separable `f`, from one
/// row of cells per axis, in `O(N)`; `None` when `f` is not separable. Both are N-rooks (one
/// point in every fine column and every fine row), so `Σ_p ũ(X_p) = Σ_p ṽ(Y_p) = 0` and
/// `M − I = (h/N) Σ_p ũ(X_p) ṽ(Y_p)`: the pairs' expectations are products of one sum per axis.
fn separable_shuffles(
    f: &dyn Integrand,
    n: usize,
    shuffles: Shuffles,
    budget: &Budget,
) -> Result<Option<CellSum>> {
    if !shuffles_at_any_n(f) {
        return Ok(None);
    }
    budget.check(
        "the multi-jittered samplers' rows",
        crate::budget::Needs {
            memory_bytes: 3.0 * super::cell_moments::separable_row_bytes(&[n, n]),
            work_seconds: (2 * n) as f64 * crate::costs::CELL_SECONDS,
        },
        "lower N",
    )?;
    Ok(f.separable_cells(&[n, n])
        .map(|rows| shuffles_of_rows(&rows, n, shuffles)))
}

/// The variance of a multi-jittered sampler's estimator (`kind`: multi-jitter or CMJ) on the
/// separable `f` shifted by `t` on the torus (`f(x + t mod 1)`), exactly in `O(N)`, and its
/// rounding bound; `None` for another sampler or an integrand that is not separable. Its mean
/// over uniform shifts is the randomly shifted estimator's variance.
pub(crate) fn shifted_shuffles_variance(
    f: &dyn Integrand,
    kind: crate::sampler::SamplerKind,
    n: usize,
    t: &[f64],
) -> Option<CellSum> {
    use crate::sampler::CellLaw;
    let shuffles = match kind.facts().cell_law {
        CellLaw::IndependentShuffles => Shuffles::Independent,
        // In 2D an orthogonal array with its offsets is CMJ on p × p cells.
        CellLaw::CorrelatedShuffles | CellLaw::OrthogonalArray => Shuffles::Correlated,
        _ => return None,
    };
    if f.dimension() != 2 {
        return None;
    }
    f.shifted_separable_cells(&[n, n], t)
        .map(|rows| shuffles_of_rows(&rows, n, shuffles))
}

/// [`separable_shuffles`] from the rows of cells of each axis.
fn shuffles_of_rows(rows: &SeparableCells, n: usize, shuffles: Shuffles) -> CellSum {
    let (m, r) = crate::sampler::near_square_factors(n);
    let x = AxisPairs::new(&rows.mass[0], &rows.square[0], m, r);
    let y = AxisPairs::new(&rows.mass[1], &rows.square[1], r, m);
    // One column: its points' x in one block; one row: their y in one block.
    let (column, row, apart) = match shuffles {
        Shuffles::Independent => (
            (x.same_block, y.independent),
            (x.independent, y.same_block),
            (x.independent, y.independent),
        ),
        Shuffles::Correlated => (
            (x.same_block, y.same_position),
            (x.same_position, y.same_block),
            (x.distinct, y.distinct),
        ),
    };
    let mut pairs = CompensatedSum::default();
    pairs.add(x.own * y.own);
    let mut magnitude = x.own * y.own;
    for ((a, a_mag), (b, b_mag)) in [column, row, apart] {
        pairs.add(a * b);
        magnitude += a_mag * b_mag;
    }
    let (h2, nf) = (rows.height * rows.height, n as f64);
    let within_sum = h2 * (x.raw_squares * y.inner + x.inner * y.raw_squares + x.inner * y.inner);
    let within = within_sum / (nf * nf * nf);
    let variance = h2 * pairs.value() / (nf * nf) + within;
    CellSum {
        variance: variance.max(0.0),
        rounding: CELL_ROUNDING * (h2 * magnitude / (nf * nf) + within),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::Gaussian;

    /// Every permutation of `0..n`.
    fn permutations(n: usize) -> Vec<Vec<usize>> {
        if n == 0 {
            return vec![Vec::new()];
        }
        let mut all = Vec::new();
        for p in permutations(n - 1) {
            for at in 0..n {
                let mut q = p.clone();
                q.insert(at, n - 1);
                all.push(q);
            }
        }
        all
    }

    /// Every tuple of `count` permutations of `0..len`.
    fn tuples(len: usize, count: usize) -> Vec<Vec<Vec<usize>>> {
        let each = permutations(len);
        (0..count).fold(vec![Vec::new()], |acc, _| {
            acc.iter()
                .flat_map(|t| {
                    each.iter().map(move |p| {
                        let mut u = t.clone();
                        u.push(p.clone());
                        u
                    })
                })
                .collect()
        })
    }

    /// The variance by enumeration of every equally likely choice of the sub-strata: for each,
    /// `(M − I)² + (1/N²) Σ_p V_{c_p}` from the `N × N` cells' moments of `f` shifted by `t`,
    /// averaged.
    fn enumerated(
        f: &dyn Integrand,
        n: usize,
        choices: &[Vec<(usize, usize)>],
        t: [f64; 2],
    ) -> f64 {
        let nf = n as f64;
        // Each cell's moments from its boxes (wrapped across the faces), not from the
        // integrand's rows.
        let moments = |x: usize, y: usize| {
            crate::predict::strata::cell_moments::shifted_cell_mean_and_variance(
                f,
                &[n, n],
                y * n + x,
                &t,
            )
        };
        let integral = f.integral();
        let mut total = CompensatedSum::default();
        for choice in choices {
            let (mut mean, mut within) = (CompensatedSum::default(), CompensatedSum::default());
            for &(x, y) in choice {
                let (f_c, v_c) = moments(x, y);
                mean.add(f_c / nf);
                within.add(v_c / (nf * nf));
            }
            total.add((mean.value() - integral).powi(2) + within.value());
        }
        total.value() / choices.len() as f64
    }

    /// The shifts of the integrand the enumerations run at: none, and one across both faces.
    const SHIFTS: [[f64; 2]; 2] = [[0.0, 0.0], [0.37, 0.81]];

    /// The closed form at shift `t`: the unshifted route's at `t = 0`.
    fn closed(f: &Gaussian, n: usize, shuffles: Shuffles, t: [f64; 2]) -> CellSum {
        use crate::sampler::SamplerKind;
        let kind = match shuffles {
            Shuffles::Independent => SamplerKind::MultiJitter,
            Shuffles::Correlated => SamplerKind::Cmj,
        };
        let s = shifted_shuffles_variance(f, kind, n, &t).unwrap();
        if t == [0.0, 0.0] {
            let unshifted = separable_shuffles(f, n, shuffles, &Budget::default())
                .unwrap()
                .unwrap();
            assert_eq!(s.variance, unshifted.variance);
        }
        s
    }

    fn integrands() -> Vec<Gaussian> {
        vec![
            Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap(),
            Gaussian::new(0.1, vec![0.9, 0.15], 2.0).unwrap(),
        ]
    }

    /// The closed form for `shuffles` against the mean over every choice of the permutations
    /// (`choices`), unshifted and at each of [`SHIFTS`].
    fn assert_closed_is_enumerated(
        f: &Gaussian,
        n: usize,
        choices: &[Vec<(usize, usize)>],
        shuffles: Shuffles,
    ) {
        for t in SHIFTS {
            let truth = enumerated(f, n, choices, t);
            let s = closed(f, n, shuffles, t);
            let tolerance = s.rounding + CELL_ROUNDING * truth;
            assert!(
                (s.variance - truth).abs() <= tolerance,
                "N = {n}, t = {t:?}: {:e} vs {truth:e}",
                s.variance
            );
        }
    }

    /// Correlated multi-jitter's pair sums against every choice of its two permutations, at
    /// counts whose `m × r` include a single column (`N = 7`), unshifted and shifted.
    #[test]
    fn correlated_shuffles_are_their_enumeration() {
        for f in integrands() {
            for n in [6, 7, 8, 9, 12] {
                assert_closed_is_enumerated(&f, n, &correlated_choices(n), Shuffles::Correlated);
            }
        }
    }

    /// Multi-jitter's pair sums from the rows of a separable integrand against every choice of
    /// its independent shuffles, unshifted and shifted.
    #[test]
    fn independent_shuffles_are_their_enumeration() {
        for f in integrands() {
            for n in [6, 7, 8, 9] {
                assert_closed_is_enumerated(&f, n, &independent_choices(n), Shuffles::Independent);
            }
        }
    }

    /// Every choice of CMJ's two permutations at `n`: the fine cells of its points.
    fn correlated_choices(n: usize) -> Vec<Vec<(usize, usize)>> {
        let (m, r) = crate::sampler::near_square_factors(n);
        let mut choices = Vec::new();
        for sigma in permutations(r) {
            for tau in permutations(m) {
                choices.push(
                    (0..r)
                        .flat_map(|j| {
                            let (sigma, tau) = (&sigma, &tau);
                            (0..m).map(move |i| (i * r + sigma[j], j * m + tau[i]))
                        })
                        .collect(),
                );
            }
        }
        choices
    }

    /// Every choice of multi-jitter's independent shuffles at `n`: the fine cells of its points.
    fn independent_choices(n: usize) -> Vec<Vec<(usize, usize)>> {
        let (m, r) = crate::sampler::near_square_factors(n);
        let mut choices = Vec::new();
        for columns in tuples(r, m) {
            for rows in tuples(m, r) {
                choices.push(
                    (0..r)
                        .flat_map(|j| {
                            let (columns, rows) = (&columns, &rows);
                            (0..m).map(move |i| (i * r + columns[i][j], j * m + rows[j][i]))
                        })
                        .collect(),
                );
            }
        }
        choices
    }

    /// Integrands that are not products of functions of one coordinate: a disk inside the
    /// square, a disk wrapped across a face, an edge, a triangle, a tabulated 5 × 3 grid
    /// (whose cells straddle the grids' cells unevenly).
    fn shapes() -> Vec<Box<dyn Integrand>> {
        use crate::integrand::{Ball, GridIntegrand, Polygon};
        let values = (0..15).map(|i| ((i * 7) % 11) as f64 / 10.0).collect();
        vec![
            Box::new(Ball::new(0.3, vec![0.4, 0.55], 1.0).unwrap()),
            Box::new(Ball::new(0.25, vec![0.15, 0.6], 2.0).unwrap()),
            Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap()),
            Box::new(Polygon::new(vec![[0.1, 0.2], [0.8, 0.35], [0.3, 0.9]], 1.0).unwrap()),
            Box::new(GridIntegrand::new(5, 3, values).unwrap()),
        ]
    }

    fn assert_is_enumerated(what: &str, f: &dyn Integrand, n: usize, s: CellSum, truth: f64) {
        let tolerance = s.rounding + CELL_ROUNDING * truth;
        assert!(
            (s.variance - truth).abs() <= tolerance,
            "{what}, {}, N = {n}: {:e} vs {truth:e}",
            f.label(),
            s.variance
        );
    }

    /// CMJ's sums over the table of cells (the integrand is not separable) against every
    /// choice of its two permutations, at counts with a single column (`N = 7`) and with
    /// `m ≠ r`.
    #[test]
    fn correlated_table_is_its_enumeration() {
        for f in shapes() {
            for n in [6, 7, 8, 9, 12] {
                let truth = enumerated(f.as_ref(), n, &correlated_choices(n), [0.0, 0.0]);
                let s =
                    correlated_multi_jitter_variance(f.as_ref(), n, &Budget::default()).unwrap();
                assert_is_enumerated("CMJ's table", f.as_ref(), n, s, truth);
            }
        }
    }

    /// Multi-jitter's sums from boxes and from the table of cells against every choice of its
    /// independent shuffles.
    #[test]
    fn independent_boxes_and_table_are_their_enumeration() {
        use crate::predict::strata::shuffle_cells::{
            multi_jitter_from_boxes, multi_jitter_from_table,
        };
        for f in shapes() {
            for n in [6, 7, 8, 9] {
                let truth = enumerated(f.as_ref(), n, &independent_choices(n), [0.0, 0.0]);
                let boxes = multi_jitter_from_boxes(f.as_ref(), n, &Budget::default())
                    .unwrap()
                    .unwrap();
                assert_is_enumerated("multi-jitter's boxes", f.as_ref(), n, boxes, truth);
                let table = multi_jitter_from_table(f.as_ref(), n);
                assert_is_enumerated("multi-jitter's table", f.as_ref(), n, table, truth);
            }
        }
    }

    /// At counts beyond enumeration, the routes agree: multi-jitter's boxes with its table,
    /// and on a separable Gaussian CMJ's table with its rows (N = 97 is a single column).
    #[test]
    fn the_routes_agree_beyond_enumeration() {
        use crate::predict::strata::shuffle_cells::{
            correlated_from_table, multi_jitter_from_boxes, multi_jitter_from_table,
        };
        for f in shapes() {
            for n in [96, 97, 100] {
                let boxes = multi_jitter_from_boxes(f.as_ref(), n, &Budget::default())
                    .unwrap()
                    .unwrap();
                let table = multi_jitter_from_table(f.as_ref(), n);
                assert_is_enumerated("multi-jitter", f.as_ref(), n, boxes, table.variance);
            }
        }
        for f in integrands() {
            for n in [96, 97, 100] {
                let rows = separable_shuffles(&f, n, Shuffles::Correlated, &Budget::default())
                    .unwrap()
                    .unwrap();
                let table = correlated_from_table(&f, n);
                assert_is_enumerated("CMJ", &f, n, table, rows.variance);
            }
        }
    }
}
