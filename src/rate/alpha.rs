//! The low-frequency exponent `α` of a radial spectrum, fitted without the biases of a plain
//! log-log line.
//!
//! A straight line through `(ln ν_b, ln P_b)` is biased three ways: a spectrum is a power law
//! only in the limit (jitter's `1 − Π sinc²` bends below `ν²` already at `ν = 0.3`); a ring's
//! mean power is the mean of `c ν^α` over its lattice points, not its value at their mean
//! radius (5% in the first ring for `α = 2`); and the log of a noisy mean is low by half its
//! squared relative error. The fit here models each ring exactly — the mean over the ring's own
//! lattice points of `c ν^α e^{γν²}`, with the curvature `γ` a nuisance parameter — and adds
//! `s²/(2P²)` to each log power, by weighted Gauss–Newton with the rings' standard errors.

use crate::error::{invalid, Result};
use crate::montecarlo::Z_99;
use crate::spectrum::RadialSpectrum;
use serde::Serialize;

/// A fitted low-frequency exponent.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlphaFit {
    /// `α`.
    pub alpha: f64,
    /// Its standard error (from the rings' standard errors).
    pub stderr: f64,
    /// Its 99% interval.
    pub ci: (f64, f64),
    /// The amplitude `c` of `P̆ ≈ c ν^α`.
    pub amplitude: f64,
    /// The curvature `γ` of `e^{γν²}` (0 when too few rings to fit it).
    pub curvature: f64,
    /// Rings used.
    pub rings: usize,
    /// The `ν` range fitted.
    pub nu_range: (f64, f64),
}

/// A ring's relative standard error below this is the rounding of identical realizations (a
/// deterministic pattern), not sampling noise: such rings carry no weight a fit could use.
const MIN_RELATIVE_STDERR: f64 = 1e-9;

/// Rings below which the curvature term is not fitted.
const MIN_RINGS_FOR_CURVATURE: usize = 4;
/// Gauss–Newton stops when no parameter moves by more than this.
const STEP_TOLERANCE: f64 = 1e-12;
const MAX_ITERATIONS: usize = 100;

/// Fits `α` over the rings with `nu_min ≤ ν ≤ nu_max` of `radial` (positive power and a finite
/// standard error; see the module notes for the model).
///
/// # Errors
/// Fewer than two usable rings, a spectrum of one realization (no standard errors), or a fit
/// that does not converge.
///
/// # Examples
/// ```
/// use specvar::rate::fit_alpha;
/// use specvar::sampler::Jitter;
/// use specvar::spectrum::{estimate, SpectrumParams};
/// let params = SpectrumParams { kmax: 24, realizations: 64, seed: 3, ..Default::default() };
/// let est = estimate(&Jitter::new(2)?, 4096, &params)?;
/// let fit = fit_alpha(&est.radial, 0.0, 0.3)?;
/// assert!(fit.ci.0 < 2.0 && 2.0 < fit.ci.1, "{fit:?}"); // jitter rises like ν²
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn fit_alpha(radial: &RadialSpectrum, nu_min: f64, nu_max: f64) -> Result<AlphaFit> {
    let used: Vec<usize> = (0..radial.bins.len())
        .filter(|&i| {
            let b = &radial.bins[i];
            b.nu >= nu_min
                && b.nu <= nu_max
                && b.power > 0.0
                && b.stderr.is_finite()
                && b.stderr > MIN_RELATIVE_STDERR * b.power
        })
        .collect();
    if used.len() < 2 {
        return Err(invalid(
            "α fit",
            format!("{} usable rings in ν ∈ [{nu_min}, {nu_max}]", used.len()),
            "at least two rings with positive power and a standard error from realization noise \
             (two or more realizations of a random pattern)",
        ));
    }
    let rings = ring_members(radial, &used);
    let y: Vec<f64> = used
        .iter()
        .map(|&i| {
            let b = &radial.bins[i];
            b.power.ln() + 0.5 * (b.stderr / b.power).powi(2)
        })
        .collect();
    let w: Vec<f64> = used
        .iter()
        .map(|&i| {
            let b = &radial.bins[i];
            (b.power / b.stderr).powi(2)
        })
        .collect();
    let with_curvature = used.len() >= MIN_RINGS_FOR_CURVATURE;
    let params = if with_curvature { 3 } else { 2 };
    // Start from the plain line; then Gauss–Newton on (ln c, α, γ).
    let mut theta = [y[0], 0.0, 0.0];
    let mut covariance = [[0.0; 3]; 3];
    let mut converged = false;
    for _ in 0..MAX_ITERATIONS {
        let mut jtj = [[0.0; 3]; 3];
        let mut jtr = [0.0; 3];
        for (b, members) in rings.iter().enumerate() {
            let (model, grad) = ring_model(members, theta[1], theta[2]);
            let j = [1.0, grad[0], grad[1]];
            let r = y[b] - (theta[0] + model);
            for p in 0..params {
                jtr[p] += w[b] * j[p] * r;
                for q in 0..params {
                    jtj[p][q] += w[b] * j[p] * j[q];
                }
            }
        }
        covariance = invert(&jtj, params).ok_or_else(|| {
            invalid(
                "α fit",
                "a singular system",
                "rings at distinct frequencies",
            )
        })?;
        let mut step = [0.0; 3];
        for p in 0..params {
            step[p] = (0..params).map(|q| covariance[p][q] * jtr[q]).sum();
        }
        for p in 0..params {
            theta[p] += step[p];
        }
        if step.iter().all(|s| s.abs() < STEP_TOLERANCE) {
            converged = true;
            break;
        }
    }
    if !converged || !theta.iter().all(|t| t.is_finite()) {
        return Err(invalid(
            "α fit",
            "no convergence",
            "a spectrum rising smoothly from DC",
        ));
    }
    let stderr = covariance[1][1].sqrt();
    let lo = radial.bins[used[0]].nu;
    let hi = radial.bins[used[used.len() - 1]].nu;
    Ok(AlphaFit {
        alpha: theta[1],
        stderr,
        ci: (theta[1] - Z_99 * stderr, theta[1] + Z_99 * stderr),
        amplitude: theta[0].exp(),
        curvature: theta[2],
        rings: used.len(),
        nu_range: (lo, hi),
    })
}

/// `ln mean_k ν_k^α e^{γν_k²}` over a ring's members, and its derivatives in `α` and `γ`.
fn ring_model(members: &[f64], alpha: f64, gamma: f64) -> (f64, [f64; 2]) {
    let (mut s, mut s_log, mut s_sq) = (0.0, 0.0, 0.0);
    for &nu in members {
        let v = (alpha * nu.ln() + gamma * nu * nu).exp();
        s += v;
        s_log += v * nu.ln();
        s_sq += v * nu * nu;
    }
    ((s / members.len() as f64).ln(), [s_log / s, s_sq / s])
}

/// The `ν` of every lattice point of each ring in `used` (rings as [`RadialSpectrum`] bins them:
/// `b·Δ ≤ |k| < (b+1)·Δ`, found by the mean radius the bin reports).
fn ring_members(radial: &RadialSpectrum, used: &[usize]) -> Vec<Vec<f64>> {
    let d = radial.dimension;
    let width = radial.bin_width;
    let scale = (radial.n as f64).powf(1.0 / d as f64);
    let ring_of = |rho: f64| (rho / width).floor() as usize;
    let wanted: Vec<usize> = used.iter().map(|&i| ring_of(radial.bins[i].rho)).collect();
    let reach = ((wanted.iter().max().copied().unwrap_or(0) + 1) as f64 * width).ceil() as i64;
    let mut members = vec![Vec::new(); used.len()];
    let side = 2 * reach + 1;
    for flat in 0..side.pow(d as u32) {
        let mut rest = flat;
        let mut r2 = 0i64;
        for _ in 0..d {
            let c = rest % side - reach;
            rest /= side;
            r2 += c * c;
        }
        if r2 == 0 {
            continue;
        }
        let rho = (r2 as f64).sqrt();
        if let Some(slot) = wanted.iter().position(|&b| b == ring_of(rho)) {
            members[slot].push(rho / scale);
        }
    }
    members
}

/// The inverse of the leading `n × n` block of a symmetric positive definite matrix (Gauss–Jordan).
fn invert(a: &[[f64; 3]; 3], n: usize) -> Option<[[f64; 3]; 3]> {
    let mut m = *a;
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate().take(n) {
        row[i] = 1.0;
    }
    for col in 0..n {
        let pivot = (col..n).max_by(|&x, &y| m[x][col].abs().total_cmp(&m[y][col].abs()))?;
        if m[pivot][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, pivot);
        inv.swap(col, pivot);
        let p = m[col][col];
        for j in 0..n {
            m[col][j] /= p;
            inv[col][j] /= p;
        }
        for r in 0..n {
            if r != col {
                let f = m[r][col];
                for j in 0..n {
                    m[r][j] -= f * m[col][j];
                    inv[r][j] -= f * inv[col][j];
                }
            }
        }
    }
    Some(inv)
}

/// A two-term fit of a spectrum's low band, `P̆(ν) ≈ a ν² + b ν⁴`, each ring modelled by its own
/// lattice points' mean of `ν²` and `ν⁴` (weighted least squares with the rings' standard
/// errors). For CCVT, `a` is the floor its discrete density leaves (`π²/(3c²)` for capacity
/// `c`) and `b` its optimized band; the band dominates above `ν = √(a/b)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LowBandFit {
    /// `a`.
    pub floor: f64,
    /// Its standard error.
    pub floor_stderr: f64,
    /// `b`.
    pub band: f64,
    /// Its standard error.
    pub band_stderr: f64,
    /// Rings used.
    pub rings: usize,
}

impl LowBandFit {
    /// `√(a/b)`: below it the `ν²` floor carries the spectrum, above it the `ν⁴` band.
    pub fn crossover_nu(&self) -> f64 {
        (self.floor / self.band).sqrt()
    }
}

/// Fits `P̆(ν) ≈ a ν² + b ν⁴` over the rings with `ν ≤ nu_max` (see [`LowBandFit`]).
///
/// # Errors
/// Fewer than three usable rings (positive power, finite standard error), or rings whose
/// moments do not separate the two terms.
pub fn fit_low_band(radial: &RadialSpectrum, nu_max: f64) -> Result<LowBandFit> {
    let used: Vec<usize> = (0..radial.bins.len())
        .filter(|&i| {
            let b = &radial.bins[i];
            b.nu <= nu_max && b.stderr.is_finite() && b.stderr > 0.0
        })
        .collect();
    if used.len() < 3 {
        return Err(invalid(
            "low-band fit",
            format!("{} usable rings with ν ≤ {nu_max}", used.len()),
            "at least three rings with standard errors (two or more realizations)",
        ));
    }
    let members = ring_members(radial, &used);
    let mut normal = [[0.0; 3]; 3];
    let mut rhs = [0.0; 3];
    for (&i, ring) in used.iter().zip(&members) {
        let b = &radial.bins[i];
        let count = ring.len() as f64;
        let x = [
            ring.iter().map(|v| v * v).sum::<f64>() / count,
            ring.iter().map(|v| v.powi(4)).sum::<f64>() / count,
        ];
        let w = 1.0 / (b.stderr * b.stderr);
        for p in 0..2 {
            rhs[p] += w * x[p] * b.power;
            for q in 0..2 {
                normal[p][q] += w * x[p] * x[q];
            }
        }
    }
    let inverse = invert(&normal, 2).ok_or_else(|| {
        invalid(
            "low-band fit",
            "a singular system",
            "rings at distinct radii",
        )
    })?;
    let coefficient = |p: usize| (0..2).map(|q| inverse[p][q] * rhs[q]).sum::<f64>();
    Ok(LowBandFit {
        floor: coefficient(0),
        floor_stderr: inverse[0][0].sqrt(),
        band: coefficient(1),
        band_stderr: inverse[1][1].sqrt(),
        rings: used.len(),
    })
}
