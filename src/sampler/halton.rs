//! Halton sequence with random digit permutations.

use super::facts::{
    CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling, Symmetry,
};
use super::{check_supported, random_permutation, Sampler, SamplerKind, ONE_MINUS_EPS};
use crate::error::Result;
use crate::pointset::{PointSet, MAX_DIMENSION};
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// Halton: each axis its own radical inverse, so only partly symmetric.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "halton",
    description: "Halton with random digit permutations",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Any,
    balanced_counts: CountRule::Any,
    randomness: Randomness::PermutedDigits,
    native_randomization: Randomization::None,
    cells: CellRule::None,
    closed_form: ClosedFormRule::None,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    cost_per_point_ns: 35.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: |_, _| 4096.0,
};

/// The base of each axis: the first primes.
pub(crate) const PRIMES: [u64; MAX_DIMENSION] = [2, 3, 5, 7, 11, 13, 17, 19];

/// The first N points of the Halton sequence (axis `j` in base `p_j`, the j-th prime), each
/// digit position of each axis scrambled by its own random permutation of `{0, …, p-1}`.
/// Digits beyond the index's length (zeros) are scrambled too, down to 2^-53, so the points
/// are uniform inside their elementary intervals; the stratification of the sequence is kept.
#[derive(Debug, Clone, Copy)]
pub struct Halton {
    dimension: usize,
}

impl Halton {
    /// Scrambled Halton in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

/// Digits needed in base `b` to reach below 2^-53.
fn digit_count(b: u64) -> usize {
    (53.0 / (b as f64).log2()).ceil() as usize
}

/// One axis's permuted digits as the values they add: `values[j b + a]` is digit `a` at
/// position `j` (least significant first) mapped through its permutation and weighted by
/// `b^-(j+1)`, the weight formed by repeated multiplication as a digit-by-digit sum forms it,
/// so that summing the values gives the same bits. Once the index's digits run out, every
/// further digit is 0, whose scrambled contribution is `tails[j]`
/// (`Σ_{m ≥ j} perms[m][0] b^-(m+1)`), so only `log_b(index)` digits are visited.
struct ScrambledAxis {
    base: u64,
    values: Vec<f64>,
    tails: Vec<f64>,
}

impl ScrambledAxis {
    fn new(b: u64, perms: &[Vec<usize>]) -> Self {
        let inv = 1.0 / b as f64;
        let mut scale = inv;
        let mut values = Vec::with_capacity(perms.len() * b as usize);
        for perm in perms {
            values.extend(perm.iter().map(|&d| d as f64 * scale));
            scale *= inv;
        }
        Self {
            base: b,
            values,
            tails: zero_digit_tails(b, perms),
        }
    }

    /// The scrambled radical inverse of `index`, the base a constant for the common bases
    /// (their divisions by a constant are multiplications).
    fn radical_inverse(&self, index: u64) -> f64 {
        match self.base {
            2 => self.digits_of::<2>(index),
            3 => self.digits_of::<3>(index),
            5 => self.digits_of::<5>(index),
            _ => self.digits_in(index, self.base),
        }
    }

    fn digits_of<const B: u64>(&self, index: u64) -> f64 {
        self.digits_in(index, B)
    }

    #[inline(always)]
    fn digits_in(&self, mut index: u64, b: u64) -> f64 {
        let positions = self.tails.len() - 1;
        let mut value = 0.0;
        let mut j = 0;
        while index != 0 && j < positions {
            let digit = (index % b) as usize;
            index /= b;
            value += self.values[j * b as usize + digit];
            j += 1;
        }
        (value + self.tails[j]).min(ONE_MINUS_EPS)
    }
}

/// `tails[j] = Σ_{m ≥ j} perms[m][0] b^-(m+1)`, with `tails[len] = 0`.
fn zero_digit_tails(b: u64, perms: &[Vec<usize>]) -> Vec<f64> {
    let inv = 1.0 / b as f64;
    let mut tails = vec![0.0; perms.len() + 1];
    for j in (0..perms.len()).rev() {
        tails[j] = tails[j + 1] + perms[j][0] as f64 * inv.powi(j as i32 + 1);
    }
    tails
}

impl Sampler for Halton {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Halton)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let d = self.dimension;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let perms: Vec<Vec<Vec<usize>>> = PRIMES[..d]
            .iter()
            .map(|&b| {
                (0..digit_count(b))
                    .map(|_| random_permutation(&mut rng, b as usize))
                    .collect()
            })
            .collect();
        let axes: Vec<ScrambledAxis> = PRIMES[..d]
            .iter()
            .zip(&perms)
            .map(|(&b, p)| ScrambledAxis::new(b, p))
            .collect();
        let mut coords = Vec::with_capacity(n * d);
        for i in 0..n as u64 {
            coords.extend(axes.iter().map(|axis| axis.radical_inverse(i)));
        }
        Ok(PointSet::from_trusted(d, coords))
    }
}
