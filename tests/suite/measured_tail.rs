//! The lattice form with a measured tail: where the white-tail bound is wide (samplers whose
//! projections are stratified, on integrands cut by the cube's faces), each pattern's error
//! beyond the lattice is measured at shifts. Checked against Monte Carlo of the shifted
//! estimator and against the white-tail prediction it replaces.

use crate::common;

use specvar::integrand::{Gaussian, Integrand, Polygon};
use specvar::montecarlo::{empirical_variance, McParams};
use specvar::predict::{predict, Form, PredictParams, Prediction, Problem, SpectrumOrigin};
use specvar::randomization::Randomization;
use specvar::sampler::SamplerKind;

fn halton_shifted(f: &dyn Integrand, n: usize, params: &PredictParams) -> Prediction {
    let sampler = SamplerKind::Halton.build(2).unwrap();
    let problem = Problem::new(sampler.as_ref(), f, n)
        .unwrap()
        .with_randomization(Randomization::Shift);
    predict(&problem, params).unwrap()
}

/// A fixed number of patterns keeps the test's time bounded; the noise is stated either way.
fn params() -> PredictParams {
    PredictParams {
        realizations: Some(96),
        ..Default::default()
    }
}

#[test]
fn halton_across_the_faces_agrees_with_monte_carlo() {
    let seam = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
    let square = Polygon::new(vec![[0.2, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]], 1.0).unwrap();
    for f in [&seam as &dyn Integrand, &square] {
        let n = 256;
        let p = halton_shifted(f, n, &params());
        assert_eq!(p.route.form, Form::Lattice);
        assert!(
            matches!(
                p.route.spectrum,
                SpectrumOrigin::MeasuredTail { patterns: 96, .. }
            ),
            "{}: {}",
            f.label(),
            p.route
        );
        assert_eq!(
            p.budget.truncation, 0.0,
            "nothing is modelled beyond the lattice"
        );
        // The white-tail prediction it replaces is kept as the alternative.
        assert!(p.alternatives.iter().any(|a| a.budget.truncation > 0.0));
        let sampler = SamplerKind::Halton.build(2).unwrap();
        let mc = empirical_variance(
            sampler.as_ref(),
            f,
            n,
            &McParams::pooled(SamplerKind::Halton, 20_000, 29, Randomization::Shift),
        )
        .unwrap();
        common::assert_agrees(&p, &mc, common::Z_LOOSE, &f.label());
    }
}

#[test]
fn the_same_bits_on_any_thread_count() {
    let seam = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
    let (measured, ..) = common::assert_thread_count_invariant(|| {
        let p = halton_shifted(
            &seam,
            256,
            &PredictParams {
                realizations: Some(8),
                ..Default::default()
            },
        );
        let measured = matches!(p.route.spectrum, SpectrumOrigin::MeasuredTail { .. });
        (measured, p.variance, p.budget.spectrum_noise)
    });
    assert!(measured, "the route under test");
}
