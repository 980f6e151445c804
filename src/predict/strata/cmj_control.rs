//! Correlated multi-jitter beyond the table of its `N × N` cells: the occupancy estimate of
//! [`super::cells`] with a control variate whose variance is known exactly.
//!
//! CMJ's `N = m r` points fill `m` columns and `r` rows of blocks; the point of block `(i, j)`
//! lies in the fine cell `(i r + σ(j), j m + τ(i))` of the `N × N` grid, `σ` and `τ` uniform
//! permutations of `r` and `m` positions. The occupied cells' mean is `M = (1/N) Σ_ij
//! F_ij(σ(j), τ(i))`, with `F_ij(a, b)` the mean of `f` over the fine cell at position `(a, b)`
//! of block `(i, j)`; the estimate averages `(M − I)²` (and the occupied cells' inner variance)
//! over patterns, and its noise is that of a squared deviation: about `√(2/R)` of the value
//! after `R` patterns. A pattern is read from its two permutations alone, at the blocks where
//! the integrand varies: a block where it is constant (a shape's blocks wholly inside or
//! outside it) holds one point whose cell mean is the block's, a fixed share of `M − I`, so a
//! disk at `N = 262144` costs about a thousand cells a pattern instead of `N`.
//!
//! Each block's cell means are close to a bilinear function of the position,
//! `α u(a) + β w(b) + γ u(a) w(b)` with `u(a) = (a + ½)/r − ½` and `w(b) = (b + ½)/m − ½`,
//! whose coefficients come from the integrand's masses on the block's four quadrants. The
//! same permutations give this surrogate's deviation `L = (1/N) Σ_ij [α_ij u(σ(j)) + β_ij
//! w(τ(i)) + γ_ij u(σ(j)) w(τ(i))]`, whose second moment is exact in `O(N)` (below). Each
//! pattern's term is `(M − I)² − b (L² − E L²)`: unbiased for any fixed `b`, and of far lower
//! spread when `M − I` follows `L`, as it does for an integrand smooth on the blocks' scale,
//! where the interaction `γ` carries most of the variance (the pure terms `Σ_i α_ij` are
//! Riemann sums of a derivative and nearly cancel). The coefficient is fixed at `b = 1`, the
//! regression coefficient where the surrogate is exact: on a rotated or cut anisotropic
//! Gaussian the terms' spread falls 5–250× (at N = 4096 and 65536), and where it follows `M`
//! less (a disk, a polygon crossing the blocks, whose cells jump) the spread stays within 3%
//! of the plain estimate's. Either way the noise is the terms' own spread.
//!
//! `E L²`: with `s_u = (r² − 1)/(12 r²)` the mean of `u²` over positions, a uniform
//! permutation gives `E[u(σ(j)) u(σ(j'))] = s_u (r/(r−1)) (δ_jj' − 1/r)`, and likewise for
//! `τ`; the three parts are uncorrelated (each cross moment holds one centred factor alone), so
//! `N² E L² = s_u (r/(r−1)) Σ_j (A_j − Ā)² + s_w (m/(m−1)) Σ_i (B_i − B̄)² + s_u s_w
//! (r/(r−1)) (m/(m−1)) Σ_ij γ̃_ij²`, with `A_j = Σ_i α_ij`, `B_i = Σ_j β_ij` and `γ̃` the
//! doubly centred `γ`.

use super::cell_moments::{
    is_marked, masses_and_constant_cells, CellMoments, CellSum, CELL_ROUNDING,
};
use crate::budget::Needs;
use crate::costs::CELL_SECONDS;
use crate::error::Result;
use crate::integrand::Integrand;
use crate::predict::term_mean::{mean_of_exact_terms, terms_within_budget, OccupancyEstimate};
use crate::progress::{stage, Progress};
use crate::quadrature::CompensatedSum;
use crate::sampler::{near_square_factors, CmjShuffles};

/// Patterns the estimate starts with: a few more than a 99% interval rests on
/// ([`crate::predict::term_mean::MIN_TERMS`]); where the control variate leaves little spread (a smooth
/// integrand) they are already enough, and where it does not, their spread says how many more.
const INITIAL_PATTERNS: usize = 24;
/// Patterns it never exceeds.
const MAX_PATTERNS: usize = 1 << 18;

/// The unshifted variance of CMJ's estimator at `n` points (beyond the table of its cells),
/// estimated from the permutations of realizations `0, 1, …` of `params.seed` with the blocks'
/// bilinear surrogate as a control variate (module notes), within the work budget, and to the
/// relative noise `params.target_noise`.
///
/// # Errors
/// A work budget that cannot afford the quadrants' masses or the first patterns.
pub(crate) fn controlled_cmj_variance(
    f: &dyn Integrand,
    n: usize,
    params: &crate::predict::PredictParams,
    progress: &dyn Progress,
) -> Result<OccupancyEstimate> {
    let per_cell = CELL_SECONDS;
    params.budget.check(
        "the blocks' bilinear surrogate",
        Needs {
            memory_bytes: 8.0 * 4.0 * n as f64 + 40.0 * n as f64,
            work_seconds: 4.0 * n as f64 * per_cell,
        },
        "lower N",
    )?;
    let surrogate = stage(progress, "the blocks' bilinear surrogate", 0, || {
        BlockSurrogate::new(f, n)
    });
    let (m, r) = (surrogate.m, surrogate.r);
    let per_pattern =
        (m + r) as f64 * crate::costs::SHUFFLE_SECONDS + surrogate.varying.len() as f64 * per_cell;
    let counts = terms_within_budget(params, per_pattern, (INITIAL_PATTERNS, MAX_PATTERNS));
    params.budget.check(
        "the occupancy estimate",
        Needs {
            memory_bytes: 8.0 * counts.1 as f64,
            work_seconds: counts.0 as f64 * per_pattern,
        },
        "lower N or the realizations",
    )?;
    let grid = [n, n];
    let moments = CellMoments::new(f, &grid);
    let mut estimate = mean_of_exact_terms(
        "occupancy of the cells",
        counts,
        params.target_noise,
        0.0,
        |i| {
            let shuffles = CmjShuffles::of_realization(n, params.seed, i as u64);
            Ok(surrogate.term(&moments, &shuffles))
        },
        progress,
    )?;
    // The terms may be negative; their mean is not, but for its noise.
    estimate.variance = estimate.variance.max(0.0);
    Ok(estimate)
}

/// CMJ's blocks where the integrand varies, with the bilinear surrogate of their cell means,
/// and the constant blocks' share of the occupied cells' mean.
struct BlockSurrogate {
    /// Blocks along x (`m`) and along y (`r`); fine positions: `r` along x, `m` along y.
    m: usize,
    r: usize,
    n: usize,
    /// Each varying block `i + m j` with its surrogate's `(α, β, γ)`.
    varying: Vec<(usize, [f64; 3])>,
    /// `Σ (F_b − I)` and `Σ |F_b − I|` over the constant blocks `b`, each holding one point
    /// whose cell mean is the block's `F_b`.
    constant_deviation: (f64, f64),
    /// `E L²`, exactly (to rounding).
    second_moment: f64,
}

impl BlockSurrogate {
    /// The surrogate of `f` for CMJ's `n` points, from its masses on the `2m × 2r` quadrants:
    /// a block is constant where its four quadrants are, with one mean.
    fn new(f: &dyn Integrand, n: usize) -> Self {
        let (m, r) = near_square_factors(n);
        let (masses, constant) = masses_and_constant_cells(f, &[2 * m, 2 * r]);
        let integral = f.integral();
        // Quadrant masses to means: each quadrant has volume 1 / (4N).
        let scale = 4.0 * n as f64;
        let quadrant = |i: usize, j: usize, s: usize, t: usize| (2 * i + s) + 2 * m * (2 * j + t);
        let mut coefficients = vec![[0.0; 3]; m * r];
        let mut varying = Vec::new();
        let (mut deviation, mut size) = (CompensatedSum::default(), CompensatedSum::default());
        for (block, slot) in coefficients.iter_mut().enumerate() {
            let (i, j) = (block % m, block / m);
            let q = |s: usize, t: usize| masses[quadrant(i, j, s, t)] * scale;
            let (q00, q10, q01, q11) = (q(0, 0), q(1, 0), q(0, 1), q(1, 1));
            let flat = constant.as_ref().is_some_and(|bits| {
                let on = |s, t| is_marked(bits, quadrant(i, j, s, t));
                on(0, 0)
                    && on(1, 0)
                    && on(0, 1)
                    && on(1, 1)
                    && q00 == q10
                    && q00 == q01
                    && q00 == q11
            });
            if flat {
                deviation.add(q00 - integral);
                size.add((q00 - integral).abs());
            } else {
                *slot = [
                    q10 + q11 - q00 - q01,
                    q01 + q11 - q00 - q10,
                    4.0 * (q11 - q10 - q01 + q00),
                ];
                varying.push((block, *slot));
            }
        }
        Self {
            m,
            r,
            n,
            varying,
            constant_deviation: (deviation.value(), size.value()),
            second_moment: second_moment(&coefficients, m, r),
        }
    }

    /// One pattern's term `(1/N²) Σ_j V_{c_j} + (M − I)² − (L² − E L²)`, from its permutations,
    /// with a bound on its rounding.
    fn term(&self, moments: &CellMoments, shuffles: &CmjShuffles) -> CellSum {
        let (m, r, n) = (self.m, self.r, self.n);
        let nf = n as f64;
        let (rf, mf) = (r as f64, m as f64);
        let integral = moments.integral();
        let mut deviation = CompensatedSum::default();
        let mut magnitude = CompensatedSum::default();
        let mut within = CompensatedSum::default();
        let mut surrogate = CompensatedSum::default();
        let mut surrogate_size = 0.0;
        deviation.add(self.constant_deviation.0);
        magnitude.add(self.constant_deviation.1);
        for &(block, [alpha, beta, gamma]) in &self.varying {
            let (i, j) = (block % m, block / m);
            let (a, b) = (shuffles.sub_x[j], shuffles.sub_y[i]);
            let (mean, var) = moments.mean_and_variance((i * r + a) + n * (j * m + b));
            deviation.add(mean - integral);
            magnitude.add((mean - integral).abs());
            within.add(var);
            let u = (a as f64 + 0.5) / rf - 0.5;
            let w = (b as f64 + 0.5) / mf - 0.5;
            let t = alpha * u + beta * w + gamma * u * w;
            surrogate.add(t);
            surrogate_size += t.abs();
        }
        let d = deviation.value() / nf;
        let off = CELL_ROUNDING * (magnitude.value() / nf + 2.0 * integral.abs());
        let inner = within.value() / (nf * nf);
        let l = surrogate.value() / nf;
        let l_off = 8.0 * f64::EPSILON * surrogate_size / nf;
        CellSum {
            variance: inner + d * d - (l * l - self.second_moment),
            rounding: CELL_ROUNDING * (inner + self.second_moment)
                + 2.0 * d.abs() * off
                + off * off
                + 2.0 * l.abs() * l_off
                + l_off * l_off,
        }
    }
}

/// `E L²` of the surrogate with `coefficients` on `m × r` blocks (module notes).
fn second_moment(coefficients: &[[f64; 3]], m: usize, r: usize) -> f64 {
    let n = (m * r) as f64;
    // `E[u(σ(j)) u(σ(j'))] = s (p/(p−1)) (δ − 1/p)`; a single position has no spread.
    let pair_scale = |p: usize| {
        if p < 2 {
            0.0
        } else {
            let pf = p as f64;
            (pf * pf - 1.0) / (12.0 * pf * pf) * pf / (pf - 1.0)
        }
    };
    let (ku, kw) = (pair_scale(r), pair_scale(m));
    let a: Vec<f64> = (0..r)
        .map(|j| (0..m).map(|i| coefficients[i + m * j][0]).sum())
        .collect();
    let b: Vec<f64> = (0..m)
        .map(|i| (0..r).map(|j| coefficients[i + m * j][1]).sum())
        .collect();
    let gamma = |i: usize, j: usize| coefficients[i + m * j][2];
    let row_mean: Vec<f64> = (0..r)
        .map(|j| (0..m).map(|i| gamma(i, j)).sum::<f64>() / m as f64)
        .collect();
    let column_mean: Vec<f64> = (0..m)
        .map(|i| (0..r).map(|j| gamma(i, j)).sum::<f64>() / r as f64)
        .collect();
    let mean = row_mean.iter().sum::<f64>() / r as f64;
    let mut centred = CompensatedSum::default();
    for j in 0..r {
        for i in 0..m {
            let g = gamma(i, j) - row_mean[j] - column_mean[i] + mean;
            centred.add(g * g);
        }
    }
    (ku * spread(&a) + kw * spread(&b) + ku * kw * centred.value()) / (n * n)
}

/// `Σ (v − v̄)²`.
fn spread(values: &[f64]) -> f64 {
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let mut sum = CompensatedSum::default();
    values.iter().for_each(|v| sum.add((v - mean) * (v - mean)));
    sum.value()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::{parse_integrand, Integrand};
    use crate::predict::strata::cells::pattern_term;
    use crate::progress::Silent;
    use crate::sampler::{CorrelatedMultiJitter, Sampler};

    /// A standard normal beyond this is a failure: about 7e-5 of the time each, over a dozen
    /// comparisons.
    const Z: f64 = 4.0;

    fn shapes() -> Vec<Box<dyn Integrand>> {
        [
            "agaussian:s1=0.1,s2=0.04,angle=30,c=0.4;0.55",
            "disk:r=0.3,c=0.5;0.45",
            "edge:theta=30,offset=0.4",
            "polygon:0.2,0.2;0.8,0.3;0.4,0.9",
        ]
        .iter()
        .map(|spec| parse_integrand(spec).unwrap().build(2).unwrap())
        .collect()
    }

    impl BlockSurrogate {
        /// The surrogate's deviation `L` alone.
        fn deviation(&self, shuffles: &CmjShuffles) -> f64 {
            let (m, r) = (self.m, self.r);
            let l: f64 = self
                .varying
                .iter()
                .map(|&(block, [alpha, beta, gamma])| {
                    let (i, j) = (block % m, block / m);
                    let u = (shuffles.sub_x[j] as f64 + 0.5) / r as f64 - 0.5;
                    let w = (shuffles.sub_y[i] as f64 + 0.5) / m as f64 - 0.5;
                    alpha * u + beta * w + gamma * u * w
                })
                .sum();
            l / self.n as f64
        }
    }

    /// The surrogate's exact second moment against its mean over many patterns.
    #[test]
    fn second_moment_is_the_patterns_mean() {
        for f in shapes() {
            for n in [12, 64, 150] {
                let s = BlockSurrogate::new(f.as_ref(), n);
                let squares: Vec<f64> = (0..20000)
                    .map(|k| s.deviation(&CmjShuffles::of_realization(n, 3, k)).powi(2))
                    .collect();
                let (mean, se) = crate::spread::mean_and_standard_error(&squares);
                let z = (mean - s.second_moment) / se;
                assert!(
                    z.abs() < Z,
                    "{} at {n}: {mean} against {} (z {z})",
                    f.label(),
                    s.second_moment
                );
            }
        }
    }

    /// A term read from the permutations and the varying blocks alone is the plain term of the
    /// pattern those permutations drew, less the control variate.
    #[test]
    fn terms_are_the_patterns_own() {
        let cmj = CorrelatedMultiJitter::new(2).unwrap();
        for f in shapes() {
            for n in [100, 256] {
                let grid = [n, n];
                let moments = CellMoments::new(f.as_ref(), &grid);
                let s = BlockSurrogate::new(f.as_ref(), n);
                for k in 0..4 {
                    let shuffles = CmjShuffles::of_realization(n, 9, k);
                    let term = s.term(&moments, &shuffles);
                    let l = s.deviation(&shuffles);
                    let plain = pattern_term(&moments, &cmj.sample(n, 9, k).unwrap(), &grid, None);
                    let ours = term.variance + l * l - s.second_moment;
                    let slack = term.rounding + plain.rounding + 1e-12 * plain.variance;
                    assert!(
                        (ours - plain.variance).abs() <= slack,
                        "{} at {n}: {ours} against {}",
                        f.label(),
                        plain.variance
                    );
                }
            }
        }
    }

    /// The estimate meets CMJ's exact variance from the table of its cells.
    #[test]
    fn estimate_meets_the_table() {
        let params = crate::predict::PredictParams {
            target_noise: 0.03,
            ..Default::default()
        };
        for f in shapes() {
            for n in [256, 1024] {
                let exact = crate::predict::correlated_multi_jitter_variance(
                    f.as_ref(),
                    n,
                    &Default::default(),
                )
                .unwrap();
                let e = controlled_cmj_variance(f.as_ref(), n, &params, &Silent).unwrap();
                let z = (e.variance - exact.variance).abs()
                    / (e.standard_error + (e.rounding + exact.rounding) / Z);
                assert!(
                    z < Z,
                    "{} at {n}: {} ± {} against {}",
                    f.label(),
                    e.variance,
                    e.standard_error,
                    exact.variance
                );
            }
        }
    }
}
