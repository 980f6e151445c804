//! Integrands sampled on a grid: images, visibility rasters, any tabulated function on `[0,1)²`.

use super::{Integrand, IntegrandKind};
use crate::error::{invalid, Result};
use crate::spectrum::Lattice;
use num_complex::Complex64;
use rustfft::FftPlanner;
use std::f64::consts::PI;

/// What a grid's cells are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GridMeaning {
    /// The averages of a finer function over the cells (a rendered pixel's sub-pixels, an
    /// antialiased image of a scene, supersampled coverage): predictions are for that function,
    /// the grid's own prediction extrapolated over its coarser averages, with the
    /// extrapolation's bound as the budget's tabulation term. The default.
    CellAverages,
    /// A finer function's values at the cells' centres (a tabulation by point evaluation):
    /// predicted as [`CellAverages`](Self::CellAverages) are, its coarser levels the values at
    /// every second and fourth cell.
    PointSamples,
    /// The function itself (a texture looked up by nearest neighbour, an image integrated as
    /// pixels): predictions are exact for the piecewise-constant function.
    Exact,
}

impl std::str::FromStr for GridMeaning {
    type Err = crate::error::Error;
    /// `averages`, `samples` or `exact`.
    fn from_str(s: &str) -> Result<Self> {
        [
            GridMeaning::CellAverages,
            GridMeaning::PointSamples,
            GridMeaning::Exact,
        ]
        .into_iter()
        .find(|m| m.name() == s.trim())
        .ok_or_else(|| {
            invalid(
                "tabulation",
                crate::error::quoted(s),
                "averages (a finer function's cell averages), samples (its values at the cells' \
                 centres) or exact (the grid is the function)",
            )
        })
    }
}

impl GridMeaning {
    /// The name in an integrand's spec (`grid:FILE,exact`): `averages`, `samples` or `exact`.
    pub fn name(self) -> &'static str {
        match self {
            GridMeaning::CellAverages => "averages",
            GridMeaning::PointSamples => "samples",
            GridMeaning::Exact => "exact",
        }
    }
}

/// A piecewise-constant function on `[0,1)²`: `width × height` cells, cell `(x, y)` covering
/// `[x/w, (x+1)/w) × [y/h, (y+1)/h)` with value `values[y * width + x]`, and zero outside the
/// square.
///
/// Its Fourier coefficients at integer frequencies are exact and come from one 2D FFT `G` of the
/// values: `f̂(k) = G[k mod (w, h)] Π_a sinc(π k_a / M_a) e^{-π i k_a / M_a} / M_a`, where the
/// sinc and phase are a cell's own transform. At other frequencies [`Integrand::fourier`] sums
/// the cells directly (`O(w h)`). This is the route by which an integrand of one's own (an
/// image, a grid in a file, a pixel's visibility) enters the lattice-form prediction.
///
/// # Examples
/// ```
/// use specvar::integrand::{GridIntegrand, Integrand};
/// // A 2 × 2 checkerboard.
/// let f = GridIntegrand::new(2, 2, vec![1.0, 0.0, 0.0, 1.0]).unwrap();
/// assert_eq!(f.integral(), 0.5);
/// assert_eq!(f.eval(&[0.25, 0.25]), 1.0);
/// assert_eq!(f.eval(&[0.75, 0.25]), 0.0);
/// // Parseval: Σ_k |f̂(k)|² = ∫ f² = 1/2; the jumps leave a tail beyond |k_i| ≤ 100 that
/// // falls like 1/K along the axes.
/// let mut sum = 0.0;
/// for kx in -100..=100 {
///     for ky in -100..=100 {
///         sum += f.fourier(&[kx as f64, ky as f64]).norm_sqr();
///     }
/// }
/// assert!(sum < 0.5 && sum > 0.99 * 0.5);
/// ```
#[derive(Debug, Clone)]
pub struct GridIntegrand {
    meaning: GridMeaning,
    width: usize,
    height: usize,
    values: Vec<f64>,
    /// `G[ky * width + kx] = Σ g(x, y) e^{-2πi (kx x / w + ky y / h)}`.
    dft: Vec<Complex64>,
    /// `e^{-πi k / M_a} sin(π k / M_a)` for `k` in `0..2 M_a`, per axis: the periodic part of a
    /// cell's transform at integer `k`, so the lattice form needs no trigonometric call.
    cell_x: Vec<Complex64>,
    cell_y: Vec<Complex64>,
    mean: f64,
    mean_square: f64,
    name: String,
    /// The cells' circular autocorrelation, computed when first asked for.
    correlation: std::sync::OnceLock<Vec<f64>>,
    /// The grid of the squared values, built when its coefficients are first asked for.
    square: std::sync::OnceLock<Option<Box<GridIntegrand>>>,
}

impl GridIntegrand {
    /// The function with `width × height` cell values, row by row from `y = 0`.
    ///
    /// # Errors
    /// A zero side, a value count other than `width × height`, or a value that is not finite.
    pub fn new(width: usize, height: usize, values: Vec<f64>) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(invalid(
                "grid size",
                format!("{width} × {height}"),
                "at least 1 × 1",
            ));
        }
        if values.len() != width * height {
            return Err(invalid(
                "grid values",
                values.len(),
                format!("{width} × {height} = {}", width * height),
            ));
        }
        if let Some(i) = values
            .iter()
            .position(|v| !(v.is_finite() && v.abs() <= super::MAX_HEIGHT))
        {
            return Err(invalid(
                "grid value",
                format!("{} at cell ({}, {})", values[i], i % width, i / width),
                format!(
                    "finite and at most {:e} in size (energies are squares of it)",
                    super::MAX_HEIGHT
                ),
            ));
        }
        let cells = (width * height) as f64;
        let mean = values.iter().sum::<f64>() / cells;
        let mean_square = values.iter().map(|v| v * v).sum::<f64>() / cells;
        Ok(Self {
            meaning: GridMeaning::CellAverages,
            dft: dft_2d(width, height, &values),
            cell_x: cell_table(width),
            cell_y: cell_table(height),
            width,
            height,
            values,
            mean,
            mean_square,
            name: format!("grid({width}×{height})"),
            correlation: std::sync::OnceLock::new(),
            square: std::sync::OnceLock::new(),
        })
    }

    /// The function times `factor` (a grey level in `[0, 1]` to radiance, say), its label
    /// saying so.
    ///
    /// # Errors
    /// A factor that makes a value infinite or not a number.
    pub fn scaled(self, factor: f64) -> Result<Self> {
        let name = format!("{} × {factor}", self.name);
        let values = self.values().iter().map(|v| v * factor).collect();
        Ok(Self::new(self.width(), self.height(), values)?
            .with_name(name)
            .with_meaning(self.meaning))
    }

    /// The same cells with another meaning: [`GridMeaning::Exact`] for a grid that is the
    /// function itself.
    pub fn with_meaning(mut self, meaning: GridMeaning) -> Self {
        self.meaning = meaning;
        self
    }

    /// What the cells are: a tabulation of a finer function (its cell averages by default, or
    /// its values at the centres) or the function.
    pub fn meaning(&self) -> GridMeaning {
        self.meaning
    }

    /// Whether every cell holds the same value: a constant, whose every estimator has
    /// variance 0, and whose coarser averages say nothing of a finer function.
    pub fn is_constant(&self) -> bool {
        self.values.iter().all(|&v| v == self.values[0])
    }

    /// The cell averages of this function on a coarser `width × height` grid: each coarse
    /// cell's value is the mean of the fine cells it covers, weighted by the area they share
    /// (for sides that divide, the mean of whole blocks). A tabulation by cell averages
    /// averaged again is the tabulation at the coarser resolution; the result is declared
    /// [`GridMeaning::Exact`], being the function it is computed from at that resolution.
    ///
    /// # Errors
    /// A side of zero, or finer than this grid's.
    ///
    /// # Examples
    /// ```
    /// use specvar::integrand::{GridIntegrand, Integrand};
    /// let f = GridIntegrand::new(4, 2, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0])?;
    /// let coarse = f.averaged(2, 1)?;
    /// assert_eq!(coarse.values(), &[3.5, 5.5]);
    /// // An uneven split shares the middle cell: 3 cells to 2.
    /// let g = GridIntegrand::new(3, 1, vec![0.0, 3.0, 6.0])?.averaged(2, 1)?;
    /// assert_eq!(g.values(), &[1.0, 5.0]);
    /// assert_eq!(g.integral(), 3.0);
    /// # Ok::<(), specvar::Error>(())
    /// ```
    pub fn averaged(&self, width: usize, height: usize) -> Result<GridIntegrand> {
        self.check_coarser(width, height)?;
        let columns = Self::shares(width, self.width);
        let rows = Self::shares(height, self.height);
        let mut values = Vec::with_capacity(width * height);
        for row in &rows {
            for column in &columns {
                let mut sum = 0.0;
                for &(y, wy) in row {
                    let fine = &self.values[y * self.width..(y + 1) * self.width];
                    sum += wy * column.iter().map(|&(x, wx)| wx * fine[x]).sum::<f64>();
                }
                values.push(sum);
            }
        }
        Ok(GridIntegrand::new(width, height, values)?
            .with_name(format!("{} averaged to {width}×{height}", self.name))
            .with_meaning(GridMeaning::Exact))
    }

    /// The values at the cells of a coarser `width × height` grid that hold its cells'
    /// centres: a tabulation by point evaluation at the coarser resolution (each point within
    /// half a fine cell of its coarse cell's centre), declared [`GridMeaning::Exact`].
    ///
    /// # Errors
    /// A side of zero, or finer than this grid's.
    pub fn subsampled(&self, width: usize, height: usize) -> Result<GridIntegrand> {
        self.check_coarser(width, height)?;
        let centre = |i: usize, coarse: usize, fine: usize| {
            (((2 * i + 1) * fine) / (2 * coarse)).min(fine - 1)
        };
        let values = (0..height)
            .flat_map(|j| {
                let y = centre(j, height, self.height);
                (0..width).map(move |i| (y, centre(i, width, self.width)))
            })
            .map(|(y, x)| self.values[y * self.width + x])
            .collect();
        Ok(GridIntegrand::new(width, height, values)?
            .with_name(format!("{} sampled at {width}×{height}", self.name))
            .with_meaning(GridMeaning::Exact))
    }

    fn check_coarser(&self, width: usize, height: usize) -> Result<()> {
        if width == 0 || height == 0 || width > self.width || height > self.height {
            return Err(invalid(
                "coarser grid",
                format!("{width} × {height}"),
                format!("1 × 1 to {} × {}", self.width, self.height),
            ));
        }
        Ok(())
    }

    /// The tabulation of the same function at a coarser `width × height` resolution, as this
    /// grid's meaning says it was made: its averages ([`averaged`](Self::averaged)) or its
    /// values at the coarser centres ([`subsampled`](Self::subsampled)).
    ///
    /// # Errors
    /// As [`averaged`](Self::averaged).
    pub fn coarser(&self, width: usize, height: usize) -> Result<GridIntegrand> {
        match self.meaning {
            GridMeaning::PointSamples => self.subsampled(width, height),
            _ => self.averaged(width, height),
        }
    }

    /// For each of `coarse` cells on an axis of `fine` cells, the fine cells it covers with the
    /// share of the coarse cell each takes (summing to 1).
    pub(crate) fn shares(coarse: usize, fine: usize) -> Vec<Vec<(usize, f64)>> {
        (0..coarse)
            .map(|i| {
                if fine.is_multiple_of(coarse) {
                    let ratio = fine / coarse;
                    let share = 1.0 / ratio as f64;
                    return (i * ratio..(i + 1) * ratio).map(|j| (j, share)).collect();
                }
                let (lo, hi) = (i as f64 / coarse as f64, (i + 1) as f64 / coarse as f64);
                Self::overlaps(lo, hi, fine)
                    .map(|(j, len)| (j, len * coarse as f64))
                    .collect()
            })
            .collect()
    }

    /// The same function under another label (e.g. the file it came from).
    pub fn with_name(mut self, name: impl Into<String>) -> Self {
        self.name = name.into();
        self
    }

    /// Cells along x.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Cells along y.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The cell values, row by row from `y = 0`.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// `f̂(k)` at an integer frequency, from the FFT and the tables.
    fn fourier_at_integer(&self, kx: i64, ky: i64) -> Complex64 {
        let (w, h) = (self.width as i64, self.height as i64);
        let g = self.dft[(ky.rem_euclid(h) * w + kx.rem_euclid(w)) as usize];
        g * cell_factor(&self.cell_x, kx, w) * cell_factor(&self.cell_y, ky, h)
    }

    /// `f̂(ω)` at any frequency by the direct sum over cells; `phase_x` (length `width`) is
    /// scratch space.
    fn fourier_direct(&self, omega: [f64; 2], phase_x: &mut [Complex64]) -> Complex64 {
        fill_phases(omega[0] / self.width as f64, phase_x);
        let step_y = Complex64::from_polar(1.0, -2.0 * PI * omega[1] / self.height as f64);
        let mut phase_y = Complex64::new(1.0, 0.0);
        let mut total = Complex64::new(0.0, 0.0);
        for row in self.values.chunks_exact(self.width) {
            let inner: Complex64 = row.iter().zip(phase_x.iter()).map(|(&v, &p)| p * v).sum();
            total += inner * phase_y;
            phase_y *= step_y;
        }
        total * cell_transform(omega[0], self.width) * cell_transform(omega[1], self.height)
    }

    /// The mean of `|f̂|²` over the circle `|ω| = rho`, by the trapezoid rule in the angle
    /// (exact for the circle's angular harmonics below the node count, which exceeds
    /// `2π ρ √2`, the largest that a function supported on the unit square can have).
    fn angular_mean(&self, rho: f64) -> f64 {
        if rho == 0.0 {
            return self.mean * self.mean;
        }
        // |f̂(-ω)| = |f̂(ω)| for a real f: half the circle suffices.
        let nodes = ((2.0 * PI * 2f64.sqrt() * rho).ceil() as usize + 32) / 2;
        let mut phase_x = vec![Complex64::new(0.0, 0.0); self.width];
        (0..nodes)
            .map(|i| {
                let (s, c) = (PI * i as f64 / nodes as f64).sin_cos();
                self.fourier_direct([rho * c, rho * s], &mut phase_x)
                    .norm_sqr()
            })
            .sum::<f64>()
            / nodes as f64
    }
}

/// The unnormalized 2D DFT of row-major values, by rows then columns.
fn dft_2d(width: usize, height: usize, values: &[f64]) -> Vec<Complex64> {
    transform_2d(
        width,
        height,
        values.iter().map(|&v| Complex64::new(v, 0.0)).collect(),
    )
}

/// The normalized circular autocorrelation of the cell values,
/// `Â[q w + p] = (1/(w h)) Σ_{i,j} F[i, j] F[i + p, j + q]`, from `|G|²` (even in `k` for real
/// values, so its forward transform is its inverse).
fn cell_autocorrelation(width: usize, height: usize, dft: &[Complex64]) -> Vec<f64> {
    let power = dft
        .iter()
        .map(|g| Complex64::new(g.norm_sqr(), 0.0))
        .collect();
    let scale = ((width * height) as f64).powi(2);
    transform_2d(width, height, power)
        .iter()
        .map(|c| c.re / scale)
        .collect()
}

/// The unnormalized 2D DFT of row-major complex values, by rows then columns.
fn transform_2d(width: usize, height: usize, mut data: Vec<Complex64>) -> Vec<Complex64> {
    let mut planner = FftPlanner::<f64>::new();
    planner.plan_fft_forward(width).process(&mut data);
    let column_fft = planner.plan_fft_forward(height);
    let mut column = vec![Complex64::new(0.0, 0.0); height];
    for x in 0..width {
        for y in 0..height {
            column[y] = data[y * width + x];
        }
        column_fft.process(&mut column);
        for y in 0..height {
            data[y * width + x] = column[y];
        }
    }
    data
}

/// `e^{-πi k/M} sin(π k/M)` for `k` in `0..2M`: periodic in `k` with period `2M`.
fn cell_table(m: usize) -> Vec<Complex64> {
    (0..2 * m)
        .map(|k| {
            let angle = PI * k as f64 / m as f64;
            Complex64::from_polar(angle.sin(), -angle)
        })
        .collect()
}

/// A cell's transform `∫_0^{1/M} e^{-2πi k x} dx = e^{-πi k/M} sin(π k/M) / (π k)` at integer
/// `k` (`1/M` at `k = 0`), from the table.
#[inline]
fn cell_factor(table: &[Complex64], k: i64, m: i64) -> Complex64 {
    if k == 0 {
        return Complex64::new(1.0 / m as f64, 0.0);
    }
    table[k.rem_euclid(2 * m) as usize] / (PI * k as f64)
}

/// A cell's transform at any `ω`.
fn cell_transform(omega: f64, m: usize) -> Complex64 {
    let x = PI * omega / m as f64;
    Complex64::from_polar(crate::spectrum::sinc(x) / m as f64, -x)
}

/// `phases[j] = e^{-2πi t j}` by recurrence.
fn fill_phases(t: f64, phases: &mut [Complex64]) {
    let step = Complex64::from_polar(1.0, -2.0 * PI * t);
    let mut p = Complex64::new(1.0, 0.0);
    for slot in phases.iter_mut() {
        *slot = p;
        p *= step;
    }
}

impl GridIntegrand {
    /// The cells of one axis (`m` of them) that `[lo, hi]` meets, each with its overlap length.
    fn overlaps(lo: f64, hi: f64, m: usize) -> impl Iterator<Item = (usize, f64)> {
        let w = 1.0 / m as f64;
        let first = ((lo * m as f64).floor().max(0.0) as usize).min(m - 1);
        let last = ((hi * m as f64).ceil().max(1.0) as usize).min(m);
        (first..last).filter_map(move |i| {
            let len = (hi.min((i + 1) as f64 * w) - lo.max(i as f64 * w)).max(0.0);
            (len > 0.0).then_some((i, len))
        })
    }
}

/// The cells of one axis of a sampling grid, grouped by how they overlap the value grid's
/// columns (or rows): a run of cells inside one value cell is one class, weighted by its length.
struct OverlapClass {
    multiplicity: f64,
    /// `(value cell, fraction of the sampling cell's width)`.
    weights: Vec<(usize, f64)>,
}

impl GridIntegrand {
    /// The classes of `cells` sampling cells on an axis of `m` value cells.
    fn overlap_classes(cells: usize, m: usize) -> Vec<OverlapClass> {
        let mut classes: Vec<OverlapClass> = Vec::new();
        for i in 0..cells {
            let (lo, hi) = (i as f64 / cells as f64, (i + 1) as f64 / cells as f64);
            let mut weights: Vec<(usize, f64)> = Self::overlaps(lo, hi, m)
                .map(|(v, len)| (v, len * cells as f64))
                .collect();
            if let [(only, _)] = weights[..] {
                // Inside one value cell: its weight is 1 exactly.
                weights = vec![(only, 1.0)];
                if let Some(last) = classes.last_mut()
                    && last.weights[..] == [(only, 1.0)]
                {
                    last.multiplicity += 1.0;
                    continue;
                }
            }
            classes.push(OverlapClass {
                multiplicity: 1.0,
                weights,
            });
        }
        classes
    }
}

impl Integrand for GridIntegrand {
    fn cell_sums(&self, grid: &[usize]) -> Option<super::CellSums> {
        // A sampling cell's mean and mean square are weighted sums of the values it overlaps,
        // and the weights factor by axis: every cell of one class pair has the same moments,
        // so the sums run over the pairs of classes (a few per value cell), not the cells.
        if grid.len() != 2 {
            return None;
        }
        let columns = Self::overlap_classes(grid[0], self.width);
        let rows = Self::overlap_classes(grid[1], self.height);
        let (mut squares, mut within) = (
            crate::quadrature::CompensatedSum::default(),
            crate::quadrature::CompensatedSum::default(),
        );
        for row in &rows {
            for column in &columns {
                let (mut mean, mut second) = (0.0, 0.0);
                for &(y, wy) in &row.weights {
                    for &(x, wx) in &column.weights {
                        let v = self.values[y * self.width + x];
                        mean += wx * wy * v;
                        second += wx * wy * v * v;
                    }
                }
                let count = row.multiplicity * column.multiplicity;
                squares.add(count * mean * mean);
                // One value: no inner variance, exactly.
                if row.weights.len() > 1 || column.weights.len() > 1 {
                    within.add(count * (second - mean * mean).max(0.0));
                }
            }
        }
        Some(super::CellSums {
            mean_square: squares.value(),
            within: within.value(),
            within_error: 0.0,
            within_rounding: None,
            visited: (rows.len() * columns.len()) as u64,
        })
    }
    fn box_moments(&self, lo: &[f64], hi: &[f64]) -> Option<(f64, f64)> {
        // Piecewise constant: each cell's value times the area it shares with the box.
        let (mut mass, mut square) = (0.0, 0.0);
        for (y, ly) in Self::overlaps(lo[1], hi[1], self.height) {
            for (x, lx) in Self::overlaps(lo[0], hi[0], self.width) {
                let v = self.values[y * self.width + x];
                mass += v * lx * ly;
                square += v * v * lx * ly;
            }
        }
        Some((mass, square))
    }
    fn kind(&self) -> IntegrandKind {
        IntegrandKind::Grid
    }
    fn tabulation(&self) -> Option<&GridIntegrand> {
        (self.meaning != GridMeaning::Exact).then_some(self)
    }
    fn is_isotropic(&self) -> bool {
        false
    }
    fn label(&self) -> String {
        self.name.clone()
    }
    fn dimension(&self) -> usize {
        2
    }
    fn dyadic_level(&self) -> Option<u32> {
        (self.width == self.height && self.width.is_power_of_two())
            .then(|| self.width.trailing_zeros())
    }
    fn eval(&self, x: &[f64]) -> f64 {
        let cell = |v: f64, m: usize| ((v * m as f64).max(0.0) as usize).min(m - 1);
        self.values[cell(x[1], self.height) * self.width + cell(x[0], self.width)]
    }
    fn integral(&self) -> f64 {
        self.mean
    }
    fn integral_of_square(&self) -> f64 {
        self.mean_square
    }
    fn coefficient(&self, k: &[i64]) -> Complex64 {
        self.fourier_at_integer(k[0], k[1])
    }
    fn square_coefficient(&self, k: &[i64]) -> Option<Complex64> {
        // f² is the grid of the squared values, with its own DFT.
        let square = self.square.get_or_init(|| {
            let values = self.values.iter().map(|v| v * v).collect();
            GridIntegrand::new(self.width, self.height, values)
                .ok()
                .map(Box::new)
        });
        square.as_ref().map(|g| g.coefficient(k))
    }
    fn power_on_lattice(&self, lattice: Lattice, out: &mut [f64]) {
        // |f̂(k)|² = |G(k mod M)|² |c_x(k_x)|² |c_y(k_y)|²: the cells' factors once per axis
        // and the DFT's row of each k_y once, then one product per frequency (a pixel's power
        // is summed over every pixel of an image).
        let k = lattice.kmax as i64;
        let (w, h) = (self.width as i64, self.height as i64);
        let axis_power = |table: &[Complex64], m: i64| -> Vec<f64> {
            (-k..=k)
                .map(|kk| cell_factor(table, kk, m).norm_sqr())
                .collect()
        };
        let (px, py) = (axis_power(&self.cell_x, w), axis_power(&self.cell_y, h));
        let rows: Vec<usize> = (-k..=k).map(|ky| (ky.rem_euclid(h) * w) as usize).collect();
        let side = lattice.side();
        for (a, kx) in (-k..=k).enumerate() {
            let column = kx.rem_euclid(w) as usize;
            let line = &mut out[a * side..(a + 1) * side];
            for ((slot, &row), &wy) in line.iter_mut().zip(&rows).zip(&py) {
                *slot = self.dft[row + column].norm_sqr() * px[a] * wy;
            }
        }
    }
    fn projection_energy(&self, axis: usize) -> f64 {
        // The projection onto an axis is piecewise constant: the mean of each column (x) or
        // row (y), so ∫ F² is the mean of their squares.
        let (w, h) = (self.width, self.height);
        let means: Vec<f64> = if axis == 0 {
            (0..w)
                .map(|x| (0..h).map(|y| self.values[y * w + x]).sum::<f64>() / h as f64)
                .collect()
        } else {
            self.values
                .chunks_exact(w)
                .map(|row| row.iter().sum::<f64>() / w as f64)
                .collect()
        };
        means.iter().map(|m| m * m).sum::<f64>() / means.len() as f64
    }
    /// Exact: a cell moved by `((p + α)/w, (q + β)/h)` (`p, q` whole, `α, β ∈ [0, 1)`) meets four
    /// cells with the overlaps `(1 − α)(1 − β)`, `α(1 − β)`, `(1 − α)β` and `αβ` of its area, so the
    /// autocorrelation is the bilinear interpolation of the cells' circular autocorrelation
    /// `Â` (one 2D FFT of `|G|²`, kept).
    fn autocorrelation(&self, r: &[f64]) -> Option<f64> {
        let (w, h) = (self.width, self.height);
        let a = self
            .correlation
            .get_or_init(|| cell_autocorrelation(w, h, &self.dft));
        let split = |t: f64, m: usize| {
            let x = (t - t.floor()) * m as f64;
            let whole = (x.floor() as usize).min(m - 1);
            (whole, (x - whole as f64).clamp(0.0, 1.0))
        };
        let ((p, alpha), (q, beta)) = (split(r[0], w), split(r[1], h));
        let at = |i: usize, j: usize| a[((j % h) * w) + (i % w)];
        Some(
            (1.0 - alpha) * (1.0 - beta) * at(p, q)
                + alpha * (1.0 - beta) * at(p + 1, q)
                + (1.0 - alpha) * beta * at(p, q + 1)
                + alpha * beta * at(p + 1, q + 1),
        )
    }
    fn autocorrelation_beyond(&self, _distance: f64) -> Option<f64> {
        None
    }
    fn fourier(&self, omega: &[f64]) -> Complex64 {
        let integer = |w: f64| w.fract() == 0.0 && w.abs() < 1e15;
        if integer(omega[0]) && integer(omega[1]) {
            return self.fourier_at_integer(omega[0] as i64, omega[1] as i64);
        }
        let mut phase_x = vec![Complex64::new(0.0, 0.0); self.width];
        self.fourier_direct([omega[0], omega[1]], &mut phase_x)
    }
    fn spectral_integral(&self) -> f64 {
        self.mean
    }
    fn spectral_energy(&self) -> f64 {
        self.mean_square
    }
    /// Not isotropic: the mean of `|f̂|²` over the circle, `O(ρ w h)` per call, so the polar
    /// form is slow for large grids; the lattice form needs only integer frequencies.
    fn radial_power(&self, rho: f64) -> f64 {
        self.angular_mean(rho)
    }
    /// Jumps along cell edges: `|f̂|²` falls like `ρ^{-3}` on average in 2D.
    fn decay_exponent(&self) -> f64 {
        3.0
    }
    fn panel_width(&self) -> f64 {
        0.5
    }
    fn negligible_beyond(&self) -> f64 {
        f64::INFINITY
    }
}
