//! A type-1 non-uniform FFT: `S(k) = Σ_j e^{-2πi k·x_j}` on the lattice `|k_i| ≤ K`.
//!
//! As in FINUFFT (Barnett, Magland and af Klinteberg 2019): spread every point onto a grid
//! of `g ≥ σ(2K+1)` cells per axis with the "exponential of semicircle" kernel
//! ([`kernel`]); take the FFT of the grid; keep the frequencies `|k| ≤ K`; divide by the
//! kernel's Fourier transform. Unlike a general NUFFT, every strength is 1 and the grid is
//! real: the last axis takes a real FFT, every other axis transforms only the lines that the
//! crop to `|k| ≤ K` keeps, and `S(-k) = conj S(k)` fills the other half.
//!
//! The tolerance is a guarantee, not a target: `|S_fast(k) - S(k)| ≤ ε N` at every frequency
//! for any point set, because the one-point error is measured for the plan ([`kernel`]) and
//! the errors of `N` points add at most linearly. For each upsampling of
//! [`choice::UPSAMPLINGS`] the plan finds the narrowest kernel meeting `ε`, and keeps the pair
//! the cost model of [`choice`] predicts to be fastest for the number of points.

pub mod choice;
pub mod kernel;
mod spread;

use crate::error::{invalid, Result};
use crate::pointset::PointSet;
use choice::Choice;
use kernel::EsKernel;
use num_complex::Complex64;
use realfft::{RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};
use spread::{Padded, SortScratch};
use std::sync::Arc;

/// The tolerance of [`Engine::fast`](super::Engine::fast): `|δP| ≤ 2ε√(NP) + ε²N` keeps
/// `|P_fast - P_direct|` below `1e-8` for every `P ≤ 10` up to `N = 10^5` points.
pub const DEFAULT_TOLERANCE: f64 = 1e-12;

/// The smallest tolerance a plan accepts: the widest kernel at upsampling 2 guarantees about
/// `2·10⁻¹⁴`, the FFT's rounding is of order `10⁻¹⁵`.
pub const MIN_TOLERANCE: f64 = 1e-13;

/// A reusable NUFFT plan for one dimension and lattice size.
#[derive(Clone)]
pub struct NufftPlan {
    dimension: usize,
    kmax: usize,
    choice: Choice,
    tolerance: f64,
    layout: Padded,
    /// `1 / (g ψ̂(k))` for `k = -K..=K`: the deconvolution factor per axis.
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
            .field("choice", &self.choice)
            .finish()
    }
}

impl NufftPlan {
    /// Plans a NUFFT in dimension `d` (1 to 3) for `|k_i| ≤ kmax` and sets of about `points`
    /// points, guaranteeing `|S_fast(k) - S(k)| ≤ tolerance · N`; the upsampling and kernel
    /// width are the cheapest that do (see the module notes).
    ///
    /// # Errors
    /// A dimension outside 1 to 3, a `kmax` of 0, or a tolerance outside
    /// `[MIN_TOLERANCE, 0.1]` or below what the widest kernel reaches at this `kmax`.
    pub fn new(dimension: usize, kmax: usize, points: usize, tolerance: f64) -> Result<Self> {
        check_band(dimension, kmax)?;
        if !(MIN_TOLERANCE..=1e-1).contains(&tolerance) {
            return Err(invalid(
                "tolerance",
                tolerance,
                format!("between {MIN_TOLERANCE:e} and 0.1"),
            ));
        }
        let choice = Choice::cheapest(dimension, kmax, points, tolerance)?;
        Ok(Self::from_choice(dimension, kmax, choice, tolerance))
    }

    /// Plans a NUFFT with an explicit upsampling (a grid of at least `upsampling · (2K+1)`
    /// cells per axis) and kernel `width`, the shape parameter following the upsampling.
    /// Its guaranteed error is [`error_bound`](Self::error_bound).
    ///
    /// # Errors
    /// A dimension outside 1 to 3, a `kmax` of 0, an upsampling outside `[1.1, 4]` or a width
    /// outside 2 to 16.
    pub fn with_kernel(
        dimension: usize,
        kmax: usize,
        upsampling: f64,
        width: usize,
    ) -> Result<Self> {
        check_band(dimension, kmax)?;
        if !(1.1..=4.0).contains(&upsampling) {
            return Err(invalid("upsampling", upsampling, "between 1.1 and 4"));
        }
        if !(2..=kernel::MAX_WIDTH).contains(&width) {
            return Err(invalid(
                "kernel width",
                width,
                format!("2 to {} cells", kernel::MAX_WIDTH),
            ));
        }
        let choice = Choice::with_width(dimension, kmax, upsampling, width);
        Ok(Self::from_choice(dimension, kmax, choice, choice.error))
    }

    fn from_choice(dimension: usize, kmax: usize, choice: Choice, tolerance: f64) -> Self {
        let EsKernel { width, grid, .. } = choice.kernel;
        Self {
            dimension,
            kmax,
            choice,
            tolerance,
            layout: Padded::new(dimension, grid, width),
            correction: choice.kernel.correction(kmax),
            fft: FftPlanner::new().plan_fft_forward(grid),
            rfft: RealFftPlanner::new().plan_fft_forward(grid),
        }
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
        self.choice.kernel.width
    }

    /// Oversampled grid size per axis.
    pub fn grid_size(&self) -> usize {
        self.choice.kernel.grid
    }

    /// The upsampling factor asked for (the grid is the next FFT-friendly size above it).
    pub fn upsampling(&self) -> f64 {
        self.choice.upsampling
    }

    /// The tolerance the plan was made for.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The guaranteed error: `|S_fast(k) - S(k)| ≤ error_bound · N` at every frequency of the
    /// band, for any `N` points (at most the tolerance).
    pub fn error_bound(&self) -> f64 {
        self.choice.error
    }

    /// Scratch space for [`sums_with_scratch`](Self::sums_with_scratch): the padded grid,
    /// the FFTs' buffers and the spreading order, about `8 (g + w + 1)^d` bytes.
    pub fn make_scratch(&self) -> NufftScratch {
        let (d, g, k) = (self.dimension, self.grid_size(), self.kmax);
        let half = k + 1;
        let rows = g.pow(d as u32 - 1);
        let zero = Complex64::new(0.0, 0.0);
        NufftScratch {
            cells: vec![0.0; self.layout.len()],
            data: vec![zero; rows * half],
            spare: vec![zero; rows * half],
            spectrum: self.rfft.make_output_vec(),
            rfft: self.rfft.make_scratch_vec(),
            fft: vec![zero; self.fft.get_inplace_scratch_len()],
            line: vec![zero; g],
            sort: SortScratch::default(),
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
    /// let plan = NufftPlan::new(2, 32, 1000, 1e-10)?;
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
    /// `scratch` from [`make_scratch`](Self::make_scratch) of this plan: nothing is allocated
    /// once the scratch has seen a set of this size.
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
        let (d, g, k) = (self.dimension, self.grid_size(), self.kmax);
        let len = self.output_len();
        if out.len() != len || scratch.cells.len() != self.layout.len() {
            return Err(invalid(
                "NUFFT buffers",
                format!("{} outputs, a grid of {}", out.len(), scratch.cells.len()),
                format!(
                    "{len} outputs and a grid of {} (make_scratch)",
                    self.layout.len()
                ),
            ));
        }
        spread::spread(
            &self.choice.kernel,
            &self.layout,
            points,
            &mut scratch.cells,
            &mut scratch.sort,
        );
        spread::fold(&self.layout, &mut scratch.cells);
        // Last axis: real-to-complex, keeping k_last = 0..=K (the rest follows by symmetry).
        let half = k + 1;
        let rows = g.pow(d as u32 - 1);
        for (row, dst) in scratch.data.chunks_exact_mut(half).enumerate() {
            let start = self.layout.row_start(row);
            // The input row is used as scratch by the transform; it is not needed again.
            let _ = self.rfft.process_with_scratch(
                &mut scratch.cells[start..start + g],
                &mut scratch.spectrum,
                &mut scratch.rfft,
            );
            dst.copy_from_slice(&scratch.spectrum[..half]);
        }
        let mut shape = [1usize; 3];
        shape[..d].fill(g);
        shape[d - 1] = half;
        let mut used = rows * half;
        for axis in (0..d - 1).rev() {
            used = self.fft_axis_and_crop(scratch, used, &mut shape, axis);
        }
        self.unfold(&scratch.data[..used], out);
        Ok(())
    }

    /// Writes the full lattice from the half `k_last ≥ 0` with `S(-k) = conj S(k)`,
    /// deconvolving on the way.
    fn unfold(&self, data: &[Complex64], out: &mut [Complex64]) {
        let (d, k) = (self.dimension, self.kmax);
        let (side, half, len) = (2 * k + 1, k + 1, out.len());
        for o in 0..len / side {
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
        let (g, k) = (self.grid_size(), self.kmax);
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
    cells: Vec<f64>,
    data: Vec<Complex64>,
    spare: Vec<Complex64>,
    spectrum: Vec<Complex64>,
    rfft: Vec<Complex64>,
    fft: Vec<Complex64>,
    line: Vec<Complex64>,
    sort: SortScratch,
}

fn check_band(dimension: usize, kmax: usize) -> Result<()> {
    if !(1..=3).contains(&dimension) {
        return Err(invalid("dimension", dimension, "1 to 3 for spectra"));
    }
    if kmax == 0 {
        return Err(invalid("kmax", kmax, "at least 1"));
    }
    Ok(())
}
