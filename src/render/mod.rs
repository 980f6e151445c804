//! Ambient occlusion rendered with every sampler, its measured error, and its error predicted
//! from spectra.
//!
//! A small CPU ray tracer ([`geometry`]) shoots one primary ray through each pixel centre of a
//! Cornell-box-like scene. At the surface point, ambient occlusion is an integral over primary
//! sample space `[0,1)²` ([`ao`]). Each pixel estimates it from its own homogenized pattern of N
//! points: one of a pool of patterns (realizations of the sampler) under the pixel's own random
//! toroidal shift, so that every pixel's estimator is unbiased and its mean squared error is
//! its variance.
//!
//! That variance is, by the lattice form, `(1/N) Σ_{k≠0} |V̂_p(k)|² P_S(k)` for the pixel's
//! visibility `V_p` and the sampler's expected spectrum `P_S` at N, and so the image's MSE is
//! `(1/N) Σ_{k≠0} A(k) P_S(k)` with `A` the mean over pixels of `|V̂_p|²` ([`pixel_power`]):
//! one rasterization of the pixels' visibilities serves every sampler.
//!
//! A renderer uses strata and nets as drawn, or under a digital shift
//! ([`RenderParams::randomization`]); their pixels' variances keep cross terms between
//! frequencies that no mean power carries, so the image's MSE is then the mean of each pixel's
//! own prediction for that estimator ([`predict_mse_per_pixel`]).

pub mod ao;
mod compare;
pub mod geometry;
mod image;
mod mse;
mod power_cache;

pub use compare::{
    all_2d_samplers, compare, comparison_table, measured_ratio, run_comparison, samplers_for_rays,
    talk_mse, talk_ratio, write_comparison, Comparison, ComparisonConfig, ComparisonRow, TALK_MSE,
};
pub use image::{AoImage, Reference, ReferenceKey};
pub use mse::{
    measure_mse, pixel_power, predict_mse, predict_mse_per_pixel, MseEstimate, PixelPowerParams,
};
pub use power_cache::cached_pixel_power;

use crate::error::{invalid, Result};
use crate::pointset::PointSet;
use crate::progress::Progress;
use crate::randomization::{Randomization, RandomizationChoice, UnitTransform};
use crate::rng::{realization_rng, Stream};
use crate::sampler::{uniform, uniform_index, Sampler};
use ao::ShadingPoint;
use geometry::Scene;
use rayon::prelude::*;

/// The largest image side accepted.
pub const MAX_SIDE: usize = 4096;

/// A scene seen at a resolution: the shading point of every pixel, found once.
#[derive(Debug, Clone)]
pub struct Frame {
    scene: Scene,
    width: usize,
    height: usize,
    points: Vec<Option<ShadingPoint>>,
}

impl Frame {
    /// Traces the primary rays of a `width × height` image (row 0 at the top).
    ///
    /// # Errors
    /// A side of 0 or above [`MAX_SIDE`].
    pub fn new(scene: Scene, width: usize, height: usize) -> Result<Self> {
        for (name, side) in [("image width", width), ("image height", height)] {
            if !(1..=MAX_SIDE).contains(&side) {
                return Err(invalid(name, side, format!("1 to {MAX_SIDE} pixels")));
            }
        }
        let points = (0..width * height)
            .into_par_iter()
            .map(|i| {
                let ray = scene
                    .camera
                    .primary_ray(i % width, i / width, width, height);
                scene.first_hit(&ray).map(|hit| ShadingPoint::new(&hit))
            })
            .collect();
        Ok(Self {
            scene,
            width,
            height,
            points,
        })
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }
    /// Pixels per row.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Rows.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Pixel `i`'s shading point (`None` where the primary ray leaves the scene).
    pub fn point(&self, i: usize) -> Option<&ShadingPoint> {
        self.points[i].as_ref()
    }
    /// `width × height`.
    pub fn pixels(&self) -> usize {
        self.points.len()
    }
}

/// How an image is rendered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderParams {
    /// Secondary rays (sample points) per pixel: the pattern's N. Default 96.
    pub rays: usize,
    /// Surfaces farther than this do not occlude. Default 0.5 (the room's side is 1).
    pub max_distance: f64,
    /// Seed of the patterns and shifts.
    pub seed: u64,
    /// Distinct patterns per image (default 1024): pixel `p` uses pattern `h(p) mod P` for a
    /// hash `h` of the seed and `p`, under its own shift; each pixel has its own pattern when
    /// the image has at most `P` pixels. Costly samplers (CCVT) need the pool.
    pub patterns: usize,
    /// How each pixel randomizes its pattern: under its own shift (the default, the talk's
    /// homogenized estimator), as the sampler is used (`Native`), or one randomization for all.
    pub randomization: RandomizationChoice,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            rays: 96,
            max_distance: 0.5,
            seed: 0,
            patterns: 1024,
            randomization: RandomizationChoice::Given(Randomization::Shift),
        }
    }
}

impl RenderParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// Zero rays or patterns, or a maximum distance that is not positive and finite.
    pub fn check(&self) -> Result<()> {
        if self.rays == 0 {
            return Err(invalid("rays", 0, "at least 1"));
        }
        check_max_distance(self.max_distance)?;
        if self.patterns == 0 {
            return Err(invalid("patterns", 0, "at least 1"));
        }
        Ok(())
    }
}

/// Errors unless the maximum occlusion distance is positive and finite.
pub(crate) fn check_max_distance(max_distance: f64) -> Result<()> {
    if !(max_distance.is_finite() && max_distance > 0.0) {
        return Err(invalid("max distance", max_distance, "positive and finite"));
    }
    Ok(())
}

/// A rendered image and which pattern each pixel used (pixels sharing a pattern are not
/// independent, so the measured MSE's standard error groups them).
#[derive(Debug, Clone, PartialEq)]
pub struct Rendering {
    /// The sampler's name.
    pub sampler: String,
    /// The parameters.
    pub params: RenderParams,
    /// The image.
    pub image: AoImage,
    /// Pattern index per pixel.
    pub pattern: Vec<u32>,
    /// How each pixel's pattern was randomized.
    pub randomization: Randomization,
}

/// The pattern of pixel `p` in a pool of `pool` patterns for an image of `pixels` pixels.
fn pattern_of(seed: u64, p: usize, pool: usize, pixels: usize) -> usize {
    if pool >= pixels {
        p
    } else {
        uniform_index(&mut realization_rng(seed, p as u64, Stream::Trial), pool)
    }
}

/// Renders ambient occlusion with `sampler` (2D; used fixed and homogenized here, per pixel),
/// advancing `progress` once per finished row.
///
/// # Errors
/// A sampler that is not 2D or cannot produce `params.rays` points, or invalid parameters.
///
/// # Examples
/// ```
/// use specvar::render::{geometry::Scene, render_ao, Frame, RenderParams};
/// use specvar::sampler::Jitter;
/// let frame = Frame::new(Scene::cornell_box(), 8, 8).unwrap();
/// let params = RenderParams { rays: 16, ..Default::default() };
/// let r = render_ao(&frame, &Jitter::new(2).unwrap(), &params, &specvar::progress::Silent).unwrap();
/// assert_eq!(r.image.values.len(), 64);
/// assert!(r.image.values.iter().all(|v| (0.0..=1.0).contains(v)));
/// ```
pub fn render_ao(
    frame: &Frame,
    sampler: &dyn Sampler,
    params: &RenderParams,
    progress: &dyn Progress,
) -> Result<Rendering> {
    params.check()?;
    if sampler.dimension() != 2 {
        return Err(invalid(
            "sampler dimension",
            sampler.dimension(),
            "2 (primary sample space of the hemisphere)",
        ));
    }
    sampler.check_count(params.rays)?;
    let pixels = frame.pixels();
    let pool = params.patterns.min(pixels);
    let patterns: Vec<PointSet> = (0..pool as u64)
        .into_par_iter()
        .map(|i| sampler.sample(params.rays, params.seed, i))
        .collect::<Result<_>>()?;
    let pattern: Vec<u32> = (0..pixels)
        .map(|p| pattern_of(params.seed, p, pool, pixels) as u32)
        .collect();
    let randomization = params.randomization.resolve(
        sampler
            .kind()
            .map_or(Randomization::Shift, |k| k.native_randomization()),
    );
    let values = per_row(frame, progress, |p| {
        frame.point(p).map_or(1.0, |point| {
            let transform = randomization.draw(2, params.seed, p as u64);
            randomized_estimate(
                frame.scene(),
                point,
                &patterns[pattern[p] as usize],
                params.max_distance,
                &transform,
            )
        })
    });
    Ok(Rendering {
        sampler: sampler.name().to_string(),
        params: *params,
        image: AoImage {
            width: frame.width(),
            height: frame.height(),
            values,
        },
        pattern,
        randomization,
    })
}

/// The mean visibility over `pattern` randomized by the pixel's own `transform` (its shift, its
/// digital shift, or none).
fn randomized_estimate(
    scene: &Scene,
    point: &ShadingPoint,
    pattern: &PointSet,
    max_distance: f64,
    transform: &UnitTransform,
) -> f64 {
    let near = point.near(scene, max_distance);
    let visible: f64 = pattern
        .points()
        .map(|u| {
            let v = [transform.coordinate(0, u[0]), transform.coordinate(1, u[1])];
            point.visibility_near(scene, near, &v, max_distance)
        })
        .sum();
    visible / pattern.len() as f64
}

/// `value(p)` for every pixel, in parallel by rows, advancing `progress` once per row.
fn per_row(
    frame: &Frame,
    progress: &dyn Progress,
    value: impl Fn(usize) -> f64 + Sync,
) -> Vec<f64> {
    let width = frame.width();
    let mut values = vec![0.0; frame.pixels()];
    values
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, out)| {
            for (x, slot) in out.iter_mut().enumerate() {
                *slot = value(row * width + x);
            }
            progress.advance(1);
        });
    values
}

/// Renders the reference: `rays` independent uniform rays per pixel (the ray stream of
/// `(seed, pixel)`), advancing `progress` once per row.
///
/// # Errors
/// Fewer than 2 rays or invalid parameters.
pub fn render_reference(
    frame: &Frame,
    rays: usize,
    max_distance: f64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Reference> {
    if rays < 2 {
        return Err(invalid("reference rays", rays, "at least 2"));
    }
    check_max_distance(max_distance)?;
    let values = per_row(frame, progress, |p| {
        frame.point(p).map_or(1.0, |point| {
            let mut rng = realization_rng(seed, p as u64, Stream::Reference);
            let near = point.near(frame.scene(), max_distance);
            let visible: f64 = (0..rays)
                .map(|_| {
                    let u = [uniform(&mut rng), uniform(&mut rng)];
                    point.visibility_near(frame.scene(), near, &u, max_distance)
                })
                .sum();
            visible / rays as f64
        })
    });
    Ok(Reference {
        key: ReferenceKey::new(frame, rays, max_distance, seed),
        image: AoImage {
            width: frame.width(),
            height: frame.height(),
            values,
        },
    })
}

/// The reference for `key`'s parameters from the cache in `dir`, or rendered (advancing
/// `progress` per row) and saved there. Returns it and whether it came from the cache.
///
/// # Errors
/// As [`render_reference`], or an unreadable cache or unwritable directory.
pub fn cached_reference(
    dir: &std::path::Path,
    frame: &Frame,
    rays: usize,
    max_distance: f64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<(Reference, bool)> {
    let key = ReferenceKey::new(frame, rays, max_distance, seed);
    if let Some(cached) = Reference::load(dir, &key)? {
        return Ok((cached, true));
    }
    let reference = render_reference(frame, rays, max_distance, seed, progress)?;
    // A cache that cannot be written only costs time, as for patterns: the reference is right.
    let _ = reference.save(dir);
    Ok((reference, false))
}
