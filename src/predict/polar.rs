//! The polar form: one radial integral, for isotropic integrands.
//!
//! `Var[μ_N] = (1/N) [ M(S^{d-1}) ∫_0^∞ ρ^{d-1} P̆_f(ρ) P̆_S(ρ/N^{1/d}) dρ - P̆_S(0⁺) I² ]`.
//!
//! The last term excludes DC, which the exact lattice sum leaves out and the integral does not.
//! With Parseval (`M ∫ ρ^{d-1} P̆_f = ∫ f²`) the integral is evaluated as
//! `∫ f² - M ∫ ρ^{d-1} P̆_f (1 - P̆_S)`, and the second integral only where `P̆_S` differs from 1,
//! on panels of half an oscillation period: no oscillatory tail is ever integrated.

use super::{check_dimension, check_n, ErrorBudget, Form, Prediction, Route, SpectrumSource};
use crate::error::{invalid, Error, Result};
use crate::integrand::{sphere_measure, Integrand};
use crate::quadrature::{integrate_panels, panel_breakpoints};
use crate::spectrum::{ClosedForm, RadialSpectrum};

/// Parameters of the polar form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarParams {
    /// For closed forms that never become white (jitter): integrate up to this `ν`, and bound
    /// the rest. Default 32 in 1D and 2D, 8 in 3D (the angular mean costs more there).
    pub nu_max: Option<f64>,
    /// Absolute tolerance per panel, relative to `∫ f²`.
    pub tolerance: f64,
}

impl Default for PolarParams {
    fn default() -> Self {
        Self {
            nu_max: None,
            tolerance: 1e-14,
        }
    }
}

/// The polar-form variance of the homogenized estimator with `n` points.
///
/// # Errors
/// `n = 0`, or an estimated spectrum of another dimension than the integrand.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::predict::{predict_polar, PolarParams, SpectrumSource};
/// use specvar::spectrum::ClosedForm;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
/// let p = predict_polar(&disk, &SpectrumSource::Closed(ClosedForm::WhiteNoise), 64, &PolarParams::default()).unwrap();
/// let exact = (disk.integral_of_square() - disk.integral().powi(2)) / 64.0;
/// assert!((p.variance - exact).abs() < 1e-12 * exact);
/// ```
pub fn predict_polar(
    f: &dyn Integrand,
    source: &SpectrumSource<'_>,
    n: usize,
    params: &PolarParams,
) -> Result<Prediction> {
    check_n(n)?;
    let d = f.dimension();
    check_dimension(d)?;
    if !f.is_isotropic() {
        return Err(Error::OutsideValidity {
            route: "the polar form".into(),
            reason: format!("{} is not isotropic: use the lattice form", f.label()),
        });
    }
    if let SpectrumSource::Closed(c) = source {
        if !c.is_scale_invariant() {
            return Err(Error::OutsideValidity {
                route: "the polar form".into(),
                reason: format!(
                    "the closed form ({}) depends on N itself, not on ν alone: use the lattice \
                     form",
                    c.name()
                ),
            });
        }
    }
    if let SpectrumSource::Closed(ClosedForm::Jitter) = source {
        if crate::sampler::perfect_root(n, d).is_none() {
            return Err(invalid(
                "N",
                n,
                format!(
                    "m^{d} for jitter's closed radial form (rectangular strata are \
                     anisotropic: use the lattice form)"
                ),
            ));
        }
    }
    if let SpectrumSource::Estimated(e) = source {
        let r = &e.radial;
        if r.dimension != d {
            return Err(Error::Mismatch(format!(
                "spectrum of dimension {} for an integrand of dimension {d}",
                r.dimension
            )));
        }
    }
    let scale = (n as f64).powf(1.0 / d as f64);
    let measure = sphere_measure(d);
    let nu_end =
        white_beyond(source).unwrap_or(params.nu_max.unwrap_or(if d == 3 { 8.0 } else { 32.0 }));
    let rho_end = (nu_end * scale).min(f.negligible_beyond());
    let kinks: Vec<f64> = match source {
        SpectrumSource::Estimated(e) => e.radial.bins.iter().map(|b| b.nu * scale).collect(),
        SpectrumSource::Closed(_) => Vec::new(),
    };
    let width = f.panel_width().min(scale / 2.0);
    let breaks = panel_breakpoints(rho_end, width, kinks);
    let energy = f.spectral_energy();
    let tol = params.tolerance * energy.max(f64::MIN_POSITIVE);
    let radial = |rho: f64| measure * rho.powi(d as i32 - 1) * f.radial_power(rho);
    let deficit = integrate_panels(&breaks, tol, |rho| {
        radial(rho) * (1.0 - radial_power(source, d, rho / scale))
    });
    // Beyond rho_end the source is white, or P̆_f is negligible, or (jitter) the deficit is
    // bounded by its value at the end times the energy left there.
    let tail_bound = match white_beyond(source) {
        Some(_) => 0.0,
        None if rho_end >= f.negligible_beyond() => 0.0,
        None => {
            // Jitter: 1 - P̆_S is a mean of Π sinc²(π ν_i) ≤ sinc² of the largest component,
            // which is at least ν/√d: so 1 - P̆_S ≤ d / (π ν)² beyond ν_end.
            let inside = integrate_panels(&breaks, tol, radial);
            let envelope = d as f64 / (std::f64::consts::PI * nu_end).powi(2);
            (energy - inside.value).abs() * envelope.min(1.0)
        }
    };
    let integral = f.spectral_integral();
    let dc = dc_limit(source) * integral * integral;
    let spectrum_noise = match source {
        SpectrumSource::Estimated(e) => {
            propagated_stderr(&e.radial, &breaks, scale, integral, &|rho| radial(rho)) / n as f64
        }
        SpectrumSource::Closed(_) => 0.0,
    };
    Ok(Prediction {
        variance: (energy - deficit.value - dc) / n as f64,
        route: Route {
            form: Form::Polar,
            spectrum: source.origin(),
        },
        reason: String::new(),
        budget: ErrorBudget {
            spectrum_noise,
            quadrature: deficit.error / n as f64,
            truncation: tail_bound / n as f64,
            model: 0.0,
        },
        n,
        dimension: d,
        dc_term: dc / n as f64,
        evaluations: deficit.evaluations,
        alternatives: Vec::new(),
    })
}

/// The standard error of `N·Var` from the rings' standard errors. `N·Var` depends on the ring
/// powers `b_i` through the interpolated spectrum and the DC limit `a = Σ c_i b_i`:
/// `∂(N·Var)/∂b_i = ∫ W(ρ) ∂P̆_S/∂b_i dρ - c_i I²`, with `W = M ρ^{d-1} P̆_f`. Between rings the
/// log-log interpolation `P = b_{j-1}^{1-t} b_j^t` gives `∂P/∂b = (1-t) P/b_{j-1}` and `t P/b_j`;
/// below the first ring `P = a + (b_0 - a) u`, `u = (ν/ν_0)^γ`, gives `u` for `b_0` and `1 - u`
/// through `a` (the dependence of `γ` on the rings is neglected). Rings are independent sets of
/// frequencies, so the variances add. Weights by 16-point Gauss–Legendre on the panels.
fn propagated_stderr(
    r: &RadialSpectrum,
    breaks: &[f64],
    scale: f64,
    integral: f64,
    weight: &dyn Fn(f64) -> f64,
) -> f64 {
    let bins = &r.bins;
    if bins.len() < 2 {
        return f64::NAN;
    }
    let dc = RadialSpectrum::dc_weights(bins);
    let clamped = r.dc_limit <= 0.0;
    let mut sensitivity = vec![0.0; bins.len()];
    let mut via_dc = 0.0;
    if !clamped {
        via_dc -= integral * integral;
    }
    let gamma = r.first_segment_exponent();
    let rule = crate::quadrature::gauss_legendre(16);
    for w in breaks.windows(2) {
        let (mid, half) = ((w[0] + w[1]) / 2.0, (w[1] - w[0]) / 2.0);
        for (x, gw) in rule.0.iter().zip(&rule.1) {
            let rho = mid + half * x;
            let nu = rho / scale;
            let wt = gw * half * weight(rho);
            let j = bins.partition_point(|b| b.nu < nu);
            if j == 0 {
                let u = (nu / bins[0].nu).powf(gamma);
                sensitivity[0] += wt * u;
                if !clamped {
                    via_dc += wt * (1.0 - u);
                }
            } else if j < bins.len() {
                let (lo, hi) = (&bins[j - 1], &bins[j]);
                let t = (nu / lo.nu).ln() / (hi.nu / lo.nu).ln();
                if lo.power > 0.0 && hi.power > 0.0 {
                    let p = r.power_at(nu);
                    sensitivity[j - 1] += wt * (1.0 - t) * p / lo.power;
                    sensitivity[j] += wt * t * p / hi.power;
                } else {
                    sensitivity[j - 1] += wt * (1.0 - t);
                    sensitivity[j] += wt * t;
                }
            }
        }
    }
    for (i, c) in dc {
        sensitivity[i] += c * via_dc;
    }
    sensitivity
        .iter()
        .zip(bins)
        .map(|(s, b)| (s * b.stderr).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// `P̆_S(ν)` in dimension `d` (the closed forms reaching here are scale invariant).
fn radial_power(source: &SpectrumSource<'_>, d: usize, nu: f64) -> f64 {
    match source {
        SpectrumSource::Closed(c) => c.radial(d, nu).unwrap_or(1.0),
        SpectrumSource::Estimated(e) => e.radial.power_at(nu),
    }
}

/// `P̆_S(0⁺)`.
fn dc_limit(source: &SpectrumSource<'_>) -> f64 {
    match source {
        SpectrumSource::Closed(c) => c.dc_limit().unwrap_or(1.0),
        SpectrumSource::Estimated(e) => e.radial.dc_limit,
    }
}

/// The `ν` beyond which the radial spectrum is taken as white (`P̆_S = 1`), if it ever is.
fn white_beyond(source: &SpectrumSource<'_>) -> Option<f64> {
    match source {
        SpectrumSource::Closed(ClosedForm::WhiteNoise) => Some(0.0),
        SpectrumSource::Closed(_) => None,
        SpectrumSource::Estimated(e) => Some(e.radial.max_nu()),
    }
}
