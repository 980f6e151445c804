//! The lattice form evaluated in space: by Poisson summation,
//! `(1/N) Σ_{k≠0} |f̂(k)|² P(k) = (1/N²) Σ_{i,j} a_f(x_i - x_j) - I²`, with `a_f` the integrand's
//! torus autocorrelation. Exact where `a_f` has a closed form, with no truncation at all.

use crate::error::{invalid, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::quadrature::CompensatedSum;
use crate::sampler::strata;
use rayon::prelude::*;

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

/// `Σ rows / count - I²`, with the subtraction's rounding bound: a few ulps of the larger term.
fn finish(f: &dyn Integrand, rows: &[f64], count: f64) -> (f64, f64) {
    let mut total = CompensatedSum::default();
    rows.iter().for_each(|&v| total.add(v));
    let mean = total.value() / count;
    let i2 = f.integral().powi(2);
    let rounding = 8.0 * f64::EPSILON * (mean.abs() + i2);
    ((mean - i2).max(0.0), rounding)
}
