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
mod ring;
mod spread;
mod stream;
mod transform;

use crate::error::{invalid, Result};
use crate::pointset::PointSet;
use choice::Choice;
use kernel::{EsKernel, KernelTable};
use num_complex::Complex64;
use ring::Ring;
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
    /// The kernel's values as polynomials, for the spreading.
    table: KernelTable,
    /// `1 / (g ψ̂(k))` for `k = -K..=K`: the deconvolution factor per axis.
    correction: Vec<f64>,
    /// The FFT of one line of the grid, along any axis.
    fft: Arc<dyn Fft<f64>>,
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
    /// outside 2 to [`kernel::MAX_WIDTH`].
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
            table: KernelTable::new(&choice.kernel),
            correction: choice.kernel.correction(kmax),
            fft: FftPlanner::new().plan_fft_forward(grid),
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

    /// Scratch space for [`sums_with_scratch`](Self::sums_with_scratch): the slabs of the
    /// padded grid in flight (see the `stream` module), the half spectra of the rows, the FFTs'
    /// buffers and the spreading order: about `16 g (K + 1)` bytes (in 3D, `16 g (K + 1)
    /// (2K + 1)` more for the second axis' output), plus `8 (g + w + 1)^{d-1}` per slab in
    /// flight (`68 + w` slabs in 2D and `9 + w` in 3D on grids of 32 cells or more).
    pub fn make_scratch(&self) -> NufftScratch {
        self.scratch_with_ring(Ring::for_layout(&self.layout, self.width()))
    }

    fn scratch_with_ring(&self, ring: Option<Ring>) -> NufftScratch {
        let (d, g, k) = (self.dimension, self.grid_size(), self.kmax);
        // The rows' half spectra: of the one row in 1D, of every row in 2D, of one plane's
        // rows in 3D.
        let rows = if d == 1 { 1 } else { g };
        let side = 2 * k + 1;
        let zero = Complex64::new(0.0, 0.0);
        // In 3D, the middle axis' cropped output: (side, K+1, g).
        let spare = if d == 3 { side * (k + 1) * g } else { 0 };
        NufftScratch {
            shape: self.shape(),
            ring,
            cells: super::written_zeros(ring.map_or(self.layout.side, |r| r.cells())),
            parked: ring.map_or(Vec::new(), |r| vec![0.0; r.parked_cells(&self.layout)]),
            rows: vec![zero; rows * (k + 1)],
            spare: vec![zero; spare],
            fft: vec![zero; self.fft.get_inplace_scratch_len()],
            batch: vec![zero; ring::BATCH * g],
            sort: SortScratch::default(),
        }
    }

    fn shape(&self) -> [usize; 4] {
        [self.dimension, self.kmax, self.grid_size(), self.width()]
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

    /// The periodogram `P(k) = |S(k)|² / N` on the half lattice, flat indices `0..=dc` of the
    /// lattice order (the rest follows from `P(-k) = P(k)`), into `out` (length
    /// `output_len() / 2 + 1`): half the memory traffic of [`sums_with_scratch`] and a square.
    ///
    /// [`sums_with_scratch`]: Self::sums_with_scratch
    ///
    /// # Errors
    /// As [`sums_with_scratch`](Self::sums_with_scratch).
    pub fn half_power_with_scratch(
        &self,
        points: &PointSet,
        scratch: &mut NufftScratch,
        out: &mut [f64],
    ) -> Result<()> {
        self.check_buffers(points, scratch, out.len(), self.output_len() / 2 + 1)?;
        self.spread_rows(points, scratch);
        self.unfold_half_power(scratch, 1.0 / points.len() as f64, out);
        Ok(())
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
        self.check_buffers(points, scratch, out.len(), self.output_len())?;
        self.spread_rows(points, scratch);
        self.unfold(scratch, out);
        Ok(())
    }

    fn check_buffers(
        &self,
        points: &PointSet,
        scratch: &NufftScratch,
        out: usize,
        expected: usize,
    ) -> Result<()> {
        if points.dimension() != self.dimension {
            return Err(invalid(
                "point dimension",
                points.dimension(),
                format!("{} (the plan's)", self.dimension),
            ));
        }
        if out != expected || scratch.shape != self.shape() {
            return Err(invalid(
                "NUFFT buffers",
                format!("{out} outputs, a scratch for {:?}", scratch.shape),
                format!(
                    "{expected} outputs and a scratch for {:?} (make_scratch)",
                    self.shape()
                ),
            ));
        }
        Ok(())
    }
}

/// Caller-owned buffers of a [`NufftPlan`] (from [`NufftPlan::make_scratch`]), reused across
/// realizations so that a transform allocates nothing.
#[derive(Debug, Clone)]
pub struct NufftScratch {
    /// The plan's dimension, band, grid and width: what the buffers are sized for.
    shape: [usize; 4],
    /// The slabs of the padded grid in flight along the first axis (2D, 3D), or the padded
    /// row (1D).
    ring: Option<Ring>,
    /// The ring's cells, or the padded row.
    cells: Vec<f64>,
    /// Parked slabs: the padding before the grid, then the first periodic slabs.
    parked: Vec<f64>,
    /// The rows' half spectra, `K + 1` per row (in 3D, of one plane's rows).
    rows: Vec<Complex64>,
    /// In 3D, the second axis' output, cropped.
    spare: Vec<Complex64>,
    /// The FFT's own scratch.
    fft: Vec<Complex64>,
    /// Lines transformed together.
    batch: Vec<Complex64>,
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
