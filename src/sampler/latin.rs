//! Latin hypercube (N-rooks) sampling.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::ClosedForm;
use super::{check_supported, in_cell, random_permutation, uniform, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::PointSet;
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// Latin hypercube sampling.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "lhs",
    description: "Latin hypercube (N-rooks): one point per row per axis",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Any,
    balanced_counts: CountRule::Any,
    randomness: Randomness::Stratified,
    native_randomization: Randomization::None,
    cells: CellRule::Rows,
    cell_law: CellLaw::Permutations,
    closed_form: ClosedFormRule::Always(ClosedForm::LatinHypercube),
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Cube,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 10.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// On every axis, the `N` points occupy the `N` intervals `[j/N, (j+1)/N)` once each, through an
/// independent random permutation per axis, uniformly jittered inside the interval.
#[derive(Debug, Clone, Copy)]
pub struct LatinHypercube {
    dimension: usize,
}

impl LatinHypercube {
    /// Latin hypercube sampling in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

impl Sampler for LatinHypercube {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::LatinHypercube)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let d = self.dimension;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let mut coords = vec![0.0; n * d];
        for axis in 0..d {
            let perm = random_permutation(&mut rng, n);
            for (i, row) in perm.into_iter().enumerate() {
                coords[i * d + axis] = in_cell(row, uniform(&mut rng), n);
            }
        }
        Ok(PointSet::from_trusted(d, coords))
    }
}
