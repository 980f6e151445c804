//! The low band of a spectrum read from a fit over a disc of frequencies (`LowBand`), against
//! closed-form truths: unbiased where the spectrum is linear in `|k|²` on the disc (white
//! noise), far less noisy than the raw per-pattern sums there, and covered by its measured
//! model term where it is not (jitter, whose spectrum curves and is not isotropic).

mod common;

use common::Z_STRICT;
use specvar::integrand::{parse_integrand, Integrand};
use specvar::predict::{
    predict_lattice, predict_on_patterns, LatticePower, LowBand, PatternPlan, Prediction,
    SpectrumOrigin, SpectrumSource,
};
use specvar::progress::Silent;
use specvar::sampler::{Jitter, Random, Sampler, SamplerKind};
use specvar::spectrum::{Engine, Lattice, PatternSource, SpectrumParams};

const N: usize = 4096;
const KMAX: usize = 64;
const PATTERNS: usize = 64;

/// The lattice form of `f` on `PATTERNS` patterns of `sampler`, its low band fitted over a
/// disc of `radius`.
fn fitted(sampler: &dyn Sampler, f: &dyn Integrand, radius: f64) -> Prediction {
    let lattice = Lattice {
        dimension: 2,
        kmax: KMAX,
    };
    let power = LatticePower::of(f, lattice).unwrap();
    let plan = PatternPlan {
        initial: PATTERNS,
        target_noise: 0.0,
        max_realizations: PATTERNS,
        spectrum: SpectrumParams {
            kmax: KMAX,
            realizations: PATTERNS,
            seed: 11,
            engine: Engine::Auto,
            bin_width: 1.0,
            budget: Default::default(),
        },
        symmetric: false,
        low_band: Some(LowBand { radius }),
    };
    let source = PatternSource::Sampler {
        sampler,
        n: N,
        seed: 11,
    };
    predict_on_patterns(&power, source, &plan, &Silent).unwrap()
}

fn uses_low_band(p: &Prediction) -> bool {
    matches!(
        p.route.spectrum,
        SpectrumOrigin::Estimated {
            low_band: Some(_),
            ..
        }
    )
}

/// White noise's spectrum is 1 everywhere: the fit is exact, the estimate unbiased, and it
/// reads the low band from hundreds of frequencies where the raw sums read it from a few.
#[test]
fn white_noise_through_the_low_band_is_its_closed_form() {
    let sampler = Random::new(2).unwrap();
    for text in ["gaussian:sigma=0.2,c=0.2;0.7", "disk"] {
        let f = parse_integrand(text).unwrap().build(2).unwrap();
        let truth = (f.integral_of_square() - f.integral().powi(2)) / N as f64;
        let p = fitted(&sampler, f.as_ref(), 20.0);
        assert!(uses_low_band(&p), "{text}: {:?}", p.route);
        let raw = &p.alternatives[0];
        assert!(
            (p.variance - truth).abs() <= p.budget.half_width(Z_STRICT),
            "{text}: {} ± {:?} against {truth}",
            p.variance,
            p.budget
        );
        // At least three times less noise (measured: 4.4 on the disk, 5.7 on the Gaussian).
        assert!(
            3.0 * p.budget.spectrum_noise < raw.budget.spectrum_noise,
            "{text}: {:?} against the raw {:?}",
            p.budget,
            raw.budget
        );
    }
}

/// Jitter's spectrum `1 − sinc²(k₁/m) sinc²(k₂/m)` is neither linear in `|k|²` nor isotropic
/// beyond its first order: on a small disc the line fits, on a wide one it does not, and
/// whichever estimate is reported, its budget covers the closed form.
#[test]
fn a_curved_spectrum_is_covered_by_the_fits_model_term() {
    let sampler = Jitter::new(2).unwrap();
    let f = parse_integrand("gaussian:sigma=0.1")
        .unwrap()
        .build(2)
        .unwrap();
    let closed = SamplerKind::Jitter.closed_form(N, 2).unwrap();
    let truth = predict_lattice(f.as_ref(), &SpectrumSource::Closed(closed), N, KMAX)
        .unwrap()
        .variance;
    let mut reported = Vec::new();
    for radius in [8.0, 40.0] {
        let p = fitted(&sampler, f.as_ref(), radius);
        for q in std::iter::once((p.variance, p.budget))
            .chain(p.alternatives.iter().map(|a| (a.variance, a.budget)))
        {
            assert!(
                (q.0 - truth).abs() <= q.1.half_width(Z_STRICT),
                "R = {radius}: {} ± {:?} against {truth}",
                q.0,
                q.1
            );
        }
        reported.push(uses_low_band(&p));
    }
    // The wide disc's curvature shows in its model term, which leaves the raw sums the
    // narrower (without the term, the fit there is reported and 35 times too high).
    assert!(!reported[1]);
}

/// The long experiment behind the low band's figures (`cargo test --release -- --ignored`,
/// about 85 s on 2 cores): Poisson disk's default prediction at N = 4096, its low
/// band fitted, against Monte Carlo of the shifted estimator over 4000 independent patterns
/// (8 shifts each), on a Gaussian cut by the faces and on a disk; the two intervals must meet.
#[test]
#[ignore]
fn poisson_disk_through_the_low_band_meets_monte_carlo() {
    use specvar::montecarlo::{empirical_variance, McParams};
    use specvar::predict::{predict, PredictParams, Problem};
    use specvar::randomization::Randomization;
    let poisson = SamplerKind::PoissonDisk.build(2).unwrap();
    for text in ["gaussian:sigma=0.2,c=0.2;0.7", "disk"] {
        let f = parse_integrand(text).unwrap().build(2).unwrap();
        let p = predict(
            &Problem::new(poisson.as_ref(), f.as_ref(), N).unwrap(),
            &PredictParams::default(),
        )
        .unwrap();
        assert!(uses_low_band(&p), "{text}: {:?}", p.route);
        let m = empirical_variance(
            poisson.as_ref(),
            f.as_ref(),
            N,
            &McParams {
                patterns: 4000,
                shifts: 8,
                seed: 77,
                randomization: Randomization::Shift,
                ..Default::default()
            },
        )
        .unwrap();
        let band = p.budget.half_width(common::Z_LOOSE);
        assert!(
            p.variance - band <= m.ci_high && m.ci_low <= p.variance + band,
            "{text}: {} ± {band:.2e} against Monte Carlo [{}, {}]",
            p.variance,
            m.ci_low,
            m.ci_high
        );
    }
}
