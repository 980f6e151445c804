//! Rates: theory, fits, α, crossovers, and a measured slope against the predicted one.

use specvar::integrand::*;
use specvar::montecarlo::*;
use specvar::predict::*;
use specvar::rate::*;
use specvar::sampler::*;
use specvar::spectrum::*;

#[test]
fn theory_reproduces_the_talks_table() {
    let disk = 3.0;
    let gauss = f64::INFINITY;
    assert_eq!(theory_rate(0.0, disk, 2).0, -1.0);
    assert_eq!(theory_rate(0.0, gauss, 2).0, -1.0);
    assert_eq!(theory_rate(2.0, disk, 2).0, -1.5);
    assert_eq!(theory_rate(2.0, gauss, 2).0, -2.0);
    assert_eq!(theory_rate(4.0, gauss, 2).0, -3.0);
    // Jitter in d dimensions: N^{-1-1/d} on a ball, N^{-1-2/d} on a Gaussian.
    for d in 1..=3 {
        assert!((theory_rate(2.0, d as f64 + 1.0, d).0 - (-1.0 - 1.0 / d as f64)).abs() < 1e-15);
        assert!((theory_rate(2.0, gauss, d).0 - (-1.0 - 2.0 / d as f64)).abs() < 1e-15);
    }
}

#[test]
fn weighted_line_recovers_slopes_and_their_errors() {
    let x: Vec<f64> = (0..8).map(|i| i as f64).collect();
    let y: Vec<f64> = x.iter().map(|x| 3.0 - 1.5 * x).collect();
    let fit = weighted_line(&x, &y, Some(&[0.04; 8])).unwrap();
    assert!((fit.slope + 1.5).abs() < 1e-12 && (fit.intercept - 3.0).abs() < 1e-12);
    // se = σ / √Σ(x - x̄)² with σ = 0.2 and Σ(x - x̄)² = 42.
    assert!((fit.stderr - 0.2 / 42f64.sqrt()).abs() < 1e-15);
    assert!(weighted_line(&[1.0], &[1.0], None).is_err());
    assert!(weighted_line(&[1.0, 1.0], &[1.0, 2.0], None).is_err());
}

#[test]
fn crossover_of_two_power_laws() {
    let ns: Vec<f64> = (0..9).map(|i| 4f64.powi(i)).collect();
    let a: Vec<f64> = ns.iter().map(|n| 1.0 / n).collect();
    let b: Vec<f64> = ns.iter().map(|n| 10.0 / n.powf(1.5)).collect();
    let c = crossover(&ns, &a, &b).unwrap();
    assert!((c - 100.0).abs() < 1e-9, "{c}");
    assert!(crossover(&ns, &a, &a.iter().map(|v| v * 2.0).collect::<Vec<_>>()).is_none());
}

#[test]
fn alpha_of_jitter_and_white_noise() {
    let params = SpectrumParams {
        kmax: 128,
        realizations: 32,
        seed: 1,
        ..Default::default()
    };
    let jitter = estimate(&Jitter::new(2).unwrap(), 4096, &params).unwrap();
    let fit = fit_alpha(&jitter.radial, 0.0, 0.3).unwrap();
    assert!((fit.slope - 2.0).abs() < 0.15, "{fit:?}");
    let random = estimate(&Random::new(2).unwrap(), 4096, &params).unwrap();
    let fit = fit_alpha(&random.radial, 0.0, 0.3).unwrap();
    assert!(fit.slope.abs() < 4.0 * fit.stderr + 0.05, "{fit:?}");
}

#[test]
fn measured_jitter_slope_agrees_with_the_predicted_slope() {
    // Over N = 16…1024 the exact (lattice-form) slope is not yet the asymptotic -1.5; the
    // Monte Carlo slope's 99% interval must contain the exact one.
    let f = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let ns = [16usize, 64, 256, 1024];
    let params = McParams {
        patterns: 4000,
        seed: 12,
        ..Default::default()
    };
    let mut mc = Vec::new();
    let mut rel = Vec::new();
    let mut exact = Vec::new();
    for &n in &ns {
        let r = empirical_variance(&Jitter::new(2).unwrap(), &f, n, &params).unwrap();
        rel.push((r.ci_high / r.ci_low).ln() / (2.0 * Z_99));
        mc.push(r.variance);
        exact.push(
            predict_lattice(&f, LatticeSource::Closed(ClosedForm::Jitter), n, 400)
                .unwrap()
                .variance,
        );
    }
    let x: Vec<f64> = ns.iter().map(|&n| n as f64).collect();
    let measured = loglog_slope(&x, &mc, Some(&rel)).unwrap();
    let predicted = loglog_slope(&x, &exact, None).unwrap().slope;
    assert!(
        measured.ci.0 <= predicted && predicted <= measured.ci.1,
        "{measured:?} vs {predicted}"
    );
    assert!((predicted + 1.5).abs() < 0.05);
}
