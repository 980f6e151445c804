//! An anisotropic Gaussian: a BRDF lobe or a blurred feature stretched along one direction, in
//! the square or crossing its faces.

use super::truncated_lobe::TruncatedLobe;
use super::{shift_phase, Integrand, IntegrandKind, MAX_HEIGHT};
use crate::error::{invalid, Result};
use crate::spectrum::Lattice;
use num_complex::Complex64;
use std::f64::consts::PI;

/// The largest mass the Gaussian may hold outside the unit square, relative to its total, for
/// its closed forms: below it the full-space transform, integral and energies are its torus
/// values to rounding (truncation changes them by at most this fraction). Above it the torus
/// values of the truncated function are computed ([`AnisotropicGaussian`]).
pub const MAX_OUTSIDE_FRACTION: f64 = 1e-15;

/// The most quadrature panels a truncated lobe may need before its oscillations (20 nodes each).
const MAX_PANELS: f64 = 5000.0;

/// The widest lobe accepted, in units of the square: wider, the function is nearly flat on the
/// square and its variance a small difference of large numbers (as for [`super::Gaussian`]).
pub const MAX_LOBE_SIGMA: f64 = 10.0;
/// The narrowest width of a lobe: `10^-6`, as for the isotropic Gaussian
/// ([`super::gaussian::MIN_SIGMA`]). Its sums over cells grow like `1/σ`: 0.9 s at `10^-6`,
/// 9 s at `10^-9` on jitter's 4 × 4 strata.
pub const MIN_LOBE_SIGMA: f64 = super::gaussian::MIN_SIGMA;

/// `a · exp(−½ (x − c)ᵀ Σ⁻¹ (x − c))` in 2D with `Σ = R(θ) diag(σ_1², σ_2²) R(θ)ᵀ`: widths
/// `σ_1` along the direction at angle `θ` and `σ_2` across it.
///
/// Monte Carlo integrates it on the square, zero outside. Contained in the square (its mass
/// outside, bounded by the four half-planes' tails, below [`MAX_OUTSIDE_FRACTION`]), its torus
/// coefficients are the full-space transform `a 2π √det Σ exp(−2π² kᵀΣk) e^{−2πik·c}` and its
/// integral, energy and autocorrelation have closed forms. Crossing the faces, the coefficients,
/// integral, energy and projections are those of the truncated function, exact to rounding:
/// one axis in closed form (Faddeeva), the other by Gauss–Legendre (see `truncated_lobe`); the
/// full-space transform then differs from the torus's, so the polar form is refused, and no
/// torus autocorrelation is offered.
///
/// # Examples
/// ```
/// use specvar::integrand::{AnisotropicGaussian, Integrand};
/// let lobe = AnisotropicGaussian::new(0.05, 0.01, 30.0, [0.5, 0.5], 1.0)?;
/// let i = lobe.integral();
/// assert!((i - 2.0 * std::f64::consts::PI * 0.05 * 0.01).abs() < 1e-15);
/// // Half of a lobe centred on a face lies outside: the square holds the other half.
/// let cut = AnisotropicGaussian::new(0.2, 0.05, 0.0, [0.5, 1.0], 1.0)?;
/// assert!((cut.integral() / (2.0 * std::f64::consts::PI * 0.2 * 0.05) - 0.5).abs() < 0.01);
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct AnisotropicGaussian {
    sigma: [f64; 2],
    angle: f64,
    centre: [f64; 2],
    height: f64,
    /// Σ as (xx, xy, yy).
    cov: [f64; 3],
    /// Σ⁻¹ as (xx, xy, yy).
    inv: [f64; 3],
    /// The truncated function's torus values, for a lobe that crosses the faces.
    truncated: Option<TruncatedLobe>,
}

impl AnisotropicGaussian {
    /// Widths `sigma_1` along the direction at `angle_degrees` and `sigma_2` across it.
    ///
    /// # Errors
    /// Widths outside `MIN_LOBE_SIGMA` to `MAX_LOBE_SIGMA`, a centre outside the
    /// square, or a non-finite angle or height.
    pub fn new(
        sigma_1: f64,
        sigma_2: f64,
        angle_degrees: f64,
        centre: [f64; 2],
        height: f64,
    ) -> Result<Self> {
        for (name, s) in [("sigma_1", sigma_1), ("sigma_2", sigma_2)] {
            if !(s.is_finite() && (MIN_LOBE_SIGMA..=MAX_LOBE_SIGMA).contains(&s)) {
                return Err(invalid(
                    name,
                    s,
                    format!(
                        "from {MIN_LOBE_SIGMA:e} to {MAX_LOBE_SIGMA}: the sums over a sampler's \
                         cells grow like 1/σ"
                    ),
                ));
            }
        }
        if !angle_degrees.is_finite() {
            return Err(invalid("angle", angle_degrees, "an angle in degrees"));
        }
        if !centre.iter().all(|c| (0.0..=1.0).contains(c)) {
            return Err(invalid(
                "centre",
                format!("{centre:?}"),
                "in the unit square",
            ));
        }
        if !(height.is_finite() && height.abs() <= MAX_HEIGHT) {
            return Err(invalid(
                "height",
                height,
                format!("finite, at most {MAX_HEIGHT:e}"),
            ));
        }
        let t = angle_degrees.to_radians();
        let (c, s) = (libm::cos(t), libm::sin(t));
        let (v1, v2) = (sigma_1 * sigma_1, sigma_2 * sigma_2);
        let cov = [
            v1 * c * c + v2 * s * s,
            (v1 - v2) * c * s,
            v1 * s * s + v2 * c * c,
        ];
        let det = v1 * v2;
        let inv = [cov[2] / det, -cov[1] / det, cov[0] / det];
        let mut g = Self {
            sigma: [sigma_1, sigma_2],
            angle: angle_degrees,
            centre,
            height,
            cov,
            inv,
            truncated: None,
        };
        if g.outside_fraction() > MAX_OUTSIDE_FRACTION {
            let lobe = TruncatedLobe {
                cov,
                centre,
                height,
            };
            // A thin lobe far from the axes needs panels as narrow as its width across them.
            if lobe.base_panels() > MAX_PANELS {
                return Err(invalid(
                    "anisotropic Gaussian",
                    format!(
                        "widths {sigma_1} and {sigma_2} at {angle_degrees}° crossing the faces"
                    ),
                    format!(
                        "a truncated lobe whose quadrature needs at most {MAX_PANELS} panels \
                         (a wider s2, an angle nearer an axis, or cell values for a thinner one)"
                    ),
                ));
            }
            g.truncated = Some(lobe);
        }
        Ok(g)
    }

    /// A bound on the fraction of the mass outside the square: the sum of the four
    /// half-planes' normal tails, `½ erfc(distance / (√2 σ_axis))`.
    pub fn outside_fraction(&self) -> f64 {
        (0..2)
            .map(|a| {
                let s = (2.0 * self.cov[2 * a]).sqrt();
                let c = self.centre[a];
                0.5 * (libm::erfc(c / s) + libm::erfc((1.0 - c) / s))
            })
            .sum()
    }

    fn det(&self) -> f64 {
        (self.sigma[0] * self.sigma[1]).powi(2)
    }

    /// `kᵀ Σ k`.
    fn quadratic(&self, k: [f64; 2]) -> f64 {
        self.cov[0] * k[0] * k[0] + 2.0 * self.cov[1] * k[0] * k[1] + self.cov[2] * k[1] * k[1]
    }

    /// `rᵀ Σ⁻¹ r`.
    fn inverse_quadratic(&self, r: [f64; 2]) -> f64 {
        self.inv[0] * r[0] * r[0] + 2.0 * self.inv[1] * r[0] * r[1] + self.inv[2] * r[1] * r[1]
    }

    fn transform(&self, nu: [f64; 2]) -> Complex64 {
        shift_phase(&nu, &self.centre) * self.amplitude(nu)
    }

    /// `|f̂(ν)|`, the transform without its phase: `exp` of an exponent below −745 is 0, which
    /// is returned without the library's slow path for results beyond the subnormals.
    fn amplitude(&self, nu: [f64; 2]) -> f64 {
        let exponent = -2.0 * PI * PI * self.quadratic(nu);
        if exponent < -745.2 {
            return 0.0;
        }
        self.spectral_integral() * exponent.exp()
    }
}

impl Integrand for AnisotropicGaussian {
    fn kind(&self) -> IntegrandKind {
        IntegrandKind::AnisotropicGaussian
    }
    fn label(&self) -> String {
        format!(
            "agaussian(s1={}, s2={}, angle={}, c={:?}, a={})",
            self.sigma[0], self.sigma[1], self.angle, self.centre, self.height
        )
    }
    fn is_isotropic(&self) -> bool {
        self.sigma[0] == self.sigma[1]
    }
    fn dimension(&self) -> usize {
        2
    }
    fn cell_sums(&self, grid: &[usize]) -> Option<super::CellSums> {
        // Too many cells to visit, but the lobe is smooth inside every cell: by Poincaré's
        // inequality on a rectangle `a × b`, `∫_c (f − F_c)² ≤ (a² ∫_c f_x² + b² ∫_c f_y²)/π²`,
        // and over the whole plane `∫ f_x² = ∫ f² (Σ⁻¹)_xx / 2` (∇f = −f Σ⁻¹ r, and f² is the
        // lobe of covariance Σ/2), which bounds the square's. So `Σ_c V_c = cells · Σ_c ∫_c
        // (f − F_c)²` lies in `[0, P]`; its midpoint is the value and half the interval its
        // error, while `Σ_c (F_c² + V_c) = cells · ∫ f²` exactly.
        let &[mx, my] = grid else {
            return None;
        };
        if mx == 0 || my == 0 {
            return None;
        }
        let cells = mx as f64 * my as f64;
        let (a, b) = (1.0 / mx as f64, 1.0 / my as f64);
        let energy = self.spectral_energy() / 2.0;
        let gradient = (a * a * energy * self.inv[0] + b * b * energy * self.inv[2]) / (PI * PI);
        let bound = cells * gradient;
        Some(super::CellSums {
            mean_square: cells * self.integral_of_square() - bound / 2.0,
            within: bound / 2.0,
            within_error: bound / 2.0,
            within_rounding: None,
            visited: 0,
        })
    }
    fn box_moments(&self, lo: &[f64], hi: &[f64]) -> Option<(f64, f64)> {
        let lobe = TruncatedLobe {
            cov: self.cov,
            centre: self.centre,
            height: self.height,
        };
        let (lo, hi) = ([lo[0], lo[1]], [hi[0], hi[1]]);
        Some(
            lobe.small_box_moments(lo, hi)
                .unwrap_or_else(|| (lobe.box_mass(lo, hi), lobe.squared().box_mass(lo, hi))),
        )
    }
    fn eval(&self, x: &[f64]) -> f64 {
        let r = [x[0] - self.centre[0], x[1] - self.centre[1]];
        self.height * (-0.5 * self.inverse_quadratic(r)).exp()
    }
    fn integral(&self) -> f64 {
        match &self.truncated {
            Some(lobe) => lobe.integral(),
            None => self.spectral_integral(),
        }
    }
    fn integral_of_square(&self) -> f64 {
        match &self.truncated {
            Some(lobe) => lobe.squared().integral(),
            None => self.spectral_energy(),
        }
    }
    fn coefficient(&self, k: &[i64]) -> Complex64 {
        match &self.truncated {
            Some(lobe) => lobe.coefficient([k[0], k[1]]),
            None => self.transform([k[0] as f64, k[1] as f64]),
        }
    }
    fn square_coefficient(&self, k: &[i64]) -> Option<Complex64> {
        // f² = a² exp(-rᵀΣ⁻¹r): the lobe of covariance Σ/2 and height a², whose transform has
        // half the exponent and, over the whole plane, a·(its integral)/2.
        Some(match &self.truncated {
            Some(lobe) => lobe.squared().coefficient([k[0], k[1]]),
            None => {
                let nu = [k[0] as f64, k[1] as f64];
                let amplitude = 0.5
                    * self.height
                    * self.spectral_integral()
                    * (-PI * PI * self.quadratic(nu)).exp();
                shift_phase(&nu, &self.centre) * amplitude
            }
        })
    }
    fn power_on_lattice(&self, lattice: Lattice, out: &mut [f64]) {
        match &self.truncated {
            Some(lobe) => lobe.power_on_lattice(lattice.kmax, out),
            None => {
                // The power needs no phase: one exponential a frequency, no sine or cosine.
                super::on_lattice(lattice, out, |k| {
                    self.amplitude([k[0] as f64, k[1] as f64]).powi(2)
                });
            }
        }
    }
    fn full_space_leak(&self) -> f64 {
        let full = self.spectral_energy();
        ((full - self.integral_of_square()) / full).abs()
    }
    fn projection_energy(&self, axis: usize) -> f64 {
        if let Some(lobe) = &self.truncated {
            return lobe.projection_energy(axis);
        }
        // ∫ f dx_other = a √(2π det/Σ_aa) exp(−x²/(2Σ_aa)), whose square integrates to
        // a² 2π (det/Σ_aa) √(π Σ_aa).
        let saa = self.cov[2 * axis];
        self.height * self.height * 2.0 * PI * self.det() / saa * (PI * saa).sqrt()
    }
    fn autocorrelation(&self, r: &[f64]) -> Option<f64> {
        if self.truncated.is_some() {
            // Truncated at the faces and wrapped: no closed form.
            return None;
        }
        // Contained: a(r) = a² π √det exp(−¼ rᵀΣ⁻¹r) for the nearest image of r, and the
        // Gaussian's reach (≤ 1/16 per axis) makes every other image negligible; the 3 × 3
        // images are summed all the same.
        let peak = self.spectral_energy();
        let mut total = 0.0;
        for i in -1..=1 {
            for j in -1..=1 {
                let d = [
                    crate::pointset::toroidal_delta(r[0], 0.0) + i as f64,
                    crate::pointset::toroidal_delta(r[1], 0.0) + j as f64,
                ];
                total += peak * (-0.25 * self.inverse_quadratic(d)).exp();
            }
        }
        Some(total)
    }
    fn fourier(&self, omega: &[f64]) -> Complex64 {
        self.transform([omega[0], omega[1]])
    }
    fn autocorrelation_beyond(&self, distance: f64) -> Option<f64> {
        // rᵀΣ⁻¹r ≥ |r|²/σ_max² and |r| is at least its largest component.
        let widest = self.sigma[0].max(self.sigma[1]);
        Some(self.spectral_energy() * (-distance.max(0.0).powi(2) / (4.0 * widest * widest)).exp())
    }
    fn spectral_integral(&self) -> f64 {
        self.height * 2.0 * PI * self.det().sqrt()
    }
    fn spectral_energy(&self) -> f64 {
        // f² is the Gaussian of covariance Σ/2 and height a².
        self.height * self.height * PI * self.det().sqrt()
    }
    fn radial_power(&self, rho: f64) -> f64 {
        super::circular_mean_power(rho, |nu| self.transform(nu))
    }
    fn decay_exponent(&self) -> f64 {
        f64::INFINITY
    }
    fn panel_width(&self) -> f64 {
        1.0 / (4.0 * self.sigma[0].min(self.sigma[1]))
    }
    fn negligible_beyond(&self) -> f64 {
        69.1f64.sqrt() / (2.0 * PI * self.sigma[0].min(self.sigma[1]))
    }
    fn smooth_decay(&self) -> Option<super::SmoothDecay> {
        // |f̂|² = (a 2π √det)² e^{−4π² kᵀΣk} and kᵀΣk ≥ s_min² |k|²; the lobe is below the
        // isotropic Gaussian of the larger width, whose images bound its own.
        let (narrow, wide) = (
            self.sigma[0].min(self.sigma[1]),
            self.sigma[0].max(self.sigma[1]),
        );
        Some(super::SmoothDecay {
            peak: self.spectral_integral().powi(2),
            rate: 4.0 * PI * PI * narrow * narrow,
            images: self.height.abs() * super::gaussian_images(&self.centre, wide),
        })
    }
}
