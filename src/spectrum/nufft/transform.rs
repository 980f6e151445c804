//! The FFT stage of a [`NufftPlan`]: the folded grid to the half lattice `k_last = 0..=K`.
//!
//! Rows (the last axis) are real: two rows ride in one complex FFT, `z = a + i b`, and
//! separate as `A(k) = (Z(k) + conj Z(-k)) / 2`, `B(k) = (Z(k) - conj Z(-k)) / 2i`; only
//! `k = 0..=K` is kept. The other axes transform only the lines that crop keeps. Lines go
//! through the FFT [`BATCH`] at a time, gathered into one contiguous buffer.

use super::spread::fold_row;
use super::{NufftPlan, NufftScratch};
use num_complex::Complex64;

/// Lines transformed together.
pub(super) const BATCH: usize = 16;

impl NufftPlan {
    /// Transforms the grid in `scratch.cells` (folded but for the last axis) and returns the
    /// half lattice, `(2K+1)^{d-1}` rows of `K + 1` values. Leaves the grid cleared.
    pub(super) fn fft_stage<'s>(&self, scratch: &'s mut NufftScratch) -> &'s [Complex64] {
        let (d, g, k) = (self.dimension, self.grid_size(), self.kmax);
        let keep = k + 1;
        self.rows(scratch);
        let s = &mut *scratch;
        match d {
            1 => &s.rows[..keep],
            2 => {
                self.columns(&s.rows, keep, 1, &mut s.spare, &mut s.batch, &mut s.fft);
                &s.spare[..]
            }
            _ => {
                // Axis 1 in every slab of axis 0, then axis 0 over the cropped planes.
                self.columns(&s.rows, keep, g, &mut s.spare, &mut s.batch, &mut s.fft);
                let plane = (2 * k + 1) * keep;
                self.columns(&s.spare, plane, 1, &mut s.rows, &mut s.batch, &mut s.fft);
                &s.rows[..(2 * k + 1) * plane]
            }
        }
    }

    /// The last axis: folds each row, transforms rows in pairs, keeps `k = 0..=K` of each in
    /// `scratch.rows`, and clears the grid row by row while it is in cache.
    fn rows(&self, scratch: &mut NufftScratch) {
        let (d, g, k) = (self.dimension, self.grid_size(), self.kmax);
        let (keep, rows) = (k + 1, g.pow(d as u32 - 1));
        let s = &mut *scratch;
        for first in (0..rows).step_by(2 * BATCH) {
            let pairs = BATCH.min((rows - first).div_ceil(2));
            for p in 0..pairs {
                let line = &mut s.batch[p * g..][..g];
                for (part, row) in [first + 2 * p, first + 2 * p + 1].into_iter().enumerate() {
                    if row >= rows {
                        line.iter_mut().for_each(|z| z.im = 0.0);
                        continue;
                    }
                    let start = self.layout.row_start(row) - self.layout.offset;
                    let padded = &mut s.cells[start..start + self.layout.side];
                    fold_row(&self.layout, padded);
                    let cells = &mut padded[self.layout.offset..][..g];
                    for (z, c) in line.iter_mut().zip(cells.iter()) {
                        if part == 0 {
                            z.re = *c;
                        } else {
                            z.im = *c;
                        }
                    }
                    cells.fill(0.0);
                }
            }
            self.fft
                .process_with_scratch(&mut s.batch[..pairs * g], &mut s.fft);
            for p in 0..pairs {
                let z = &s.batch[p * g..][..g];
                let (a, b) = (first + 2 * p, first + 2 * p + 1);
                for t in 0..keep {
                    let (zk, zn) = (z[t], z[(g - t) % g].conj());
                    s.rows[a * keep + t] = (zk + zn) * 0.5;
                    if b < rows {
                        // (zk - zn) / 2i
                        let diff = zk - zn;
                        s.rows[b * keep + t] = Complex64::new(diff.im * 0.5, -diff.re * 0.5);
                    }
                }
            }
        }
    }

    /// The FFT along the middle axis of `input`, a row-major `(outer, g, inner)` array; writes
    /// the frequencies `-K..=K` of the middle axis to `output` as `(outer, 2K+1, inner)`.
    /// Lines are gathered [`BATCH`] at a time (contiguous reads of `BATCH` values per grid
    /// row) and transformed in one call.
    fn columns(
        &self,
        input: &[Complex64],
        inner: usize,
        outer: usize,
        output: &mut [Complex64],
        batch: &mut [Complex64],
        fft_scratch: &mut [Complex64],
    ) {
        let (g, k) = (self.grid_size(), self.kmax);
        let side = 2 * k + 1;
        for o in 0..outer {
            for first in (0..inner).step_by(BATCH) {
                let lines = BATCH.min(inner - first);
                for t in 0..g {
                    let src = &input[(o * g + t) * inner + first..][..lines];
                    for (j, v) in src.iter().enumerate() {
                        batch[j * g + t] = *v;
                    }
                }
                self.fft
                    .process_with_scratch(&mut batch[..lines * g], fft_scratch);
                for t in 0..side {
                    let bin = (t + g - k) % g; // frequency t - K
                    let dst = &mut output[(o * side + t) * inner + first..][..lines];
                    for (j, v) in dst.iter_mut().enumerate() {
                        *v = batch[j * g + bin];
                    }
                }
            }
        }
    }

    /// Calls `write(index, value)` for every frequency of the half `k_last = 0..=K` with its
    /// flat lattice index, deconvolved.
    #[inline(always)]
    fn deconvolved(&self, half: &[Complex64], mut write: impl FnMut(usize, Complex64)) {
        let (d, k) = (self.dimension, self.kmax);
        let side = 2 * k + 1;
        for o in 0..side.pow(d as u32 - 1) {
            let mut factor = 1.0;
            let mut rest = o;
            for _ in 0..d - 1 {
                factor *= self.correction[rest % side];
                rest /= side;
            }
            let row = &half[o * (k + 1)..][..k + 1];
            for (t, v) in row.iter().enumerate() {
                write(o * side + k + t, v * (factor * self.correction[k + t]));
            }
        }
    }

    /// Writes the full lattice from the half `k_last = 0..=K` with `S(-k) = conj S(k)`.
    pub(super) fn unfold(&self, half: &[Complex64], out: &mut [Complex64]) {
        let len = out.len();
        self.deconvolved(half, |i, v| {
            out[i] = v;
            // -k: flat index len - 1 - i.
            out[len - 1 - i] = v.conj();
        });
    }

    /// Writes `|S|² · scale` at flat indices `0..=dc`: each frequency of the half
    /// `k_last = 0..=K`, or its mirror `-k`, whichever comes first in lattice order.
    pub(super) fn unfold_half_power(&self, half: &[Complex64], scale: f64, out: &mut [f64]) {
        let len = self.output_len();
        self.deconvolved(half, |i, v| out[i.min(len - 1 - i)] = v.norm_sqr() * scale);
    }
}
