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
use std::f64::consts::PI;

/// The widest kernel, in cells.
pub const MAX_WIDTH: usize = 16;

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
        let (nodes, weights) = gauss_legendre(QUADRATURE_NODES);
        self.fourier_with(k, &nodes, &weights)
    }

    fn fourier_with(&self, k: f64, nodes: &[f64], weights: &[f64]) -> f64 {
        let half = self.width as f64 / 2.0;
        let a = 2.0 * PI * k * half / self.grid as f64;
        let mut integral = 0.0;
        for (s, w) in nodes.iter().zip(weights) {
            let theta = PI / 4.0 * (s + 1.0); // [-1, 1] → [0, π/2]
            let (sin, cos) = theta.sin_cos();
            let phi = (self.beta * (cos - 1.0)).exp();
            integral += w * phi * (a * sin).cos() * cos;
        }
        // ∫_{-1}^{1} φ(z) cos(a z) dz = 2 ∫_0^{π/2} …, and dx = (w / 2g) dz.
        2.0 * (PI / 4.0) * integral * half / self.grid as f64
    }

    /// The deconvolution factors `1 / (g ψ̂(k))` for `k = -K..=K`.
    pub fn correction(&self, kmax: usize) -> Vec<f64> {
        let (nodes, weights) = gauss_legendre(QUADRATURE_NODES);
        (0..=2 * kmax)
            .map(|t| {
                let k = t as f64 - kmax as f64;
                1.0 / (self.grid as f64 * self.fourier_with(k, &nodes, &weights))
            })
            .collect()
    }

    /// The largest error `|fast(k) - e^{-2πikx}|` of the one-point transform in one dimension
    /// over the band `|k| ≤ kmax`: measured at offsets across a cell, at the band's edge where
    /// the error peaks (and, as a check, at `0` and `K/2`), times [`PEAK_MARGIN`].
    pub fn point_error(&self, kmax: usize) -> f64 {
        let (nodes, weights) = gauss_legendre(QUADRATURE_NODES);
        let g = self.grid as f64;
        let half = self.width as f64 / 2.0;
        let mut values = [0.0; MAX_WIDTH];
        let mut worst: f64 = 0.0;
        let edge = (kmax.saturating_sub(3)..=kmax).chain([0, kmax / 2]);
        for k in edge {
            let kf = k as f64;
            let correction = 1.0 / (g * self.fourier_with(kf, &nodes, &weights));
            // The phases of the w cells, e^{-2πik i/g}.
            let step = num_complex::Complex64::from_polar(1.0, -2.0 * PI * kf / g);
            for s in 0..OFFSETS {
                // A point `t` cells left of the window's centre: its first cell is 0.
                let x = (half - (s as f64 + 0.5) / OFFSETS as f64) / g;
                let first = self.values(x, &mut values);
                debug_assert_eq!(first, 0);
                let mut phase = num_complex::Complex64::new(1.0, 0.0);
                let mut sum = num_complex::Complex64::new(0.0, 0.0);
                for v in &values[..self.width] {
                    sum += phase * *v;
                    phase *= step;
                }
                let exact = num_complex::Complex64::from_polar(1.0, -2.0 * PI * kf * x);
                worst = worst.max((sum * correction - exact).norm());
            }
        }
        worst * PEAK_MARGIN
    }
}

/// Gauss–Legendre nodes for `ψ̂`: the integrand `e^{β(cos θ - 1)} cos(a sin θ) cos θ` is entire,
/// with at most `(a + β)/π ≤ 2w` oscillations on `[0, π/2]`; 80 nodes resolve it to rounding.
const QUADRATURE_NODES: usize = 80;

/// The error of a `d`-dimensional transform of one point from the one-dimensional error `e`
/// per axis: the product of `d` factors each within `e` of a unit phase.
pub fn tensor_error(e: f64, dimension: usize) -> f64 {
    (1.0 + e).powi(dimension as i32) - 1.0
}
