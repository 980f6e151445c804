//! Jittered (stratified) sampling.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::regular::{check_strata, for_each_cell};
use super::ClosedForm;
use super::{check_supported, in_cell, uniform, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::PointSet;
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// Jitter: points correlate only within one stratum's reach.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "jitter",
    description: "jittered: one uniform point in each of m^d strata",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Strata,
    balanced_counts: CountRule::Strata,
    randomness: Randomness::Stratified,
    native_randomization: Randomization::None,
    cells: CellRule::Strata,
    cell_law: CellLaw::Fixed,
    closed_form: ClosedFormRule::WithStrata(ClosedForm::Jitter),
    known_alpha: Some(2.0),
    scaling: Scaling::PerfectPowers,
    isotropic: false,
    symmetry: Symmetry::CubeWithSquareStrata,
    correlation_reach: 1.0,
    axis_strata: super::AxisStrata::Spacing,
    cost_per_point_ns: 8.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// One uniform point in each cell of a grid of [`super::strata`]: `N = m^d`, or in 2D a
/// near-square `a × b` rectangle (`96 = 12 × 8`). Its expected power spectrum at integer
/// `k ≠ 0` is `1 - Π_i sinc²(π k_i / m_i)` with `m_i` cells along axis `i`.
#[derive(Debug, Clone, Copy)]
pub struct Jitter {
    dimension: usize,
}

impl Jitter {
    /// Jittered sampling in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

impl Sampler for Jitter {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Jitter)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        check_strata(self.name(), self.dimension, n).map(|_| ())
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        let d = self.dimension;
        let cells = check_strata(self.name(), d, n)?;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let mut coords = vec![0.0; n * d];
        for_each_cell(&cells, |i, axis, cell| {
            coords[i * d + axis] = in_cell(cell, uniform(&mut rng), cells[axis]);
        });
        Ok(PointSet::from_trusted(d, coords))
    }
}
