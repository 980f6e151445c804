//! The low band of a spectrum read from a fit over a disc of frequencies (`LowBand`), against
//! closed-form truths: unbiased where the spectrum is linear in `|k|²` on the disc (white
//! noise), far less noisy than the raw per-pattern sums there, and covered by its measured
//! model term where it is not (jitter, whose spectrum curves and is not isotropic).

use crate::common;

use common::Z_STRICT;
use specvar::integrand::{parse_integrand, Integrand};
use specvar::pointset::PointSet;
use specvar::predict::{
    predict_lattice, predict_on_patterns, LatticePower, LowBand, PatternPlan, Prediction,
    SpectrumOrigin, SpectrumSource,
};
use specvar::progress::Silent;
use specvar::rng::{realization_rng, Stream};
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

/// White noise modulated by a density wave of random phase, `ρ(x) = 1 + a cos 2π(x₁ + φ)`: a
/// stationary law whose expected spectrum is 1 except at `k = ±(1, 0)`, where it is
/// `1 + (N − 1) a²/4`. Both fits smooth the spike away (it is two frequencies of the disc's
/// thousands), so only the raw sums see it.
#[derive(Debug)]
struct DensityWave {
    amplitude: f64,
}

impl Sampler for DensityWave {
    fn name(&self) -> &'static str {
        "density wave"
    }
    fn dimension(&self) -> usize {
        2
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> specvar::Result<PointSet> {
        use rand::RngExt;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let phase: f64 = rng.random();
        let mut coords = Vec::with_capacity(2 * n);
        while coords.len() < 2 * n {
            let (x, y, accept): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
            let density = 1.0 + self.amplitude * (std::f64::consts::TAU * (x + phase)).cos();
            if accept * (1.0 + self.amplitude) < density {
                coords.extend([x, y]);
            }
        }
        PointSet::new(2, coords)
    }
}

/// A low band the fit's polynomial cannot describe (a spike at the lowest frequencies, as
/// Gaussian blue noise's climb back to white noise's) leaves the degree check blind; the
/// fit's departure from the raw sums, which are unbiased whatever the spectrum, shows it, and
/// the raw estimate is reported, within its budget of the closed form.
#[test]
fn a_low_band_the_fit_cannot_follow_is_read_raw() {
    let amplitude = 0.1;
    let f = parse_integrand("gaussian:sigma=0.2,c=0.2;0.7")
        .unwrap()
        .build(2)
        .unwrap();
    let lattice = Lattice {
        dimension: 2,
        kmax: KMAX,
    };
    let power = LatticePower::of(f.as_ref(), lattice).unwrap();
    let lowest = power.power[lattice.index(&[1, 0]).unwrap()];
    let spike = (N - 1) as f64 * amplitude * amplitude / 4.0;
    let white = f.integral_of_square() - f.integral().powi(2);
    let truth = (white + 2.0 * spike * lowest) / N as f64;
    let p = fitted(&DensityWave { amplitude }, f.as_ref(), 20.0);
    assert!(!uses_low_band(&p), "{} ± {:?}", p.variance, p.budget);
    assert!(
        (p.variance - truth).abs() <= p.budget.half_width(Z_STRICT),
        "{} ± {:?} against {truth}",
        p.variance,
        p.budget
    );
}

/// The long experiment behind the low band's figures (`cargo test --release -- --ignored`,
/// about 85 s on 2 cores): Poisson disk's default prediction at N = 4096, its low
/// band fitted, against Monte Carlo of the shifted estimator over 4000 independent patterns
/// (8 shifts each), on a Gaussian cut by the faces and on a disk; the two intervals must meet.
#[test]
#[ignore = "long: 4000 Poisson disk patterns of 4096 points against the low band, about 85 s on 2 cores"]
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
        common::assert_intervals_meet(&p, &m, common::Z_LOOSE, text);
    }
}
