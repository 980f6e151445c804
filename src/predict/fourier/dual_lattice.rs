//! The lattice rules' variance as a sum over their dual lattice, for a smooth integrand
//! contained in the cube ([`Integrand::smooth_decay`]).
//!
//! Under a random shift a lattice rule's variance is `Σ_{k ∈ L*, k ≠ 0} |f̂(k)|²` over the dual
//! lattice `L*` (the frequencies where the points' power is N), which the space sum
//! `(1/N) Σ_i a_f(x_i) − I²` computes as a difference of two numbers equal to within the
//! variance: below `ε I²` it keeps nothing. The dual sum is of positive terms. For a function
//! whose full-space power falls like `A e^{−c|ω|²}` (a Gaussian), every dual vector outside
//! `|k|_∞ ≤ K` is bounded by the sum of that bound over all integer vectors outside, and `K` is
//! taken where it underflows. Its terms are the full-space transform's, the torus coefficients
//! of the periodized function `f_P = Σ_n f(x + n)`; `f` itself differs from `f_P` on the cube by
//! at most `E` (its images), so by Minkowski's inequality for the estimator's standard
//! deviation `|Var_f − Var_P| ≤ 2 √Var_P E + E²`, the model term (`docs/theory.md`, "The dual
//! lattice of a smooth integrand").

use crate::integrand::{Integrand, SmoothDecay};
use crate::quadrature::CompensatedSum;

/// `−ln` of the smallest positive double: a bound term `e^{−c K²}` beyond it is 0.
const UNDERFLOW: f64 = 745.0;

/// A lattice rule's variance summed over its dual lattice, with its error bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DualSum {
    /// `Σ_{k ∈ L*, k ≠ 0, |k|_∞ ≤ K} |f̂(k)|²`.
    pub(crate) variance: f64,
    /// A bound on the dual vectors beyond `K`.
    pub(crate) truncation: f64,
    /// A bound on the difference between the periodized function's variance and `f`'s.
    pub(crate) model: f64,
    /// A bound on the rounding of the sum.
    pub(crate) rounding: f64,
    /// The box `|k|_∞ ≤ K` summed.
    pub(crate) kmax: u64,
}

/// The box `K` beyond which `e^{−c |k|²}` underflows on every vector outside it.
fn reach(decay: &SmoothDecay) -> u64 {
    (UNDERFLOW / decay.rate).sqrt().ceil() as u64
}

/// `Σ_{k ∈ Z^d, |k|_∞ > K} A e^{−c|k|²}`: with `S_in = Σ_{|j| ≤ K} e^{−c j²}` and the rest
/// `S_out ≤ 2 e^{−c(K+1)²} / (1 − e^{−c(2K+3)})` (a geometric bound on the ratio of successive
/// terms), the sum over vectors with some component beyond `K` is
/// `(S_in + S_out)^d − S_in^d ≤ d S_out (S_in + S_out)^{d−1}`, with `S_in ≤ 1 + √(π/c)`.
fn tail(decay: &SmoothDecay, kmax: u64, d: usize) -> f64 {
    let c = decay.rate;
    let next = (kmax + 1) as f64;
    let out = 2.0 * (-c * next * next).exp() / (1.0 - (-c * (2.0 * next + 1.0)).exp());
    let inside = 1.0 + (std::f64::consts::PI / c).sqrt();
    decay.peak * d as f64 * out * (inside + out).powi(d as i32 - 1)
}

/// The sum of `powers` over the dual vectors in the box `kmax`, and its bounds.
fn finish(
    f: &dyn Integrand,
    decay: &SmoothDecay,
    kmax: u64,
    powers: impl Iterator<Item = f64>,
) -> DualSum {
    let mut sum = CompensatedSum::default();
    powers.for_each(|p| sum.add(p));
    let variance = sum.value();
    let images = decay.images;
    DualSum {
        variance,
        truncation: tail(decay, kmax, f.dimension()),
        model: 2.0 * variance.sqrt() * images + images * images,
        // Each power rounds by a few ε (the transform's exponential and products), and the
        // compensated sum of positive terms adds 2ε.
        rounding: 8.0 * f64::EPSILON * variance,
        kmax,
    }
}

/// A bound on how far jitter's unshifted `‖Πf‖²` (the squared means over the strata of `grid`,
/// `Πf` the projection on functions constant on them) is from its mean over shifts, for a
/// smooth `f`. With `β` the strata's box filter (`|β| ≤ 1`) and `x_c` their centres,
/// `‖Πf‖² = Σ_k Σ_ℓ f̂(k) β(k) conj(f̂(k + mℓ) β(k + mℓ)) (−1)^{Σℓ}` over the strata's
/// replicas `mℓ`; a shift multiplies the `ℓ ≠ 0` terms by `e^{−2πi mℓ·t}`, whose mean is 0,
/// so the difference is at most `Σ_{ℓ≠0} Σ_k |f̂(k)| |f̂(k + mℓ)|`. Under `|f̂|² ≤ A e^{−c|ω|²}`,
/// `|f̂(k)| |f̂(k + v)| ≤ A e^{−c|v|²/4} e^{−c|k + v/2|²}`, the sum over `k` is at most
/// `(1 + √(π/c))^d`, and over `ℓ ≠ 0` at most `Π_a S_a − 1` with
/// `S_a = 1 + 2 e^{−q_a}/(1 − e^{−3q_a})`, `q_a = c m_a²/4`.
pub(crate) fn strata_aliasing(decay: &SmoothDecay, grid: &[usize]) -> f64 {
    let c = decay.rate;
    let d = grid.len() as i32;
    let replicas: f64 = grid
        .iter()
        .map(|&m| {
            let q = c * (m as f64).powi(2) / 4.0;
            (2.0 * (-q).exp() / (1.0 - (-3.0 * q).exp())).ln_1p()
        })
        .sum::<f64>()
        .exp_m1();
    decay.peak * (1.0 + (std::f64::consts::PI / c).sqrt()).powi(d) * replicas
}

/// `|f̂(k)|²` at an integer vector.
fn power(f: &dyn Integrand, k: &[i64]) -> f64 {
    let omega: Vec<f64> = k.iter().map(|&v| v as f64).collect();
    f.fourier(&omega).norm_sqr()
}

/// The variance of the 2D rank-1 lattice `x_i = frac(i (1, a) / N)` under a random shift as a
/// sum over its dual lattice `{k : k_0 + a k_1 ≡ 0 (mod N)}`; `None` unless `f` is 2D and
/// smooth and contained ([`Integrand::smooth_decay`]).
pub(crate) fn rank1_dual_variance(f: &dyn Integrand, n: usize, generator: u64) -> Option<DualSum> {
    let decay = f.smooth_decay()?;
    if f.dimension() != 2 || n == 0 {
        return None;
    }
    let kmax = reach(&decay);
    let (big, k) = (n as i128, kmax as i128);
    let a = generator as i128 % big;
    let vectors = (-k..=k).flat_map(move |k1| {
        // k_0 ≡ −a k_1 (mod N), within [−K, K].
        let r = (-a * k1).rem_euclid(big);
        let first = (-k - r).div_euclid(big) + i128::from((-k - r).rem_euclid(big) != 0);
        (first..)
            .map(move |t| r + t * big)
            .take_while(move |&k0| k0 <= k)
            .filter(move |&k0| k0 != 0 || k1 != 0)
            .map(move |k0| [k0 as i64, k1 as i64])
    });
    Some(finish(f, &decay, kmax, vectors.map(|k| power(f, &k))))
}

/// The variance of the regular grid of `cells[a]` strata per axis under a random shift as a sum
/// over its dual lattice `{k : k_a ∈ cells[a] Z}`; `None` unless `f` is smooth and contained.
pub(crate) fn grid_dual_variance(f: &dyn Integrand, cells: &[usize]) -> Option<DualSum> {
    let decay = f.smooth_decay()?;
    let d = f.dimension();
    if cells.len() != d || cells.contains(&0) {
        return None;
    }
    let kmax = reach(&decay);
    // Multiples of each axis's count within the box.
    let axes: Vec<Vec<i64>> = cells
        .iter()
        .map(|&m| {
            let reach = (kmax / m as u64) as i64;
            (-reach..=reach).map(|t| t * m as i64).collect()
        })
        .collect();
    let count: usize = axes.iter().map(Vec::len).product();
    let powers = (0..count).filter_map(|flat| {
        let mut rest = flat;
        let mut k = [0i64; 3];
        for (a, values) in axes.iter().enumerate() {
            k[a] = values[rest % values.len()];
            rest /= values.len();
        }
        (k[..d].iter().any(|&v| v != 0)).then(|| power(f, &k[..d]))
    });
    Some(finish(f, &decay, kmax, powers))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::AnisotropicGaussian;

    /// The half-width of its interval: every term is a bound.
    fn width(dual: &DualSum) -> f64 {
        dual.truncation + dual.model + dual.rounding
    }

    /// The dual sum of a rank-1 lattice agrees with the space sum where the space sum keeps
    /// its digits (a wide lobe at small N), within both bounds.
    #[test]
    fn the_dual_sum_is_the_space_sum_where_both_keep_their_digits() {
        let f = AnisotropicGaussian::new(0.05, 0.03, 30.0, [0.5, 0.5], 1.0).unwrap();
        for (n, a) in [(16usize, 5u64), (32, 11), (64, 19)] {
            let dual = rank1_dual_variance(&f, n, a).unwrap();
            let (space, rounding) =
                crate::predict::fourier::space::rank1_lattice_variance(&f, n, a)
                    .unwrap()
                    .unwrap();
            assert!(
                (dual.variance - space).abs() <= width(&dual) + rounding,
                "N = {n}: dual {:e} ± {:e} against space {space:e} ± {rounding:e}",
                dual.variance,
                width(&dual)
            );
            assert!(width(&dual) <= 1e-6 * dual.variance, "N = {n}: {dual:?}");
        }
    }
}
