//! Correlated multi-jittered sampling (Kensler 2013).

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::{check_supported, in_cell, random_permutation, uniform, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::PointSet;
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// Correlated multi-jitter: rows and columns are built differently.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "cmj",
    description: "correlated multi-jittered (Kensler 2013): jittered and N-rooks",
    dimensions: 2..=2,
    count: CountRule::Any,
    balanced_counts: CountRule::Strata,
    randomness: Randomness::Stratified,
    native_randomization: Randomization::None,
    cells: CellRule::Rows,
    cell_law: CellLaw::CorrelatedShuffles,
    closed_form: ClosedFormRule::None,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 8.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// `N = m × n` samples, one in each of the `m × n` cells (jittered) and one in each of the `N`
/// columns and `N` rows (N-rooks). The sub-stratum inside each cell comes from two permutations
/// shared by all rows and all columns (the "correlated" choice that lowers variance against
/// independent shuffles). `m` is the largest divisor of N not above `√N`, so any N is accepted.
#[derive(Debug, Clone, Copy)]
pub struct CorrelatedMultiJitter {
    dimension: usize,
}

impl CorrelatedMultiJitter {
    /// CMJ sampling; only d = 2 exists.
    ///
    /// # Errors
    /// Any dimension other than 2.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

/// The factorization `N = m × n` with `m ≤ n` as close to square as possible.
pub(crate) fn near_square_factors(n: usize) -> (usize, usize) {
    let mut m = (n as f64).sqrt().floor() as usize;
    while m > 1 && !n.is_multiple_of(m) {
        m -= 1;
    }
    let m = m.max(1);
    (m, n / m)
}

/// The two permutations of a CMJ pattern: the point of row `j` and column `i` lies in
/// sub-column `sub_x[j]` of its column and sub-row `sub_y[i]` of its row.
pub(crate) struct Shuffles {
    /// The sub-column of each of the `r` rows.
    pub(crate) sub_x: Vec<usize>,
    /// The sub-row of each of the `m` columns.
    pub(crate) sub_y: Vec<usize>,
}

impl Shuffles {
    /// The permutations of `n` points, the first draws of `rng`.
    fn draw(rng: &mut impl rand::Rng, n: usize) -> Self {
        let (m, r) = near_square_factors(n);
        let sub_x = random_permutation(rng, r);
        let sub_y = random_permutation(rng, m);
        Self { sub_x, sub_y }
    }

    /// The permutations of realization `realization` of `seed` at `n` points: those its
    /// pattern is drawn with, without its points.
    pub(crate) fn of_realization(n: usize, seed: u64, realization: u64) -> Self {
        Self::draw(&mut realization_rng(seed, realization, Stream::Points), n)
    }
}

impl Sampler for CorrelatedMultiJitter {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Cmj)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        // m columns (x cells), r rows (y cells).
        let (m, r) = near_square_factors(n);
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let Shuffles { sub_x, sub_y } = Shuffles::draw(&mut rng, n);
        let mut coords = Vec::with_capacity(2 * n);
        for j in 0..r {
            for i in 0..m {
                // Column i has r x-sub-strata; the point of row j takes sub_x[j].
                coords.push(in_cell(i * r + sub_x[j], uniform(&mut rng), n));
                coords.push(in_cell(j * m + sub_y[i], uniform(&mut rng), n));
            }
        }
        Ok(PointSet::from_trusted(2, coords))
    }
}
