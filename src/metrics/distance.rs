//! Nearest-neighbour distances relative to the densest packing, and the effective Nyquist
//! frequency of a radial spectrum.

use crate::budget::Budget;
use crate::error::{invalid, Result};
use crate::pointset::{toroidal_distance_sq, PointSet};
use crate::sampler::max_packing_radius;
use crate::spectrum::RadialSpectrum;
use rayon::prelude::*;
use serde::Serialize;

/// Nearest-neighbour distances of a pattern on the torus, relative to the neighbour distance
/// of the densest packing of as many points (the hexagonal lattice in 2D, FCC in 3D).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Distances {
    /// The smallest distance between two points, relative to the packing's.
    pub min_distance: f64,
    /// The mean over the points of their nearest neighbour's distance, relative to the
    /// packing's.
    pub mean_min_distance: f64,
}

/// The distances of `points` (1 to 3 dimensions, at least 2 points), in `O(N²)`.
///
/// # Errors
/// A dimension above 3, fewer than 2 points, or work beyond the default budget
/// ([`distances_within`] takes another).
///
/// # Examples
/// ```
/// use specvar::metrics::distances;
/// use specvar::sampler::{Regular, Sampler};
/// // A square grid's neighbours are 1/m apart: √(√3/2) ≈ 0.93 of the hexagonal packing's.
/// let grid = Regular::new(2)?.sample(64, 0, 0)?;
/// let d = distances(&grid)?;
/// assert!((d.min_distance - (3f64.sqrt() / 2.0).sqrt()).abs() < 1e-12);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn distances(points: &PointSet) -> Result<Distances> {
    distances_within(points, &Budget::default())
}

/// [`distances`] within `budget`.
///
/// # Errors
/// As [`distances`], the work checked against `budget`.
pub fn distances_within(points: &PointSet, budget: &Budget) -> Result<Distances> {
    let (n, d) = (points.len(), points.dimension());
    if !(1..=3).contains(&d) {
        return Err(invalid("dimension", d, "1 to 3"));
    }
    if n < 2 {
        return Err(invalid("point count", n, "at least 2"));
    }
    budget.check(
        "nearest-neighbour distances",
        super::pair_needs(1, n, 1.0),
        "use fewer points",
    )?;
    let nearest: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|i| {
            (0..n)
                .filter(|&j| j != i)
                .map(|j| toroidal_distance_sq(points.point(i), points.point(j)))
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        })
        .collect();
    let packing = max_packing_radius(d, n);
    let min = nearest.iter().copied().fold(f64::INFINITY, f64::min);
    let mean = nearest.iter().sum::<f64>() / n as f64;
    Ok(Distances {
        min_distance: min / packing,
        mean_min_distance: mean / packing,
    })
}

/// The power below which a spectrum counts as suppressed for the effective Nyquist
/// frequency: 0.1, i.e. −10 dB (Heck, Schlömer and Deussen 2013).
pub const NYQUIST_THRESHOLD: f64 = 0.1;

/// The hexagonal lattice's Nyquist frequency in `ν = |k|/√N`: half its shortest dual vector,
/// `1/√(2√3) ≈ 0.537`.
pub fn hexagonal_nyquist() -> f64 {
    1.0 / (2.0 * 3f64.sqrt()).sqrt()
}

/// The effective Nyquist frequency `ν_eff`: the largest `ν` below which every ring of the radial
/// spectrum lies under [`NYQUIST_THRESHOLD`] (interpolated linearly between the last ring
/// below and the first at or above it). `None` if the first ring is already at or above it
/// (white noise) or no ring reaches it.
///
/// # Examples
/// ```
/// use specvar::metrics::effective_nyquist;
/// use specvar::sampler::Jitter;
/// use specvar::spectrum::{estimate, SpectrumParams};
/// let params = SpectrumParams { realizations: 16, kmax: 64, ..Default::default() };
/// let e = estimate(&Jitter::new(2)?, 1024, &params)?;
/// let nu = effective_nyquist(&e.radial).unwrap();
/// assert!(nu > 0.1 && nu < 0.3); // 1 - sinc² reaches 0.1 near ν = 0.18 along a diagonal
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn effective_nyquist(radial: &RadialSpectrum) -> Option<f64> {
    let bins = &radial.bins;
    let first_above = bins.iter().position(|b| b.power >= NYQUIST_THRESHOLD)?;
    if first_above == 0 {
        return None;
    }
    let (below, above) = (&bins[first_above - 1], &bins[first_above]);
    let t = (NYQUIST_THRESHOLD - below.power) / (above.power - below.power);
    Some(below.nu + t * (above.nu - below.nu))
}
