//! Homogenization: a random toroidal shift (Cranley–Patterson rotation).

use super::ClosedForm;
use super::{Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::{PointSet, MAX_DIMENSION};

/// Adds one uniform random vector to every point, modulo 1, drawn from the shift stream of
/// `(seed, realization)` ([`homogenizing_shift`]). Any pattern so shifted gives an unbiased
/// estimator.
pub fn homogenize(points: &mut PointSet, seed: u64, realization: u64) {
    let d = points.dimension();
    let shift = homogenizing_shift(d, seed, realization);
    // The shift has the right length and finite entries, so translate cannot fail.
    let _ = points.translate(&shift[..d]);
}

/// The random shift that [`homogenize`] applies for `(seed, realization)` in dimension `d`
/// (components beyond `d` are 0).
pub fn homogenizing_shift(d: usize, seed: u64, realization: u64) -> [f64; MAX_DIMENSION] {
    crate::randomization::toroidal_shift(d, seed, realization)
}

/// Wraps any sampler so that every realization is homogenized. The inner, fixed pattern stays
/// available through [`Homogenized::inner`].
///
/// # Examples
/// ```
/// use specvar::sampler::{Homogenized, Regular, Sampler};
/// let grid = Homogenized::new(Regular::new(2).unwrap());
/// let a = grid.sample(4, 1, 0).unwrap();
/// let b = grid.sample(4, 1, 1).unwrap();
/// assert_ne!(a, b); // two realizations, two shifts
/// ```
#[derive(Debug, Clone)]
pub struct Homogenized<S> {
    inner: S,
}

impl<S: Sampler> Homogenized<S> {
    /// Homogenizes `inner`.
    pub fn new(inner: S) -> Self {
        Self { inner }
    }
    /// The fixed (unshifted) sampler.
    pub fn inner(&self) -> &S {
        &self.inner
    }
}

impl<S: Sampler> Sampler for Homogenized<S> {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn dimension(&self) -> usize {
        self.inner.dimension()
    }
    fn check_count(&self, n: usize) -> Result<()> {
        self.inner.check_count(n)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        let mut p = self.inner.sample(n, seed, realization)?;
        homogenize(&mut p, seed, realization);
        Ok(p)
    }
    fn kind(&self) -> Option<SamplerKind> {
        self.inner.kind()
    }
    fn closed_form(&self, n: usize) -> Option<ClosedForm> {
        // The closed forms are the homogenized spectra already.
        self.inner.closed_form(n)
    }
}

impl Sampler for Box<dyn Sampler> {
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn dimension(&self) -> usize {
        (**self).dimension()
    }
    fn check_count(&self, n: usize) -> Result<()> {
        (**self).check_count(n)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        (**self).sample(n, seed, realization)
    }
    fn kind(&self) -> Option<SamplerKind> {
        (**self).kind()
    }
    fn closed_form(&self, n: usize) -> Option<ClosedForm> {
        (**self).closed_form(n)
    }
}
