//! Variance and bias predicted from spectra.
//!
//! **Polar form** (homogenized pattern, isotropic spectra):
//!
//! `Var[μ_N] = (1/N) [ M(S^{d-1}) ∫_0^∞ ρ^{d-1} P̆_f(ρ) P̆_S(ρ/N^{1/d}) dρ - P̆_S(0⁺) I² ]`.
//!
//! The last term excludes DC, which the exact lattice sum leaves out and the integral does not.
//! With Parseval (`M ∫ ρ^{d-1} P̆_f = ∫ f²`) the integral is evaluated as
//! `∫ f² - M ∫ ρ^{d-1} P̆_f (1 - P̆_S)`, and the second integral only where `P̆_S` differs from 1,
//! on panels of half an oscillation period: no oscillatory tail is ever integrated.
//!
//! **Lattice form** (exact on the torus): `Var[μ_N] = (1/N) Σ_{k≠0} |f̂(k)|² E[P_S(k)]`, summed
//! over `|k_i| ≤ K`, and beyond `K` the remaining energy (by Parseval) times `P_S = 1`.
//!
//! **Bias** of a fixed pattern: `E[μ_N] - I = Σ_{k≠0} f̂(k)* Ŝ(k)`.

use crate::error::{invalid, Error, Result};
use crate::integrand::{sphere_measure, Integrand};
use crate::pointset::PointSet;
use crate::quadrature::{integrate_panels, panel_breakpoints, CompensatedSum};
use crate::spectrum::{lattice::direct_sums, ClosedForm, Lattice, LatticeSpectrum, RadialSpectrum};
use rayon::prelude::*;
use serde::Serialize;

/// Where a sampler's spectrum comes from.
#[derive(Debug, Clone, Copy)]
pub enum SpectrumSource<'a> {
    /// A closed form, exact at every N.
    Closed(ClosedForm),
    /// A radial spectrum estimated at some `N_ref`, used at every N through `ν = ρ/N^{1/d}`.
    Estimated(&'a RadialSpectrum),
}

impl SpectrumSource<'_> {
    /// A short description: `closed form (jitter)` or `estimated at N_ref = 4096 (64 realizations)`.
    pub fn label(&self) -> String {
        match self {
            SpectrumSource::Closed(c) => format!("closed form ({c:?})").to_lowercase(),
            SpectrumSource::Estimated(r) => format!(
                "estimated at N_ref = {} ({} realizations)",
                r.n, r.realizations
            ),
        }
    }

    /// `P̆_S(ν)` in dimension `d`.
    pub fn power(&self, d: usize, nu: f64) -> f64 {
        match self {
            SpectrumSource::Closed(c) => c.radial(d, nu),
            SpectrumSource::Estimated(r) => r.power_at(nu),
        }
    }

    /// `P̆_S(0⁺)`.
    pub fn dc_limit(&self) -> f64 {
        match self {
            SpectrumSource::Closed(c) => c.dc_limit(),
            SpectrumSource::Estimated(r) => r.dc_limit,
        }
    }

    /// The `ν` beyond which the source is white (`P̆_S = 1`), if it ever is.
    fn white_beyond(&self) -> Option<f64> {
        match self {
            SpectrumSource::Closed(ClosedForm::WhiteNoise) => Some(0.0),
            SpectrumSource::Closed(ClosedForm::Jitter) => None,
            SpectrumSource::Estimated(r) => Some(r.max_nu()),
        }
    }
}

/// Which route a prediction took.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Form {
    /// The radial integral.
    Polar,
    /// The sum over the integer lattice.
    Lattice,
}

/// A predicted variance.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prediction {
    /// The route.
    pub form: Form,
    /// The spectrum source, in words.
    pub spectrum_source: String,
    /// Points per pattern.
    pub n: usize,
    /// Dimension.
    pub dimension: usize,
    /// `Var[μ_N]` of the homogenized estimator.
    pub variance: f64,
    /// The DC term `P̆_S(0⁺) I² / N` already subtracted (0 for the lattice form).
    pub dc_term: f64,
    /// An error estimate: quadrature error plus a bound on the truncated tail.
    pub error_estimate: f64,
    /// Integrand or spectrum evaluations spent.
    pub evaluations: u64,
    /// The standard error of `variance` due to the noise of an estimated spectrum (its rings'
    /// standard errors propagated through the linear map from ring powers to the variance);
    /// 0 for closed forms.
    pub spectrum_stderr: f64,
}

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

fn check_n(n: usize) -> Result<()> {
    if n == 0 {
        return Err(invalid("N", 0, "at least 1"));
    }
    Ok(())
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
/// let p = predict_polar(&disk, SpectrumSource::Closed(ClosedForm::WhiteNoise), 64, &PolarParams::default()).unwrap();
/// let exact = (disk.integral_of_square() - disk.integral().powi(2)) / 64.0;
/// assert!((p.variance - exact).abs() < 1e-12 * exact);
/// ```
pub fn predict_polar(
    f: &dyn Integrand,
    source: SpectrumSource<'_>,
    n: usize,
    params: &PolarParams,
) -> Result<Prediction> {
    check_n(n)?;
    let d = f.dimension();
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
    if let SpectrumSource::Estimated(r) = source {
        if r.dimension != d {
            return Err(Error::Mismatch(format!(
                "spectrum of dimension {} for an integrand of dimension {d}",
                r.dimension
            )));
        }
    }
    let scale = (n as f64).powf(1.0 / d as f64);
    let measure = sphere_measure(d);
    let nu_end = source
        .white_beyond()
        .unwrap_or(params.nu_max.unwrap_or(if d == 3 { 8.0 } else { 32.0 }));
    let rho_end = (nu_end * scale).min(f.negligible_beyond());
    let kinks: Vec<f64> = match source {
        SpectrumSource::Estimated(r) => r.bins.iter().map(|b| b.nu * scale).collect(),
        SpectrumSource::Closed(_) => Vec::new(),
    };
    let width = f.panel_width().min(scale / 2.0);
    let breaks = panel_breakpoints(rho_end, width, kinks);
    let energy = f.spectral_energy();
    let tol = params.tolerance * energy.max(f64::MIN_POSITIVE);
    let radial = |rho: f64| measure * rho.powi(d as i32 - 1) * f.radial_power(rho);
    let deficit = integrate_panels(&breaks, tol, |rho| {
        radial(rho) * (1.0 - source.power(d, rho / scale))
    });
    // Beyond rho_end the source is white, or P̆_f is negligible, or (jitter) the deficit is
    // bounded by its value at the end times the energy left there.
    let tail_bound = match source.white_beyond() {
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
    let dc = source.dc_limit() * integral * integral;
    let spectrum_stderr = match source {
        SpectrumSource::Estimated(r) => {
            propagated_stderr(r, &breaks, scale, integral, &|rho| radial(rho)) / n as f64
        }
        SpectrumSource::Closed(_) => 0.0,
    };
    Ok(Prediction {
        form: Form::Polar,
        spectrum_source: source.label(),
        n,
        dimension: d,
        variance: (energy - deficit.value - dc) / n as f64,
        dc_term: dc / n as f64,
        error_estimate: (deficit.error + tail_bound) / n as f64,
        evaluations: deficit.evaluations,
        spectrum_stderr,
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

/// The expected spectrum on the lattice, for the lattice form.
#[derive(Debug, Clone, Copy)]
pub enum LatticeSource<'a> {
    /// A closed form evaluated at the integer frequencies (jitter needs `N = m^d`).
    Closed(ClosedForm),
    /// A spectrum estimated at the target N.
    Estimated(&'a LatticeSpectrum),
}

/// An integrand's power `|f̂(k)|²` on a lattice of integer frequencies, with the energy beyond
/// it: everything the lattice form needs from the integrand. The mean of these over many
/// integrands (the pixels of an image) predicts their mean variance, since the variance is
/// linear in the power.
#[derive(Debug, Clone, PartialEq)]
pub struct LatticePower {
    /// The frequencies.
    pub lattice: Lattice,
    /// `|f̂(k)|²` in lattice order (0 at DC, which the variance excludes).
    pub power: Vec<f64>,
    /// `∫ f² - I² - Σ_{k≠0 in the lattice} |f̂(k)|²` by Parseval: the energy beyond the lattice.
    pub beyond: f64,
    /// What it is the power of.
    pub label: String,
}

impl LatticePower {
    /// The power of `f` on `lattice` (computed in parallel over rows).
    ///
    /// # Errors
    /// A lattice of another dimension than `f`.
    pub fn of(f: &dyn Integrand, lattice: Lattice) -> Result<Self> {
        let d = f.dimension();
        if lattice.dimension != d {
            return Err(Error::Mismatch(format!(
                "lattice of dimension {} for an integrand of dimension {d}",
                lattice.dimension
            )));
        }
        let side = lattice.side();
        let mut power = vec![0.0; lattice.len()];
        power.par_chunks_mut(side).enumerate().for_each(|(r, row)| {
            let mut omega = [0.0; 3];
            for (j, slot) in row.iter_mut().enumerate() {
                let i = r * side + j;
                if i == lattice.dc_index() {
                    continue;
                }
                let k = lattice.frequency(i);
                for a in 0..d {
                    omega[a] = k[a] as f64;
                }
                *slot = f.fourier(&omega[..d]).norm_sqr();
            }
        });
        let mut inside = CompensatedSum::default();
        power.iter().for_each(|&p| inside.add(p));
        let i0 = f.spectral_integral();
        Ok(Self {
            lattice,
            beyond: (f.spectral_energy() - i0 * i0 - inside.value()).max(0.0),
            power,
            label: f.label(),
        })
    }

    /// The mean of several powers on one lattice.
    ///
    /// # Errors
    /// No parts, or parts on different lattices.
    pub fn mean(parts: &[LatticePower], label: impl Into<String>) -> Result<Self> {
        let first = parts
            .first()
            .ok_or_else(|| invalid("lattice powers", 0, "at least one"))?;
        if parts.iter().any(|p| p.lattice != first.lattice) {
            return Err(Error::Mismatch(
                "lattice powers on different lattices".into(),
            ));
        }
        let scale = 1.0 / parts.len() as f64;
        let mut power = vec![0.0; first.power.len()];
        for part in parts {
            for (acc, p) in power.iter_mut().zip(&part.power) {
                *acc += p * scale;
            }
        }
        Ok(Self {
            lattice: first.lattice,
            power,
            beyond: parts.iter().map(|p| p.beyond).sum::<f64>() * scale,
            label: label.into(),
        })
    }
}

/// The lattice-form variance of the homogenized estimator with `n` points, summed over
/// `|k_i| ≤ kmax` (for an estimated spectrum, its own K), with `P_S = 1` assumed beyond.
///
/// # Errors
/// `n = 0`, a dimension mismatch, or an estimated spectrum at another N.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::predict::{predict_lattice, LatticeSource};
/// use specvar::spectrum::ClosedForm;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
/// let p = predict_lattice(&disk, LatticeSource::Closed(ClosedForm::WhiteNoise), 64, 32).unwrap();
/// let exact = (disk.integral_of_square() - disk.integral().powi(2)) / 64.0;
/// assert!((p.variance - exact).abs() < 1e-12 * exact);
/// ```
pub fn predict_lattice(
    f: &dyn Integrand,
    source: LatticeSource<'_>,
    n: usize,
    kmax: usize,
) -> Result<Prediction> {
    let lattice = match source {
        LatticeSource::Closed(_) => Lattice {
            dimension: f.dimension(),
            kmax,
        },
        LatticeSource::Estimated(s) => s.lattice,
    };
    // A lattice of another dimension is refused by `LatticePower::of`.
    predict_from_power(&LatticePower::of(f, lattice)?, source, n)
}

/// The lattice-form variance from an integrand's power on the lattice (see [`LatticePower`]):
/// `(Σ_{k≠0} |f̂(k)|² P_S(k) + beyond) / N`, the energy beyond the lattice counted as white.
///
/// # Errors
/// `n = 0`, or an estimated spectrum at another N or on another lattice.
pub fn predict_from_power(
    power: &LatticePower,
    source: LatticeSource<'_>,
    n: usize,
) -> Result<Prediction> {
    check_n(n)?;
    let lattice = power.lattice;
    let d = lattice.dimension;
    let label = match source {
        LatticeSource::Closed(c) => format!("closed form ({c:?})").to_lowercase(),
        LatticeSource::Estimated(s) => {
            if s.n != n || s.lattice != lattice {
                return Err(Error::Mismatch(format!(
                    "lattice spectrum of N = {} in {}D with K = {} for N = {n} in {d}D with K = {}",
                    s.n, s.lattice.dimension, s.lattice.kmax, lattice.kmax
                )));
            }
            format!("estimated at N = {} ({} realizations)", s.n, s.realizations)
        }
    };
    let side = lattice.side();
    let edge = lattice.kmax as u64;
    // Per row: Σ |f̂|² P, the edge's Σ |f̂|² |1 - P|, and Σ (|f̂|² se(P))².
    let per_row: Vec<[f64; 3]> = power
        .power
        .par_chunks(side)
        .enumerate()
        .map(|(r, row)| {
            let mut acc = [0.0; 3];
            for (j, &power_f) in row.iter().enumerate() {
                let i = r * side + j;
                if i == lattice.dc_index() {
                    continue;
                }
                let k = lattice.frequency(i);
                let (power_s, se) = match source {
                    LatticeSource::Closed(c) => (c.lattice_power(&k[..d], n), 0.0),
                    LatticeSource::Estimated(s) => (s.mean[i], s.stderr[i]),
                };
                acc[0] += power_f * power_s;
                if k[..d].iter().any(|c| c.unsigned_abs() == edge) {
                    acc[1] += power_f * (1.0 - power_s).abs();
                }
                if se.is_finite() {
                    acc[2] += (power_f * se).powi(2);
                }
            }
            acc
        })
        .collect();
    let mut weighted = CompensatedSum::default();
    let (mut edge_sum, mut noise) = (0.0, 0.0);
    for [w, e, q] in per_row {
        weighted.add(w);
        edge_sum += e;
        noise += q;
    }
    Ok(Prediction {
        form: Form::Lattice,
        spectrum_source: label,
        n,
        dimension: d,
        variance: (weighted.value() + power.beyond) / n as f64,
        dc_term: 0.0,
        error_estimate: edge_sum.min(power.beyond) / n as f64,
        evaluations: lattice.len() as u64,
        // P(k) = P(-k) exactly, so the two halves add coherently: 2 Σ (w se)².
        spectrum_stderr: (2.0 * noise).sqrt() / n as f64,
    })
}

/// The bias `E[μ_N] - I` of a fixed pattern, from its sampling spectrum on `|k_i| ≤ kmax`:
/// `Σ_{k≠0} Re(f̂(k)* Ŝ(k))`. Exact as `kmax` grows; converges fast for smooth integrands.
///
/// # Errors
/// A dimension mismatch or a dimension above 3.
pub fn bias_of_pattern(f: &dyn Integrand, points: &PointSet, kmax: usize) -> Result<f64> {
    let d = points.dimension();
    if d != f.dimension() || d > 3 {
        return Err(Error::Mismatch(format!(
            "points of dimension {d} for an integrand of dimension {} (1 to 3)",
            f.dimension()
        )));
    }
    let sums = direct_sums(points, kmax);
    let lattice = Lattice { dimension: d, kmax };
    let n = points.len() as f64;
    let mut total = CompensatedSum::default();
    for (i, s) in sums.iter().enumerate() {
        if i == lattice.dc_index() {
            continue;
        }
        let k = lattice.frequency(i);
        let omega: Vec<f64> = k[..d].iter().map(|&c| c as f64).collect();
        total.add((f.fourier(&omega).conj() * s).re / n);
    }
    Ok(total.value())
}

/// The bias of the fixed cell-centred regular grid with `n = m^d` points, from its exact
/// sampling spectrum `Ŝ(m q) = (-1)^{|q|_1}` (zero at every other integer frequency):
/// `Σ_{q≠0} Re f̂(m q) (-1)^{|q|_1}`, summed over shells `|q|_∞ ≤ Q` until a shell adds less
/// than 1e-17 of `∫ f²`, or `Q` = 512, 128, 32 in 1D, 2D, 3D. Returns the bias and the last shell's contribution.
///
/// # Errors
/// `n` not a perfect power.
pub fn regular_grid_bias(f: &dyn Integrand, n: usize) -> Result<(f64, f64)> {
    let d = f.dimension();
    let m = crate::sampler::perfect_root(n, d)
        .ok_or_else(|| invalid("N", n, format!("m^{d} for the regular grid")))?;
    let threshold = 1e-17 * f.spectral_energy().max(f64::MIN_POSITIVE);
    let mut total = CompensatedSum::default();
    let mut last = 0.0;
    let max_shell: i64 = [512, 128, 32][d - 1];
    for shell in 1..=max_shell {
        let mut contribution = CompensatedSum::default();
        for_each_on_shell(d, shell, |q| {
            let omega: Vec<f64> = q.iter().map(|&c| (c * m as i64) as f64).collect();
            let sign = if q.iter().map(|c| c.abs()).sum::<i64>() % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            contribution.add(f.fourier(&omega).re * sign);
        });
        last = contribution.value();
        total.add(last);
        if last.abs() < threshold && shell >= 2 {
            break;
        }
    }
    Ok((total.value(), last.abs()))
}

/// Calls `visit` for every integer vector with `max_i |q_i| = shell`.
fn for_each_on_shell(d: usize, shell: i64, mut visit: impl FnMut(&[i64])) {
    let side = 2 * shell + 1;
    let mut q = vec![0i64; d];
    for i in 0..side.pow(d as u32) {
        let mut rest = i;
        for c in q.iter_mut() {
            *c = rest % side - shell;
            rest /= side;
        }
        if q.iter().any(|c| c.abs() == shell) {
            visit(&q);
        }
    }
}
