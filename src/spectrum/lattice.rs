//! Periodograms on the integer lattice: the direct engine and the naive reference.
//!
//! Frequencies are the integer vectors `k` with `|k_i| ≤ K`, stored row-major with the first
//! axis slowest: the value for `k` sits at `Σ_i (k_i + K) (2K+1)^{d-1-i}`.

use crate::pointset::PointSet;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::TAU;

/// Points per chunk of the direct engine: bounds the phase tables to a few MB.
const CHUNK: usize = 512;

/// The geometry of a `(2K+1)^d` frequency lattice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lattice {
    /// Dimension `d` (1 to 3).
    pub dimension: usize,
    /// Largest frequency `K` per axis.
    pub kmax: usize,
}

impl Lattice {
    /// Points per axis, `2K+1`.
    pub fn side(&self) -> usize {
        2 * self.kmax + 1
    }
    /// Number of frequencies, `(2K+1)^d`.
    pub fn len(&self) -> usize {
        self.side().pow(self.dimension as u32)
    }
    /// Always false: the lattice holds at least `k = 0`.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// The flat index of the DC frequency `k = 0` (the centre).
    pub fn dc_index(&self) -> usize {
        (self.len() - 1) / 2
    }
    /// The flat index of frequency `k` (length `d`), the inverse of
    /// [`frequency`](Self::frequency); `None` outside the lattice.
    pub fn index(&self, k: &[i64]) -> Option<usize> {
        let kmax = self.kmax as i64;
        if k.len() != self.dimension || k.iter().any(|c| c.abs() > kmax) {
            return None;
        }
        let side = self.side() as i64;
        Some(k.iter().fold(0i64, |acc, c| acc * side + c + kmax) as usize)
    }
    /// The frequency vector at flat index `i` (components beyond `d` are 0).
    pub fn frequency(&self, i: usize) -> [i64; 3] {
        let side = self.side();
        let mut k = [0i64; 3];
        let mut rest = i;
        for a in (0..self.dimension).rev() {
            k[a] = (rest % side) as i64 - self.kmax as i64;
            rest /= side;
        }
        k
    }
    /// `|k|` at flat index `i`.
    pub fn radius(&self, i: usize) -> f64 {
        let k = self.frequency(i);
        (k.iter().map(|&c| (c * c) as f64).sum::<f64>()).sqrt()
    }

    /// Calls `visit(i, |k|²)` for the flat indices `i = 0..count` in order: the frequencies
    /// are stepped like an odometer, without the divisions of [`frequency`](Self::frequency).
    /// `(|k|² as f64).sqrt()` is [`radius`](Self::radius) to the bit (integer sums below
    /// `2^53` are exact in either order).
    pub fn for_each_squared_radius(&self, count: usize, mut visit: impl FnMut(usize, i64)) {
        let (d, k) = (self.dimension, self.kmax as i64);
        let mut c = [0i64; 3];
        c[..d].fill(-k);
        for i in 0..count.min(self.len()) {
            visit(i, c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            for a in (0..d).rev() {
                if c[a] < k {
                    c[a] += 1;
                    break;
                }
                c[a] = -k;
            }
        }
    }
}

/// Per-axis phase tables of the direct engine, reused across calls (see [`direct_sums_into`]).
#[derive(Debug, Clone, Default)]
pub struct PhaseTables {
    axes: [Vec<Complex64>; 3],
}

/// Per-axis phase tables `e^{-2πi k x}` for `k = -K..=K` of the points `first..first + count`,
/// built by complex multiplication: two `sin`/`cos` per point and axis, none per frequency.
fn phase_table(
    points: &PointSet,
    first: usize,
    count: usize,
    axis: usize,
    kmax: usize,
    out: &mut Vec<Complex64>,
) {
    let side = 2 * kmax + 1;
    out.clear();
    out.resize(count * side, Complex64::new(0.0, 0.0));
    out.par_chunks_mut(side).enumerate().for_each(|(j, row)| {
        let x = points.point(first + j)[axis];
        let step = Complex64::from_polar(1.0, -TAU * x);
        // Start at k = -K: e^{+2πi K x}. Re-anchor every 64 steps to bound rounding drift.
        let mut e = Complex64::from_polar(1.0, TAU * kmax as f64 * x);
        for (t, slot) in row.iter_mut().enumerate() {
            if t > 0 && t % 64 == 0 {
                e = Complex64::from_polar(1.0, -TAU * (t as f64 - kmax as f64) * x);
            }
            *slot = e;
            e *= step;
        }
    });
}

/// The exact sampling sums `Σ_j e^{-2πi k·x_j}` on the lattice by the phase recurrence,
/// parallel over the first frequency axis. Uses `S(-k) = conj S(k)` to compute half.
pub fn direct_sums(points: &PointSet, kmax: usize) -> Vec<Complex64> {
    let len = Lattice {
        dimension: points.dimension(),
        kmax,
    }
    .len();
    let mut sums = vec![Complex64::new(0.0, 0.0); len];
    direct_sums_into(points, kmax, &mut PhaseTables::default(), &mut sums);
    sums
}

/// As [`direct_sums`], into `sums` (length `(2K+1)^d`), with `tables` reused across calls.
///
/// # Panics
/// If `sums` has another length.
pub fn direct_sums_into(
    points: &PointSet,
    kmax: usize,
    tables: &mut PhaseTables,
    sums: &mut [Complex64],
) {
    let d = points.dimension();
    let lattice = Lattice { dimension: d, kmax };
    assert_eq!(sums.len(), lattice.len(), "direct_sums_into: output length");
    let side = lattice.side();
    let row = side.pow(d as u32 - 1);
    sums.fill(Complex64::new(0.0, 0.0));
    for first in (0..points.len()).step_by(CHUNK) {
        let count = CHUNK.min(points.len() - first);
        for a in 0..d {
            phase_table(points, first, count, a, kmax, &mut tables.axes[a]);
        }
        let tables = &tables.axes;
        if d == 1 {
            // One axis: parallel over blocks of frequencies, points innermost per block.
            sums[kmax..]
                .par_chunks_mut(256)
                .enumerate()
                .for_each(|(b, out)| {
                    let start = kmax + b * 256;
                    for j in 0..count {
                        let row = &tables[0][j * side + start..j * side + start + out.len()];
                        for (o, e) in out.iter_mut().zip(row) {
                            *o += e;
                        }
                    }
                });
            continue;
        }
        // Rows t0 ≥ K (k_0 ≥ 0); the others follow by symmetry below.
        sums[kmax * row..]
            .par_chunks_mut(row)
            .enumerate()
            .for_each(|(r, out)| {
                let t0 = r + kmax;
                for j in 0..count {
                    let e0 = tables[0][j * side + t0];
                    match d {
                        2 => {
                            let e1 = &tables[1][j * side..(j + 1) * side];
                            for (o, e) in out.iter_mut().zip(e1) {
                                *o += e0 * e;
                            }
                        }
                        _ => {
                            let e1 = &tables[1][j * side..(j + 1) * side];
                            let e2 = &tables[2][j * side..(j + 1) * side];
                            for (t1, plane) in out.chunks_exact_mut(side).enumerate() {
                                let a = e0 * e1[t1];
                                for (o, e) in plane.iter_mut().zip(e2) {
                                    *o += a * e;
                                }
                            }
                        }
                    }
                }
            });
    }
    // S(-k) = conj S(k): the flat index of -k is len - 1 - index(k).
    let len = lattice.len();
    for i in 0..kmax * row {
        sums[i] = sums[len - 1 - i].conj();
    }
}

/// Converts sampling sums to the power spectrum `|S|²/N`.
pub fn power_from_sums(sums: &[Complex64], n: usize) -> Vec<f64> {
    sums.iter().map(|s| s.norm_sqr() / n as f64).collect()
}

/// The periodogram by one `sin`/`cos` pair per point and frequency, parallel over
/// frequencies. This is the reference that faster engines are measured against (it is the
/// method of the common direct-DFT tools); it is slow by design.
pub fn naive_periodogram(points: &PointSet, kmax: usize) -> Vec<f64> {
    let lattice = Lattice {
        dimension: points.dimension(),
        kmax,
    };
    (0..lattice.len())
        .into_par_iter()
        .map(|i| {
            let k = lattice.frequency(i);
            let (mut re, mut im) = (0.0, 0.0);
            for p in points.points() {
                let phase: f64 = p.iter().zip(&k).map(|(x, &kk)| kk as f64 * x).sum();
                let (s, c) = (-TAU * phase).sin_cos();
                re += c;
                im += s;
            }
            (re * re + im * im) / points.len() as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The odometer visits every index once, in order, with the radius of `frequency`.
    #[test]
    fn squared_radii_follow_the_flat_order() {
        for (dimension, kmax) in [(1, 7), (2, 5), (3, 3)] {
            let lattice = Lattice { dimension, kmax };
            let mut next = 0;
            lattice.for_each_squared_radius(lattice.len(), |i, r2| {
                assert_eq!(i, next);
                assert_eq!((r2 as f64).sqrt().to_bits(), lattice.radius(i).to_bits());
                next += 1;
            });
            assert_eq!(next, lattice.len());
            let mut partial = 0;
            lattice.for_each_squared_radius(lattice.len() / 2 + 1, |_, _| partial += 1);
            assert_eq!(partial, lattice.len() / 2 + 1);
        }
    }
}
