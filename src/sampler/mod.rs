//! Samplers: patterns of N points on the unit torus.
//!
//! Every sampler implements [`Sampler`]; [`SamplerKind`] names them and holds every fact about
//! each one (closed form, scale invariance, isotropy, cost). Realization `i` of seed `s` is computed from `(s, i)` alone (see [`crate::rng`]), so it
//! is the same on any machine and thread count.

mod ccvt;
mod closed_form;
mod cmj;
mod facts;
mod fibonacci;
mod gaussian_jitter;
mod gbn;
mod halton;
mod homogenize;
mod jitter;
mod kind;
mod kronecker;
mod latin;
mod memo;
mod multi_jitter;
mod orthogonal;
mod pmj02;
mod poisson;
mod random;
mod rank1;
mod regular;
mod sobol;
mod sobol_net;

pub use ccvt::{Ccvt, CcvtParams, CcvtStats};
pub use closed_form::{fejer, sinc, ClosedForm, ClosedLattice, TailDeviation};
pub use cmj::CorrelatedMultiJitter;
pub use facts::{
    AxisStrata, CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness,
    SamplerFacts, Scaling, Symmetry, COST_REFERENCE_N, COST_TOLERANCE,
};
pub use gaussian_jitter::{
    GaussianJitter, DEFAULT_GAUSSIAN_WIDTH, MAX_GAUSSIAN_WIDTH, MIN_GAUSSIAN_WIDTH,
};
pub use gbn::{GaussianBlueNoise, GbnParams};
pub use halton::Halton;
pub(crate) use halton::HaltonRealization;
pub(crate) use halton::PRIMES as HALTON_BASES;
pub use homogenize::{homogenize, homogenizing_shift, Homogenized};
pub use jitter::Jitter;
pub use kind::{costly_realizations, Pool, SamplerKind, SamplerSummary, MIN_POOL_PATTERNS};
pub use kronecker::Kronecker;
pub use latin::LatinHypercube;
pub use memo::Memoized;
pub use multi_jitter::MultiJitter;
pub use orthogonal::OrthogonalArray;
pub use pmj02::{Pmj02, MAX_PMJ02_POINTS};
pub use poisson::{
    default_relative_radius, max_packing_radius, PoissonDisk, PoissonMethod, MAX_ATTEMPTS,
};
pub use random::Random;
pub use rank1::{shortest_dual_vector_sq, LatticeRule, Rank1Lattice};
pub use regular::{strata, Regular};
pub use sobol::Sobol;
pub use sobol_net::SobolNet;

use crate::error::{Error, Result};
use crate::pointset::PointSet;
use crate::randomization::Randomization;

/// A generator of point sets on `[0,1)^d` for a fixed dimension `d`. Its `Debug` text names
/// every parameter that shapes its patterns (the derived form does): caches key patterns by it.
pub trait Sampler: Send + Sync + std::fmt::Debug {
    /// Short name, as used on the command line.
    fn name(&self) -> &'static str;

    /// The dimension of the points this sampler produces.
    fn dimension(&self) -> usize;

    /// Checks that this sampler can produce exactly `n` points.
    ///
    /// # Errors
    /// [`Error::UnsupportedCount`] naming the rule and the nearest valid N.
    fn check_count(&self, n: usize) -> Result<()> {
        check_positive(self.name(), self.dimension(), n)
    }

    /// Realization `realization` of `seed`: exactly `n` points.
    ///
    /// # Errors
    /// An unsupported `n`, or a generator that cannot place `n` points.
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet>;

    /// Which of this crate's samplers this is, so that its facts ([`SamplerKind`]: closed form,
    /// scale invariance, isotropy, cost) are known; `None` for a sampler of one's own, which the
    /// predictions then treat as anisotropic and not scale invariant, with no closed form.
    fn kind(&self) -> Option<SamplerKind> {
        None
    }

    /// This sampler's exact expected power spectrum at `n` points, if one is known: by default
    /// its kind's ([`SamplerKind::closed_form`]); a sampler with parameters that enter the
    /// spectrum (Gaussian jitter's width) gives its own.
    fn closed_form(&self, n: usize) -> Option<ClosedForm> {
        self.kind().and_then(|k| k.closed_form(n, self.dimension()))
    }
}

/// What one pattern of `sampler` at `n` points costs: its kind's model
/// ([`SamplerKind::pattern_needs`]), or for a sampler of one's own a generous guess (32 bytes
/// and a microsecond a point).
pub fn pattern_needs(sampler: &dyn Sampler, n: usize) -> crate::budget::Needs {
    match sampler.kind() {
        Some(kind) => kind.pattern_needs(n, sampler.dimension()),
        None => crate::budget::Needs {
            memory_bytes: n as f64 * sampler.dimension() as f64 * 32.0,
            work_seconds: n as f64 * 1e-6,
        },
    }
}

/// Realizations `realizations` of `seed` at `n` points, drawn in parallel (the same bits as
/// one by one) and randomized by `randomization` (realization `r` by unit `r` of `seed`: for
/// the shift, [`homogenize`]), after checking their memory and work against `budget`.
///
/// # Errors
/// A count the sampler cannot draw, no realizations, a budget the sets would exceed, or a
/// sampler error.
///
/// # Examples
/// ```
/// use specvar::budget::Budget;
/// use specvar::randomization::Randomization;
/// use specvar::sampler::{draw_realizations, Jitter, Sampler};
/// let jitter = Jitter::new(2)?;
/// let sets = draw_realizations(&jitter, 16, 3, 4..6, Randomization::None, &Budget::default())?;
/// assert_eq!(sets[1], jitter.sample(16, 3, 5)?);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn draw_realizations(
    sampler: &dyn Sampler,
    n: usize,
    seed: u64,
    realizations: std::ops::Range<u64>,
    randomization: Randomization,
    budget: &crate::budget::Budget,
) -> Result<Vec<PointSet>> {
    use rayon::prelude::*;
    sampler.check_count(n)?;
    if realizations.is_empty() {
        return Err(crate::error::invalid(
            "realizations",
            realizations.end.saturating_sub(realizations.start),
            "at least 1",
        ));
    }
    let one = pattern_needs(sampler, n);
    let m = (realizations.end - realizations.start) as f64;
    let threads = rayon::current_num_threads().max(1) as f64;
    let needs = crate::budget::Needs {
        memory_bytes: m * (n * sampler.dimension() * 8) as f64 + threads * one.memory_bytes,
        work_seconds: m * one.work_seconds,
    };
    budget.check("sampling", needs, "lower N or the realizations")?;
    realizations
        .into_par_iter()
        .map(|r| {
            let set = sampler.sample(n, seed, r)?;
            Ok(match randomization {
                Randomization::None => set,
                _ => randomization.draw(set.dimension(), seed, r).apply(&set),
            })
        })
        .collect()
}

/// The randomization patterns are used with in practice: a built-in sampler's native one
/// ([`SamplerKind::native_randomization`]); for given point sets none, since they are used as
/// given (`None` here stands for point sets).
pub fn native_randomization(kind: Option<SamplerKind>) -> Randomization {
    kind.map_or(Randomization::None, SamplerKind::native_randomization)
}

/// The randomization `sampler`'s patterns are used with by default: a built-in sampler's
/// native one; for a sampler of one's own, whose law the crate does not know, the random
/// toroidal shift, the one estimator predicted for any law (as [`crate::predict::Problem::new`],
/// padded pairs and the renders take it).
///
/// # Examples
/// ```
/// use specvar::randomization::Randomization;
/// use specvar::sampler::{sampler_native_randomization, Jitter};
/// assert_eq!(sampler_native_randomization(&Jitter::new(2)?), Randomization::None);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn sampler_native_randomization(sampler: &dyn Sampler) -> Randomization {
    sampler
        .kind()
        .map_or(Randomization::Shift, SamplerKind::native_randomization)
}

/// Errors unless `d` lies in the dimensions `facts` declares.
pub(crate) fn check_supported(facts: &SamplerFacts, d: usize) -> Result<()> {
    let supported = &facts.dimensions;
    if supported.contains(&d) {
        Ok(())
    } else {
        Err(Error::UnsupportedDimension {
            sampler: facts.name,
            dimension: d,
            supported: format!("{} to {}", supported.start(), supported.end()),
        })
    }
}

/// Errors unless `n >= 1`.
pub(crate) fn check_positive(sampler: &'static str, d: usize, n: usize) -> Result<()> {
    if n == 0 {
        return Err(Error::UnsupportedCount {
            sampler,
            n,
            dimension: d,
            rule: "N must be at least 1".into(),
            nearest: "1".into(),
        });
    }
    Ok(())
}

/// The integer `m` with `m^d = n`, if there is one.
pub fn perfect_root(n: usize, d: usize) -> Option<usize> {
    let guess = (n as f64).powf(1.0 / d as f64).round() as usize;
    (guess.saturating_sub(1)..=guess + 1).find(|&m| m >= 1 && m.checked_pow(d as u32) == Some(n))
}

pub(crate) use crate::rng::uniform;
pub(crate) use cmj::{near_square_factors, Shuffles as CmjShuffles};

/// A uniform index in `0..n` (Lemire's multiply-shift; bias below 2^-32 for n < 2^32).
#[inline]
pub fn uniform_index<R: rand::Rng>(rng: &mut R, n: usize) -> usize {
    ((rng.next_u64() as u128 * n as u128) >> 64) as usize
}

/// A uniformly random permutation of `0..n` (Fisher–Yates).
pub(crate) fn random_permutation<R: rand::Rng>(rng: &mut R, n: usize) -> Vec<usize> {
    let mut p: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = uniform_index(rng, i + 1);
        p.swap(i, j);
    }
    p
}

/// `(cell + offset) / cells`, kept strictly below 1 against rounding.
#[inline]
pub(crate) fn in_cell(cell: usize, offset: f64, cells: usize) -> f64 {
    let v = (cell as f64 + offset) / cells as f64;
    v.min(ONE_MINUS_EPS)
}

/// The largest f64 below 1.
pub(crate) const ONE_MINUS_EPS: f64 = 1.0 - f64::EPSILON / 2.0;
