//! The FFT stage of a [`NufftPlan`]: the folded grid to the deconvolved half lattice
//! `k_last = 0..=K`.
//!
//! Rows (the last axis) are real: two rows ride in one complex FFT, `z = a + i b`, and
//! separate as `A(k) = (Z(k) + conj Z(-k)) / 2`, `B(k) = (Z(k) - conj Z(-k)) / 2i`; only
//! `k = 0..=K` is kept. The rows are transformed as the spreading completes them (see
//! `stream`). The other axes transform only the lines that crop keeps. Every pass stores its
//! output transposed, so that the next axis's lines are contiguous: they are transformed in
//! place, [`BATCH`] at a time, and each batch is cropped into the next layout (or, after the
//! first axis, written deconvolved) while it is in cache.

use super::ring::{Ring, BATCH};
use super::spread::fold_row;
use super::{NufftPlan, NufftScratch};
use num_complex::Complex64;
use std::ops::Range;

impl NufftPlan {
    /// Transforms the rows' half spectra in `scratch.rows` (from
    /// [`spread_rows`](Self::spread_rows)) along the other axes and calls `write(index, value)`
    /// for every frequency of the half `k_last = 0..=K` with its flat lattice index,
    /// deconvolved.
    pub(super) fn fft_stage(
        &self,
        scratch: &mut NufftScratch,
        mut write: impl FnMut(usize, Complex64),
    ) {
        let (g, keep) = (self.grid_size(), self.kmax + 1);
        match self.dimension {
            1 => {
                for (t, v) in scratch.rows[..keep].iter().enumerate() {
                    write(self.kmax + t, v * self.correction[self.kmax + t]);
                }
            }
            2 => {
                for first in (0..keep).step_by(BATCH) {
                    let lines = BATCH.min(keep - first);
                    let block = &mut scratch.rows[first * g..(first + lines) * g];
                    self.first_axis(block, &mut scratch.fft, first, None, &mut write);
                }
            }
            _ => {
                for o1 in 0..2 * self.kmax + 1 {
                    for first in (0..keep).step_by(BATCH) {
                        let lines = BATCH.min(keep - first);
                        let block = &mut scratch.spare[(o1 * keep + first) * g..][..lines * g];
                        self.first_axis(block, &mut scratch.fft, first, Some(o1), &mut write);
                    }
                }
            }
        }
    }

    /// The last axis, for the periodic rows `range` (in pairs from an even row; in 3D the rows
    /// of one plane): folds each row, transforms rows in pairs, keeps `k = 0..=K` of each in
    /// `scratch.rows`, transposed (value `t` of row `r` at `t · g + r`, `r` counted within
    /// the plane in 3D), and clears the rows while they are in cache.
    pub(super) fn transform_rows(&self, scratch: &mut NufftScratch, range: Range<usize>) {
        let (d, g, k) = (self.dimension, self.grid_size(), self.kmax);
        let (keep, rows) = (k + 1, g.pow(d as u32 - 1));
        let (stride, base) = match d {
            1 => (1, 0),
            2 => (g, 0),
            _ => (g, range.start - range.start % g),
        };
        debug_assert!(d < 3 || range.end <= base + g, "one plane at a time in 3D");
        let s = &mut *scratch;
        for first in range.clone().step_by(2 * BATCH) {
            let pairs = BATCH.min((range.end - first).div_ceil(2));
            for p in 0..pairs {
                let a = first + 2 * p;
                let (start_a, start_b) = (self.row_cells(s.ring, a), self.row_cells(s.ring, a + 1));
                let line = &mut s.batch[p * g..][..g];
                self.pack_pair(
                    &mut s.cells,
                    line,
                    start_a,
                    (a + 1 < rows).then_some(start_b),
                );
            }
            self.fft
                .process_with_scratch(&mut s.batch[..pairs * g], &mut s.fft);
            if rows == 1 {
                // 1D: the one row, alone in its line.
                let z = &s.batch[..g];
                for (t, out) in s.rows[..keep].iter_mut().enumerate() {
                    let mirror = if t == 0 { 0 } else { g - t };
                    *out = (z[t] + z[mirror].conj()) * 0.5;
                }
                continue;
            }
            // Grids are even (`choice::nice_size`): every row has its pair.
            debug_assert!(rows.is_multiple_of(2));
            let lines = &s.batch[..pairs * g];
            split_pairs(lines, g, keep, &mut s.rows, stride, first - base);
        }
    }

    /// Where the padded cells of periodic row `row` start in `scratch.cells`: the row's slab in
    /// the ring, then the row within the slab in 3D (in 1D the grid is the one row).
    fn row_cells(&self, ring: Option<Ring>, row: usize) -> usize {
        let (g, o, side) = (self.grid_size(), self.layout.offset, self.layout.side);
        match (self.dimension, ring) {
            (2, Some(ring)) => ring.start(row + o),
            (3, Some(ring)) => ring.start(row / g + o) + (row % g + o) * side,
            _ => 0,
        }
    }

    /// Folds the padded rows starting at `a` and `b` (if any) in `cells`, writes them into
    /// `line` as its real and imaginary parts, and clears them.
    fn pack_pair(&self, cells: &mut [f64], line: &mut [Complex64], a: usize, b: Option<usize>) {
        let side = self.layout.side;
        let Some(b) = b else {
            let cells_a = self.folded(&mut cells[a..][..side]);
            for (z, c) in line.iter_mut().zip(cells_a.iter()) {
                *z = Complex64::new(*c, 0.0);
            }
            cells_a.fill(0.0);
            return;
        };
        // Two distinct rows of the ring, in either order.
        let (row_a, row_b) = if a < b {
            let (low, high) = cells.split_at_mut(b);
            (&mut low[a..][..side], &mut high[..side])
        } else {
            let (low, high) = cells.split_at_mut(a);
            (&mut high[..side], &mut low[b..][..side])
        };
        let (cells_a, cells_b) = (self.folded(row_a), self.folded(row_b));
        for ((z, x), y) in line.iter_mut().zip(cells_a.iter()).zip(cells_b.iter()) {
            *z = Complex64::new(*x, *y);
        }
        cells_a.fill(0.0);
        cells_b.fill(0.0);
    }

    /// Folds the padding of one padded row onto its periodic cells and returns them.
    fn folded<'c>(&self, padded: &'c mut [f64]) -> &'c mut [f64] {
        fold_row(&self.layout, padded);
        &mut padded[self.layout.offset..][..self.grid_size()]
    }

    /// The FFT bin of lattice frequency `o - K`.
    fn bin(&self, o: usize) -> usize {
        let (g, k) = (self.grid_size(), self.kmax);
        if o < k {
            o + g - k
        } else {
            o - k
        }
    }

    /// In 3D, after the rows of plane `plane` (index along axis 0): transforms axis 1, whose
    /// lines (one per `t`) are contiguous in `scratch.rows`, and crops it into
    /// `scratch.spare` laid out `(o1, t, a0)`: lines along axis 0, contiguous for consecutive
    /// `t`. The plane's lines are in cache, and the writes of consecutive planes share theirs.
    pub(super) fn middle_plane(&self, scratch: &mut NufftScratch, plane: usize) {
        let (g, keep, side) = (self.grid_size(), self.kmax + 1, 2 * self.kmax + 1);
        let s = &mut *scratch;
        for first in (0..keep).step_by(BATCH) {
            let lines = BATCH.min(keep - first);
            let block = &mut s.rows[first * g..][..lines * g];
            self.fft.process_with_scratch(block, &mut s.fft);
            for (j, line) in block.chunks_exact(g).enumerate() {
                for o1 in 0..side {
                    s.spare[(o1 * keep + first + j) * g + plane] = line[self.bin(o1)];
                }
            }
        }
    }

    /// Transforms `block`, the lines along axis 0 of the last axis' frequencies `first..`
    /// (at frequency index `middle` of axis 1 in 3D), in place, and writes them deconvolved.
    fn first_axis(
        &self,
        block: &mut [Complex64],
        fft_scratch: &mut [Complex64],
        first: usize,
        middle: Option<usize>,
        write: &mut impl FnMut(usize, Complex64),
    ) {
        let (g, k) = (self.grid_size(), self.kmax);
        let side = 2 * k + 1;
        self.fft.process_with_scratch(block, fft_scratch);
        for o0 in 0..side {
            let bin = self.bin(o0);
            let (row, factor) = match middle {
                None => (o0, self.correction[o0]),
                Some(o1) => (o0 * side + o1, self.correction[o1] * self.correction[o0]),
            };
            for (j, line) in block.chunks_exact(g).enumerate() {
                let t = first + j;
                write(
                    row * side + k + t,
                    line[bin] * (factor * self.correction[k + t]),
                );
            }
        }
    }

    /// Writes the full lattice from the half `k_last = 0..=K` with `S(-k) = conj S(k)`.
    pub(super) fn unfold(&self, scratch: &mut NufftScratch, out: &mut [Complex64]) {
        let len = out.len();
        self.fft_stage(scratch, |i, v| {
            out[i] = v;
            // -k: flat index len - 1 - i.
            out[len - 1 - i] = v.conj();
        });
    }

    /// Writes `|S|² · scale` at flat indices `0..=dc`: each frequency of the half
    /// `k_last = 0..=K`, or its mirror `-k`, whichever comes first in lattice order.
    pub(super) fn unfold_half_power(
        &self,
        scratch: &mut NufftScratch,
        scale: f64,
        out: &mut [f64],
    ) {
        let len = self.output_len();
        self.fft_stage(scratch, |i, v| {
            out[i.min(len - 1 - i)] = v.norm_sqr() * scale
        });
    }
}

/// Separates the transforms of row pairs, `Z = A + i B` (`lines`, `g` values each), into
/// their rows' half spectra `A(t) = (Z(t) + conj Z(-t)) / 2`, `B(t) = (Z(t) - conj Z(-t)) / 2i`
/// for `t < keep`, written transposed: the rows of pair `p` at `t · stride + offset + 2p` and
/// the next cell, so that each frequency's writes are contiguous.
fn split_pairs(
    lines: &[Complex64],
    g: usize,
    keep: usize,
    out: &mut [Complex64],
    stride: usize,
    offset: usize,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, checked just above.
        unsafe { split_pairs_avx(lines, g, keep, out, stride, offset) };
        return;
    }
    split_pairs_any(lines, g, keep, out, stride, offset);
}

/// [`split_pairs_any`] compiled for AVX: two values per vector, the same operations, the
/// same bits.
///
/// # Safety
/// The CPU must support AVX.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
unsafe fn split_pairs_avx(
    lines: &[Complex64],
    g: usize,
    keep: usize,
    out: &mut [Complex64],
    stride: usize,
    offset: usize,
) {
    split_pairs_any(lines, g, keep, out, stride, offset);
}

#[inline(always)]
fn split_pairs_any(
    lines: &[Complex64],
    g: usize,
    keep: usize,
    out: &mut [Complex64],
    stride: usize,
    offset: usize,
) {
    assert!(keep <= g && lines.len().is_multiple_of(g));
    let pairs = lines.len() / g;
    for t in 0..keep {
        let mirror = if t == 0 { 0 } else { g - t };
        let cells = &mut out[t * stride + offset..][..2 * pairs];
        for (pair, z) in cells.chunks_exact_mut(2).zip(lines.chunks_exact(g)) {
            let (zk, zn) = (z[t], z[mirror].conj());
            pair[0] = (zk + zn) * 0.5;
            let diff = zk - zn;
            pair[1] = Complex64::new(diff.im * 0.5, -diff.re * 0.5);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX build of the pairs' separation gives the portable build's bits.
    #[test]
    fn avx_and_portable_separation_agree_bit_for_bit() {
        let (g, keep, pairs) = (30, 16, 3);
        // Values with full mantissas, from a fixed sequence.
        let lines: Vec<Complex64> = (0..pairs * g)
            .map(|i| {
                let x = (i as f64 * 0.618_033_988_749_895).fract();
                Complex64::new(x - 0.5, (x * 7.0).fract() / 3.0)
            })
            .collect();
        let (stride, offset) = (2 * pairs + 5, 2);
        let mut portable = vec![Complex64::new(0.0, 0.0); keep * stride + offset];
        split_pairs_any(&lines, g, keep, &mut portable, stride, offset);
        let mut dispatched = vec![Complex64::new(0.0, 0.0); portable.len()];
        split_pairs(&lines, g, keep, &mut dispatched, stride, offset);
        let bits = |v: &[Complex64]| -> Vec<(u64, u64)> {
            v.iter().map(|z| (z.re.to_bits(), z.im.to_bits())).collect()
        };
        assert_eq!(bits(&portable), bits(&dispatched));
        assert!(portable.iter().filter(|z| z.norm() > 0.0).count() >= keep * 2 * pairs - 2);
    }
}
