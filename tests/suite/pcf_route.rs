//! The pair-correlation route against the spectral route: the variance from the pattern's pair
//! correlation function and from its power spectrum are Fourier pairs, so they must agree
//! within their noise.

use crate::common;

use rayon::prelude::*;
use specvar::integrand::{Ball, Gaussian, Integrand};
use specvar::predict::{pair_correlation_variance, predict, PredictParams, Problem};
use specvar::randomization::Randomization;
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
        let sampler = common::cached_sampler(kind, 2);
        let count = if kind.is_costly() { 32 } else { 128 };
        let sets: Vec<_> = (0..count)
            .map(|r| sampler.sample(n, 7, r).unwrap())
            .collect();
        for f in [&disk as &dyn Integrand, &gaussian] {
            let pcf = pair_correlation_variance(f, &sets, 3.0).unwrap();
            let problem = Problem::new(sampler.as_ref(), f, n)
                .unwrap()
                .with_randomization(Randomization::Shift);
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
    // A polygon of more vertices than are cut into triangles has no autocorrelation.
    let many = (0..600)
        .map(|i| {
            let t = 2.0 * std::f64::consts::PI * i as f64 / 600.0;
            [0.5 + 0.3 * t.cos(), 0.5 + 0.3 * t.sin()]
        })
        .collect();
    let round = specvar::integrand::Polygon::new(many, 1.0).unwrap();
    assert!(
        pair_correlation_variance(&round, &sets, 3.0).is_err(),
        "no autocorrelation"
    );
}

/// The window's own autocorrelation `a_W(r) = ∫ f_W(x) f_W(x + r) dx`, with `f_W` zero outside
/// the window `[0, s)²` (no wrapping), for `f_W(x) = u_x^p` at `u = x / s` and `p` 0 (the
/// count) or 1 (a ramp that is largest on a face): per axis, the overlap of the window with its
/// translate, weighted by the ramp.
fn window_autocorrelation(power: i32, s: f64, r: [f64; 2]) -> f64 {
    let (tx, ty) = (r[0] / s, r[1] / s);
    if tx.abs() >= 1.0 || ty.abs() >= 1.0 {
        return 0.0;
    }
    let (a, b) = ((-tx).max(0.0), (1.0 - tx).min(1.0));
    let along_x = match power {
        0 => b - a,
        // ∫_a^b u (u + t) du
        _ => (b.powi(3) - a.powi(3)) / 3.0 + tx * (b * b - a * a) / 2.0,
    };
    s * s * along_x * (1.0 - ty.abs())
}

/// The pair-correlation route on a domain that is not a torus: a window `[0, 1/2)²` of a
/// stationary pattern (homogenized jitter of M points on the torus), rescaled to the unit
/// square, with the estimator `μ = Σ_{x_i ∈ W} f(x_i / s) / (M s²)` of `∫ f` (its count of
/// points is random). Öztireli's identity holds with the window's own autocorrelation `a_W`
/// (no wrapping) and the pair measure of the stationary pattern:
/// `Var[Σ f_W] = M ∫ f_W² + E Σ_{i≠j} a_W(x_i − x_j) − M² (∫ f_W)²`. The prediction from the
/// patterns' pair sums falls inside Monte Carlo's interval for the count (`f = 1`, whose
/// variance the torus formula, with N fixed, puts at 0) and for a ramp that is largest on a
/// face (which the torus would wrap into a jump).
#[test]
fn pair_correlation_route_on_a_window_of_a_stationary_pattern() {
    use specvar::montecarlo::{result_from_estimates, McParams, Z_99};
    use specvar::pointset::toroidal_delta;
    use specvar::sampler::{Homogenized, Jitter, Sampler};
    let (m, s) = (256usize, 0.5);
    let area = s * s;
    let process = Homogenized::new(Jitter::new(2).unwrap());
    for power in [0, 1] {
        // ∫_D f and ∫_D f² on the unit square for f = u_x^power.
        let (integral, square) = if power == 0 {
            (1.0, 1.0)
        } else {
            (0.5, 1.0 / 3.0)
        };
        let f_w =
            |x: &[f64]| -> Option<f64> { (x[0] < s && x[1] < s).then(|| (x[0] / s).powi(power)) };
        // Prediction: pair sums over 200 patterns (a seed of its own).
        let pair_sums: Vec<f64> = (0..200)
            .into_par_iter()
            .map(|r| {
                let p = process.sample(m, 21, r).unwrap();
                // An autocorrelation is even: each unordered pair once, counted twice.
                let mut total = 0.0;
                for i in 0..m {
                    for j in (i + 1)..m {
                        let (a, b) = (p.point(i), p.point(j));
                        let d = [toroidal_delta(a[0], b[0]), toroidal_delta(a[1], b[1])];
                        total += 2.0 * window_autocorrelation(power, s, d);
                    }
                }
                total
            })
            .collect();
        let k = pair_sums.len() as f64;
        let mean = pair_sums.iter().sum::<f64>() / k;
        let se = (pair_sums.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (k - 1.0) / k).sqrt();
        let (mf, int_w, sq_w) = (m as f64, area * integral, area * square);
        let scale = (mf * area).powi(2);
        let predicted = (mf * sq_w + mean - mf * mf * int_w * int_w) / scale;
        let predicted_se = se / scale;
        // Monte Carlo of the window estimator (another seed).
        let params = McParams {
            patterns: 20_000,
            ..Default::default()
        };
        let estimates: Vec<f64> = (0..params.patterns as u64)
            .into_par_iter()
            .map(|t| {
                let p = process.sample(m, 22, t).unwrap();
                p.points().filter_map(f_w).sum::<f64>() / (mf * area)
            })
            .collect();
        let mc = result_from_estimates(m, &params, &estimates, Some(integral)).unwrap();
        let mc_se = (mc.ci_high - mc.ci_low) / (2.0 * Z_99);
        let z = (predicted - mc.variance) / predicted_se.hypot(mc_se);
        println!(
            "window, f = u_x^{power}: predicted {predicted:.4e} ± {predicted_se:.1e}, Monte Carlo \
             {:.4e} [{:.4e}, {:.4e}], z = {z:.2}",
            mc.variance, mc.ci_low, mc.ci_high
        );
        // Two-sided 0.1% for each of the two integrands.
        assert!(z.abs() < 3.29, "z = {z}");
        // The window's count varies: far from the torus's fixed-N answer of 0.
        assert!(mc.ci_low > 0.0);
    }
}
