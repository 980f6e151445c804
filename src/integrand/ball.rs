//! The ball (the disk in 2D, an interval in 1D) of constant height.

use super::{
    check_parameters, shift_phase, squared_distance, unit_ball_volume, Integrand, IntegrandKind,
};
use crate::error::{invalid, Result};
use num_complex::Complex64;
use std::f64::consts::PI;

/// `f(x) = a` inside the ball `|x - x0| < R`, 0 outside; the ball must lie inside the unit
/// cube, so that Monte Carlo on the torus sees the same function as the Fourier routes.
///
/// `f̂(ρ) = a (R/ρ)^{d/2} J_{d/2}(2π R ρ)`: `a sin(2πRρ)/(πρ)` in 1D, `a R J_1(2πRρ)/ρ` in 2D,
/// and in 3D `a (R/ρ)^{3/2} J_{3/2}(2πRρ)` with `J_{3/2}(t) = √(2/(πt)) (sin t / t - cos t)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Ball {
    radius: f64,
    centre: Vec<f64>,
    height: f64,
}

impl Ball {
    /// A ball of radius `radius`, centre `centre` (its length is the dimension, 1 to 3) and
    /// height `height`.
    ///
    /// # Errors
    /// A radius that is not positive and finite, a height that is not finite, a centre outside
    /// the cube, or a ball that does not fit inside the unit cube.
    ///
    /// # Examples
    /// ```
    /// use specvar::integrand::{Ball, Integrand};
    /// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    /// assert!((disk.integral() - std::f64::consts::PI / 16.0).abs() < 1e-15);
    /// assert!(Ball::new(0.3, vec![0.2, 0.5], 1.0).is_err()); // sticks out of the square
    /// ```
    pub fn new(radius: f64, centre: Vec<f64>, height: f64) -> Result<Self> {
        check_parameters("ball", "radius", radius, &centre, height)?;
        if centre.iter().any(|&c| c - radius < 0.0 || c + radius > 1.0) {
            return Err(invalid(
                "radius",
                radius,
                format!(
                    "at most the distance from the centre {centre:?} to the cube's faces: \
                     the predictions need the ball inside the unit cube, where the torus \
                     Fourier series and the closed-form transform agree"
                ),
            ));
        }
        Ok(Self {
            radius,
            centre,
            height,
        })
    }

    /// The radius.
    pub fn radius(&self) -> f64 {
        self.radius
    }
    /// The centre.
    pub fn centre(&self) -> &[f64] {
        &self.centre
    }
    /// The height.
    pub fn height(&self) -> f64 {
        self.height
    }

    fn volume(&self) -> f64 {
        unit_ball_volume(self.centre.len()) * self.radius.powi(self.centre.len() as i32)
    }

    /// The real transform of the centred ball at `|ω| = rho`.
    fn centred_transform(&self, rho: f64) -> f64 {
        let (r, a) = (self.radius, self.height);
        if rho == 0.0 {
            return a * self.volume();
        }
        let t = 2.0 * PI * r * rho;
        match self.centre.len() {
            1 => a * t.sin() / (PI * rho),
            2 => a * r * libm::j1(t) / rho,
            _ => {
                // Small t: the closed form cancels; use the series of 3 (sin t - t cos t)/t³.
                let ratio = if t < 1e-3 {
                    1.0 - t * t / 10.0 + t.powi(4) / 280.0
                } else {
                    3.0 * (t.sin() - t * t.cos()) / t.powi(3)
                };
                a * self.volume() * ratio
            }
        }
    }
}

impl Integrand for Ball {
    fn kind(&self) -> IntegrandKind {
        IntegrandKind::Ball
    }
    fn is_isotropic(&self) -> bool {
        true
    }
    fn label(&self) -> String {
        let name = if self.centre.len() == 2 {
            "disk"
        } else {
            "ball"
        };
        format!(
            "{name}(r={}, c={:?}, a={}, d={})",
            self.radius,
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
        if r2 < self.radius * self.radius {
            self.height
        } else {
            0.0
        }
    }
    fn integral(&self) -> f64 {
        self.height * self.volume()
    }
    fn integral_of_square(&self) -> f64 {
        self.height * self.height * self.volume()
    }
    fn fourier(&self, omega: &[f64]) -> Complex64 {
        let rho = omega.iter().map(|w| w * w).sum::<f64>().sqrt();
        shift_phase(omega, &self.centre) * self.centred_transform(rho)
    }
    fn spectral_integral(&self) -> f64 {
        self.integral()
    }
    fn spectral_energy(&self) -> f64 {
        self.integral_of_square()
    }
    fn radial_power(&self, rho: f64) -> f64 {
        self.centred_transform(rho).powi(2)
    }
    fn decay_exponent(&self) -> f64 {
        self.centre.len() as f64 + 1.0
    }
    fn panel_width(&self) -> f64 {
        // J(2πRρ) has zeros about π apart in t = 2πRρ: half a period is 1/(2R) in ρ.
        1.0 / (2.0 * self.radius)
    }
    fn negligible_beyond(&self) -> f64 {
        f64::INFINITY
    }
}
