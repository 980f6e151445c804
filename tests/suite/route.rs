//! The one-call prediction off the talk's setup: every route chosen by default, each against a
//! truth computed by an independent route, and the error budget's coverage measured.

use specvar::integrand::*;
use specvar::montecarlo::{empirical_variance, McParams, Z_99};
use specvar::predict::*;
use specvar::randomization::Randomization;
use specvar::sampler::*;
use specvar::spectrum::ClosedForm;

use crate::common;

fn predict_default(sampler: &dyn Sampler, f: &dyn Integrand, n: usize) -> Prediction {
    predict(
        &Problem::new(sampler, f, n)
            .unwrap()
            .with_randomization(Randomization::Shift),
        &PredictParams::default(),
    )
    .unwrap()
}

/// The trust table's closed-form rows: jitter on a centred Gaussian at N = 65536, on an
/// off-centre one at N = 256 (jumps at the faces), white noise on a wide Gaussian at N = 16,
/// each within its budget of the independent value (the budgets are exact tail bounds, so the
/// check allows them plus the independent route's own quadrature error of 1e-9).
#[test]
fn closed_form_rows_match_independent_values() {
    let cases: [(&[f64], f64, usize); 3] = [
        (&[0.5, 0.5], 0.1, 256),
        (&[0.1, 0.1], 0.1, 16),
        (&[0.3, 0.6], 0.1, 32),
    ];
    for (c, s, m) in cases {
        let f = Gaussian::new(s, c.to_vec(), 1.0).unwrap();
        let n = m * m;
        let p = predict_default(&Jitter::new(2).unwrap(), &f, n);
        assert_eq!(p.route.spectrum, SpectrumOrigin::Closed(ClosedForm::Jitter));
        let truth = common::jitter_variance_of_product(c, s, m);
        let allowed = p.budget.half_width(Z_99) + common::QUADRATURE * truth;
        assert!(
            (p.variance - truth).abs() <= allowed,
            "c={c:?} N={n}: {} vs {truth} (budget {allowed:e})",
            p.variance
        );
    }
    // White noise on σ = 0.3: (∫f² - I²)/N, the integrals by 2D Gauss–Legendre (40 panels of
    // 20 points per axis; the Gaussian is smooth, so this is exact to rounding).
    let f = Gaussian::new(0.3, vec![0.5, 0.5], 1.0).unwrap();
    let rule = specvar::quadrature::GaussLegendre::new(20);
    let integrate = |g: &dyn Fn(f64, f64) -> f64| {
        let mut total = 0.0;
        for i in 0..40 {
            for j in 0..40 {
                let (a, b) = (i as f64 / 40.0, j as f64 / 40.0);
                total +=
                    rule.integrate(a, a + 0.025, |x| rule.integrate(b, b + 0.025, |y| g(x, y)));
            }
        }
        total
    };
    let i0 = integrate(&|x, y| f.eval(&[x, y]));
    let i2 = integrate(&|x, y| f.eval(&[x, y]).powi(2));
    let truth = (i2 - i0 * i0) / 16.0;
    let p = predict_default(&Random::new(2).unwrap(), &f, 16);
    assert!(
        common::close(p.variance, truth, common::QUADRATURE),
        "{} vs {truth}",
        p.variance
    );
}

/// The disk of radius 0.45 at N = 16: the lattice form with jitter's closed form against the
/// geometric route (exact areas of the cells cut by the disk), where the polar form is off by
/// 7% because the disk's autocorrelation wraps around the torus, and is refused.
#[test]
fn wide_disk_with_jitter_matches_the_geometric_variance_and_refuses_the_polar_form() {
    let f = Ball::new(0.45, vec![0.5, 0.5], 1.0).unwrap();
    let jitter = Jitter::new(2).unwrap();
    let p = predict_default(&jitter, &f, 16);
    // The midpoint rule over the offsets converges like 1/q² on this piecewise smooth function:
    // ten times the change from q = 200 to 400 bounds its error.
    let coarse = common::geometric_jitter_variance(0.45, [0.5, 0.5], 4, 200);
    let truth = common::geometric_jitter_variance(0.45, [0.5, 0.5], 4, 400);
    let allowed = p.budget.half_width(Z_99) + 10.0 * (truth - coarse).abs();
    assert!(
        (p.variance - truth).abs() <= allowed,
        "{} vs {truth} ± {allowed:e}",
        p.variance
    );
    assert!(p.alternatives.is_empty());
    let polar = PredictParams {
        form: FormChoice::Polar,
        ..Default::default()
    };
    let refused = predict(
        &Problem::new(&jitter, &f, 16)
            .unwrap()
            .with_randomization(Randomization::Shift),
        &polar,
    );
    assert!(
        matches!(refused, Err(specvar::Error::OutsideValidity { .. })),
        "{refused:?}"
    );
}

/// Monte Carlo's 99% interval and the prediction's budget at 99%, combined: the two agree when
/// their difference is within `Z_99 √(noise² + mc_se²)` plus the prediction's bounds.
fn agrees_with_monte_carlo(p: &Prediction, mc: &specvar::montecarlo::McResult) -> bool {
    let mc_se = (mc.ci_high - mc.ci_low) / (2.0 * Z_99);
    let b = &p.budget;
    let allowed = Z_99 * b.spectrum_noise.hypot(mc_se) + b.quadrature + b.truncation + b.model;
    (p.variance - mc.variance).abs() <= allowed
}

/// The trust table's rows for samplers without a closed form (and the Latin hypercube, whose
/// closed form is new): each default prediction against Monte Carlo of the same sampler.
#[test]
fn estimated_rows_agree_with_monte_carlo() {
    let gaussian = Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap();
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let rows: Vec<(SamplerKind, &dyn Integrand, usize)> = vec![
        (SamplerKind::Sobol, &gaussian, 256),
        (SamplerKind::Halton, &gaussian, 256),
        (SamplerKind::LatinHypercube, &disk, 256),
        (SamplerKind::LatinHypercube, &gaussian, 256),
        (SamplerKind::PoissonDisk, &gaussian, 16),
        (SamplerKind::Ccvt, &gaussian, 64),
    ];
    for (kind, f, n) in rows {
        let sampler = common::cached_sampler(kind, 2);
        let p = predict_default(sampler.as_ref(), f, n);
        let mc = empirical_variance(
            sampler.as_ref(),
            f,
            n,
            &McParams::pooled(kind, 40_000, 91, Randomization::Shift),
        )
        .unwrap();
        assert!(
            agrees_with_monte_carlo(&p, &mc),
            "{kind} on {}: {p:?} vs {mc:?}",
            f.label()
        );
    }
}

/// The estimated route's budget covers the truth at its nominal rate: 40 independent
/// predictions of jitter's variance from its estimated spectrum (32 patterns each, the fewest
/// the route uses) against the closed form's exact value. At 99% about 0.4 misses are expected;
/// P(3 or more) = 0.8%.
#[test]
fn estimated_budget_covers_the_exact_value_at_its_nominal_rate() {
    let f = Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap();
    let jitter = Jitter::new(2).unwrap();
    let problem = Problem::new(&jitter, &f, 64)
        .unwrap()
        .with_randomization(Randomization::Shift);
    let exact = predict(&problem, &PredictParams::default())
        .unwrap()
        .variance;
    let misses = (0..40)
        .filter(|&seed| {
            let params = PredictParams {
                spectrum: SpectrumChoice::Estimated,
                realizations: Some(32),
                seed,
                ..Default::default()
            };
            !predict(&problem, &params).unwrap().covers(exact, Z_99)
        })
        .count();
    assert!(misses <= 2, "{misses} of 40 budgets miss the exact value");
}

/// Jitter at N = 65536 on the Gaussian: the closed form's lattice form is exact there, where a
/// spectrum rescaled from N = 4096 is refused (it would need frequencies below its first ring).
#[test]
fn large_n_takes_the_closed_form_and_refuses_to_extrapolate() {
    let f = Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap();
    let jitter = Jitter::new(2).unwrap();
    let p = predict_default(&jitter, &f, 65536);
    let truth = common::jitter_variance_of_product(&[0.5, 0.5], 0.1, 256);
    assert!(
        common::close(p.variance, truth, 1e-6),
        "{} vs {truth}",
        p.variance
    );
    let poisson = PoissonDisk::new(2).unwrap();
    let rescaled = PredictParams {
        form: FormChoice::Polar,
        reference_n: Some(4096),
        ..Default::default()
    };
    let refused = predict(
        &Problem::new(&poisson, &f, 16384)
            .unwrap()
            .with_randomization(Randomization::Shift),
        &rescaled,
    );
    assert!(
        matches!(refused, Err(specvar::Error::OutsideValidity { .. })),
        "{refused:?}"
    );
}

/// The routes the library chooses for the shifted estimator, sampler by sampler.
#[test]
fn every_sampler_gets_a_valid_route() {
    let f = Gaussian::new(0.1, vec![0.5, 0.5], 1.0).unwrap();
    for kind in SamplerKind::in_dimension(2) {
        let sampler = common::cached_sampler(kind, 2);
        let n = kind.nearest_count(64, 2);
        let p = predict_default(sampler.as_ref(), &f, n);
        // Owen-scrambled Sobol' under the shift: its gains averaged over shifts, in space;
        // the samplers with cells and no closed form: the lattice form with a measured tail.
        let form = match kind {
            // Sobol' and PMJ02 at a power of two: Owen's gains over shifts; CMJ and orthogonal
            // arrays (CMJ on p × p cells in 2D) on the Gaussian: the exact variance at each shift.
            SamplerKind::Sobol
            | SamplerKind::Pmj02
            | SamplerKind::Cmj
            | SamplerKind::OrthogonalArray => Form::Cells,
            _ => Form::Lattice,
        };
        assert_eq!(p.route.form, form, "{kind}");
        let strata = [SamplerKind::MultiJitter];
        if strata.contains(&kind) {
            assert!(
                matches!(p.route.spectrum, SpectrumOrigin::MeasuredTail { .. }),
                "{kind}: {}",
                p.route
            );
        }
        let closed = matches!(p.route.spectrum, SpectrumOrigin::Closed(_));
        assert_eq!(
            closed,
            kind.closed_form(n, 2).is_some(),
            "{kind}: {}",
            p.route
        );
        assert!(!p.reason.is_empty());
    }
    // In 1D too (the estimate's lattice no longer asks for a K beyond its limit).
    let disk = Ball::new(0.25, vec![0.5], 1.0).unwrap();
    let p = predict_default(&PoissonDisk::new(1).unwrap(), &disk, 64);
    assert!(p.variance > 0.0);
}

/// The regular grid summed in space against the lattice sum over its replicas `|q_i| ≤ Q`.
/// An off-centre Gaussian jumps at the faces, so its coefficients fall like 1/k on the axis
/// lines and the replica sum's tail like 1/Q: tail(Q) = 2 (S(2Q) - S(Q)); twice that is
/// allowed beside the spatial sum's rounding.
#[test]
fn regular_grid_in_space_equals_its_replica_sum() {
    let f = Gaussian::new(0.12, vec![0.45, 0.55], 1.0).unwrap();
    let replica_sum = |m: usize, q: i64| {
        let mut sum = 0.0;
        for q0 in -q..=q {
            for q1 in -q..=q {
                if (q0, q1) != (0, 0) {
                    sum += f.coefficient(&[q0 * m as i64, q1 * m as i64]).norm_sqr();
                }
            }
        }
        sum
    };
    for m in [4usize, 8, 16] {
        let (space, rounding) = regular_grid_variance(&f, m * m).unwrap().unwrap();
        let (s60, s120) = (replica_sum(m, 60), replica_sum(m, 120));
        let tail = 2.0 * (s120 - s60);
        let allowed = rounding + 2.0 * tail.abs() + common::ROUNDING * space;
        assert!(
            (space - (s120 + tail / 2.0)).abs() <= allowed,
            "m={m}: {space} vs {s120} + {tail:e}"
        );
    }
}

/// The rank-1 lattice's and the Kronecker sequence's sums in space (O(N) by their group and
/// lag structure) against the pattern's own double sum over all pairs (O(N²)): the same
/// quantity by two routes, to the rounding of the autocorrelation values they average.
#[test]
fn lattice_and_kronecker_sums_in_space_equal_the_pair_sum() {
    let f = Gaussian::new(0.12, vec![0.45, 0.55], 1.0).unwrap();
    let disk = Ball::new(0.3, vec![0.5, 0.5], 1.0).unwrap();
    for integrand in [&f as &dyn Integrand, &disk] {
        for kind in [
            SamplerKind::Korobov,
            SamplerKind::Fibonacci,
            SamplerKind::Kronecker,
        ] {
            let n = kind.nearest_count(300, 2);
            let sampler = common::cached_sampler(kind, 2);
            let points = sampler.sample(n, 0, 0).unwrap();
            let (pairs, r1) = pattern_shift_variance(integrand, &points).unwrap().unwrap();
            let (fast, r2) = match sampler.closed_form(n).unwrap() {
                ClosedForm::Rank1Lattice { generator } => {
                    rank1_lattice_variance(integrand, n, generator)
                        .unwrap()
                        .unwrap()
                }
                ClosedForm::Kronecker { alpha } => {
                    kronecker_variance(integrand, n, &alpha).unwrap().unwrap()
                }
                other => panic!("{other:?}"),
            };
            // Both routes average values of a_f, each good to ROUNDING relative; the
            // variance is that mean less I², so the error is relative to the mean.
            let mean = pairs + integrand.integral().powi(2);
            assert!(
                (pairs - fast).abs() <= r1 + r2 + common::ROUNDING * mean,
                "{kind}: {pairs} vs {fast}"
            );
            let p = predict_default(sampler.as_ref(), integrand, n);
            assert_eq!(
                p.variance, fast,
                "{kind}: the default route is the sum in space"
            );
        }
    }
}

/// Given sets under the shift are summed exactly over their pairs: a rank-1 lattice's, a
/// regular grid's and a Kronecker sequence's sets give their samplers' own exact sums over
/// lattice vectors or lags (another route to the same number), for a disk, an edge and a grid;
/// random sets agree with Monte Carlo of those sets under shifts.
#[test]
fn given_sets_under_the_shift_are_summed_over_their_pairs() {
    let pixel = GridIntegrand::new(5, 3, (0..15).map(|i| ((i * 3) % 7) as f64 * 0.2).collect())
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact);
    let integrands: Vec<Box<dyn Integrand>> = vec![
        Box::new(Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap()),
        Box::new(Polygon::edge(30.0, 0.4, 1.0).unwrap()),
        Box::new(pixel),
    ];
    for (kind, n) in [
        (SamplerKind::Fibonacci, 233),
        (SamplerKind::Regular, 256),
        (SamplerKind::Kronecker, 200),
    ] {
        let sampler = common::cached_sampler(kind, 2);
        let sets = [sampler.sample(n, 0, 0).unwrap()];
        for f in &integrands {
            let own = predict_default(sampler.as_ref(), f.as_ref(), n);
            let given = predict(
                &Problem::from_point_sets(&sets, f.as_ref())
                    .unwrap()
                    .with_randomization(Randomization::Shift),
                &PredictParams::default(),
            )
            .unwrap();
            assert!(
                matches!(given.route.spectrum, SpectrumOrigin::Pairs { sets: 1 }),
                "{:?}",
                given.route
            );
            let tolerance = own.budget.half_width(0.0) + given.budget.quadrature;
            assert!(
                (own.variance - given.variance).abs() <= tolerance,
                "{kind} {}: {} by its own route, {} over pairs",
                f.label(),
                own.variance,
                given.variance
            );
        }
    }
    let random = SamplerKind::Random.build(2).unwrap();
    let sets: Vec<_> = (0..24).map(|i| random.sample(64, 3, i).unwrap()).collect();
    let f = Polygon::new(vec![[0.1, 0.2], [0.8, 0.1], [0.4, 0.9]], 2.0).unwrap();
    let p = predict(
        &Problem::from_point_sets(&sets, &f)
            .unwrap()
            .with_randomization(Randomization::Shift),
        &PredictParams::default(),
    )
    .unwrap();
    let mc = &specvar::montecarlo::empirical_variances_of_sets(
        &sets,
        &[&f],
        &McParams::for_sets(24, 48_000, None, 7, Randomization::Shift),
        &specvar::progress::Silent,
    )
    .unwrap()[0];
    let z = p.z_beyond_bounds(mc);
    assert!(z.abs() < common::Z_STRICT, "{} vs {mc:?}", p.variance);
}

/// A disk on CCVT at N = 64: its slowly falling tail widens the lattice far beyond N^(1/d),
/// where each pattern's pairs cost less than its transform, so the default route sums each
/// pattern in space (exact for the pattern, nothing truncated). Its mean over the same
/// realizations equals each pattern's estimated lattice form plus its tail, so it must meet
/// both Monte Carlo of the estimator and the lattice estimate asked for explicitly, within
/// their budgets.
#[test]
fn a_jump_at_small_n_sums_each_pattern_in_space() {
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let ccvt = common::cached_sampler(SamplerKind::Ccvt, 2);
    let n = 64;
    let p = predict_default(ccvt.as_ref(), &disk, n);
    assert!(
        matches!(p.route.spectrum, SpectrumOrigin::PatternPairs { n: 64, .. }),
        "{}",
        p.route
    );
    assert_eq!(p.budget.truncation, 0.0);
    assert!(p.budget.spectrum_noise > 0.0 && p.budget.spectrum_noise < 0.05 * p.variance);
    let mc = empirical_variance(
        ccvt.as_ref(),
        &disk,
        n,
        &McParams::pooled(SamplerKind::Ccvt, 40_000, 92, Randomization::Shift),
    )
    .unwrap();
    assert!(agrees_with_monte_carlo(&p, &mc), "{p:?} vs {mc:?}");
    let lattice = predict(
        &Problem::new(ccvt.as_ref(), &disk, n)
            .unwrap()
            .with_randomization(Randomization::Shift),
        &PredictParams {
            spectrum: SpectrumChoice::Estimated,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(
        matches!(lattice.route.spectrum, SpectrumOrigin::Estimated { .. }),
        "{}",
        lattice.route
    );
    let allowed = lattice.budget.half_width(Z_99) + p.budget.half_width(Z_99);
    assert!(
        (p.variance - lattice.variance).abs() <= allowed,
        "pairs {p:?} against the lattice {lattice:?}"
    );
}
