//! The pair correlation function: the density of pairs at each distance, relative to white
//! noise's.

use crate::budget::Budget;
use crate::error::{invalid, Result};
use crate::pointset::{toroidal_distance_sq, PointSet};
use crate::quadrature::GaussLegendre;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;

/// How the pair correlation function is estimated; distances in units of the mean spacing
/// `Δ = N^{-1/d}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PcfParams {
    /// The largest distance, in spacings (kept below half the torus).
    pub r_max: f64,
    /// The number of radii, evenly spaced on `(0, r_max]`.
    pub radii: usize,
    /// The Gaussian kernel's standard deviation, in spacings.
    pub sigma: f64,
    /// What the pair sums may spend, checked before they start.
    pub budget: Budget,
}

impl PcfParams {
    /// These parameters with `r_max` cut to what the torus holds at `n` points in `d`
    /// dimensions (`r_max + 8σ` at most half the torus, in spacings): the default 3 spacings
    /// need at least 58 points in 2D.
    pub fn within_torus(self, n: usize, d: usize) -> Self {
        let half = 0.5 * (n as f64).powf(1.0 / d as f64) - 8.0 * self.sigma;
        Self {
            r_max: self.r_max.min(half),
            ..self
        }
    }
}

impl Default for PcfParams {
    fn default() -> Self {
        Self {
            r_max: 3.0,
            radii: 150,
            sigma: 0.05,
            budget: Budget::default(),
        }
    }
}

/// A pair correlation function: `g(r)` at each radius, in absolute units and in spacings.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Pcf {
    /// Points per pattern.
    pub n: usize,
    /// Dimension.
    pub dimension: usize,
    /// Patterns averaged.
    pub patterns: usize,
    /// Radii (absolute, on the unit torus).
    pub radius: Vec<f64>,
    /// Radii in spacings `r / Δ`.
    pub radius_in_spacings: Vec<f64>,
    /// `g(r)`, the mean over the patterns.
    pub g: Vec<f64>,
    /// The standard error of each `g(r)` across the patterns (0 with one pattern).
    pub stderr: Vec<f64>,
    /// The kernel's standard deviation (absolute).
    pub sigma: f64,
    /// Each pattern's own estimate, radius by radius (the units of `stderr`).
    #[serde(skip)]
    pub per_pattern: Vec<Vec<f64>>,
}

/// The surface of the unit sphere in dimension `d` (1 to 3): 2, 2π, 4π.
fn unit_sphere_surface(d: usize) -> f64 {
    match d {
        1 => 2.0,
        2 => 2.0 * PI,
        _ => 4.0 * PI,
    }
}

/// The Gaussian-kernel estimator Öztireli and Gross use, on the torus:
/// `g(r) = Σ_{i≠j} k_σ(r - |x_i - x_j|) / (N (N - 1) ∫_0^∞ k_σ(r - s) ω_d s^{d-1} ds)`
/// with toroidal distances and `ω_d s^{d-1}` the sphere's surface. The denominator is the
/// numerator's expectation for white noise (for radii below half the torus, where spheres do
/// not meet themselves), so `g = 1` for white noise at every radius, with no kernel bias; it
/// is integrated by Gauss–Legendre over ±8σ. Pairs are summed in `O(N²)` per pattern.
///
/// # Errors
/// Fewer than 2 points in a pattern, patterns of different sizes or dimensions, a dimension
/// above 3, parameters out of range (`r_max + 8σ` at most half the torus), or work beyond
/// the default budget.
///
/// # Examples
/// ```
/// use specvar::metrics::{pair_correlation, PcfParams};
/// use specvar::sampler::{Regular, Sampler};
/// let grid = Regular::new(2)?.sample(256, 0, 0)?;
/// let pcf = pair_correlation(&[grid], &PcfParams::default())?;
/// // No pair of a grid is closer than its spacing: below 1 - 8σ = 0.6 spacings the kernel
/// // of every pair is cut off, and g is exactly 0.
/// let inside = pcf.radius_in_spacings.iter().position(|&r| r > 0.59).unwrap();
/// assert!(pcf.g[..inside].iter().all(|&g| g.abs() < 1e-12));
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn pair_correlation(patterns: &[PointSet], params: &PcfParams) -> Result<Pcf> {
    let first = patterns
        .first()
        .ok_or_else(|| invalid("patterns", 0, "at least one"))?;
    let (n, d) = (first.len(), first.dimension());
    check(patterns, n, d, params)?;
    let spacing = (n as f64).powf(-1.0 / d as f64);
    let sigma = params.sigma * spacing;
    let radius: Vec<f64> = (1..=params.radii)
        .map(|i| params.r_max * spacing * i as f64 / params.radii as f64)
        .collect();
    let expected: Vec<f64> = radius
        .iter()
        .map(|&r| white_pair_density(r, sigma, d))
        .collect();
    let per_pattern: Vec<Vec<f64>> = patterns
        .par_iter()
        .map(|p| {
            let sums = kernel_sums(p, &radius, sigma);
            let pairs = (n * (n - 1)) as f64;
            sums.iter()
                .zip(&expected)
                .map(|(s, e)| s / (pairs * e))
                .collect()
        })
        .collect();
    let m = patterns.len() as f64;
    let g: Vec<f64> = (0..radius.len())
        .map(|i| per_pattern.iter().map(|v| v[i]).sum::<f64>() / m)
        .collect();
    let stderr = (0..radius.len())
        .map(|i| {
            if patterns.len() < 2 {
                return 0.0;
            }
            let ss: f64 = per_pattern.iter().map(|v| (v[i] - g[i]).powi(2)).sum();
            (ss / (m - 1.0) / m).sqrt()
        })
        .collect();
    Ok(Pcf {
        n,
        dimension: d,
        patterns: patterns.len(),
        radius_in_spacings: radius.iter().map(|r| r / spacing).collect(),
        radius,
        g,
        stderr,
        sigma,
        per_pattern,
    })
}

fn check(patterns: &[PointSet], n: usize, d: usize, params: &PcfParams) -> Result<()> {
    if !(1..=3).contains(&d) {
        return Err(invalid("dimension", d, "1 to 3"));
    }
    if n < 2 {
        return Err(invalid("point count", n, "at least 2 (pairs are counted)"));
    }
    if let Some(p) = patterns.iter().find(|p| p.len() != n || p.dimension() != d) {
        return Err(invalid(
            "pattern",
            format!("{} points in {}D", p.len(), p.dimension()),
            format!("{n} points in {d}D, like the first"),
        ));
    }
    let spacing = (n as f64).powf(-1.0 / d as f64);
    if !(params.sigma > 0.0 && params.sigma.is_finite()) {
        return Err(invalid(
            "sigma",
            params.sigma,
            "a positive width in spacings",
        ));
    }
    let reach = (params.r_max + 8.0 * params.sigma) * spacing;
    if !(params.r_max > 0.0 && reach <= 0.5) {
        return Err(invalid(
            "r_max",
            params.r_max,
            format!(
                "positive, with r_max + 8 sigma at most half the torus ({:.2} spacings)",
                0.5 / spacing - 8.0 * params.sigma
            ),
        ));
    }
    if params.radii == 0 || params.radii > 100_000 {
        return Err(invalid("radii", params.radii, "1 to 100000"));
    }
    params.budget.check(
        "the pair correlation function",
        super::pair_needs(patterns.len(), n, 0.5),
        "use fewer points or patterns",
    )
}

/// `∫_0^∞ k_σ(r - s) ω_d s^{d-1} ds` over `s ∈ [max(0, r - 8σ), r + 8σ]` (the Gaussian beyond
/// 8σ weighs below 1e-15): the expected kernel sum per ordered pair of white noise.
fn white_pair_density(r: f64, sigma: f64, d: usize) -> f64 {
    let rule = GaussLegendre::new(16);
    let (a, b) = ((r - 8.0 * sigma).max(0.0), r + 8.0 * sigma);
    let panels = 8;
    let width = (b - a) / panels as f64;
    (0..panels)
        .map(|p| {
            let lo = a + p as f64 * width;
            rule.integrate(lo, lo + width, |s| {
                kernel(r - s, sigma) * unit_sphere_surface(d) * s.powi(d as i32 - 1)
            })
        })
        .sum()
}

#[inline]
fn kernel(x: f64, sigma: f64) -> f64 {
    (-0.5 * (x / sigma).powi(2)).exp() / (sigma * (2.0 * PI).sqrt())
}

/// `Σ_{i≠j} k_σ(r - d_ij)` at every radius, pairs beyond the last radius + 8σ skipped.
fn kernel_sums(p: &PointSet, radius: &[f64], sigma: f64) -> Vec<f64> {
    let n = p.len();
    let step = radius[0];
    let reach = radius[radius.len() - 1] + 8.0 * sigma;
    let window = (8.0 * sigma / step).ceil() as isize;
    // Fixed blocks of rows, summed in order: the same bits on any thread count.
    const BLOCK: usize = 64;
    let rows: Vec<Vec<f64>> = (0..n.div_ceil(BLOCK))
        .into_par_iter()
        .map(|b| {
            let mut row = vec![0.0; radius.len()];
            for i in b * BLOCK..((b + 1) * BLOCK).min(n) {
                add_pairs_of(p, i, &mut row, radius, sigma, reach, window);
            }
            row
        })
        .collect();
    (0..radius.len())
        .map(|k| rows.iter().map(|r| r[k]).sum())
        .collect()
}

/// Adds the pairs `(i, j > i)` (each counted for both orders) to `row`.
fn add_pairs_of(
    p: &PointSet,
    i: usize,
    row: &mut [f64],
    radius: &[f64],
    sigma: f64,
    reach: f64,
    window: isize,
) {
    let step = radius[0];
    let step_decay = (-(step / sigma).powi(2)).exp();
    for j in (i + 1)..p.len() {
        let dist = toroidal_distance_sq(p.point(i), p.point(j)).sqrt();
        if dist > reach {
            continue;
        }
        // Radii are step, 2 step, …: the nearest index to this distance.
        let centre = (dist / step).round() as isize - 1;
        let lo = (centre - window).max(0) as usize;
        let hi = ((centre + window).max(-1) + 1).min(radius.len() as isize) as usize;
        if lo >= hi {
            continue;
        }
        // The radii are evenly spaced, so the kernel at successive radii is a Gaussian at
        // `x, x + h, …`: its ratio from one radius to the next is itself multiplied by
        // `exp(-h²/σ²)` each step. Two exponentials a pair instead of one a radius.
        let x = radius[lo] - dist;
        let mut value = 2.0 * kernel(x, sigma);
        let mut ratio = (-(x * step) / (sigma * sigma) - 0.5 * (step / sigma).powi(2)).exp();
        for slot in &mut row[lo..hi] {
            *slot += value;
            value *= ratio;
            ratio *= step_decay;
        }
    }
}
