//! Orthogonal array sampling (Jarosz et al. 2019, "Orthogonal array sampling for Monte Carlo
//! rendering"): Bose's orthogonal arrays of strength 2 with multi-jittered offsets, as the
//! `orthogonal` sampler of renderers draws them.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::{
    check_positive, check_supported, in_cell, perfect_root, random_permutation, uniform, Sampler,
    SamplerKind,
};
use crate::error::{Error, Result};
use crate::pointset::{PointSet, MAX_DIMENSION};
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// Orthogonal arrays: strata in every 2D projection, so no cube symmetry beyond the first pair
/// is claimed.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "orthogonal",
    description: "orthogonal array (Bose, strength 2) with multi-jittered offsets (Jarosz et al. \
                  2019): p × p strata in every 2D projection, N strata on every axis",
    dimensions: 2..=MAX_DIMENSION,
    count: CountRule::PrimeSquare,
    balanced_counts: CountRule::PrimeSquare,
    randomness: Randomness::Stratified,
    native_randomization: Randomization::None,
    cells: CellRule::Rows,
    cell_law: CellLaw::OrthogonalArray,
    closed_form: ClosedFormRule::None,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 14.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// `N = p²` points (`p` prime) from Bose's orthogonal array `OA(p², p + 1, p, 2)`: point
/// `(i₀, i₁)` (the base-`p` digits of its index) has the level `c_a = i₀ + (a − 1) i₁ mod p` in
/// column `a ≥ 2` (`c₀ = i₀`, `c₁ = i₁`), and any two columns take every pair of levels once.
/// Axis `a` places the point in its stratum `π_a(c_a)` of width `1/p`, in the sub-stratum
/// `σ_a(c_b)` of width `1/N` given by its partner column `b` (`a ± 1`), and uniformly within it,
/// with `π_a`, `σ_a` uniform random permutations per axis. Every 2D projection onto two
/// distinct columns is then jittered on `p × p` cells, and every 1D projection is stratified
/// on `N` intervals; in 2D it is a correlated multi-jitter. Columns exist up to `p + 1`, so
/// dimension `d` needs `p ≥ d − 1`.
///
/// # Examples
/// ```
/// use specvar::sampler::{OrthogonalArray, Sampler};
/// let oa = OrthogonalArray::new(3)?;
/// let points = oa.sample(25, 1, 0)?;
/// // Every axis is stratified on N = 25 intervals.
/// for axis in 0..3 {
///     let mut cells: Vec<usize> = points.points().map(|p| (p[axis] * 25.0) as usize).collect();
///     cells.sort();
///     assert_eq!(cells, (0..25).collect::<Vec<_>>());
/// }
/// assert!(oa.sample(24, 1, 0).is_err()); // not the square of a prime
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct OrthogonalArray {
    dimension: usize,
}

impl OrthogonalArray {
    /// Orthogonal array sampling in dimension `d` (2 to 8).
    ///
    /// # Errors
    /// A dimension outside 2 to 8.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

/// The level of point `(i0, i1)` in column `column` of Bose's array on `p` levels.
fn level(column: usize, i0: usize, i1: usize, p: usize) -> usize {
    match column {
        0 => i0,
        1 => i1,
        c => (i0 + (c - 1) * i1) % p,
    }
}

/// The column that gives axis `a` its sub-strata: its neighbour in the pairs (0, 1), (2, 3), ….
fn partner(a: usize) -> usize {
    a ^ 1
}

impl Sampler for OrthogonalArray {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::OrthogonalArray)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        check_positive(FACTS.name, self.dimension, n)?;
        if FACTS.count.admits(n, self.dimension) {
            return Ok(());
        }
        let nearest = SamplerKind::OrthogonalArray.nearest_count(n, self.dimension);
        Err(Error::UnsupportedCount {
            sampler: FACTS.name,
            n,
            dimension: self.dimension,
            rule: format!(
                "{} with p ≥ {} in {}D",
                FACTS.count,
                self.dimension.saturating_sub(1).max(2),
                self.dimension
            ),
            nearest: nearest.to_string(),
        })
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let (d, p) = (self.dimension, perfect_root(n, 2).unwrap_or(1));
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let strata: Vec<Vec<usize>> = (0..d).map(|_| random_permutation(&mut rng, p)).collect();
        let sub: Vec<Vec<usize>> = (0..d).map(|_| random_permutation(&mut rng, p)).collect();
        let mut coords = Vec::with_capacity(d * n);
        for i0 in 0..p {
            for i1 in 0..p {
                for a in 0..d {
                    let stratum = strata[a][level(a, i0, i1, p)];
                    let within = sub[a][level(partner(a), i0, i1, p)];
                    coords.push(in_cell(stratum * p + within, uniform(&mut rng), n));
                }
            }
        }
        Ok(PointSet::from_trusted(d, coords))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_pair_of_axes_is_jittered_on_p_by_p_cells_and_every_axis_on_n() {
        for (d, p) in [(2, 2), (3, 2), (3, 3), (4, 5), (8, 7)] {
            let n = p * p;
            let points = OrthogonalArray::new(d).unwrap().sample(n, 9, 1).unwrap();
            for a in 0..d {
                let mut intervals: Vec<usize> = points
                    .points()
                    .map(|x| (x[a] * n as f64) as usize)
                    .collect();
                intervals.sort();
                assert_eq!(intervals, (0..n).collect::<Vec<_>>(), "axis {a} at p = {p}");
                for b in a + 1..d {
                    let mut cells: Vec<usize> = points
                        .points()
                        .map(|x| (x[a] * p as f64) as usize * p + (x[b] * p as f64) as usize)
                        .collect();
                    cells.sort();
                    assert_eq!(
                        cells,
                        (0..n).collect::<Vec<_>>(),
                        "axes {a}, {b} at p = {p}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_count_rule_needs_enough_columns() {
        let oa = OrthogonalArray::new(8).unwrap();
        assert!(oa.check_count(25).is_err()); // p = 5 has 6 columns
        assert!(oa.check_count(49).is_ok());
        assert!(OrthogonalArray::new(2).unwrap().check_count(4).is_ok());
    }
}
