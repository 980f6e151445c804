//! White noise.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::ClosedForm;
use super::{check_supported, uniform, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::PointSet;
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// White noise: no correlation between points, so no reach.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "random",
    description: "white noise: independent uniform points",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Any,
    balanced_counts: CountRule::Any,
    randomness: Randomness::Independent,
    native_randomization: Randomization::None,
    cells: CellRule::Whole,
    cell_law: CellLaw::Fixed,
    closed_form: ClosedFormRule::Always(ClosedForm::WhiteNoise),
    known_alpha: Some(0.0),
    scaling: Scaling::Invariant,
    isotropic: true,
    symmetry: Symmetry::Cube,
    correlation_reach: 0.0,
    axis_strata: super::AxisStrata::Independent,
    cost_per_point_ns: 4.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// Independent uniform points: the reference sampler, with `E[P_S(k)] = 1` for all `k ≠ 0`.
#[derive(Debug, Clone, Copy)]
pub struct Random {
    dimension: usize,
}

impl Random {
    /// White noise in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

impl Sampler for Random {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Random)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let coords = (0..n * self.dimension).map(|_| uniform(&mut rng)).collect();
        Ok(PointSet::from_trusted(self.dimension, coords))
    }
}
