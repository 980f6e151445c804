//! Measures of a point set beside its spectrum: L2 discrepancies, the pair correlation
//! function, and distances between points.

mod discrepancy;
mod distance;
mod pcf;

pub use discrepancy::{squared_discrepancy, DiscrepancyKind, MAX_DISCREPANCY_POINTS};
pub use distance::{
    distances, distances_within, effective_nyquist, hexagonal_nyquist, Distances, NYQUIST_THRESHOLD,
};
pub use pcf::{pair_correlation, Pcf, PcfParams};

/// How far in `ν` a summary of a pattern's spectrum reads it (the effective Nyquist
/// frequency): past every blue-noise peak.
pub const SUMMARY_NU: f64 = 1.5;

/// The lattice extent of a summary's spectrum at `n` points in dimension `d`: up to
/// [`SUMMARY_NU`], and at least 4.
pub fn summary_kmax(n: usize, d: usize) -> usize {
    crate::spectrum::kmax_at_nu(n, d, SUMMARY_NU).max(4)
}

use crate::budget::{Budget, Needs};
use crate::error::Result;
use crate::pointset::PointSet;

/// A quantity measured on several patterns: its mean and the standard error of the mean (0
/// with one pattern).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Mean {
    /// The mean over the patterns.
    pub mean: f64,
    /// Its standard error.
    pub stderr: f64,
}

impl Mean {
    /// The mean and standard error of `values`.
    pub fn of(values: &[f64]) -> Self {
        let m = values.len() as f64;
        let mean = values.iter().sum::<f64>() / m;
        let ss: f64 = values.iter().map(|v| (v - mean).powi(2)).sum();
        let stderr = if values.len() > 1 {
            (ss / (m - 1.0) / m).sqrt()
        } else {
            0.0
        };
        Self { mean, stderr }
    }
}

/// Every squared discrepancy of [`DiscrepancyKind::ALL`], averaged over `patterns`.
///
/// # Errors
/// As [`squared_discrepancy`].
pub fn discrepancy_means(patterns: &[PointSet]) -> Result<Vec<(DiscrepancyKind, Mean)>> {
    DiscrepancyKind::ALL
        .iter()
        .map(|&kind| {
            let values = patterns
                .iter()
                .map(|p| squared_discrepancy(p, kind))
                .collect::<Result<Vec<_>>>()?;
            Ok((kind, Mean::of(&values)))
        })
        .collect()
}

/// The work of visiting `share` of the `N²` ordered pairs of `n` points in each of `patterns`
/// sets, at [`crate::costs::PAIR_DISTANCE_SECONDS`] a pair.
pub(crate) fn pair_needs(patterns: usize, n: usize, share: f64) -> Needs {
    Needs::work(patterns as f64 * (n as f64).powi(2) * share * crate::costs::PAIR_DISTANCE_SECONDS)
}

/// What a summary of `patterns` sets of `n` points in `d` dimensions needs beyond drawing them
/// (their distances and pair correlation, `O(N²)` each, and the sets held at once), to check
/// before they are drawn.
pub fn summary_needs(patterns: usize, n: usize, d: usize) -> Needs {
    let held = Needs::memory(patterns as f64 * n as f64 * d as f64 * 8.0);
    held.and(pair_needs(patterns, n, 1.0))
        .and(pair_needs(patterns, n, 0.5))
}

/// The smallest nearest-neighbour distance over `patterns` and the mean of their mean
/// nearest-neighbour distances, relative to the densest packing's (see [`distances`]), within
/// `budget`.
///
/// # Errors
/// As [`distances_within`].
pub fn distance_summary(patterns: &[PointSet], budget: &Budget) -> Result<Distances> {
    let found = patterns
        .iter()
        .map(|p| distances_within(p, budget))
        .collect::<Result<Vec<_>>>()?;
    Ok(Distances {
        min_distance: found
            .iter()
            .map(|d| d.min_distance)
            .fold(f64::INFINITY, f64::min),
        mean_min_distance: found.iter().map(|d| d.mean_min_distance).sum::<f64>()
            / found.len().max(1) as f64,
    })
}
