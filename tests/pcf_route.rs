//! The pair-correlation route against the spectral route: the variance from the pattern's pair
//! correlation function and from its power spectrum are Fourier pairs, so they must agree
//! within their noise.

use specvar::integrand::{Ball, Gaussian, Integrand};
use specvar::predict::{pair_correlation_variance, predict, PredictParams, Problem};
use specvar::sampler::SamplerKind;

/// Three samplers × two integrands at N = 256. Each route has its own noise (the PCF's from
/// its patterns, the spectral prediction's from its own); the difference is compared with
/// their combined standard error at z = 3.29 (two-sided 0.1% each, 0.6% for the six), and the
/// PCF route's far field is checked against the `1/(N−1)` that jitter's partition of unity
/// gives exactly.
#[test]
fn pair_correlation_and_spectral_routes_agree() {
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let gaussian = Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap();
    let n = 256;
    for kind in [
        SamplerKind::Jitter,
        SamplerKind::PoissonDisk,
        SamplerKind::Ccvt,
    ] {
        let sampler = kind.build(2).unwrap();
        let count = if kind.is_costly() { 32 } else { 128 };
        let sets: Vec<_> = (0..count)
            .map(|r| sampler.sample(n, 7, r).unwrap())
            .collect();
        for f in [&disk as &dyn Integrand, &gaussian] {
            let pcf = pair_correlation_variance(f, &sets, 3.0).unwrap();
            let problem = Problem::new(sampler.as_ref(), f, n).unwrap();
            let spectral = predict(&problem, &PredictParams::default()).unwrap();
            let noise = pcf
                .budget
                .spectrum_noise
                .hypot(spectral.budget.spectrum_noise);
            let systematic = spectral.budget.quadrature + spectral.budget.truncation;
            let gap = (pcf.variance - spectral.variance).abs();
            assert!(
                gap <= 3.29 * noise + systematic,
                "{kind} {}: PCF {:.4e} ± {noise:.1e}, spectral {:.4e}",
                f.label(),
                pcf.variance,
                spectral.variance
            );
            assert!(
                pcf.budget.half_width(3.29) >= gap,
                "the PCF route's budget covers it"
            );
            if kind == SamplerKind::Jitter {
                let exact = 1.0 / (n as f64 - 1.0);
                assert!(
                    (pcf.far_field - exact).abs() < 0.05 * exact,
                    "{}",
                    pcf.far_field
                );
            }
        }
    }
}

#[test]
fn pair_correlation_route_refuses_what_it_cannot_do() {
    use specvar::sampler::{Random, Sampler};
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let sets: Vec<_> = (0..4)
        .map(|r| Random::new(2).unwrap().sample(64, 1, r).unwrap())
        .collect();
    assert!(
        pair_correlation_variance(&disk, &sets[..1], 3.0).is_err(),
        "one pattern"
    );
    assert!(pair_correlation_variance(&disk, &sets, 0.0).is_err());
    assert!(
        pair_correlation_variance(&disk, &sets, 4.0).is_err(),
        "beyond half the torus"
    );
    let edge = specvar::integrand::Polygon::edge(30.0, 0.5, 1.0).unwrap();
    assert!(
        pair_correlation_variance(&edge, &sets, 3.0).is_err(),
        "no autocorrelation"
    );
}
