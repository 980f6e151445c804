//! Padded dimensions: the predicted variance of a 4D pixel integrand under two padded 2D
//! patterns, against Monte Carlo of the padded estimator itself.

use specvar::montecarlo::Z_99;
use specvar::padded::{padded_monte_carlo, predict_padded, PaddedGrid, PaddedSamplers};
use specvar::predict::PredictParams;
use specvar::progress::Silent;
use specvar::randomization::Randomization;
use specvar::sampler::SamplerKind;

/// Cells per axis of the 4D grid.
const M: usize = 16;
/// Monte Carlo trials: the measured variance's 99% interval is about ±6%.
const TRIALS: usize = 4000;

/// A pixel with antialiasing and a soft shadow: `u` the film position in the pixel, `v` the
/// light sample. An object's silhouette crosses the pixel (beyond it a background of 0.2);
/// in front, a floor lit where the light sample is not hidden, the shadow's edge moving with
/// the film position, shaded by `u_y`.
fn pixel() -> PaddedGrid {
    let c = |i: usize| (i as f64 + 0.5) / M as f64;
    let (c30, s30) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let (c70, s70) = (70f64.to_radians().cos(), 70f64.to_radians().sin());
    let mut values = Vec::with_capacity(M.pow(4));
    for ay in 0..M {
        for ax in 0..M {
            for by in 0..M {
                for bx in 0..M {
                    let (ux, uy, vx, vy) = (c(ax), c(ay), c(bx), c(by));
                    let value = if ux * c30 + uy * s30 > 0.75 {
                        0.2
                    } else {
                        let lit = vx * c70 + vy * s70 > 0.3 + 0.5 * ux;
                        (0.5 + 0.5 * uy) * lit as u8 as f64
                    };
                    values.push(value);
                }
            }
        }
    }
    PaddedGrid::new([M; 4], values)
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact)
}

fn check(first: SamplerKind, second: SamplerKind, randomization: Option<Randomization>, n: usize) {
    let f = pixel();
    let (a, b) = (first.build(2).unwrap(), second.build(2).unwrap());
    let mut samplers = PaddedSamplers::native(a.as_ref(), b.as_ref()).unwrap();
    if let Some(r) = randomization {
        samplers.randomizations = (r, r);
    }
    let p = predict_padded(&f, samplers, n, &PredictParams::default(), &Silent).unwrap();
    let mc = padded_monte_carlo(
        &f,
        samplers,
        n,
        TRIALS,
        17,
        &specvar::budget::Budget::default(),
    )
    .unwrap();
    let half = p.budget.half_width(Z_99);
    eprintln!(
        "{first} × {second} ({:?}) at N = {n}: predicted {:.4e} ± {:.1e} (2D {:.3e} + {:.3e}, interaction {:.3e}, white {:.3e}), measured {:.4e} [{:.4e}, {:.4e}]",
        samplers.randomizations,
        p.variance,
        half,
        p.first.variance,
        p.second.variance,
        p.interaction,
        p.interaction_white,
        mc.variance,
        mc.ci_low,
        mc.ci_high
    );
    assert!(
        mc.ci_low <= p.variance + half && p.variance - half <= mc.ci_high,
        "{first} × {second} at N = {n}: predicted {:.4e} ± {half:.1e}, measured {:.4e} [{:.4e}, {:.4e}]",
        p.variance,
        mc.variance,
        mc.ci_low,
        mc.ci_high
    );
}

#[test]
fn independent_points_padded_are_independent_points() {
    for n in [16, 256] {
        check(SamplerKind::Random, SamplerKind::Random, None, n);
    }
}

#[test]
fn padded_strata_and_nets_as_drawn_match_monte_carlo() {
    for n in [16, 64, 256] {
        check(SamplerKind::Jitter, SamplerKind::Jitter, None, n);
        check(SamplerKind::Cmj, SamplerKind::Sobol, None, n);
    }
}

#[test]
fn padded_patterns_under_shifts_match_monte_carlo() {
    for n in [16, 256] {
        check(
            SamplerKind::Jitter,
            SamplerKind::Sobol,
            Some(Randomization::Shift),
            n,
        );
    }
}

/// A padded plan: the count reaches the target by Monte Carlo of the padded estimator.
#[test]
fn a_padded_plan_reaches_its_target_by_monte_carlo() {
    use specvar::plan::{PlanParams, Target};
    let f = pixel();
    for kind in [SamplerKind::Jitter, SamplerKind::Sobol] {
        let s = kind.build(2).unwrap();
        let samplers = PaddedSamplers::native(s.as_ref(), s.as_ref()).unwrap();
        let params = PlanParams::new(Target::RelativeRmse(0.01));
        let p = specvar::padded::plan_padded(&f, samplers, &params, &Silent).unwrap();
        let mc = padded_monte_carlo(
            &f,
            samplers,
            p.n,
            TRIALS,
            23,
            &specvar::budget::Budget::default(),
        )
        .unwrap();
        let (rmse, target) = (mc.variance.sqrt(), p.target);
        eprintln!(
            "padded plan {kind}: N = {}, predicted {:.4e}, measured {rmse:.4e} [{:.4e}, {:.4e}], target {target:.4e}",
            p.n,
            p.rmse,
            mc.ci_low.sqrt(),
            mc.ci_high.sqrt()
        );
        assert!(p.rmse <= target && p.route.starts_with("cell form"));
        // Within the issue's ±25% (from above only on the powers of two of Sobol').
        assert!(rmse <= 1.25 * target, "{kind}: {rmse:.4e}");
        if kind == SamplerKind::Jitter {
            assert!(rmse >= 0.75 * target, "{kind}: {rmse:.4e}");
        }
    }
}

/// An image of padded pixels: one pixel twice plans as that pixel; two different pixels plan
/// for their mean variance, checked by Monte Carlo of each.
#[test]
fn an_image_of_padded_pixels_plans_for_its_mean_variance() {
    use specvar::padded::{plan_padded, plan_padded_pixels};
    use specvar::plan::{PlanParams, Target};
    let f = pixel();
    let s = SamplerKind::Jitter.build(2).unwrap();
    let samplers = PaddedSamplers::native(s.as_ref(), s.as_ref()).unwrap();
    let params = PlanParams::new(Target::RelativeRmse(0.02));
    let one = plan_padded(&f, samplers, &params, &Silent).unwrap();
    let twice = plan_padded_pixels(&[f.clone(), f.clone()], samplers, &params, &Silent).unwrap();
    assert_eq!(one.n, twice.n);
    assert!((one.rmse / twice.rmse - 1.0).abs() < 1e-12);
    // A second pixel: the first's complement, scaled.
    let [ah, aw, bh, bw] = f.shape();
    let values = (0..ah * aw * bh * bw)
        .map(|i| {
            let (bx, ax) = (i % bw, i / (bw * bh) % aw);
            0.3 + 0.5 * ((bx + ax) % 3 == 0) as u8 as f64
        })
        .collect();
    let g = PaddedGrid::new([ah, aw, bh, bw], values)
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact);
    let image = [f, g];
    let p = plan_padded_pixels(&image, samplers, &params, &Silent).unwrap();
    let measured = image
        .iter()
        .map(|h| {
            padded_monte_carlo(
                h,
                samplers,
                p.n,
                TRIALS,
                29,
                &specvar::budget::Budget::default(),
            )
            .unwrap()
        })
        .collect::<Vec<_>>();
    let mean_of = |v: &dyn Fn(&specvar::montecarlo::McResult) -> f64| {
        (measured.iter().map(v).sum::<f64>() / 2.0).sqrt()
    };
    let (lo, hi) = (mean_of(&|m| m.ci_low), mean_of(&|m| m.ci_high));
    eprintln!(
        "padded image: N = {}, predicted {:.4e}, measured [{lo:.4e}, {hi:.4e}], target {:.4e}",
        p.n, p.rmse, p.target
    );
    assert!(lo <= p.rmse_interval.1 && p.rmse_interval.0 <= hi);
    assert!(lo <= 1.25 * p.target && hi >= 0.75 * p.target);
}

/// Bad padded input is refused with the parameter named and what is allowed.
#[test]
fn bad_padded_input_is_refused_with_what_is_allowed() {
    use specvar::Error;
    let e = PaddedGrid::new([2, 2, 2, 0], vec![]).unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name: "padded grid shape", allowed, .. } if allowed.contains("four positive sides")),
        "{e}"
    );
    let e = PaddedGrid::new([2, 2, 2, 2], vec![0.0; 15]).unwrap_err();
    assert!(
        matches!(
            &e,
            Error::InvalidParameter {
                name: "padded grid values",
                ..
            }
        ),
        "{e}"
    );
    let mut values = vec![0.0; 16];
    values[3] = f64::INFINITY;
    let e = PaddedGrid::new([2, 2, 2, 2], values).unwrap_err();
    assert!(
        matches!(
            &e,
            Error::InvalidParameter {
                name: "padded grid value",
                ..
            }
        ),
        "{e}"
    );
    let regular = SamplerKind::Regular.build(2).unwrap();
    let mut samplers = PaddedSamplers::native(regular.as_ref(), regular.as_ref()).unwrap();
    samplers.randomizations = (Randomization::None, Randomization::None);
    let e = samplers.check().unwrap_err();
    assert!(
        matches!(&e, Error::InvalidParameter { name: "padded randomization", allowed, .. } if allowed.contains("biased")),
        "{e}"
    );
    let cube = SamplerKind::Jitter.build(3).unwrap();
    let e = PaddedSamplers::native(cube.as_ref(), cube.as_ref())
        .err()
        .unwrap();
    assert!(
        matches!(
            &e,
            Error::InvalidParameter {
                name: "padded sampler dimension",
                ..
            }
        ),
        "{e}"
    );
}
