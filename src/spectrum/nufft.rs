//! A type-1 non-uniform FFT: `S(k) = Σ_j e^{-2πi k·x_j}` on the lattice `|k_i| ≤ K`.
//!
//! As in FINUFFT (Barnett, Magland and af Klinteberg 2019): spread every point onto a grid
//! of `n_f ≥ 2(2K+1)` cells per axis with the "exponential of semicircle" kernel
//! `φ(z) = exp(β(√(1-z²) - 1))`, `|z| ≤ 1`, of width `w` cells and `β = 2.30 w`; take the FFT
//! of the grid; keep the frequencies `|k| ≤ K`; divide by the kernel's Fourier transform,
//! computed by Gauss–Legendre quadrature. The width follows the tolerance:
//! `w = ⌈log10(1/ε)⌉ + 1` (at most 16). The error relative to `Σ|c_j| = N` is about `ε`.

use crate::error::{invalid, Result};
use crate::pointset::PointSet;
use crate::quadrature::gauss_legendre;
use num_complex::Complex64;
use realfft::{RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};
use std::f64::consts::PI;
use std::sync::Arc;

/// The default tolerance: keeps `|P_fast - P_direct| ≤ 1e-8` up to N = 65536.
pub const DEFAULT_TOLERANCE: f64 = 1e-14;

/// A reusable NUFFT plan for one dimension and lattice size.
#[derive(Clone)]
pub struct NufftPlan {
    dimension: usize,
    kmax: usize,
    grid: usize,
    width: usize,
    beta: f64,
    /// `h / ψ̂(k)` for `k = -K..=K`: the deconvolution factor per axis.
    correction: Vec<f64>,
    /// Complex FFT for every axis but the last.
    fft: Arc<dyn Fft<f64>>,
    /// Real-to-complex FFT for the last axis: the spread grid is real.
    rfft: Arc<dyn RealToComplex<f64>>,
}

impl std::fmt::Debug for NufftPlan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NufftPlan")
            .field("dimension", &self.dimension)
            .field("kmax", &self.kmax)
            .field("grid", &self.grid)
            .field("width", &self.width)
            .finish()
    }
}

/// The smallest `2^a 3^b 5^c` at least `n`: sizes the FFT handles fastest.
fn nice_size(n: usize) -> usize {
    (n..)
        .find(|&m| {
            let mut r = m;
            for p in [2, 3, 5] {
                while r % p == 0 {
                    r /= p;
                }
            }
            r == 1
        })
        .unwrap_or(n)
}

impl NufftPlan {
    /// Plans a NUFFT in dimension `d` (1 to 3) for `|k_i| ≤ kmax` at tolerance `tolerance`.
    ///
    /// # Errors
    /// A dimension outside 1 to 3, or a tolerance outside `[1e-16, 1e-1]`.
    pub fn new(dimension: usize, kmax: usize, tolerance: f64) -> Result<Self> {
        if !(1..=3).contains(&dimension) {
            return Err(invalid("dimension", dimension, "1 to 3 for spectra"));
        }
        if !(1e-16..=1e-1).contains(&tolerance) {
            return Err(invalid("tolerance", tolerance, "between 1e-16 and 1e-1"));
        }
        let width = ((1.0 / tolerance).log10().ceil() as usize + 1).clamp(2, 16);
        let beta = 2.30 * width as f64;
        let side = 2 * kmax + 1;
        let grid = nice_size((2 * side).max(2 * width));
        let fft = FftPlanner::new().plan_fft_forward(grid);
        let rfft = RealFftPlanner::new().plan_fft_forward(grid);
        let correction = kernel_correction(kmax, grid, width, beta);
        Ok(Self {
            dimension,
            kmax,
            grid,
            width,
            beta,
            correction,
            fft,
            rfft,
        })
    }

    /// The dimension.
    pub fn dimension(&self) -> usize {
        self.dimension
    }

    /// The largest frequency per axis `K`.
    pub fn kmax(&self) -> usize {
        self.kmax
    }

    /// Kernel width in grid cells.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Oversampled grid size per axis.
    pub fn grid_size(&self) -> usize {
        self.grid
    }

    /// Kernel values at the `w` grid cells starting at `first` for coordinate `x`.
    fn kernel(&self, x: f64, values: &mut [f64; 16]) -> usize {
        let half = self.width as f64 / 2.0;
        let centre = x * self.grid as f64;
        let first = (centre - half).ceil();
        for (i, v) in values.iter_mut().enumerate().take(self.width) {
            let z = (first + i as f64 - centre) / half;
            *v = (self.beta * ((1.0 - z * z).max(0.0).sqrt() - 1.0)).exp();
        }
        first.rem_euclid(self.grid as f64) as usize
    }

    /// Spreads the points onto the oversampled grid `n_f^d` (row-major, real weights).
    pub fn spread(&self, points: &PointSet, grid: &mut [f64]) {
        let (d, g, w) = (self.dimension, self.grid, self.width);
        grid.fill(0.0);
        let mut kv = [[0.0f64; 16]; 3];
        let mut idx = [[0usize; 16]; 3];
        for p in points.points() {
            for a in 0..d {
                let first = self.kernel(p[a], &mut kv[a]);
                for i in 0..w {
                    idx[a][i] = (first + i) % g;
                }
            }
            match d {
                1 => {
                    for i in 0..w {
                        grid[idx[0][i]] += kv[0][i];
                    }
                }
                2 => {
                    for i in 0..w {
                        let row = idx[0][i] * g;
                        let v = kv[0][i];
                        for j in 0..w {
                            grid[row + idx[1][j]] += v * kv[1][j];
                        }
                    }
                }
                _ => {
                    for i in 0..w {
                        for j in 0..w {
                            let row = (idx[0][i] * g + idx[1][j]) * g;
                            let v = kv[0][i] * kv[1][j];
                            for l in 0..w {
                                grid[row + idx[2][l]] += v * kv[2][l];
                            }
                        }
                    }
                }
            }
        }
    }

    /// Scratch space for [`sums_with_scratch`](Self::sums_with_scratch): the oversampled grid
    /// and the FFTs' buffers, about `16 n_f^d` bytes.
    pub fn make_scratch(&self) -> NufftScratch {
        let (d, g, k) = (self.dimension, self.grid, self.kmax);
        let half = k + 1;
        let rows = g.pow(d as u32 - 1);
        let zero = Complex64::new(0.0, 0.0);
        NufftScratch {
            real: vec![0.0; g.pow(d as u32)],
            data: vec![zero; rows * half],
            spare: vec![zero; rows * half],
            spectrum: self.rfft.make_output_vec(),
            rfft: self.rfft.make_scratch_vec(),
            fft: vec![zero; self.fft.get_inplace_scratch_len()],
            line: vec![zero; g],
        }
    }

    /// The number of lattice frequencies `(2K+1)^d`: the length of the output of
    /// [`sums_with_scratch`](Self::sums_with_scratch).
    pub fn output_len(&self) -> usize {
        (2 * self.kmax + 1).pow(self.dimension as u32)
    }

    /// The sampling sums `Σ_j e^{-2πi k·x_j}` on the lattice, in the lattice order of
    /// [`super::lattice::Lattice`]. Allocates its scratch; see
    /// [`sums_with_scratch`](Self::sums_with_scratch) to reuse it.
    ///
    /// # Errors
    /// A point set of another dimension.
    ///
    /// # Examples
    /// ```
    /// use specvar::sampler::{Random, Sampler};
    /// use specvar::spectrum::nufft::NufftPlan;
    /// use num_complex::Complex64;
    /// let plan = NufftPlan::new(2, 32, 1e-10)?;
    /// let mut scratch = plan.make_scratch();
    /// let mut sums = vec![Complex64::new(0.0, 0.0); plan.output_len()];
    /// for realization in 0..4 {
    ///     let points = Random::new(2)?.sample(1000, 7, realization)?;
    ///     plan.sums_with_scratch(&points, &mut scratch, &mut sums)?; // no allocation
    ///     let dc = sums[(sums.len() - 1) / 2];
    ///     assert!((dc.re - 1000.0).abs() < 1e-6 && dc.im.abs() < 1e-6);
    /// }
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn sums(&self, points: &PointSet) -> Result<Vec<Complex64>> {
        let mut out = vec![Complex64::new(0.0, 0.0); self.output_len()];
        self.sums_with_scratch(points, &mut self.make_scratch(), &mut out)?;
        Ok(out)
    }

    /// As [`sums`](Self::sums), into `out` (length [`output_len`](Self::output_len)), using
    /// `scratch` from [`make_scratch`](Self::make_scratch) of this plan: nothing is allocated.
    ///
    /// # Errors
    /// A point set of another dimension, or `out` or `scratch` of another size.
    pub fn sums_with_scratch(
        &self,
        points: &PointSet,
        scratch: &mut NufftScratch,
        out: &mut [Complex64],
    ) -> Result<()> {
        if points.dimension() != self.dimension {
            return Err(invalid(
                "point dimension",
                points.dimension(),
                format!("{} (the plan's)", self.dimension),
            ));
        }
        let (d, g, k) = (self.dimension, self.grid, self.kmax);
        let side = 2 * k + 1;
        let len = side.pow(d as u32);
        if out.len() != len || scratch.real.len() != g.pow(d as u32) {
            return Err(invalid(
                "NUFFT buffers",
                format!("{} outputs, a grid of {}", out.len(), scratch.real.len()),
                format!(
                    "{len} outputs and a grid of {} (make_scratch)",
                    g.pow(d as u32)
                ),
            ));
        }
        self.spread(points, &mut scratch.real);
        // Last axis: real-to-complex, keeping k_last = 0..=K (the rest follows by symmetry).
        let half = k + 1;
        let rows = scratch.real.len() / g;
        for (row, dst) in scratch
            .real
            .chunks_exact_mut(g)
            .zip(scratch.data.chunks_exact_mut(half))
        {
            // The input row is used as scratch by the transform; it is not needed again.
            let _ = self
                .rfft
                .process_with_scratch(row, &mut scratch.spectrum, &mut scratch.rfft);
            dst.copy_from_slice(&scratch.spectrum[..half]);
        }
        let mut shape = [1usize; 3];
        shape[..d].fill(g);
        shape[d - 1] = half;
        let mut used = rows * half;
        for axis in (0..d - 1).rev() {
            used = self.fft_axis_and_crop(scratch, used, &mut shape, axis);
        }
        // Unfold to the full lattice with S(-k) = conj S(k), deconvolving on the way.
        let data = &scratch.data[..used];
        let outer = len / side;
        for o in 0..outer {
            let mut factor = 1.0;
            let mut rest = o;
            for _ in 0..d - 1 {
                factor *= self.correction[rest % side];
                rest /= side;
            }
            for t in 0..half {
                let v = data[o * half + t] * (factor * self.correction[k + t]);
                out[o * side + k + t] = v;
                // -k: flat index len - 1 - index(k).
                out[len - 1 - (o * side + k + t)] = v.conj();
            }
        }
        Ok(())
    }

    /// FFT along `axis` of the row-major array `scratch.data[..used]` of `shape`, keeping
    /// frequencies `-K..=K` in order; the result replaces it. Returns its length.
    fn fft_axis_and_crop(
        &self,
        scratch: &mut NufftScratch,
        used: usize,
        shape: &mut [usize; 3],
        axis: usize,
    ) -> usize {
        let (g, k) = (self.grid, self.kmax);
        let side = 2 * k + 1;
        let outer: usize = shape[..axis].iter().product();
        let inner: usize = shape[axis + 1..].iter().product();
        let data = &scratch.data[..used];
        let out = &mut scratch.spare[..outer * side * inner];
        for o in 0..outer {
            for i in 0..inner {
                for (t, v) in scratch.line.iter_mut().enumerate() {
                    *v = data[(o * g + t) * inner + i];
                }
                self.fft
                    .process_with_scratch(&mut scratch.line, &mut scratch.fft);
                for t in 0..side {
                    let bin = (t + g - k) % g; // frequency t - K
                    out[(o * side + t) * inner + i] = scratch.line[bin];
                }
            }
        }
        shape[axis] = side;
        std::mem::swap(&mut scratch.data, &mut scratch.spare);
        outer * side * inner
    }
}

/// Caller-owned buffers of a [`NufftPlan`] (from [`NufftPlan::make_scratch`]), reused across
/// realizations so that a transform allocates nothing.
#[derive(Debug, Clone)]
pub struct NufftScratch {
    real: Vec<f64>,
    data: Vec<Complex64>,
    spare: Vec<Complex64>,
    spectrum: Vec<Complex64>,
    rfft: Vec<Complex64>,
    fft: Vec<Complex64>,
    line: Vec<Complex64>,
}

/// `h / ψ̂(k)` for `k = -K..=K`, where `ψ(x) = φ(x n_f / (w/2))` and
/// `ψ̂(k) = (w / n_f) ∫_0^1 φ(z) cos(π k w z / n_f) dz`.
fn kernel_correction(kmax: usize, grid: usize, width: usize, beta: f64) -> Vec<f64> {
    let (nodes, weights) = gauss_legendre(2 * width + 60);
    let half = width as f64 / 2.0;
    let h = 1.0 / grid as f64;
    (0..=2 * kmax)
        .map(|t| {
            let k = t as f64 - kmax as f64;
            let mut integral = 0.0;
            for (x, w) in nodes.iter().zip(&weights) {
                let z = (x + 1.0) / 2.0; // [-1, 1] → [0, 1]
                let phi = (beta * ((1.0 - z * z).sqrt() - 1.0)).exp();
                integral += 0.5 * w * phi * (2.0 * PI * k * half * z / grid as f64).cos();
            }
            let psi_hat = 2.0 * half / grid as f64 * integral;
            h / psi_hat
        })
        .collect()
}
