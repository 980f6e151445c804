//! The bias of a fixed (not homogenized) pattern: `E[μ_N] - I = Σ_{k≠0} f̂(k)* Ŝ(k)`.
//!
//! For a fixed pattern the bias is `μ_N - I` itself, which direct evaluation gives exactly:
//! that is the answer. The spectral sum, with the torus coefficients of the function Monte
//! Carlo integrates, is computed beside it as the theory's account of it. It converges only
//! conditionally for integrands with jumps (a disk, a Gaussian cut by the cube's faces: their
//! coefficients are not absolutely summable), so no bound on its truncation exists in general;
//! the difference to the exact value is reported instead, as what the truncated sum leaves.

use crate::budget::{Budget, Needs};
use crate::error::{invalid, Error, Result};
use crate::integrand::Integrand;
use crate::montecarlo::estimate_integral;
use crate::pointset::PointSet;
use crate::quadrature::CompensatedSum;
use crate::sampler::{Regular, Sampler, SamplerKind};
use crate::spectrum::{lattice::direct_sums, Lattice};
use serde::Serialize;

/// A bias, exactly and as a spectral sum.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpectralBias {
    /// `μ_N - I`, by direct evaluation: exact up to rounding.
    pub bias: f64,
    /// `Σ_{k≠0} Re(f̂(k)* Ŝ(k))` over the frequencies summed.
    pub spectral: f64,
    /// `bias - spectral`: what the truncated spectral sum leaves out.
    pub remainder: f64,
    /// Frequencies (or replicas) summed.
    pub terms: usize,
}

impl SpectralBias {
    fn new(f: &dyn Integrand, points: &PointSet, spectral: f64, terms: usize) -> Self {
        let bias = estimate_integral(f, points) - f.integral();
        Self {
            bias,
            spectral,
            remainder: bias - spectral,
            terms,
        }
    }
}

fn check(f: &dyn Integrand, d: usize) -> Result<()> {
    if d != f.dimension() || !(1..=3).contains(&d) {
        return Err(Error::Mismatch(format!(
            "points of dimension {d} for an integrand of dimension {} (1 to 3)",
            f.dimension()
        )));
    }
    Ok(())
}

/// The bias of a fixed pattern, exactly and from its sampling spectrum on `|k_i| ≤ kmax`.
///
/// # Errors
/// A dimension mismatch or a dimension above 3.
///
/// # Examples
/// ```
/// use specvar::integrand::Gaussian;
/// use specvar::predict::bias_of_pattern;
/// use specvar::sampler::{Jitter, Sampler};
/// let f = Gaussian::new(0.1, vec![0.5, 0.5], 1.0)?;
/// let points = Jitter::new(2)?.sample(64, 3, 0)?;
/// let b = bias_of_pattern(&f, &points, 64)?;
/// // A centred Gaussian's coefficients vanish fast but for the faces' exp(-12.5) = 3.7e-6,
/// // whose 1/k tail beyond |k_i| = 64 leaves a few 1e-9 of a bias of 1e-2.
/// assert!(b.remainder.abs() < 1e-8 && b.bias.abs() > 1e-3, "{b:?}");
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn bias_of_pattern(f: &dyn Integrand, points: &PointSet, kmax: usize) -> Result<SpectralBias> {
    let d = points.dimension();
    check(f, d)?;
    crate::spectrum::check_kmax(kmax)?;
    let sums = direct_sums(points, kmax);
    let lattice = Lattice { dimension: d, kmax };
    let n = points.len() as f64;
    let mut total = CompensatedSum::default();
    for (i, s) in sums.iter().enumerate() {
        if i == lattice.dc_index() {
            continue;
        }
        let k = lattice.frequency(i);
        total.add((f.coefficient(&k[..d]).conj() * s).re / n);
    }
    Ok(SpectralBias::new(
        f,
        points,
        total.value(),
        lattice.len() - 1,
    ))
}

/// The bias of the fixed cell-centred regular grid with `n = m^d` points, exactly and from its
/// exact sampling spectrum `Ŝ(m q) = (-1)^{|q|_1}` (zero at every other integer frequency):
/// `Σ_{q≠0} Re f̂(m q) (-1)^{|q|_1}` over shells `|q|_∞ ≤ Q` until a shell adds less than
/// 1e-17 of `∫ f²`, or `Q` = 512, 128, 32 in 1D, 2D, 3D.
///
/// # Errors
/// `n` not a perfect power, or a dimension above 3.
pub fn regular_grid_bias(f: &dyn Integrand, n: usize) -> Result<SpectralBias> {
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
    let threshold = 1e-17 * f.integral_of_square().max(f64::MIN_POSITIVE);
    let mut total = CompensatedSum::default();
    let mut terms = 0;
    let mut q = vec![0i64; d];
    for shell in 1..=max_shell {
        let mut contribution = CompensatedSum::default();
        for_each_on_shell(d, shell, &mut q, |q| {
            let k: Vec<i64> = q.iter().map(|&c| c * m as i64).collect();
            let sign = if q.iter().map(|c| c.abs()).sum::<i64>() % 2 == 0 {
                1.0
            } else {
                -1.0
            };
            contribution.add(f.coefficient(&k).re * sign);
            terms += 1;
        });
        total.add(contribution.value());
        if contribution.value().abs() < threshold && shell >= 2 {
            break;
        }
    }
    let points = Regular::new(d)?.sample(n, 0, 0)?;
    Ok(SpectralBias::new(f, &points, total.value(), terms))
}

/// Calls `visit` for every integer vector with `max_i |q_i| = shell`.
fn for_each_on_shell(d: usize, shell: i64, q: &mut [i64], mut visit: impl FnMut(&[i64])) {
    let side = 2 * shell + 1;
    for i in 0..side.pow(d as u32) {
        let mut rest = i;
        for c in q.iter_mut() {
            *c = rest % side - shell;
            rest /= side;
        }
        if q.iter().any(|c| c.abs() == shell) {
            visit(q);
        }
    }
}

/// How [`sampler_bias`] computed a bias's spectral sum.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BiasMethod {
    /// The regular grid's exact spectrum, summed over its replicas ([`regular_grid_bias`]).
    ReplicaSum,
    /// Realization 0's spectrum on the lattice ([`bias_of_pattern`]).
    LatticeSum,
}

impl std::fmt::Display for BiasMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BiasMethod::ReplicaSum => "replica sum of the regular grid's exact spectrum",
            BiasMethod::LatticeSum => "lattice sum over realization 0's spectrum",
        })
    }
}

/// The bias of `kind`'s pattern used as drawn (realization 0 of `seed`, `n` points in `f`'s
/// dimension), exactly and as a spectral sum: the regular grid's over its exact spectrum,
/// any other's over its pattern's spectrum on `|k_i| ≤ kmax`, after checking the work against
/// `budget` (the pattern, and direct sums of 32 bytes and about half a nanosecond per
/// frequency and point).
///
/// # Errors
/// A count the sampler cannot draw, a budget the sums would exceed, or the errors of
/// [`bias_of_pattern`] and [`regular_grid_bias`].
///
/// # Examples
/// ```
/// use specvar::budget::Budget;
/// use specvar::integrand::Gaussian;
/// use specvar::predict::{sampler_bias, BiasMethod};
/// use specvar::sampler::SamplerKind;
/// let f = Gaussian::new(0.1, vec![0.5, 0.5], 1.0)?;
/// let (b, method) = sampler_bias(SamplerKind::Regular, &f, 64, 0, 64, &Budget::default())?;
/// assert_eq!(method, BiasMethod::ReplicaSum);
/// // The grid's bias (-7.6e-7) is the replicas' sum but for the faces' slow 1/k tail, which
/// // the shells' cut leaves: 4.5e-12.
/// assert!(b.bias < 0.0 && b.remainder.abs() < 1e-4 * b.bias.abs());
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn sampler_bias(
    kind: SamplerKind,
    f: &dyn Integrand,
    n: usize,
    seed: u64,
    kmax: usize,
    budget: &Budget,
) -> Result<(SpectralBias, BiasMethod)> {
    let d = f.dimension();
    let lattice = (2.0 * kmax as f64 + 1.0).powi(d as i32);
    let needs = kind.pattern_needs(n, d).and(Needs {
        memory_bytes: lattice * 32.0,
        work_seconds: lattice * n as f64 * 0.5e-9,
    });
    budget.check("the bias's spectral sum", needs, "lower --kmax or N")?;
    if kind.closed_form(n, d) == Some(crate::spectrum::ClosedForm::RegularGrid) {
        return Ok((regular_grid_bias(f, n)?, BiasMethod::ReplicaSum));
    }
    let points = kind.build(d)?.sample(n, seed, 0)?;
    Ok((bias_of_pattern(f, &points, kmax)?, BiasMethod::LatticeSum))
}
