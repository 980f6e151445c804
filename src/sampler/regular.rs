//! The cell-centred regular grid.

use super::{check_perfect_power, check_supported, Sampler};
use crate::error::Result;
use crate::pointset::{PointSet, MAX_DIMENSION};

/// Points at the cell centres `(j + 1/2)/m` of an `m^d` grid. Deterministic: the seed and the
/// realization are ignored, so use [`super::Homogenized`] for a randomized version.
#[derive(Debug, Clone, Copy)]
pub struct Regular {
    dimension: usize,
}

impl Regular {
    /// The regular grid in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported("regular", d, 1..=MAX_DIMENSION)?;
        Ok(Self { dimension: d })
    }
}

/// Calls `f(point_index, axis, cell)` for the `m^d` cells of a grid, last axis fastest.
pub(crate) fn for_each_cell(m: usize, d: usize, mut f: impl FnMut(usize, usize, usize)) {
    let n = m.pow(d as u32);
    for i in 0..n {
        let mut rest = i;
        for axis in (0..d).rev() {
            f(i, axis, rest % m);
            rest /= m;
        }
    }
}

impl Sampler for Regular {
    fn name(&self) -> &'static str {
        "regular"
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn check_count(&self, n: usize) -> Result<()> {
        check_perfect_power(self.name(), self.dimension, n).map(|_| ())
    }
    fn sample(&self, n: usize, _seed: u64, _realization: u64) -> Result<PointSet> {
        let d = self.dimension;
        let m = check_perfect_power(self.name(), d, n)?;
        let mut coords = vec![0.0; n * d];
        for_each_cell(m, d, |i, axis, cell| {
            coords[i * d + axis] = (cell as f64 + 0.5) / m as f64;
        });
        Ok(PointSet::from_trusted(d, coords))
    }
    fn is_scale_invariant(&self) -> bool {
        false
    }
}
