//! Drawing a costly pattern once when several computations ask for the same realization.

use super::{Sampler, SamplerKind};
use crate::error::Result;
use crate::pointset::PointSet;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// A sampler that keeps the patterns it has drawn, keyed by `(N, seed, realization)`, up to a
/// memory budget: predictions of several integrands from one sampler, or a study that returns
/// to an N, draw each costly pattern (CCVT, dart throwing) once. The patterns are the inner
/// sampler's, bit for bit.
///
/// # Examples
/// ```
/// use specvar::sampler::{Ccvt, Memoized, Sampler};
/// let ccvt = Memoized::new(Ccvt::new(2)?, 64 << 20);
/// let a = ccvt.sample(64, 1, 0)?; // drawn
/// let b = ccvt.sample(64, 1, 0)?; // kept
/// assert_eq!(a, b);
/// # Ok::<(), specvar::Error>(())
/// ```
pub struct Memoized<S> {
    inner: S,
    kept: Mutex<Store>,
}

/// The inner sampler's text: the patterns are its own, so caches key them alike.
impl<S: Sampler> std::fmt::Debug for Memoized<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.inner.fmt(f)
    }
}

struct Store {
    patterns: HashMap<(usize, u64, u64), Arc<PointSet>>,
    bytes: usize,
    budget: usize,
}

impl<S: Sampler> Memoized<S> {
    /// Keeps up to `budget_bytes` of `inner`'s patterns (beyond it, patterns are drawn and not
    /// kept).
    pub fn new(inner: S, budget_bytes: usize) -> Self {
        Self {
            inner,
            kept: Mutex::new(Store {
                patterns: HashMap::new(),
                bytes: 0,
                budget: budget_bytes,
            }),
        }
    }
}

impl<S: Sampler> Sampler for Memoized<S> {
    fn name(&self) -> &'static str {
        self.inner.name()
    }
    fn dimension(&self) -> usize {
        self.inner.dimension()
    }
    fn kind(&self) -> Option<SamplerKind> {
        self.inner.kind()
    }
    fn check_count(&self, n: usize) -> Result<()> {
        self.inner.check_count(n)
    }
    fn closed_form(&self, n: usize) -> Option<super::ClosedForm> {
        self.inner.closed_form(n)
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        let key = (n, seed, realization);
        if let Some(p) = self
            .kept
            .lock()
            .ok()
            .and_then(|s| s.patterns.get(&key).cloned())
        {
            return Ok((*p).clone());
        }
        let points = self.inner.sample(n, seed, realization)?;
        if let Ok(mut store) = self.kept.lock() {
            let bytes = std::mem::size_of_val(points.coords());
            if store.bytes + bytes <= store.budget {
                store.bytes += bytes;
                store.patterns.insert(key, Arc::new(points.clone()));
            }
        }
        Ok(points)
    }
}
