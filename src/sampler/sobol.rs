//! Sobol sequence with Owen (nested uniform) scrambling.

use super::{check_supported, Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::{PointSet, MAX_DIMENSION};
use crate::rng::{splitmix64, Stream};

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

const BITS: usize = 32;

/// The 32 direction numbers `v_k = m_k · 2^(32-k)` of an axis (axis 0 is van der Corput).
fn direction_numbers(axis: usize) -> [u32; BITS] {
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

/// The unscrambled 32-bit Sobol coordinate of `index` on one axis.
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

/// Owen scrambling of a 32-bit fraction, extended to 53 bits: bit `b` (from the top) is
/// flipped by a random bit that depends on the key and on all the bits above it, i.e. one
/// independent flip per node of the binary tree of elementary intervals; the bits below 2^-32
/// are uniform, as the scrambling of the infinite tail of zeros makes them.
///
/// From level `distinct` down, every point of the set has its own prefix (the first `2^L`
/// points of a Sobol axis have distinct `L`-bit prefixes), so each of its flips there is an
/// independent uniform bit of its own node: the scrambled bits below that level are independent
/// uniform bits, drawn from one hash of the point's prefix instead of one hash per level.
fn owen_scramble(x: u32, key: u64, distinct: usize) -> u64 {
    let mut out = 0u64;
    for b in 0..distinct {
        let prefix = if b == 0 { 0 } else { (x >> (BITS - b)) as u64 };
        let node = splitmix64(key ^ splitmix64(((b as u64) << 32) | prefix));
        let bit = ((x >> (BITS - 1 - b)) & 1) ^ (node & 1) as u32;
        out |= (bit as u64) << (53 - 1 - b);
    }
    let prefix = if distinct == 0 {
        0
    } else {
        (x >> (BITS - distinct)) as u64
    };
    let below = 53 - distinct;
    let uniform = splitmix64(key ^ 0x5EED ^ splitmix64(((distinct as u64) << 40) | prefix));
    out | uniform >> (64 - below)
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
        check_supported("sobol", d, 1..=MAX_DIMENSION)?;
        Ok(Self { dimension: d })
    }
}

impl Sampler for Sobol {
    fn name(&self) -> &'static str {
        "sobol"
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::Sobol)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        super::check_positive(self.name(), self.dimension, n)?;
        if n > u32::MAX as usize {
            return Err(crate::error::invalid("N", n, "at most 2^32 - 1 for Sobol"));
        }
        Ok(())
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        self.check_count(n)?;
        let d = self.dimension;
        let base = splitmix64(seed ^ splitmix64(realization ^ ((Stream::Points as u64) << 56)));
        let axes: Vec<([u32; BITS], u64)> = (0..d)
            .map(|a| (direction_numbers(a), splitmix64(base ^ a as u64)))
            .collect();
        // Levels at which the N points' prefixes are all distinct: ⌈log2 N⌉ and below.
        let distinct = (usize::BITS - (n - 1).leading_zeros()) as usize;
        let mut coords = Vec::with_capacity(n * d);
        for i in 0..n as u32 {
            for (v, key) in &axes {
                // 53 bits, strictly below 1.
                let bits = owen_scramble(sobol_bits(i, v), *key, distinct.min(BITS));
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
}
