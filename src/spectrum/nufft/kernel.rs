//! The "exponential of semicircle" spreading kernel and the error it leaves.
//!
//! `φ(z) = exp(β(√(1-z²) - 1))` on `|z| ≤ 1`, spread over `w` cells of a grid of `g` cells per
//! unit, with `β = 0.97 π (1 - 1/(2σ)) w` for the upsampling `σ = g / (2K+1)` (Barnett,
//! Magland and af Klinteberg 2019, section 4). The transform of one point at `x` is exact up to
//! aliasing: the error `|fast(k) - e^{-2πikx}|` depends only on where `x` falls within its
//! cell and on `k`, and it peaks at the band's edge `|k| = K`, where `ψ̂(k)` is smallest.
//! [`EsKernel::point_error`] measures its maximum; by the triangle inequality, a transform of
//! `N` points then errs by at most `N` times that at every frequency, whatever the points.

use crate::quadrature::gauss_legendre;
use num_complex::Complex64;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::sync::{Mutex, OnceLock};

/// The widest kernel, in cells. Wider kernels do not help: at upsampling 1.25 the error
/// reaches its floor near width 20, where rounding in the sums, amplified by `1/ψ̂(K)` at the
/// band's edge, takes over from aliasing (and the error grows again beyond).
pub const MAX_WIDTH: usize = 20;

/// Offsets within one cell at which the one-point error is measured; the error oscillates at
/// most `w` times across a cell, so 8 samples per oscillation find its peak to within 10%.
const OFFSETS: usize = 8 * MAX_WIDTH;

/// Margin on the sampled peak: the true maximum between samples exceeds the sampled one by at
/// most `1 / cos(π / 8) - 1 < 9%` for a sinusoid sampled 8 times per period.
const PEAK_MARGIN: f64 = 1.1;

/// An "exponential of semicircle" kernel of `width` cells on a grid of `grid` cells per unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EsKernel {
    /// Width in cells.
    pub width: usize,
    /// Shape parameter `β`.
    pub beta: f64,
    /// Grid cells per unit.
    pub grid: usize,
}

impl EsKernel {
    /// The kernel of `width` cells for a grid of `grid` cells holding the band `|k| ≤ kmax`,
    /// with the shape parameter recommended for its upsampling.
    pub fn for_band(width: usize, grid: usize, kmax: usize) -> Self {
        let sigma = grid as f64 / (2 * kmax + 1) as f64;
        Self {
            width,
            beta: 0.97 * PI * (1.0 - 0.5 / sigma) * width as f64,
            grid,
        }
    }

    /// Writes the kernel's values at the `w` cells `first, first+1, …` covering a point at
    /// `x` (in `[0, 1)`), and returns `first` (between `-w/2` and `g - w/2 + 1`).
    #[inline]
    pub fn values(&self, x: f64, values: &mut [f64]) -> isize {
        let half = self.width as f64 / 2.0;
        let centre = x * self.grid as f64;
        let first = (centre - half).ceil();
        let inv_half = 1.0 / half;
        for (i, v) in values.iter_mut().enumerate().take(self.width) {
            let z = (first + i as f64 - centre) * inv_half;
            *v = (self.beta * ((1.0 - z * z).max(0.0).sqrt() - 1.0)).exp();
        }
        first as isize
    }

    /// The Fourier transform `ψ̂(k) = ∫ ψ(x) e^{-2πikx} dx` of the kernel on the unit torus,
    /// `ψ(x) = φ(2gx / w)`. With `z = sin θ` the integrand is analytic, so Gauss–Legendre
    /// converges geometrically.
    pub fn fourier(&self, k: f64) -> f64 {
        self.fourier_with(k, &self.fourier_nodes())
    }

    /// Per quadrature node `θ = π/4 (s + 1)`: the weight times `φ(cos θ)`, `sin θ` and
    /// `cos θ`, which do not depend on `k`.
    fn fourier_nodes(&self) -> Vec<[f64; 3]> {
        let (nodes, weights) = quadrature_rule();
        nodes
            .iter()
            .zip(weights)
            .map(|(s, w)| {
                let theta = PI / 4.0 * (s + 1.0); // [-1, 1] → [0, π/2]
                let (sin, cos) = theta.sin_cos();
                let phi = (self.beta * (cos - 1.0)).exp();
                [w * phi, sin, cos]
            })
            .collect()
    }

    fn fourier_with(&self, k: f64, nodes: &[[f64; 3]]) -> f64 {
        let half = self.width as f64 / 2.0;
        let a = 2.0 * PI * k * half / self.grid as f64;
        let mut integral = 0.0;
        for &[weighted_phi, sin, cos] in nodes {
            integral += weighted_phi * (a * sin).cos() * cos;
        }
        // ∫_{-1}^{1} φ(z) cos(a z) dz = 2 ∫_0^{π/2} …, and dx = (w / 2g) dz.
        2.0 * (PI / 4.0) * integral * half / self.grid as f64
    }

    /// The deconvolution factors `1 / (g ψ̂(k))` for `k = -K..=K` (computed in parallel: a
    /// quadrature each, a few milliseconds in all for a large band).
    pub fn correction(&self, kmax: usize) -> Vec<f64> {
        let nodes = self.fourier_nodes();
        (0..=2 * kmax)
            .into_par_iter()
            .map(|t| {
                let k = t as f64 - kmax as f64;
                1.0 / (self.grid as f64 * self.fourier_with(k, &nodes))
            })
            .collect()
    }

    /// The largest error `|fast(k) - e^{-2πikx}|` of the one-point transform in one dimension
    /// over the band `|k| ≤ kmax`, with the values of the [`KernelTable`] the spreading uses:
    /// measured at offsets across a cell, at the band's edge where the error peaks (and, as a
    /// check, at `0` and `K/2`), times a 10% margin for the peak between samples.
    pub fn point_error(&self, kmax: usize) -> f64 {
        // Plans for the same band recur (an estimate, its budget check, the next estimate);
        // the error is a pure function of the kernel and the band, so it is remembered.
        static KNOWN: Mutex<BTreeMap<(usize, usize, u64, usize), f64>> =
            Mutex::new(BTreeMap::new());
        let key = (self.width, self.grid, self.beta.to_bits(), kmax);
        if let Some(e) = KNOWN.lock().ok().and_then(|m| m.get(&key).copied()) {
            return e;
        }
        let table = KernelTable::new(self);
        let e = self.point_error_of(kmax, |x, v| table.values_dyn(x, v));
        if let Ok(mut m) = KNOWN.lock() {
            m.insert(key, e);
        }
        e
    }

    /// As [`point_error`](Self::point_error) with a table of another polynomial degree, or
    /// (`None`) the kernel's exact values: what the table's degree costs in accuracy.
    pub fn point_error_at_degree(&self, kmax: usize, degree: Option<usize>) -> f64 {
        match degree {
            Some(p) => {
                let table = KernelTable::with_degree(self, p);
                self.point_error_of(kmax, |x, v| table.values_dyn(x, v))
            }
            None => self.point_error_of(kmax, |x, v| self.values(x, v)),
        }
    }

    fn point_error_of(&self, kmax: usize, values_at: impl Fn(f64, &mut [f64]) -> isize) -> f64 {
        let nodes = self.fourier_nodes();
        let g = self.grid as f64;
        let half = self.width as f64 / 2.0;
        let mut values = [0.0; MAX_WIDTH];
        let mut worst: f64 = 0.0;
        let edge = (kmax.saturating_sub(3)..=kmax).chain([0, kmax / 2]);
        for k in edge {
            let kf = k as f64;
            let correction = 1.0 / (g * self.fourier_with(kf, &nodes));
            // The phases of the w cells, e^{-2πik i/g}.
            let step = Complex64::from_polar(1.0, -2.0 * PI * kf / g);
            for s in 0..OFFSETS {
                // A point `t` cells left of the window's centre: its first cell is 0.
                let x = (half - (s as f64 + 0.5) / OFFSETS as f64) / g;
                let first = values_at(x, &mut values);
                debug_assert_eq!(first, 0);
                let mut phase = Complex64::new(1.0, 0.0);
                let mut sum = Complex64::new(0.0, 0.0);
                for v in &values[..self.width] {
                    sum += phase * *v;
                    phase *= step;
                }
                let exact = Complex64::from_polar(1.0, -2.0 * PI * kf * x);
                worst = worst.max((sum * correction - exact).norm());
            }
        }
        worst * PEAK_MARGIN
    }
}

/// Gauss–Legendre nodes for `ψ̂`: the integrand `e^{β(cos θ - 1)} cos(a sin θ) cos θ` is entire,
/// with `a ≤ πw/2` (at `|k| ≤ K`, `g ≥ 2K`) and `β < 3w`, so at most `2w` oscillations on
/// `[0, π/2]`; four nodes per oscillation and a margin resolve it to rounding.
const QUADRATURE_NODES: usize = 8 * MAX_WIDTH + 40;

/// The Gauss–Legendre rule of [`QUADRATURE_NODES`] nodes, computed once.
fn quadrature_rule() -> &'static (Vec<f64>, Vec<f64>) {
    static RULE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    RULE.get_or_init(|| gauss_legendre(QUADRATURE_NODES))
}

/// The error of a `d`-dimensional transform of one point from the one-dimensional error `e`
/// per axis: the product of `d` factors each within `e` of a unit phase.
pub fn tensor_error(e: f64, dimension: usize) -> f64 {
    (1.0 + e).powi(dimension as i32) - 1.0
}

/// The kernel's values as polynomials: for each of the `w` cells a point covers, a polynomial
/// of degree `p` in the point's offset `u ∈ [-1, 1]` within its cell (Chebyshev interpolation,
/// stored as monomial coefficients), evaluated by Horner's rule across the cells at once, with
/// no `exp` or `sqrt` per value. Its error is part of what [`EsKernel::point_error`] measures:
/// the one-point transform is computed with these very values.
#[derive(Debug, Clone, PartialEq)]
pub struct KernelTable {
    kernel: EsKernel,
    degree: usize,
    /// `coefficients[j * w + i]`: of `u^j` for cell `i`.
    coefficients: Vec<f64>,
}

impl KernelTable {
    /// The table of `kernel` at the degree [`table_degree`] gives its width.
    pub fn new(kernel: &EsKernel) -> Self {
        Self::with_degree(kernel, table_degree(kernel.width))
    }

    /// The table of `kernel` at polynomial degree `degree`.
    pub fn with_degree(kernel: &EsKernel, degree: usize) -> Self {
        let w = kernel.width;
        let half = w as f64 / 2.0;
        let nodes = degree + 1;
        // Chebyshev polynomials' monomial coefficients, T_n = 2u T_{n-1} - T_{n-2}: integers
        // below 2^degree, exact in f64.
        let mut chebyshev = vec![vec![0.0; nodes]; nodes];
        chebyshev[0][0] = 1.0;
        if nodes > 1 {
            chebyshev[1][1] = 1.0;
        }
        for n in 2..nodes {
            for j in 0..nodes {
                let up = if j > 0 {
                    2.0 * chebyshev[n - 1][j - 1]
                } else {
                    0.0
                };
                chebyshev[n][j] = up - chebyshev[n - 2][j];
            }
        }
        let angle = |m: usize| PI * (m as f64 + 0.5) / nodes as f64;
        // cos(n θ_m), the same for every cell.
        let cosines: Vec<f64> = (0..nodes)
            .flat_map(|n| (0..nodes).map(move |m| (n as f64 * angle(m)).cos()))
            .collect();
        let mut coefficients = vec![0.0; nodes * w];
        for i in 0..w {
            let f = |u: f64| {
                let t = (u + 1.0) / 2.0;
                let z = (t + i as f64) / half - 1.0;
                (kernel.beta * ((1.0 - z * z).max(0.0).sqrt() - 1.0)).exp()
            };
            let samples: Vec<f64> = (0..nodes).map(|m| f(angle(m).cos())).collect();
            for n in 0..nodes {
                let mut a: f64 = samples
                    .iter()
                    .zip(&cosines[n * nodes..][..nodes])
                    .map(|(v, c)| v * c)
                    .sum::<f64>()
                    * 2.0
                    / nodes as f64;
                if n == 0 {
                    a /= 2.0;
                }
                for j in 0..=n {
                    coefficients[j * w + i] += a * chebyshev[n][j];
                }
            }
        }
        Self {
            kernel: *kernel,
            degree,
            coefficients,
        }
    }

    /// The kernel.
    pub fn kernel(&self) -> &EsKernel {
        &self.kernel
    }

    /// Writes the values at the `W` cells covering a point at `x` (in `[0, 1)`) and returns
    /// the first cell, as [`EsKernel::values`] does. `W` must be the kernel's width.
    #[inline(always)]
    pub fn values<const W: usize>(&self, x: f64, values: &mut [f64; W]) -> isize {
        debug_assert_eq!(W, self.kernel.width);
        let half = W as f64 / 2.0;
        let left = x * self.kernel.grid as f64 - half;
        let first = left.ceil();
        let u = 2.0 * (first - left) - 1.0;
        let top: &[f64; W] = self.coefficients[self.degree * W..][..W]
            .try_into()
            .expect("W coefficients per degree");
        *values = *top;
        for j in (0..self.degree).rev() {
            let c: &[f64; W] = self.coefficients[j * W..][..W]
                .try_into()
                .expect("W coefficients per degree");
            for (v, c) in values.iter_mut().zip(c) {
                *v = *v * u + c;
            }
        }
        first as isize
    }

    /// As [`values`](Self::values), for a width known only at run time.
    pub fn values_dyn(&self, x: f64, values: &mut [f64]) -> isize {
        let w = self.kernel.width;
        let half = w as f64 / 2.0;
        let left = x * self.kernel.grid as f64 - half;
        let first = left.ceil();
        let u = 2.0 * (first - left) - 1.0;
        values[..w].copy_from_slice(&self.coefficients[self.degree * w..][..w]);
        for j in (0..self.degree).rev() {
            for (v, c) in values[..w].iter_mut().zip(&self.coefficients[j * w..][..w]) {
                *v = *v * u + c;
            }
        }
        first as isize
    }
}

/// The polynomial degree of a kernel table for width `w`: degree `w` already gives the
/// exact kernel's one-point error at every width and upsampling (to the digit, at `K` = 40 and
/// 320); two more degrees are a margin.
pub fn table_degree(width: usize) -> usize {
    width + 2
}
