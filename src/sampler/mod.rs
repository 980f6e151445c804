//! Samplers: patterns of N points on the unit torus.
//!
//! Every sampler implements [`Sampler`]; [`SamplerKind`] names them for the command line and the
//! report. Realization `i` of seed `s` is computed from `(s, i)` alone (see [`crate::rng`]), so it
//! is the same on any machine and thread count.

mod ccvt;
mod cmj;
mod halton;
mod homogenize;
mod jitter;
mod latin;
mod poisson;
mod random;
mod regular;
mod sobol;

pub use ccvt::{Ccvt, CcvtParams, CcvtStats};
pub use cmj::CorrelatedMultiJitter;
pub use halton::Halton;
pub use homogenize::{homogenize, Homogenized};
pub use jitter::Jitter;
pub use latin::LatinHypercube;
pub use poisson::{
    default_relative_radius, max_packing_radius, PoissonDisk, PoissonMethod, MAX_ATTEMPTS,
};
pub use random::Random;
pub use regular::{strata, Regular};
pub use sobol::Sobol;

use crate::error::{Error, Result};
use crate::pointset::PointSet;
use std::ops::RangeInclusive;

/// A generator of point sets on `[0,1)^d` for a fixed dimension `d`.
pub trait Sampler: Send + Sync {
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

    /// Whether the pattern's expected spectrum is a function of `ν = ρ / N^{1/d}` alone, so that
    /// one spectrum estimated at a reference N serves every N.
    fn is_scale_invariant(&self) -> bool {
        true
    }

    /// Whether the spectrum at this particular `n` is the common one in `ν`: jitter's
    /// rectangular strata (`96 = 12 × 8`) are not a rescaled square grid.
    fn is_scale_invariant_at(&self, n: usize) -> bool {
        let _ = n;
        self.is_scale_invariant()
    }
}

/// Every sampler this crate provides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SamplerKind {
    /// White noise.
    Random,
    /// Cell-centred regular grid.
    Regular,
    /// Jittered (stratified) sampling.
    Jitter,
    /// Poisson disk by dart throwing.
    PoissonDisk,
    /// Poisson disk by Bridson's algorithm.
    Bridson,
    /// Capacity-constrained Voronoi tessellation.
    Ccvt,
    /// Latin hypercube / N-rooks.
    LatinHypercube,
    /// Randomly scrambled Halton.
    Halton,
    /// Owen-scrambled Sobol.
    Sobol,
    /// Correlated multi-jittered (2D).
    Cmj,
}

impl SamplerKind {
    /// All kinds, in display order.
    pub const ALL: [SamplerKind; 10] = [
        SamplerKind::Random,
        SamplerKind::Regular,
        SamplerKind::Jitter,
        SamplerKind::PoissonDisk,
        SamplerKind::Bridson,
        SamplerKind::Ccvt,
        SamplerKind::LatinHypercube,
        SamplerKind::Halton,
        SamplerKind::Sobol,
        SamplerKind::Cmj,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Random => "random",
            SamplerKind::Regular => "regular",
            SamplerKind::Jitter => "jitter",
            SamplerKind::PoissonDisk => "poisson",
            SamplerKind::Bridson => "bridson",
            SamplerKind::Ccvt => "ccvt",
            SamplerKind::LatinHypercube => "lhs",
            SamplerKind::Halton => "halton",
            SamplerKind::Sobol => "sobol",
            SamplerKind::Cmj => "cmj",
        }
    }

    /// One line saying what the sampler is.
    pub fn description(self) -> &'static str {
        match self {
            SamplerKind::Random => "white noise: independent uniform points",
            SamplerKind::Regular => "regular grid at cell centres (j + 1/2)/m; deterministic",
            SamplerKind::Jitter => "jittered: one uniform point in each of m^d strata",
            SamplerKind::PoissonDisk => {
                "Poisson disk: toroidal dart throwing, relative radius 0.75 (0.65 in 1D)"
            }
            SamplerKind::Bridson => "Poisson disk: Bridson's algorithm on the torus, thinned to N",
            SamplerKind::Ccvt => "capacity-constrained Voronoi tessellation (Balzer et al. 2009)",
            SamplerKind::LatinHypercube => "Latin hypercube (N-rooks): one point per row per axis",
            SamplerKind::Halton => "Halton with random digit permutations",
            SamplerKind::Sobol => "Sobol (Joe-Kuo directions) with Owen scrambling",
            SamplerKind::Cmj => "correlated multi-jittered (Kensler 2013): jittered and N-rooks",
        }
    }

    /// The dimensions this sampler supports.
    pub fn dimensions(self) -> RangeInclusive<usize> {
        match self {
            SamplerKind::PoissonDisk | SamplerKind::Bridson | SamplerKind::Ccvt => 1..=3,
            SamplerKind::Cmj => 2..=2,
            _ => 1..=crate::pointset::MAX_DIMENSION,
        }
    }

    /// The rule N must follow, in words.
    pub fn count_rule(self) -> &'static str {
        match self {
            SamplerKind::Regular | SamplerKind::Jitter => "N = m^d; 2D: or a×b, b<a≤2b",
            _ => "any N >= 1",
        }
    }

    /// Looks a sampler up by its command-line name.
    ///
    /// # Errors
    /// An unknown name, with the list of known ones.
    pub fn from_name(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| Error::InvalidParameter {
                name: "sampler",
                value: name.to_string(),
                allowed: format!("one of {}", Self::names().join(", ")),
            })
    }

    /// All command-line names.
    pub fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|k| k.name()).collect()
    }

    /// Builds this sampler in dimension `d` with default parameters.
    ///
    /// # Errors
    /// An unsupported dimension.
    ///
    /// # Examples
    /// ```
    /// use specvar::sampler::{Sampler, SamplerKind};
    /// let jitter = SamplerKind::Jitter.build(2).unwrap();
    /// let points = jitter.sample(16, 1, 0).unwrap();
    /// assert_eq!(points.len(), 16);
    /// assert_eq!(jitter.sample(96, 1, 0).unwrap().len(), 96); // 12 × 8 strata
    /// assert!(jitter.sample(17, 1, 0).is_err()); // prime: use 16 or 18
    /// ```
    pub fn build(self, d: usize) -> Result<Box<dyn Sampler>> {
        Ok(match self {
            SamplerKind::Random => Box::new(Random::new(d)?),
            SamplerKind::Regular => Box::new(Regular::new(d)?),
            SamplerKind::Jitter => Box::new(Jitter::new(d)?),
            SamplerKind::PoissonDisk => Box::new(PoissonDisk::new(d)?),
            SamplerKind::Bridson => {
                Box::new(PoissonDisk::new(d)?.with_method(PoissonMethod::Bridson))
            }
            SamplerKind::Ccvt => Box::new(Ccvt::new(d)?),
            SamplerKind::LatinHypercube => Box::new(LatinHypercube::new(d)?),
            SamplerKind::Halton => Box::new(Halton::new(d)?),
            SamplerKind::Sobol => Box::new(Sobol::new(d)?),
            SamplerKind::Cmj => Box::new(CorrelatedMultiJitter::new(d)?),
        })
    }
}

/// Errors unless `d` lies in `supported`.
pub(crate) fn check_supported(
    sampler: &'static str,
    d: usize,
    supported: RangeInclusive<usize>,
) -> Result<()> {
    if supported.contains(&d) {
        Ok(())
    } else {
        Err(Error::UnsupportedDimension {
            sampler,
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

/// A uniform draw in `[0, 1)` with 53 random bits.
#[inline]
pub(crate) fn uniform<R: rand::Rng>(rng: &mut R) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

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
