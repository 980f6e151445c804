//! Measures of a point set beside its spectrum: L2 discrepancies, the pair correlation
//! function, and distances between points.

mod discrepancy;
mod distance;
mod pcf;

pub use discrepancy::{squared_discrepancy, DiscrepancyKind, MAX_DISCREPANCY_POINTS};
pub use distance::{distances, effective_nyquist, hexagonal_nyquist, Distances, NYQUIST_THRESHOLD};
pub use pcf::{pair_correlation, Pcf, PcfParams};
