//! The pair-correlation route (Öztireli 2016): the variance from the pattern's pair
//! correlation function and the integrand's autocorrelation, the spectral route's Fourier
//! pair.
//!
//! For a homogenized pattern of N points whose pair differences have density `g` on the torus
//! (white noise: `g = 1`), `E[(Σ f(x_i))²] = N ∫f² + N(N−1) ∫ a_f g`, and since `∫ a_f = I²`,
//! `Var = (∫f² − I²)/N + ((N−1)/N) ∫ a_f(r) (g(r) − 1) dr`. The PCF is estimated within a
//! radius `r_c` by its empirical pair measure (no kernel: smoothing `g` would bias the
//! integral at the order of the kernel's width). Beyond `r_c`, `g − 1` is taken as the
//! constant `c` that the normalization of a density of differences imposes,
//! `∫ (g − 1) dr = 0` over the torus: `c = −∫_{|r|≤r_c} (g − 1) / (1 − π r_c²)`, which is
//! what remains of the hole a blue-noise pattern digs near 0 (for jitter it is exactly the
//! `1/(N−1)` of the strata's partition of unity).

use crate::error::{invalid, Result};
use crate::integrand::Integrand;
use crate::metrics::Mean;
use crate::pointset::{toroidal_delta, PointSet};
use crate::predict::ErrorBudget;
use crate::quadrature::GaussLegendre;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;

/// Angles of a circular mean (the trapezoid rule on a periodic function).
const ANGLES: usize = 64;
/// Standard errors added to the measured far-field deviation where it stands for a bound.
const BOUND_Z: f64 = 3.0;

/// A variance from the pair correlation function, with its budget: `spectrum_noise` is the
/// spread of the patterns' own values; `quadrature` the rounding of `∫ a_f` inside `r_c`;
/// `truncation` a bound on `|g − 1 − c|` beyond `r_c` (measured in the first annulus outside
/// it) times `∫_{|r|>r_c} a_f`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PcfVariance {
    /// The predicted variance.
    pub variance: f64,
    /// Its error budget.
    pub budget: ErrorBudget,
    /// Points per pattern.
    pub n: usize,
    /// Patterns.
    pub patterns: usize,
    /// The radius `r_c` within which the PCF is measured (absolute).
    pub r_c: f64,
    /// The far-field constant `c = g − 1` beyond `r_c`, mean over the patterns.
    pub far_field: f64,
}

/// The variance of the homogenized estimator with `patterns` (2D, all of one N) for `f`, by
/// the pair-correlation route with the PCF measured within `r_c` mean spacings (`N^{-1/2}`).
/// The bound beyond `r_c` assumes `|g − 1 − c|` there no larger than in the annulus of half a
/// spacing just outside, and `f` of one sign (`a_f ≥ 0`, as every integrand of this crate).
///
/// # Errors
/// Patterns not in 2D or of different sizes, fewer than 2 patterns, an integrand without a
/// closed-form autocorrelation or in another dimension, or `r_c` outside `(0, 0.45/Δ]`.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::predict::pair_correlation_variance;
/// use specvar::sampler::{Random, Sampler};
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let sets: Vec<_> = (0..32).map(|r| Random::new(2).unwrap().sample(256, 1, r).unwrap()).collect();
/// let v = pair_correlation_variance(&disk, &sets, 3.0)?;
/// let white = (disk.integral_of_square() - disk.integral().powi(2)) / 256.0;
/// assert!((v.variance - white).abs() < v.budget.half_width(4.0)); // g = 1 for white noise
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn pair_correlation_variance(
    f: &dyn Integrand,
    patterns: &[PointSet],
    r_c_spacings: f64,
) -> Result<PcfVariance> {
    let n = check(f, patterns)?;
    let spacing = (n as f64).sqrt().recip();
    let r_c = r_c_spacings * spacing;
    let annulus = r_c + 0.5 * spacing;
    if !(r_c_spacings > 0.0 && annulus <= 0.5) {
        return Err(invalid(
            "r_c",
            r_c_spacings,
            format!("positive, at most {:.2} spacings", 0.5 / spacing - 0.5),
        ));
    }
    let nf = n as f64;
    let pairs = nf * (nf - 1.0);
    let inner = inner_autocorrelation(f, r_c);
    let outer = (f.integral().powi(2) - inner).max(0.0);
    let white = (f.integral_of_square() - f.integral().powi(2)) / nf;
    let disk = PI * r_c * r_c;
    let ring = PI * (annulus * annulus - r_c * r_c);
    let per_pattern: Vec<(f64, f64, f64)> = patterns
        .par_iter()
        .map(|p| {
            let s = pair_sums(f, p, r_c, annulus);
            let far = -(s.inside / pairs - disk) / (1.0 - disk);
            let value = white + (nf - 1.0) / nf * (s.weighted / pairs - inner + far * outer);
            let ring_excess = s.annulus / pairs / ring - 1.0 - far;
            (value, far, ring_excess)
        })
        .collect();
    let column = |pick: fn(&(f64, f64, f64)) -> f64| {
        Mean::of(&per_pattern.iter().map(pick).collect::<Vec<_>>())
    };
    let value = column(|v| v.0);
    let far_field = column(|v| v.1).mean;
    let ring = column(|v| v.2);
    let (variance, noise) = (value.mean, value.stderr);
    let (excess, excess_error) = (ring.mean, ring.stderr);
    let deviation = excess.abs() + BOUND_Z * excess_error;
    Ok(PcfVariance {
        variance,
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise: noise,
            quadrature: 16.0 * f64::EPSILON * (inner + f.integral_of_square()),
            truncation: (nf - 1.0) / nf * deviation * outer,
            model: 0.0,
        },
        n,
        patterns: patterns.len(),
        r_c,
        far_field,
    })
}

fn check(f: &dyn Integrand, patterns: &[PointSet]) -> Result<usize> {
    let first = patterns
        .first()
        .ok_or_else(|| invalid("patterns", 0, "at least two"))?;
    let n = first.len();
    if patterns.len() < 2 || n < 2 {
        return Err(invalid(
            "patterns",
            format!("{} of {n} points", patterns.len()),
            "at least two patterns of at least two points",
        ));
    }
    if patterns.iter().any(|p| p.dimension() != 2 || p.len() != n) || f.dimension() != 2 {
        return Err(invalid(
            "dimension",
            f.dimension(),
            "2, with patterns of one N, for the pair-correlation route",
        ));
    }
    if f.autocorrelation(&[0.0, 0.0]).is_none() {
        return Err(invalid(
            "integrand",
            f.label(),
            "one with a closed-form autocorrelation (disk, Gaussian)",
        ));
    }
    Ok(n)
}

/// One pattern's sums over its ordered pairs `i ≠ j`: the count within `r_c`, the sum of
/// `a_f(x_i − x_j)` within `r_c`, and the count in the annulus `(r_c, annulus]`.
struct PairSums {
    inside: f64,
    weighted: f64,
    annulus: f64,
}

fn pair_sums(f: &dyn Integrand, p: &PointSet, r_c: f64, annulus: f64) -> PairSums {
    let n = p.len();
    let mut s = PairSums {
        inside: 0.0,
        weighted: 0.0,
        annulus: 0.0,
    };
    for i in 0..n {
        for j in (i + 1)..n {
            let (a, b) = (p.point(i), p.point(j));
            let delta = [toroidal_delta(a[0], b[0]), toroidal_delta(a[1], b[1])];
            let d = delta[0].hypot(delta[1]);
            if d <= r_c {
                s.inside += 2.0;
                s.weighted += 2.0 * f.autocorrelation(&delta).unwrap_or(0.0);
            } else if d <= annulus {
                s.annulus += 2.0;
            }
        }
    }
    s
}

/// `∫_{|r| ≤ r_c} a_f(r) dr`: circular means by the trapezoid rule over [`ANGLES`] angles,
/// then Gauss–Legendre in the radius on eight panels.
fn inner_autocorrelation(f: &dyn Integrand, r_c: f64) -> f64 {
    let rule = GaussLegendre::new(16);
    let panels = 8;
    let width = r_c / panels as f64;
    let circular = |s: f64| {
        (0..ANGLES)
            .map(|i| {
                let t = 2.0 * PI * i as f64 / ANGLES as f64;
                f.autocorrelation(&[s * t.cos(), s * t.sin()])
                    .unwrap_or(0.0)
            })
            .sum::<f64>()
            / ANGLES as f64
    };
    (0..panels)
        .map(|k| {
            let a = k as f64 * width;
            rule.integrate(a, a + width, |s| circular(s) * 2.0 * PI * s)
        })
        .sum()
}
