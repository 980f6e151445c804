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
                    work_seconds: (d * n) as f64 * super::cell_moments::CELL_SECONDS,
                },
                "lower N",
            )?;
            if let Some(rows) = f.separable_cells(&vec![n; d]) {
                return Ok(separable_latin_hypercube(&rows, n));
            }
        }
        // In 2D an integrand's own sums over the cells (a disk's crossed cells, a grid's
        // classes) replace the table of N² cells at every N.
        LatinHypercubeSum::Crossed => return crossed_latin_hypercube(f, n, budget),
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
            work_seconds: 10.0 * n as f64 * super::cell_moments::CELL_SECONDS,
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
    Ok(latin_hypercube_sum(
        (n, 2),
        sums.within,
        squares,
        pairs,
        sums.mean_square + sums.within,
    ))
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
/// a sum of squares of marginals by inclusion–exclusion.
///
/// # Errors
/// A dimension other than 2, an integrand without box moments, or `N²` cells beyond the budget
/// or above `2^24`.
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
    exact_cells("the multi-jittered pair sum", n, 2, budget)?;
    let (m, r) = crate::sampler::near_square_factors(n);
    let table = CellTable::new(&CellMoments::new(f, &[n, n]), n);
    let g = |x: usize, y: usize| table.deviation[y * n + x];
    // Block (i, j): fine x in [i r, (i + 1) r), fine y in [j m, (j + 1) m).
    let block = |i: usize, j: usize| i + m * j;
    let mut columns = vec![0.0; m * r * r]; // A_ij(s) at block(i, j) * r + s
    let mut rows = vec![0.0; m * r * m]; // B_ij(t) at block(i, j) * m + t
    let mut means = vec![0.0; m * r];
    let mut squares = CompensatedSum::default();
    for j in 0..r {
        for i in 0..m {
            let b = block(i, j);
            for s in 0..r {
                for t in 0..m {
                    let v = g(i * r + s, j * m + t);
                    squares.add(v * v);
                    columns[b * r + s] += v / m as f64;
                    rows[b * m + t] += v / r as f64;
                    means[b] += v / n as f64;
                }
            }
        }
    }
    let square = |v: f64| v * v;
    // Pairs in different columns and rows: independent, each uniform in its block.
    let total: f64 = means.iter().sum();
    let by_column: f64 = (0..m)
        .map(|i| square((0..r).map(|j| means[block(i, j)]).sum()))
        .sum();
    let by_row: f64 = (0..r)
        .map(|j| square((0..m).map(|i| means[block(i, j)]).sum()))
        .sum();
    let own: f64 = means.iter().map(|v| v * v).sum();
    let blocks = square(total) - by_column - by_row + own;
    // Pairs in one column: distinct sub-columns (the profiles A), independent sub-rows; pairs
    // in one row: distinct sub-rows (the profiles B), independent sub-columns.
    let same_column: f64 = (0..m)
        .map(|i| line_pairs(r, |j, s| columns[block(i, j) * r + s]))
        .sum();
    let same_row: f64 = (0..r)
        .map(|j| line_pairs(m, |i, t| rows[block(i, j) * m + t]))
        .sum();
    let nf = n as f64;
    let variance =
        table.within + (squares.value() / nf + blocks + same_column + same_row) / (nf * nf);
    // The sums of squares cancel down from (Σ_b |Ḡ_b|)², each term rounded once per cell.
    let mass: f64 = means.iter().map(|v| v.abs()).sum();
    let scale = table.within + (squares.value() / nf + mass * mass) / (nf * nf);
    Ok(CellSum {
        variance: variance.max(0.0),
        rounding: CELL_ROUNDING * scale,
    })
}

/// The mean over a line's pairs of distinct blocks `k ≠ k'` (its `len` blocks) and distinct
/// positions `s ≠ s'` across it of `profile(k, s) profile(k', s')`, summed over the pairs of
/// blocks: `[Σ_{k≠k'} a_k a_k' − Σ_s Σ_{k≠k'} profile(k, s) profile(k', s)] / (len (len − 1))`
/// with `a_k = Σ_s profile(k, s)`. Two points of one column of multi-jitter take distinct
/// sub-columns, uniformly: this is their sum.
fn line_pairs(len: usize, profile: impl Fn(usize, usize) -> f64) -> f64 {
    if len < 2 {
        return 0.0;
    }
    // Σ_{k≠k'} v_k v_k' = (Σ v)² − Σ v².
    let distinct = |values: &mut dyn Iterator<Item = f64>| {
        let (sum, squares) = values.fold((0.0, 0.0), |(s, q), v| (s + v, q + v * v));
        sum * sum - squares
    };
    let whole = distinct(&mut (0..len).map(|k| (0..len).map(|s| profile(k, s)).sum::<f64>()));
    let same: f64 = (0..len)
        .map(|s| distinct(&mut (0..len).map(|k| profile(k, s))))
        .sum();
    (whole - same) / (len * (len - 1)) as f64
}
