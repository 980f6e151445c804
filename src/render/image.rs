//! Ambient-occlusion images, the reference image and its on-disk cache.

use crate::error::{invalid, Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A grey image of linear ambient-occlusion values in `[0, 1]`, row 0 at the top.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AoImage {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Row-major values.
    pub values: Vec<f64>,
}

impl AoImage {
    /// An 8-bit PNG for display: the linear values through the sRGB transfer curve. (Errors are
    /// always measured on the linear values.)
    ///
    /// # Errors
    /// An image whose value count is not `width × height`.
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let pixels: Vec<u8> = self
            .values
            .iter()
            .map(|&v| (srgb(v.clamp(0.0, 1.0)) * 255.0).round() as u8)
            .collect();
        crate::plot::gray_png(&pixels, self.width, self.height)
    }

    /// Writes [`to_png`](Self::to_png) to `path`.
    ///
    /// # Errors
    /// As `to_png`, or an unwritable file.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        crate::output::write_atomic(path, &self.to_png()?)
    }
}

/// The sRGB transfer curve.
fn srgb(linear: f64) -> f64 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// What a reference image depends on; it names the cache file and is checked on loading.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceKey {
    /// The scene's name and version: a change of the scene changes the key.
    pub scene: String,
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Independent uniform rays per pixel.
    pub rays: usize,
    /// The maximum occlusion distance.
    pub max_distance: f64,
    /// The seed of the reference's random rays.
    pub seed: u64,
}

impl ReferenceKey {
    /// The key of a reference of `frame` with `rays` rays per pixel.
    pub fn new(frame: &super::Frame, rays: usize, max_distance: f64, seed: u64) -> Self {
        Self {
            scene: frame.scene().name.clone(),
            width: frame.width(),
            height: frame.height(),
            rays,
            max_distance,
            seed,
        }
    }

    /// The cache file for this key in `dir`.
    pub fn path_in(&self, dir: &Path) -> PathBuf {
        dir.join(format!(
            "reference-{}-{}x{}-r{}-d{}-s{}.json",
            self.scene, self.width, self.height, self.rays, self.max_distance, self.seed
        ))
    }
}

/// A reference image from `rays` independent uniform rays per pixel, with the estimated
/// variance of each of its pixels: `p̂(1 - p̂)/(R - 1)`, unbiased for the variance of a mean of
/// `R` Bernoulli visibilities. Subtracting it from the squared error against the reference
/// removes the reference's own noise from a measured MSE, in expectation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reference {
    /// What it was computed for.
    pub key: ReferenceKey,
    /// The image.
    pub image: AoImage,
}

impl Reference {
    /// The unbiased estimate of pixel `i`'s variance.
    pub fn pixel_variance(&self, i: usize) -> f64 {
        let p = self.image.values[i];
        p * (1.0 - p) / (self.key.rays as f64 - 1.0).max(1.0)
    }

    /// Loads the cached reference for `key` from `dir`, if present, readable and computed for
    /// `key`; a damaged or foreign file counts as absent (it is recomputed and overwritten).
    ///
    /// # Errors
    /// None today; the `Result` leaves room for caches that must report failures.
    pub fn load(dir: &Path, key: &ReferenceKey) -> Result<Option<Self>> {
        let path = key.path_in(dir);
        let Ok(text) = std::fs::read_to_string(&path) else {
            return Ok(None);
        };
        let Ok(reference) = serde_json::from_str::<Reference>(&text) else {
            return Ok(None);
        };
        let sized = reference.image.values.len() == key.width * key.height;
        Ok((reference.key == *key && sized).then_some(reference))
    }

    /// Writes the reference to its cache file in `dir` (creating `dir`).
    ///
    /// # Errors
    /// An unwritable directory or file.
    pub fn save(&self, dir: &Path) -> Result<PathBuf> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let path = self.key.path_in(dir);
        let text = serde_json::to_string(self).map_err(|e| Error::format("reference image", e))?;
        crate::output::write_atomic(&path, text.as_bytes())?;
        Ok(path)
    }

    /// Checks that `image` has this reference's size.
    ///
    /// # Errors
    /// [`Error::Mismatch`] otherwise.
    pub fn check_size(&self, image: &AoImage) -> Result<()> {
        if (image.width, image.height) != (self.image.width, self.image.height) {
            return Err(Error::Mismatch(format!(
                "a {} × {} image against a {} × {} reference",
                image.width, image.height, self.image.width, self.image.height
            )));
        }
        if self.key.rays < 2 {
            return Err(invalid("reference rays", self.key.rays, "at least 2"));
        }
        Ok(())
    }
}
