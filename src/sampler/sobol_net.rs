//! The Sobol' net unscrambled, used under a random digital shift.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::sobol::{direction_numbers, flip_masks, BITS};
use super::{check_supported, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::{PointSet, MAX_DIMENSION};
use crate::randomization::Randomization;

/// The unscrambled Sobol' net: fixed, so used under a random digital shift.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "sobol-ds",
    description: "Sobol (Joe-Kuo directions) unscrambled, under a random digital shift",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Any,
    balanced_counts: CountRule::PowerOfTwo,
    randomness: Randomness::Deterministic,
    native_randomization: Randomization::DigitalShift,
    cells: CellRule::None,
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::None,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 5.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// The first N points of the Sobol' sequence (Joe–Kuo directions, up to 8 axes), unscrambled:
/// 32-bit fractions, the first `2^m` of which form a `(t, m, s)`-net (a `(0, m, 2)`-net on axes 1
/// and 2). Deterministic: the seed and the realization are ignored. Its native randomization is
/// a uniform digital shift (an XOR of every coordinate's binary digits with one random fraction
/// per axis), the estimator of Mitsuba's `ldsampler` and of a digitally shifted net, predicted
/// by the Walsh form (`docs/theory.md`, "Digital shifts").
///
/// # Examples
/// ```
/// use specvar::sampler::{Sampler, SobolNet};
/// let p = SobolNet::new(2)?.sample(4, 0, 0)?;
/// assert_eq!(p.coords(), &[0.0, 0.0, 0.5, 0.5, 0.25, 0.75, 0.75, 0.25]);
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct SobolNet {
    dimension: usize,
}

impl SobolNet {
    /// The unscrambled Sobol' net in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

impl Sampler for SobolNet {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::SobolNet)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        super::sobol::check_sobol_count(self.name(), self.dimension, n)
    }
    fn sample(&self, n: usize, _seed: u64, _realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let d = self.dimension;
        let masks: Vec<[u32; BITS]> = (0..d).map(|a| flip_masks(&direction_numbers(a))).collect();
        let mut x = [0u32; MAX_DIMENSION];
        let mut coords = Vec::with_capacity(n * d);
        let scale = (1u64 << BITS) as f64;
        for i in 0..n as u32 {
            for (a, m) in masks.iter().enumerate() {
                if i > 0 {
                    x[a] ^= m[i.trailing_zeros() as usize];
                }
                coords.push(x[a] as f64 / scale);
            }
        }
        Ok(PointSet::from_trusted(d, coords))
    }
}
