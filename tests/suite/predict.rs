//! Predictions, each against an independent route.

use specvar::integrand::*;
use specvar::predict::*;
use specvar::randomization::Randomization;
use specvar::sampler::*;
use specvar::spectrum::*;

use crate::common;

fn disk() -> Ball {
    Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()
}

#[test]
fn white_noise_polar_form_is_exact_with_the_dc_term() {
    for d in 1..=3 {
        let fs: Vec<Box<dyn Integrand>> = vec![
            Box::new(Ball::new(0.25, vec![0.5; d], 1.0).unwrap()),
            Box::new(Ball::new(0.2, vec![0.4; d], 2.2568).unwrap()),
            Box::new(Gaussian::new(0.1, vec![0.5; d], 1.0).unwrap()),
        ];
        for f in &fs {
            for n in [1, 7, 100, 4096] {
                let p = predict_polar(
                    f.as_ref(),
                    &SpectrumSource::Closed(ClosedForm::WhiteNoise),
                    n,
                    &PolarParams::default(),
                )
                .unwrap();
                let exact = (f.spectral_energy() - f.spectral_integral().powi(2)) / n as f64;
                assert!(
                    (p.variance / exact - 1.0).abs() < common::QUADRATURE,
                    "{} n={n}",
                    f.label()
                );
            }
        }
    }
    // Without the DC term white noise would come out as ∫f²/N: 24% above the truth for the disk.
    let p = predict_polar(
        &disk(),
        &SpectrumSource::Closed(ClosedForm::WhiteNoise),
        64,
        &PolarParams::default(),
    )
    .unwrap();
    assert!(((p.variance + p.dc_term) / p.variance - 1.0 - 0.2440).abs() < 1e-3);
}

#[test]
fn jitter_polar_form_equals_lattice_form_to_1e_6() {
    let cases: Vec<(Box<dyn Integrand>, Vec<usize>, usize)> = vec![
        (Box::new(disk()), vec![16, 64, 256], 400),
        (
            Box::new(Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap()),
            vec![16, 64, 256],
            200,
        ),
        (
            Box::new(Ball::new(0.25, vec![0.5], 1.0).unwrap()),
            vec![4, 16, 64],
            20000,
        ),
        (
            Box::new(Gaussian::new(0.1, vec![0.5], 1.0).unwrap()),
            vec![4, 16, 64],
            2000,
        ),
        (
            Box::new(Ball::new(0.25, vec![0.5; 3], 1.0).unwrap()),
            vec![64],
            48,
        ),
        (
            Box::new(Gaussian::new(0.1, vec![0.5; 3], 1.0).unwrap()),
            vec![64, 512],
            48,
        ),
    ];
    for (f, ns, kmax) in &cases {
        for &n in ns {
            let polar = predict_polar(
                f.as_ref(),
                &SpectrumSource::Closed(ClosedForm::Jitter),
                n,
                &PolarParams::default(),
            )
            .unwrap();
            let lattice = predict_lattice(
                f.as_ref(),
                &SpectrumSource::Closed(ClosedForm::Jitter),
                n,
                *kmax,
            )
            .unwrap();
            let rel = (polar.variance / lattice.variance - 1.0).abs();
            assert!(
                rel < 1e-6,
                "{} n={n}: {} vs {} ({rel:e})",
                f.label(),
                polar.variance,
                lattice.variance
            );
        }
    }
}

/// The disk of radius 1/4, the reference case of the talk, must land within 1%. The Gaussian probes only the few
/// lowest rings at large N, where the estimate is noisy: it must land within 1% or within 4
/// standard errors propagated from the rings, whichever is larger.
#[test]
fn jitter_with_a_spectrum_estimated_at_4096_is_within_one_percent() {
    let params = SpectrumParams {
        kmax: 320,
        realizations: 64,
        seed: 11,
        engine: Engine::fast(),
        bin_width: 1.0,
        budget: Default::default(),
    };
    let est = estimate(&Jitter::new(2).unwrap(), 4096, &params).unwrap();
    for f in [
        Box::new(disk()) as Box<dyn Integrand>,
        Box::new(Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap()),
    ] {
        for n in [16, 64, 256, 1024] {
            let estimated = predict_polar(
                f.as_ref(),
                &SpectrumSource::Estimated(&est),
                n,
                &PolarParams::default(),
            )
            .unwrap();
            let closed = predict_polar(
                f.as_ref(),
                &SpectrumSource::Closed(ClosedForm::Jitter),
                n,
                &PolarParams::default(),
            )
            .unwrap();
            let rel = (estimated.variance / closed.variance - 1.0).abs();
            let allowed = if f.decay_exponent().is_finite() {
                0.01
            } else {
                0.01f64.max(common::Z_LOOSE * estimated.budget.spectrum_noise / closed.variance)
            };
            assert!(
                rel < allowed,
                "{} n={n}: {rel:.4} (allowed {allowed:.4})",
                f.label()
            );
            assert!(estimated.budget.spectrum_noise > 0.0);
        }
    }
}

#[test]
fn corner_areas_add_up_to_the_disk() {
    let (c, r) = ([0.5, 0.5], 0.25);
    let whole = common::rect_area(0.0, 1.0, 0.0, 1.0, c, r);
    assert!((whole - std::f64::consts::PI / 16.0).abs() < 1e-15);
    let quarter = common::rect_area(0.5, 1.0, 0.5, 1.0, c, r);
    assert!((quarter - std::f64::consts::PI / 64.0).abs() < 1e-15);
    // A strip [0.5, 0.6] × everything: ∫ 2√(r² - t²) over t ∈ [0, 0.1].
    let strip = common::rect_area(0.5, 0.6, 0.0, 1.0, c, r);
    let exact = 0.1 * (r * r - 0.01f64).sqrt() + r * r * (0.1f64 / r).asin();
    assert!((strip - exact).abs() < 1e-15);
}

#[test]
fn jitter_matches_the_geometric_variance_without_fourier() {
    for m in [4usize, 8] {
        let coarse = common::geometric_jitter_variance(0.25, [0.5, 0.5], m, 128);
        let fine = common::geometric_jitter_variance(0.25, [0.5, 0.5], m, 256);
        let fourier = predict_lattice(
            &disk(),
            &SpectrumSource::Closed(ClosedForm::Jitter),
            m * m,
            400,
        )
        .unwrap();
        // The offset quadrature's own convergence sets the tolerance.
        let tolerance = 10.0 * (fine - coarse).abs() + 1e-6 * fine;
        assert!(
            (fourier.variance - fine).abs() < tolerance,
            "m={m}: fourier {} geometric {fine} (coarse {coarse})",
            fourier.variance
        );
    }
}

/// The bias is `μ_N - I` exactly; the spectral sum over the regular grid's replicas, with the
/// torus coefficients of the truncated Gaussian, converges to it. For a centred Gaussian the
/// faces carry `exp(-12.5) = 3.7e-6` of its height, so the replica sum's terms fall like
/// `3.7e-6 / (2π m q)²` after the ±q pairing on each of the d axis lines, and beyond the last
/// shell Q (512, 128, 32 in 1D, 2D, 3D) they leave at most `2 d · 3.7e-6 / ((2πm)² Q)`.
#[test]
fn regular_grid_bias_is_exact_and_its_spectral_sum_converges_to_it() {
    for d in 1..=3 {
        let g = Gaussian::new(0.1, vec![0.5; d], 1.0).unwrap();
        for m in [3usize, 4, 5, 8] {
            let n = m.pow(d as u32);
            let points = Regular::new(d).unwrap().sample(n, 0, 0).unwrap();
            let mu: f64 = points.points().map(|x| g.eval(x)).sum::<f64>() / n as f64;
            let b = regular_grid_bias(&g, n).unwrap();
            assert!((b.bias - (mu - g.integral())).abs() <= common::ROUNDING * mu.abs());
            let shells = [512.0, 128.0, 32.0][d - 1];
            let bound = 2.0 * d as f64 * 3.7e-6
                / ((2.0 * std::f64::consts::PI * m as f64).powi(2) * shells);
            assert!(
                b.remainder.abs() < bound,
                "d={d} m={m}: {b:?} (bound {bound:e})"
            );
        }
    }
}

/// The same for any fixed pattern and its own spectrum on |k_i| ≤ 24: a Gaussian of σ = 0.08
/// has `|f̂|` below 1e-30 of its peak beyond |k| = 21 and face values of exp(-19.5) = 3.4e-9 of
/// its height, whose 1/k coefficients beyond the lattice leave at most about 1e-10.
#[test]
fn bias_of_any_fixed_pattern_is_exact_and_its_spectral_sum_agrees() {
    let g = Gaussian::new(0.08, vec![0.5, 0.5], 2.0).unwrap();
    for r in 0..3 {
        let points = Jitter::new(2).unwrap().sample(36, 4, r).unwrap();
        let mu: f64 = points.points().map(|x| g.eval(x)).sum::<f64>() / 36.0;
        let b = bias_of_pattern(&g, &points, 24).unwrap();
        assert!((b.bias - (mu - g.integral())).abs() <= common::ROUNDING * mu.abs());
        assert!(b.remainder.abs() < 1e-10, "{b:?}");
    }
}

#[test]
fn lattice_form_accepts_an_estimated_spectrum_at_the_target_n() {
    let params = SpectrumParams {
        kmax: 40,
        realizations: 64,
        seed: 3,
        ..Default::default()
    };
    let est = estimate(&Jitter::new(2).unwrap(), 64, &params).unwrap();
    let g = Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap();
    let from_estimate = predict_lattice(&g, &SpectrumSource::Estimated(&est), 64, 40).unwrap();
    let closed = predict_lattice(&g, &SpectrumSource::Closed(ClosedForm::Jitter), 64, 40).unwrap();
    // Standard error of Σ w_k P_k: from the per-frequency standard errors, with P(k) = P(-k)
    // fully correlated (hence the factor 2 on each half).
    let lattice = est.lattice.lattice;
    let var: f64 = (0..lattice.len())
        .filter(|&i| i != lattice.dc_index())
        .map(|i| {
            let k = lattice.frequency(i);
            let w = g.fourier(&[k[0] as f64, k[1] as f64]).norm_sqr();
            2.0 * (w * est.lattice.stderr[i]).powi(2)
        })
        .sum();
    let se = var.sqrt() / 64.0;
    assert!(
        (from_estimate.variance - closed.variance).abs() < common::Z_STRICT * se,
        "{} vs {} ± {se}",
        from_estimate.variance,
        closed.variance
    );
    assert!(predict_lattice(&g, &SpectrumSource::Estimated(&est), 100, 40).is_err());
}

#[test]
fn bad_prediction_requests_are_errors() {
    assert!(predict_polar(
        &disk(),
        &SpectrumSource::Closed(ClosedForm::Jitter),
        0,
        &PolarParams::default()
    )
    .is_err());
    assert!(regular_grid_bias(&disk(), 15).is_err());
    let p = Random::new(3).unwrap().sample(10, 0, 0).unwrap();
    assert!(bias_of_pattern(&disk(), &p, 4).is_err());
}

/// A user's own integrand in 4D: every prediction route refuses it with an error (the spectra
/// exist in 1 to 3 dimensions), and none panics.
#[test]
fn an_integrand_of_dimension_four_is_an_error_not_a_panic() {
    struct Box4;
    impl Integrand for Box4 {
        fn kind(&self) -> IntegrandKind {
            IntegrandKind::Ball
        }
        fn label(&self) -> String {
            "4D".into()
        }
        fn is_isotropic(&self) -> bool {
            true
        }
        fn dimension(&self) -> usize {
            4
        }
        fn eval(&self, _: &[f64]) -> f64 {
            1.0
        }
        fn integral(&self) -> f64 {
            1.0
        }
        fn integral_of_square(&self) -> f64 {
            1.0
        }
        fn fourier(&self, _: &[f64]) -> num_complex::Complex64 {
            num_complex::Complex64::new(0.0, 0.0)
        }
        fn coefficient(&self, _: &[i64]) -> num_complex::Complex64 {
            num_complex::Complex64::new(0.0, 0.0)
        }
        fn projection_energy(&self, _: usize) -> f64 {
            1.0
        }
        fn autocorrelation_beyond(&self, _: f64) -> Option<f64> {
            None
        }
        fn spectral_integral(&self) -> f64 {
            1.0
        }
        fn spectral_energy(&self) -> f64 {
            1.0
        }
        fn radial_power(&self, _: f64) -> f64 {
            0.0
        }
        fn decay_exponent(&self) -> f64 {
            f64::INFINITY
        }
        fn panel_width(&self) -> f64 {
            1.0
        }
        fn negligible_beyond(&self) -> f64 {
            1.0
        }
    }
    let f = Box4;
    let jitter = Jitter::new(4).unwrap();
    assert!(Problem::new(&jitter, &f, 16).is_err());
    let closed = SpectrumSource::Closed(ClosedForm::Jitter);
    assert!(predict_polar(&f, &closed, 16, &PolarParams::default()).is_err());
    assert!(predict_lattice(&f, &closed, 16, 4).is_err());
    assert!(regular_grid_bias(&f, 16).is_err());
    let points = jitter.sample(16, 0, 0).unwrap();
    assert!(bias_of_pattern(&f, &points, 4).is_err());
}

#[test]
fn integrands_predicted_together_get_what_each_gets_alone() {
    // With the lattice and the realizations fixed, sharing the patterns changes nothing: each
    // integrand's per-pattern sums are the same numbers.
    let poisson = PoissonDisk::new(2).unwrap();
    let wide = Gaussian::new(0.3, vec![0.3, 0.6], 1.0).unwrap();
    let d = disk();
    let params = PredictParams {
        kmax: Some(24),
        realizations: Some(12),
        ..PredictParams::default()
    };
    let problems = [
        Problem::new(&poisson, &d, 64)
            .unwrap()
            .with_randomization(Randomization::Shift),
        Problem::new(&poisson, &wide, 64)
            .unwrap()
            .with_randomization(Randomization::Shift),
    ];
    let together = predict_many(&problems, &params, &specvar::progress::Silent).unwrap();
    for (p, alone) in problems.iter().zip(&together) {
        let single = predict(p, &params).unwrap();
        assert_eq!(single.variance.to_bits(), alone.variance.to_bits());
        assert_eq!(single.budget, alone.budget);
    }
    // Closed forms go their own way, one by one.
    let jitter = Jitter::new(2).unwrap();
    let closed = [
        Problem::new(&jitter, &d, 64)
            .unwrap()
            .with_randomization(Randomization::Shift),
        Problem::new(&jitter, &wide, 64)
            .unwrap()
            .with_randomization(Randomization::Shift),
    ];
    let both = predict_many(
        &closed,
        &PredictParams::default(),
        &specvar::progress::Silent,
    );
    for (p, q) in closed.iter().zip(both.unwrap()) {
        assert_eq!(
            predict(p, &PredictParams::default()).unwrap().variance,
            q.variance
        );
    }
}

#[test]
fn integrands_predicted_together_must_share_their_patterns() {
    let (a, b) = (PoissonDisk::new(2).unwrap(), PoissonDisk::new(2).unwrap());
    let d = disk();
    let mixed = [
        Problem::new(&a, &d, 64)
            .unwrap()
            .with_randomization(Randomization::Shift),
        Problem::new(&b, &d, 64)
            .unwrap()
            .with_randomization(Randomization::Shift),
    ];
    assert!(predict_many(
        &mixed,
        &PredictParams::default(),
        &specvar::progress::Silent
    )
    .is_err());
    let sizes = [
        Problem::new(&a, &d, 64)
            .unwrap()
            .with_randomization(Randomization::Shift),
        Problem::new(&a, &d, 256)
            .unwrap()
            .with_randomization(Randomization::Shift),
    ];
    assert!(predict_many(
        &sizes,
        &PredictParams::default(),
        &specvar::progress::Silent
    )
    .is_err());
}

/// Beyond a thousand oscillations the polar form integrates a ball's power through its
/// modulus–phase mean and bounds the oscillation; where following every oscillation is still
/// affordable, the two must agree within the sum of their budgets, in 1D to 3D, for splits
/// from 16 to 256 panels.
#[test]
fn the_polar_form_by_the_mean_agrees_with_every_oscillation_followed() {
    for d in 1..=3usize {
        let ball = Ball::new(0.25, vec![0.5; d], 1.0).unwrap();
        // Sizes where following every oscillation (the reference) takes seconds, not minutes.
        let counts: &[usize] = match d {
            1 => &[256],
            2 => &[4096],
            _ => &[512],
        };
        for &n in counts {
            let jitter = SpectrumSource::Closed(ClosedForm::Jitter);
            let every = PolarParams {
                max_panels: usize::MAX,
                ..PolarParams::default()
            };
            let exact = predict_polar(&ball, &jitter, n, &every).unwrap();
            for max_panels in [16, 64, 256] {
                let params = PolarParams {
                    max_panels,
                    ..PolarParams::default()
                };
                let split = predict_polar(&ball, &jitter, n, &params).unwrap();
                let gap = (split.variance - exact.variance).abs();
                let allowed = split.budget.half_width(0.0) + exact.budget.half_width(0.0);
                assert!(
                    gap <= allowed,
                    "d = {d}, N = {n}, {max_panels} panels: {:e} against {:e} (gap {gap:e}, \
                     budgets {allowed:e})",
                    split.variance,
                    exact.variance
                );
                // Informative once the split is a few hundred panels out (the default is 1024).
                if max_panels >= 256 {
                    assert!(split.budget.half_width(0.0) < 1e-2 * split.variance);
                }
            }
        }
    }
}

/// Jitter at N = 10^12 answers at once (the strata's tent in space), and its value continues
/// the N^-1.5 law of the disk from N = 2^20 (the next term of the expansion is of relative
/// order N^-1/2).
#[test]
fn jitter_at_a_trillion_points_continues_its_rate() {
    let disk = disk();
    let jitter = Jitter::new(2).unwrap();
    let at = |n: usize| {
        predict(
            &Problem::new(&jitter, &disk, n)
                .unwrap()
                .with_randomization(Randomization::Shift),
            &PredictParams::default(),
        )
        .unwrap()
    };
    let (small, huge) = (at(1 << 20), at(1_000_000_000_000));
    assert!(huge.reason.contains("strata's tent"), "{}", huge.reason);
    let ratio = (1e12 / (1u64 << 20) as f64).powf(-1.5);
    let extrapolated = small.variance * ratio;
    assert!(
        (huge.variance / extrapolated - 1.0).abs() < 1e-2,
        "{:e} against {extrapolated:e}",
        huge.variance
    );
    assert!(huge.budget.half_width(2.576) < 1e-3 * huge.variance);
}

/// In 1D, homogenized jitter on an interval has the variance `1/(3N²)` exactly (each end lies in
/// a stratum it covers a uniform fraction p of, and `E[p(1 − p)] = 1/6`): the default
/// prediction holds it within its budget at every N, up to a trillion points.
#[test]
fn jitter_on_an_interval_is_one_third_over_n_squared_at_any_n() {
    let interval = Ball::new(0.25, vec![0.5], 1.0).unwrap();
    let jitter = Jitter::new(1).unwrap();
    for n in [64usize, 4096, 1 << 20, 1 << 32, 1_000_000_000_000] {
        let p = predict(
            &Problem::new(&jitter, &interval, n)
                .unwrap()
                .with_randomization(Randomization::Shift),
            &PredictParams::default(),
        )
        .unwrap();
        let exact = 1.0 / (3.0 * (n as f64).powi(2));
        let gap = (p.variance - exact).abs();
        assert!(
            gap <= p.budget.half_width(0.0),
            "N = {n}: {:e} against {exact:e} by the {}",
            p.variance,
            p.route
        );
        assert!(
            gap < 1e-5 * exact,
            "N = {n}: {:e} against {exact:e}",
            p.variance
        );
    }
}

/// Jitter as drawn on a Gaussian at `m × m = 10^12` strata against the expansion of the
/// per-stratum sum in the cell width `h = 1/m`, an independent route: for `f = g(x) g(y)`,
/// `Σ_c V_c = W W' + W M' + M W'` with `W = Σ_i Var_i g = (h/12) ∫ g'² (1 + O(h²))` and
/// `M = Σ_i ḡ_i² = m ∫ g² (1 + O(h²))`, both integrals closed forms by `erf`; at `h = 10^-6`
/// the expansion is exact to `10^-11`. The sum taken as the difference of the cells' second
/// moments and squared means keeps only `W/M ~ 10^-12` of its digits: off by 3e-4 there.
#[test]
fn jitter_on_a_gaussian_at_a_trillion_strata_meets_its_expansion() {
    let (sigma, centre) = (0.2, [0.5, 0.3]);
    let gaussian = Gaussian::new(sigma, centre.to_vec(), 1.0).unwrap();
    let jitter = Jitter::new(2).unwrap();
    let m = 1_000_000usize;
    let p = predict(
        &Problem::new(&jitter, &gaussian, m * m).unwrap(),
        &PredictParams::default(),
    )
    .unwrap();
    // ∫_0^1 g² and ∫_0^1 g'² for g = exp(−(x − c)²/(2σ²)), with u = x − c:
    // ∫ e^{−u²/σ²} = (σ√π/2) erf(u/σ), ∫ (u²/σ⁴) e^{−u²/σ²} = [(σ√π/2) erf(u/σ) − u e^{−u²/σ²}]/(2σ²).
    let axis = |c: f64| {
        let root = sigma * std::f64::consts::PI.sqrt() / 2.0;
        let square = |u: f64| root * libm::erf(u / sigma);
        let slope = |u: f64| root * libm::erf(u / sigma) - u * (-u * u / sigma.powi(2)).exp();
        let (lo, hi) = (-c, 1.0 - c);
        let mean_square = m as f64 * (square(hi) - square(lo));
        let within = (slope(hi) - slope(lo)) / (2.0 * sigma * sigma) / (12.0 * m as f64);
        (mean_square, within)
    };
    let ((mx, wx), (my, wy)) = (axis(centre[0]), axis(centre[1]));
    let expected = (wx * wy + wx * my + mx * wy) / (m as f64).powi(4);
    let gap = (p.variance - expected).abs();
    assert!(
        gap <= p.budget.half_width(0.0) + 1e-10 * expected,
        "{:e} against {expected:e} ± {:e}",
        p.variance,
        p.budget.half_width(0.0)
    );
    assert!(
        gap < 1e-9 * expected,
        "{:e} against {expected:e}",
        p.variance
    );
    // The budget informs: its bound is far below the value.
    assert!(p.budget.half_width(2.576) < 1e-5 * p.variance);
}

/// Jitter as drawn in 1D on a Gaussian at `N = 10^12` strata, whose cells are too many to
/// visit, against the leading term of the per-stratum sum's expansion in `h = 1/N`:
/// `(1/N²) Σ_c V_c = (h³/12) ∫_0^1 g'² (1 + O(h²))`, the integral here by Simpson's rule on
/// `2·10^4` panels (an error below `10^-15` of it), not by the closed form the route uses.
#[test]
fn jitter_in_one_dimension_at_a_trillion_strata_is_its_expansion() {
    let (sigma, centre) = (0.15, 0.35);
    let gaussian = Gaussian::new(sigma, vec![centre], 1.0).unwrap();
    let jitter = Jitter::new(1).unwrap();
    let n = 1_000_000_000_000usize;
    let p = predict(
        &Problem::new(&jitter, &gaussian, n).unwrap(),
        &PredictParams::default(),
    )
    .unwrap();
    let slope_squared = |x: f64| {
        let u = x - centre;
        (u / (sigma * sigma)).powi(2) * (-u * u / (sigma * sigma)).exp()
    };
    let panels = 20_000;
    let w = 1.0 / panels as f64;
    let simpson: f64 = (0..panels)
        .map(|i| {
            let a = i as f64 * w;
            w / 6.0 * (slope_squared(a) + 4.0 * slope_squared(a + w / 2.0) + slope_squared(a + w))
        })
        .sum();
    let h = 1.0 / n as f64;
    let expected = h * h * h / 12.0 * simpson;
    assert!(
        (p.variance - expected).abs() <= p.budget.half_width(0.0) + 1e-12 * expected,
        "{:e} against {expected:e} ± {:e}",
        p.variance,
        p.budget.half_width(0.0)
    );
    assert!(p.budget.half_width(2.576) < 1e-9 * p.variance);
}
