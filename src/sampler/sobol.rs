//! Sobol sequence with Owen (nested uniform) scrambling.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::{check_supported, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::{PointSet, MAX_DIMENSION};
use crate::randomization::Randomization;
use crate::rng::{splitmix64, Stream};

/// Owen-scrambled Sobol'.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "sobol",
    description: "Sobol (Joe-Kuo directions) with Owen scrambling",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Any,
    balanced_counts: CountRule::PowerOfTwo,
    randomness: Randomness::ScrambledNet,
    native_randomization: Randomization::None,
    cells: CellRule::Dyadic,
    cell_law: CellLaw::OwenScrambledNet,
    closed_form: ClosedFormRule::None,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 25.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: |_, _| 4096.0,
};

/// Primitive polynomials and initial direction numbers for axes 2 to 8, from Joe and Kuo's
/// `new-joe-kuo-6.21201` table: (degree s, coefficients a, initial m_1..m_s).
const JOE_KUO: [(u32, u32, &[u32]); MAX_DIMENSION - 1] = [
    (1, 0, &[1]),
    (2, 1, &[1, 3]),
    (3, 1, &[1, 3, 1]),
    (3, 2, &[1, 1, 1]),
    (4, 1, &[1, 1, 3, 3]),
    (4, 4, &[1, 3, 5, 13]),
    (5, 2, &[1, 1, 5, 5, 17]),
];

pub(super) const BITS: usize = 32;

/// The 32 direction numbers `v_k = m_k · 2^(32-k)` of an axis (axis 0 is van der Corput).
pub(super) fn direction_numbers(axis: usize) -> [u32; BITS] {
    let mut v = [0u32; BITS];
    if axis == 0 {
        for (k, vk) in v.iter_mut().enumerate() {
            *vk = 1 << (BITS - 1 - k);
        }
        return v;
    }
    let (s, a, m_init) = JOE_KUO[axis - 1];
    let s = s as usize;
    let mut m = [0u32; BITS];
    m[..s].copy_from_slice(m_init);
    for k in s..BITS {
        // m_k = 2 a_1 m_{k-1} ^ 4 a_2 m_{k-2} ^ ... ^ 2^s m_{k-s} ^ m_{k-s}
        let mut mk = m[k - s] ^ (m[k - s] << s);
        for j in 1..s {
            let a_j = (a >> (s - 1 - j)) & 1;
            if a_j == 1 {
                mk ^= m[k - j] << j;
            }
        }
        m[k] = mk;
    }
    for k in 0..BITS {
        v[k] = m[k] << (BITS - 1 - k);
    }
    v
}

/// The unscrambled 32-bit Sobol coordinate of `index` on one axis (sets are drawn by
/// [`flip_masks`], one XOR per point).
#[cfg(test)]
fn sobol_bits(index: u32, v: &[u32; BITS]) -> u32 {
    let mut x = 0;
    let mut i = index;
    let mut k = 0;
    while i != 0 {
        if i & 1 == 1 {
            x ^= v[k];
        }
        i >>= 1;
        k += 1;
    }
    x
}

/// `c_t = v_0 ^ … ^ v_t`: stepping from index `i - 1` to `i` flips the bits `0 … t` of the
/// index, `t` its trailing zeros, so `x(i) = x(i - 1) ^ c_t` (one XOR per point).
pub(super) fn flip_masks(v: &[u32; BITS]) -> [u32; BITS] {
    let mut c = [0u32; BITS];
    let mut acc = 0;
    for k in 0..BITS {
        acc ^= v[k];
        c[k] = acc;
    }
    c
}

/// Levels of the scrambling tree tabulated per set: at most `2^TABLE_LEVELS` entries (4 MiB).
const TABLE_LEVELS: usize = 20;

/// The flip of node `prefix` at level `b` of the scrambling tree of `key`.
fn node_flip(key: u64, b: usize, prefix: u64) -> u32 {
    (splitmix64(key ^ splitmix64(((b as u64) << 32) | prefix)) & 1) as u32
}

/// The scrambled top `levels` bits for every `levels`-bit prefix: one hash per node of the tree
/// instead of one per level of every point, with the flips [`owen_scramble`] applies.
fn scramble_table(key: u64, levels: usize) -> Vec<u32> {
    let mut table = vec![0u32];
    for b in 0..levels {
        let mut next = vec![0u32; 2 << b];
        for (p, &above) in table.iter().enumerate() {
            let flip = node_flip(key, b, p as u64);
            next[2 * p] = (above << 1) | flip;
            next[2 * p + 1] = (above << 1) | (1 ^ flip);
        }
        table = next;
    }
    table
}

/// One axis's scrambling for a set: its key, the levels where the set's prefixes are distinct,
/// and the tabulated top of the tree.
struct AxisScramble {
    key: u64,
    distinct: usize,
    tabulated: usize,
    table: Vec<u32>,
}

impl AxisScramble {
    fn new(key: u64, distinct: usize) -> Self {
        let tabulated = distinct.min(TABLE_LEVELS);
        Self {
            key,
            distinct,
            tabulated,
            table: scramble_table(key, tabulated),
        }
    }

    /// [`owen_scramble`]`(x, key, distinct)`, its top levels read from the table.
    fn apply(&self, x: u32) -> u64 {
        let t = self.tabulated;
        let mut out = if t == 0 {
            0
        } else {
            (self.table[(x >> (BITS - t)) as usize] as u64) << (53 - t)
        };
        for b in t..self.distinct {
            let bit =
                ((x >> (BITS - 1 - b)) & 1) ^ node_flip(self.key, b, (x >> (BITS - b)) as u64);
            out |= (bit as u64) << (53 - 1 - b);
        }
        out | uniform_tail(x, self.key, self.distinct)
    }
}

/// The scrambled bits below level `distinct`: independent uniform bits from one hash of the
/// point's prefix (see [`owen_scramble`]).
fn uniform_tail(x: u32, key: u64, distinct: usize) -> u64 {
    let prefix = if distinct == 0 {
        0
    } else {
        (x >> (BITS - distinct)) as u64
    };
    let below = 53 - distinct;
    let uniform = splitmix64(key ^ 0x5EED ^ splitmix64(((distinct as u64) << 40) | prefix));
    uniform >> (64 - below)
}

/// Owen scrambling of a 32-bit fraction, extended to 53 bits: bit `b` (from the top) is
/// flipped by a random bit that depends on the key and on all the bits above it, i.e. one
/// independent flip per node of the binary tree of elementary intervals; the bits below 2^-32
/// are uniform, as the scrambling of the infinite tail of zeros makes them.
///
/// From level `distinct` down, every point of the set has its own prefix (the first `2^L`
/// points of a Sobol axis have distinct `L`-bit prefixes), so each of its flips there is an
/// independent uniform bit of its own node: the scrambled bits below that level are independent
/// uniform bits, drawn from one hash of the point's prefix instead of one hash per level.
///
/// This per-level form defines the scrambling; sets are drawn with [`AxisScramble`], which
/// tabulates the top of the tree and gives the same bits.
#[cfg(test)]
fn owen_scramble(x: u32, key: u64, distinct: usize) -> u64 {
    let mut out = 0u64;
    for b in 0..distinct {
        let prefix = if b == 0 { 0 } else { (x >> (BITS - b)) as u64 };
        let bit = ((x >> (BITS - 1 - b)) & 1) ^ node_flip(key, b, prefix);
        out |= (bit as u64) << (53 - 1 - b);
    }
    out | uniform_tail(x, key, distinct)
}

/// Errors unless the Sobol' sequence has `n` points: 1 to `2^32 − 1` (32-bit indices).
pub(super) fn check_sobol_count(name: &'static str, d: usize, n: usize) -> Result<()> {
    super::check_positive(name, d, n)?;
    if n > u32::MAX as usize {
        return Err(crate::error::invalid("N", n, "at most 2^32 - 1 for Sobol"));
    }
    Ok(())
}

/// The first N points of the Sobol sequence (Joe–Kuo directions, up to 8 axes) with Owen
/// scrambling keyed by (seed, realization), and the bits below 2^-32 filled uniformly at random,
/// as the scrambling of the infinite tail of zeros would. Scrambling keeps the (t, m, s)-net
/// structure: the first 2^k points of axes 1 and 2 form a (0, k, 2)-net.
#[derive(Debug, Clone, Copy)]
pub struct Sobol {
    dimension: usize,
}

impl Sobol {
    /// Owen-scrambled Sobol in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self { dimension: d })
    }
}

impl Sampler for Sobol {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Sobol)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        check_sobol_count(self.name(), self.dimension, n)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let d = self.dimension;
        let base = splitmix64(seed ^ splitmix64(realization ^ ((Stream::Points as u64) << 56)));
        // Levels at which the N points' prefixes are all distinct: ⌈log2 N⌉ and below.
        let distinct = ((usize::BITS - (n - 1).leading_zeros()) as usize).min(BITS);
        let axes: Vec<([u32; BITS], AxisScramble)> = (0..d)
            .map(|a| {
                let key = splitmix64(base ^ a as u64);
                (
                    flip_masks(&direction_numbers(a)),
                    AxisScramble::new(key, distinct),
                )
            })
            .collect();
        let mut x = [0u32; MAX_DIMENSION];
        let mut coords = Vec::with_capacity(n * d);
        for i in 0..n as u32 {
            for (a, (masks, scramble)) in axes.iter().enumerate() {
                if i > 0 {
                    x[a] ^= masks[i.trailing_zeros() as usize];
                }
                // 53 bits, strictly below 1.
                let bits = scramble.apply(x[a]);
                coords.push(bits as f64 / (1u64 << 53) as f64);
            }
        }
        Ok(PointSet::from_trusted(d, coords))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_axis_starts_as_published() {
        // Unscrambled axis 2 of Sobol in natural (not Gray-code) order.
        let v = direction_numbers(1);
        let got: Vec<f64> = (0..8)
            .map(|i| sobol_bits(i, &v) as f64 / 2f64.powi(32))
            .collect();
        assert_eq!(got, vec![0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875]);
    }

    #[test]
    fn stepping_by_flip_masks_is_the_direct_sum() {
        for axis in 0..MAX_DIMENSION {
            let v = direction_numbers(axis);
            let masks = flip_masks(&v);
            let mut x = 0u32;
            for i in 0..5000u32 {
                if i > 0 {
                    x ^= masks[i.trailing_zeros() as usize];
                }
                assert_eq!(x, sobol_bits(i, &v), "axis {axis}, index {i}");
            }
        }
    }

    #[test]
    fn the_tabulated_tree_scrambles_as_the_per_level_form() {
        let mut state = 7u64;
        for distinct in [0, 1, 2, 7, 12, TABLE_LEVELS, TABLE_LEVELS + 3, BITS] {
            let key = splitmix64(distinct as u64 + 11);
            let scramble = AxisScramble::new(key, distinct);
            for _ in 0..2000 {
                state = splitmix64(state);
                let x = state as u32;
                assert_eq!(
                    scramble.apply(x),
                    owen_scramble(x, key, distinct),
                    "{distinct}"
                );
            }
        }
    }
}
