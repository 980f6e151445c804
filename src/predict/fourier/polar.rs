//! The polar form: one radial integral, for isotropic integrands.
//!
//! `Var[μ_N] = (1/N) [ M(S^{d-1}) ∫_0^∞ ρ^{d-1} P̆_f(ρ) P̆_S(ρ/N^{1/d}) dρ - P̆_S(0⁺) I² ]`.
//!
//! The last term excludes DC, which the exact lattice sum leaves out and the integral does not.
//! With Parseval (`M ∫ ρ^{d-1} P̆_f = ∫ f²`) the integral is evaluated as
//! `∫ f² - M ∫ ρ^{d-1} P̆_f (1 - P̆_S)`, and the second integral only where `P̆_S` differs from 1,
//! on panels of half an oscillation period: no oscillatory tail is ever integrated.

use super::radial_table::RadialTable;
use crate::error::{invalid, Error, Result};
use crate::integrand::{sphere_measure, Integrand};
use crate::predict::{
    check_dimension, check_n, ErrorBudget, Form, Prediction, Route, SpectrumOrigin, SpectrumSource,
};
use crate::quadrature::{integrate_panels, panel_breakpoints, CompensatedSum, GaussLegendre};
use crate::spectrum::{ClosedForm, RadialSpectrum};

/// Parameters of the polar form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PolarParams {
    /// For closed forms that never become white (jitter): integrate up to this `ν`, and bound
    /// the rest. Default 32 in 1D and 2D, 8 in 3D (the angular mean costs more there).
    pub nu_max: Option<f64>,
    /// Absolute tolerance per panel, relative to `∫ f²`.
    pub tolerance: f64,
    /// Panels of half an oscillation the integral follows before, for an integrand with a
    /// modulus–phase form ([`Integrand::radial_oscillation`]), the rest is integrated through
    /// its smooth mean with the oscillation bounded: the work then no longer grows with N.
    pub max_panels: usize,
}

impl Default for PolarParams {
    fn default() -> Self {
        Self {
            nu_max: None,
            tolerance: 1e-14,
            max_panels: 1024,
        }
    }
}

/// Panels the polar integral may follow at most, with or without a modulus–phase form: beyond,
/// it is refused rather than left to run for hours.
const PANEL_LIMIT: f64 = 1e7;

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
    if let SpectrumSource::Closed(c) = source
        && !c.is_scale_invariant()
    {
        return Err(Error::OutsideValidity {
            route: "the polar form".into(),
            reason: format!(
                "the closed form ({}) depends on N itself, not on ν alone: use the lattice \
                     form",
                c.name()
            ),
        });
    }
    if let SpectrumSource::Closed(ClosedForm::Jitter) = source
        && crate::sampler::perfect_root(n, d).is_none()
    {
        return Err(invalid(
            "N",
            n,
            format!(
                "m^{d} for jitter's closed radial form (rectangular strata are \
                     anisotropic: use the lattice form)"
            ),
        ));
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
    let panels = rho_end / width;
    // A closed form's radial mean, tabulated once (white noise needs none) as far as it is
    // read: to `ν_end` where the far part is taken by its mean, else to `ρ_end` (at large N a
    // small part of `ν_end`, whose table would cost more than the integral).
    let table_to = |end: f64| match source {
        SpectrumSource::Closed(c) if *c != ClosedForm::WhiteNoise => RadialTable::new(*c, d, end),
        _ => None,
    };
    if panels > params.max_panels as f64
        && params.max_panels > 0
        && let (SpectrumSource::Closed(closed), Some(_)) = (source, f.radial_oscillation(rho_end))
    {
        let split = params.max_panels as f64 * width;
        let table = table_to(nu_end);
        return far_by_mean(f, *closed, n, params, (split, nu_end), table.as_ref());
    }
    if panels.is_nan() || panels > PANEL_LIMIT {
        return Err(Error::OutsideValidity {
            route: "the polar form".into(),
            reason: format!(
                "its integral would follow {panels:.1e} oscillations of {} (work growing like \
                 N^(1/d)), and the integrand has no modulus–phase form to integrate them by \
                 their mean; use the lattice form",
                f.label()
            ),
        });
    }
    let table = table_to(rho_end / scale);
    let breaks = panel_breakpoints(rho_end, width, kinks);
    let energy = f.spectral_energy();
    let tol = params.tolerance * energy.max(f64::MIN_POSITIVE);
    let radial = |rho: f64| measure * rho.powi(d as i32 - 1) * f.radial_power(rho);
    let deficit = integrate_panels(&breaks, tol, |rho| {
        radial(rho) * (1.0 - tabulated(table.as_ref(), source, d, rho / scale))
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
        randomization: crate::randomization::Randomization::Shift,
        variance: (energy - deficit.value - dc) / n as f64,
        route: Route {
            form: Form::Polar,
            spectrum: source.origin(),
        },
        reason: String::new(),
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise,
            // The table's error moves the integral by at most that much of ∫ W ≤ ∫ f².
            // The table is within a fraction of P̆_S everywhere: the integral ∫ W P̆_S, N Var
            // plus the DC term, within that fraction of itself.
            quadrature: (deficit.error
                + table.as_ref().map_or(0.0, |t| t.error()) * (energy - deficit.value))
                / n as f64,
            truncation: tail_bound / n as f64,
            model: 0.0,
        },
        n,
        dimension: d,
        dc_term: dc / n as f64,
        evaluations: deficit.evaluations,
        alternatives: Vec::new(),
        analysis: None,
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

/// `P̆_S(ν)` from the table where it covers `ν`, else from the source.
fn tabulated(table: Option<&RadialTable>, source: &SpectrumSource<'_>, d: usize, nu: f64) -> f64 {
    table
        .and_then(|t| t.at(nu))
        .unwrap_or_else(|| radial_power(source, d, nu))
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

/// The polar form with a closed-form spectrum for an integrand whose radial power oscillates
/// without end, `P̆_f = m (1 + cos φ)` ([`Integrand::radial_oscillation`]), at an N so large
/// that following every oscillation up to `ν_end` would cost work proportional to `N^{1/d}`.
/// With `W = M ρ^{d-1} P̆_f` and `W̄ = M ρ^{d-1} m`:
///
/// `N Var = ∫_0^{ρ_c} W P̆_S + ∫_{ρ_c}^∞ W̄ P̆_S + ∫_{ρ_c}^∞ W̄ P̆_S cos φ - P̆_S(0⁺) I²`
///
/// (`P̆_S` read at `ρ/N^{1/d}`). The first integral follows the oscillations on panels up to
/// `ρ_c`; the second is smooth, by Gauss–Legendre panels up to `ρ_end = ν_end N^{1/d}` and, with
/// `P̆_S` taken as 1 beyond (its deviation bounded as in the exact route), by the substitution
/// `x = ρ_end/ρ` to infinity. The third is bounded without computing it: with `h = W̄ P̆_S / φ'`,
/// `∫ h cos φ dφ` from `φ(ρ_c)` on is at most `2 TV(h)` (integration by parts against
/// `sin φ - sin φ(ρ_c)`, which is at most 2, and `h → 0`). `P̆_S(ρ_c/N^{1/d}) ≈ π²ν²/3` makes `h`
/// of order `N^{-2/d}` where the variance is of order `N^{-1/d}`: the bound shrinks like
/// `N^{-1/d} log N` relative to the value.
fn far_by_mean(
    f: &dyn Integrand,
    closed: ClosedForm,
    n: usize,
    params: &PolarParams,
    (split, nu_end): (f64, f64),
    table: Option<&RadialTable>,
) -> Result<Prediction> {
    let d = f.dimension();
    let scale = (n as f64).powf(1.0 / d as f64);
    let measure = sphere_measure(d);
    let rho_end = nu_end * scale;
    let energy = f.spectral_energy();
    let tol = params.tolerance * energy.max(f64::MIN_POSITIVE);
    let source = SpectrumSource::Closed(closed);
    let spectrum = |rho: f64| tabulated(table, &source, d, rho / scale);
    let jacobian = |rho: f64| measure * rho.powi(d as i32 - 1);
    let mean = |rho: f64| {
        f.radial_oscillation(rho)
            .map_or((0.0, 1.0), |o| (jacobian(rho) * o.mean, o.phase_rate))
    };
    let near_breaks = panel_breakpoints(split, f.panel_width(), Vec::new());
    let near = integrate_panels(&near_breaks, tol, |rho| {
        jacobian(rho) * f.radial_power(rho) * spectrum(rho)
    });
    // The smooth part on [ρ_c, ρ_end]: panels geometric (ratio 1.1) in ν up to 1, then 1/4 wide
    // in ν, where the spectrum has its structure (jitter's sinc² ripples are 1 apart).
    let mut edges = vec![split];
    while let Some(&last) = edges.last().filter(|&&b| b < rho_end) {
        edges.push((last * 1.1).min(last + scale / 4.0).min(rho_end));
    }
    let (fine, coarse) = (GaussLegendre::new(16), GaussLegendre::new(8));
    let mut smooth = CompensatedSum::default();
    let (mut smooth_error, mut evaluations) = (0.0, near.evaluations);
    // h = W̄ P̆_S / φ' at the nodes, in order, for its total variation.
    let mut h = Vec::with_capacity(16 * edges.len());
    for w in edges.windows(2) {
        let mut hi = 0.0;
        for (rho, weight) in fine.on(w[0], w[1]) {
            let (m, rate) = mean(rho);
            let p = spectrum(rho);
            hi += weight * m * p;
            h.push(m * p / rate);
        }
        let lo = coarse.integrate(w[0], w[1], |rho| mean(rho).0 * spectrum(rho));
        smooth.add(hi);
        smooth_error += (hi - lo).abs();
        evaluations += 24;
    }
    // Beyond ρ_end, P̆_S = 1 within δ = d/(πν_end)² (jitter; 0 for white noise): ∫ W̄ by
    // x = ρ_end/ρ on (0, 1], whose integrand tends to a finite limit as x → 0 (W̄ ~ ρ^{-2}).
    let beyond_integrand = |x: f64| mean(rho_end / x).0 * rho_end / (x * x);
    let beyond =
        fine.integrate(0.0, 0.5, beyond_integrand) + fine.integrate(0.5, 1.0, beyond_integrand);
    let beyond_lo =
        coarse.integrate(0.0, 0.5, beyond_integrand) + coarse.integrate(0.5, 1.0, beyond_integrand);
    let deviation = match closed {
        ClosedForm::WhiteNoise => 0.0,
        _ => (d as f64 / (std::f64::consts::PI * nu_end).powi(2)).min(1.0),
    };
    // Total variation of h: on [ρ_c, ρ_end] from its values at the nodes (doubled, so that an
    // extreme between two nodes is covered), beyond from h(ρ_end) (W̄/φ' decreases to 0) and
    // the ripples of P̆_S about 1, of amplitude δ(ν) ≈ d/(πν)², about one per unit of ν.
    let sampled: f64 = h.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
    let (m_end, rate_end) = mean(rho_end);
    let h_end = m_end / rate_end;
    let ripples = 4.0 * d as f64 / (std::f64::consts::PI.powi(2) * nu_end);
    let variation =
        2.0 * sampled + h_end * (1.0 + deviation + ripples) + h.first().copied().unwrap_or(0.0);
    let oscillation = 2.0 * variation;
    let integral = f.spectral_integral();
    let dc = closed.dc_limit().unwrap_or(1.0) * integral * integral;
    let total = near.value + smooth.value() + beyond - dc;
    Ok(Prediction {
        randomization: crate::randomization::Randomization::Shift,
        variance: total / n as f64,
        route: Route {
            form: Form::Polar,
            spectrum: SpectrumOrigin::Closed(closed),
        },
        reason: String::new(),
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise: 0.0,
            quadrature: (near.error
                + smooth_error
                + (beyond - beyond_lo).abs()
                + table.map_or(0.0, |t| t.error()) * (total + dc))
                / n as f64,
            truncation: (beyond * deviation + oscillation) / n as f64,
            model: 0.0,
        },
        n,
        dimension: d,
        dc_term: dc / n as f64,
        evaluations: evaluations + 64,
        alternatives: Vec::new(),
        analysis: None,
    })
}
