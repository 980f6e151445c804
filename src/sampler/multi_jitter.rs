//! Multi-jittered sampling (Chiu, Shirley and Wang 1994).

use super::cmj::near_square_factors;
use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::{check_supported, in_cell, random_permutation, uniform, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::PointSet;
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// Multi-jittered sampling.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "mj",
    description: "multi-jittered (Chiu et al. 1994): jittered and N-rooks, independent shuffles",
    dimensions: 2..=2,
    count: CountRule::Any,
    balanced_counts: CountRule::Strata,
    randomness: Randomness::Stratified,
    native_randomization: Randomization::None,
    cells: CellRule::Rows,
    cell_law: CellLaw::IndependentShuffles,
    closed_form: ClosedFormRule::None,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 30.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// `N = m × n` samples, one in each cell of the `m × n` grid (jittered) and one in each of the
/// `N` columns and `N` rows of width `1/N` (N-rooks). It starts from the canonical arrangement
/// (cell `(i, j)` takes sub-column `j` and sub-row `i`) and shuffles the sub-columns among the
/// cells of each column and the sub-rows among the cells of each row, every one by its own
/// permutation: the independent shuffles of Chiu et al., where correlated multi-jitter
/// ([`super::CorrelatedMultiJitter`]) shares one permutation.
///
/// # Examples
/// ```
/// use specvar::sampler::{MultiJitter, Sampler};
/// let p = MultiJitter::new(2)?.sample(24, 1, 0)?; // 4 × 6 cells
/// let mut columns: Vec<usize> = p.points().map(|x| (x[0] * 24.0) as usize).collect();
/// columns.sort_unstable();
/// assert_eq!(columns, (0..24).collect::<Vec<_>>());
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct MultiJitter;

impl MultiJitter {
    /// Multi-jittered sampling; only d = 2 exists.
    ///
    /// # Errors
    /// Any dimension other than 2.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self)
    }
}

impl Sampler for MultiJitter {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        2
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::MultiJitter)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        // m columns (x cells) of r rows (y cells); column i holds r sub-columns, row j holds m
        // sub-rows.
        let (m, r) = near_square_factors(n);
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let sub_x: Vec<Vec<usize>> = (0..m).map(|_| random_permutation(&mut rng, r)).collect();
        let sub_y: Vec<Vec<usize>> = (0..r).map(|_| random_permutation(&mut rng, m)).collect();
        let mut coords = Vec::with_capacity(2 * n);
        for j in 0..r {
            for i in 0..m {
                coords.push(in_cell(i * r + sub_x[i][j], uniform(&mut rng), n));
                coords.push(in_cell(j * m + sub_y[j][i], uniform(&mut rng), n));
            }
        }
        Ok(PointSet::from_trusted(2, coords))
    }
}
