//! Halton's points as drawn on any integrand: the digit supports through a tabulated level,
//! the finer digits measured.
//!
//! Every digit position `k` of every axis is mapped by its own uniform random permutation
//! (base `p` on that axis). Expand a function of the digits in a product basis that is
//! orthonormal per digit and whose first member is constant (Helmert's, [`helmert_transform`]):
//! a basis function's support `u` is the set of positions where it is not constant. Two
//! points whose digits agree at a position keep that agreement, and where they differ hold a
//! uniform pair of distinct digits, on which two non-constant members `e_r, e_s` have
//! `E[e_r(π a) e_s(π b)] = −δ_rs/(p − 1)`. With `w(u) = Π_{k∈u} (p_k − 1)` and
//! `Σ_{r≠0} e_r(a) e_r(b) = p [a = b] − 1`, the mean over the permutations of a pair's product
//! folds into a sum over the points' own basis values, and
//!
//! `Var μ = (1/N²) Σ_{u≠∅} A(u) B(u) / w(u)`,
//!
//! with `A(u)` the integrand's energy on support `u` and `B(u)` that of the points' counts,
//! both as sums of squared coefficients (`docs/theory.md`, "Halton as drawn"). It is the
//! digital shift's Walsh sum with each frequency's `|S_κ|²` replaced by its mean over the
//! frequencies of the same support.
//!
//! Split `f = f_L + g`, `f_L` its mean over the cells of a level of `p_l^{m_l}` cells per axis.
//! `f_L` depends on the level's digits only, so its part is the sum above over the supports
//! within the level, from the transforms of the cells' means and of the unscrambled points'
//! counts in the cells: exact. `g` has mean zero on every cell, and each point's digits past
//! the level are uniform given the level's permutations (their own permutations are
//! independent), so the cross term vanishes and `g`'s part, `E[((1/N) Σ_j g(X_j))²]`, is
//! measured on the sampler's own realizations; its standard error is the prediction's noise.
//! A level a few digits past the points' own leaves it a small part of the whole.

use super::halton_remainder::{draws_as, VaryingIndices};
use super::permuted_digits::{
    agreement, digit_bits, helmert_transform, packed_digits, pair_work_seconds, positions,
    support_of,
};
use crate::budget::Needs;
use crate::costs::CANDIDATE_SECONDS;
use crate::error::{Error, Result};
use crate::integrand::Integrand;
use crate::predict::strata::cell_moments::{
    check_box_moments, masses_and_constant_cells, CELL_ROUNDING,
};
use crate::predict::term_mean::mean_to_target_noise;
use crate::predict::walsh::forms::{AxisMeans, Remainder};
use crate::predict::{ErrorBudget, Form, PredictParams, Prediction, Route, SpectrumOrigin};
use crate::progress::{stage, Progress};
use crate::quadrature::CompensatedSum;
use crate::randomization::Randomization;
use crate::sampler::{Halton, Sampler, HALTON_BASES};
use crate::spectrum::written_zeros;
use rayon::prelude::*;
use serde::Serialize;
use std::fmt;

/// The most axes: the level's table is `Π p_l^{m_l}` cells, and its supports `2^{Σ m_l}`.
pub(crate) const MAX_LEVEL_AXES: usize = 3;
/// The most cells of the tabulated level, `2^24`: four arrays of at most 128 MiB (the cells'
/// means, their transform, a transpose's scratch and the points' counts).
const MAX_LEVEL_CELLS: usize = 1 << 24;
/// The most digit positions of the level over all axes: its supports, `2^20`, are summed in
/// tables of 8 MiB.
const MAX_SUPPORT_BITS: u32 = 20;
/// Cells per axis the level aims at, per point: past the points' own digits, so that the
/// finer digits' part is small (its share falls like the cells' width for a jump).
const CELLS_PER_POINT: usize = 16;
/// The share of the work budget the level's table may take.
const TABLE_SHARE: f64 = 0.25;
/// Realizations that measure the finer digits at first.
const INITIAL_REALIZATIONS: usize = 32;
/// Realizations the finer digits never exceed.
const MAX_REALIZATIONS: usize = 1 << 14;
/// Relative rounding of one Helmert stage (a `p`-point butterfly: `p` additions, a product,
/// a square root), per unit of `p`, in units of the machine epsilon.
const STAGE_ROUNDING_PER_DIGIT_VALUE: f64 = 2.0;

/// The tabulated level: digits per axis and the cells they make.
#[derive(Debug, Clone, PartialEq)]
struct Level {
    bases: Vec<usize>,
    digits: Vec<u32>,
    grid: Vec<usize>,
}

impl Level {
    /// Digits past `⌈log_p N⌉` on each axis until the cells per axis reach
    /// [`CELLS_PER_POINT`] `N` (on the binary axis, no finer than `dyadic`, the level where
    /// the integrand is constant on dyadic cells: its finer binary digits carry no energy and
    /// no remainder), then the finest axis coarsened until the table fits [`MAX_LEVEL_CELLS`]
    /// and its supports [`MAX_SUPPORT_BITS`].
    fn for_count(n: usize, d: usize, dyadic: Option<u32>) -> Self {
        let bases: Vec<usize> = HALTON_BASES[..d].iter().map(|&b| b as usize).collect();
        let target = n.saturating_mul(CELLS_PER_POINT);
        let digits: Vec<u32> = bases
            .iter()
            .map(|&p| match dyadic {
                Some(a) if p == 2 => positions(target.max(1), p).min(a.max(1)),
                _ => positions(target.max(1), p),
            })
            .collect();
        let grid = bases.iter().zip(&digits).map(|(&p, &m)| p.pow(m)).collect();
        let mut level = Self {
            bases,
            digits,
            grid,
        };
        while level.cells() > MAX_LEVEL_CELLS || level.stages() > MAX_SUPPORT_BITS {
            if !level.coarsen() {
                break;
            }
        }
        level
    }

    /// One digit fewer on the axis of the finest cells (of at least two digits); `false` when
    /// every axis is down to one digit.
    fn coarsen(&mut self) -> bool {
        let finest = (0..self.grid.len())
            .filter(|&l| self.digits[l] > 1)
            .max_by_key(|&l| self.grid[l]);
        let Some(l) = finest else {
            return false;
        };
        self.digits[l] -= 1;
        self.grid[l] /= self.bases[l];
        true
    }

    fn cells(&self) -> usize {
        self.grid.iter().product()
    }

    /// The butterfly stages of the transform: one per digit of every axis.
    fn stages(&self) -> u32 {
        self.digits.iter().sum()
    }

    /// Each axis's cells' supports, shifted to that axis's bits of a mask of `Σ m_l` bits
    /// (axis 0's first): a cell's support is the union over its axes.
    fn axis_supports(&self) -> Vec<Vec<u32>> {
        let mut shift = 0;
        (0..self.grid.len())
            .map(|l| {
                let axis = (0..self.grid[l])
                    .map(|c| (support_of(c, self.bases[l], self.digits[l]) as u32) << shift)
                    .collect();
                shift += self.digits[l];
                axis
            })
            .collect()
    }

    /// `1 / w(u) = Π_{k∈u} 1/(p_k − 1)` for every support `u`, each from the support without
    /// its lowest position.
    fn inverse_weights(&self) -> Vec<f64> {
        let factor: Vec<f64> = self
            .bases
            .iter()
            .zip(&self.digits)
            .flat_map(|(&p, &m)| std::iter::repeat_n(1.0 / (p - 1) as f64, m as usize))
            .collect();
        let mut weights = vec![1.0; 1usize << self.stages()];
        for u in 1..weights.len() {
            weights[u] = weights[u & (u - 1)] * factor[u.trailing_zeros() as usize];
        }
        weights
    }

    /// The relative rounding of the whole transform in the 2-norm: the stages' own, summed.
    fn transform_rounding(&self) -> f64 {
        let per_stage: f64 = self
            .bases
            .iter()
            .zip(&self.digits)
            .map(|(&p, &m)| m as f64 * (p + 2) as f64)
            .sum();
        STAGE_ROUNDING_PER_DIGIT_VALUE * f64::EPSILON * per_stage
    }
}

/// `values`, a table over `grid` (axis 0 fastest), transformed in place in Helmert's basis
/// along every digit of every axis (orthonormal: sums of squares are kept). Each axis is
/// transformed along its rows, then the table is transposed so that the next axis runs
/// fastest; after every axis the order is the original one.
fn level_transform(values: &mut Vec<f64>, level: &Level, scratch: &mut Vec<f64>) {
    let cells = values.len();
    for l in 0..level.grid.len() {
        let (side, p, m) = (level.grid[l], level.bases[l], level.digits[l]);
        values
            .par_chunks_mut(side)
            .for_each(|row| helmert_transform(row, p, m));
        transpose(values, cells / side, side, scratch);
        std::mem::swap(values, scratch);
    }
}

/// `out[j R + i] = values[i C + j]` for the `R × C` table `values` (rows of length `C`).
fn transpose(values: &[f64], rows: usize, columns: usize, out: &mut Vec<f64>) {
    const BLOCK: usize = 64;
    out.resize(values.len(), 0.0);
    out.par_chunks_mut(rows * BLOCK)
        .enumerate()
        .for_each(|(b, chunk)| {
            // Output rows b·BLOCK + r are input columns: read each input row's run of them.
            let width = chunk.len() / rows;
            for i in 0..rows {
                let run = &values[i * columns + b * BLOCK..][..width];
                for (r, &v) in run.iter().enumerate() {
                    chunk[r * rows + i] = v;
                }
            }
        });
}

/// `Σ_{c: supp c = u} v_c²` for every support `u` of `level`'s table `values`, in at most 16
/// parallel chunks (each with its own table of the supports' energies) added in a fixed order.
/// A cell's support is read from its axes' as the chunk runs along its rows.
fn support_energies(values: &[f64], level: &Level) -> Vec<f64> {
    let classes = 1usize << level.stages();
    let axes = level.axis_supports();
    let side = level.grid[0];
    // The support of row `r` (the axes past the first) of the table.
    let row_support = |mut r: usize| -> u32 {
        let mut mask = 0;
        for (l, axis) in axes.iter().enumerate().skip(1) {
            mask |= axis[r % level.grid[l]];
            r /= level.grid[l];
        }
        mask
    };
    let chunk = values.len().div_ceil(16).max(1 << 16);
    let parts: Vec<Vec<f64>> = values
        .par_chunks(chunk)
        .enumerate()
        .map(|(k, v)| {
            let start = k * chunk;
            let (mut column, mut row) = (start % side, start / side);
            let mut high = row_support(row);
            let mut energy = written_zeros(classes);
            for &x in v {
                energy[(axes[0][column] | high) as usize] += x * x;
                column += 1;
                if column == side {
                    (column, row) = (0, row + 1);
                    high = row_support(row);
                }
            }
            energy
        })
        .collect();
    let mut total = written_zeros(classes);
    for part in parts {
        total.iter_mut().zip(part).for_each(|(t, e)| *t += e);
    }
    total
}

/// The points' counts' energy on every support of the level, `B(u) = Σ_{supp r = u} ĥ_r²`
/// (the counts' coefficients `ĥ` in Helmert's basis), and what bounds its rounding.
struct CountEnergies {
    energies: Vec<f64>,
    rounding: CountRounding,
}

/// How far [`CountEnergies`] may be from the exact energies.
enum CountRounding {
    /// The counts transformed as a table: its coefficients within `eta` of their 2-norm, the
    /// counts' squares summing to `count_squares`.
    Table { eta: f64, count_squares: f64 },
    /// From the points' pairs: each `B(u)` within its entry.
    Pairs(Vec<f64>),
}

/// The level's counts' energies by the cheaper of the two ways: the table of counts transformed,
/// or the points' pairs ([`pair_count_energies`]).
fn count_energies(level: &Level, n: usize, scratch: &mut Vec<f64>) -> CountEnergies {
    if pairs_are_cheaper(level, n) {
        return pair_count_energies(level, n);
    }
    let mut counts = written_zeros(level.cells());
    for i in 0..n {
        counts[unscrambled_cell(i, level)] += 1.0;
    }
    let count_squares: f64 = counts.iter().map(|c| c * c).sum();
    level_transform(&mut counts, level, scratch);
    CountEnergies {
        energies: support_energies(&counts, level),
        rounding: CountRounding::Table {
            eta: level.transform_rounding(),
            count_squares,
        },
    }
}

/// Whether the counts' energies come from the points' pairs: their work is below the table's.
fn pairs_are_cheaper(level: &Level, n: usize) -> bool {
    pair_count_seconds(level, n) < table_count_seconds(level, n)
}

/// The work of the counts' energies by their table: the counts placed, transformed and summed.
fn table_count_seconds(level: &Level, n: usize) -> f64 {
    n as f64 * crate::costs::VARYING_POINT_SECONDS
        + level.cells() as f64 * crate::costs::HELMERT_BUTTERFLY_SECONDS * level.stages() as f64
}

/// The work of the counts' energies by the points' pairs: each pair's agreements on every axis,
/// then the transform of their counts.
fn pair_count_seconds(level: &Level, n: usize) -> f64 {
    let classes = (1usize << level.stages()) as f64;
    pair_work_seconds(n, level.grid.len()) / 2.0
        + classes * crate::costs::HELMERT_BUTTERFLY_SECONDS * level.stages() as f64
}

/// Roundings of one stage of [`pair_count_energies`]'s transform per output: a product, a
/// difference and a quotient.
const PAIR_STAGE_ROUNDINGS: f64 = 3.0;

/// The counts' energies from the points' pairs. Per digit position `k` (base `p_k`), two
/// points' digits agree or not, and `Σ_{r≠0} e_r(a) e_r(b) = δ_ab − 1/p`, `e_0(a) e_0(b) = 1/p`
/// (Helmert's basis is orthonormal), so
///
/// `B(u) = Σ_{i,j} Π_{k∈u} (δ_k(i,j) − 1/p_k) Π_{k∉u} 1/p_k`:
///
/// a product over positions of a 2 × 2 map from "agree" to "in the support", applied to the
/// number `C(g)` of ordered pairs whose agreement set is `g`. The counts are exact integers,
/// so their sum is the same on any thread count. Each stage rounds each output at most
/// [`PAIR_STAGE_ROUNDINGS`] times relative to the same map with the signs dropped (all its
/// inputs non-negative), so after `S` stages each `B(u)` is within `γ_{3S}` of that map's value.
fn pair_count_energies(level: &Level, n: usize) -> CountEnergies {
    let d = level.grid.len();
    let digits: Vec<Vec<u64>> = (0..d)
        .map(|l| packed_digits(n, level.bases[l], level.digits[l]))
        .collect();
    let bits: Vec<u32> = level.bases.iter().map(|&p| digit_bits(p)).collect();
    let shifts: Vec<u32> = (0..d).map(|l| level.digits[..l].iter().sum()).collect();
    let classes = 1usize << level.stages();
    let agreement_of = |i: usize, j: usize| -> usize {
        (0..d)
            .map(|l| agreement(digits[l][i], digits[l][j], level.digits[l], bits[l]) << shifts[l])
            .fold(0, |mask, axis| mask | axis)
    };
    // Integer counts add exactly: any split of the rows gives the same table.
    let rows_per_task = n.div_ceil(4 * rayon::current_num_threads()).max(1);
    let pairs: Vec<u64> = (0..n)
        .into_par_iter()
        .with_min_len(rows_per_task)
        .fold(
            || vec![0u64; classes],
            |mut counts, i| {
                counts[classes - 1] += 1;
                for j in i + 1..n {
                    counts[agreement_of(i, j)] += 2;
                }
                counts
            },
        )
        .reduce(
            || vec![0u64; classes],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                a
            },
        );
    let mut energies: Vec<f64> = pairs.iter().map(|&c| c as f64).collect();
    let mut magnitudes = energies.clone();
    let position_bases = level
        .bases
        .iter()
        .zip(&level.digits)
        .flat_map(|(&p, &m)| std::iter::repeat_n(p as f64, m as usize));
    for (k, p) in position_bases.enumerate() {
        let bit = 1usize << k;
        for a in (0..classes).filter(|a| a & bit == 0) {
            let (apart, agree) = (energies[a], energies[a | bit]);
            energies[a] = (apart + agree) / p;
            energies[a | bit] = ((p - 1.0) * agree - apart) / p;
            let (apart, agree) = (magnitudes[a], magnitudes[a | bit]);
            magnitudes[a] = (apart + agree) / p;
            magnitudes[a | bit] = ((p - 1.0) * agree + apart) / p;
        }
    }
    let roundings = PAIR_STAGE_ROUNDINGS * level.stages() as f64 * f64::EPSILON;
    let gamma = roundings / (1.0 - roundings);
    // The magnitudes' own rounding is as small again: `γ (1 + γ)` bounds the error.
    let errors = magnitudes
        .iter()
        .map(|m| gamma * (1.0 + gamma) * m)
        .collect();
    CountEnergies {
        energies,
        rounding: CountRounding::Pairs(errors),
    }
}

/// The cell of the unscrambled `i`-th Halton point on each axis of `level`: the first `m_l`
/// digits of the radical inverse, the index's lowest digits reversed, in exact integers.
fn unscrambled_cell(i: usize, level: &Level) -> usize {
    let (mut index, mut stride) = (0, 1);
    for l in 0..level.grid.len() {
        let p = level.bases[l];
        let (mut rest, mut c) = (i, 0);
        for _ in 0..level.digits[l] {
            c = c * p + rest % p;
            rest /= p;
        }
        index += c * stride;
        stride *= level.grid[l];
    }
    index
}

/// Halton as drawn on `f`: the exact part through the level, the finer digits measured.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LevelEstimate {
    /// The variance: the exact part plus the finer digits'.
    pub(crate) variance: f64,
    /// A bound on the rounding of the exact part.
    pub(crate) rounding: f64,
    /// The finer digits' standard error.
    pub(crate) noise: f64,
    /// The finer digits' part.
    pub(crate) remainder: f64,
    /// Cells per axis of the level.
    pub(crate) grid: Vec<usize>,
    /// Realizations that measured the finer digits.
    pub(crate) realizations: usize,
}

/// The work of [`halton_level_variance`] before its realizations, and of one realization.
fn work(f: &dyn Integrand, level: &Level, n: usize) -> (f64, f64) {
    let cells = level.cells() as f64;
    let means = cells
        * (crate::predict::strata::cell_moments::seconds_per_grid_cell(f)
            + crate::costs::HELMERT_BUTTERFLY_SECONDS * level.stages() as f64);
    let counts = table_count_seconds(level, n).min(pair_count_seconds(level, n));
    (
        means + counts,
        n as f64 * crate::costs::VARYING_POINT_SECONDS,
    )
}

/// The memory of [`halton_level_variance`]'s tables: the cells' means, their transform, a
/// transpose's scratch and, when they are transformed as a table, the points' counts; per
/// support, the energies' tables (16 parts and their sum) and the weights.
fn table_bytes(level: &Level, n: usize) -> f64 {
    let tables = if pairs_are_cheaper(level, n) {
        3.0
    } else {
        4.0
    };
    8.0 * (tables * level.cells() as f64 + 18.0 * (1usize << level.stages()) as f64)
}

/// The variance of `sampler`'s Halton points as drawn (`n` of them) on `f`, in 1 to 3 axes.
///
/// # Errors
/// More than [`MAX_LEVEL_AXES`] axes, an integrand without box moments, or work or memory
/// beyond the budget.
pub(crate) fn halton_level_variance(
    f: &dyn Integrand,
    sampler: &dyn Sampler,
    n: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<LevelEstimate> {
    let d = f.dimension();
    check_box_moments(f)?;
    if d > MAX_LEVEL_AXES || n == 0 {
        return Err(Error::Mismatch(format!(
            "Halton as drawn beyond a product integrand is predicted in 1 to {MAX_LEVEL_AXES} \
             axes with N ≥ 1"
        )));
    }
    let mut level = Level::for_count(n, d, f.dyadic_level());
    // The table takes at most a share of the work budget (a pixel's is a few milliseconds):
    // a coarser level leaves more to the finer digits' measure, which the rest pays for.
    while work(f, &level, n).0 > TABLE_SHARE * params.work_budget_seconds && level.coarsen() {}
    let (table_work, per_realization) = work(f, &level, n);
    params.budget.check(
        "Halton's digit supports through a level",
        Needs {
            memory_bytes: table_bytes(&level, n),
            work_seconds: table_work + INITIAL_REALIZATIONS as f64 * per_realization,
        },
        "lower N",
    )?;
    let (means, constant, exact) = stage(progress, "Halton's digit supports", 0, || {
        exact_part(f, &level, n)
    });
    let axis_means = AxisMeans::matching(f, &level.grid, &means);
    let finer = Remainder {
        f,
        means: &means,
        grid: &level.grid,
        constant: constant.as_deref(),
        axis_means: axis_means.as_ref(),
    };
    let varying = finer.varying();
    let evaluations = varying * n as f64 * crate::costs::REMAINDER_EVALUATION_SECONDS;
    // Where the integrand is constant on most cells, a realization's points in the others are
    // found from their indices, and no other point is drawn. The candidates are at most 3^d
    // a varying cell: tested on that bound first, which also bounds their memory (12 bytes
    // each, below 1.25 N of them) before the pass over the level that finds them.
    let cheaper = |draws: f64| draws * CANDIDATE_SECONDS < per_realization;
    let per_cell = (n as f64 / level.cells() as f64).ceil();
    let fewer_varying = cheaper(3f64.powi(d as i32) * varying * level.cells() as f64 * per_cell);
    let halton = Halton::new(d)?;
    let indexed = match (sampler.kind(), constant.as_deref()) {
        (Some(kind), Some(bits))
            if kind.facts().randomness == crate::sampler::Randomness::PermutedDigits
                && fewer_varying
                && draws_as(&halton, sampler, n, params.seed) =>
        {
            Some(VaryingIndices::new(
                halton,
                &level.grid,
                &level.digits,
                bits,
            ))
        }
        _ => None,
    }
    .filter(|v| cheaper(v.draws(n)));
    let each = evaluations
        + indexed
            .as_ref()
            .map_or(per_realization, |v| v.draws(n) * CANDIDATE_SECONDS);
    let remainder_of = |unit: usize| -> Result<f64> {
        match &indexed {
            Some(v) => Ok(v.as_drawn(&finer, n, params.seed, unit as u64)),
            None => Ok(finer.as_drawn(&sampler.sample(n, params.seed, unit as u64)?)),
        }
    };
    let spare = (params.work_budget_seconds - table_work).max(0.0);
    let max = ((spare / each) as usize).clamp(INITIAL_REALIZATIONS, MAX_REALIZATIONS);
    let remainder = mean_to_target_noise(
        "Halton's finer digits",
        (INITIAL_REALIZATIONS, max),
        params.target_noise,
        exact.variance,
        remainder_of,
        progress,
    )?;
    Ok(LevelEstimate {
        variance: exact.variance + remainder.variance,
        rounding: exact.rounding,
        noise: remainder.standard_error,
        remainder: remainder.variance,
        grid: level.grid,
        realizations: remainder.patterns,
    })
}

/// The exact part through the level and its rounding bound.
struct ExactPart {
    variance: f64,
    rounding: f64,
}

/// The cells' means, the constant cells, and the exact part `(1/N²) Σ_u A(u) B(u) / w(u)`.
///
/// Rounding: each transform is off by at most `η` of its 2-norm (`η` the stages' rounding,
/// plus the cells' own for the means). By Cauchy–Schwarz over the supports, with
/// `B(u)/(w(u) N²) ≤ 1/M` (a pair's product of `ρ`s is at most 1), the means' errors move the
/// sum by at most `2 √(V η² ‖F‖²/M) + η² ‖F‖²/M`, and the counts' by at most
/// `2 √(V max A η² ‖H‖²/N²) + max A η² ‖H‖²/N²` when their table is transformed, by
/// `Σ_u A(u) δB(u) / (w(u) N²)` when their energies come from the pairs (each within `δB(u)`).
fn exact_part(
    f: &dyn Integrand,
    level: &Level,
    n: usize,
) -> (Vec<f64>, Option<Vec<u64>>, ExactPart) {
    let cells = level.cells();
    let (masses, constant) = masses_and_constant_cells(f, &level.grid);
    let means: Vec<f64> = masses.into_iter().map(|m| m * cells as f64).collect();
    let mut scratch = Vec::with_capacity(cells);
    let mut transformed = means.clone();
    level_transform(&mut transformed, level, &mut scratch);
    let a = support_energies(&transformed, level);
    drop(transformed);
    let b = count_energies(level, n, &mut scratch);
    drop(scratch);
    let inverse_w = level.inverse_weights();
    let nf = n as f64;
    let mut sum = CompensatedSum::default();
    for u in 1..a.len() {
        sum.add(a[u] * b.energies[u] * inverse_w[u]);
    }
    let variance = (sum.value() / (nf * nf)).max(0.0);
    let eta_means = level.transform_rounding() + CELL_ROUNDING;
    let mean_squares: f64 = a[1..].iter().sum();
    let means_term = eta_means * eta_means * mean_squares / cells as f64;
    let counts_rounding = match b.rounding {
        CountRounding::Table { eta, count_squares } => {
            let max_a = a[1..].iter().copied().fold(0.0, f64::max);
            let term = max_a * eta * eta * count_squares / (nf * nf);
            2.0 * (variance * term).sqrt() + term
        }
        CountRounding::Pairs(errors) => {
            (1..a.len())
                .map(|u| a[u] * errors[u] * inverse_w[u])
                .sum::<f64>()
                / (nf * nf)
        }
    };
    let rounding = 2.0 * (variance * means_term).sqrt() + means_term + counts_rounding;
    (means, constant, ExactPart { variance, rounding })
}

/// Where a prediction of Halton as drawn through a level comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct PermutedLevelOrigin {
    /// Cells per axis of the level through which the sum is exact (the first `dimension`).
    pub cells_per_axis: [usize; MAX_LEVEL_AXES],
    /// Axes.
    pub dimension: usize,
    /// Realizations that measured the finer digits.
    pub realizations: usize,
}

impl fmt::Display for PermutedLevelOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "digit supports in Helmert's basis exact through {} cells, the finer digits \
             measured on {} realizations",
            grid_label(&self.cells_per_axis[..self.dimension]),
            self.realizations
        )
    }
}

/// `a × b` for a level's cells per axis.
fn grid_label(grid: &[usize]) -> String {
    let sides: Vec<String> = grid.iter().map(|c| c.to_string()).collect();
    sides.join(" × ")
}

/// The prediction of Halton as drawn on an integrand without a product form, or with one
/// whose pairs of points are beyond the work budget.
///
/// # Errors
/// As [`halton_level_variance`].
pub(crate) fn predict_halton_level(
    f: &dyn Integrand,
    sampler: &dyn Sampler,
    n: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let e = halton_level_variance(f, sampler, n, params, progress)?;
    let reason = format!(
        "halton as drawn (each digit position of each axis under its own random permutation): \
         the integrand's energy on each support of digits times the points' counts' energy on \
         it, the mean over a support's frequencies of a digital shift's sum, exact through {} \
         cells, the finer digits ({:.1}% of the value) measured on {} realizations",
        grid_label(&e.grid),
        100.0 * e.remainder / e.variance.max(f64::MIN_POSITIVE),
        e.realizations
    );
    Ok(Prediction {
        variance: e.variance,
        randomization: Randomization::None,
        route: Route {
            form: Form::Walsh,
            spectrum: SpectrumOrigin::PermutedLevel(PermutedLevelOrigin {
                cells_per_axis: std::array::from_fn(|l| e.grid.get(l).copied().unwrap_or(1)),
                dimension: e.grid.len(),
                realizations: e.realizations,
            }),
        },
        reason,
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise: e.noise,
            quadrature: e.rounding,
            ..Default::default()
        },
        n,
        dimension: f.dimension(),
        dc_term: 0.0,
        evaluations: (e.realizations * n) as u64,
        alternatives: Vec::new(),
        analysis: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The level's transform is orthonormal on a table of two bases: sums of squares kept, a
    /// constant only in coefficient 0, and the layout restored (a second table transformed
    /// alike has the same inner product).
    #[test]
    fn level_transform_is_orthonormal() {
        let level = Level {
            bases: vec![2, 3],
            digits: vec![3, 2],
            grid: vec![8, 9],
        };
        let cells = level.cells();
        let mut v: Vec<f64> = (0..cells)
            .map(|i| ((i * 7 + 3) % 11) as f64 - 4.0)
            .collect();
        let mut w: Vec<f64> = (0..cells)
            .map(|i| ((i * 5 + 1) % 13) as f64 - 6.0)
            .collect();
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let (vv, vw) = (dot(&v, &v), dot(&v, &w));
        let mut scratch = Vec::new();
        level_transform(&mut v, &level, &mut scratch);
        level_transform(&mut w, &level, &mut scratch);
        assert!((dot(&v, &v) - vv).abs() <= 1e-12 * vv);
        assert!((dot(&v, &w) - vw).abs() <= 1e-12 * vv);
        let mut c = vec![1.5; cells];
        level_transform(&mut c, &level, &mut scratch);
        assert!((c[0] - 1.5 * (cells as f64).sqrt()).abs() < 1e-12);
        assert!(c[1..].iter().all(|x| x.abs() < 1e-12));
    }

    /// One point is uniform: its variance is that of the cells' means at a uniform cell,
    /// `B(u) = w(u)/M` for every support.
    #[test]
    fn one_point_is_the_cells_variance() {
        let f = crate::integrand::Ball::new(0.3, vec![0.4, 0.55], 1.0).unwrap();
        let level = Level::for_count(1, 2, None);
        let (means, _, exact) = exact_part(&f, &level, 1);
        let mean = means.iter().sum::<f64>() / means.len() as f64;
        let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / means.len() as f64;
        assert!(
            (exact.variance - var).abs() <= 1e-12 * var,
            "{} vs {var}",
            exact.variance
        );
    }

    /// Standard errors of the finer digits' measure a difference from an exact answer may
    /// reach: a false alarm below one in 10^5 for a Gaussian error.
    const Z_TEST: f64 = 4.5;

    /// On product integrands the level's route meets the exact sum over the points' pairs of
    /// digit agreements (a route that shares only the integrand's factors), within its noise
    /// and both routes' bounds; N = 100 and 300 are powers of neither base. A work budget of
    /// one second keeps the level's table near `2^18` cells (the default's is `2^24`): the
    /// finer digits, measured, are then at most a tenth of the whole, so the exact part still
    /// carries the check.
    #[test]
    fn the_level_meets_the_pairs_on_products() {
        use crate::integrand::parse_integrand;
        let params = PredictParams {
            work_budget_seconds: 1.0,
            ..PredictParams::default()
        };
        for (text, d) in [
            ("gaussian:sigma=0.1,c=0.3;0.6", 2),
            ("polygon:0.2,0.3;0.7,0.3;0.7,0.8;0.2,0.8", 2),
            ("gaussian:sigma=0.15,c=0.3;0.6;0.45", 3),
        ] {
            let halton = crate::sampler::SamplerKind::Halton.build(d).unwrap();
            let f = parse_integrand(text).unwrap().build(d).unwrap();
            let form = f.product_form().unwrap();
            for n in [16, 100, 300] {
                let pairs =
                    crate::predict::digits::permuted_digits::halton_as_drawn_variance(&form, n);
                let level = halton_level_variance(
                    f.as_ref(),
                    halton.as_ref(),
                    n,
                    &params,
                    &crate::progress::Silent,
                )
                .unwrap();
                assert!(level.remainder <= 0.1 * level.variance);
                let allowed =
                    Z_TEST * level.noise + level.rounding + pairs.quadrature + pairs.rounding;
                assert!(
                    (level.variance - pairs.variance).abs() <= allowed,
                    "{text}, N = {n}: {:e} ± {:e} against {:e}",
                    level.variance,
                    level.noise,
                    pairs.variance
                );
            }
        }
    }

    /// The counts' energies from the points' pairs are those of their table transformed,
    /// support by support, within both ways' rounding bounds (the table's from its 2-norm:
    /// `|δB(u)| ≤ 2 √B(u) η ‖H‖ + η² ‖H‖²`), on levels finer and coarser than the points' own
    /// digits.
    #[test]
    fn pair_counts_are_the_table_transformed() {
        for (bases, digits, n) in [
            (vec![2usize, 3], vec![9u32, 6], 300),
            (vec![2, 3], vec![4, 3], 300),
            (vec![2, 3, 5], vec![5, 3, 2], 77),
        ] {
            let grid = bases.iter().zip(&digits).map(|(&p, &m)| p.pow(m)).collect();
            let level = Level {
                bases,
                digits,
                grid,
            };
            let pairs = pair_count_energies(&level, n);
            let CountRounding::Pairs(errors) = pairs.rounding else {
                panic!("the pairs' bound is per support")
            };
            let mut counts = written_zeros(level.cells());
            for i in 0..n {
                counts[unscrambled_cell(i, &level)] += 1.0;
            }
            let norm = counts.iter().map(|c| c * c).sum::<f64>().sqrt();
            level_transform(&mut counts, &level, &mut Vec::new());
            let table = support_energies(&counts, &level);
            let eta = level.transform_rounding();
            // Parseval: the energies sum to the counts' squares.
            let total: f64 = table.iter().sum();
            assert!((total - norm * norm).abs() <= 1e-12 * total);
            for (u, (&b, &t)) in pairs.energies.iter().zip(&table).enumerate() {
                let allowed = errors[u] + 2.0 * t.sqrt() * eta * norm + (eta * norm).powi(2);
                assert!(
                    (b - t).abs() <= allowed,
                    "{:?}, support {u}: {b} against the table's {t} (allowed {allowed:e})",
                    level.digits
                );
            }
        }
    }

    /// The unscrambled cells are those of the radical inverses: the first N points of base 2
    /// and base 3 fill a `2^a × 3^b` grid one to a cell when `N = 2^a 3^b`.
    #[test]
    fn unscrambled_points_stratify_their_grid() {
        let level = Level {
            bases: vec![2, 3],
            digits: vec![3, 2],
            grid: vec![8, 9],
        };
        let mut seen = [false; 72];
        for i in 0..72 {
            let c = unscrambled_cell(i, &level);
            assert!(!seen[c]);
            seen[c] = true;
        }
        // Point 1: x = 1/2 (cell 4 of 8), y = 1/3 (cell 3 of 9).
        assert_eq!(unscrambled_cell(1, &level), 4 + 8 * 3);
    }
}
