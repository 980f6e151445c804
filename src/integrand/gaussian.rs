//! The isotropic Gaussian.

use super::{check_parameters, shift_phase, squared_distance, Integrand, IntegrandKind};
use crate::error::Result;
use num_complex::Complex64;
use std::f64::consts::PI;

/// `f(x) = a exp(-|x - x0|² / (2σ²))` on the unit cube (truncated there).
///
/// `f̂(ω) = a (2πσ²)^{d/2} exp(-2π² σ² |ω|²) e^{-2πi ω·x0}` over the whole space. Its integral
/// over the cube, the Monte Carlo ground truth, is the product over axes of
/// `σ √(π/2) [erf((1 - x0_i)/(σ√2)) + erf(x0_i/(σ√2))]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Gaussian {
    sigma: f64,
    centre: Vec<f64>,
    height: f64,
}

impl Gaussian {
    /// A Gaussian of width `sigma`, centre `centre` (its length is the dimension, 1 to 3) and
    /// height `height`.
    ///
    /// # Errors
    /// A σ that is not positive and finite, a height that is not finite, or a centre outside
    /// the cube.
    ///
    /// # Examples
    /// ```
    /// use specvar::integrand::{Gaussian, Integrand};
    /// let g = Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap();
    /// // Almost all of the mass 2πσ² lies inside the square.
    /// assert!((g.integral() - 2.0 * std::f64::consts::PI * 0.01).abs() < 1e-7);
    /// ```
    pub fn new(sigma: f64, centre: Vec<f64>, height: f64) -> Result<Self> {
        check_parameters("Gaussian", "sigma", sigma, &centre, height)?;
        Ok(Self {
            sigma,
            centre,
            height,
        })
    }

    /// The width σ.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// `∫_0^1 exp(-(x - c)² / (2 s²)) dx`.
    fn axis_integral(c: f64, s: f64) -> f64 {
        let k = s * std::f64::consts::SQRT_2;
        s * (PI / 2.0).sqrt() * (libm::erf((1.0 - c) / k) + libm::erf(c / k))
    }
}

impl Integrand for Gaussian {
    fn kind(&self) -> IntegrandKind {
        IntegrandKind::Gaussian
    }
    fn is_isotropic(&self) -> bool {
        true
    }
    fn label(&self) -> String {
        format!(
            "gaussian(sigma={}, c={:?}, a={}, d={})",
            self.sigma,
            self.centre,
            self.height,
            self.centre.len()
        )
    }
    fn dimension(&self) -> usize {
        self.centre.len()
    }
    fn eval(&self, x: &[f64]) -> f64 {
        let r2 = squared_distance(x, &self.centre);
        self.height * (-r2 / (2.0 * self.sigma * self.sigma)).exp()
    }
    fn integral(&self) -> f64 {
        let s = self.sigma;
        self.height
            * self
                .centre
                .iter()
                .map(|&c| Self::axis_integral(c, s))
                .product::<f64>()
    }
    fn integral_of_square(&self) -> f64 {
        // f² is a Gaussian of width σ/√2 and height a².
        let s = self.sigma / std::f64::consts::SQRT_2;
        self.height.powi(2)
            * self
                .centre
                .iter()
                .map(|&c| Self::axis_integral(c, s))
                .product::<f64>()
    }
    fn fourier(&self, omega: &[f64]) -> Complex64 {
        let rho2: f64 = omega.iter().map(|w| w * w).sum();
        let d = self.centre.len() as i32;
        let amplitude = self.height
            * (2.0 * PI * self.sigma * self.sigma).powf(d as f64 / 2.0)
            * (-2.0 * PI * PI * self.sigma * self.sigma * rho2).exp();
        shift_phase(omega, &self.centre) * amplitude
    }
    fn spectral_integral(&self) -> f64 {
        let d = self.centre.len() as f64;
        self.height * (2.0 * PI * self.sigma * self.sigma).powf(d / 2.0)
    }
    fn spectral_energy(&self) -> f64 {
        let d = self.centre.len() as f64;
        self.height.powi(2) * (PI * self.sigma * self.sigma).powf(d / 2.0)
    }
    fn radial_power(&self, rho: f64) -> f64 {
        let d = self.centre.len() as f64;
        let s2 = self.sigma * self.sigma;
        self.height.powi(2) * (2.0 * PI * s2).powf(d) * (-4.0 * PI * PI * s2 * rho * rho).exp()
    }
    fn decay_exponent(&self) -> f64 {
        f64::INFINITY
    }
    fn panel_width(&self) -> f64 {
        // The power falls by e over Δρ ≈ 1/(2πσ); panels a quarter of 1/σ wide.
        1.0 / (4.0 * self.sigma)
    }
    fn negligible_beyond(&self) -> f64 {
        // exp(-4π²σ²ρ²) < 1e-30 once 4π²σ²ρ² > 69.1.
        69.1f64.sqrt() / (2.0 * PI * self.sigma)
    }
}
