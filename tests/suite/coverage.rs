//! The budgets' coverage: estimated predictions against exact truths of the same problem (the
//! report's coverage section, on a smaller matrix).

use specvar::randomization::Randomization;
use specvar::report::coverage::{compute, CoverageCase, CoverageConfig};
use specvar::sampler::SamplerKind;

/// Shifted random and jitter (closed-form spectra) and Latin hypercube and Owen-scrambled
/// Sobol' as drawn (pairs in closed form, Owen's gains), estimated from patterns, on a disk, a
/// seam, an edge and a square at N = 64: each estimate's 99% interval holds its exact truth.
/// With 16 cases at a nominal 1%, a correct budget misses none with probability 0.85 and at
/// most one with 0.99, so one miss is allowed.
#[test]
fn estimated_budgets_hold_the_exact_truths() {
    let case = |sampler, randomization| CoverageCase {
        sampler,
        randomization,
    };
    let config = CoverageConfig {
        cases: vec![
            case(SamplerKind::Random, Randomization::Shift),
            case(SamplerKind::Jitter, Randomization::Shift),
            case(SamplerKind::LatinHypercube, Randomization::None),
            case(SamplerKind::Sobol, Randomization::None),
        ],
        ns: vec![64],
        ..CoverageConfig::standard()
    };
    let section = compute(&config, 9).unwrap();
    assert_eq!(section.rows.len(), 16);
    assert!(section.misses <= 1, "{} misses", section.misses);
    // Informative: every interval narrower than a fifth of the value.
    for r in &section.rows {
        let width = r.estimate.budget.half_width(specvar::montecarlo::Z_99) / r.truth.variance;
        assert!(width < 0.2, "{:?} on {}: {width}", r.case, r.integrand);
        assert!(r.truth.budget.spectrum_noise == 0.0);
    }
}

/// The estimated spectrum's stated noise covers the spread of the prediction across seeds:
/// Poisson disk on a disk at N = 256, 48 seeds. The seeds' sample standard deviation has a
/// relative standard error of `1/√(2·47)`, about 10%, so a calibrated noise is above
/// `1 − 2.576·0.103` of it at 99%. (Measured: 1.29 of it here, 0.91–1.06 on a disk at
/// N = 1024 and a Gaussian at N = 256 and 1024: the stated noise is the spread, a little
/// above it at N = 256.)
#[test]
#[ignore = "48 estimated predictions, about 15 s on 2 cores: a calibration measurement, run on demand"]
fn the_stated_spectrum_noise_covers_the_spread_across_seeds() {
    use specvar::predict::{predict, PredictParams, Problem};
    let disk = specvar::integrand::Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let poisson = SamplerKind::PoissonDisk.build(2).unwrap();
    let problem = Problem::new(poisson.as_ref(), &disk, 256).unwrap();
    let seeds = 48;
    let runs: Vec<(f64, f64)> = (0..seeds)
        .map(|seed| {
            let params = PredictParams {
                seed,
                ..PredictParams::default()
            };
            let p = predict(&problem, &params).unwrap();
            (p.variance, p.budget.spectrum_noise)
        })
        .collect();
    let count = seeds as f64;
    let mean = runs.iter().map(|r| r.0).sum::<f64>() / count;
    let spread = (runs.iter().map(|r| (r.0 - mean).powi(2)).sum::<f64>() / (count - 1.0)).sqrt();
    let stated = runs.iter().map(|r| r.1).sum::<f64>() / count;
    let relative_error = 1.0 / (2.0 * (count - 1.0)).sqrt();
    let ratio = stated / spread;
    assert!(
        ratio >= 1.0 - 2.576 * relative_error,
        "stated {stated:.3e} against a spread of {spread:.3e} across {seeds} seeds"
    );
}
