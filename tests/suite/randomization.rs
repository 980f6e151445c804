//! The estimator a prediction is for, checked by Monte Carlo of the same estimator: where the
//! shifted routes hold for another randomization, the Monte Carlo of that randomization agrees
//! with them; where they do not, the prediction is refused and the Monte Carlo still runs.

use specvar::montecarlo::{empirical_variance, McParams};
use specvar::prelude::*;
use specvar::randomization::Randomization;
use specvar::sampler::draw_realizations;

/// How many combined standard errors a prediction may stand from Monte Carlo beyond its bounds
/// (the spectrum's noise and the Monte Carlo's 99% interval, read as standard errors).
const Z_LIMIT: f64 = 3.0;

fn agree(sampler: &dyn Sampler, f: &dyn Integrand, n: usize, r: Randomization, trials: usize) {
    let problem = Problem::new(sampler, f, n).unwrap().with_randomization(r);
    let params = PredictParams {
        target_noise: 0.02,
        ..PredictParams::default()
    };
    let p = predict(&problem, &params).unwrap();
    assert_eq!(p.randomization, r);
    // The reason says why the shifted route serves this estimator.
    assert!(
        p.reason.contains("the variance is the shifted one's"),
        "{}",
        p.reason
    );
    let mc = McParams {
        patterns: trials,
        seed: 17,
        randomization: r,
        ..McParams::default()
    };
    let m = empirical_variance(sampler, f, n, &mc).unwrap();
    assert_eq!(m.randomization, r);
    let z = p.z_beyond_bounds(&m);
    assert!(
        z.abs() <= Z_LIMIT,
        "{} {r}: predicted {:.4e}, measured {:.4e} [{:.4e}, {:.4e}], z = {z:.2}",
        sampler.name(),
        p.variance,
        m.variance,
        m.ci_low,
        m.ci_high
    );
}

#[test]
fn a_stationary_sampler_used_as_drawn_is_predicted_and_measured_alike() {
    let f = Ball::new(0.25, vec![0.4, 0.55], 1.0).unwrap();
    agree(
        &PoissonDisk::new(2).unwrap(),
        &f,
        64,
        Randomization::None,
        4000,
    );
    agree(&Random::new(2).unwrap(), &f, 64, Randomization::None, 4000);
}

#[test]
fn independent_points_under_a_digital_shift_are_white_noise() {
    let f = Gaussian::new(0.1, vec![0.3, 0.6], 1.0).unwrap();
    agree(
        &Random::new(2).unwrap(),
        &f,
        32,
        Randomization::DigitalShift,
        4000,
    );
}

#[test]
fn an_estimator_the_routes_do_not_predict_is_refused_and_measured() {
    use specvar::montecarlo::empirical_variances_of_sets;
    let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    // Given point sets of unknown law used as given: neither a cell form (nothing says in which
    // cells their points are uniform) nor a spectral route (those predict the shifted
    // estimator); Monte Carlo measures them.
    let sampler = specvar::sampler::Halton::new(2).unwrap();
    let sets: Vec<_> = (0..200)
        .map(|r| sampler.sample(64, 3, r).unwrap())
        .collect();
    let problem = Problem::from_point_sets(&sets, &disk)
        .unwrap()
        .with_randomization(Randomization::None);
    let e = predict(&problem, &PredictParams::default()).unwrap_err();
    assert!(e.to_string().contains("specvar mc --input"), "{e}");
    let mc = McParams {
        patterns: sets.len(),
        randomization: Randomization::None,
        ..McParams::default()
    };
    let f: [&dyn Integrand; 1] = [&disk];
    let m = empirical_variances_of_sets(&sets, &f, &mc, &specvar::progress::Silent).unwrap();
    assert!(m[0].variance > 0.0 && m[0].randomization == Randomization::None);
}

#[test]
fn a_digital_shift_is_reproducible_and_keeps_the_points_in_the_cube() {
    let sobol = Sobol::new(2).unwrap();
    let budget = specvar::budget::Budget::default();
    let a = draw_realizations(&sobol, 64, 3, 0..4, Randomization::DigitalShift, &budget).unwrap();
    let b = draw_realizations(&sobol, 64, 3, 0..4, Randomization::DigitalShift, &budget).unwrap();
    assert_eq!(a, b);
    let drawn = draw_realizations(&sobol, 64, 3, 0..4, Randomization::None, &budget).unwrap();
    assert_ne!(a, drawn);
    assert!(a
        .iter()
        .flat_map(|s| s.coords())
        .all(|&x| (0.0..1.0).contains(&x)));
}
