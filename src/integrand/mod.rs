//! Integrands with closed-form Fourier transforms: balls, Gaussians, polygons and edges, and
//! functions tabulated on a grid ([`GridIntegrand`], whose coefficients come from an FFT).
//!
//! An [`Integrand`] lives on the unit torus `[0,1)^d`: Monte Carlo integrates what
//! [`Integrand::eval`] gives there, so its exact integral ([`Integrand::integral`]) is the
//! ground truth, and its Fourier coefficients at integer frequencies
//! ([`Integrand::coefficient`]) are those of that function, periodized: a Gaussian truncated to
//! the cube (its jumps at the faces give coefficients that fall like `1/k`), a [`Ball`] wrapped
//! around the torus (an integrand spec cuts it at the faces unless asked to `wrap`:
//! [`Ball::cut_at_the_faces`]). The lattice form uses these. The polar form uses the transform over the
//! whole space, `f̂(ω) = ∫ f(x) e^{-2πi ω·x} dx`, which agrees with them only while the
//! function is contained in the cube ([`Integrand::full_space_leak`]) and its autocorrelation's
//! images on the torus are negligible ([`Integrand::autocorrelation_beyond`]).

mod anisotropic;
mod ball;
mod ball_in_box;
mod disk_column;
mod gaussian;
mod grid;
mod grid_io;
mod interval_cells;
mod polygon;
mod polygon_lattice;
mod polygon_overlap;
mod product_form;
mod spec;
mod truncated_lobe;

pub use anisotropic::{AnisotropicGaussian, MAX_OUTSIDE_FRACTION};
pub use ball::{Ball, CUT_DISK_CELLS};
pub use gaussian::Gaussian;
pub use grid::{GridIntegrand, GridMeaning};
pub use grid_io::{grid_of_array, read_grid_exr, read_grid_file, read_grid_png, read_grid_text};
pub use polygon::{Polygon, MAX_VERTICES};
pub use product_form::{AxisFactor, ProductForm};
pub use spec::{parse_integrand, IntegrandKind, IntegrandSpec, INTEGRAND_FORMS};

use crate::error::{invalid, Result};
use crate::quadrature::CompensatedSum;
use crate::spectrum::Lattice;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::{PI, SQRT_2};

/// The moments of a separable integrand over the cells of a grid, one row of factors per
/// axis ([`Integrand::separable_cells`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SeparableCells {
    /// The factor common to every cell (the integrand's height).
    pub height: f64,
    /// Per axis, `∫` of the axis factor over each of its cells.
    pub mass: Vec<Vec<f64>>,
    /// Per axis, `∫` of the axis factor's square over each of its cells.
    pub square: Vec<Vec<f64>>,
}

/// One axis of a separable integrand on a regular grid ([`Integrand::separable_details`]).
#[derive(Debug, Clone, PartialEq)]
pub struct AxisDetails {
    /// `∫` of the axis factor `g` over each cell (shifted as asked).
    pub mass: Vec<f64>,
    /// A bound on the relative rounding of each entry of `mass`, beyond its ends'.
    pub mass_rounding: f64,
    /// A bound on the error each cell end adds to the masses beside it: an entry is within
    /// `mass_rounding · mass` and its two ends' errors, and since adjacent cells share the
    /// end between them, so is the sum of adjacent entries.
    pub end_rounding: f64,
    /// `Σ_c ∫_c (g − ḡ_c)²`, the factor's variance within the cells about each cell's mean
    /// `ḡ_c = mass_c / |c|`, taken directly: at fine cells it is far below `∫g²`, and the
    /// difference `∫g² − Σ_c mass_c² / |c|` would keep none of its digits.
    pub within: f64,
    /// A bound on the error of `within` (quadrature and rounding).
    pub within_error: f64,
}

/// The axis factors of a separable integrand `height · Π_l g_l(x_l)` on the cells of a regular
/// grid, with what the variance of its fine dyadic levels reads without cancellation
/// ([`Integrand::separable_details`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SeparableDetails {
    /// The factor common to every cell (the integrand's height).
    pub height: f64,
    /// Per axis, its rows and its variance within the cells.
    pub axes: Vec<AxisDetails>,
}

impl SeparableCells {
    /// `(∫_c f, ∫_c f²)` over cell `index` (axis 0 varying fastest).
    pub fn moments(&self, index: usize) -> (f64, f64) {
        let mut rest = index;
        let (mut mass, mut square) = (self.height, self.height * self.height);
        for (row, squares) in self.mass.iter().zip(&self.square) {
            let i = rest % row.len();
            rest /= row.len();
            mass *= row[i];
            square *= squares[i];
        }
        (mass, square)
    }
}

/// Relative rounding of one cell's moments ([`Integrand::box_moments`]) and of the terms built
/// from them (a few operations of unit roundoff each, and the 3D ball's slices at 1e-14).
pub(crate) const CELL_ROUNDING: f64 = 1e-13;

/// Whether an integrand is constant on a cell of `volume` where its moments are
/// `(∫ f, ∫ f²) = (mass, square)`: its variance inside within [`CELL_ROUNDING`] of its mean
/// square (a shape's cells wholly inside or outside it).
pub(crate) fn constant_on_cell(mass: f64, square: f64, volume: f64) -> bool {
    let (mean, second) = (mass / volume, square / volume);
    second - mean * mean <= CELL_ROUNDING * second
}

/// The integrals of an integrand over every cell of a grid ([`Integrand::grid_masses`]).
#[derive(Debug, Clone, PartialEq)]
pub struct GridMasses {
    /// `∫_c f` for each cell `c`, axis 0 varying fastest.
    pub masses: Vec<f64>,
    /// The cells on which the integrand is constant (its variance inside within `1e-13` of its
    /// mean square), cell `c` at bit `c % 64` of word `c / 64`, where the integrand knows them;
    /// `None` otherwise.
    pub constant: Option<Vec<u64>>,
}

/// A set of cells being built in parallel ([`GridMasses::constant`]): every cell in it until a
/// task clears it. Clearing is an atomic AND, so the set is the same whatever the order.
pub(crate) struct ConstantCells {
    words: Vec<std::sync::atomic::AtomicU64>,
    cells: usize,
}

impl ConstantCells {
    /// Every one of `cells` cells.
    pub(crate) fn all(cells: usize) -> Self {
        let words = (0..cells.div_ceil(64))
            .map(|_| std::sync::atomic::AtomicU64::new(!0))
            .collect();
        Self { words, cells }
    }

    /// Takes cell `c` out.
    pub(crate) fn clear(&self, c: usize) {
        self.words[c / 64].fetch_and(!(1 << (c % 64)), std::sync::atomic::Ordering::Relaxed);
    }

    /// The set as words (cell `c` at bit `c % 64` of word `c / 64`), the bits past the last
    /// cell clear.
    pub(crate) fn into_words(self) -> Vec<u64> {
        let mut words: Vec<u64> = self
            .words
            .into_iter()
            .map(std::sync::atomic::AtomicU64::into_inner)
            .collect();
        if let (Some(last), 1..) = (words.last_mut(), self.cells % 64) {
            *last &= (1u64 << (self.cells % 64)) - 1;
        }
        words
    }
}

/// Two sums over every cell `c` of a grid, with `F_c` the integrand's mean over the cell and
/// `V_c` its variance inside it ([`Integrand::cell_sums`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellSums {
    /// `Σ_c F_c²`.
    pub mean_square: f64,
    /// `Σ_c V_c`.
    pub within: f64,
    /// A bound on the error of `within` beyond rounding: 0 where every cell's moments were
    /// computed or known; where they were not (a smooth integrand on cells too many to visit)
    /// `within` is only bounded, and `mean_square`, the exact `Σ_c (F_c² + V_c)` less
    /// `within`, carries the same error with the opposite sign.
    pub within_error: f64,
    /// Where `within` is summed from non-negative terms of its own, a bound on its rounding;
    /// `None` where each cell's `V_c` is the difference of its second moment and squared
    /// mean, whose rounding is `1e-13` (the cells' rounding bound) of `within + mean_square`.
    pub within_rounding: Option<f64>,
    /// Cells whose moments were computed (the rest were known without).
    pub visited: u64,
}

impl CellSums {
    /// The sums over a grid from its columns' `(Σ F², Σ V, cells visited)`, summed with
    /// compensation.
    pub(crate) fn of_columns(columns: impl IntoIterator<Item = (f64, f64, u64)>) -> Self {
        let (mut squares, mut within, mut visited) =
            (CompensatedSum::default(), CompensatedSum::default(), 0);
        for (q, w, v) in columns {
            squares.add(q);
            within.add(w);
            visited += v;
        }
        Self {
            mean_square: squares.value(),
            within: within.value(),
            within_error: 0.0,
            within_rounding: None,
            visited,
        }
    }
}

/// The torus coefficients of a separable integrand, `f̂(k) = height · Π_a axes[a][k_a + K_a]`
/// on `|k_a| ≤ K_a` ([`Integrand::separable_coefficients`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SeparableCoefficients {
    /// The factor common to every coefficient (the integrand's height).
    pub height: f64,
    /// Per axis, the axis factor's coefficients for `k = -K_a..=K_a`.
    pub axes: Vec<Vec<Complex64>>,
}

/// `value(k)` at every frequency `k` of `lattice` (its `d` components), in lattice order, into
/// `out` (at most `lattice.len()` long), in parallel.
pub(crate) fn on_lattice<T: Send>(
    lattice: Lattice,
    out: &mut [T],
    value: impl Fn(&[i64]) -> T + Sync,
) {
    let d = lattice.dimension;
    out.par_iter_mut()
        .enumerate()
        .for_each(|(i, slot)| *slot = value(&lattice.frequency(i)[..d]));
}

/// The most memory an integrand's [`CoefficientTables`] may take.
pub const COEFFICIENT_TABLES_BYTES: usize = 64 << 20;

/// An integrand's coefficients on a box `|k_a| ≤ K`, each from tables built once
/// ([`Integrand::coefficient_tables`]).
pub trait CoefficientTables: Send + Sync {
    /// `f̂(k)`, for `|k_a| ≤ K`.
    fn at(&self, k: &[i64]) -> Complex64;
}

/// The torus coefficients of an integrand radial about a centre `c`,
/// `f̂(k) = T(|k|) e^{−2πi k·c}`, on `|k_a| ≤ K` (a ball's
/// [`Integrand::coefficient_tables`]): `T` once per squared radius `|k|²` the box holds, the
/// phase as a product of one table per axis, so a coefficient costs a lookup and `d` complex
/// products, no Bessel function nor sine.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialCoefficients {
    kmax: i64,
    /// `T(√s)` at every `s = |k|²` of the box (zero at the others).
    radial: Vec<f64>,
    /// Per axis, `e^{−2πi k c_a}` for `k = −K..=K`.
    phases: Vec<Vec<Complex64>>,
}

impl RadialCoefficients {
    /// The coefficients of `transform` (of `|k|`) about `centre` on `|k_a| ≤ kmax`, or `None`
    /// where the profile's `d K²` values would exceed [`COEFFICIENT_TABLES_BYTES`] (in 1D the
    /// profile outgrows the lattice, `2K + 1` values, long before that).
    /// `(|k|² as f64).sqrt()` is the radius as [`Integrand::coefficient`] takes it, to the bit.
    ///
    /// # Examples
    /// ```
    /// use specvar::integrand::{CoefficientTables, RadialCoefficients};
    /// // A profile of |k| about the centre (0.25, 0.5): its phase at k = (2, 1) is
    /// // e^{−2πi (0.5 + 0.5)} = 1, and |k| = √5.
    /// let profile = RadialCoefficients::new(&[0.25, 0.5], 4, |rho| rho).unwrap();
    /// let c = profile.at(&[2, 1]);
    /// assert!((c.re - 5f64.sqrt()).abs() < 1e-12 && c.im.abs() < 1e-12);
    /// // In 1D its K² values outgrow the lattice: refused beyond its memory.
    /// assert!(RadialCoefficients::new(&[0.5], 10_000_000, |rho| rho).is_none());
    /// ```
    pub fn new(centre: &[f64], kmax: usize, transform: impl Fn(f64) -> f64 + Sync) -> Option<Self> {
        let d = centre.len();
        if Self::bytes(d, kmax) > COEFFICIENT_TABLES_BYTES {
            return None;
        }
        let largest = d * kmax * kmax;
        // The squared radii of the box's frequencies: the octant k_a ≥ 0 holds them all.
        let mut needed = vec![false; largest + 1];
        let squares: Vec<usize> = (0..=kmax).map(|k| k * k).collect();
        let mut k = [0usize; 3];
        loop {
            needed[k[..d].iter().map(|&c| squares[c]).sum::<usize>()] = true;
            let Some(a) = (0..d).rev().find(|&a| k[a] < kmax) else {
                break;
            };
            k[a] += 1;
            k[a + 1..d].fill(0);
        }
        let present: Vec<usize> = (0..=largest).filter(|&s| needed[s]).collect();
        let values: Vec<f64> = present
            .par_iter()
            .map(|&s| transform((s as f64).sqrt()))
            .collect();
        let mut radial = vec![0.0; largest + 1];
        for (&s, v) in present.iter().zip(values) {
            radial[s] = v;
        }
        let kmax = kmax as i64;
        let phases = centre
            .iter()
            .map(|&c| {
                (-kmax..=kmax)
                    .map(|k| Complex64::from_polar(1.0, -2.0 * PI * k as f64 * c))
                    .collect()
            })
            .collect();
        Some(Self {
            kmax,
            radial,
            phases,
        })
    }

    /// The memory of the profile and its marks on `|k_a| ≤ kmax` in dimension `d`.
    pub fn bytes(d: usize, kmax: usize) -> usize {
        d.saturating_mul(kmax)
            .saturating_mul(kmax)
            .saturating_mul(size_of::<f64>() + 1)
    }

    /// `|f̂(k)|² = T(|k|)²`.
    pub fn power(&self, k: &[i64]) -> f64 {
        self.radial[k.iter().map(|&c| (c * c) as usize).sum::<usize>()].powi(2)
    }
}

impl CoefficientTables for RadialCoefficients {
    fn at(&self, k: &[i64]) -> Complex64 {
        let mut phase = Complex64::new(1.0, 0.0);
        let mut s = 0;
        for (table, &ka) in self.phases.iter().zip(k) {
            phase *= table[(ka + self.kmax) as usize];
            s += (ka * ka) as usize;
        }
        phase * self.radial[s]
    }
}

/// A real integrand on `[0,1)^d` with a closed-form Fourier transform.
pub trait Integrand: Send + Sync {
    /// Which kind of integrand this is.
    fn kind(&self) -> IntegrandKind;
    /// A short description with its parameters, e.g. `disk(r=0.25, a=1)`.
    fn label(&self) -> String;
    /// Whether `|f̂(ω)|` depends on `|ω|` alone, so that [`radial_power`](Self::radial_power) is
    /// its whole power spectrum and the polar form applies.
    fn is_isotropic(&self) -> bool;
    /// The dimension `d`.
    fn dimension(&self) -> usize;
    /// `f(x)` for `x` in the unit cube.
    fn eval(&self, x: &[f64]) -> f64;
    /// `Σ f(x)` over the points of `coords` (`d` coordinates each), summed in order: what
    /// Monte Carlo needs, with `eval` dispatched once per set rather than once per point.
    fn sum_at(&self, coords: &[f64]) -> f64 {
        coords
            .chunks_exact(self.dimension())
            .map(|x| self.eval(x))
            .sum()
    }
    /// `∫_{[0,1)^d} f`, exactly.
    fn integral(&self) -> f64;
    /// `∫_{[0,1)^d} f²`, exactly.
    fn integral_of_square(&self) -> f64;
    /// The torus Fourier coefficient `∫_{[0,1)^d} f(x) e^{-2πi k·x} dx` at integer `k` of the
    /// function [`eval`](Self::eval) defines: exact (truncation at the faces, wrapping, cells).
    fn coefficient(&self, k: &[i64]) -> Complex64;
    /// The torus Fourier coefficient of `f²` at integer `k`, exactly, where the integrand has
    /// one (`None` otherwise). Points drawn independently from known densities, as Gaussian
    /// jitter draws them, have `E f(x)²` from these coefficients (`docs/theory.md`, "Gaussian
    /// jitter as drawn").
    fn square_coefficient(&self, k: &[i64]) -> Option<Complex64> {
        let _ = k;
        None
    }
    /// The torus coefficients on `|k_a| ≤ kmax[a]` as one row per axis, when the integrand is
    /// a product of functions of one coordinate each (a Gaussian): sums over the lattice then
    /// factor into sums per axis. `None` otherwise.
    fn separable_coefficients(&self, kmax: &[usize]) -> Option<SeparableCoefficients> {
        let _ = kmax;
        None
    }
    /// `|coefficient(k)|²` for every frequency of `lattice`, in lattice order, into `out`
    /// (length `lattice.len()`). Separable integrands override it with per-axis tables.
    fn power_on_lattice(&self, lattice: Lattice, out: &mut [f64]) {
        on_lattice(lattice, out, |k| self.coefficient(k).norm_sqr());
    }
    /// Tables built once from which any coefficient on `|k_a| ≤ kmax` is a few products
    /// (a polygon's per-edge, per-axis sines and phases; a ball's radial profile and phases by
    /// axis), where the integrand has them and they fit [`COEFFICIENT_TABLES_BYTES`]; `None`
    /// otherwise.
    fn coefficient_tables(&self, kmax: usize) -> Option<Box<dyn CoefficientTables>> {
        let _ = kmax;
        None
    }
    /// [`coefficient`](Self::coefficient) at every frequency of `lattice`, in lattice order,
    /// into `out` (length `lattice.len()`), in parallel. A polygon overrides it with per-edge,
    /// per-axis tables of its sines and phases.
    fn coefficients_on_lattice(&self, lattice: Lattice, out: &mut [Complex64]) {
        on_lattice(lattice, out, |k| self.coefficient(k));
    }
    /// `∫ F_a(x)² dx` for the projection `F_a(x) = ∫ f dx_{b≠a}` onto axis `a`. By Parseval in
    /// 1D, `∫ F_a² - I²` is the energy on the axis line `k = k_a e_a` of the lattice, where
    /// samplers with per-axis stratification keep their power far from white.
    fn projection_energy(&self, axis: usize) -> f64;
    /// The torus autocorrelation `a_f(r) = ∫ f(x) f(x + r) dx` (`x + r` modulo 1), where it has
    /// a closed form. With it the lattice form of a pattern is exact in space:
    /// `(1/N) Σ_{k≠0} |f̂(k)|² P(k) = (1/N²) Σ_{i,j} a_f(x_i - x_j) - I²`.
    fn autocorrelation(&self, r: &[f64]) -> Option<f64> {
        let _ = r;
        None
    }
    /// `(∫_B f, ∫_B f²)` over the box `B = [lo, hi]` inside the unit cube, of the function
    /// [`eval`](Self::eval) defines (jumps, wrapping and all), exactly or to rounding; `None`
    /// where the integrand has no such form. The unshifted estimator of a stratified sampler
    /// is a sum over its cells of these two numbers (`docs/theory.md`, "Strata in space").
    fn box_moments(&self, lo: &[f64], hi: &[f64]) -> Option<(f64, f64)> {
        let _ = (lo, hi);
        None
    }
    /// `(∫_c f, ∫_c f²)` for the cells `c` of the regular grid with `grid[l]` cells on axis
    /// `l`, as one row of factors per axis, when the integrand is a product of functions of
    /// one coordinate each (a Gaussian): a cell's moments are then `d` products, where
    /// [`box_moments`](Self::box_moments) computes each from scratch. The products are the
    /// same operations in the same order as `box_moments`, so the two agree to the bit.
    fn separable_cells(&self, grid: &[usize]) -> Option<SeparableCells> {
        let _ = grid;
        None
    }
    /// [`separable_cells`](Self::separable_cells) of the integrand shifted by `t` on the torus
    /// (`f(x + t mod 1)`): a cell's axis integrals are summed over its pieces on either side
    /// of a face. `None` where the integrand is not separable. The randomly shifted estimator
    /// of the multi-jittered samplers reads one such set of rows per shift.
    fn shifted_separable_cells(&self, grid: &[usize], t: &[f64]) -> Option<SeparableCells> {
        let _ = (grid, t);
        None
    }
    /// [`shifted_separable_cells`](Self::shifted_separable_cells)' rows of axis masses with a
    /// bound on their relative rounding, and each axis factor's variance within the cells
    /// taken directly, where the integrand is separable; `None` otherwise. The variance of a
    /// scrambled net at large N is a sum over dyadic levels far finer than the integrand's
    /// features, whose parts these give without subtracting nearly equal sums.
    fn separable_details(&self, grid: &[usize], t: &[f64]) -> Option<SeparableDetails> {
        let _ = (grid, t);
        None
    }
    /// [`CellSums`] over every cell of the regular grid with `grid[l]` cells on axis `l`, in
    /// less work than one [`box_moments`](Self::box_moments) per cell, where the integrand has
    /// such a form: a separable one factors the sums by axis, a disk is constant on every cell
    /// its circle does not cross. `None` otherwise. The unshifted estimator of jitter and Latin
    /// hypercube reads these sums at counts whose cells are too many to visit.
    fn cell_sums(&self, grid: &[usize]) -> Option<CellSums> {
        let _ = grid;
        None
    }
    /// The cells [`cell_sums`](Self::cell_sums) visits for `grid`, or their equivalent in work:
    /// what a caller weighs against its work budget before asking. By default one row of cells
    /// per axis (a separable integrand's rows; a boundary's crossed cells are of that order).
    fn cell_sums_visits(&self, grid: &[usize]) -> f64 {
        grid.iter().sum::<usize>() as f64
    }
    /// `∫_c f` over every cell `c` of the regular grid with `grid[l]` cells on axis `l` (axis 0
    /// varying fastest), of the integrand shifted by `t` on the torus (`f(x + t mod 1)`), when
    /// it has a faster form than one [`box_moments`](Self::box_moments) per cell (a separable
    /// integrand: one row of axis integrals per axis; an unshifted polygon: a clip for each
    /// cell its boundary touches, the others whole or empty), with the cells on which it is
    /// constant where it knows them; `None` otherwise.
    fn grid_masses(&self, grid: &[usize], t: &[f64]) -> Option<GridMasses> {
        let _ = (grid, t);
        None
    }
    /// The level `a` at which the integrand is constant on every cell of the dyadic grid with
    /// `2^a` cells per axis (a tabulated grid of power-of-two sides), if it is: its Walsh
    /// coefficients beyond that level vanish, so a Walsh sum through it is exact.
    fn dyadic_level(&self) -> Option<u32> {
        None
    }
    /// The grid, where the integrand is a grid that tabulates a finer function
    /// ([`GridMeaning::CellAverages`] or [`GridMeaning::PointSamples`]): its predictions carry
    /// the tabulation term.
    fn tabulation(&self) -> Option<&GridIntegrand> {
        None
    }
    /// The integrand as `height · Π_l g_l(x_l)`, each factor analytic between its breakpoints
    /// ([`ProductForm`]), when it is one (a Gaussian, an axis-aligned rectangle); `None`
    /// otherwise. [`eval`](Self::eval) and the form agree wherever the factors are analytic.
    fn product_form(&self) -> Option<ProductForm> {
        None
    }
    /// `f̂(ω)` over the whole space, in closed form (the polar form's transform).
    fn fourier(&self, omega: &[f64]) -> Complex64;
    /// The relative difference between the full-space energy `∫_{R^d} f²` and the torus's
    /// `∫_{[0,1)^d} f²`: 0 when the function is contained in the cube; the polar form is only
    /// valid where it is negligible.
    fn full_space_leak(&self) -> f64 {
        0.0
    }
    /// A bound on the full-space function's autocorrelation `|a(r)|` at offsets whose largest
    /// component is at least `distance`, or `None` where the function offers none. The polar
    /// form's integral differs from the lattice sum by the autocorrelation's images at the
    /// non-zero integer offsets (Poisson summation), so this bounds its model error.
    fn autocorrelation_beyond(&self, distance: f64) -> Option<f64>;
    /// `f̂(0)`: the integral over the whole space (equal to [`integral`](Self::integral) when
    /// `f` vanishes outside the cube).
    fn spectral_integral(&self) -> f64;
    /// `∫ f²` over the whole space, which Parseval equates with `M(S^{d-1}) ∫ ρ^{d-1} P̆_f`.
    fn spectral_energy(&self) -> f64;
    /// The radial power spectrum `P̆_f(ρ) = |f̂|²` on the sphere `|ω| = ρ` (isotropic
    /// integrands only: their power depends on `|ω|` alone).
    fn radial_power(&self, rho: f64) -> f64;
    /// The decay exponent `β` of `P̆_f ~ ρ^{-β}` (infinite for a Gaussian).
    fn decay_exponent(&self) -> f64;
    /// Panel width in `ρ` for quadrature: half an oscillation period of the transform, or a
    /// natural scale for a non-oscillating one.
    fn panel_width(&self) -> f64;
    /// A radius beyond which `P̆_f` is negligible (below 1e-30 of its peak), or infinity.
    fn negligible_beyond(&self) -> f64;
    /// For a radial power that oscillates without end (a ball's Bessel function), its
    /// modulus–phase form at `rho > 0`: `P̆_f(ρ) = m(ρ) (1 + cos φ(ρ))` with `m` smooth and
    /// positive and `φ` increasing. The polar form integrates the smooth mean `m` at large `ρ`,
    /// where following each oscillation would cost work proportional to `N^{1/d}`, and bounds
    /// what the oscillation adds by the variation of `m P̆_S / φ'`. `None` where no such form
    /// is known (the default).
    fn radial_oscillation(&self, rho: f64) -> Option<RadialOscillation> {
        let _ = rho;
        None
    }
    /// For a smooth function (a Gaussian), the bound on its full-space power and on its images
    /// that a sum of its power over a dual lattice needs ([`SmoothDecay`]); `None` otherwise
    /// (the default).
    fn smooth_decay(&self) -> Option<SmoothDecay> {
        None
    }
}

/// What a sum of a smooth integrand's power over a lattice of frequencies needs to be bounded
/// ([`Integrand::smooth_decay`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothDecay {
    /// `A` in the bound `|f̂(ω)|² ≤ A e^{−c|ω|²}` on the full-space transform's power.
    pub peak: f64,
    /// `c` in that bound.
    pub rate: f64,
    /// A bound on `Σ_{n≠0} f(x + n)` over the cube (`f` taken over the whole space): the
    /// periodized function, whose torus coefficients the full-space transform gives at integer
    /// frequencies, differs from `f` on the cube by at most this.
    pub images: f64,
}

/// `Σ_{n ∈ Z^d, n ≠ 0} Π_a g_a(x_a + n_a)` bounded over the cube for the Gaussian factors
/// `g_a(t) = e^{−(t − c_a)²/(2s²)}`: on axis `a` the term `n_a = 0` is at most 1 and the others
/// sum to at most `T_a = 2 Σ_{j≥0} e^{−(m_a + j)²/(2s²)}`, `m_a` the centre's distance to the
/// nearer face (`x_a + n_a` lies outside `[0, 1]`), so the sum is at most `Π_a (1 + T_a) − 1`,
/// taken as `exp(Σ_a ln(1 + T_a)) − 1` so that a tiny `T_a` is not lost against 1.
pub(crate) fn gaussian_images(centre: &[f64], s: f64) -> f64 {
    let logs: f64 = centre
        .iter()
        .map(|&c| {
            let m = c.min(1.0 - c);
            // The terms to 12 widths past the face, and the rest bounded by the integral of
            // the decreasing term beyond the last: `s √(π/2) erfc((m + J)/(s√2))`.
            let last = (12.0 * s).ceil() as usize + 1;
            let t: f64 = (0..=last)
                .map(|j| (-(m + j as f64).powi(2) / (2.0 * s * s)).exp())
                .sum::<f64>()
                + s * (PI / 2.0).sqrt() * libm::erfc((m + last as f64) / (s * SQRT_2));
            (2.0 * t).ln_1p()
        })
        .sum();
    logs.exp_m1()
}

/// The modulus–phase form of an oscillating radial power at one radius (see
/// [`Integrand::radial_oscillation`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadialOscillation {
    /// The smooth mean `m(ρ)`, about which `P̆_f` oscillates between 0 and `2m`.
    pub mean: f64,
    /// The phase's rate `φ'(ρ) > 0`.
    pub phase_rate: f64,
}

/// The sphere measure `M(S^{d-1}) = 2 π^{d/2} / Γ(d/2)`: 2 in 1D, 2π in 2D, 4π in 3D.
///
/// # Examples
/// ```
/// use specvar::integrand::sphere_measure;
/// assert_eq!(sphere_measure(1), 2.0);
/// assert!((sphere_measure(3) - 4.0 * std::f64::consts::PI).abs() < 1e-14);
/// ```
pub fn sphere_measure(d: usize) -> f64 {
    use special::Gamma;
    2.0 * PI.powf(d as f64 / 2.0) / Gamma::gamma(d as f64 / 2.0)
}

/// The volume of the unit ball in dimension `d`: `π^{d/2} / Γ(d/2 + 1)`.
pub fn unit_ball_volume(d: usize) -> f64 {
    use special::Gamma;
    PI.powf(d as f64 / 2.0) / Gamma::gamma(d as f64 / 2.0 + 1.0)
}

/// The largest height accepted: energies and variances are squares of it and must stay finite.
pub const MAX_HEIGHT: f64 = 1e100;

/// Validates the parameters every integrand shares: dimension 1 to 3 (the centre's length), a
/// positive finite scale (`scale_name`: radius or σ), a finite height, a centre in the cube.
pub(crate) fn check_parameters(
    kind: &str,
    scale_name: &'static str,
    scale: f64,
    centre: &[f64],
    height: f64,
) -> Result<()> {
    let d = centre.len();
    if !(1..=3).contains(&d) {
        return Err(invalid("dimension", d, format!("1 to 3 for a {kind}")));
    }
    if !(scale.is_finite() && scale > 0.0) {
        return Err(invalid(scale_name, scale, "positive and finite"));
    }
    if !(height.is_finite() && height.abs() <= MAX_HEIGHT) {
        return Err(invalid(
            "height",
            height,
            format!("finite and at most {MAX_HEIGHT:e} in size (energies are squares of it)"),
        ));
    }
    check_centre(centre, d)
}

/// Validates a centre: `d` coordinates in `[0, 1]`.
pub(crate) fn check_centre(centre: &[f64], d: usize) -> Result<()> {
    if centre.len() != d || centre.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(invalid(
            "centre",
            format!("{centre:?}"),
            format!("{d} coordinates in [0, 1]"),
        ));
    }
    Ok(())
}

/// `|x - centre|²` (Euclidean, not toroidal: integrands live on the cube).
pub(crate) fn squared_distance(x: &[f64], centre: &[f64]) -> f64 {
    x.iter().zip(centre).map(|(a, b)| (a - b) * (a - b)).sum()
}

/// The mean of `|f̂|²` over the circle `|ω| = rho` in 2D, by the trapezoid rule over 256
/// angles (geometrically convergent for a smooth periodic function of the angle): the radial
/// power of an anisotropic integrand, which only the polar form reads (and refuses for them).
pub(crate) fn circular_mean_power(rho: f64, transform: impl Fn([f64; 2]) -> Complex64) -> f64 {
    const ANGLES: usize = 256;
    (0..ANGLES)
        .map(|i| {
            let t = 2.0 * PI * i as f64 / ANGLES as f64;
            transform([rho * t.cos(), rho * t.sin()]).norm_sqr()
        })
        .sum::<f64>()
        / ANGLES as f64
}

/// The phase factor `e^{-2πi ω·x0}` of a shift to `x0`.
pub(crate) fn shift_phase(omega: &[f64], centre: &[f64]) -> Complex64 {
    let phase: f64 = omega.iter().zip(centre).map(|(w, c)| w * c).sum();
    Complex64::from_polar(1.0, -2.0 * PI * phase)
}

/// `piece(a, b)` summed over the pieces of cell `i` of `m` equal cells of one axis shifted by
/// `t` on the torus ([`wrapped_interval`]): an empty piece adds no bit where `piece` gives 0.
pub(crate) fn over_wrapped_cell(
    i: usize,
    m: usize,
    t: f64,
    piece: impl Fn(f64, f64) -> f64,
) -> f64 {
    let cell = (i as f64 / m as f64, (i + 1) as f64 / m as f64);
    wrapped_interval(cell.0, cell.1, t)
        .iter()
        .map(|&(a, b)| piece(a, b))
        .fold(0.0, |sum, p| sum + p)
}

/// The interval `[lo, hi) + t` of one axis (inside `[0, 2)` for `lo, hi, t` in `[0, 1]`) taken
/// modulo 1: the part before the face and the part past it moved back by 1, either of them
/// possibly empty (`a ≥ b`).
pub(crate) fn wrapped_interval(lo: f64, hi: f64, t: f64) -> [(f64, f64); 2] {
    let (x, y) = (lo + t, hi + t);
    [
        (x.min(1.0), y.min(1.0)),
        ((x - 1.0).max(0.0), (y - 1.0).max(0.0)),
    ]
}
