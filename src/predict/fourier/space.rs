//! The lattice form evaluated in space: by Poisson summation,
//! `(1/N) Σ_{k≠0} |f̂(k)|² P(k) = (1/N²) Σ_{i,j} a_f(x_i - x_j) - I²`, with `a_f` the integrand's
//! torus autocorrelation. Exact where `a_f` has a closed form, with no truncation at all.

use crate::error::{invalid, Result};
use crate::integrand::{Integrand, IntegrandKind};
use crate::pointset::PointSet;
use crate::quadrature::CompensatedSum;
use crate::sampler::strata;
use rayon::prelude::*;

/// Seconds of one autocorrelation value, by the integrand's kind ([`crate::costs`]).
pub(crate) fn autocorrelation_seconds(f: &dyn Integrand) -> f64 {
    match f.kind() {
        IntegrandKind::Ball => crate::costs::BALL_AUTOCORRELATION_SECONDS,
        IntegrandKind::Gaussian => crate::costs::GAUSSIAN_AUTOCORRELATION_SECONDS,
        IntegrandKind::Polygon | IntegrandKind::Grid | IntegrandKind::AnisotropicGaussian => {
            crate::costs::CLIPPED_AUTOCORRELATION_SECONDS
        }
    }
}

/// The variance of one pattern under uniform random shifts (the lattice form with its own
/// periodogram), exactly: `(1/N²) Σ_{i,j} a_f(x_i - x_j) - I²`, in `O(N²)`. `None` if `f` has
/// no closed-form autocorrelation. Returns the value and a bound on its rounding error.
///
/// # Errors
/// A dimension mismatch.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::predict::pattern_shift_variance;
/// // One point: the variance under shifts is that of white noise with N = 1.
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
/// let one = specvar::PointSet::new(2, vec![0.3, 0.7])?;
/// let (v, _) = pattern_shift_variance(&disk, &one)?.unwrap();
/// let white = disk.integral_of_square() - disk.integral().powi(2);
/// assert!((v - white).abs() < 1e-12);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn pattern_shift_variance(f: &dyn Integrand, points: &PointSet) -> Result<Option<(f64, f64)>> {
    let d = points.dimension();
    if d != f.dimension() {
        return Err(invalid(
            "dimension",
            d,
            format!("the integrand's {}", f.dimension()),
        ));
    }
    if f.autocorrelation(&vec![0.0; d]).is_none() {
        return Ok(None);
    }
    let n = points.len();
    let rows: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut r = [0.0; 3];
            let mut row = CompensatedSum::default();
            for j in 0..n {
                for a in 0..d {
                    r[a] = points.point(i)[a] - points.point(j)[a];
                }
                row.add(f.autocorrelation(&r[..d]).unwrap_or(0.0));
            }
            row.value()
        })
        .collect();
    Ok(Some(finish(f, &rows, (n * n) as f64)))
}

/// The variance of given point sets, each equally likely, under uniform random shifts: the
/// mean of their [`pattern_shift_variance`]s (each set's estimator is unbiased, so the sets'
/// means do not vary), exactly. `None` if `f` has no closed-form autocorrelation. Returns the
/// value and a bound on its rounding error.
///
/// # Errors
/// A dimension mismatch, or no sets.
pub(crate) fn sets_shift_variance(
    f: &dyn Integrand,
    sets: &[PointSet],
) -> Result<Option<(f64, f64)>> {
    if sets.is_empty() {
        return Err(invalid("point sets", 0, "at least one set"));
    }
    let (mut total, mut rounding) = (CompensatedSum::default(), 0.0);
    for set in sets {
        let Some((v, r)) = pattern_shift_variance(f, set)? else {
            return Ok(None);
        };
        total.add(v);
        rounding += r;
    }
    let count = sets.len() as f64;
    Ok(Some((total.value() / count, rounding / count)))
}

/// The variance of the homogenized regular grid with `n` cells ([`strata`]): every difference
/// of two grid points is a grid vector, N times each, so it is `(1/N) Σ_g a_f(g) - I²` over the
/// N grid vectors `g`. `None` if `f` has no closed-form autocorrelation. Returns the value and
/// a bound on its rounding error.
///
/// # Errors
/// An `n` without strata in the integrand's dimension.
pub fn regular_grid_variance(f: &dyn Integrand, n: usize) -> Result<Option<(f64, f64)>> {
    let d = f.dimension();
    let cells = strata(n, d)
        .ok_or_else(|| invalid("N", n, format!("a regular grid's count in dimension {d}")))?;
    if f.autocorrelation(&vec![0.0; d]).is_none() {
        return Ok(None);
    }
    let rows: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|flat| {
            let mut r = [0.0; 3];
            let mut rest = flat;
            for a in (0..d).rev() {
                r[a] = (rest % cells[a]) as f64 / cells[a] as f64;
                rest /= cells[a];
            }
            f.autocorrelation(&r[..d]).unwrap_or(0.0)
        })
        .collect();
    Ok(Some(finish(f, &rows, n as f64)))
}

/// The variance of the homogenized 2D rank-1 lattice `x_i = frac(i (1, a) / N)`: its points
/// form a group, so every difference of two points is a point, N times each, and the
/// variance is `(1/N) Σ_i a_f(x_i) - I²`. `None` if `f` has no closed-form autocorrelation.
/// Returns the value and a bound on its rounding error.
///
/// # Errors
/// An integrand not in 2D, or `n = 0`.
pub fn rank1_lattice_variance(
    f: &dyn Integrand,
    n: usize,
    generator: u64,
) -> Result<Option<(f64, f64)>> {
    check_space_problem(f, n, Some(2))?;
    if f.autocorrelation(&[0.0, 0.0]).is_none() {
        return Ok(None);
    }
    let rows: Vec<f64> = (0..n as u128)
        .into_par_iter()
        .map(|i| {
            let r = [
                i as f64 / n as f64,
                ((i * generator as u128) % n as u128) as f64 / n as f64,
            ];
            f.autocorrelation(&r).unwrap_or(0.0)
        })
        .collect();
    Ok(Some(finish(f, &rows, n as f64)))
}

/// The variance of the homogenized Kronecker sequence `x_i = frac(i α)`, `i < N`, with `α`
/// given as 64-bit binary fractions: the difference `x_i - x_j` is `frac((i - j) α)`, and a
/// lag `j` occurs `N - |j|` times, so the variance is
/// `(1/N²) [N a_f(0) + 2 Σ_{j=1}^{N-1} (N - j) a_f(frac(j α))] - I²` (`a_f` is even). `None`
/// if `f` has no closed-form autocorrelation. Returns the value and a bound on its rounding
/// error.
///
/// # Errors
/// A dimension mismatch or `n = 0`.
pub fn kronecker_variance(
    f: &dyn Integrand,
    n: usize,
    alpha: &[u64],
) -> Result<Option<(f64, f64)>> {
    let d = f.dimension();
    check_space_problem(f, n, None)?;
    if f.autocorrelation(&vec![0.0; d]).is_none() {
        return Ok(None);
    }
    let scale = 2f64.powi(-64);
    let rows: Vec<f64> = (0..n as u64)
        .into_par_iter()
        .map(|j| {
            let mut r = [0.0; crate::pointset::MAX_DIMENSION];
            for (x, &a) in r.iter_mut().zip(&alpha[..d]) {
                *x = crate::pointset::wrap(j.wrapping_mul(a) as f64 * scale);
            }
            let weight = if j == 0 { n } else { 2 * (n - j as usize) };
            weight as f64 * f.autocorrelation(&r[..d]).unwrap_or(0.0)
        })
        .collect();
    Ok(Some(finish(f, &rows, (n * n) as f64)))
}

fn check_space_problem(f: &dyn Integrand, n: usize, dimension: Option<usize>) -> Result<()> {
    if n == 0 {
        return Err(invalid("N", 0, "at least 1"));
    }
    match dimension {
        Some(d) if f.dimension() != d => Err(invalid(
            "dimension",
            f.dimension(),
            format!("{d} (the lattice's)"),
        )),
        _ => Ok(()),
    }
}

/// `Σ rows / count - I²`, with the subtraction's rounding bound: a few ulps of the larger term.
fn finish(f: &dyn Integrand, rows: &[f64], count: f64) -> (f64, f64) {
    let mut total = CompensatedSum::default();
    rows.iter().for_each(|&v| total.add(v));
    let mean = total.value() / count;
    let i2 = f.integral().powi(2);
    let rounding = 8.0 * f64::EPSILON * (mean.abs() + i2);
    ((mean - i2).max(0.0), rounding)
}
