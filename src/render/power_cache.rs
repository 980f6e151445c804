//! The pixels' mean visibility power, kept between runs as the reference image is: it depends
//! on the scene and the frame alone, not on any sampler, and rasterizing every pixel's
//! visibility grid costs more than all the predictions that read it.

use super::{pixel_power, Frame, PixelPowerParams};
use crate::error::{Error, Result};
use crate::predict::LatticePower;
use crate::progress::Progress;
use crate::spectrum::Lattice;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What the mean power depends on; it names the cache file and is checked on loading.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct PowerKey {
    /// The scene's name and version: a change of the scene changes the key.
    scene: String,
    width: usize,
    height: usize,
    max_distance: f64,
    resolution: usize,
    kmax: usize,
    stride: usize,
}

impl PowerKey {
    fn new(frame: &Frame, max_distance: f64, params: &PixelPowerParams) -> Self {
        Self {
            scene: frame.scene().name.clone(),
            width: frame.width(),
            height: frame.height(),
            max_distance,
            resolution: params.resolution,
            kmax: params.kmax,
            stride: params.stride,
        }
    }

    fn path_in(&self, dir: &Path) -> PathBuf {
        dir.join(format!(
            "pixel-power-{}-{}x{}-d{}-g{}-k{}-s{}.json",
            self.scene,
            self.width,
            self.height,
            self.max_distance,
            self.resolution,
            self.kmax,
            self.stride
        ))
    }
}

/// The file: the key and the power, whose floats JSON carries exactly.
#[derive(Serialize, Deserialize)]
struct PowerFile {
    key: PowerKey,
    power: Vec<f64>,
    beyond: f64,
    axis_beyond: f64,
    label: String,
}

/// [`pixel_power`] from the cache in `dir`, or computed (advancing `progress` as it does) and
/// saved there. Returns it and whether it came from the cache; a cached power is the computed
/// one bit for bit.
///
/// # Errors
/// As [`pixel_power`]. A cache that cannot be read or written is ignored: it costs time only.
pub fn cached_pixel_power(
    dir: &Path,
    frame: &Frame,
    max_distance: f64,
    params: &PixelPowerParams,
    progress: &dyn Progress,
) -> Result<(LatticePower, bool)> {
    params.check()?;
    let key = PowerKey::new(frame, max_distance, params);
    let lattice = Lattice {
        dimension: 2,
        kmax: params.kmax,
    };
    if let Some(power) = load(dir, &key, lattice) {
        return Ok((power, true));
    }
    let power = pixel_power(frame, max_distance, params, progress)?;
    let _ = save(dir, key, &power);
    Ok((power, false))
}

fn load(dir: &Path, key: &PowerKey, lattice: Lattice) -> Option<LatticePower> {
    let text = std::fs::read_to_string(key.path_in(dir)).ok()?;
    let file: PowerFile = serde_json::from_str(&text).ok()?;
    (file.key == *key && file.power.len() == lattice.len()).then_some(LatticePower {
        lattice,
        power: file.power,
        beyond: file.beyond,
        axis_beyond: file.axis_beyond,
        label: file.label,
    })
}

fn save(dir: &Path, key: PowerKey, power: &LatticePower) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let path = key.path_in(dir);
    let file = PowerFile {
        key,
        power: power.power.clone(),
        beyond: power.beyond,
        axis_beyond: power.axis_beyond,
        label: power.label.clone(),
    };
    let text = serde_json::to_string(&file).map_err(|e| Error::format("pixel power", e))?;
    crate::output::write_atomic(&path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::Silent;
    use crate::render::geometry::Scene;

    #[test]
    fn a_cached_power_is_the_computed_one_and_another_key_is_computed_anew() {
        let dir = std::env::temp_dir().join(format!("specvar-power-cache-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let frame = Frame::new(Scene::cornell_box(), 6, 4).unwrap();
        let params = PixelPowerParams {
            resolution: 16,
            kmax: 8,
            stride: 1,
        };
        let (computed, cached) = cached_pixel_power(&dir, &frame, 0.5, &params, &Silent).unwrap();
        assert!(!cached);
        let (loaded, cached) = cached_pixel_power(&dir, &frame, 0.5, &params, &Silent).unwrap();
        assert!(cached);
        assert_eq!(loaded, computed);
        let bits = |p: &LatticePower| p.power.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&loaded), bits(&computed));
        // Another distance is another key: computed, and equal to the uncached computation.
        let (other, cached) = cached_pixel_power(&dir, &frame, 0.25, &params, &Silent).unwrap();
        assert!(!cached);
        assert_eq!(other, pixel_power(&frame, 0.25, &params, &Silent).unwrap());
        assert_ne!(other, computed);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
