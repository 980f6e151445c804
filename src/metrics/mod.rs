//! Measures of a point set beside its spectrum: L2 discrepancies, the pair correlation
//! function, and distances between points.

mod discrepancy;
mod distance;
mod pcf;

pub use discrepancy::{squared_discrepancy, DiscrepancyKind, MAX_DISCREPANCY_POINTS};
pub use distance::{distances, effective_nyquist, hexagonal_nyquist, Distances, NYQUIST_THRESHOLD};
pub use pcf::{pair_correlation, Pcf, PcfParams};

/// How far in `ν` a summary of a pattern's spectrum reads it (the effective Nyquist
/// frequency): past every blue-noise peak.
pub const SUMMARY_NU: f64 = 1.5;

/// The lattice extent of a summary's spectrum at `n` points in dimension `d`: up to
/// [`SUMMARY_NU`], and at least 4.
pub fn summary_kmax(n: usize, d: usize) -> usize {
    crate::spectrum::kmax_at_nu(n, d, SUMMARY_NU).max(4)
}

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

/// The smallest nearest-neighbour distance over `patterns` and the mean of their mean
/// nearest-neighbour distances, relative to the densest packing's (see [`distances`]).
///
/// # Errors
/// As [`distances`].
pub fn distance_summary(patterns: &[PointSet]) -> Result<Distances> {
    let found = patterns.iter().map(distances).collect::<Result<Vec<_>>>()?;
    Ok(Distances {
        min_distance: found
            .iter()
            .map(|d| d.min_distance)
            .fold(f64::INFINITY, f64::min),
        mean_min_distance: found.iter().map(|d| d.mean_min_distance).sum::<f64>()
            / found.len().max(1) as f64,
    })
}
