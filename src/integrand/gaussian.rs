//! The isotropic Gaussian, truncated to the unit cube.

use super::{
    check_parameters, shift_phase, squared_distance, wrapped_interval, Integrand, IntegrandKind,
};
use crate::error::{invalid, Result};
use crate::vector_exp::{exp_in_place, exp_nonpositive};
use errorfunctions::ComplexErrorFunctions;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::{PI, SQRT_2};

/// `f(x) = a exp(-|x - x0|² / (2σ²))` on the unit cube, zero outside it: what Monte Carlo on
/// `[0,1)^d` integrates, and, periodized, what its torus Fourier coefficients describe.
///
/// `f̂(ω) = a (2πσ²)^{d/2} exp(-2π² σ² |ω|²) e^{-2πi ω·x0}` over the whole space (the polar
/// form's transform, right only while the mass outside the cube is negligible). The torus
/// coefficients are products over axes of the 1D coefficients of a truncated Gaussian, which
/// have a closed form through the Faddeeva function `w` ([`Gaussian::coefficient`]): the
/// full-space term plus one term per face, which falls like `1/k` where the Gaussian does not
/// vanish at the faces. Its integral over the cube, the Monte Carlo ground truth, is the product
/// of `σ √(π/2) [erf((1 - x0_i)/(σ√2)) + erf(x0_i/(σ√2))]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Gaussian {
    sigma: f64,
    centre: Vec<f64>,
    height: f64,
}

/// The widest σ accepted. Variances are differences such as `∫f² - I²` of numbers near `I²`;
/// at σ = 100 the Gaussian varies by `1/(2σ²) = 5e-5` over the cube, its variance is about
/// 1e-10 of `I²`, and the subtraction leaves it about six correct digits. Wider, the answer
/// would be rounding noise.
pub const MAX_SIGMA: f64 = 100.0;
/// The narrowest Gaussian predicted: `σ = 10^-6`. Its sums over cells split every cell into
/// segments a quarter of σ long, so their work and memory grow like `1/σ` on a coarse grid of
/// cells: 1.6 s and 0.7 GB at `10^-6`, 38 s and 7 GB at `10^-7` (two cores, jitter's 4 × 4
/// strata). A millionth of the unit square is far below any pixel's resolution.
pub const MIN_SIGMA: f64 = 1e-6;

impl Gaussian {
    /// A Gaussian of width `sigma`, centre `centre` (its length is the dimension, 1 to 3) and
    /// height `height`.
    ///
    /// # Errors
    /// A σ that is not positive and finite, below `MIN_SIGMA` (1e-6) or above `MAX_SIGMA` (100),
    /// a height that is not
    /// finite, or a centre outside the cube.
    ///
    /// # Examples
    /// ```
    /// use specvar::integrand::{Gaussian, Integrand};
    /// let g = Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap();
    /// // Almost all of the mass 2πσ² lies inside the square.
    /// assert!((g.integral() - 2.0 * std::f64::consts::PI * 0.01).abs() < 1e-7);
    /// // Off centre, the torus coefficients keep a 1/k tail from the jump at the faces.
    /// let near_face = Gaussian::new(0.1, vec![0.3, 0.6], 1.0).unwrap();
    /// let far = near_face.coefficient(&[512, 0]).norm();
    /// assert!(far > 1e-7 && near_face.fourier(&[512.0, 0.0]).norm() == 0.0);
    /// ```
    pub fn new(sigma: f64, centre: Vec<f64>, height: f64) -> Result<Self> {
        check_parameters("Gaussian", "sigma", sigma, &centre, height)?;
        if sigma < MIN_SIGMA {
            return Err(invalid(
                "sigma",
                sigma,
                format!(
                    "at least {MIN_SIGMA:e}: the sums over a sampler's cells take work and memory \
                     growing like 1/σ (seconds at {MIN_SIGMA:e}, minutes and gigabytes below)"
                ),
            ));
        }
        if sigma > MAX_SIGMA {
            return Err(invalid(
                "sigma",
                sigma,
                format!(
                    "at most {MAX_SIGMA}: a wider Gaussian is nearly constant on the cube and \
                     its variance (below 1e-10 of I²) is lost to rounding"
                ),
            ));
        }
        Ok(Self {
            sigma,
            centre,
            height,
        })
    }

    /// The width σ.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// The centre.
    pub fn centre(&self) -> &[f64] {
        &self.centre
    }

    /// The height.
    pub fn height(&self) -> f64 {
        self.height
    }

    /// The 1D torus coefficients `∫_0^1 exp(-(x - c)²/(2σ²)) e^{-2πikx} dx` for `k = -K..=K`
    /// on axis `axis`.
    pub fn axis_coefficients(&self, axis: usize, kmax: usize) -> Vec<Complex64> {
        (-(kmax as i64)..=kmax as i64)
            .map(|k| axis_coefficient(k, self.centre[axis], self.sigma))
            .collect()
    }
}

/// `∫_0^1 exp(-(x - m)²/(2s²)) e^{-2πikx} dx`. With `t = (x - m)/(s√2)` and `b = π k s √2`
/// it is `s √(π/2) e^{-2πikm} e^{-b²} [erf(t₁ + ib) - erf(t₀ + ib)]`, `t₀ = -m/(s√2)`,
/// `t₁ = (1 - m)/(s√2)`. Written with `erfc(z) = e^{-z²} w(iz)` so that every `w` is taken in
/// the upper half plane (where `|w| ≤ 1`): for a centre in `[0, 1]` (`t₀ ≤ 0 ≤ t₁`) it is
/// `s √(π/2) e^{-2πikm} [2e^{-b²} - e^{-t₀² - 2it₀b} w(b - it₀) - e^{-t₁² - 2it₁b} w(-b + it₁)]`,
/// the full-space term and one term per face; for a centre beyond a face (the conditional
/// slices of a rotated lobe, [`super::truncated_lobe`]) the two faces' terms alone, from
/// `erf(t₁ + ib) - erf(t₀ + ib) = erfc(t₀ + ib) - erfc(t₁ + ib)` when `0 < t₀` and
/// `= erfc(-t₁ - ib) - erfc(-t₀ - ib)` when `t₁ < 0`.
pub(crate) fn axis_coefficient(k: i64, m: f64, s: f64) -> Complex64 {
    let b = PI * k as f64 * s * SQRT_2;
    let (t0, t1) = (-m / (s * SQRT_2), (1.0 - m) / (s * SQRT_2));
    let face = |t: f64, w: Complex64| Complex64::from_polar((-t * t).exp(), -2.0 * t * b) * w;
    // e^{-b²} erfc(t + ib) for t > 0, and e^{-b²} erfc(-t - ib) for t < 0.
    let above = |t: f64| face(t, Complex64::new(-b, t).w());
    let below = |t: f64| face(t, Complex64::new(b, -t).w());
    let inner = if t0 > 0.0 {
        above(t0) - above(t1)
    } else if t1 < 0.0 {
        below(t1) - below(t0)
    } else {
        2.0 * (-b * b).exp() - below(t0) - above(t1)
    };
    Complex64::from_polar(s * (PI / 2.0).sqrt(), -2.0 * PI * k as f64 * m) * inner
}

/// Segments shorter than this, in units of the width `s`, are integrated by Gauss–Legendre:
/// a difference of two error functions this close loses the digits the segment is short by
/// (a cell of 2^-20 would keep 10), while [`SHORT_SEGMENT_NODES`] nodes are exact to rounding:
/// their error, `w^{2n+1} (n!)^4 / ((2n+1) ((2n)!)^3) · max |H_{2n}(t) e^{-t²}|`, is below
/// 1e-17 at `w = 1/4`, `n = 6`.
const SHORT_SEGMENT: f64 = 0.25;
/// Gauss–Legendre nodes for a short segment.
const SHORT_SEGMENT_NODES: usize = 6;

/// The Gauss–Legendre rule of [`short_segment`], built once.
fn short_rule() -> &'static (Vec<f64>, Vec<f64>) {
    static RULE: std::sync::OnceLock<(Vec<f64>, Vec<f64>)> = std::sync::OnceLock::new();
    RULE.get_or_init(|| crate::quadrature::gauss_legendre(SHORT_SEGMENT_NODES))
}

/// `∫_u^v exp(-t²) dt` for `v - u <` [`SHORT_SEGMENT`], by Gauss–Legendre, each node's
/// exponential by [`crate::vector_exp`] (so that [`short_segments`] gives the same bits).
fn short_segment(u: f64, v: f64) -> f64 {
    let mut values = [0.0; SHORT_SEGMENT_NODES];
    short_arguments(u, v, &mut values);
    values.iter_mut().for_each(|x| *x = exp_nonpositive(*x));
    short_sum(u, v, &values)
}

/// The exponents `−t²` at the rule's nodes on `[u, v]`.
fn short_arguments(u: f64, v: f64, out: &mut [f64]) {
    let (nodes, _) = short_rule();
    let (mid, half) = ((u + v) / 2.0, (v - u) / 2.0);
    for (o, x) in out.iter_mut().zip(nodes) {
        let t = mid + half * x;
        *o = -t * t;
    }
}

/// The rule's sum on `[u, v]` from the exponentials at its nodes, added in order.
fn short_sum(u: f64, v: f64, values: &[f64]) -> f64 {
    let (_, weights) = short_rule();
    let mut sum = 0.0;
    for (w, e) in weights.iter().zip(values) {
        sum += w * e;
    }
    (v - u) / 2.0 * sum
}

/// Cells per parallel task of [`short_segments`].
const SEGMENT_CHUNK: usize = 4096;

/// The ends `((a − c)/s, (b − c)/s)` of the cells `[i/m, (i+1)/m)` for `i` in `cells`, and the
/// exponentials at their short rule's nodes ([`short_arguments`]), all taken at once.
fn short_cells(
    cells: std::ops::Range<usize>,
    m: usize,
    c: f64,
    s: f64,
) -> (Vec<(f64, f64)>, Vec<f64>) {
    let ends: Vec<(f64, f64)> = cells
        .map(|i| {
            let (a, b) = (i as f64 / m as f64, (i + 1) as f64 / m as f64);
            ((a - c) / s, (b - c) / s)
        })
        .collect();
    let mut values = vec![0.0; ends.len() * SHORT_SEGMENT_NODES];
    for (&(u, v), row) in ends
        .iter()
        .zip(values.chunks_exact_mut(SHORT_SEGMENT_NODES))
    {
        short_arguments(u, v, row);
    }
    exp_in_place(&mut values);
    (ends, values)
}

/// `gaussian_segment(i/m, (i+1)/m, c, s)` for every `i < m`, when a cell is shorter than
/// [`SHORT_SEGMENT`] widths: the same bits as cell by cell, with the exponentials of a chunk
/// of cells taken at once ([`crate::vector_exp::exp_in_place`]).
fn short_segments(m: usize, c: f64, s: f64) -> Vec<f64> {
    let mut out = vec![0.0; m];
    out.par_chunks_mut(SEGMENT_CHUNK)
        .enumerate()
        .for_each(|(chunk, cells)| {
            let first = chunk * SEGMENT_CHUNK;
            let cell_ends = |i: usize| (i as f64 / m as f64, (i + 1) as f64 / m as f64);
            let (ends, values) = short_cells(first..first + cells.len(), m, c, s);
            for (k, ((cell, &(u, v)), row)) in cells
                .iter_mut()
                .zip(&ends)
                .zip(values.chunks_exact(SHORT_SEGMENT_NODES))
                .enumerate()
            {
                // The cell-by-cell rule's own test, should rounding put a cell at its edge.
                *cell = if v - u < SHORT_SEGMENT {
                    s * short_sum(u, v, row)
                } else {
                    let (a, b) = cell_ends(first + k);
                    gaussian_segment(a, b, c, s)
                };
            }
        });
    out
}

/// `∫_a^b exp(-(x - c)²/s²) dx`, with `erfc` on the side where `erf` would cancel, and
/// Gauss–Legendre on segments short enough that any difference of error functions would.
fn gaussian_segment(a: f64, b: f64, c: f64, s: f64) -> f64 {
    if b <= a {
        return 0.0;
    }
    let (u, v) = ((a - c) / s, (b - c) / s);
    if v - u < SHORT_SEGMENT {
        return s * short_segment(u, v);
    }
    let half = s * PI.sqrt() / 2.0;
    if u >= 0.0 {
        half * (libm::erfc(u) - libm::erfc(v))
    } else if v <= 0.0 {
        half * (libm::erfc(-v) - libm::erfc(-u))
    } else {
        half * (libm::erf(v) - libm::erf(u))
    }
}

/// The relative rounding of `exp(−t²)` at a point `t = (x − c)/s` of the unit interval: the
/// point's own rounding, `δt ≤ ε (3/s + 3|t|)` from `x` (a few operations on numbers of the
/// unit interval), `x − c` and the division, moves the value by `2|t| δt`, and `t²` and `exp`
/// round by `ε t²` and `ε`.
fn exp_rounding(t: f64, s: f64) -> f64 {
    let t = t.abs();
    f64::EPSILON * (8.0 * t * t + 8.0 * t / s + 4.0 + EXP_ULPS)
}

/// Units in the last place [`crate::vector_exp`]'s exponential may err by beyond the one
/// [`exp_rounding`] counts for a library `exp`.
const EXP_ULPS: f64 = 3.0;

/// A bound on the relative rounding of [`gaussian_segment`] (of width `s`, centre `c`) over
/// any piece of a cell of width `h` in the unit interval. A short piece is a Gauss–Legendre
/// sum of positive terms, each within [`exp_rounding`] at the farthest point from `c`, twice
/// over with the sum, its weights and the pieces' sum (the rounding of its ends, which
/// adjacent cells share, is [`end_rounding`]'s). Otherwise a difference of error
/// functions, each within `2ε` and moved by its argument's rounding times
/// `|d ln erfc(u)/du| ≤ 2u + 2`; the difference is at least `1 − e^{−1/16}` of the sum of the
/// two (for `0 ≤ u < v`, `erfc(v) ≤ erfc(u) e^{−(v² − u²)}` and `v − u ≥ 1/4`), which
/// multiplies their errors by at most 33.
fn segment_rounding(c: f64, s: f64, h: f64) -> f64 {
    let t = c.max(1.0 - c) / s;
    let short = 2.0 * exp_rounding(t, s) + 8.0 * f64::EPSILON;
    if h / s < SHORT_SEGMENT {
        return short;
    }
    let argument = f64::EPSILON * (3.0 / s + 3.0 * t);
    let each = (2.0 * t + 2.0) * argument + 2.0 * f64::EPSILON;
    short.max(33.0 * 2.0 * each + 4.0 * f64::EPSILON)
}

/// A bound on the error a cell end `x` adds to the masses of [`gaussian_segment`] (of width
/// `s`, centre `c`) on either side of it. Its argument `t = (x − c)/s` is within
/// `ε (δx/s + |t|)`: `x` itself within `δx` (none for `i/m` with `m` a power of two, `ε/2`
/// otherwise, `ε` more once shifted), then the difference and the division each half an ulp;
/// so it moves a mass by at most `s (…) max g`, `ε (δx + |x − c|)`. Adjacent cells compute
/// their shared end alike, so it moves mass from one to the other: a union of adjacent cells
/// is within the same two ends' error, where a bound relative to each mass would grow with
/// the cells.
fn end_rounding(c: f64, m: usize, shift: f64) -> f64 {
    let end = if shift != 0.0 {
        1.5
    } else if m.is_power_of_two() {
        0.0
    } else {
        0.5
    };
    f64::EPSILON * (end + c.max(1.0 - c))
}

/// `Σ_c ∫_c (g − ḡ_c)²` over the `m` cells of the unit interval for `g(x) = exp(−((x − c)/s)²)`
/// shifted by `shift` on the torus, `ḡ_c` its mean on cell `c`, and a bound on its error: from
/// each cell's mass's own values where the cells are short and unshifted
/// ([`short_variances_within_cells`]), by the embedded rules otherwise.
fn variance_within_cells(m: usize, shift: f64, c: f64, s: f64) -> (f64, f64) {
    if shift == 0.0 && m > 0 && 1.0 / (m as f64 * s) < SHORT_VARIANCE {
        let short = short_variances_within_cells(m, c, s);
        return (short.within, short.within_error);
    }
    embedded_variances_within_cells(m, shift, c, s)
}

/// [`variance_within_cells`] on any cells, shifted or not, by the embedded rules.
///
/// Each piece of a cell is split into segments shorter than [`SHORT_SEGMENT`] widths, on which
/// 10-point Gauss–Legendre is exact to rounding (the 5-point rule's difference from it is
/// counted as its error, a wide margin: [`crate::quadrature::EmbeddedRules`]). The mean `ḡ_c` is
/// the 10-point rule's own, from the same nodes: then `Σ w (g − ḡ)` vanishes to rounding, where
/// a mean computed from the cell's ends apart (as its mass is) would differ from the nodes' by
/// the ends' rounding, about `ε/h` of itself, and add its square, `ε²/h⁴` of the variance
/// (10^-7 at `h = 10^-6.5`). Each node's `(g − ḡ)²` is within `2|g − ḡ| e + e²`, `e` the
/// rounding of `g` ([`exp_rounding`]) and of `ḡ`; a cell's computed ends (`i/m`, then the
/// shift added) are each within `1.5ε`, so its length within `3ε` and its variance, of order
/// `h³`, within `9ε/h` of itself.
fn embedded_variances_within_cells(m: usize, shift: f64, c: f64, s: f64) -> (f64, f64) {
    static RULES: std::sync::OnceLock<crate::quadrature::EmbeddedRules> =
        std::sync::OnceLock::new();
    let rules = RULES.get_or_init(Default::default);
    let (low, high) = rules.point_counts();
    let per_piece = low + high;
    // The higher rule's weights on [−1, 1].
    let weights: Vec<f64> = rules
        .nodes_on(-1.0, 1.0)
        .skip(low)
        .map(|(_, w)| w)
        .collect();
    // The rounding of any node's value, at the farthest point of the interval from `c`.
    let farthest = exp_rounding(c.max(1.0 - c) / s, s);
    let mut cells = vec![(0.0, 0.0); m];
    cells
        .par_chunks_mut(SEGMENT_CHUNK)
        .enumerate()
        .for_each(|(chunk, out)| {
            let first = chunk * SEGMENT_CHUNK;
            // The chunk's pieces (cell, ends), then every node's exponential at once.
            let mut pieces: Vec<(usize, f64, f64)> = Vec::with_capacity(out.len());
            for k in 0..out.len() {
                let i = first + k;
                let cell = (i as f64 / m as f64, (i + 1) as f64 / m as f64);
                for (a, b) in wrapped_interval(cell.0, cell.1, shift) {
                    if b <= a {
                        continue;
                    }
                    let count = ((b - a) / (s * SHORT_SEGMENT)).ceil().max(1.0);
                    let step = (b - a) / count;
                    for j in 0..count as usize {
                        let lo = a + j as f64 * step;
                        pieces.push((k, lo, lo + step));
                    }
                }
            }
            let mut scaled = Vec::with_capacity(pieces.len() * per_piece);
            for &(_, lo, hi) in &pieces {
                scaled.extend(rules.nodes_on(lo, hi).map(|(x, _)| (x - c) / s));
            }
            let mut values: Vec<f64> = scaled.iter().map(|t| -t * t).collect();
            exp_in_place(&mut values);
            let nodes = |p: usize| p * per_piece..(p + 1) * per_piece;
            // Each cell's mean from the higher rule's sums over its pieces.
            let mut means = vec![(0.0, 0.0); out.len()];
            for (p, &(k, lo, hi)) in pieces.iter().enumerate() {
                let half = (hi - lo) / 2.0;
                let sum: f64 = weights
                    .iter()
                    .zip(&values[nodes(p)][low..])
                    .map(|(w, g)| w * g)
                    .sum();
                means[k].0 += half * sum;
                means[k].1 += hi - lo;
            }
            let mut terms = Vec::with_capacity(per_piece);
            for (p, &(k, lo, hi)) in pieces.iter().enumerate() {
                let (mass, length) = means[k];
                let mean = mass / length;
                let mean_error = (farthest + 8.0 * f64::EPSILON) * mean;
                terms.clear();
                terms.extend(
                    scaled[nodes(p)]
                        .iter()
                        .zip(&values[nodes(p)])
                        .map(|(&t, &g)| {
                            let e = exp_rounding(t, s) * g + mean_error;
                            ((g - mean).powi(2), 2.0 * (g - mean).abs() * e + e * e)
                        }),
                );
                let piece = rules.estimate(lo, hi, &terms, per_piece as u64);
                out[k].0 += piece.value;
                out[k].1 += piece.error + 16.0 * f64::EPSILON * piece.value;
            }
            for (o, &(_, length)) in out.iter_mut().zip(&means) {
                o.1 += 9.0 * f64::EPSILON / length * o.0;
            }
        });
    let (mut value, mut error) = (
        crate::quadrature::CompensatedSum::default(),
        crate::quadrature::CompensatedSum::default(),
    );
    for (v, e) in cells {
        value.add(v);
        error.add(e);
    }
    let value = value.value();
    (value, error.value() + 4.0 * f64::EPSILON * value)
}

/// Cells per axis beyond which an axis's sums come from their expansion in the cell width
/// ([`expanded_axis_sums`]) where its remainder allows: visiting them would take a tenth of a
/// second an axis.
const EXPANDED_CELLS: usize = 1 << 24;
/// The expansion's remainder and rounding, relative to the sum, it may leave at most.
const EXPANSION_TOLERANCE: f64 = 1e-12;

/// `max_u |d^k/du^k e^{−u²}|` for `k = 1, 2, 3`, by Cramér's inequality `|H_k(u)| e^{−u²/2} ≤
/// 1.0865 √(2^k k!)`: 1.537, 3.073 and 7.527 (the maxima are 0.858, 2 and 2.9).
const DERIVATIVE_BOUNDS: [f64; 3] = [1.537, 3.073, 7.527];

/// One axis's sums over its `m` cells of width `h = 1/m` for `g(x) = exp(−((x − c)/s)²)`,
/// unshifted, from their expansion in `h`, where `m` exceeds [`EXPANDED_CELLS`] and the bounds
/// below stay within [`EXPANSION_TOLERANCE`]; as the entries of [`Gaussian::cell_sums`]'s
/// axes: `[Σ_c μ_c², its relative error, Σ_c w_c, its relative error]`.
///
/// On a cell of centre `x` and `t` uniform on `[−h/2, h/2]`, `g(x + t) = g(x) + g'(x) t +
/// g''(x) t²/2 + R₃` with `|R₃| ≤ M₃ |t|³/6` (`M_k` the bounds on `|g^(k)|`). The linear term
/// has variance `g'(x)² h²/12`; its covariance with the even `t²` term vanishes, with `R₃` it
/// is at most `M₁ M₃ E[t⁴]/6 = M₁ M₃ h⁴/480`, and the rest's variance is at most
/// `M₂² E[t⁴]/4 = M₂² h⁴/320`. The midpoint rule gives `h Σ_c g'(x_c)² = J ± (h²/24)
/// max |(g'²)''|`, with `J = ∫_0^1 g'²` and `(g'²)'' = 2g''² + 2g'g'''`. So
/// `Σ_c ∫_c (g − ḡ_c)² = (h²/12) J ± h⁴ [(2M₂² + 2M₁M₃)/288 + M₁M₃/240 + M₂²/320]`, and
/// `Σ_c μ_c² = m ∫_0^1 g² − Σ_c w_c`. By parts, `J = (G − (1 − c) e^{−2(1−c)²/s²} −
/// c e^{−2c²/s²}) / s²` with `G = ∫_0^1 e^{−2(x−c)²/s²}`, each term within a few ε of itself;
/// where `J` cancels to a small share of its terms the bound says so, and the cells are
/// visited instead.
fn expanded_axis_sums(m: usize, c: f64, s: f64) -> Option<[f64; 4]> {
    if m <= EXPANDED_CELLS {
        return None;
    }
    let sums = axis_expansion(m, c, s);
    (sums[2] > 0.0 && sums[3] <= EXPANSION_TOLERANCE).then_some(sums)
}

/// [`expanded_axis_sums`] at any `m`, its remainder bound however wide.
fn axis_expansion(m: usize, c: f64, s: f64) -> [f64; 4] {
    let h = 1.0 / m as f64;
    let [m1, m2, m3] = [
        DERIVATIVE_BOUNDS[0] / s,
        DERIVATIVE_BOUNDS[1] / (s * s),
        DERIVATIVE_BOUNDS[2] / (s * s * s),
    ];
    let squared = gaussian_segment(0.0, 1.0, c, s / SQRT_2);
    let (upper, lower) = (
        (1.0 - c) * (-2.0 * (1.0 - c) * (1.0 - c) / (s * s)).exp(),
        c * (-2.0 * c * c / (s * s)).exp(),
    );
    let j = (squared - upper - lower) / (s * s);
    // `G` within 4ε, each exponential's term within 3ε, the two differences and the division
    // by `s²` within 3ε more, and the products below within 6ε: 16ε of the terms' size.
    let j_rounding = 16.0 * f64::EPSILON * (squared + upper.abs() + lower.abs()) / (s * s);
    let within = h * h / 12.0 * j;
    let remainder =
        h.powi(4) * ((2.0 * m2 * m2 + 2.0 * m1 * m3) / 288.0 + m1 * m3 / 240.0 + m2 * m2 / 320.0);
    let within_error = (remainder + h * h / 12.0 * j_rounding) / within.abs();
    let cells = m as f64;
    let variances = within * cells;
    let squares = cells * squared - variances;
    [
        squares,
        8.0 * f64::EPSILON + variances.abs() * within_error / squares,
        variances,
        within_error + f64::EPSILON,
    ]
}

/// Cells shorter than this, in units of the width `s`, take [`short_variances_within_cells`].
const SHORT_VARIANCE: f64 = 1.0 / 64.0;

/// A bound on the error of the [`SHORT_SEGMENT_NODES`]-point Gauss–Legendre rule for
/// `∫ (e^{−t²} − ḡ)² dt` over a segment of length `w`, over `w^13`: the rule errs by
/// `w^13 (6!)^4 / (13 (12!)^3) |f^(12)|` = `1.881e-16 w^13 |f^(12)|`, and with Cramér's
/// `|H_k(x)| e^{−x²/2} ≤ 1.0865 √(2^k k!)`, `|f^(12)| ≤ (2^6 + 2ḡ) 1.522e6 ≤ 1.006e8` for
/// `ḡ ≤ 1`.
const SHORT_VARIANCE_QUADRATURE: f64 = 1.9e-8;

/// [`variance_within_cells`] unshifted on cells shorter than [`SHORT_VARIANCE`] widths: each
/// cell's [`SHORT_SEGMENT_NODES`] values, at the nodes of its mass in [`short_segments`] (whose
/// rule the mean `ḡ` is, so that `Σ w (g − ḡ)` vanishes to rounding), their exponentials a chunk
/// of cells at a time. Its rule's error is [`SHORT_VARIANCE_QUADRATURE`]'s, at most `10^-18`
/// of the cell's `∫g²` there; each node's `(g − ḡ)²` is within `2|g − ḡ| e + e²`, `e` the
/// largest node's rounding at the cell's far end and the mean's, and the cell's ends, each
/// within `δt` in units of `s` ([`end_rounding`]), move its variance, of order `w³`, by
/// `6 δt / w` of itself.
fn short_variances_within_cells(m: usize, c: f64, s: f64) -> ShortCells {
    let (_, weights) = short_rule();
    let farthest = c.max(1.0 - c) / s;
    let mean_rounding = exp_rounding(farthest, s) + 8.0 * f64::EPSILON;
    // A cell end's argument `(x − c)/s` is within [`end_rounding`] over `s`.
    let end_argument = end_rounding(c, m, 0.0) / s;
    let chunks: Vec<[f64; 3]> = (0..m.div_ceil(SEGMENT_CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let cells = chunk * SEGMENT_CHUNK..(m.min((chunk + 1) * SEGMENT_CHUNK));
            let (ends, values) = short_cells(cells, m, c, s);
            let [mut value, mut error, mut squares] =
                [crate::quadrature::CompensatedSum::default(); 3];
            for (&(u, v), row) in ends.iter().zip(values.chunks_exact(SHORT_SEGMENT_NODES)) {
                let (half, width) = ((v - u) / 2.0, v - u);
                // The cell's mass as `short_segments` has it, the same bits.
                let integral = short_sum(u, v, row);
                squares.add((s * integral * m as f64).powi(2));
                let mean = integral / width;
                let (mut sum, mut spread, mut largest) = (0.0, 0.0, 0.0f64);
                for (w, &g) in weights.iter().zip(row) {
                    let d = g - mean;
                    sum += w * d * d;
                    spread += w * d.abs();
                    largest = largest.max(g);
                }
                // Every node's value within `e`, its rounding at the cell's end farther from
                // `c` ([`exp_rounding`] grows with |t|), and the weights summing to 2.
                let e = exp_rounding(u.abs().max(v.abs()), s) * largest + mean_rounding * mean;
                let bound = 2.0 * spread * e + 2.0 * e * e;
                let cell = s * half * sum;
                value.add(cell);
                error.add(
                    s * half * bound
                        + s * SHORT_VARIANCE_QUADRATURE * width.powi(13)
                        + (16.0 * f64::EPSILON + 6.0 * end_argument / width) * cell,
                );
            }
            [value.value(), error.value(), squares.value()]
        })
        .collect();
    let [mut value, mut error, mut squares] = [crate::quadrature::CompensatedSum::default(); 3];
    for [v, e, q] in chunks {
        value.add(v);
        error.add(e);
        squares.add(q);
    }
    let within = value.value();
    ShortCells {
        within,
        within_error: error.value() + 4.0 * f64::EPSILON * within,
        mean_square: squares.value(),
    }
}

/// One axis's sums over its cells from [`short_variances_within_cells`].
struct ShortCells {
    /// `Σ_c ∫_c (g − ḡ_c)²`.
    within: f64,
    /// A bound on the error of `within`.
    within_error: f64,
    /// `Σ_c ḡ_c²`.
    mean_square: f64,
}

/// The torus autocorrelation of the truncated 1D Gaussian `g(x) = exp(-(x - m)²/(2s²))` on
/// `[0, 1)`: `∫_0^1 g(x) g((x + r) mod 1) dx`, for `r` in `[0, 1)`. The product of two
/// Gaussians is a Gaussian, so each of the two pieces (before and after the wrap) is an `erf`
/// difference.
pub(crate) fn axis_autocorrelation(r: f64, m: f64, s: f64) -> f64 {
    let r = r - r.floor();
    // g(x) g(x + t) = exp(-t²/(4s²)) exp(-(x - m + t/2)²/s²).
    let piece = |t: f64, a: f64, b: f64| {
        (-t * t / (4.0 * s * s)).exp() * gaussian_segment(a, b, m - t / 2.0, s)
    };
    piece(r, 0.0, 1.0 - r) + piece(r - 1.0, 1.0 - r, 1.0)
}

impl Gaussian {
    /// `∫_0^1 exp(-(x - c)² / (2 s²)) dx`.
    fn axis_integral(c: f64, s: f64) -> f64 {
        let k = s * SQRT_2;
        s * (PI / 2.0).sqrt() * (libm::erf((1.0 - c) / k) + libm::erf(c / k))
    }

    /// `∫` of the axis factor of width `width` over each cell of each axis of `grid`: the rows
    /// [`Integrand::box_moments`] multiplies, the same bounds, widths and order (short cells'
    /// exponentials taken a chunk at a time, the same bits).
    fn cell_rows(&self, grid: &[usize], width: f64) -> Vec<Vec<f64>> {
        let mut rows: Vec<Vec<f64>> = Vec::with_capacity(grid.len());
        for (l, (&m, &c)) in grid.iter().zip(&self.centre).enumerate() {
            // An axis with an earlier one's cells and centre has its row.
            if let Some(same) = (0..l).find(|&e| grid[e] == m && self.centre[e] == c) {
                rows.push(rows[same].clone());
                continue;
            }
            rows.push(axis_row(m, c, width));
        }
        rows
    }

    /// Per axis, the integral over each cell of `grid` of the axis factor of width `width`
    /// shifted by `t` on the torus: a cell's pieces on either side of a face summed (an empty
    /// piece has no mass, so adding it changes no bit).
    fn shifted_rows(&self, grid: &[usize], t: &[f64], width: f64) -> Vec<Vec<f64>> {
        grid.iter()
            .zip(t)
            .zip(&self.centre)
            .map(|((&m, &shift), &c)| {
                (0..m)
                    .into_par_iter()
                    .map(|i| {
                        super::over_wrapped_cell(i, m, shift, |a, b| axis_mass(a, b, c, width))
                    })
                    .collect()
            })
            .collect()
    }
}

/// [`axis_mass`] of width `width` over each of `m` cells of the unit interval (short cells'
/// exponentials taken a chunk at a time, the same bits).
fn axis_row(m: usize, c: f64, width: f64) -> Vec<f64> {
    let s = width * SQRT_2;
    if m > 0 && 1.0 / (m as f64 * s) < SHORT_SEGMENT {
        short_segments(m, c, s)
    } else {
        (0..m)
            .into_par_iter()
            .map(|i| axis_mass(i as f64 / m as f64, (i + 1) as f64 / m as f64, c, width))
            .collect()
    }
}

/// `∫_a^b exp(-(x - c)² / (2 s²)) dx`: [`gaussian_segment`] of width `s √2`.
pub(crate) fn axis_mass(a: f64, b: f64, c: f64, s: f64) -> f64 {
    gaussian_segment(a, b, c, s * SQRT_2)
}

impl Integrand for Gaussian {
    fn box_moments(&self, lo: &[f64], hi: &[f64]) -> Option<(f64, f64)> {
        // Separable: f = a Π_i g(x_i) with g of width σ, and f² = a² Π_i g(x_i)² with g² of
        // width σ/√2.
        let (s, a) = (self.sigma, self.height);
        let mut mass = a;
        let mut square = a * a;
        for ((&l, &h), &c) in lo.iter().zip(hi).zip(&self.centre) {
            mass *= axis_mass(l, h, c, s);
            square *= axis_mass(l, h, c, s / SQRT_2);
        }
        Some((mass, square))
    }
    fn separable_cells(&self, grid: &[usize]) -> Option<super::SeparableCells> {
        if grid.len() != self.centre.len() {
            return None;
        }
        Some(super::SeparableCells {
            height: self.height,
            mass: self.cell_rows(grid, self.sigma),
            square: self.cell_rows(grid, self.sigma / SQRT_2),
        })
    }
    fn cell_sums(&self, grid: &[usize]) -> Option<super::CellSums> {
        // F_c = a Π_l μ_l(i_l) and V_c = a² (Π_l (μ_l² + w_l) − Π_l μ_l²), with μ_l and w_l
        // the axis factor's mean and variance on each of its cells. Expanded, V_c is a sum of
        // products of non-negative terms, one per non-empty set of axes taking w, and each sum
        // over cells a product of per-axis sums. The difference of the two products, summed,
        // would keep only w/μ² of its digits: none on cells of 10^-6, where w/μ² ~ 10^-12.
        if grid.len() != self.centre.len() || grid.contains(&0) {
            return None;
        }
        let width = self.sigma * SQRT_2;
        // Per axis: Σ_i μ_i², Σ_i w_i and a bound on each one's relative error.
        let mut axes: Vec<[f64; 4]> = Vec::with_capacity(grid.len());
        for (l, (&m, &c)) in grid.iter().zip(&self.centre).enumerate() {
            if let Some(same) = (0..l).find(|&e| grid[e] == m && self.centre[e] == c) {
                axes.push(axes[same]);
                continue;
            }
            let cells = m as f64;
            if let Some(expanded) = expanded_axis_sums(m, c, width) {
                axes.push(expanded);
                continue;
            }
            let mass_rounding = segment_rounding(c, width, 1.0 / cells);
            let (squares, within, within_error) = if 1.0 / (cells * width) < SHORT_VARIANCE {
                // The masses and the variances from the same values.
                let short = short_variances_within_cells(m, c, width);
                (short.mean_square, short.within, short.within_error)
            } else {
                let mut squares = crate::quadrature::CompensatedSum::default();
                for mass in axis_row(m, c, self.sigma) {
                    squares.add((mass * cells).powi(2));
                }
                let (within, within_error) = variance_within_cells(m, 0.0, c, width);
                (squares.value(), within, within_error)
            };
            // The ends move each mean by `±m e` across them: `Σ 2μ δμ` is `2m e` times the
            // means' total variation with the faces, at most `4 max μ ≤ 4` for one peak.
            let ends = 8.0 * cells * end_rounding(c, m, 0.0);
            axes.push([
                squares,
                2.0 * mass_rounding + 3.0 * f64::EPSILON + ends / squares,
                within * cells,
                within_error / within.max(f64::MIN_POSITIVE) + f64::EPSILON,
            ]);
        }
        // `none`: the product of the mean squares; `some`: the sum of the products with at
        // least one axis's variance.
        let (mut none, mut some, mut relative) = (1.0, 0.0, 0.0);
        for &[square, square_error, within, within_error] in &axes {
            some = some * (square + within) + none * within;
            none *= square;
            relative += square_error.max(within_error) + 4.0 * f64::EPSILON;
        }
        let h2 = self.height * self.height;
        Some(super::CellSums {
            mean_square: h2 * none,
            within: h2 * some,
            within_error: 0.0,
            within_rounding: Some(h2 * some * (relative + 2.0 * f64::EPSILON)),
            visited: self.cell_sums_visits(grid) as u64,
        })
    }
    fn cell_sums_visits(&self, grid: &[usize]) -> f64 {
        let width = self.sigma * SQRT_2;
        grid.iter()
            .zip(&self.centre)
            .map(|(&m, &c)| {
                if expanded_axis_sums(m, c, width).is_some() {
                    1.0
                } else {
                    m as f64
                }
            })
            .sum()
    }
    fn separable_details(&self, grid: &[usize], t: &[f64]) -> Option<super::SeparableDetails> {
        if grid.len() != self.centre.len() || t.len() != grid.len() || grid.contains(&0) {
            return None;
        }
        let rows = self.shifted_rows(grid, t, self.sigma);
        let axes = rows
            .into_iter()
            .zip(grid.iter().zip(t).zip(&self.centre))
            .map(|(mass, ((&m, &shift), &c))| {
                let width = self.sigma * SQRT_2;
                let mass_rounding = segment_rounding(c, width, 1.0 / m as f64);
                let (within, within_error) = variance_within_cells(m, shift, c, width);
                super::AxisDetails {
                    mass,
                    mass_rounding,
                    end_rounding: end_rounding(c, m, shift),
                    within,
                    within_error,
                }
            })
            .collect();
        Some(super::SeparableDetails {
            height: self.height,
            axes,
        })
    }
    fn shifted_separable_cells(&self, grid: &[usize], t: &[f64]) -> Option<super::SeparableCells> {
        if grid.len() != self.centre.len() || t.len() != grid.len() {
            return None;
        }
        Some(super::SeparableCells {
            height: self.height,
            mass: self.shifted_rows(grid, t, self.sigma),
            square: self.shifted_rows(grid, t, self.sigma / SQRT_2),
        })
    }
    fn grid_masses(&self, grid: &[usize], t: &[f64]) -> Option<super::GridMasses> {
        // Separable: the mass of a cell is the height times its axes' masses, and a shifted
        // cell wraps axis by axis.
        let rows = self.shifted_rows(grid, t, self.sigma);
        let mut masses = vec![self.height];
        for row in &rows {
            masses = row
                .iter()
                .flat_map(|&r| masses.iter().map(move |&m| m * r))
                .collect();
        }
        Some(super::GridMasses {
            masses,
            constant: None,
        })
    }
    fn product_form(&self) -> Option<super::ProductForm> {
        Some(super::ProductForm {
            height: self.height,
            axes: self
                .centre
                .iter()
                .map(|&centre| super::AxisFactor::Gaussian {
                    centre,
                    sigma: self.sigma,
                })
                .collect(),
        })
    }
    fn kind(&self) -> IntegrandKind {
        IntegrandKind::Gaussian
    }
    fn is_isotropic(&self) -> bool {
        true
    }
    fn label(&self) -> String {
        format!(
            "gaussian(sigma={}, c={:?}, a={}, d={})",
            self.sigma,
            self.centre,
            self.height,
            self.centre.len()
        )
    }
    fn dimension(&self) -> usize {
        self.centre.len()
    }
    fn eval(&self, x: &[f64]) -> f64 {
        let r2 = squared_distance(x, &self.centre);
        self.height * exp_nonpositive(-r2 / (2.0 * self.sigma * self.sigma))
    }
    fn sum_at(&self, coords: &[f64]) -> f64 {
        // Blocks of exponents, then their exponentials in one vectorized pass: the values
        // `eval` gives, summed in order.
        const BLOCK: usize = 128;
        let d = self.centre.len();
        let two_s2 = 2.0 * self.sigma * self.sigma;
        let mut exponents = [0.0; BLOCK];
        let mut total = 0.0;
        for block in coords.chunks(BLOCK * d) {
            let m = block.len() / d;
            let points = block.chunks_exact(d);
            if let [c0, c1] = self.centre[..] {
                for (e, x) in exponents.iter_mut().zip(points) {
                    *e = -((x[0] - c0) * (x[0] - c0) + (x[1] - c1) * (x[1] - c1)) / two_s2;
                }
            } else {
                for (e, x) in exponents.iter_mut().zip(points) {
                    *e = -squared_distance(x, &self.centre) / two_s2;
                }
            }
            exp_in_place(&mut exponents[..m]);
            for e in &exponents[..m] {
                total += self.height * e;
            }
        }
        total
    }
    fn integral(&self) -> f64 {
        let s = self.sigma;
        self.height
            * self
                .centre
                .iter()
                .map(|&c| Self::axis_integral(c, s))
                .product::<f64>()
    }
    fn integral_of_square(&self) -> f64 {
        // f² is a Gaussian of width σ/√2 and height a².
        let s = self.sigma / SQRT_2;
        self.height.powi(2)
            * self
                .centre
                .iter()
                .map(|&c| Self::axis_integral(c, s))
                .product::<f64>()
    }
    fn coefficient(&self, k: &[i64]) -> Complex64 {
        k.iter()
            .zip(&self.centre)
            .map(|(&k, &m)| axis_coefficient(k, m, self.sigma))
            .product::<Complex64>()
            * self.height
    }
    fn square_coefficient(&self, k: &[i64]) -> Option<Complex64> {
        // f² = a² exp(-|x - c|²/σ²): the same cube's Gaussian of width σ/√2 and height a².
        let square = Gaussian::new(
            self.sigma * std::f64::consts::FRAC_1_SQRT_2,
            self.centre.clone(),
            self.height * self.height,
        )
        .ok()?;
        Some(square.coefficient(k))
    }
    fn separable_coefficients(&self, kmax: &[usize]) -> Option<super::SeparableCoefficients> {
        (kmax.len() == self.centre.len()).then(|| super::SeparableCoefficients {
            height: self.height,
            axes: kmax
                .iter()
                .enumerate()
                .map(|(a, &k)| self.axis_coefficients(a, k))
                .collect(),
        })
    }
    fn power_on_lattice(&self, lattice: crate::spectrum::Lattice, out: &mut [f64]) {
        // Separable: |c(k)|² = a² Π_i |c_i(k_i)|², from one table per axis.
        let tables: Vec<Vec<f64>> = (0..lattice.dimension)
            .map(|a| {
                self.axis_coefficients(a, lattice.kmax)
                    .iter()
                    .map(|c| c.norm_sqr())
                    .collect()
            })
            .collect();
        let (side, h2) = (lattice.side(), self.height * self.height);
        for (i, slot) in out.iter_mut().enumerate() {
            let mut rest = i;
            let mut p = h2;
            for table in tables.iter().rev() {
                p *= table[rest % side];
                rest /= side;
            }
            *slot = p;
        }
    }
    fn projection_energy(&self, axis: usize) -> f64 {
        let s2 = self.sigma / SQRT_2;
        let others: f64 = (0..self.centre.len())
            .filter(|&b| b != axis)
            .map(|b| Self::axis_integral(self.centre[b], self.sigma).powi(2))
            .product();
        self.height.powi(2) * Self::axis_integral(self.centre[axis], s2) * others
    }
    fn autocorrelation(&self, r: &[f64]) -> Option<f64> {
        Some(
            self.height.powi(2)
                * r.iter()
                    .zip(&self.centre)
                    .map(|(&r, &m)| axis_autocorrelation(r, m, self.sigma))
                    .product::<f64>(),
        )
    }
    fn fourier(&self, omega: &[f64]) -> Complex64 {
        let rho2: f64 = omega.iter().map(|w| w * w).sum();
        let d = self.centre.len() as i32;
        let amplitude = self.height
            * (2.0 * PI * self.sigma * self.sigma).powf(d as f64 / 2.0)
            * (-2.0 * PI * PI * self.sigma * self.sigma * rho2).exp();
        shift_phase(omega, &self.centre) * amplitude
    }
    fn spectral_integral(&self) -> f64 {
        let d = self.centre.len() as f64;
        self.height * (2.0 * PI * self.sigma * self.sigma).powf(d / 2.0)
    }
    fn spectral_energy(&self) -> f64 {
        let d = self.centre.len() as f64;
        self.height.powi(2) * (PI * self.sigma * self.sigma).powf(d / 2.0)
    }
    fn full_space_leak(&self) -> f64 {
        // The energy the full-space transform counts and the cube does not hold.
        let full = self.spectral_energy();
        ((full - self.integral_of_square()) / full).abs()
    }
    fn autocorrelation_beyond(&self, distance: f64) -> Option<f64> {
        // a(r) = a² (πσ²)^{d/2} exp(-|r|²/(4σ²)), and |r| is at least its largest component.
        let d = self.centre.len() as f64;
        let s2 = self.sigma * self.sigma;
        Some(
            self.height.powi(2)
                * (PI * s2).powf(d / 2.0)
                * (-distance.max(0.0).powi(2) / (4.0 * s2)).exp(),
        )
    }
    fn radial_power(&self, rho: f64) -> f64 {
        let d = self.centre.len() as f64;
        let s2 = self.sigma * self.sigma;
        self.height.powi(2) * (2.0 * PI * s2).powf(d) * (-4.0 * PI * PI * s2 * rho * rho).exp()
    }
    fn decay_exponent(&self) -> f64 {
        f64::INFINITY
    }
    fn panel_width(&self) -> f64 {
        // The power falls by e over Δρ ≈ 1/(2πσ); panels a quarter of 1/σ wide.
        1.0 / (4.0 * self.sigma)
    }
    fn negligible_beyond(&self) -> f64 {
        // exp(-4π²σ²ρ²) < 1e-30 once 4π²σ²ρ² > 69.1.
        69.1f64.sqrt() / (2.0 * PI * self.sigma)
    }
    fn smooth_decay(&self) -> Option<super::SmoothDecay> {
        Some(super::SmoothDecay {
            peak: self.spectral_integral().powi(2),
            rate: 4.0 * PI * PI * self.sigma * self.sigma,
            images: self.height.abs() * super::gaussian_images(&self.centre, self.sigma),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis's sums from their expansion in the cell width against the cells visited one by
    /// one (the six-node rule), within both bounds, at `2^14 … 2^20` cells where the expansion's
    /// remainder is still wide enough to be tested and the cells are few enough to visit; off
    /// centre, narrow and wide. The expansion's `h²` law is then what it extrapolates.
    #[test]
    fn the_expansion_in_the_cell_width_meets_the_cells() {
        for (c, s) in [
            (0.5, 0.2 * SQRT_2),
            (0.3, 0.1 * SQRT_2),
            (0.7, 0.05 * SQRT_2),
        ] {
            for m in [1usize << 14, 1 << 17, 1 << 20] {
                let [squares, square_error, variances, variance_error] = axis_expansion(m, c, s);
                let cells = short_variances_within_cells(m, c, s);
                let visited = cells.within * m as f64;
                let allowed = variance_error * variances.abs() + cells.within_error * m as f64;
                assert!(
                    (variances - visited).abs() <= allowed,
                    "c = {c}, s = {s}, m = {m}: {variances:e} against {visited:e} (allowed {allowed:e})"
                );
                // The visited squares' bound, as `cell_sums` takes it.
                let ends = 8.0 * m as f64 * end_rounding(c, m, 0.0);
                let visited_error = (2.0 * segment_rounding(c, s, 1.0 / m as f64)
                    + 3.0 * f64::EPSILON)
                    * cells.mean_square
                    + ends;
                let allowed = square_error * squares + visited_error;
                assert!(
                    (squares - cells.mean_square).abs() <= allowed,
                    "c = {c}, s = {s}, m = {m}: Σμ² {squares:e} against {:e}",
                    cells.mean_square
                );
            }
        }
    }

    /// The short cells' variances (their masses' own six nodes) against the embedded rules'
    /// (fifteen other nodes, the mean the ten-point rule's own): within the two bounds, from
    /// cells of 2^-10 to 10^-6, narrow and wide, centred and near a face; and the short
    /// path's mean squares are its masses', the same bits.
    #[test]
    fn short_cells_variances_agree_with_the_embedded_rules() {
        for (sigma, c) in [(0.2, 0.5), (0.2, 0.03), (0.01, 0.7), (1.5, 0.9)] {
            let s = sigma * SQRT_2;
            for m in [1usize << 10, 1 << 16, 1_000_000] {
                if 1.0 / (m as f64 * s) >= SHORT_VARIANCE {
                    continue;
                }
                let short = short_variances_within_cells(m, c, s);
                let (value, error) = embedded_variances_within_cells(m, 0.0, c, s);
                let gap = (short.within - value).abs();
                assert!(
                    gap <= short.within_error + error,
                    "σ = {sigma}, c = {c}, m = {m}: {:e} against {value:e} (bounds {:e}, {error:e})",
                    short.within,
                    short.within_error
                );
                // Informative: within 1e-6 of the value at 10^-6.
                assert!(short.within_error <= 1e-6 * short.within, "{sigma} {c} {m}");
                let mut squares = crate::quadrature::CompensatedSum::default();
                for mass in short_segments(m, c, s) {
                    squares.add((mass * m as f64).powi(2));
                }
                let squares = squares.value();
                assert!(
                    (short.mean_square - squares).abs() <= 4.0 * f64::EPSILON * squares,
                    "σ = {sigma}, c = {c}, m = {m}: {:e} against {squares:e}",
                    short.mean_square
                );
            }
        }
    }

    /// Segments on both sides of the switch to Gauss–Legendre agree with the error functions
    /// (their complements away from 0) where those are accurate (width near 1/4), and a tiny segment matches its midpoint series
    /// `e^{-m²} w (1 + (2m² − 1) w²/12)` (next term `O(w⁵)`) to rounding.
    #[test]
    fn short_segments_keep_their_digits() {
        for &(u, w) in &[(-0.1f64, 0.249), (0.7, 0.249), (-2.0, 0.249), (1.3, 0.251)] {
            let v = u + w;
            let difference = if u >= 0.0 {
                libm::erfc(u) - libm::erfc(v)
            } else if v <= 0.0 {
                libm::erfc(-v) - libm::erfc(-u)
            } else {
                libm::erf(v) - libm::erf(u)
            };
            let erf = PI.sqrt() / 2.0 * difference;
            let got = gaussian_segment(u, u + w, 0.0, 1.0);
            assert!(
                (got - erf).abs() <= 4.0 * f64::EPSILON * erf,
                "{u} {w} {got} {erf}"
            );
        }
        for &(m, k) in &[(0.3f64, 20), (-1.7, 22), (2.5, 30)] {
            // Ends exact in binary: the segment is the one the series is for.
            let w = 2f64.powi(-k);
            let m = (m / w).round() * w + w / 2.0;
            let series = (-m * m).exp() * w * (1.0 + (2.0 * m * m - 1.0) * w * w / 12.0);
            let got = gaussian_segment(m - w / 2.0, m + w / 2.0, 0.0, 1.0);
            assert!(
                (got - series).abs() <= 8.0 * f64::EPSILON * series,
                "{m} {w}"
            );
        }
    }

    /// The truncated 1D coefficient for centres inside, on and beyond the faces, against a
    /// 400-panel Gauss–Legendre sum of the integrand.
    #[test]
    fn axis_coefficient_holds_for_any_centre() {
        let rule = crate::quadrature::GaussLegendre::new(20);
        for &(m, s) in &[
            (0.3, 0.05),
            (1.0, 0.1),
            (1.5, 0.3),
            (-0.7, 0.3),
            (2.5, 0.4),
            (-0.1, 0.02),
        ] {
            for k in [0i64, 3, -11] {
                let part = |f: &dyn Fn(f64) -> f64| -> f64 {
                    (0..400)
                        .map(|p| rule.integrate(p as f64 / 400.0, (p + 1) as f64 / 400.0, f))
                        .sum()
                };
                let g = |x: f64| (-(x - m) * (x - m) / (2.0 * s * s)).exp();
                let w = 2.0 * PI * k as f64;
                let re = part(&|x| g(x) * (w * x).cos());
                let im = part(&|x| -g(x) * (w * x).sin());
                let c = axis_coefficient(k, m, s);
                let scale = part(&g).max(1e-300);
                assert!(
                    (c.re - re).abs() <= 1e-12 * scale && (c.im - im).abs() <= 1e-12 * scale,
                    "m = {m}, s = {s}, k = {k}: {c} against {re} + {im}i"
                );
            }
        }
    }

    /// Whole rows of short cells, their exponentials a chunk at a time, are the cells one by
    /// one to the bit: rows and box moments must agree, since sums over cells mix the two.
    #[test]
    fn short_rows_are_their_cells_to_the_bit() {
        for (m, c, s) in [
            (4096, 0.3, 0.1 * SQRT_2),
            (10_000, 0.5, 0.2),
            (5000, 0.97, 0.05),
        ] {
            let row = short_segments(m, c, s);
            for (i, &value) in row.iter().enumerate() {
                let (a, b) = (i as f64 / m as f64, (i + 1) as f64 / m as f64);
                assert_eq!(
                    value.to_bits(),
                    gaussian_segment(a, b, c, s).to_bits(),
                    "cell {i} of {m}"
                );
            }
        }
    }
}
