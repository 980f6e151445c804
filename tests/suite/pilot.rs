//! Plans from a pilot (a few renders at 16 samples per pixel), checked by Monte Carlo of the
//! image at the planned count (for white noise, by its exact variance).

use crate::common;

use rayon::prelude::*;
use specvar::integrand::{GridIntegrand, Integrand};
use specvar::montecarlo::{empirical_variance, estimate_integral, McParams};
use specvar::padded::{predict_padded, PaddedGrid, PaddedSamplers};
use specvar::pilot::{plan_pilot, Pilot, PilotModel};
use specvar::plan::{PlanParams, Target};
use specvar::predict::PredictParams;
use specvar::progress::Silent;
use specvar::sampler::{CountRule, Sampler, SamplerKind};

/// The pilot's renders and their sample count: the "at most 4 renders at 16 samples".
const RENDERS: usize = 4;
const PILOT_N: usize = 16;
/// Pixels of the test image.
const PIXELS: usize = 64;
/// How far the measured image RMSE at the planned count may be from the target.
const PILOT_BAND: f64 = 0.40;
/// Monte Carlo trials per pixel: with 64 pixels the image variance's relative standard error
/// is about `√(2/500)/8`, 0.8%; a skewed pixel (a net on a hard edge) needs the
/// patterns for its interval.
const TRIALS: usize = 500;

/// An image: shadow edges over the light square, hard or slightly soft, whose angle and position
/// change from pixel to pixel.
fn image() -> Vec<GridIntegrand> {
    (0..PIXELS)
        .map(|p| {
            let t = p as f64 / PIXELS as f64;
            common::soft_shadow(
                64,
                10.0 + 157.0 * t,
                0.3 + 0.5 * ((p * 7) % 11) as f64 / 11.0,
                0.002 + 0.05 * ((p * 3) % 5) as f64 / 5.0,
            )
        })
        .collect()
}

/// `RENDERS` renders of the image at `PILOT_N` samples per pixel, pilot `seed`.
fn render(sampler: &dyn Sampler, image: &[GridIntegrand], seed: u64) -> Pilot {
    let values = (0..RENDERS * image.len())
        .map(|i| {
            let points = sampler.sample(PILOT_N, seed, i as u64).unwrap();
            estimate_integral(&image[i % image.len()], &points)
        })
        .collect();
    Pilot::new(PILOT_N, RENDERS, values)
        .unwrap()
        .with_model(PilotModel::Single)
}

#[test]
fn a_pilot_of_four_renders_at_16_samples_plans_within_40_percent() {
    let image = image();
    let mean = image.iter().map(|f| f.integral()).sum::<f64>() / PIXELS as f64;
    let target = 0.01 * mean;
    let params = PlanParams::new(Target::Rmse(target));
    // The samplers are independent: checked side by side.
    [
        SamplerKind::Random,
        SamplerKind::Jitter,
        SamplerKind::Cmj,
        SamplerKind::Sobol,
    ]
    .into_par_iter()
    .for_each(|kind| {
        let sampler = kind.build(2).unwrap();
        for seed in 0..3 {
            let pilot = render(sampler.as_ref(), &image, 100 + seed);
            let p = plan_pilot(sampler.as_ref(), &pilot, &params, &Silent).unwrap();
            // Each pixel's variance at the planned count with its 99% bounds: exact for white
            // noise (the pixel's variance over N), by Monte Carlo otherwise.
            let runs: Vec<(f64, f64, f64)> = if kind == SamplerKind::Random {
                image
                    .iter()
                    .map(|f| {
                        let v = (f.integral_of_square() - f.integral().powi(2)) / p.n as f64;
                        (v, v, v)
                    })
                    .collect()
            } else {
                let mc = McParams::pooled(kind, TRIALS, 5, p.randomization);
                image
                    .iter()
                    .map(|f| {
                        let r = empirical_variance(sampler.as_ref(), f, p.n, &mc).unwrap();
                        (r.variance, r.ci_low, r.ci_high)
                    })
                    .collect()
            };
            let mean_of = |v: &dyn Fn(&(f64, f64, f64)) -> f64| {
                (runs.iter().map(v).sum::<f64>() / PIXELS as f64).sqrt()
            };
            let rmse = mean_of(&|r| r.0);
            let (lo, hi) = (mean_of(&|r| r.1), mean_of(&|r| r.2));
            let case = format!("{kind}, pilot {seed}: N = {}", p.n);
            eprintln!(
                "{case}: predicted {:.4e} [{:.4e}, {:.4e}], measured {rmse:.4e}, target {target:.4e} ({:+.0}%)",
                p.rmse, p.rmse_interval.0, p.rmse_interval.1, 100.0 * (rmse / target - 1.0)
            );
            // The planned count reaches the target, within the band (from below only on a
            // ladder of powers of two, whose steps are wider than the band).
            assert!(rmse <= target * (1.0 + PILOT_BAND), "{case}: {rmse:.4e}");
            if kind.facts().balanced_counts != CountRule::PowerOfTwo {
                assert!(rmse >= target * (1.0 - PILOT_BAND), "{case}: {rmse:.4e}");
            }
            // The plan's interval meets the measurement's (each pixel's 99% bounds, averaged:
            // wider than the image's own, so this errs towards passing only by their width).
            assert!(
                lo <= p.rmse_interval.1 && p.rmse_interval.0 <= hi,
                "{case}: predicted [{:.4e}, {:.4e}], measured [{lo:.4e}, {hi:.4e}]",
                p.rmse_interval.0,
                p.rmse_interval.1
            );
        }
    });
}

/// Pixels of the padded image.
const PADDED_PIXELS: usize = 24;

/// Pixel `p` of a padded image: film `u` × light `v` on 8² × 16² cells, a silhouette across
/// the film and a shadow edge on the light that moves with the film position.
fn padded_pixel(p: usize) -> PaddedGrid {
    let (fm, lm) = (8, 16);
    let silhouette = (25.0 + 40.0 * (p % 5) as f64 / 5.0).to_radians();
    let shadow = (20.0 + 140.0 * p as f64 / PADDED_PIXELS as f64).to_radians();
    let offset = 0.3 + 0.4 * ((p * 7) % 11) as f64 / 11.0;
    let c = |i: usize, m: usize| (i as f64 + 0.5) / m as f64;
    let mut values = Vec::with_capacity(fm * fm * lm * lm);
    for ay in 0..fm {
        for ax in 0..fm {
            for by in 0..lm {
                for bx in 0..lm {
                    let (ux, uy, vx, vy) = (c(ax, fm), c(ay, fm), c(bx, lm), c(by, lm));
                    let value = if ux * silhouette.cos() + uy * silhouette.sin() > 0.8 {
                        0.2
                    } else {
                        let lit = vx * shadow.cos() + vy * shadow.sin() > offset + 0.3 * (ux - 0.5);
                        (0.5 + 0.5 * uy) * lit as u8 as f64
                    };
                    values.push(value);
                }
            }
        }
    }
    PaddedGrid::new([fm, fm, lm, lm], values)
        .unwrap()
        .with_meaning(specvar::integrand::GridMeaning::Exact)
}

/// A permutation of `0..n` from a 64-bit mixer (the test's own, not the library's).
fn shuffled(n: usize, key: u64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = specvar::rng::splitmix64(key ^ (i as u64 * 0x9E37)) % (i as u64 + 1);
        order.swap(i, j as usize);
    }
    order
}

/// A padded image planned from four renders at 16 samples: the default (padded) model.
#[test]
fn a_pilot_of_padded_pixels_plans_within_40_percent() {
    let image: Vec<PaddedGrid> = (0..PADDED_PIXELS).map(padded_pixel).collect();
    let mean = image.iter().map(|f| f.integral()).sum::<f64>() / image.len() as f64;
    let target = 0.01 * mean;
    let params = PlanParams::new(Target::Rmse(target));
    // CMJ's marginals take estimated routes (seconds each): jitter and Sobol' keep the test
    // short.
    for kind in [SamplerKind::Jitter, SamplerKind::Sobol] {
        let sampler = kind.build(2).unwrap();
        let s = sampler.as_ref();
        let values = (0..RENDERS * image.len())
            .map(|i| {
                let a = s.sample(PILOT_N, 300, i as u64).unwrap();
                let b = s.sample(PILOT_N, 301, i as u64).unwrap();
                let order = shuffled(PILOT_N, i as u64);
                let f = &image[i % image.len()];
                a.points()
                    .zip(&order)
                    .map(|(u, &m)| f.eval(u, b.point(m)))
                    .sum::<f64>()
                    / PILOT_N as f64
            })
            .collect();
        let pilot = Pilot::new(PILOT_N, RENDERS, values).unwrap();
        assert_eq!(pilot.model(), PilotModel::Padded);
        let p = plan_pilot(s, &pilot, &params, &Silent).unwrap();
        // The truth at N: the padded prediction, itself checked by Monte Carlo
        // (tests/suite/padded.rs), averaged over the pixels.
        let padded = PaddedSamplers::native(s, s).unwrap();
        let variance = image
            .iter()
            .map(|f| {
                predict_padded(f, padded, p.n, &PredictParams::default(), &Silent)
                    .unwrap()
                    .variance
            })
            .sum::<f64>()
            / image.len() as f64;
        let rmse = variance.sqrt();
        let case = format!("{kind}: N = {}", p.n);
        eprintln!(
            "padded {case}: predicted {:.4e} [{:.4e}, {:.4e}], truth {rmse:.4e}, target {target:.4e} ({:+.0}%)",
            p.rmse, p.rmse_interval.0, p.rmse_interval.1, 100.0 * (rmse / target - 1.0)
        );
        assert!(rmse <= target * (1.0 + PILOT_BAND), "{case}: {rmse:.4e}");
        if kind.facts().balanced_counts != CountRule::PowerOfTwo {
            assert!(rmse >= target * (1.0 - PILOT_BAND), "{case}: {rmse:.4e}");
        }
        assert!(
            p.rmse_interval.0 <= rmse && rmse <= p.rmse_interval.1,
            "{case}: predicted [{:.4e}, {:.4e}], truth {rmse:.4e}",
            p.rmse_interval.0,
            p.rmse_interval.1
        );
    }
}

/// Bad pilots are refused with the parameter named and what is allowed.
#[test]
fn bad_pilots_are_refused_with_what_is_allowed() {
    use specvar::Error;
    let invalid = |r: specvar::Result<Pilot>| match r {
        Err(Error::InvalidParameter { name, allowed, .. }) => (name, allowed),
        other => panic!("expected an invalid parameter, got {other:?}"),
    };
    let (name, allowed) = invalid(Pilot::new(16, 1, vec![0.5; 8]));
    assert_eq!(name, "pilot renders");
    assert!(allowed.contains("at least 2 renders"), "{allowed}");
    let (name, allowed) = invalid(Pilot::new(16, 3, vec![0.5; 8]));
    assert_eq!(name, "pilot values");
    assert!(allowed.contains("multiple of the 3 renders"), "{allowed}");
    let (name, allowed) = invalid(Pilot::new(16, 2, vec![0.5, f64::NAN, 0.4, 0.3]));
    assert_eq!(name, "pilot value");
    assert!(allowed.contains("render 0, pixel 1"), "{allowed}");
    let (name, _) = invalid(Pilot::new(16, 2, vec![0.5; 6]));
    assert_eq!(name, "pilot");
    let (name, _) = invalid(Pilot::new(0, 2, vec![0.5, 0.4]));
    assert_eq!(name, "pilot sample count");
    let model = "4d".parse::<PilotModel>().unwrap_err();
    assert!(model.to_string().contains("padded or single"), "{model}");
    // A 3D sampler, and a pilot count the sampler cannot draw.
    let pilot = Pilot::new(16, 2, vec![0.5, 0.4]).unwrap();
    let params = PlanParams::new(Target::Rmse(0.01));
    let ball = SamplerKind::Jitter.build(3).unwrap();
    let e = plan_pilot(ball.as_ref(), &pilot, &params, &Silent).unwrap_err();
    assert!(
        matches!(
            e,
            Error::InvalidParameter {
                name: "pilot sampler dimension",
                ..
            }
        ),
        "{e}"
    );
    let orthogonal = SamplerKind::OrthogonalArray.build(2).unwrap();
    assert!(plan_pilot(orthogonal.as_ref(), &pilot, &params, &Silent).is_err());
}
