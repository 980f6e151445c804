//! Rendering: geometry, the per-pixel estimator against the reference within its statistical
//! error, the measured MSE against its closed-form expectation, determinism, bad input.

use specvar::predict::{predict_from_power, SpectrumSource};
use specvar::render::ao::ShadingPoint;
use specvar::render::geometry::*;
use specvar::render::*;
use specvar::sampler::*;
use specvar::spectrum::ClosedForm;

use crate::common;

const Z_999: f64 = 3.29;

#[test]
fn rays_hit_boxes_and_spheres_where_they_should() {
    let ray = Ray {
        origin: Vec3::new(0.0, 0.0, -5.0),
        direction: Vec3::new(0.0, 0.0, 1.0),
    };
    let sphere = Shape::Sphere {
        centre: Vec3::new(0.0, 0.0, 0.0),
        radius: 1.0,
    };
    let (t, n) = sphere.intersect(&ray, f64::INFINITY).unwrap();
    assert!((t - 4.0).abs() < common::ROUNDING && (n.z + 1.0).abs() < common::ROUNDING);
    assert!(sphere.intersect(&ray, 3.9).is_none());
    let cube = Shape::AxisBox {
        min: Vec3::new(-1.0, -1.0, 2.0),
        max: Vec3::new(1.0, 1.0, 3.0),
    };
    let (t, n) = cube.intersect(&ray, f64::INFINITY).unwrap();
    assert!((t - 7.0).abs() < common::ROUNDING && n == Vec3::new(0.0, 0.0, -1.0));
    let miss = Ray {
        origin: Vec3::new(3.0, 0.0, -5.0),
        direction: Vec3::new(0.0, 0.0, 1.0),
    };
    assert!(cube.intersect(&miss, f64::INFINITY).is_none());
    // Every pixel of the Cornell box sees a surface.
    let frame = Frame::new(Scene::cornell_box(), 16, 12).unwrap();
    assert!((0..frame.pixels()).all(|p| frame.point(p).is_some()));
}

/// Skipping the shapes beyond the maximum distance changes no ray's visibility, at distances
/// from a sliver to the whole room, and it does skip shapes: rays from most points near the
/// back wall cannot reach the open front.
#[test]
fn rays_skip_only_shapes_beyond_their_reach() {
    let frame = Frame::new(Scene::cornell_box(), 24, 18).unwrap();
    let scene = frame.scene();
    let mut culled = 0;
    for p in 0..frame.pixels() {
        let point = frame.point(p).unwrap();
        let everything = point.near(scene, 100.0);
        for max_distance in [0.01, 0.05, 0.2, 0.35, 0.5, 2.0] {
            let near = point.near(scene, max_distance);
            culled += usize::from(near != everything);
            for i in 0..24 {
                for j in 0..12 {
                    let u = [(i as f64 + 0.5) / 24.0, (j as f64 + 0.5) / 12.0];
                    assert_eq!(
                        point.visibility_near(scene, near, &u, max_distance),
                        point.visibility(scene, &u, max_distance),
                        "pixel {p}, distance {max_distance}, u = {u:?}"
                    );
                }
            }
        }
    }
    assert!(culled > frame.pixels(), "only {culled} culled sets");
}

/// A point on a floor with nothing above sees the whole hemisphere; at the foot of an infinite
/// wall, the cosine-weighted visible fraction is exactly 1/2 by symmetry.
#[test]
fn ambient_occlusion_has_its_closed_form_values() {
    let hit = Hit {
        point: Vec3::new(0.0, 0.0, 0.0),
        normal: Vec3::new(0.0, 1.0, 0.0),
    };
    let point = ShadingPoint::new(&hit);
    let open = Scene {
        name: "empty".into(),
        shapes: vec![],
        camera: Scene::cornell_box().camera,
    };
    let grid = point.visibility_grid(&open, 16, 1.0).unwrap();
    assert!(grid.values().iter().all(|&v| v == 1.0));
    // A wall filling x < 0: by symmetry half the cosine-weighted hemisphere is blocked.
    let walled = Scene {
        shapes: vec![Shape::AxisBox {
            min: Vec3::new(-10.0, -10.0, -10.0),
            max: Vec3::new(-1e-9, 10.0, 10.0),
        }],
        ..open
    };
    let grid = point.visibility_grid(&walled, 64, 100.0).unwrap();
    use specvar::integrand::Integrand;
    assert!(
        (grid.integral() - 0.5).abs() < 2.0 / 64.0,
        "{}",
        grid.integral()
    );
}

/// Tiny image: every pixel's mean estimate over independent renders agrees with the reference
/// within the combined standard error (a χ² test over the pixels, and each |z| below a
/// Bonferroni bound).
#[test]
fn tiny_render_is_unbiased_against_the_reference() {
    let frame = Frame::new(Scene::cornell_box(), 6, 6).unwrap();
    let reference = render_reference(&frame, 1 << 16, 0.5, 7, &specvar::progress::Silent).unwrap();
    let sampler = Jitter::new(2).unwrap();
    let renders: Vec<Vec<f64>> = (0..64)
        .map(|seed| {
            let params = RenderParams {
                rays: 16,
                seed,
                ..Default::default()
            };
            render_ao(&frame, &sampler, &params, &specvar::progress::Silent)
                .unwrap()
                .image
                .values
        })
        .collect();
    let s = renders.len() as f64;
    let mut chi2 = 0.0;
    let mut informative = 0;
    for p in 0..frame.pixels() {
        let mean = renders.iter().map(|r| r[p]).sum::<f64>() / s;
        let var = renders.iter().map(|r| (r[p] - mean).powi(2)).sum::<f64>() / (s - 1.0);
        let se2 = var / s + reference.pixel_variance(p);
        if se2 == 0.0 {
            // Fully visible or fully occluded: both must be exact.
            assert_eq!(mean, reference.image.values[p]);
            continue;
        }
        let z = (mean - reference.image.values[p]) / se2.sqrt();
        assert!(z.abs() < 4.0, "pixel {p}: z = {z}");
        chi2 += z * z;
        informative += 1;
    }
    // χ²(k) 99.9% quantile ≤ k + 3.1 √(2k) + 10 for k ≤ 36.
    let k = informative as f64;
    assert!(
        chi2 < k + 3.1 * (2.0 * k).sqrt() + 10.0,
        "χ² = {chi2} over {k}"
    );
}

/// The measured MSE of random and jitter, averaged over independent renders, agrees with the
/// lattice-form prediction from the closed-form spectra.
#[test]
fn measured_mse_matches_the_closed_form_prediction() {
    let frame = Frame::new(Scene::cornell_box(), 12, 12).unwrap();
    let reference = render_reference(&frame, 1 << 14, 0.5, 3, &specvar::progress::Silent).unwrap();
    let power = pixel_power(
        &frame,
        0.5,
        &PixelPowerParams::default(),
        &specvar::progress::Silent,
    )
    .unwrap();
    let samplers: [(Box<dyn Sampler>, ClosedForm); 2] = [
        (Box::new(Random::new(2).unwrap()), ClosedForm::WhiteNoise),
        (Box::new(Jitter::new(2).unwrap()), ClosedForm::Jitter),
    ];
    for (sampler, closed) in samplers {
        let n = 24; // 6 × 4 strata for jitter
        let predicted = predict_from_power(&power, &SpectrumSource::Closed(closed), n)
            .unwrap()
            .variance;
        let (mean, se) = mean_mse(&frame, sampler.as_ref(), &reference, |seed| RenderParams {
            rays: n,
            seed,
            ..Default::default()
        });
        assert!(
            (mean - predicted).abs() < Z_999 * se,
            "{}: measured {mean:e} ± {se:e}, predicted {predicted:e}",
            sampler.name()
        );
    }
}

#[test]
fn renders_do_not_depend_on_thread_count() {
    let frame = Frame::new(Scene::cornell_box(), 9, 7).unwrap();
    let params = RenderParams {
        rays: 32,
        patterns: 5,
        seed: 11,
        ..Default::default()
    };
    let sampler = PoissonDisk::new(2).unwrap();
    let silent = &specvar::progress::Silent;
    common::assert_thread_count_invariant(|| render_ao(&frame, &sampler, &params, silent).unwrap());
    let power = PixelPowerParams::default();
    common::assert_thread_count_invariant(|| pixel_power(&frame, 0.5, &power, silent).unwrap());
}

#[test]
fn reference_cache_round_trips_and_is_keyed() {
    let dir = std::env::temp_dir().join("specvar-render-cache-test");
    let _ = std::fs::remove_dir_all(&dir);
    let frame = Frame::new(Scene::cornell_box(), 4, 3).unwrap();
    let (first, cached) =
        cached_reference(&dir, &frame, 64, 0.5, 1, &specvar::progress::Silent).unwrap();
    assert!(!cached);
    let (second, cached) =
        cached_reference(&dir, &frame, 64, 0.5, 1, &specvar::progress::Silent).unwrap();
    assert!(cached);
    assert_eq!(first, second);
    let (_, cached) =
        cached_reference(&dir, &frame, 128, 0.5, 1, &specvar::progress::Silent).unwrap();
    assert!(!cached, "another ray count is another reference");
}

#[test]
fn bad_render_requests_are_errors() {
    assert!(Frame::new(Scene::cornell_box(), 0, 4).is_err());
    let frame = Frame::new(Scene::cornell_box(), 2, 2).unwrap();
    let jitter = Jitter::new(2).unwrap();
    let bad = |params: RenderParams| {
        render_ao(&frame, &jitter, &params, &specvar::progress::Silent).is_err()
    };
    assert!(bad(RenderParams {
        rays: 0,
        ..Default::default()
    }));
    assert!(bad(RenderParams {
        rays: 17, // prime: no strata
        ..Default::default()
    }));
    assert!(bad(RenderParams {
        max_distance: f64::NAN,
        ..Default::default()
    }));
    assert!(bad(RenderParams {
        patterns: 0,
        ..Default::default()
    }));
    assert!(render_ao(
        &frame,
        &Jitter::new(3).unwrap(),
        &RenderParams::default(),
        &specvar::progress::Silent
    )
    .is_err());
    assert!(render_reference(&frame, 1, 0.5, 0, &specvar::progress::Silent).is_err());
    let params = PixelPowerParams {
        resolution: 0,
        ..Default::default()
    };
    assert!(pixel_power(&frame, 0.5, &params, &specvar::progress::Silent).is_err());
}

/// Rendered as a renderer uses the samplers (jitter's strata and Owen-scrambled Sobol' as
/// drawn, the unscrambled net under a digital shift per pixel): the measured MSE, averaged over
/// independent renders, agrees with the mean of each pixel's own prediction for that estimator,
/// which differs from the shifted estimator's.
#[test]
fn renders_as_used_match_the_per_pixel_prediction() {
    use specvar::randomization::{Randomization, RandomizationChoice};
    let frame = Frame::new(Scene::cornell_box(), 10, 10).unwrap();
    let reference = render_reference(&frame, 1 << 14, 0.5, 4, &specvar::progress::Silent).unwrap();
    let grid = PixelPowerParams::default();
    let cases: [(Box<dyn Sampler>, Randomization); 3] = [
        (Box::new(Jitter::new(2).unwrap()), Randomization::None),
        (SamplerKind::Sobol.build(2).unwrap(), Randomization::None),
        (
            SamplerKind::SobolNet.build(2).unwrap(),
            Randomization::DigitalShift,
        ),
    ];
    for (sampler, expected) in cases {
        let n = 16;
        let predicted =
            predict_mse_per_pixel(&frame, sampler.as_ref(), expected, n, 0.5, &grid, 7).unwrap();
        assert_eq!(predicted.randomization, expected);
        let native = RenderParams {
            rays: n,
            randomization: RandomizationChoice::Native,
            ..Default::default()
        };
        let r = render_ao(
            &frame,
            sampler.as_ref(),
            &native,
            &specvar::progress::Silent,
        )
        .unwrap();
        assert_eq!(r.randomization, expected);
        let (mean, se) = mean_mse(&frame, sampler.as_ref(), &reference, |seed| RenderParams {
            seed,
            ..native
        });
        let allowed = Z_999 * se.hypot(predicted.budget.spectrum_noise)
            + predicted.budget.quadrature
            + predicted.budget.truncation
            + predicted.budget.model;
        assert!(
            (mean - predicted.variance).abs() < allowed,
            "{}: measured {mean:e} ± {se:e}, predicted {:e}",
            sampler.name(),
            predicted.variance
        );
    }
}

/// The measured MSE averaged over 40 independent renders (`params(seed)` for seeds 0 to 39), and
/// its standard error from their spread.
fn mean_mse(
    frame: &Frame,
    sampler: &dyn Sampler,
    reference: &Reference,
    params: impl Fn(u64) -> RenderParams,
) -> (f64, f64) {
    let mses: Vec<f64> = (0..40)
        .map(|seed| {
            let r = render_ao(frame, sampler, &params(seed), &specvar::progress::Silent).unwrap();
            measure_mse(&r, reference).unwrap().mse
        })
        .collect();
    let s = mses.len() as f64;
    let mean = mses.iter().sum::<f64>() / s;
    let se = (mses.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (s - 1.0) / s).sqrt();
    (mean, se)
}
