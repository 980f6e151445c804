//! `plan`: the counts it picks, checked by Monte Carlo of the same estimator at the planned N
//! and at the count just below it.

use crate::common;

use specvar::integrand::{Integrand, IntegrandSpec};
use specvar::montecarlo::{empirical_variance, McParams, McResult};
use specvar::plan::{default_samplers, plan, Plan, PlanParams, Target};
use specvar::progress::Silent;
use specvar::sampler::{CountRule, SamplerKind};
use specvar::Error;

/// Monte Carlo trials per count: the measured RMSE's relative standard error is about
/// `1/√(2·TRIALS)`, 2.5%, so its 99% interval is about ±7%.
const TRIALS: usize = 800;
/// How far the measured RMSE at the planned N may be from the target where the candidates are
/// dense (random, strata): the issue's ±25%.
const TARGET_BAND: f64 = 0.25;

fn edge() -> Box<dyn Integrand> {
    "edge:theta=30"
        .parse::<IntegrandSpec>()
        .unwrap()
        .build(2)
        .unwrap()
}

fn measured(kind: SamplerKind, f: &dyn Integrand, plan: &Plan, n: usize) -> McResult {
    let sampler = kind.build(2).unwrap();
    let params = McParams::pooled(kind, TRIALS, 7, plan.randomization);
    empirical_variance(sampler.as_ref(), f, n, &params).unwrap()
}

/// Plans each default sampler and measures the planned count and the one below it.
fn check_plans(name: &str, f: &dyn Integrand, relative: f64) {
    let params = PlanParams::new(Target::RelativeRmse(relative));
    for kind in default_samplers(2) {
        let sampler = kind.build(2).unwrap();
        let p = plan(sampler.as_ref(), f, &params, &Silent).unwrap();
        let case = format!("{name}, {kind} at N = {}", p.n);
        let target = relative * f.integral().abs();
        assert!(p.rmse <= target, "{case}: predicted {:.4e}", p.rmse);
        let mc = measured(kind, f, &p, p.n);
        let rmse = mc.variance.sqrt();
        let (lo, hi) = (mc.ci_low.sqrt(), mc.ci_high.sqrt());
        // The prediction at N is right: the measurement's 99% interval meets the budget's.
        assert!(
            lo <= p.rmse_interval.1 && p.rmse_interval.0 <= hi,
            "{case}: predicted {:.4e} [{:.4e}, {:.4e}], measured {rmse:.4e} [{lo:.4e}, {hi:.4e}]",
            p.rmse,
            p.rmse_interval.0,
            p.rmse_interval.1
        );
        // The planned N reaches the target, within the band.
        assert!(rmse <= target * (1.0 + TARGET_BAND), "{case}: {rmse:.4e}");
        if kind.facts().balanced_counts != CountRule::PowerOfTwo {
            assert!(rmse >= target * (1.0 - TARGET_BAND), "{case}: {rmse:.4e}");
        }
        // The count below misses it: N is the smallest (up to the candidates' spacing).
        let below = p.below.expect("a count below that misses");
        assert!(below.rmse > target, "{case}");
        let below_rmse = measured(kind, f, &p, below.n).variance.sqrt();
        assert!(
            below_rmse >= target * (1.0 - TARGET_BAND),
            "{case}: at N = {} measured {below_rmse:.4e}",
            below.n
        );
    }
}

#[test]
fn planned_counts_reach_the_target_on_an_edge_with_a_seam() {
    check_plans("edge at 30°", edge().as_ref(), 0.02);
}

#[test]
fn planned_counts_reach_the_target_on_a_soft_shadow() {
    check_plans(
        "soft shadow",
        &common::soft_shadow(128, 30.0, 0.6, 0.15),
        0.005,
    );
}

#[test]
fn sobol_counts_are_powers_of_two_and_jitter_counts_are_strata() {
    let f = edge();
    let params = PlanParams::new(Target::Rmse(2e-3));
    for (kind, rule) in [
        (SamplerKind::Sobol, CountRule::PowerOfTwo),
        (SamplerKind::Jitter, CountRule::Strata),
        (SamplerKind::OrthogonalArray, CountRule::PrimeSquare),
    ] {
        let sampler = kind.build(2).unwrap();
        let p = plan(sampler.as_ref(), f.as_ref(), &params, &Silent).unwrap();
        assert!(rule.admits(p.n, 2), "{kind}: N = {}", p.n);
        assert_eq!(p.counts, rule);
    }
}

#[test]
fn unreachable_targets_name_the_largest_n_and_its_rmse() {
    let f = edge();
    let random = SamplerKind::Random.build(2).unwrap();
    let params = PlanParams {
        max_n: Some(4096),
        ..PlanParams::new(Target::Rmse(1e-4))
    };
    let e = plan(random.as_ref(), f.as_ref(), &params, &Silent).unwrap_err();
    let Error::Unreachable {
        largest_n, rmse, ..
    } = &e
    else {
        panic!("{e}")
    };
    assert_eq!(*largest_n, 4096);
    // Random points: RMSE = σ/√N exactly, σ² = ∫f² − I² = 1/4 for a half-plane.
    assert!(common::close(*rmse, (0.25f64 / 4096.0).sqrt(), 1e-9), "{e}");
    assert!(e.to_string().contains("4096"), "{e}");
}

#[test]
fn bad_targets_are_refused() {
    let f = edge();
    let jitter = SamplerKind::Jitter.build(2).unwrap();
    for bad in [0.0, -0.01, f64::NAN, f64::INFINITY] {
        let params = PlanParams::new(Target::Rmse(bad));
        let e = plan(jitter.as_ref(), f.as_ref(), &params, &Silent).unwrap_err();
        assert!(matches!(e, Error::InvalidParameter { .. }), "{bad}: {e}");
    }
}

/// An image of four soft shadows at different angles, planned for its RMSE and measured.
#[test]
fn an_image_is_planned_for_its_rmse_and_measured_pixel_by_pixel() {
    use specvar::pixels::PixelStack;
    use specvar::plan::plan_pixels;
    let pixel = |angle: f64| common::soft_shadow(32, angle, 0.6, 0.1);
    let stack = PixelStack::new(2, [10.0, 35.0, 60.0, 85.0].map(pixel).to_vec()).unwrap();
    let params = PlanParams::new(Target::RelativeRmse(0.01));
    for kind in [SamplerKind::Jitter, SamplerKind::Sobol] {
        let sampler = kind.build(2).unwrap();
        let p = plan_pixels(sampler.as_ref(), &stack, &params, &Silent).unwrap();
        let mean_variance = stack
            .pixels()
            .iter()
            .map(|f| measured(kind, f, &p, p.n).variance)
            .sum::<f64>()
            / 4.0;
        let rmse = mean_variance.sqrt();
        assert!(
            (rmse / p.rmse - 1.0).abs() <= TARGET_BAND && rmse <= p.target * (1.0 + TARGET_BAND),
            "{kind} at N = {}: predicted {:.4e}, measured {rmse:.4e}, target {:.4e}",
            p.n,
            p.rmse,
            p.target
        );
    }
}

/// Several samplers: one out of reach is a row saying so, and the others still answer; all out
/// of reach is the first one's error.
#[test]
fn a_sampler_out_of_reach_is_a_row_beside_those_that_reach() {
    use specvar::plan::plan_many;
    let f = edge();
    let random = SamplerKind::Random.build(2).unwrap();
    let jitter = SamplerKind::Jitter.build(2).unwrap();
    let params = PlanParams {
        max_n: Some(4096),
        ..PlanParams::new(Target::Rmse(1e-3))
    };
    let rows = plan_many(
        &[random.as_ref(), jitter.as_ref()],
        f.as_ref(),
        &params,
        &Silent,
    )
    .unwrap()
    .rows;
    assert!(!rows[0].reached && rows[0].n == 4096 && rows[0].limit.is_some());
    assert!(rows[0].rmse > 1e-3);
    assert!(rows[1].reached && rows[1].rmse <= 1e-3 && rows[1].limit.is_none());
    let e = plan_many(&[random.as_ref()], f.as_ref(), &params, &Silent).unwrap_err();
    assert!(
        matches!(
            e,
            Error::Unreachable {
                largest_n: 4096,
                ..
            }
        ),
        "{e}"
    );
}

/// Gaussian jitter as drawn is biased: a plan, which reads the variance as the squared error,
/// refuses it with the kind and words of the refusal, and plans it under a shift.
#[test]
fn a_biased_estimator_is_refused_with_its_reason() {
    let disk = specvar::integrand::Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let jitter = specvar::sampler::GaussianJitter::new(2).unwrap();
    let params = PlanParams::new(Target::Rmse(1e-3));
    let e = plan(&jitter, &disk, &params, &Silent).unwrap_err();
    assert!(matches!(e, Error::OutsideValidity { .. }), "{e:?}");
    let message = e.to_string();
    assert!(
        message.contains("biased") && message.contains("--randomization shift"),
        "{message}"
    );
    let shifted = PlanParams {
        randomization: specvar::randomization::RandomizationChoice::Given(
            specvar::randomization::Randomization::Shift,
        ),
        ..params
    };
    let p = plan(&jitter, &disk, &shifted, &Silent).unwrap();
    assert!(p.rmse <= 1e-3);
}

/// Several samplers: one whose estimator has no route (Gaussian jitter used as drawn, biased) is a refusal with
/// its reason, and the others still answer; all refused is the first refusal's error.
#[test]
fn a_refused_sampler_is_a_refusal_beside_those_planned() {
    use specvar::plan::plan_many;
    let disk = specvar::integrand::Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
    let gjitter = SamplerKind::GaussianJitter.build(2).unwrap();
    let jitter = SamplerKind::Jitter.build(2).unwrap();
    let params = PlanParams::new(Target::Rmse(1e-3));
    let plans = plan_many(
        &[gjitter.as_ref(), jitter.as_ref()],
        &disk,
        &params,
        &Silent,
    )
    .unwrap();
    assert_eq!(plans.rows.len(), 1);
    assert!(plans.rows[0].sampler == "jitter" && plans.rows[0].reached);
    assert_eq!(plans.refused.len(), 1);
    assert_eq!(plans.refused[0].sampler, "gjitter");
    assert!(
        plans.refused[0].reason.contains("--randomization shift"),
        "{:?}",
        plans.refused
    );
    let e = plan_many(&[gjitter.as_ref()], &disk, &params, &Silent).unwrap_err();
    assert!(matches!(e, Error::OutsideValidity { .. }), "{e}");
}
