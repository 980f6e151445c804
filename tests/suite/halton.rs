//! Halton as drawn (every digit position of every axis under its own random permutation): on
//! product integrands the exact route by the points' pairs of digit agreements, on others the
//! digit supports through a level of cells with the finer digits measured, against Monte Carlo
//! of the same estimator and, in 1D at a full period, against the closed form of a randomly
//! shifted grid.

use crate::common;

use common::Z_STRICT;
use specvar::integrand::{parse_integrand, Integrand};
use specvar::montecarlo::{empirical_variances, McParams};
use specvar::predict::{predict, PredictParams, Problem, SpectrumOrigin};
use specvar::progress::Silent;
use specvar::randomization::Randomization;
use specvar::sampler::SamplerKind;

/// Every default prediction of `texts` (in `d` axes) at each of `ns` is the route `routed` names and meets
/// Monte Carlo of 20000 patterns as drawn (all integrands on the same patterns, keyed by
/// `seed`): the two 99% intervals overlap (the prediction's widened to `Z_STRICT`).
fn assert_defaults_meet_monte_carlo(
    d: usize,
    texts: &[&str],
    ns: &[usize],
    seed: u64,
    routed: fn(&SpectrumOrigin) -> bool,
) {
    let halton = SamplerKind::Halton.build(d).unwrap();
    let fs: Vec<_> = texts
        .iter()
        .map(|t| parse_integrand(t).unwrap().build(d).unwrap())
        .collect();
    let refs: Vec<&dyn Integrand> = fs.iter().map(|f| f.as_ref()).collect();
    for &n in ns {
        let runs = empirical_variances(
            halton.as_ref(),
            &refs,
            n,
            &McParams {
                patterns: 20_000,
                shifts: 1,
                seed,
                randomization: Randomization::None,
                ..Default::default()
            },
            &Silent,
        )
        .unwrap();
        for ((text, f), m) in texts.iter().zip(&refs).zip(runs) {
            let p = predict(
                &Problem::new(halton.as_ref(), *f, n).unwrap(),
                &PredictParams::default(),
            )
            .unwrap();
            assert!(routed(&p.route.spectrum), "{text}, N = {n}: {}", p.route);
            assert_eq!(p.randomization, Randomization::None);
            common::assert_intervals_meet(&p, &m, Z_STRICT, &format!("{text}, N = {n}"));
        }
    }
}

/// On products the default is the exact sum over the points' pairs. N = 100 is no power of
/// either base.
#[test]
fn halton_as_drawn_meets_monte_carlo_on_products() {
    assert_defaults_meet_monte_carlo(
        2,
        &[
            "gaussian:sigma=0.2,c=0.2;0.7",
            "polygon:0.2,0.3;0.7,0.3;0.7,0.8;0.2,0.8",
        ],
        &[16, 100, 512],
        29,
        |o| matches!(o, SpectrumOrigin::PermutedDigits(_)),
    );
}

/// Beyond products (a disk, an edge, a triangle) the default is the level of digit cells with
/// the finer digits measured.
#[test]
fn halton_as_drawn_meets_monte_carlo_beyond_products() {
    assert_defaults_meet_monte_carlo(
        2,
        &[
            "disk:r=0.3,c=0.45;0.55",
            "edge:theta=30,offset=0.4",
            "polygon:0.2,0.2;0.8,0.3;0.4,0.9",
        ],
        &[16, 100, 300],
        31,
        |o| matches!(o, SpectrumOrigin::PermutedLevel(_)),
    );
}

/// In 1D at N = 2^m, the first N indices hold every m-digit string once: the permutations only
/// reorder the cells, and the points are the grid `(c + u)/N` with a common uniform offset `u`,
/// the randomly shifted regular grid, whose variance is `Σ_{k ≠ 0, N | k} |f̂(k)|²` (its closed
/// spectrum). The two routes share nothing but the integrand.
#[test]
fn a_full_period_in_one_dimension_is_the_shifted_grid() {
    let halton = SamplerKind::Halton.build(1).unwrap();
    let grid = SamplerKind::Regular.build(1).unwrap();
    for text in ["gaussian:sigma=0.1,c=0.3", "gaussian:sigma=0.05"] {
        let f = parse_integrand(text).unwrap().build(1).unwrap();
        for n in [8, 64] {
            let as_drawn = predict(
                &Problem::new(halton.as_ref(), f.as_ref(), n).unwrap(),
                &PredictParams::default(),
            )
            .unwrap();
            let shifted = predict(
                &Problem::new(grid.as_ref(), f.as_ref(), n)
                    .unwrap()
                    .with_randomization(Randomization::Shift),
                &PredictParams::default(),
            )
            .unwrap();
            let band = as_drawn.budget.half_width(Z_STRICT)
                + shifted.budget.half_width(Z_STRICT)
                + 1e-12 * shifted.variance;
            assert!(
                (as_drawn.variance - shifted.variance).abs() <= band,
                "{text}, N = {n}: {} against the shifted grid's {}",
                as_drawn.variance,
                shifted.variance
            );
        }
    }
}

/// In 3D (bases 2, 3 and 5) on a ball, the default is the level of digit cells and meets
/// Monte Carlo of 20000 patterns as drawn (the prediction's interval widened to `Z_STRICT`).
#[test]
fn halton_as_drawn_meets_monte_carlo_on_a_ball() {
    assert_defaults_meet_monte_carlo(3, &["ball"], &[64, 512], 37, |o| {
        matches!(o, SpectrumOrigin::PermutedLevel(_))
    });
}

/// Both routes give the same bits on any thread count: the pairs' sums (a product, N = 1000)
/// and the level with its finer digits measured (a disk, N = 16).
#[test]
fn halton_as_drawn_is_the_same_bits_on_any_thread_count() {
    let halton = SamplerKind::Halton.build(2).unwrap();
    for (text, n) in [("gaussian:sigma=0.2", 1000), ("disk:r=0.3,c=0.45;0.55", 16)] {
        let f = parse_integrand(text).unwrap().build(2).unwrap();
        let problem = Problem::new(halton.as_ref(), f.as_ref(), n).unwrap();
        common::assert_thread_count_invariant(|| {
            let p = predict(&problem, &PredictParams::default()).unwrap();
            (p.variance.to_bits(), p.budget.quadrature.to_bits())
        });
    }
}
