//! Fixed patterns under a random digital shift (the Walsh form), each check against an
//! independent route: the enumeration of every shift where the integrand is constant on dyadic
//! cells, and Monte Carlo of the same estimator otherwise; and Owen's scrambling, which a
//! digital shift leaves unchanged; and random samplers drawn anew under a digital shift, by the
//! mean over patterns of each one's Walsh sum.

use crate::common;

use common::{ROUNDING, Z_STRICT};
use specvar::integrand::{Ball, Gaussian, GridIntegrand, Integrand, Polygon};
use specvar::montecarlo::{empirical_variance, McParams, McResult, Z_99};
use specvar::pointset::PointSet;
use specvar::predict::{predict, Form, FormChoice, PredictParams, Problem, SpectrumOrigin};
use specvar::randomization::{xor_digits, Randomization};
use specvar::sampler::SamplerKind;

/// An integrand constant on the 16 × 16 dyadic cells, with jumps at the faces.
fn dyadic_pixel() -> GridIntegrand {
    let values = (0..256)
        .map(|i| {
            let (x, y) = ((i % 16) as f64, (i / 16) as f64);
            if x + 0.6 * y < 13.0 {
                1.0 + 0.03 * x * y
            } else {
                0.1
            }
        })
        .collect();
    GridIntegrand::new(16, 16, values)
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact)
}

/// The variance over every digital shift of the top 4 digits per axis, which is the whole
/// variance for an integrand constant on the 16 × 16 dyadic cells: `x ⊕ Δ` keeps its cell's
/// digits as `x`'s XOR `Δ`'s, with no carry from the digits below.
fn enumerated_variance(f: &dyn Integrand, pattern: &PointSet) -> f64 {
    let integral = f.integral();
    let mut total = 0.0;
    for a in 0..16u64 {
        for b in 0..16u64 {
            let masks = [a << 49, b << 49];
            let mean = pattern
                .points()
                .map(|x| f.eval(&[xor_digits(x[0], masks[0]), xor_digits(x[1], masks[1])]))
                .sum::<f64>()
                / pattern.len() as f64;
            total += (mean - integral).powi(2);
        }
    }
    total / 256.0
}

#[test]
fn the_walsh_form_is_every_shift_where_the_integrand_is_dyadic() {
    let f = dyadic_pixel();
    let net = SamplerKind::SobolNet.build(2).unwrap();
    for n in [1, 16, 48, 64, 256, 1000] {
        let problem = Problem::new(net.as_ref(), &f, n).unwrap();
        assert_eq!(problem.randomization, Randomization::DigitalShift);
        let p = predict(&problem, &PredictParams::default()).unwrap();
        assert_eq!(p.route.form, Form::Walsh);
        // The remainder below the cells is zero: nothing is measured.
        assert_eq!(p.budget.spectrum_noise, 0.0);
        let truth = enumerated_variance(&f, &net.sample(n, 0, 0).unwrap());
        // A net that integrates the cells exactly leaves only the rounding of each mean.
        let floor = (ROUNDING * f.integral()).powi(2);
        assert!(
            (p.variance - truth).abs() <= p.budget.quadrature + ROUNDING * truth + floor,
            "N = {n}: {} vs {truth}",
            p.variance
        );
    }
    // Given sets of any law, each under its own shifts: the mean of their variances.
    let random = SamplerKind::Random.build(2).unwrap();
    let sets: Vec<PointSet> = (0..3).map(|i| random.sample(40, 9, i).unwrap()).collect();
    let problem = Problem::from_point_sets(&sets, &f)
        .unwrap()
        .with_randomization(Randomization::DigitalShift);
    let p = predict(&problem, &PredictParams::default()).unwrap();
    let truth = sets.iter().map(|s| enumerated_variance(&f, s)).sum::<f64>() / 3.0;
    assert!(
        (p.variance - truth).abs() <= p.budget.quadrature + ROUNDING * truth,
        "{} vs {truth}",
        p.variance
    );
}

/// Monte Carlo of the Sobol' net of `n` points under 20 000 digital shifts, keyed by `seed`.
fn net_under_digital_shifts(f: &dyn Integrand, n: usize, seed: u64) -> McResult {
    let net = SamplerKind::SobolNet.build(f.dimension()).unwrap();
    empirical_variance(
        net.as_ref(),
        f,
        n,
        &McParams::for_sampler(
            SamplerKind::SobolNet,
            20_000,
            None,
            seed,
            Randomization::DigitalShift,
        ),
    )
    .unwrap()
}

/// The unscrambled Sobol' net under digital shifts on integrands that are not dyadic (the
/// remainder below the tabulated cells measured), in 2D and 3D: the default prediction against
/// Monte Carlo of the same estimator, Bonferroni over the cases.
#[test]
fn the_walsh_form_agrees_with_monte_carlo_of_digital_shifts() {
    let cases: Vec<(Box<dyn Integrand>, usize)> = vec![
        (Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()), 16),
        (Box::new(Ball::new(0.45, vec![0.9, 0.1], 1.0).unwrap()), 256),
        (
            Box::new(Gaussian::new(0.3, vec![0.7, 0.2], 1.0).unwrap()),
            64,
        ),
        (
            Box::new(Gaussian::new(0.3, vec![0.7, 0.2], 1.0).unwrap()),
            1000,
        ),
        (Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap()), 256),
        (
            Box::new(Polygon::new(vec![[0.1, 0.2], [0.8, 0.1], [0.4, 0.9]], 2.0).unwrap()),
            128,
        ),
        (
            Box::new(Ball::new(0.3, vec![0.5, 0.4, 0.6], 1.0).unwrap()),
            64,
        ),
        (
            Box::new(Gaussian::new(0.15, vec![0.3; 3], 1.0).unwrap()),
            512,
        ),
    ];
    let z_family = common::inverse_normal_tail(0.01 / cases.len() as f64 / 2.0);
    let params = PredictParams {
        target_noise: 0.03,
        ..Default::default()
    };
    for (f, n) in cases {
        let d = f.dimension();
        let net = SamplerKind::SobolNet.build(d).unwrap();
        let p = predict(&Problem::new(net.as_ref(), f.as_ref(), n).unwrap(), &params).unwrap();
        assert!(
            p.budget.half_width(Z_99) < 0.2 * p.variance,
            "{d}D N = {n} {}: {:?}",
            f.label(),
            p.budget
        );
        let mc = net_under_digital_shifts(f.as_ref(), n, 3);
        common::assert_agrees(&p, &mc, z_family, &format!("{d}D N = {n} {}", f.label()));
    }
}

/// A Sobol' net of `2^m` points is a linear net, and a Gaussian or an axis-aligned rectangle a
/// product: the default prediction is the exact sum over the net's dual at every level (no
/// measured remainder, so no noise, and a quadrature bound far below the value), and Monte
/// Carlo of digital shifts agrees with it, Bonferroni over the cases.
#[test]
fn a_linear_net_on_a_product_is_summed_exactly() {
    let cases: Vec<(Box<dyn Integrand>, usize)> = vec![
        (
            Box::new(Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap()),
            4096,
        ),
        (
            Box::new(
                Polygon::new(vec![[0.2, 0.3], [0.7, 0.3], [0.7, 0.8], [0.2, 0.8]], 1.0).unwrap(),
            ),
            1024,
        ),
        (Box::new(Polygon::edge(90.0, 0.37, 1.0).unwrap()), 256),
        (
            Box::new(Gaussian::new(0.15, vec![0.3; 3], 1.0).unwrap()),
            2048,
        ),
    ];
    let z_family = common::inverse_normal_tail(0.01 / cases.len() as f64 / 2.0);
    for (f, n) in cases {
        let d = f.dimension();
        let what = format!("{d}D N = {n} {}", f.label());
        let net = SamplerKind::SobolNet.build(d).unwrap();
        let p = predict(
            &Problem::new(net.as_ref(), f.as_ref(), n).unwrap(),
            &PredictParams::default(),
        )
        .unwrap();
        assert!(
            matches!(p.route.spectrum, SpectrumOrigin::WalshNet(_)),
            "{what}: {}",
            p.route
        );
        assert_eq!(p.budget.spectrum_noise, 0.0, "{what}");
        assert!(
            p.budget.half_width(Z_99) < 1e-6 * p.variance,
            "{what}: {:?}",
            p.budget
        );
        let mc = net_under_digital_shifts(f.as_ref(), n, 5);
        common::assert_agrees(&p, &mc, z_family, &what);
    }
}

/// A digital shift of an Owen-scrambled net is again Owen's scrambling: the prediction is the
/// one as drawn, and Monte Carlo of the shifted estimator measures it.
#[test]
fn a_digital_shift_leaves_owen_scrambling_as_it_is() {
    let f = Gaussian::new(0.3, vec![0.7, 0.2], 1.0).unwrap();
    let sobol = SamplerKind::Sobol.build(2).unwrap();
    let problem = Problem::new(sobol.as_ref(), &f, 256).unwrap();
    let drawn = predict(&problem, &PredictParams::default()).unwrap();
    let shifted = predict(
        &problem.with_randomization(Randomization::DigitalShift),
        &PredictParams::default(),
    )
    .unwrap();
    assert_eq!(drawn.variance, shifted.variance);
    assert_eq!(shifted.randomization, Randomization::DigitalShift);
    let mc = empirical_variance(
        sobol.as_ref(),
        &f,
        256,
        &McParams::for_sampler(
            SamplerKind::Sobol,
            20_000,
            None,
            5,
            Randomization::DigitalShift,
        ),
    )
    .unwrap();
    let z = shifted.z_beyond_bounds(&mc);
    assert!(z.abs() < Z_STRICT, "{} vs {mc:?}", shifted.variance);
}

#[test]
fn routes_of_the_toroidal_shift_are_refused_under_a_digital_shift() {
    let f = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let net = SamplerKind::SobolNet.build(2).unwrap();
    let problem = Problem::new(net.as_ref(), &f, 64).unwrap();
    for params in [
        PredictParams {
            form: FormChoice::Polar,
            ..Default::default()
        },
        PredictParams {
            kmax: Some(40),
            ..Default::default()
        },
    ] {
        let e = predict(&problem, &params).unwrap_err().to_string();
        assert!(e.contains("Walsh"), "{e}");
    }
    // The toroidal shift of the same net is the lattice form's.
    let shifted = predict(
        &problem.with_randomization(Randomization::Shift),
        &PredictParams::default(),
    )
    .unwrap();
    assert_ne!(shifted.route.form, Form::Walsh);
}

/// Random samplers drawn anew under a digital shift (strata, N-rooks, Halton's permuted digits,
/// dart throwing): the mean over patterns of each one's Walsh sum meets Monte Carlo of 20000
/// patterns (5000 of dart throwing, whose drawing is most of the test's time), each under its
/// own shift, on a disk and a Gaussian cut by the faces (both on the same patterns; the
/// prediction's interval widened to `Z_STRICT`, ±25% at its 5% noise, where 5000 patterns'
/// 99% interval is about ±5%).
#[test]
fn drawn_patterns_under_a_digital_shift_meet_monte_carlo() {
    use specvar::montecarlo::empirical_variances;
    use specvar::progress::Silent;
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let bump = Gaussian::new(0.2, vec![0.2, 0.7], 1.0).unwrap();
    let fs: [&dyn Integrand; 2] = [&disk, &bump];
    let params = PredictParams {
        target_noise: 0.05,
        ..Default::default()
    };
    for kind in [
        SamplerKind::Jitter,
        SamplerKind::Cmj,
        SamplerKind::Halton,
        SamplerKind::PoissonDisk,
    ] {
        let sampler = kind.build(2).unwrap();
        let mc = McParams {
            patterns: if kind == SamplerKind::PoissonDisk {
                5_000
            } else {
                20_000
            },
            shifts: 1,
            seed: 17,
            randomization: Randomization::DigitalShift,
            ..Default::default()
        };
        let runs = empirical_variances(sampler.as_ref(), &fs, 64, &mc, &Silent).unwrap();
        for (f, m) in fs.iter().zip(runs) {
            let problem = Problem::new(sampler.as_ref(), *f, 64)
                .unwrap()
                .with_randomization(Randomization::DigitalShift);
            let p = predict(&problem, &params).unwrap();
            let what = format!("{kind} on {}", f.label());
            assert!(
                matches!(p.route.spectrum, SpectrumOrigin::Walsh(_)),
                "{what}: {}",
                p.route
            );
            assert_eq!(p.randomization, Randomization::DigitalShift);
            common::assert_intervals_meet(&p, &m, Z_STRICT, &what);
        }
    }
}
