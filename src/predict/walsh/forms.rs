//! Digital shifts: fixed patterns under a uniform random digital shift, by Walsh functions.
//!
//! A digital shift XORs every coordinate's binary digits with those of one uniform fraction
//! `Δ_l` per axis. It is to the Walsh functions what the toroidal shift is to the Fourier ones:
//! with `wal_κ(x) = (−1)^{Σ_l Σ_i κ_{l,i} x_{l,i+1}}` (bit `i` of `κ_l` against digit `i + 1` of
//! `x_l`), `wal_κ(x ⊕ Δ) = wal_κ(x) wal_κ(Δ)`, and the `wal_κ(Δ)` are orthonormal over `Δ`. With
//! `f̌(κ) = ∫ f wal_κ` and `S_κ = (1/N) Σ_j wal_κ(x_j)`, the estimator is unbiased and
//!
//! `Var μ = Σ_{κ≠0} |f̌(κ)|² |S_κ|²`
//!
//! (for a digital net `|S_κ|²` is 1 on its dual net and 0 elsewhere).
//!
//! Split `f = f_L + g`, `f_L` its mean over the cells of the grid with `2^L` cells per axis:
//! `f_L`'s Walsh coefficients are `f`'s for `κ < 2^L` and zero beyond, `g`'s the reverse, so the
//! variance is the sum of the two parts' variances, with no cross term. The first is exact: the
//! fast Walsh–Hadamard transform of the cells' integrals gives `f̌(κ)` for `κ < 2^L`, and that of
//! the points' counts in the cells gives `N S_κ` (a Walsh function below level `L` is constant
//! on the cells). The second, the digits below `2^−L`, is measured: the mean of
//! `((1/N) Σ_j g(x_j ⊕ Δ))²` over random shifts is unbiased for it (the mean of `g` over every
//! cell is zero), and its standard error is the prediction's noise. With `L` a few digits past
//! the pattern's own (`log2 N`), it is a small part of the whole (`docs/theory.md`, "Digital
//! shifts"). When every pattern is a linear net and the integrand a product of one factor per
//! axis, [`super::walsh_net`] sums every level exactly instead, and no remainder is measured.

use super::walsh_net::{linear_net_variance, NetVariance};
use super::walsh_transform::walsh_hadamard;
use crate::budget::{Budget, Needs};
use crate::costs::CELL_SECONDS;
use crate::error::{Error, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::predict::strata::cell_moments::{
    check_box_moments, chunked_sum, is_marked, masses_and_constant_cells, CELL_ROUNDING,
};
use crate::predict::strata::cells::{cell_coordinates, cell_of};
use crate::predict::term_mean::mean_to_target_noise;
use crate::predict::{
    ErrorBudget, Form, FormChoice, Patterns, PredictParams, Prediction, Problem, Route,
    SpectrumChoice, SpectrumOrigin,
};
use crate::progress::{stage, Progress};
use crate::quadrature::CompensatedSum;
use crate::randomization::{digital_shift, xor_digits, Randomization, DIGITAL_SHIFT_BITS};
use crate::sampler::Sampler;
use rayon::prelude::*;
use serde::Serialize;
use std::fmt;

/// The most axes (box moments exist up to 3).
const MAX_AXES: usize = 3;
/// The most cells of the tabulated level: `2^22` (two arrays of 32 MiB).
pub(crate) const MAX_WALSH_CELLS: usize = 1 << 22;
/// Digits past the pattern's own (`⌈log2 N⌉`) the tabulated level reaches, within
/// [`MAX_WALSH_CELLS`]: the remainder below it is then a small part of the variance (its
/// share falls like `4^{−extra}` for a smooth integrand, `2^{−extra}` for a jump).
const EXTRA_DIGITS: u32 = 4;
/// Shifts that measure the remainder at first.
const INITIAL_SHIFTS: usize = 64;
/// Shifts the remainder never exceeds.
const MAX_SHIFTS: usize = 1 << 16;
/// A digitally shifted prediction: the exact part below the level, the remainder measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WalshEstimate {
    /// The variance: exact part plus remainder.
    pub(crate) variance: f64,
    /// A bound on the rounding of the exact part.
    pub(crate) rounding: f64,
    /// The remainder's standard error.
    pub(crate) noise: f64,
    /// The remainder's share of the variance.
    pub(crate) remainder: f64,
    /// Cells per axis of the tabulated level.
    pub(crate) cells_per_axis: usize,
    /// Shifts that measured the remainder.
    pub(crate) shifts: usize,
}

/// The most cells transformed over all patterns, `2^26`: each pattern's counts are
/// transformed once, so many given sets share this work (a level coarser by a digit per
/// quadrupling of the sets in 2D), and the remainder's shifts measure what it leaves.
const PATTERN_CELLS: usize = 1 << 26;

/// The tabulated level for `sets` patterns of `n` points: `EXTRA_DIGITS` past `⌈log2 N⌉` per
/// axis, within [`MAX_WALSH_CELLS`] and [`PATTERN_CELLS`] over all patterns.
pub(crate) fn walsh_level(n: usize, d: usize, sets: usize) -> u32 {
    let ceil_log2 = |x: usize| usize::BITS - (x.max(1) - 1).leading_zeros();
    let cell_bits = MAX_WALSH_CELLS.trailing_zeros().min(
        PATTERN_CELLS
            .trailing_zeros()
            .saturating_sub(ceil_log2(sets)),
    );
    (ceil_log2(n) + EXTRA_DIGITS)
        .min(cell_bits / d as u32)
        .max(1)
}

/// `Σ_{κ≠0} a[κ]² (b[κ]/N)²` and `Σ_{κ≠0} |a[κ]| (b[κ]/N)²`, in chunks summed in a fixed order.
fn weighted_energy(a: &[f64], b: &[f64], n: f64) -> (f64, f64) {
    chunked_sum(a.len(), |k| {
        if k == 0 {
            return (0.0, 0.0);
        }
        let s = (b[k] / n) * (b[k] / n);
        (a[k] * a[k] * s, a[k].abs() * s)
    })
}

/// The integrand on the cells of the tabulated level: their means, their Walsh coefficients
/// (the fast transform of their integrals) and the cells it is constant on.
struct LevelTable {
    means: Vec<f64>,
    coefficients: Vec<f64>,
    constant: Option<Vec<u64>>,
    axis_means: Option<AxisMeans>,
}

impl LevelTable {
    fn new(f: &dyn Integrand, grid: &[usize]) -> Self {
        let cells: usize = grid.iter().product();
        let (mut masses, constant) = masses_and_constant_cells(f, grid);
        let means: Vec<f64> = masses.iter().map(|m| m * cells as f64).collect();
        walsh_hadamard(&mut masses);
        let axis_means = AxisMeans::matching(f, grid, &means);
        Self {
            means,
            coefficients: masses,
            constant,
            axis_means,
        }
    }

    fn remainder<'a>(&'a self, f: &'a dyn Integrand, grid: &'a [usize]) -> Remainder<'a> {
        Remainder {
            f,
            means: &self.means,
            grid,
            constant: self.constant.as_deref(),
            axis_means: self.axis_means.as_ref(),
        }
    }
}

/// The most a Walsh coefficient of the level is off: its cells' rounding plus one unit per
/// butterfly, of the total mass `Σ|Φ_c|`.
fn coefficient_error(means: &[f64], level: u32, d: usize) -> f64 {
    let mass: f64 = means.iter().map(|m| m.abs()).sum::<f64>() / means.len() as f64;
    (CELL_ROUNDING + f64::EPSILON * (level as usize * d) as f64) * mass
}

/// The finer digits' part of the integrand, `g = f − (its mean on the tabulated level's
/// cell)`, which is zero on the cells where `f` is constant (`constant`, a bit per cell: a
/// shape's cells wholly inside or outside it, most of a fine grid's, read without `f` or the
/// means, whose table is beyond the caches).
pub(crate) struct Remainder<'a> {
    pub(crate) f: &'a dyn Integrand,
    pub(crate) means: &'a [f64],
    pub(crate) grid: &'a [usize],
    pub(crate) constant: Option<&'a [u64]>,
    /// The means as products of per-axis rows, read in place of the table where they are
    /// its entries to the bit.
    pub(crate) axis_means: Option<&'a AxisMeans>,
}

/// A separable integrand's cell means as products of its per-axis cell masses,
/// `(a Π_l μ_l(c_l)) |C|^{-1}`, in the order the table forms them: a table beyond the caches
/// costs a miss a point read at random, and its rows stay in the caches.
pub(crate) struct AxisMeans {
    height: f64,
    rows: Vec<Vec<f64>>,
    cells: f64,
}

impl AxisMeans {
    /// The rows of `f` on `grid` where every product is `means`' entry to the bit (checked
    /// cell by cell, so that reading them changes no value); `None` otherwise.
    pub(crate) fn matching(f: &dyn Integrand, grid: &[usize], means: &[f64]) -> Option<Self> {
        let rows = f.separable_cells(grid)?;
        let cells: usize = grid.iter().product();
        let axis_means = Self {
            height: rows.height,
            rows: rows.mass,
            cells: cells as f64,
        };
        let side = grid[0];
        let same = axis_means.rows.len() == grid.len()
            && means.len() == cells
            && means.par_chunks(side).enumerate().all(|(row, entries)| {
                let mut at = cell_coordinates(row * side, grid);
                entries.iter().enumerate().all(|(i, &entry)| {
                    at[0] = i;
                    axis_means.product(&at[..grid.len()]).to_bits() == entry.to_bits()
                })
            });
        same.then_some(axis_means)
    }

    /// The mean of the cell at per-axis indices `at`.
    fn product(&self, at: &[usize]) -> f64 {
        let mut m = self.height;
        for (row, &i) in self.rows.iter().zip(at) {
            m *= row[i];
        }
        m * self.cells
    }

    /// The mean of the cell of `grid` holding `y` (found as [`cell_of`] finds it).
    fn at_point(&self, y: &[f64], grid: &[usize]) -> f64 {
        let mut at = [0usize; MAX_AXES];
        for (a, &m) in grid.iter().enumerate() {
            at[a] = ((y[a] * m as f64) as usize).min(m - 1);
        }
        self.product(&at[..grid.len()])
    }
}

impl Remainder<'_> {
    /// `((1/N) Σ_j g(x_j ⊕ Δ))²` for one shift: the remainder's estimator, squared.
    fn term(&self, pattern: &PointSet, mask: &[u64]) -> f64 {
        let d = pattern.dimension();
        let mut y = [0.0; MAX_AXES];
        self.squared_mean(
            pattern.len(),
            pattern.points().map(|x| {
                for l in 0..d {
                    y[l] = xor_digits(x[l], mask[l]);
                }
                y
            }),
            d,
        )
    }

    /// [`term`](Self::term) visiting only the points that `mask` moves into a varying cell,
    /// found through `index` (the same points in the same order, so the same bits).
    fn term_indexed(
        &self,
        (pattern, index): (&PointSet, &PointsByCell),
        varying: &VaryingCells,
        mask: &[u64],
    ) -> f64 {
        let mut hits = Vec::new();
        let shift_cell = varying.shift_cell(mask);
        for &v in &varying.cells {
            hits.extend_from_slice(index.points_in(v as usize ^ shift_cell));
        }
        // The direct sum visits the points in their order; so does this one.
        hits.sort_unstable();
        let d = pattern.dimension();
        let mut y = [0.0; MAX_AXES];
        self.squared_mean(
            pattern.len(),
            hits.iter().map(|&j| {
                let x = pattern.point(j as usize);
                for l in 0..d {
                    y[l] = xor_digits(x[l], mask[l]);
                }
                y
            }),
            d,
        )
    }

    /// `((1/N) Σ_j g(x_j))²` for the pattern as it is.
    pub(crate) fn as_drawn(&self, pattern: &PointSet) -> f64 {
        let d = pattern.dimension();
        let mut y = [0.0; MAX_AXES];
        self.squared_mean(
            pattern.len(),
            pattern.points().map(|x| {
                y[..d].copy_from_slice(x);
                y
            }),
            d,
        )
    }

    /// `((1/N) Σ g(y))²` over the `n` points `ys` (their first `d` coordinates), skipping
    /// those in constant cells.
    pub(crate) fn squared_mean(
        &self,
        n: usize,
        ys: impl Iterator<Item = [f64; MAX_AXES]>,
        d: usize,
    ) -> f64 {
        let mut sum = CompensatedSum::default();
        for y in ys {
            let c = cell_of(&y[..d], self.grid);
            if self.constant.is_some_and(|bits| is_marked(bits, c)) {
                continue;
            }
            let mean = match self.axis_means {
                Some(rows) => rows.at_point(&y[..d], self.grid),
                None => self.means[c],
            };
            sum.add(self.f.eval(&y[..d]) - mean);
        }
        let m = sum.value() / n as f64;
        m * m
    }

    /// The share of the cells where the integrand varies (1 without a set of constant cells):
    /// only points there are evaluated.
    pub(crate) fn varying(&self) -> f64 {
        self.constant.map_or(1.0, |bits| {
            1.0 - bits.iter().map(|w| w.count_ones() as f64).sum::<f64>() / self.means.len() as f64
        })
    }
}

/// The cells of a level of `2^level` cells per axis where the integrand varies, where the
/// remainder `g` can be non-zero. A cell's index is its axes' top `level` digits side by side
/// ([`cell_of`] with axis 0 the fastest), so a digital shift, which XORs each axis's digits,
/// moves the points of cell `u` to cell `u ⊕ c(Δ)`, `c(Δ)` the shift's own cell.
struct VaryingCells {
    cells: Vec<u32>,
    level: u32,
}

impl VaryingCells {
    /// The cells not marked in `constant` (a bit per cell, of `cells` cells).
    fn new(constant: &[u64], cells: usize, level: u32) -> Self {
        Self {
            cells: (0..cells as u32)
                .filter(|&c| !is_marked(constant, c as usize))
                .collect(),
            level,
        }
    }

    /// The cell of the level holding the shift's own digits.
    fn shift_cell(&self, mask: &[u64]) -> usize {
        let drop = DIGITAL_SHIFT_BITS - self.level;
        mask.iter().enumerate().fold(0, |cell, (a, &m)| {
            cell | ((m >> drop) as usize) << (a as u32 * self.level)
        })
    }
}

/// A fixed pattern's points grouped by the cell of a level that holds them: the points of cell
/// `c` are `order[starts[c]..starts[c + 1]]`, in their order in the pattern.
struct PointsByCell {
    starts: Vec<u32>,
    order: Vec<u32>,
}

impl PointsByCell {
    /// The bytes of the index of `n` points over `cells` cells.
    fn bytes(n: usize, cells: usize) -> f64 {
        4.0 * (cells + 1 + n) as f64
    }

    /// `pattern`'s points grouped by the cells of `grid` (of fewer than `2^32` cells and
    /// points), by a counting sort.
    fn new(pattern: &PointSet, grid: &[usize]) -> Self {
        let cells: usize = grid.iter().product();
        let mut starts = vec![0u32; cells + 1];
        let homes: Vec<u32> = pattern.points().map(|x| cell_of(x, grid) as u32).collect();
        for &c in &homes {
            starts[c as usize + 1] += 1;
        }
        for c in 0..cells {
            starts[c + 1] += starts[c];
        }
        let mut next = starts.clone();
        let mut order = vec![0u32; homes.len()];
        for (j, &c) in homes.iter().enumerate() {
            order[next[c as usize] as usize] = j as u32;
            next[c as usize] += 1;
        }
        Self { starts, order }
    }

    /// The points (their indices in the pattern) in cell `c`.
    fn points_in(&self, c: usize) -> &[u32] {
        &self.order[self.starts[c] as usize..self.starts[c + 1] as usize]
    }
}

/// The variance of the estimator of `patterns` (each a fixed pattern, all equally likely)
/// under a uniform random digital shift: exact through level `walsh_level(N, d)` by the Walsh
/// transforms, the finer digits measured by shifts (`counts.0` first, then as many as the
/// relative standard error `target_noise` needs, up to `counts.1`), keyed by `seed`.
///
/// # Errors
/// An integrand of more than 3 axes or without box moments, patterns of another dimension or
/// count, or work beyond `budget`.
pub(crate) fn digital_shift_variance(
    f: &dyn Integrand,
    patterns: &[PointSet],
    target_noise: f64,
    seed: u64,
    work_seconds: f64,
    budget: &Budget,
    progress: &dyn Progress,
) -> Result<WalshEstimate> {
    let d = f.dimension();
    let n = patterns.first().map_or(0, PointSet::len);
    if d > MAX_AXES || patterns.iter().any(|p| p.dimension() != d || p.len() != n) || n == 0 {
        return Err(Error::Mismatch(format!(
            "the Walsh form needs patterns of one N > 0 in the integrand's dimension {d} (at \
             most {MAX_AXES})"
        )));
    }
    // An integrand constant on dyadic cells has no Walsh coefficient beyond their level.
    let level = f
        .dyadic_level()
        .map_or(walsh_level(n, d, patterns.len()), |a| {
            walsh_level(n, d, patterns.len()).min(a.max(1))
        });
    let side = 1usize << level;
    let cells = 1usize << (level as usize * d);
    budget.check(
        "the Walsh form",
        Needs {
            memory_bytes: 16.0 * cells as f64,
            work_seconds: cells as f64
                * (CELL_SECONDS + 1e-9 * (level as usize * d) as f64)
                * (1 + patterns.len()) as f64,
        },
        "lower N",
    )?;
    let grid = vec![side; d];
    let table = stage(progress, "Walsh coefficients", 0, || {
        LevelTable::new(f, &grid)
    });
    let LevelTable {
        means,
        coefficients,
        constant,
        axis_means,
    } = table;
    let nf = n as f64;
    let (mut exact, mut magnitude) = (CompensatedSum::default(), CompensatedSum::default());
    let mut counts = vec![0.0; cells];
    for pattern in patterns {
        counts.iter_mut().for_each(|c| *c = 0.0);
        pattern
            .points()
            .for_each(|x| counts[cell_of(x, &grid)] += 1.0);
        walsh_hadamard(&mut counts);
        let (e, m) = weighted_energy(&coefficients, &counts, nf);
        exact.add(e);
        magnitude.add(m);
    }
    let sets = patterns.len() as f64;
    let exact = exact.value() / sets;
    let rounding = 2.0 * coefficient_error(&means, level, d) * magnitude.value() / sets;
    let table = LevelTable {
        means,
        coefficients,
        constant,
        axis_means,
    };
    let remainder_of = table.remainder(f, &grid);
    // Only the points in cells where the integrand varies are evaluated (a disk's or an edge's
    // boundary cells, a small share at fine levels).
    let varying = remainder_of.varying();
    let evaluations = nf * varying * crate::costs::REMAINDER_EVALUATION_SECONDS;
    let indexed = table
        .constant
        .as_deref()
        .map(|bits| VaryingCells::new(bits, cells, level))
        .filter(|v| {
            // Visiting the varying cells must cost less than skipping the points outside them,
            // and the patterns' indices must fit the memory budget.
            let needs = Needs {
                memory_bytes: patterns.len() as f64 * PointsByCell::bytes(n, cells),
                work_seconds: 0.0,
            };
            (v.cells.len() as f64 * crate::costs::VISIT_SECONDS) < nf * crate::costs::SKIP_SECONDS
                && budget
                    .check("the patterns' points by cell", needs, "")
                    .is_ok()
        })
        .map(|v| {
            let index: Vec<PointsByCell> = patterns
                .par_iter()
                .map(|p| PointsByCell::new(p, &grid))
                .collect();
            (v, index)
        });
    let per_shift = evaluations
        + indexed
            .as_ref()
            .map_or(nf * crate::costs::SKIP_SECONDS, |(v, _)| {
                v.cells.len() as f64 * crate::costs::VISIT_SECONDS
            });
    let max_shifts = ((work_seconds / per_shift) as usize).clamp(INITIAL_SHIFTS, MAX_SHIFTS);
    // The remainder below the level, measured by shifts until its standard error is
    // `target_noise` of the whole.
    let remainder = mean_to_target_noise(
        "finer digits by digital shifts",
        (INITIAL_SHIFTS, max_shifts),
        target_noise,
        exact,
        |unit| {
            let p = unit % patterns.len();
            let mask = digital_shift(d, seed, unit as u64);
            Ok(match &indexed {
                Some((varying, index)) => {
                    remainder_of.term_indexed((&patterns[p], &index[p]), varying, &mask[..d])
                }
                None => remainder_of.term(&patterns[p], &mask[..d]),
            })
        },
        progress,
    )?;
    Ok(WalshEstimate {
        variance: exact + remainder.variance,
        rounding,
        noise: remainder.standard_error,
        remainder: remainder.variance,
        cells_per_axis: side,
        shifts: remainder.patterns,
    })
}

/// Patterns of a random sampler that the level is sized for ([`walsh_level`]): each pattern's
/// counts are transformed once.
const DRAWN_PATTERNS: usize = 256;
/// Patterns of a random sampler under digital shifts drawn at first.
const INITIAL_DRAWN: usize = 32;
/// Patterns of a random sampler never exceeded.
const MAX_DRAWN: usize = 1 << 12;

/// The variance of a random sampler's estimator (`n` points, its patterns drawn anew) under a
/// uniform random digital shift: each pattern's estimator is unbiased under the shift, so the
/// variance is the mean over patterns of each one's variance under shifts. Pattern `u`
/// (realization `u` of `params.seed`) gives that variance's exact part through the level and
/// the finer digits' square at digital shift `u`, whose sum is unbiased for it; their mean over
/// as many patterns as the relative standard error `params.target_noise` needs (their spread
/// is the noise) is the prediction.
///
/// # Errors
/// An integrand of more than 3 axes or without box moments, a sampler of another dimension, a
/// sampler error, or work beyond the budget.
pub(crate) fn drawn_digital_shift_variance(
    f: &dyn Integrand,
    sampler: &dyn Sampler,
    n: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<WalshEstimate> {
    let d = f.dimension();
    check_box_moments(f)?;
    if d > MAX_AXES || sampler.dimension() != d || n == 0 {
        return Err(Error::Mismatch(format!(
            "the Walsh form needs a sampler in the integrand's dimension {d} (at most \
             {MAX_AXES}) and N > 0"
        )));
    }
    let level = f
        .dyadic_level()
        .map_or(walsh_level(n, d, DRAWN_PATTERNS), |a| {
            walsh_level(n, d, DRAWN_PATTERNS).min(a.max(1))
        });
    let side = 1usize << level;
    let cells = 1usize << (level as usize * d);
    let nf = n as f64;
    let transform =
        cells as f64 * crate::costs::WALSH_BUTTERFLY_SECONDS * (level as usize * d) as f64;
    let draw = crate::sampler::pattern_needs(sampler, n).work_seconds;
    let per_pattern = transform
        + draw
        + nf * (crate::costs::SKIP_SECONDS + crate::costs::REMAINDER_EVALUATION_SECONDS);
    params.budget.check(
        "the Walsh form over drawn patterns",
        Needs {
            memory_bytes: 16.0 * cells as f64 * (1 + rayon::current_num_threads()) as f64,
            work_seconds: cells as f64 * CELL_SECONDS
                + transform
                + INITIAL_DRAWN as f64 * per_pattern,
        },
        "lower N",
    )?;
    let grid = vec![side; d];
    let table = stage(progress, "Walsh coefficients", 0, || {
        LevelTable::new(f, &grid)
    });
    let remainder_of = table.remainder(f, &grid);
    let varying = remainder_of.varying();
    let each = transform
        + draw
        + nf * (crate::costs::SKIP_SECONDS + varying * crate::costs::REMAINDER_EVALUATION_SECONDS);
    let max = ((params.work_budget_seconds / each) as usize).clamp(INITIAL_DRAWN, MAX_DRAWN);
    // The largest of the patterns' `Σ|a| (b/N)²`, for the rounding bound (a maximum, so that
    // it does not depend on the order the patterns finish in).
    let largest_magnitude = std::sync::Mutex::new(0.0f64);
    let estimate = mean_to_target_noise(
        "patterns under digital shifts",
        (INITIAL_DRAWN, max),
        params.target_noise,
        0.0,
        |unit| {
            let pattern = sampler.sample(n, params.seed, unit as u64)?;
            let mut counts = vec![0.0; cells];
            pattern
                .points()
                .for_each(|x| counts[cell_of(x, &grid)] += 1.0);
            walsh_hadamard(&mut counts);
            let (exact, magnitude) = weighted_energy(&table.coefficients, &counts, nf);
            if let Ok(mut largest) = largest_magnitude.lock() {
                *largest = largest.max(magnitude);
            }
            let mask = digital_shift(d, params.seed, unit as u64);
            Ok(exact + remainder_of.term(&pattern, &mask[..d]))
        },
        progress,
    )?;
    let magnitude = largest_magnitude.into_inner().unwrap_or(f64::INFINITY);
    Ok(WalshEstimate {
        variance: estimate.variance,
        rounding: 2.0 * coefficient_error(&table.means, level, d) * magnitude,
        noise: estimate.standard_error,
        remainder: 0.0,
        cells_per_axis: side,
        shifts: estimate.patterns,
    })
}

/// The prediction for a random sampler's patterns under a digital shift
/// ([`drawn_digital_shift_variance`]).
///
/// # Errors
/// As [`drawn_digital_shift_variance`], or choices of the shifted estimator's routes.
pub(crate) fn predict_walsh_drawn(
    problem: &Problem<'_>,
    sampler: &dyn Sampler,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    check_choices(params)?;
    let f = problem.integrand;
    let e = drawn_digital_shift_variance(f, sampler, problem.n, params, progress)?;
    let reason = format!(
        "{} patterns drawn anew under a random digital shift: each pattern's estimator is \
         unbiased under the shift, so the variance is the mean over patterns of each one's Walsh \
         sum (the integrand's coefficients times the pattern's, exact through {} cells per \
         axis, the finer digits at one shift of each), over {} patterns",
        problem
            .kind()
            .map_or("the sampler's".to_string(), |k| k.to_string()),
        e.cells_per_axis,
        e.shifts
    );
    Ok(walsh_prediction(problem, &e, reason))
}

/// The prediction of a Walsh-form estimate: its noise and rounding as the budget.
fn walsh_prediction(problem: &Problem<'_>, e: &WalshEstimate, reason: String) -> Prediction {
    Prediction {
        variance: e.variance,
        randomization: Randomization::DigitalShift,
        route: Route {
            form: Form::Walsh,
            spectrum: SpectrumOrigin::Walsh(WalshOrigin {
                cells_per_axis: e.cells_per_axis,
                shifts: e.shifts,
            }),
        },
        reason,
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise: e.noise,
            quadrature: e.rounding,
            ..Default::default()
        },
        n: problem.n,
        dimension: problem.integrand.dimension(),
        dc_term: 0.0,
        evaluations: (e.shifts * problem.n) as u64,
        alternatives: Vec::new(),
        analysis: None,
    }
}

/// Where a Walsh-form prediction's coefficients come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct WalshOrigin {
    /// Cells per axis of the level through which the sum is exact.
    pub cells_per_axis: usize,
    /// Digital shifts that measured the finer digits.
    pub shifts: usize,
}

impl fmt::Display for WalshOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Walsh coefficients exact through {} cells per axis (fast Walsh–Hadamard \
             transforms), the finer digits measured by {} digital shifts",
            self.cells_per_axis, self.shifts
        )
    }
}

/// The prediction for fixed patterns under a digital shift: a deterministic sampler's pattern,
/// or every given set (each equally likely).
pub(crate) fn predict_walsh(
    problem: &Problem<'_>,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let f = problem.integrand;
    check_box_moments(f)?;
    check_choices(params)?;
    let drawn;
    let patterns: &[PointSet] = match problem.patterns {
        Patterns::Sampler(s) => {
            drawn = [s.sample(problem.n, params.seed, 0)?];
            &drawn
        }
        Patterns::PointSets(sets) => sets,
    };
    if let Some(net) = f.product_form().and_then(|form| {
        linear_net_variance(
            &form,
            patterns,
            params.work_budget_seconds,
            params.budget.memory_bytes,
        )
    }) {
        return Ok(net_prediction(problem, patterns.len(), &net));
    }
    let e = digital_shift_variance(
        f,
        patterns,
        params.target_noise,
        params.seed,
        params.work_budget_seconds,
        &params.budget,
        progress,
    )?;
    let whose = whose_patterns(problem, patterns.len());
    let reason = format!(
        "{whose} under a random digital shift: the sum over Walsh frequencies of the \
         integrand's coefficients times the pattern's, exact through {} cells per axis, the \
         finer digits ({:.1}% of the value) measured by {} shifts of the remainder",
        e.cells_per_axis,
        100.0 * e.remainder / e.variance.max(f64::MIN_POSITIVE),
        e.shifts
    );
    Ok(walsh_prediction(problem, &e, reason))
}

/// Where an exact prediction of a linear net under a digital shift comes from
/// (the Walsh sum of a linear net's dual).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct WalshNetOrigin {
    /// Binary digits per axis of the net.
    pub digits: u32,
    /// Elements of the net's dual.
    pub dual_size: u64,
    /// Gauss–Legendre nodes per cell that folded the finer digits.
    pub nodes: usize,
}

impl fmt::Display for WalshNetOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Walsh coefficients of each axis's factor at every level, folded onto the net's {} \
             digits by {} Gauss–Legendre nodes per cell and summed over its dual ({} \
             frequencies)",
            self.digits, self.nodes, self.dual_size
        )
    }
}

/// What the patterns of a Walsh-form prediction are, for its reason: a sampler's fixed
/// pattern, or `sets` given point sets.
fn whose_patterns(problem: &Problem<'_>, sets: usize) -> String {
    match problem.kind() {
        Some(k) => format!("{k}'s fixed pattern"),
        None => format!("{sets} given point sets (each equally likely)"),
    }
}

/// The prediction of the exact route for linear nets and product integrands.
fn net_prediction(problem: &Problem<'_>, sets: usize, net: &NetVariance) -> Prediction {
    let each = if problem.kind().is_some() {
        ""
    } else {
        "each "
    };
    let reason = format!(
        "{} ({each}a linear digital net of {} digits per axis) on an integrand that is a product \
         of one factor per axis, under a random digital shift: the sum over the net's dual of \
         the factors' Walsh energies at every level, exact to quadrature",
        whose_patterns(problem, sets),
        net.digits
    );
    Prediction {
        variance: net.variance,
        randomization: Randomization::DigitalShift,
        route: Route {
            form: Form::Walsh,
            spectrum: SpectrumOrigin::WalshNet(WalshNetOrigin {
                digits: net.digits,
                dual_size: net.dual_size,
                nodes: net.nodes,
            }),
        },
        reason,
        budget: ErrorBudget {
            tabulation: 0.0,
            quadrature: net.quadrature + net.rounding,
            ..Default::default()
        },
        n: problem.n,
        dimension: problem.integrand.dimension(),
        dc_term: 0.0,
        evaluations: 0,
        alternatives: Vec::new(),
        analysis: None,
    }
}

/// Errors for the choices that belong to the shifted estimator's routes.
fn check_choices(params: &PredictParams) -> Result<()> {
    if params.kmax.is_some()
        || params.form == FormChoice::Polar
        || params.spectrum == SpectrumChoice::Closed
    {
        return Err(Error::OutsideValidity {
            route: "the polar form, a closed spectrum or a lattice extent".into(),
            reason: "a digital shift is predicted by the Walsh form, over Walsh frequencies; the \
                     polar form, the closed spectra and the lattice extent are for the toroidal \
                     shift (--randomization shift)"
                .into(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::{Ball, Polygon};
    use crate::rng::{realization_rng, Stream};

    /// `n` independent uniform points in `d` axes.
    fn uniform_pattern(n: usize, d: usize, seed: u64) -> PointSet {
        let mut rng = realization_rng(seed, 0, Stream::Points);
        let coords = (0..n * d).map(|_| crate::rng::uniform(&mut rng)).collect();
        PointSet::new(d, coords).unwrap()
    }

    /// A separable integrand's means read from its rows are the table's to the bit, so the
    /// remainder is unchanged; an integrand that is not separable keeps the table.
    #[test]
    fn axis_means_are_the_tables() {
        use crate::integrand::Gaussian;
        let cases: Vec<(Box<dyn Integrand>, Vec<usize>)> = vec![
            (
                Box::new(Gaussian::new(0.2, vec![0.2, 0.7], 1.5).unwrap()),
                vec![64, 32],
            ),
            (
                Box::new(Gaussian::new(0.1, vec![0.3, 0.6, 0.45], 1.0).unwrap()),
                vec![8, 16, 4],
            ),
        ];
        for (f, grid) in cases {
            // Halton's levels are not dyadic: the rows match there too.
            let halton_grid: Vec<usize> = [64, 27, 5][..grid.len()].to_vec();
            let (masses, _) = masses_and_constant_cells(f.as_ref(), &halton_grid);
            let cells = masses.len() as f64;
            let means: Vec<f64> = masses.iter().map(|m| m * cells).collect();
            assert!(AxisMeans::matching(f.as_ref(), &halton_grid, &means).is_some());
            let table = LevelTable::new(f.as_ref(), &grid);
            assert!(table.axis_means.is_some(), "{}", f.label());
            let with = table.remainder(f.as_ref(), &grid);
            let without = Remainder {
                axis_means: None,
                ..table.remainder(f.as_ref(), &grid)
            };
            let pattern = uniform_pattern(500, grid.len(), 3);
            let (a, b) = (with.as_drawn(&pattern), without.as_drawn(&pattern));
            assert!(
                a > 0.0 && a.to_bits() == b.to_bits(),
                "{}: {a:e} vs {b:e}",
                f.label()
            );
        }
        let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
        assert!(LevelTable::new(&disk, &[32, 32]).axis_means.is_none());
    }

    /// The indexed remainder visits exactly the points the direct one evaluates, in the same
    /// order: the same bits for every shift, with several points to a cell and in 2D and 3D.
    #[test]
    fn the_indexed_remainder_is_the_direct_one() {
        let shapes: Vec<(Box<dyn Integrand>, u32)> = vec![
            (Box::new(Ball::new(0.25, vec![0.15, 0.6], 2.0).unwrap()), 6),
            (Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap()), 7),
            (
                Box::new(Polygon::new(vec![[0.1, 0.2], [0.8, 0.35], [0.3, 0.9]], 1.0).unwrap()),
                5,
            ),
            (
                Box::new(Ball::new(0.3, vec![0.4, 0.55, 0.9], 1.0).unwrap()),
                4,
            ),
        ];
        for (f, level) in shapes {
            let d = f.dimension();
            let grid = vec![1usize << level; d];
            let cells: usize = grid.iter().product();
            let table = LevelTable::new(f.as_ref(), &grid);
            let constant = table.constant.as_deref().expect("a shape's constant cells");
            let varying = VaryingCells::new(constant, cells, level);
            assert!(!varying.cells.is_empty() && varying.cells.len() < cells);
            let remainder = table.remainder(f.as_ref(), &grid);
            let pattern = uniform_pattern(3 * cells, d, 11);
            let index = PointsByCell::new(&pattern, &grid);
            for unit in 0..64 {
                let mask = digital_shift(d, 5, unit);
                let direct = remainder.term(&pattern, &mask[..d]);
                let indexed = remainder.term_indexed((&pattern, &index), &varying, &mask[..d]);
                assert_eq!(
                    direct.to_bits(),
                    indexed.to_bits(),
                    "{}, shift {unit}",
                    f.label()
                );
                assert!(
                    direct > 0.0,
                    "{}, shift {unit}: no varying point",
                    f.label()
                );
            }
        }
    }
}
