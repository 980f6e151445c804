//! The Kronecker sequence of Roberts' generalized golden ratio (the R_d sequence).

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::ClosedForm;
use super::{check_supported, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::{PointSet, MAX_DIMENSION};
use crate::randomization::Randomization;

/// The Kronecker sequence: fixed, so used under a random shift.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "kronecker",
    description:
        "Kronecker sequence frac(i alpha), alpha from x^(d+1) = x + 1 (R_d); deterministic",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Any,
    balanced_counts: CountRule::Any,
    randomness: Randomness::Deterministic,
    native_randomization: Randomization::Shift,
    cells: CellRule::None,
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::OfSampler,
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

/// The Kronecker sequence `x_i = frac(i α)`, `i = 0 … N-1`, with `α_j = φ_d^{-j}` (`j = 1 … d`)
/// and `φ_d` the positive root of `x^{d+1} = x + 1` (the golden ratio in 1D, the plastic
/// number in 2D): Roberts' R_d sequence. Deterministic: the seed and the realization are
/// ignored; Monte Carlo homogenizes it (a random start is the same thing).
///
/// `α` is held as 64-bit binary fractions and the points are computed in that fixed point,
/// `frac(i α) = (i · A mod 2^64) / 2^64` (then rounded once to a double), so the pattern is `N`
/// points of the Kronecker sequence of `A / 2^64` to the last bit, and its power spectrum is
/// the Fejér kernel [`super::fejer`] of `k·α`.
///
/// # Examples
/// ```
/// use specvar::sampler::{Kronecker, Sampler};
/// let r2 = Kronecker::new(2)?;
/// let alpha = r2.alpha();
/// assert!((alpha[0] - 0.7548776662466927).abs() < 1e-15); // 1 / plastic number
/// assert_eq!(r2.sample(1000, 0, 0)?.len(), 1000);
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Kronecker {
    dimension: usize,
    fractions: [u64; MAX_DIMENSION],
}

impl Kronecker {
    /// The R_d sequence in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self {
            dimension: d,
            fractions: generalized_golden_fractions(d),
        })
    }

    /// `α` as floating-point numbers.
    pub fn alpha(&self) -> Vec<f64> {
        self.fractions[..self.dimension]
            .iter()
            .map(|&a| a as f64 / 2f64.powi(64))
            .collect()
    }
}

/// `φ_d^{-j}` for `j = 1 … d` as 64-bit binary fractions, `φ_d` the root of `x^{d+1} = x + 1`
/// found by the fixed-point iteration `x ← (1 + x)^{1/(d+1)}` (a contraction near the root) in
/// `libm`'s arithmetic, so every platform gets the same bits.
fn generalized_golden_fractions(d: usize) -> [u64; MAX_DIMENSION] {
    let mut phi = 2.0f64;
    for _ in 0..200 {
        phi = libm::pow(1.0 + phi, 1.0 / (d as f64 + 1.0));
    }
    let mut fractions = [0u64; MAX_DIMENSION];
    let mut power = 1.0;
    for f in fractions.iter_mut().take(d) {
        power /= phi;
        // Every φ_d^{-j} lies in (0, 1): the product by 2^64 rounds to an integer below 2^64.
        *f = (power * 2f64.powi(64)) as u64;
    }
    fractions
}

impl Sampler for Kronecker {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Kronecker)
    }
    fn closed_form(&self, _n: usize) -> Option<ClosedForm> {
        Some(ClosedForm::Kronecker {
            alpha: self.fractions,
        })
    }
    fn sample(&self, n: usize, _seed: u64, _realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let d = self.dimension;
        let scale = 2f64.powi(-64);
        let mut coords = Vec::with_capacity(n * d);
        for i in 0..n as u64 {
            for &a in &self.fractions[..d] {
                coords.push(crate::pointset::wrap(i.wrapping_mul(a) as f64 * scale));
            }
        }
        Ok(PointSet::from_trusted(d, coords))
    }
}
