//! Point sets that are linear digital nets in base 2 (up to a digital shift), and their duals.
//!
//! Write each coordinate with `p` binary digits, `u_l = x_l 2^p` (its first digit the most
//! significant bit), and a point as the `dp`-bit word of its axes' digits. A digital net of a
//! linear construction (Sobol', Niederreiter–Xing, any `(t, m, s)`-net built from generator
//! matrices) is a subspace of `GF(2)^{dp}`, and a digitally shifted one a coset of it. Its dual
//! is the set of words `κ` orthogonal to every point, `popcount(κ & u) ≡ 0 (mod 2)`: exactly
//! the Walsh frequencies (read through their first `p` digits per axis) at which the pattern's
//! Walsh sum `(1/N) Σ_j wal_κ(x_j)` is 1 in magnitude; it is 0 at every other one.

use crate::pointset::PointSet;
use crate::predict::strata::cells::cell_of;
use crate::quadrature::CompensatedSum;
use rayon::prelude::*;

/// The most binary digits per axis a net's coordinates may carry (beyond it the point is not
/// read as a finite net).
const MAX_DIGITS: u32 = 24;
/// Elements of the dual summed per parallel task (a fixed order: the same bits on any number
/// of threads).
const DUAL_CHUNK: u64 = 1 << 14;

/// A point set that is a coset of a linear subspace of `GF(2)^{dp}`: its digits and its dual.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct LinearNet {
    /// The axes.
    dimension: usize,
    /// Binary digits per axis.
    digits: u32,
    /// A basis of the dual, as `dp`-bit words (axis `l` in bits `l p .. (l + 1) p`).
    dual_basis: Vec<u64>,
}

/// The least `p` at which every point's digits past the `p`-th agree with the first point's,
/// axis by axis (`frac(x 2^p)` the same for every point: 0 for a net, the shift's finer digits
/// for a digitally shifted one), if at most [`MAX_DIGITS`]. Scaling by a power of 2 is exact,
/// so the comparison is too.
fn digit_depth(pattern: &PointSet) -> Option<u32> {
    let d = pattern.dimension();
    let first = pattern.points().next()?;
    if pattern.coords().iter().any(|x| !(0.0..1.0).contains(x)) {
        return None;
    }
    let mut p = 0;
    for x in pattern.points() {
        while (0..d).any(|l| {
            let scale = f64::from(1u32 << p);
            (x[l] * scale).fract() != (first[l] * scale).fract()
        }) {
            p += 1;
            if p > MAX_DIGITS {
                return None;
            }
        }
    }
    Some(p)
}

impl LinearNet {
    /// `pattern` as a linear net up to a digital shift, or `None` when it is not one (its
    /// points are not a coset of a subspace, or differ past [`MAX_DIGITS`] digits, or need
    /// more than 64 bits in all). A shift's digits past the `p`-th are common to every point:
    /// a further uniform digital shift absorbs them with the rest. Work `O(N (dp + log N))`.
    pub(crate) fn of(pattern: &PointSet) -> Option<Self> {
        let d = pattern.dimension();
        let p = digit_depth(pattern)?;
        let bits = d as u32 * p;
        if bits > u64::BITS {
            return None;
        }
        // A point's cell on the grid of 2^p cells per axis, axis l in its digits l p .. (l+1) p.
        let grid = vec![1usize << p; d];
        let mut keys: Vec<u64> = pattern.points().map(|x| cell_of(x, &grid) as u64).collect();
        // A digital shift moves the set by XOR with one word: undo it with the first point's.
        let origin = keys[0];
        keys.iter_mut().for_each(|k| *k ^= origin);
        let basis = echelon_basis(&keys);
        let rank = basis.iter().filter(|&&b| b != 0).count();
        // N distinct words in a span of 2^rank words are the whole span when N = 2^rank.
        keys.sort_unstable();
        keys.dedup();
        if rank >= usize::BITS as usize || keys.len() != 1 << rank || keys.len() != pattern.len() {
            return None;
        }
        Some(Self {
            dimension: d,
            digits: p,
            dual_basis: dual_basis(&basis, bits),
        })
    }

    /// Binary digits per axis.
    pub(crate) fn digits(&self) -> u32 {
        self.digits
    }

    /// The number of elements of the dual, zero included.
    pub(crate) fn dual_size(&self) -> u64 {
        1 << self.dual_basis.len()
    }

    /// Axis `l`'s digits of the word `kappa` (as a cell or frequency index at level `p`).
    pub(crate) fn axis_digits(&self, kappa: u64, l: usize) -> usize {
        ((kappa >> (l as u32 * self.digits)) & ((1u64 << self.digits) - 1)) as usize
    }

    /// `Σ term(κ)` over the dual's elements other than 0 (two sums at once), in Gray-code
    /// order within chunks summed in a fixed order. Terms should be non-negative: each sum is
    /// then accurate to a relative `dual_size · ε`.
    pub(crate) fn sum_over_dual(&self, term: impl Fn(u64) -> [f64; 2] + Sync) -> [f64; 2] {
        let size = self.dual_size();
        let chunks = size.div_ceil(DUAL_CHUNK);
        let parts: Vec<[f64; 2]> = (0..chunks)
            .into_par_iter()
            .map(|c| {
                let (start, end) = (c * DUAL_CHUNK, ((c + 1) * DUAL_CHUNK).min(size));
                let gray = start ^ (start >> 1);
                let mut kappa = (0..self.dual_basis.len())
                    .filter(|&b| gray >> b & 1 == 1)
                    .fold(0u64, |k, b| k ^ self.dual_basis[b]);
                let mut sum = if start == 0 { [0.0; 2] } else { term(kappa) };
                for t in start + 1..end {
                    kappa ^= self.dual_basis[t.trailing_zeros() as usize];
                    let [a, b] = term(kappa);
                    sum[0] += a;
                    sum[1] += b;
                }
                sum
            })
            .collect();
        let mut total = [CompensatedSum::default(), CompensatedSum::default()];
        for part in parts {
            total[0].add(part[0]);
            total[1].add(part[1]);
        }
        [total[0].value(), total[1].value()]
    }

    /// The axes.
    pub(crate) fn dimension(&self) -> usize {
        self.dimension
    }
}

/// A reduced echelon basis of the span of `words`, indexed by pivot (its highest bit): entry
/// `i` is 0 or the basis word whose highest bit is `i`, and no other word has bit `i` set.
fn echelon_basis(words: &[u64]) -> [u64; 64] {
    let mut basis = [0u64; 64];
    for &w in words {
        let mut v = w;
        while v != 0 {
            let top = 63 - v.leading_zeros() as usize;
            if basis[top] == 0 {
                basis[top] = v;
                break;
            }
            v ^= basis[top];
        }
    }
    // Clear each pivot from every other word, highest first: a lower pivot's word has no
    // higher bit, so later steps never bring a cleared pivot back.
    for i in (0..64).rev() {
        if basis[i] == 0 {
            continue;
        }
        for j in 0..64 {
            if j != i && basis[j] >> i & 1 == 1 {
                basis[j] ^= basis[i];
            }
        }
    }
    basis
}

/// A basis of the words of `bits` bits orthogonal to every word of `basis` (reduced echelon,
/// by pivot): one per free bit `j`, `e_j` plus the pivots whose word has bit `j`.
fn dual_basis(basis: &[u64; 64], bits: u32) -> Vec<u64> {
    (0..bits as usize)
        .filter(|&j| basis[j] == 0)
        .map(|j| {
            (0..64)
                .filter(|&i| basis[i] != 0 && basis[i] >> j & 1 == 1)
                .fold(1u64 << j, |v, i| v | 1u64 << i)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::{Halton, Sampler, SobolNet};

    /// The dual of a Sobol' net, against its definition: every element is orthogonal to every
    /// point, and the dual has `2^{dp} / N` elements (a subspace's dual's size).
    #[test]
    fn the_dual_of_a_sobol_net_is_orthogonal_to_it() {
        for (d, n) in [(1, 64), (2, 256), (3, 128)] {
            let pattern = SobolNet::new(d).unwrap().sample(n, 0, 0).unwrap();
            let net = LinearNet::of(&pattern).expect("a Sobol' net is linear");
            let p = net.digits();
            assert_eq!(1u64 << p, n as u64, "d {d}");
            assert_eq!(net.dual_size() * n as u64, 1u64 << (d as u32 * p));
            let visited = net.sum_over_dual(|kappa| {
                for x in pattern.points() {
                    let parity: u32 = (0..d)
                        .map(|l| {
                            ((x[l] * f64::from(1u32 << p)) as usize & net.axis_digits(kappa, l))
                                .count_ones()
                        })
                        .sum();
                    assert_eq!(parity % 2, 0, "d {d}, κ {kappa:b}");
                }
                [1.0, 0.0]
            });
            assert_eq!(visited[0], (net.dual_size() - 1) as f64, "d {d}");
        }
    }

    /// A digitally shifted net is still a net, with the same dual; the Sobol' sequence's first points short of a
    /// power of 2, and a Halton set, are not.
    #[test]
    fn only_cosets_of_subspaces_are_nets() {
        let pattern = SobolNet::new(2).unwrap().sample(128, 0, 0).unwrap();
        let plain = LinearNet::of(&pattern).unwrap();
        // A digital shift of every digit (the net's own and the 52 past them).
        let mask = crate::randomization::digital_shift(2, 7, 0);
        let coords: Vec<f64> = pattern
            .points()
            .flat_map(|x| (0..2).map(move |l| crate::randomization::xor_digits(x[l], mask[l])))
            .collect();
        let shifted = PointSet::new(2, coords).unwrap();
        assert_eq!(LinearNet::of(&shifted), Some(plain));
        let short = SobolNet::new(2).unwrap().sample(100, 0, 0).unwrap();
        assert!(LinearNet::of(&short).is_none());
        let halton = Halton::new(2).unwrap().sample(64, 0, 0).unwrap();
        assert!(LinearNet::of(&halton).is_none());
    }
}
