//! The bias of a fixed (not homogenized) pattern: `E[μ_N] - I = Σ_{k≠0} f̂(k)* Ŝ(k)`.

use crate::error::{invalid, Error, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::quadrature::CompensatedSum;
use crate::spectrum::{lattice::direct_sums, Lattice};

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
    let max_shell: i64 = match d {
        1 => 512,
        2 => 128,
        3 => 32,
        _ => {
            return Err(invalid(
                "dimension",
                d,
                "1 to 3 for the regular grid's bias",
            ))
        }
    };
    let m = crate::sampler::perfect_root(n, d)
        .ok_or_else(|| invalid("N", n, format!("m^{d} for the regular grid")))?;
    let threshold = 1e-17 * f.spectral_energy().max(f64::MIN_POSITIVE);
    let mut total = CompensatedSum::default();
    let mut last = 0.0;
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
