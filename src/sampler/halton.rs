//! Halton sequence with random digit permutations.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
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
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::None,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
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

/// One realization of the scrambled sequence: its axes' permutations, from which any point is
/// drawn by its index alone, with the same bits as [`Sampler::sample`] gives it.
pub(crate) struct HaltonRealization {
    axes: Vec<ScrambledAxis>,
}

impl HaltonRealization {
    /// Point `index`'s coordinates, into `out` (its first `d` entries).
    pub(crate) fn point(&self, index: u64, out: &mut [f64]) {
        for (x, axis) in out.iter_mut().zip(&self.axes) {
            *x = axis.radical_inverse(index);
        }
    }

    /// Axis `a`'s cell among `b^m` (`b` its base) for each residue of the index modulo `b^m`:
    /// the points whose indices share that residue all lie in that cell (up to rounding at its
    /// sides: a point is the sum of its digits' values in floating point), and distinct
    /// residues make distinct cells.
    pub(crate) fn leading_cells(&self, a: usize, m: u32) -> Vec<usize> {
        self.axes[a].leading_cells(m)
    }
}

impl Halton {
    /// Realization `realization` of `seed`: every digit position's permutation on every axis.
    pub(crate) fn realization(&self, seed: u64, realization: u64) -> HaltonRealization {
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let axes = PRIMES[..self.dimension]
            .iter()
            .map(|&b| {
                let perms = (0..digit_count(b))
                    .map(|_| random_permutation(&mut rng, b as usize))
                    .collect();
                ScrambledAxis::new(b, perms)
            })
            .collect();
        HaltonRealization { axes }
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
/// The permutations themselves are kept for [`leading_cells`](Self::leading_cells).
struct ScrambledAxis {
    base: u64,
    values: Vec<f64>,
    tails: Vec<f64>,
    perms: Vec<Vec<usize>>,
}

impl ScrambledAxis {
    fn new(b: u64, perms: Vec<Vec<usize>>) -> Self {
        let inv = 1.0 / b as f64;
        let mut scale = inv;
        let mut values = Vec::with_capacity(perms.len() * b as usize);
        for perm in &perms {
            values.extend(perm.iter().map(|&d| d as f64 * scale));
            scale *= inv;
        }
        Self {
            base: b,
            values,
            tails: zero_digit_tails(b, &perms),
            perms,
        }
    }

    /// For each residue `r < b^m` of the index, the cell of `b^m` cells that its point's
    /// first `m` permuted digits make, `Σ_{j<m} π_j(r_j) b^{m−1−j}`, in integers (the index's
    /// first `m` digits are `r`'s; at most the digits this axis permutes).
    fn leading_cells(&self, m: u32) -> Vec<usize> {
        let b = self.base as usize;
        let m = (m as usize).min(self.perms.len());
        let mut cells = vec![0usize; b.pow(m as u32)];
        for (r, cell) in cells.iter_mut().enumerate() {
            let mut rest = r;
            for perm in &self.perms[..m] {
                *cell = *cell * b + perm[rest % b];
                rest /= b;
            }
        }
        cells
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
        let axes = self.realization(seed, realization).axes;
        let mut coords = Vec::with_capacity(n * self.dimension);
        for i in 0..n as u64 {
            coords.extend(axes.iter().map(|axis| axis.radical_inverse(i)));
        }
        Ok(PointSet::from_trusted(self.dimension, coords))
    }
}
