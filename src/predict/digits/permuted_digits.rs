//! Halton's points as drawn: every digit position of every axis permuted by its own uniform
//! random permutation, on an integrand that is a product of one factor per axis.
//!
//! Point `i`'s coordinate on axis `l` (base `p`) has digit `ℓ` equal to the `ℓ`-th least
//! significant base-`p` digit of `i`, for `ℓ ≤ m` (`p^m ≥ N`), and 0 beyond; the permutation
//! `π_ℓ` maps it. Two points therefore share every digit past `m` (a common offset `u` inside a
//! cell of width `p^{−m}`, uniform), and at a position `ℓ ≤ m` either share a digit (when `i`
//! and `j` do) or hold a uniform pair of distinct digits. Write `g(c, u)` for the factor at cell
//! `c` (its `m` digits) and offset `u`, and expand it per digit in an orthonormal basis of the
//! functions of one digit whose first member is constant (Helmert's): a coefficient's support
//! `S` is the set of positions where its basis function is not constant. For two distinct digits
//! `a ≠ b`, `E[e_r(π a) e_s(π b)] = −δ_rs/(p − 1)` (`r, s ≠ 0`), so
//!
//! `E[g(X_i) g(X_j)] = K(A_ij) = Σ_S E_S Π_{ℓ∈S} ρ_ℓ`, `ρ_ℓ = 1` if `ℓ ∈ A_ij`, else `−1/(p − 1)`,
//!
//! with `A_ij` the positions where `i` and `j` agree and `E_S` the factor's energy on support
//! `S`, averaged over `u`. For a product `f = a Π_l g_l` the estimator's variance is then
//!
//! `Var = a² [(1/N²) Σ_{i,j} Π_l K_l(A^l_ij)] − I²`.
//!
//! Splitting each `K_l = E_{∅,l} + K'_l` (the support-free part is the squared cell mean,
//! `I_l² + ε_l`) leaves `Π_l E_{∅,l} − Π_l I_l²`, a sum of positive terms (the offset's own
//! variance), plus pair sums of products of the `K'_l`. The expectation over `u` is a
//! Gauss–Legendre rule on panels between the factor's breakpoints, doubled until two answers
//! agree (`docs/theory.md`, "Halton as drawn").

use crate::budget::{Budget, Needs};
use crate::error::{Error, Result};
use crate::integrand::{AxisFactor, ProductForm};
use crate::pointset::MAX_DIMENSION;
use crate::predict::walsh::walsh_net::cell_rule;
use crate::predict::{ErrorBudget, Form, Prediction, Route, SpectrumOrigin};
use crate::quadrature::CompensatedSum;
use crate::randomization::Randomization;
use crate::sampler::HALTON_BASES;
use rayon::prelude::*;
use serde::Serialize;
use std::fmt;

/// The base of Halton's axis `l`.
fn base(l: usize) -> usize {
    HALTON_BASES[l] as usize
}
/// Two successive quadratures agreeing to this relative difference end the doubling; the
/// difference is what the budget reports.
const QUADRATURE_TOLERANCE: f64 = 1e-7;
/// The most panels a cell's piece is cut into.
const MAX_PANELS: usize = 16;
/// Pair sums a prediction takes at least: the rule and its doubling.
const PASSES: f64 = 2.0;

/// The variance of Halton as drawn on a product integrand, with its error bounds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PermutedVariance {
    /// The variance.
    pub(crate) variance: f64,
    /// The difference from the quadrature with half as many panels.
    pub(crate) quadrature: f64,
    /// A bound on the rounding of the pair sums.
    pub(crate) rounding: f64,
    /// Digit positions per axis that the points do not share.
    pub(crate) digits: [u32; MAX_DIMENSION],
}

/// Digits of `N − 1` in base `p` (at least one): the positions where points may differ.
pub(crate) fn positions(n: usize, p: usize) -> u32 {
    let (mut m, mut reach) = (1, p);
    while reach < n {
        reach *= p;
        m += 1;
    }
    m
}

/// The work of the pair sum for `n` points in dimension `d`, in seconds of one core.
pub(crate) fn pair_work_seconds(n: usize, d: usize) -> f64 {
    PASSES * (n as f64) * (n as f64) / 2.0 * d as f64 * crate::costs::PAIR_AXIS_SECONDS
}

/// One axis's kernel: `K'(A)` for every agreement set `A` of its `m` positions (bit `ℓ − 1`
/// for position `ℓ`), and the support-free energy `E_∅ = I² + ε`.
struct AxisKernel {
    varying: Vec<f64>,
    integral_sq: f64,
    excess: f64,
}

/// The energies `E_S` (bit `ℓ − 1` of `S` for position `ℓ`) of `g` over its `m` positions in
/// base `p`, averaged over the offset by the rule with `panels` panels per piece, and the
/// squared cell mean's excess over `I²`.
fn support_energies(g: &AxisFactor, p: usize, m: u32, panels: usize) -> (Vec<f64>, f64) {
    let cells = p.pow(m);
    let w = 1.0 / cells as f64;
    let integral = g.integral();
    let mut energy = vec![0.0; 1 << m];
    let mut excess = 0.0;
    let mut values = vec![0.0; cells];
    let support: Vec<usize> = (0..cells).map(|c| support_of(c, p, m)).collect();
    for (u, weight) in cell_rule(g, w, panels) {
        values
            .par_iter_mut()
            .enumerate()
            .for_each(|(c, v)| *v = g.eval(c as f64 * w + u));
        helmert_transform(&mut values, p, m);
        // Coefficient 0 is `√cells` times the cell mean.
        let e = values[0] / (cells as f64).sqrt() - integral;
        excess += weight * e * e;
        for (c, v) in values.iter().enumerate().skip(1) {
            energy[support[c]] += weight * v * v * w;
        }
    }
    (energy, excess)
}

/// The positions (bit `ℓ − 1` for position `ℓ`, the most significant digit of `c` being
/// position 1) where the index `c` of a coefficient has a non-zero digit.
pub(crate) fn support_of(mut c: usize, p: usize, m: u32) -> usize {
    let mut mask = 0;
    for k in 0..m {
        if !c.is_multiple_of(p) {
            mask |= 1 << (m - 1 - k);
        }
        c /= p;
    }
    mask
}

/// The orthonormal transform of `values` (length `p^m`) in Helmert's basis along every digit:
/// `e_0 = 1/√p`, `e_k(a) = (1 for a < k, −k for a = k, 0 beyond)/√(k(k+1))`.
///
/// Each stage runs over whole rows of `stride` values at once (the `p` members of a butterfly
/// are `stride` apart), so its loops run over contiguous lanes; every lane takes the same
/// operations in the same order as a butterfly taken alone.
pub(crate) fn helmert_transform(values: &mut [f64], p: usize, m: u32) {
    let norms: Vec<f64> = (0..p)
        .map(|k| {
            if k == 0 {
                (p as f64).sqrt()
            } else {
                let kf = k as f64;
                (kf * (kf + 1.0)).sqrt()
            }
        })
        .collect();
    let lanes = values.len() / p;
    let (mut total, mut prefix) = (vec![0.0; lanes], vec![0.0; lanes]);
    let mut stride = 1;
    for _ in 0..m {
        let span = stride * p;
        let (total, prefix) = (&mut total[..stride], &mut prefix[..stride]);
        if p == 2 {
            for block in values.chunks_exact_mut(span) {
                haar_stage(block, stride, norms[0]);
            }
        } else if stride == 1 {
            values
                .chunks_exact_mut(p)
                .for_each(|block| helmert_butterfly(block, &norms));
        } else {
            for block in values.chunks_exact_mut(span) {
                helmert_stage(block, stride, &norms, total, prefix);
            }
        }
        stride = span;
    }
}

/// [`helmert_stage`] in base 2, where both norms are `√2`: row 0 becomes `(a + b)/√2` and row
/// 1 `(a − b)/√2`, the same operations on the same values (`1 · b` is `b`), so the same bits.
fn haar_stage(block: &mut [f64], stride: usize, norm: f64) {
    let (first, second) = block.split_at_mut(stride);
    for (a, b) in first.iter_mut().zip(second.iter_mut()) {
        let (x, y) = (*a, *b);
        *a = (x + y) / norm;
        *b = (x - y) / norm;
    }
}

/// One butterfly over `p = norms.len()` contiguous values: [`helmert_stage`] with one lane.
fn helmert_butterfly(block: &mut [f64], norms: &[f64]) {
    let total: f64 = block.iter().sum();
    let mut prefix = 0.0;
    prefix += block[0];
    for k in 1..block.len() {
        let v = block[k];
        block[k] = (prefix - k as f64 * v) / norms[k];
        prefix += v;
    }
    block[0] = total / norms[0];
}

/// One butterfly stage over `block`, `p = norms.len()` rows of `stride` lanes; `total` and
/// `prefix` are scratch of `stride` lanes. Row `k ≥ 1` becomes `(Σ_{a<k} row_a − k row_k) /
/// √(k(k+1))`, read before it is written; row 0, the sum over rows `/√p`, is written last.
fn helmert_stage(
    block: &mut [f64],
    stride: usize,
    norms: &[f64],
    total: &mut [f64],
    prefix: &mut [f64],
) {
    total.copy_from_slice(&block[..stride]);
    for row in block[stride..].chunks_exact(stride) {
        total.iter_mut().zip(row).for_each(|(t, &x)| *t += x);
    }
    prefix.fill(0.0);
    prefix
        .iter_mut()
        .zip(&block[..stride])
        .for_each(|(s, &x)| *s += x);
    for (k, row) in block.chunks_exact_mut(stride).enumerate().skip(1) {
        let (kf, norm) = (k as f64, norms[k]);
        for (x, s) in row.iter_mut().zip(prefix.iter_mut()) {
            let v = *x;
            *x = (*s - kf * v) / norm;
            *s += v;
        }
    }
    block[..stride]
        .iter_mut()
        .zip(total.iter())
        .for_each(|(x, &t)| *x = t / norms[0]);
}

/// `K'(A) = Σ_{S≠∅} E_S Π_{ℓ∈S} ρ_ℓ(A)` for every `A`, position by position.
fn kernel(energy: &[f64], p: usize, m: u32) -> Vec<f64> {
    let mut k = energy.to_vec();
    k[0] = 0.0;
    let apart = -1.0 / (p as f64 - 1.0);
    for bit in 0..m {
        let b = 1usize << bit;
        for a in 0..k.len() {
            if a & b == 0 {
                let (without, with) = (k[a], k[a | b]);
                k[a] = without + apart * with;
                k[a | b] = without + with;
            }
        }
    }
    k
}

fn axis_kernel(g: &AxisFactor, p: usize, m: u32, panels: usize) -> AxisKernel {
    let (energy, excess) = support_energies(g, p, m, panels);
    let integral = g.integral();
    AxisKernel {
        varying: kernel(&energy, p, m),
        integral_sq: integral * integral,
        excess,
    }
}

/// Bits per digit of base `p` in a packed index: `⌈log2 p⌉`, so that `m` digits of an index
/// below `2^64` fit in 64 bits.
pub(crate) fn digit_bits(p: usize) -> u32 {
    usize::BITS - (p - 1).leading_zeros()
}

/// Every index's base-`p` digits over `m` positions, packed [`digit_bits`] bits apiece (least
/// significant digit lowest), so that comparing two indices needs no division.
pub(crate) fn packed_digits(n: usize, p: usize, m: u32) -> Vec<u64> {
    let bits = digit_bits(p);
    (0..n)
        .map(|mut i| {
            let mut packed = 0u64;
            for k in 0..m {
                packed |= ((i % p) as u64) << (k * bits);
                i /= p;
            }
            packed
        })
        .collect()
}

/// The agreement set of two packed indices over `m` positions of `bits` bits (bit `ℓ − 1` for
/// the `ℓ`-th least significant digit).
pub(crate) fn agreement(a: u64, b: u64, m: u32, bits: u32) -> usize {
    let differ = a ^ b;
    if bits == 1 {
        return (!differ & ((1u64 << m) - 1)) as usize;
    }
    let field = (1u64 << bits) - 1;
    let mut mask = 0;
    for k in 0..m {
        if differ >> (k * bits) & field == 0 {
            mask |= 1 << k;
        }
    }
    mask
}

/// Rows of the pair sums one parallel task takes.
const PAIR_ROWS: usize = 16;

/// `(1/N²) Σ_{i,j}` of the products `Π_{l∈T} K'_l` for every non-empty subset `T` of the axes
/// (index `T` as a bit set), and the sums of their magnitudes.
fn pair_sums(kernels: &[AxisKernel], ms: &[u32], n: usize) -> (Vec<f64>, Vec<f64>) {
    let d = kernels.len();
    let digits: Vec<Vec<u64>> = ms
        .iter()
        .enumerate()
        .map(|(l, &m)| packed_digits(n, base(l), m))
        .collect();
    let bits: Vec<u32> = (0..d).map(|l| digit_bits(base(l))).collect();
    let subsets = 1usize << d;
    // Rows in fixed chunks added in their order: the same bits on any thread count.
    let parts: Vec<(Vec<f64>, Vec<f64>)> = (0..n.div_ceil(PAIR_ROWS))
        .into_par_iter()
        .map(|chunk| {
            let (mut s, mut a) = (vec![0.0; subsets], vec![0.0; subsets]);
            let mut k = [0.0; MAX_DIMENSION];
            for i in chunk * PAIR_ROWS..((chunk + 1) * PAIR_ROWS).min(n) {
                for j in i..n {
                    // The diagonal once, the pairs i ≠ j twice.
                    let times = if j == i { 1.0 } else { 2.0 };
                    for (l, axis) in kernels.iter().enumerate() {
                        k[l] = axis.varying[agreement(digits[l][i], digits[l][j], ms[l], bits[l])];
                    }
                    for t in 1..subsets {
                        let mut product = times;
                        for (l, kl) in k.iter().enumerate().take(d) {
                            if t >> l & 1 == 1 {
                                product *= kl;
                            }
                        }
                        s[t] += product;
                        a[t] += product.abs();
                    }
                }
            }
            (s, a)
        })
        .collect();
    let (mut sums, mut magnitudes) = (vec![0.0; subsets], vec![0.0; subsets]);
    for (s, a) in parts {
        sums.iter_mut().zip(&s).for_each(|(x, y)| *x += y);
        magnitudes.iter_mut().zip(&a).for_each(|(x, y)| *x += y);
    }
    let scale = 1.0 / (n as f64 * n as f64);
    (
        sums.iter().map(|s| s * scale).collect(),
        magnitudes.iter().map(|s| s * scale).collect(),
    )
}

/// The variance (without the height²) with `panels` panels per piece, and its rounding bound.
fn variance_at(form: &ProductForm, n: usize, ms: &[u32], panels: usize) -> (f64, f64) {
    let kernels: Vec<AxisKernel> = form
        .axes
        .iter()
        .zip(ms)
        .enumerate()
        .map(|(l, (g, &m))| axis_kernel(g, base(l), m, panels))
        .collect();
    let (sums, magnitudes) = pair_sums(&kernels, ms, n);
    let d = kernels.len();
    let mut total = CompensatedSum::default();
    let mut magnitude = 0.0;
    for t in 0..1usize << d {
        // The axes outside `T` contribute their support-free energy, `I² + ε`; for `T = ∅`
        // the product less `Π I²` is expanded into positive terms.
        let outside = |sub: usize| -> f64 {
            kernels
                .iter()
                .enumerate()
                .filter(|(l, _)| t >> l & 1 == 0)
                .map(|(l, a)| {
                    if sub >> l & 1 == 1 {
                        a.excess
                    } else {
                        a.integral_sq
                    }
                })
                .product()
        };
        if t == 0 {
            for sub in 1..1usize << d {
                total.add(outside(sub));
            }
        } else {
            let free = (0..1usize << d)
                .filter(|sub| sub & t == 0)
                .map(outside)
                .sum::<f64>();
            total.add(sums[t] * free);
            magnitude += magnitudes[t] * free;
        }
    }
    let rounding = 4.0 * f64::EPSILON * (n as f64 + 8.0) * magnitude;
    (total.value(), rounding)
}

/// The variance of `N` Halton points as drawn on `form` (dimension at most 8), exact to
/// quadrature: panels doubled until two answers agree to [`QUADRATURE_TOLERANCE`].
pub(crate) fn halton_as_drawn_variance(form: &ProductForm, n: usize) -> PermutedVariance {
    let d = form.axes.len();
    let ms: Vec<u32> = (0..d).map(|l| positions(n, base(l))).collect();
    let height_sq = form.height * form.height;
    let (mut previous, _) = variance_at(form, n, &ms, 1);
    let mut panels = 2;
    loop {
        let (v, rounding) = variance_at(form, n, &ms, panels);
        let difference = (v - previous).abs();
        if difference <= QUADRATURE_TOLERANCE * v.abs() || panels >= MAX_PANELS {
            let mut digits = [0; MAX_DIMENSION];
            digits[..d].copy_from_slice(&ms);
            return PermutedVariance {
                variance: height_sq * v,
                quadrature: height_sq * difference,
                rounding: height_sq * rounding,
                digits,
            };
        }
        previous = v;
        panels *= 2;
    }
}

/// Where an exact prediction of Halton as drawn comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct PermutedDigitsOrigin {
    /// Digit positions per axis where the points differ (the rest they share).
    pub digits: [u32; MAX_DIMENSION],
    /// Axes.
    pub dimension: usize,
}

impl fmt::Display for PermutedDigitsOrigin {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let per_axis: Vec<String> = self.digits[..self.dimension]
            .iter()
            .zip(HALTON_BASES)
            .map(|(m, p)| format!("{p}^{m}"))
            .collect();
        write!(
            f,
            "each axis's factor by digit supports in Helmert's basis ({} cells), summed over \
             the points' pairs of agreeing digits",
            per_axis.join(" × ")
        )
    }
}

/// The prediction of Halton as drawn on a product integrand.
///
/// # Errors
/// More than 8 axes, `n = 0`, pairs whose work exceeds `work_seconds` (the route is quadratic
/// in N: about 8 s of one core at N = 16384 in 2D), or cells beyond `budget`.
pub(crate) fn predict_halton_as_drawn(
    form: &ProductForm,
    n: usize,
    work_seconds: f64,
    budget: &Budget,
) -> Result<Prediction> {
    let d = form.axes.len();
    if d > HALTON_BASES.len() || n == 0 {
        return Err(Error::Mismatch(format!(
            "Halton as drawn needs 1 to {} axes and N ≥ 1",
            HALTON_BASES.len()
        )));
    }
    let work = pair_work_seconds(n, d);
    if work > work_seconds {
        return Err(Error::OutsideValidity {
            route: "Halton's pairs of digit agreements".into(),
            reason: format!(
                "halton used as drawn is summed exactly over its {n}² pairs of points, about \
                 {work:.0} s of one core, beyond the work budget of {work_seconds:.0} s; measure \
                 it with `specvar mc --randomization none`, or predict with --randomization \
                 shift"
            ),
        });
    }
    let cells: f64 = (0..d)
        .map(|l| (base(l) as f64).powi(positions(n, base(l)) as i32))
        .sum();
    budget.check(
        "Halton's pairs of digit agreements",
        Needs {
            memory_bytes: 16.0 * cells,
            work_seconds: work,
        },
        "lower N, or measure it with `specvar mc`",
    )?;
    let v = halton_as_drawn_variance(form, n);
    let origin = PermutedDigitsOrigin {
        digits: v.digits,
        dimension: d,
    };
    Ok(Prediction {
        variance: v.variance,
        randomization: Randomization::None,
        route: Route {
            form: Form::Walsh,
            spectrum: SpectrumOrigin::PermutedDigits(origin),
        },
        reason: "halton as drawn (each digit position of each axis under its own random \
                 permutation) on an integrand that is a product of one factor per axis: two \
                 points share the digits past the index's and, where their indices' digits \
                 differ, hold a uniform pair of distinct digits, so the variance is a sum over \
                 the points' pairs of each axis's kernel on the positions where they agree, from \
                 the factor's energy on each support of digits, exact to quadrature"
            .into(),
        budget: ErrorBudget {
            tabulation: 0.0,
            quadrature: v.quadrature + v.rounding,
            ..Default::default()
        },
        n,
        dimension: d,
        dc_term: 0.0,
        evaluations: (n as u64).saturating_mul(n as u64),
        alternatives: Vec::new(),
        analysis: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Helmert's transform is orthonormal: it keeps the sum of squares, and a constant has
    /// only coefficient 0.
    #[test]
    fn helmert_transform_is_orthonormal() {
        for (p, m) in [(2usize, 3u32), (3, 2), (5, 2)] {
            let len = p.pow(m);
            let mut v: Vec<f64> = (0..len).map(|i| ((i * 7 + 3) % 11) as f64 - 4.0).collect();
            let before: f64 = v.iter().map(|x| x * x).sum();
            helmert_transform(&mut v, p, m);
            let after: f64 = v.iter().map(|x| x * x).sum();
            assert!((before - after).abs() <= 1e-12 * before);
            let mut c = vec![2.5; len];
            helmert_transform(&mut c, p, m);
            assert!((c[0] - 2.5 * (len as f64).sqrt()).abs() < 1e-12);
            assert!(c[1..].iter().all(|x| x.abs() < 1e-12));
        }
    }

    /// A pair that agrees everywhere has the whole energy: `K'(all) = Σ_{S≠∅} E_S`.
    #[test]
    fn full_agreement_reads_every_support() {
        let energy = [0.0, 1.0, 2.0, 4.0];
        let k = kernel(&energy, 3, 2);
        assert!((k[3] - 7.0).abs() < 1e-15);
        // Disagreement at both positions: ρ = −1/2 on each.
        assert!((k[0] - (-0.5 - 1.0 + 1.0)).abs() < 1e-15);
    }

    /// Packed digits compare as the digits do, at every base (64 bits hold `m` digits).
    #[test]
    fn packed_digits_agree_where_the_digits_do() {
        for p in HALTON_BASES.map(|b| b as usize) {
            let m = positions(1 << 18, p);
            assert!(m * digit_bits(p) <= 64);
            let packed = packed_digits(300, p, m);
            for (i, j) in [(0, 1), (5, 7), (17, 299), (123, 124)] {
                let (mut a, mut b, mut want) = (i, j, 0);
                for k in 0..m {
                    if a % p == b % p {
                        want |= 1 << k;
                    }
                    a /= p;
                    b /= p;
                }
                assert_eq!(agreement(packed[i], packed[j], m, digit_bits(p)), want);
            }
        }
    }

    #[test]
    fn positions_cover_the_indices() {
        assert_eq!(positions(4096, 2), 12);
        assert_eq!(positions(4096, 3), 8);
        assert_eq!(positions(1, 3), 1);
        assert_eq!(positions(9, 3), 2);
        assert_eq!(positions(10, 3), 3);
    }
}
