//! The multi-jittered samplers' unshifted estimator on an integrand that is not a product of
//! functions of one coordinate, exactly: the sums over pairs of occupied cells that
//! [`crate::predict::multi_jitter_variance`] and [`crate::predict::correlated_multi_jitter_variance`] read.
//!
//! Both samplers place point `(i, j)` (column `i` of `m`, row `j` of `r`, `N = m r`) in one of
//! the `N` fine cells of its block: fine x `i r + s`, fine y `j m + t`. Write `G = F − I` on the
//! `N × N` fine cells and `B_ij(s, t)` for block `(i, j)`'s matrix of them.
//!
//! - Multi-jitter (independent shuffles) pairs a block only with a block's mean, with its
//!   sub-columns' means over the sub-rows, or with its sub-rows' means over the sub-columns:
//!   each the mean over a cell of a coarser grid (`N × r`, `m × N`), so the integrand's own
//!   sums over grids' cells ([`Integrand::cell_sums`]: a disk or a polygon visits only the
//!   cells its boundary crosses) and `3N` boxes answer at any N; an integrand without them is
//!   summed over the table of its `N²` cells.
//! - CMJ (one permutation for every column's sub-columns, one for every row's sub-rows) pairs
//!   two blocks at one sub-row position, at one sub-column position, or at distinct positions
//!   on both axes: by inclusion–exclusion over the blocks, self-pairings of the blocks, of their
//!   sums over each column `C_i = Σ_j B_ij` and each row `R_j = Σ_i B_ij`, and of the sum of
//!   all `S = Σ_ij B_ij`. Those fold the blocks onto one another, which no box integral gives,
//!   so they are read from the table of the `N²` cells.
//!
//! `N² E[(M − I)²] = (1/N) Σ_c G_c² + P`, with `P` the sum over ordered pairs of distinct
//! points of `E[G_p G_q]`; the within-cell term is `Σ_c V_c / N³`, as each point is uniform over
//! its block's `N` cells (`docs/theory.md`, "Strata in space").

use super::cell_moments::{seconds_per_cell, CellMoments, CellSum, CellTable, CELL_ROUNDING};
use crate::budget::{Budget, Needs};
use crate::costs::CELL_SECONDS;
use crate::error::Result;
use crate::integrand::Integrand;
use crate::quadrature::CompensatedSum;
use crate::sampler::near_square_factors;
use rayon::prelude::*;

/// The work of [`multi_jitter_from_boxes`] at `n`: `3N` boxes (the blocks, the fine columns
/// and the fine rows) and the integrand's sums over three grids (about ten cells a point
/// visited on each, as for Latin hypercube's crossed cells); `None` unless `f` is 2D with its
/// own sums over a grid's cells.
pub(crate) fn multi_jitter_box_needs(f: &dyn Integrand, n: usize) -> Option<Needs> {
    (f.dimension() == 2 && f.cell_sums(&[1, 1]).is_some()).then(|| {
        let nf = n as f64;
        Needs::work(3.0 * nf * seconds_per_cell(f, &[n, n]) + 30.0 * nf * CELL_SECONDS)
    })
}

/// Multi-jitter's variance, unshifted, from boxes and the integrand's sums over grids' cells,
/// in `O(N)` boxes; `None` unless `f` is 2D with such sums. A block's sub-column profile
/// `A_ij(s)` is the mean of `G` over a cell of the `N × r` grid (a fine column by a block's
/// height), and a row profile `B_ij(t)` over a cell of the `m × N` grid, so the sums of their
/// squares that the pairs in one column or one row read are those grids' `Σ_c F_c²`
/// ([`Integrand::cell_sums`], visiting only the cells the boundary crosses); the other sums
/// read the blocks' means and the fine columns' and rows' means, `3N` boxes.
///
/// # Errors
/// Work beyond the budget.
pub(crate) fn multi_jitter_from_boxes(
    f: &dyn Integrand,
    n: usize,
    budget: &Budget,
) -> Result<Option<CellSum>> {
    let Some(needs) = multi_jitter_box_needs(f, n) else {
        return Ok(None);
    };
    budget.check("multi-jitter's boxes", needs, "lower N")?;
    let (m, r) = near_square_factors(n);
    let grids = [[n, n], [n, r], [m, n]].map(|grid| f.cell_sums(&grid));
    let [Some(cells), Some(column_strips), Some(row_strips)] = grids else {
        return Ok(None);
    };
    let (nf, integral) = (n as f64, f.integral());
    // The mean of G over fine columns [x0, x1) × fine rows [y0, y1).
    let mean = |(x0, x1): (usize, usize), (y0, y1): (usize, usize)| -> f64 {
        let lo = [x0 as f64 / nf, y0 as f64 / nf];
        let hi = [x1 as f64 / nf, y1 as f64 / nf];
        let area = ((x1 - x0) * (y1 - y0)) as f64 / (nf * nf);
        f.box_moments(&lo, &hi).map_or(0.0, |q| q.0) / area - integral
    };
    // Block b = i + m j.
    let means: Vec<f64> = (0..m * r)
        .into_par_iter()
        .map(|b| {
            let (i, j) = (b % m, b / m);
            mean((i * r, (i + 1) * r), (j * m, (j + 1) * m))
        })
        .collect();
    let fine_columns: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|x| mean((x, x + 1), (0, n)))
        .collect();
    let fine_rows: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|y| mean((0, n), (y, y + 1)))
        .collect();
    // Σ_c G_c² = Σ_c F_c² − (cells) I², as Σ_c F_c = (cells) I; Σ F² bounds its rounding.
    let centred = |sums: &crate::integrand::CellSums, cells: usize| {
        sums.mean_square - cells as f64 * integral * integral
    };
    let block = |i: usize, j: usize| means[i + m * j];
    // Pairs in one column: blocks j ≠ j' (profile sums a_ij = r Ḡ_ij) at distinct
    // sub-columns s ≠ s' (the profiles summed down the column: r times the fine column's mean).
    let same_column = one_line_pairs(
        r,
        (0..m).map(|i| (0..r).map(|j| r as f64 * block(i, j)).collect()),
        fine_columns.iter().map(|&g| r as f64 * g),
        centred(&column_strips, n * r),
    );
    let same_row = one_line_pairs(
        m,
        (0..r).map(|j| (0..m).map(|i| m as f64 * block(i, j)).collect()),
        fine_rows.iter().map(|&g| m as f64 * g),
        centred(&row_strips, m * n),
    );
    // Each line's sums cancel down from sums of squares of at most (len + 1) Σ profile², by
    // Cauchy–Schwarz over the len positions summed.
    let strip_size = |len: usize, sums: &crate::integrand::CellSums| {
        let pairs = (len * len.saturating_sub(1)).max(1) as f64;
        nf * (len + 1) as f64 * sums.mean_square / pairs
    };
    let size = cells.mean_square + strip_size(r, &column_strips) + strip_size(m, &row_strips);
    let mut sum = multi_jitter_sum(
        n,
        cells.within / (nf * nf * nf),
        (centred(&cells, n * n), size),
        &means,
        same_column + same_row,
    );
    // An error `e` in a grid's `Σ V` moves its `Σ F²` by `−e`: the `N × N` cells' two terms
    // cancel it; a strip grid's moves its line pairs by `e / (len (len − 1))`, over `N²`.
    let strips = |len: usize, sums: &crate::integrand::CellSums| {
        if len < 2 {
            0.0
        } else {
            sums.within_error / (len * (len - 1)) as f64
        }
    };
    sum.rounding += (strips(r, &column_strips) + strips(m, &row_strips)) / (nf * nf);
    Ok(Some(sum))
}

/// [`line_pairs`] summed over every line of blocks, from sums alone: each line's blocks' sums
/// of their profiles (`lines`), each position's sum over its line's blocks (`positions`, every
/// line's in turn), and the sum of every profile's square (`squares`).
fn one_line_pairs(
    len: usize,
    lines: impl Iterator<Item = Vec<f64>>,
    positions: impl Iterator<Item = f64>,
    squares: f64,
) -> f64 {
    if len < 2 {
        return 0.0;
    }
    let whole: f64 = lines
        .map(|a| a.iter().sum::<f64>().powi(2) - a.iter().map(|v| v * v).sum::<f64>())
        .sum();
    let same = positions.map(|w| w * w).sum::<f64>() - squares;
    (whole - same) / (len * (len - 1)) as f64
}

/// Multi-jitter's variance, unshifted, from the table of the `N × N` cells (the caller checks
/// their count against the budget): the blocks' means and profiles summed from the cells.
pub(crate) fn multi_jitter_from_table(f: &dyn Integrand, n: usize) -> CellSum {
    let (m, r) = near_square_factors(n);
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
    // Pairs in one column: distinct sub-columns (the profiles A), independent sub-rows; pairs
    // in one row: distinct sub-rows (the profiles B), independent sub-columns.
    let same_column: f64 = (0..m)
        .map(|i| line_pairs(r, |j, s| columns[block(i, j) * r + s]))
        .sum();
    let same_row: f64 = (0..r)
        .map(|j| line_pairs(m, |i, t| rows[block(i, j) * m + t]))
        .sum();
    let squares = squares.value();
    multi_jitter_sum(
        n,
        table.within,
        (squares, squares),
        &means,
        same_column + same_row,
    )
}

/// Multi-jitter's variance from its parts: the within-cell term, `Σ_c G_c²` (and a bound on
/// its terms' size), the blocks' means of `G` (block `i + m j`), and the sums over pairs in one
/// column or one row.
fn multi_jitter_sum(
    n: usize,
    within: f64,
    (squares, squares_size): (f64, f64),
    means: &[f64],
    one_line: f64,
) -> CellSum {
    let (m, r) = near_square_factors(n);
    let block = |i: usize, j: usize| means[i + m * j];
    let square = |v: f64| v * v;
    // Pairs in different columns and rows: independent, each uniform in its block.
    let total: f64 = means.iter().sum();
    let by_column: f64 = (0..m)
        .map(|i| square((0..r).map(|j| block(i, j)).sum()))
        .sum();
    let by_row: f64 = (0..r)
        .map(|j| square((0..m).map(|i| block(i, j)).sum()))
        .sum();
    let own: f64 = means.iter().map(|v| v * v).sum();
    let blocks = square(total) - by_column - by_row + own;
    let nf = n as f64;
    let variance = within + (squares / nf + blocks + one_line) / (nf * nf);
    // The sums of squares cancel down from (Σ_b |Ḡ_b|)², each term rounded once per cell.
    let mass: f64 = means.iter().map(|v| v.abs()).sum();
    let scale = within + (squares_size / nf + mass * mass) / (nf * nf);
    CellSum {
        variance: variance.max(0.0),
        rounding: CELL_ROUNDING * scale,
    }
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

/// What CMJ's pair forms read of a matrix `X(s, t)` (`s` the sub-column, `t` the sub-row):
/// `(Σ X)²`, `Σ_s X_s²` with `X_s = Σ_t X(s, t)`, `Σ_t (X^t)²` with `X^t = Σ_s X(s, t)`, and
/// `Σ X²`. Sums of these over matrices are the same quantities summed.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct SelfPairs {
    total_squared: f64,
    by_sub_column: f64,
    by_sub_row: f64,
    squares: f64,
}

impl SelfPairs {
    /// Of `x` laid out as `x[t r + s]`, `r` sub-columns.
    fn of(x: &[f64], r: usize) -> Self {
        let mut sub_columns = vec![0.0; r];
        let (mut total, mut by_sub_row, mut squares) = (0.0, 0.0, 0.0);
        for row in x.chunks_exact(r) {
            let mut along = 0.0;
            for (s, &v) in row.iter().enumerate() {
                sub_columns[s] += v;
                along += v;
                squares += v * v;
            }
            total += along;
            by_sub_row += along * along;
        }
        Self {
            total_squared: total * total,
            by_sub_column: sub_columns.iter().map(|v| v * v).sum(),
            by_sub_row,
            squares,
        }
    }

    /// `Σ_t Σ_{s≠s'} X(s, t) X(s', t)`: two cells in one sub-row, distinct sub-columns.
    fn one_sub_row(&self) -> f64 {
        self.by_sub_row - self.squares
    }

    /// `Σ_s Σ_{t≠t'} X(s, t) X(s, t')`: two cells in one sub-column, distinct sub-rows.
    fn one_sub_column(&self) -> f64 {
        self.by_sub_column - self.squares
    }

    /// `Σ_{s≠s'} Σ_{t≠t'} X(s, t) X(s', t')`: distinct positions on both axes.
    fn apart(&self) -> f64 {
        self.total_squared - self.by_sub_column - self.by_sub_row + self.squares
    }
}

impl std::ops::Add for SelfPairs {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self {
            total_squared: self.total_squared + o.total_squared,
            by_sub_column: self.by_sub_column + o.by_sub_column,
            by_sub_row: self.by_sub_row + o.by_sub_row,
            squares: self.squares + o.squares,
        }
    }
}

impl std::iter::Sum for SelfPairs {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::default(), |a, b| a + b)
    }
}

/// CMJ's variance, unshifted, from the table of the `N × N` cells (the caller checks their
/// count against the budget). Ordered pairs of points:
/// - in one column (`j ≠ j'`): distinct sub-columns, one sub-row, probability
///   `1 / (m r (r − 1))` each: `Σ_i [Q(C_i) − Σ_j Q(B_ij)]` with `Q` the one-sub-row pairing;
/// - in one row (`i ≠ i'`): one sub-column, distinct sub-rows, `1 / (r m (m − 1))` each, from
///   `R_j` and the one-sub-column pairing;
/// - apart (`i ≠ i'`, `j ≠ j'`): distinct positions on both axes, `1 / (r (r − 1) m (m − 1))`
///   each, all pairs of blocks less those in one column and in one row, plus those in one block
///   (counted out twice).
pub(crate) fn correlated_from_table(f: &dyn Integrand, n: usize) -> CellSum {
    let (m, r) = near_square_factors(n);
    let table = CellTable::new(&CellMoments::new(f, &[n, n]), n);
    let g = &table.deviation;
    // Block (i, j)'s sub-row t: fine cells i r .. (i + 1) r of fine row j m + t.
    let sub_row = |i: usize, j: usize, t: usize| {
        let start = (j * m + t) * n + i * r;
        &g[start..start + r]
    };
    let add_block = |into: &mut [f64], i: usize, j: usize| {
        for (t, row) in into.chunks_exact_mut(r).enumerate() {
            row.iter_mut()
                .zip(sub_row(i, j, t))
                .for_each(|(a, &v)| *a += v);
        }
    };
    // Per column: C_i, its self-pairs, and the self-pairs of its blocks.
    let columns: Vec<(Vec<f64>, SelfPairs, SelfPairs)> = (0..m)
        .into_par_iter()
        .map(|i| {
            let (mut fold, mut one) = (vec![0.0; n], vec![0.0; n]);
            let mut blocks = SelfPairs::default();
            for j in 0..r {
                one.iter_mut().for_each(|v| *v = 0.0);
                add_block(&mut one, i, j);
                blocks = blocks + SelfPairs::of(&one, r);
                fold.iter_mut().zip(&one).for_each(|(a, &v)| *a += v);
            }
            let pairs = SelfPairs::of(&fold, r);
            (fold, pairs, blocks)
        })
        .collect();
    let rows: SelfPairs = (0..r)
        .into_par_iter()
        .map(|j| {
            let mut fold = vec![0.0; n];
            (0..m).for_each(|i| add_block(&mut fold, i, j));
            SelfPairs::of(&fold, r)
        })
        .collect::<Vec<_>>()
        .into_iter()
        .sum();
    let mut all = vec![0.0; n];
    for (fold, _, _) in &columns {
        all.iter_mut().zip(fold).for_each(|(a, &v)| *a += v);
    }
    let whole = SelfPairs::of(&all, r);
    let folds: SelfPairs = columns.iter().map(|c| c.1).sum();
    let blocks: SelfPairs = columns.iter().map(|c| c.2).sum();
    let (mf, rf) = (m as f64, r as f64);
    let per = |pairs: f64| if pairs > 0.0 { 1.0 / pairs } else { 0.0 };
    let one_column = (folds.one_sub_row() - blocks.one_sub_row()) * per(mf * rf * (rf - 1.0));
    let one_row = (rows.one_sub_column() - blocks.one_sub_column()) * per(rf * mf * (mf - 1.0));
    let apart = (whole.apart() - folds.apart() - rows.apart() + blocks.apart())
        * per(rf * (rf - 1.0) * mf * (mf - 1.0));
    let nf = n as f64;
    let squares = blocks.squares;
    let variance = table.within + (squares / nf + one_column + one_row + apart) / (nf * nf);
    // Each pairing cancels down from sums of |G| squared.
    let mut size = CompensatedSum::default();
    g.iter().for_each(|v| size.add(v.abs()));
    let mass = size.value() / nf;
    let scale = table.within + (squares / nf + mass * mass) / (nf * nf);
    CellSum {
        variance: variance.max(0.0),
        rounding: CELL_ROUNDING * scale,
    }
}
