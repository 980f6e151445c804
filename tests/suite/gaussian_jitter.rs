//! Gaussian jitter used as drawn (no shift): the aliased-pair form against two independent
//! routes, the points' own moments by quadrature in space, and Monte Carlo of the same
//! estimator (its variance and its bias).

use crate::common;

use common::{assert_thread_count_invariant, Z_STRICT};
use specvar::integrand::{Ball, Gaussian, GridIntegrand, Integrand, Polygon};
use specvar::montecarlo::{empirical_variance, McParams, Z_99};
use specvar::predict::{gaussian_jitter_bias, predict, Form, FormChoice, PredictParams, Problem};
use specvar::quadrature::{CompensatedSum, GaussLegendre};
use specvar::randomization::Randomization;
use specvar::sampler::{strata, GaussianJitter, SamplerKind, DEFAULT_GAUSSIAN_WIDTH};
use std::f64::consts::PI;

/// Relative error of the space route's 1D integrals: composite Gauss–Legendre with 64 panels
/// of 20 nodes on an integrand smooth over `[0, 1)` (an analytic Gaussian times an analytic
/// wrapped density), so its error is at the rounding of the sums, a few hundred units of
/// roundoff.
const SPACE_QUADRATURE: f64 = 1e-13;

/// `∫_0^1 g(x) ρ(x − c) dx` for the wrapped normal `ρ` of standard deviation `s`.
fn against_wrapped_normal(g: impl Fn(f64) -> f64, c: f64, s: f64) -> f64 {
    let rule = GaussLegendre::new(20);
    let density = |x: f64| -> f64 {
        // Images beyond ±(s·12 + 1) weigh below e⁻⁷²; s is at most a quarter here.
        (-6..=6)
            .map(|i| {
                let u = x - c + i as f64;
                (-u * u / (2.0 * s * s)).exp()
            })
            .sum::<f64>()
            / (s * (2.0 * PI).sqrt())
    };
    let mut sum = CompensatedSum::default();
    for panel in 0..64 {
        let (a, b) = (panel as f64 / 64.0, (panel + 1) as f64 / 64.0);
        sum.add(rule.integrate(a, b, |x| g(x) * density(x)));
    }
    sum.value()
}

/// The variance and bias of a separable Gaussian `exp(−|x − μ|²/(2σ²))` on the unit square
/// under Gaussian jitter as drawn, in space: each point's `∫ f p_j` and `∫ f² p_j` as products
/// of 1D integrals against its wrapped normal. Returns `(variance, bias, mean second moment)`.
fn space_route(sigma: f64, mu: [f64; 2], n: usize, width: f64) -> (f64, f64, f64) {
    let m = strata(n, 2).unwrap();
    let axis = |a: usize, power: i32| -> Vec<f64> {
        let s = width / m[a] as f64;
        (0..m[a])
            .map(|j| {
                let c = (j as f64 + 0.5) / m[a] as f64;
                let g = |x: f64| {
                    (-(x - mu[a]).powi(2) / (2.0 * sigma * sigma))
                        .exp()
                        .powi(power)
                };
                against_wrapped_normal(g, c, s)
            })
            .collect()
    };
    let (first, second) = ([axis(0, 1), axis(1, 1)], [axis(0, 2), axis(1, 2)]);
    let (mut mean, mut within, mut squares) = (
        CompensatedSum::default(),
        CompensatedSum::default(),
        CompensatedSum::default(),
    );
    for j in 0..m[1] {
        for i in 0..m[0] {
            let e1 = first[0][i] * first[1][j];
            let e2 = second[0][i] * second[1][j];
            mean.add(e1);
            within.add(e2 - e1 * e1);
            squares.add(e2);
        }
    }
    let nf = n as f64;
    let f = Gaussian::new(sigma, mu.to_vec(), 1.0).unwrap();
    (
        within.value() / (nf * nf),
        mean.value() / nf - f.integral(),
        squares.value() / nf,
    )
}

#[test]
fn as_drawn_is_each_points_moments_in_space() {
    let jitter = GaussianJitter::new(2).unwrap();
    // Square and oblong grids (4 × 3), a Gaussian cut by two faces and one inside.
    for (sigma, mu) in [(0.15, [0.3, 0.85]), (0.1, [0.5, 0.45])] {
        let f = Gaussian::new(sigma, mu.to_vec(), 1.0).unwrap();
        for n in [12, 16, 36, 64] {
            let p = predict(
                &Problem::new(&jitter, &f, n).unwrap(),
                &PredictParams::default(),
            )
            .unwrap();
            assert_eq!(p.route.form, Form::AliasedPairs);
            assert_eq!(p.randomization, Randomization::None);
            let (variance, bias, second) = space_route(sigma, mu, n, DEFAULT_GAUSSIAN_WIDTH);
            // The space route's error on each moment, carried through the difference
            // E f² − (E f)², whose terms are of the size of the second moment.
            let space_error = 2.0 * SPACE_QUADRATURE * second / n as f64;
            let tolerance = p.budget.half_width(0.0) + space_error;
            assert!(
                (p.variance - variance).abs() <= tolerance,
                "σ = {sigma} N = {n}: {:.12e} vs {variance:.12e} (tolerance {tolerance:.2e})",
                p.variance
            );
            let b = gaussian_jitter_bias(&f, n, DEFAULT_GAUSSIAN_WIDTH).unwrap();
            assert!(
                (b - bias).abs() <= 2.0 * SPACE_QUADRATURE * f.integral() + 1e-18,
                "σ = {sigma} N = {n}: bias {b:.12e} vs {bias:.12e}"
            );
        }
    }
}

/// Every kind of integrand with coefficients of its square, at two N, against Monte Carlo of
/// the same estimator: the variance within the combined interval, and the exact bias within
/// the measured one. Each comparison fails a correct implementation with probability
/// 1% / comparisons (Bonferroni).
#[test]
fn as_drawn_agrees_with_monte_carlo_of_the_same_estimator() {
    let pixel: Vec<f64> = (0..12 * 12)
        .map(|i| {
            if (i % 12) + (i / 12) / 2 < 9 {
                1.0
            } else {
                0.2
            }
        })
        .collect();
    let integrands: Vec<Box<dyn Integrand>> = vec![
        Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()),
        Box::new(Ball::new(0.45, vec![0.9, 0.1], 1.0).unwrap()),
        Box::new(Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap()),
        Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap()),
        Box::new(
            GridIntegrand::new(12, 12, pixel)
                .unwrap()
                .with_meaning(specvar::integrand::GridMeaning::Exact),
        ),
    ];
    let jitter = SamplerKind::GaussianJitter.build(2).unwrap();
    let ns = [16, 144];
    let comparisons = (2 * ns.len() * integrands.len()) as f64;
    let z_family = common::inverse_normal_tail(0.01 / comparisons / 2.0);
    let mut worst: f64 = 0.0;
    for n in ns {
        for f in &integrands {
            let p = predict(
                &Problem::new(jitter.as_ref(), f.as_ref(), n).unwrap(),
                &PredictParams::default(),
            )
            .unwrap();
            // Exact: the budget is rounding and truncation only.
            assert!(
                p.budget.half_width(Z_99) < 1e-6 * p.variance,
                "{:?}",
                p.budget
            );
            let mc = empirical_variance(
                jitter.as_ref(),
                f.as_ref(),
                n,
                &McParams::for_sampler(
                    SamplerKind::GaussianJitter,
                    20_000,
                    None,
                    5,
                    Randomization::None,
                ),
            )
            .unwrap();
            let z = p.z_beyond_bounds(&mc);
            let bias = gaussian_jitter_bias(f.as_ref(), n, DEFAULT_GAUSSIAN_WIDTH).unwrap();
            let z_bias = (bias - mc.bias) / mc.bias_stderr;
            worst = worst.max(z.abs()).max(z_bias.abs());
            assert!(
                z.abs() < z_family && z_bias.abs() < z_family,
                "N = {n} {}: variance {:.4e} vs {:.4e} [{:.4e}, {:.4e}] (z = {z:.2}), bias \
                 {bias:.4e} vs {:.4e} ± {:.1e}",
                f.label(),
                p.variance,
                mc.variance,
                mc.ci_low,
                mc.ci_high,
                mc.bias,
                mc.bias_stderr
            );
        }
    }
    eprintln!("worst |z| {worst:.2} of {comparisons} comparisons (limit {z_family:.2})");
}

#[test]
fn as_drawn_in_3d_and_at_other_widths_agrees_with_monte_carlo() {
    let ball = Ball::new(0.3, vec![0.5, 0.4, 0.6], 1.0).unwrap();
    let disk = Ball::new(0.3, vec![0.5, 0.4], 1.0).unwrap();
    let cases: [(f64, &dyn Integrand, usize); 3] =
        [(0.25, &ball, 64), (0.1, &disk, 64), (1.0, &disk, 64)];
    let z_family = common::inverse_normal_tail(0.01 / cases.len() as f64 / 2.0);
    for (width, f, n) in cases {
        let jitter = GaussianJitter::new(f.dimension())
            .unwrap()
            .with_width(width)
            .unwrap();
        let p = predict(
            &Problem::new(&jitter, f, n).unwrap(),
            &PredictParams::default(),
        )
        .unwrap();
        let mc = empirical_variance(
            &jitter,
            f,
            n,
            &McParams {
                patterns: 20_000,
                seed: 9,
                randomization: Randomization::None,
                ..McParams::default()
            },
        )
        .unwrap();
        common::assert_agrees(&p, &mc, z_family, &format!("width {width} {}", f.label()));
    }
}

#[test]
fn as_drawn_is_the_same_bits_on_any_thread_count() {
    let f = Polygon::edge(20.0, 0.5, 1.0).unwrap();
    let jitter = GaussianJitter::new(2).unwrap();
    assert_thread_count_invariant(|| {
        let p = predict(
            &Problem::new(&jitter, &f, 256).unwrap(),
            &PredictParams::default(),
        )
        .unwrap();
        p.variance.to_bits()
    });
}

/// Under a shift, the closed-form spectrum summed by Parseval against the same spectrum summed
/// on an explicit lattice wide enough to hold the integrands' jumps (its own truncation bound
/// beside it), and against Monte Carlo of the shifted estimator.
#[test]
fn shifted_is_the_closed_form_summed_and_agrees_with_monte_carlo() {
    let integrands: Vec<Box<dyn Integrand>> = vec![
        Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()),
        Box::new(Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap()),
        Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap()),
    ];
    let jitter = GaussianJitter::new(2).unwrap();
    let z_family = common::inverse_normal_tail(0.01 / integrands.len() as f64 / 2.0);
    for f in &integrands {
        let n = 1024;
        let problem = Problem::new(&jitter, f.as_ref(), n)
            .unwrap()
            .with_randomization(Randomization::Shift);
        let exact = predict(&problem, &PredictParams::default()).unwrap();
        assert!(exact.budget.half_width(Z_99) < 1e-6 * exact.variance);
        let on_lattice = predict(
            &problem,
            &PredictParams {
                kmax: Some(512),
                ..PredictParams::default()
            },
        )
        .unwrap();
        let gap = (exact.variance - on_lattice.variance).abs();
        assert!(
            gap <= exact.budget.half_width(0.0) + on_lattice.budget.half_width(0.0),
            "{}: {:.10e} vs lattice {:.10e} ± {:.1e}",
            f.label(),
            exact.variance,
            on_lattice.variance,
            on_lattice.budget.half_width(0.0)
        );
        let mc = empirical_variance(
            &jitter,
            f.as_ref(),
            n,
            &McParams {
                patterns: 6_000,
                seed: 13,
                randomization: Randomization::Shift,
                ..McParams::default()
            },
        )
        .unwrap();
        common::assert_agrees(&exact, &mc, z_family, &f.label());
    }
}

/// Under a shift at N where the frequency sum costs more than the same spectrum in space (its
/// frequencies grow like N), the default sums it in space: against the lattice form's sum over
/// the frequencies of the closed-form spectrum at 256² strata (a route that shares only the
/// integrand with it; Monte Carlo of the shifted estimator checks both at smaller N above),
/// and at 10^12 points answered with a budget within 1e-6 of the value (where the frequencies
/// would number 10^13).
#[test]
fn shifted_at_large_n_is_summed_in_space() {
    let jitter = GaussianJitter::new(2).unwrap();
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let triangle = Polygon::new(vec![[0.2, 0.2], [0.8, 0.3], [0.4, 0.9]], 1.0).unwrap();
    let shifted_with = |f: &dyn Integrand, n: usize, params: &PredictParams| {
        let problem = Problem::new(&jitter, f, n)
            .unwrap()
            .with_randomization(Randomization::Shift);
        predict(&problem, params).unwrap()
    };
    let shifted = |f: &dyn Integrand, n: usize| shifted_with(f, n, &PredictParams::default());
    let n = 256 * 256;
    let p = shifted(&disk, n);
    assert!(p.reason.contains("in space"), "{}", p.reason);
    let lattice = shifted_with(
        &disk,
        n,
        &PredictParams {
            form: FormChoice::Lattice,
            ..PredictParams::default()
        },
    );
    assert_eq!(lattice.route.form, Form::Lattice);
    let band = p.budget.half_width(Z_STRICT)
        + lattice.budget.half_width(Z_STRICT)
        + common::ROUNDING * lattice.variance;
    assert!(
        (p.variance - lattice.variance).abs() <= band,
        "disk at 256²: {:e} in space against {:e} by frequencies (band {band:e})",
        p.variance,
        lattice.variance
    );
    for f in [&disk as &dyn Integrand, &triangle] {
        let p = shifted(f, 1_000_000_000_000);
        assert!(p.reason.contains("in space"), "{}", p.reason);
        assert!(
            p.budget.half_width(Z_99) <= 1e-6 * p.variance,
            "{}: {:e} ± {:e}",
            f.label(),
            p.variance,
            p.budget.half_width(Z_99)
        );
    }
}
