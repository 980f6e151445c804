//! Jittered (stratified) sampling.

use super::regular::for_each_cell;
use super::{check_perfect_power, check_supported, in_cell, uniform, Sampler};
use crate::error::Result;
use crate::pointset::{PointSet, MAX_DIMENSION};
use crate::rng::{realization_rng, Stream};

/// One uniform point in each cell of an `m^d` grid (`N = m^d`). Its expected power spectrum
/// at integer `k ≠ 0` is `1 - Π_i sinc²(π k_i / m)`.
#[derive(Debug, Clone, Copy)]
pub struct Jitter {
    dimension: usize,
}

impl Jitter {
    /// Jittered sampling in dimension `d` (1 to 8).
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported("jitter", d, 1..=MAX_DIMENSION)?;
        Ok(Self { dimension: d })
    }
}

impl Sampler for Jitter {
    fn name(&self) -> &'static str {
        "jitter"
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn check_count(&self, n: usize) -> Result<()> {
        check_perfect_power(self.name(), self.dimension, n).map(|_| ())
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        let d = self.dimension;
        let m = check_perfect_power(self.name(), d, n)?;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let mut coords = vec![0.0; n * d];
        for_each_cell(m, d, |i, axis, cell| {
            coords[i * d + axis] = in_cell(cell, uniform(&mut rng), m);
        });
        Ok(PointSet::from_trusted(d, coords))
    }
}
