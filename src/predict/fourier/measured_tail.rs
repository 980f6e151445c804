//! The lattice form of the randomly shifted estimator with the energy beyond the lattice
//! measured rather than modelled.
//!
//! With `Q(k) = (1/N) Σ_j e^{2πi k·x_j}` a pattern's normalized sums and `t` a uniform shift,
//! the error is `μ_t − I = Σ_{k≠0} f̂(k) Q(k) e^{2πi k·t}`. Its modes are orthogonal over `t`, so
//! a pattern's variance under the shift splits exactly into the lattice `|k_i| ≤ K` and the rest:
//!
//! `E_t (μ_t − I)² = Σ_{k ∈ lattice, k≠0} |f̂(k)|² |Q(k)|² + E_t r_t²`,
//! `r_t = μ_t − I − Σ_{k ∈ lattice, k≠0} f̂(k) Q(k) e^{2πi k·t}`.
//!
//! The first term is summed from the pattern's transform; the residual `r_t` is the error less
//! its lattice part, computed at a few uniform shifts from the integrand's values at the shifted
//! points, so `r_t²` is an unbiased estimate of the tail. Each pattern's term is unbiased for
//! its variance, and the mean over independent patterns is unbiased for the estimator's, with
//! its standard error from the terms' spread: nothing is modelled beyond the lattice. The
//! white-tail model counts `(1/N) Σ_beyond |f̂|²`, while samplers whose projections are
//! stratified (Halton, nets) have spectra far below white along the axes, where the energy of
//! an integrand that jumps across the cube's faces lies (`docs/theory.md`, "A measured tail").

use crate::budget::{try_filled, Needs};
use crate::costs::COEFFICIENT_SECONDS;
use crate::error::{finite, Result};
use crate::integrand::Integrand;
use crate::pointset::PointSet;
use crate::predict::term_mean::{mean_to_target_noise, terms_within_budget};
use crate::predict::{ErrorBudget, Form, PredictParams, Prediction, Route, SpectrumOrigin};
use crate::progress::Progress;
use crate::quadrature::CompensatedSum;
use crate::randomization::{toroidal_shift, Randomization};
use crate::spectrum::nufft::NufftPlan;
use crate::spectrum::{kmax_at_nu, Lattice, PatternSource};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// Shifts per pattern: enough that evaluating the integrand at the shifted points costs about
/// what drawing and transforming the pattern does, so neither dominates the spread.
pub(crate) const SHIFTS_PER_PATTERN: usize = 8;
/// Patterns the mean starts with.
const INITIAL_PATTERNS: usize = 16;
/// Patterns the mean never exceeds.
const MAX_PATTERNS: usize = 4096;
/// The transform's guaranteed error `|δQ(k)|`: far below the residuals, which are the
/// estimator's errors beyond the lattice (at least `1e-8` where this route is taken).
const TRANSFORM_TOLERANCE: f64 = 1e-12;
/// Seconds per point of the transform (spreading).
const TRANSFORM_SECONDS_PER_POINT: f64 = 2e-7;
/// Seconds per cell of the transform's upsampled grid (its FFT).
const FFT_SECONDS_PER_CELL: f64 = 3e-8;
/// The lattice's extent in units of `N^{1/d}` (at most the white-tail route's own): the
/// lattice part's spread over patterns, not the tail's over shifts, dominates the noise once
/// the lattice holds the sampler's structured low band, and a smaller lattice buys more
/// patterns (Halton at N = 16384 on a polygon: 1.2 s for 2% at `ν = 1`–`2`, 2.9 s at `ν = 6`).
const TAIL_NU: f64 = 2.0;
/// The smallest lattice extent.
const MIN_KMAX: usize = 16;
/// The share `1 − ρ²` of the lattice parts' variance that [`least_half_width`] takes to
/// survive their correlation `ρ` with the tails: half, for `|ρ|` up to `1/√2`.
const LEAST_SPREAD_SHARE: f64 = 0.5;

/// The integrand's torus coefficients on a lattice, with what the error bound needs.
struct Coefficients {
    lattice: Lattice,
    /// `f̂(k)` in lattice order, 0 at DC.
    values: Vec<Complex64>,
    /// `Σ_{k≠0} |f̂(k)|`.
    absolute_sum: f64,
    /// `Σ_{k≠0} |f̂(k)|²`.
    energy: f64,
}

impl Coefficients {
    fn of(f: &dyn Integrand, lattice: Lattice) -> Result<Self> {
        let mut values = try_filled(
            lattice.len(),
            Complex64::new(0.0, 0.0),
            "the integrand's coefficients on the lattice",
        )?;
        crate::integrand::on_lattice(lattice, &mut values, |k| f.coefficient(k));
        values[lattice.dc_index()] = Complex64::new(0.0, 0.0);
        let absolute_sum = values.iter().map(|c| c.norm()).sum();
        let energy = values.iter().map(|c| c.norm_sqr()).sum();
        Ok(Self {
            lattice,
            values,
            absolute_sum,
            energy,
        })
    }
}

/// What one pattern contributes: its lattice part and its residuals' mean square.
struct PatternTerm {
    lattice_part: f64,
    tail: f64,
}

/// The phases `e^{2πi k t}` for `k = −K..=K`, into `out`.
fn phases(t: f64, kmax: usize, out: &mut [Complex64]) {
    for (j, e) in out.iter_mut().enumerate() {
        *e = Complex64::from_polar(1.0, TAU * (j as f64 - kmax as f64) * t);
    }
}

/// `Re Σ_k c(k) e^{2πi k·t}` over the lattice, axis by axis: the last axis's phases are
/// summed along each row, and each row's sum is weighted by the product of the other axes'.
fn lattice_part_at(c: &[Complex64], lattice: Lattice, tables: &[Vec<Complex64>]) -> f64 {
    let d = lattice.dimension;
    let side = lattice.side();
    let last = &tables[d - 1];
    let mut total = CompensatedSum::default();
    for (r, row) in c.chunks_exact(side).enumerate() {
        let acc = row_dot(row, last);
        // The row's index over the first d − 1 axes, the first axis slowest.
        let mut weight = Complex64::new(1.0, 0.0);
        let mut rest = r;
        for a in (0..d - 1).rev() {
            weight *= tables[a][rest % side];
            rest /= side;
        }
        total.add((acc * weight).re);
    }
    total.value()
}

/// `Σ_j a_j b_j` in four independent partial sums, so that neighbouring products do not wait
/// for each other's additions.
fn row_dot(a: &[Complex64], b: &[Complex64]) -> Complex64 {
    let mut lanes = [Complex64::new(0.0, 0.0); 4];
    let body = a.len() - a.len() % 4;
    for (ac, bc) in a[..body].chunks_exact(4).zip(b[..body].chunks_exact(4)) {
        for l in 0..4 {
            lanes[l] += ac[l] * bc[l];
        }
    }
    let tail: Complex64 = a[body..].iter().zip(&b[body..]).map(|(x, y)| x * y).sum();
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// One pattern's term: its lattice part from its transform, and the mean square of its
/// residuals at `shifts` shifts (units `first_unit..first_unit + shifts` of `seed`).
fn pattern_term(
    f: &dyn Integrand,
    coefficients: &Coefficients,
    plan: &NufftPlan,
    pattern: &PointSet,
    (seed, first_unit, shifts): (u64, u64, usize),
) -> Result<PatternTerm> {
    let lattice = coefficients.lattice;
    let (n, d) = (pattern.len(), lattice.dimension);
    let nf = n as f64;
    // The transform gives S(k) = Σ_j e^{−2πi k·x_j} = N conj Q(k); c(k) = f̂(k) Q(k).
    let mut c = plan.sums(pattern)?;
    let mut lattice_part = CompensatedSum::default();
    for (ck, fk) in c.iter_mut().zip(&coefficients.values) {
        let q = ck.conj() / nf;
        lattice_part.add(fk.norm_sqr() * q.norm_sqr());
        *ck = fk * q;
    }
    let integral = f.integral();
    let mut tables = vec![vec![Complex64::new(0.0, 0.0); lattice.side()]; d];
    let mut shifted = vec![0.0; pattern.coords().len()];
    let mut tail = CompensatedSum::default();
    for s in 0..shifts {
        let t = toroidal_shift(d, seed, first_unit + s as u64);
        for (out, x) in shifted
            .chunks_exact_mut(d)
            .zip(pattern.coords().chunks_exact(d))
        {
            for a in 0..d {
                let y = x[a] + t[a];
                out[a] = if y >= 1.0 { y - 1.0 } else { y };
            }
        }
        for (a, table) in tables.iter_mut().enumerate() {
            phases(t[a], lattice.kmax, table);
        }
        let error = f.sum_at(&shifted) / nf - integral;
        let residual = error - lattice_part_at(&c, lattice, &tables);
        tail.add(residual * residual);
    }
    Ok(PatternTerm {
        lattice_part: lattice_part.value(),
        tail: tail.value() / shifts as f64,
    })
}

/// The route's lattice, its transform and the seconds one pattern costs.
struct TailPlan {
    lattice: Lattice,
    plan: NufftPlan,
    per_pattern: f64,
}

impl TailPlan {
    /// The plan on `|k_i| ≤ kmax`, at most [`TAIL_NU`] `N^{1/d}`: a pattern's draw, its
    /// transform, and its integrand values and lattice parts at the shifts.
    fn new(source: PatternSource<'_>, kmax: usize) -> Result<Self> {
        let (n, d) = (source.points(), source.dimension());
        let kmax = kmax.min(kmax_at_nu(n, d, TAIL_NU).max(MIN_KMAX));
        let lattice = Lattice { dimension: d, kmax };
        let plan = NufftPlan::new(d, kmax, n, TRANSFORM_TOLERANCE)?;
        let grid = (plan.grid_size() as f64).powi(d as i32);
        let per_pattern = source.pattern_needs().work_seconds
            + (n as f64 * TRANSFORM_SECONDS_PER_POINT + grid * FFT_SECONDS_PER_CELL)
            + SHIFTS_PER_PATTERN as f64
                * (n as f64 * crate::costs::SHIFTED_EVALUATION_SECONDS
                    + lattice.len() as f64 * crate::costs::LATTICE_TERM_SECONDS);
        Ok(Self {
            lattice,
            plan,
            per_pattern,
        })
    }
}

/// The least 99% half-width this route can reach for a stationary sampler, with as many
/// patterns as the work budget allows, from the standard error `stderr` of the raw lattice
/// form's mean over `realizations` of the same patterns on the same lattice; `None` where this
/// route's lattice is another (the white-tail route's extends past [`TAIL_NU`]).
///
/// Each pattern's term here is its lattice part, which is the raw lattice form's term, plus
/// its measured tail: with `m` patterns the standard error is at least
/// `√(1 − ρ²) σ_L / √m`, `σ_L` the lattice parts' spread and `ρ` their correlation with the
/// tails. The two are sums over disjoint frequencies of a stationary pattern, nearly
/// uncorrelated; [`LEAST_SPREAD_SHARE`] grants them a correlation as strong as `1/√2`.
///
/// # Errors
/// A lattice or transform outside the planner's range.
pub(crate) fn least_half_width(
    source: PatternSource<'_>,
    kmax: usize,
    params: &PredictParams,
    (stderr, realizations): (f64, usize),
) -> Result<Option<f64>> {
    let plan = TailPlan::new(source, kmax)?;
    if plan.lattice.kmax != kmax {
        return Ok(None);
    }
    let (_, max) = terms_within_budget(params, plan.per_pattern, (INITIAL_PATTERNS, MAX_PATTERNS));
    let spread = stderr * (realizations as f64).sqrt();
    let least = LEAST_SPREAD_SHARE.sqrt() * spread / (max.max(2) as f64).sqrt();
    Ok(Some(crate::montecarlo::Z_99 * least))
}

/// The randomly shifted variance of the patterns of `source` on `f` by the lattice form on
/// `|k_i| ≤ kmax` (at most [`TAIL_NU`] `N^{1/d}`) with the tail measured at [`SHIFTS_PER_PATTERN`] shifts of each pattern:
/// patterns added until the relative standard error reaches `params.target_noise` or the work
/// budget ends. Given point sets are used in turn, each time with new shifts.
///
/// # Errors
/// A lattice or transform beyond the budget, or a sampler error.
pub(crate) fn predict_measured_tail(
    f: &dyn Integrand,
    source: PatternSource<'_>,
    kmax: usize,
    params: &PredictParams,
    progress: &dyn Progress,
) -> Result<Prediction> {
    let (n, d) = (source.points(), source.dimension());
    let shifts = SHIFTS_PER_PATTERN;
    let TailPlan {
        lattice,
        plan,
        per_pattern,
    } = TailPlan::new(source, kmax)?;
    let kmax = lattice.kmax;
    let len = lattice.len() as f64;
    let grid = (plan.grid_size() as f64).powi(d as i32);
    let (initial, max) = terms_within_budget(params, per_pattern, (INITIAL_PATTERNS, MAX_PATTERNS));
    let threads = rayon::current_num_threads() as f64;
    params.budget.check(
        "the lattice form with a measured tail",
        Needs {
            // The coefficients, and per pattern in flight its sums and the transform's grid.
            memory_bytes: 16.0 * len * (1.0 + threads) + 16.0 * grid * threads,
            work_seconds: len * COEFFICIENT_SECONDS + initial as f64 * per_pattern,
        },
        "lower N or kmax",
    )?;
    let coefficients = Coefficients::of(f, lattice)?;
    let sets = source.available();
    let estimate = mean_to_target_noise(
        "the lattice form with a measured tail",
        (initial.max(2), max.max(2)),
        params.target_noise,
        0.0,
        |i| {
            let pattern = source.realization(sets.map_or(i, |m| i % m))?;
            let units = (params.seed, (i * shifts) as u64, shifts);
            let term = pattern_term(f, &coefficients, &plan, &pattern, units)?;
            Ok(term.lattice_part + term.tail)
        },
        progress,
    )?;
    let variance = finite(estimate.variance, || {
        format!("the lattice form of {} is not finite", f.label())
    })?;
    // |δQ| ≤ ε moves |Q|² by at most 2ε + ε² (|Q| ≤ 1), and the lattice part at a shift by
    // at most ε Σ|f̂|, hence a residual's square by 2|r| ε Σ|f̂| + (ε Σ|f̂|)², with the mean
    // |r| at most √(the tail) ≤ √(the variance).
    let eps = plan.error_bound();
    let moved = eps * coefficients.absolute_sum;
    let quadrature = eps * (2.0 + eps) * coefficients.energy
        + 2.0 * moved * variance.max(0.0).sqrt()
        + moved * moved;
    Ok(Prediction {
        variance,
        randomization: Randomization::Shift,
        route: Route {
            form: Form::Lattice,
            spectrum: SpectrumOrigin::MeasuredTail {
                n,
                patterns: estimate.patterns,
                kmax,
                shifts,
            },
        },
        reason: String::new(),
        budget: ErrorBudget {
            tabulation: 0.0,
            spectrum_noise: estimate.standard_error,
            quadrature,
            ..Default::default()
        },
        n,
        dimension: d,
        dc_term: 0.0,
        evaluations: (estimate.patterns * shifts * n) as u64,
        alternatives: Vec::new(),
        analysis: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrand::parse_integrand;
    use crate::progress::Silent;
    use crate::sampler::{Halton, Sampler};

    /// Standard errors within which an unbiased mean meets its truth in every case here
    /// (Bonferroni over the cases at a 10⁻⁴ false-alarm rate each).
    const Z: f64 = 4.0;

    /// The four-lane dot product is the plain one up to rounding (`len · ε · Σ|a_j b_j|`), at
    /// every length modulo the lanes.
    #[test]
    fn row_dot_is_the_plain_sum() {
        for len in [0, 1, 3, 4, 5, 129] {
            let a: Vec<Complex64> = (0..len)
                .map(|j| Complex64::from_polar(1.0 + j as f64, 0.3 * j as f64))
                .collect();
            let b: Vec<Complex64> = (0..len)
                .map(|j| Complex64::from_polar(1.0, -0.7 * j as f64))
                .collect();
            let plain: Complex64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
            let scale: f64 = a.iter().zip(&b).map(|(x, y)| (x * y).norm()).sum();
            let gap = (row_dot(&a, &b) - plain).norm();
            assert!(
                gap <= 2.0 * len as f64 * f64::EPSILON * scale,
                "{len}: {gap}"
            );
        }
    }

    /// For one fixed set the variance under the shift is exactly the pair sum
    /// `(1/N²) Σ a_f(x_i − x_j) − I²`; the lattice part plus the measured tail must meet it
    /// on a lattice so small that most of the variance lies beyond it.
    #[test]
    fn a_fixed_set_meets_its_pair_sum() {
        let set = Halton::new(2).unwrap().sample(1024, 3, 0).unwrap();
        for text in [
            "gaussian:sigma=0.2,c=0.2;0.7",
            "polygon:0.2,0.3;0.7,0.3;0.7,0.8;0.2,0.8",
            "disk:r=0.3,c=0.9;0.4",
        ] {
            let f = parse_integrand(text).unwrap().build(2).unwrap();
            let sets = std::slice::from_ref(&set);
            let (exact, _) = crate::predict::fourier::space::sets_shift_variance(f.as_ref(), sets)
                .unwrap()
                .unwrap();
            let params = PredictParams {
                realizations: Some(256),
                ..Default::default()
            };
            let p =
                predict_measured_tail(f.as_ref(), PatternSource::Sets(sets), 8, &params, &Silent)
                    .unwrap();
            let gap = (p.variance - exact).abs() - p.budget.quadrature;
            assert!(
                gap <= Z * p.budget.spectrum_noise,
                "{text}: {} ± {:.2e} against the pair sum {exact}",
                p.variance,
                p.budget.spectrum_noise
            );
            // Informative: the tail is most of the variance at K = 8, and is measured to a few %.
            assert!(
                p.budget.spectrum_noise < 0.05 * exact,
                "{text}: {:?}",
                p.budget
            );
        }
    }

    /// The least half-width is at most the one the route reaches on the same patterns, where
    /// the lattice parts dominate (a Gaussian's energy is low) and where the tail does (a
    /// disk's edge at `K = 16`); on a lattice wider than the route's own there is none.
    #[test]
    fn the_least_half_width_is_below_the_reached_one() {
        use crate::predict::fourier::lattice::{predict_on_patterns, LatticePower, PatternPlan};
        use crate::spectrum::SpectrumParams;
        let poisson = crate::sampler::PoissonDisk::new(2).unwrap();
        let sets: Vec<PointSet> = (0..48)
            .map(|i| poisson.sample(1024, 5, i).unwrap())
            .collect();
        let source = PatternSource::Sets(&sets);
        let params = PredictParams {
            realizations: Some(sets.len()),
            ..Default::default()
        };
        let kmax = 16;
        for text in ["gaussian:sigma=0.2,c=0.2;0.7", "disk"] {
            let f = parse_integrand(text).unwrap().build(2).unwrap();
            let power = LatticePower::of(f.as_ref(), Lattice { dimension: 2, kmax }).unwrap();
            let plan = PatternPlan {
                initial: sets.len(),
                target_noise: 0.0,
                max_realizations: sets.len(),
                spectrum: SpectrumParams {
                    kmax,
                    realizations: sets.len(),
                    ..Default::default()
                },
                symmetric: false,
                low_band: None,
            };
            let raw = predict_on_patterns(&power, source, &plan, &Silent).unwrap();
            let noise = (raw.budget.spectrum_noise, sets.len());
            let least = least_half_width(source, kmax, &params, noise)
                .unwrap()
                .unwrap();
            let reached = predict_measured_tail(f.as_ref(), source, kmax, &params, &Silent)
                .unwrap()
                .budget
                .spectrum_noise
                * crate::montecarlo::Z_99;
            assert!(
                least <= reached,
                "{text}: least {least:e}, reached {reached:e}"
            );
        }
        let wide = kmax_at_nu(1024, 2, TAIL_NU) + 1;
        assert_eq!(
            least_half_width(source, wide, &params, (1.0, 48)).unwrap(),
            None
        );
    }
}
