//! Every sampler this crate provides, and every fact about each one, in one place.

use super::{
    Ccvt, CorrelatedMultiJitter, GaussianBlueNoise, GaussianJitter, Halton, Jitter, Kronecker,
    LatinHypercube, LatticeRule, MultiJitter, Pmj02, PoissonDisk, PoissonMethod, Random,
    Rank1Lattice, Regular, Sampler, Sobol,
};
use crate::budget::Needs;
use crate::error::{Error, Result};
use crate::spectrum::ClosedForm;
use serde::Serialize;
use std::fmt;
use std::ops::RangeInclusive;

/// Every sampler this crate provides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(into = "&'static str")]
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
    /// Gaussian jitter: grid centres moved by Gaussian offsets.
    GaussianJitter,
    /// Korobov's rank-1 lattice with the best spectral test (2D).
    Korobov,
    /// The Fibonacci lattice (2D).
    Fibonacci,
    /// The Kronecker sequence of the generalized golden ratio (R_d).
    Kronecker,
    /// Progressive multi-jittered (0,2) sequence (2D).
    Pmj02,
    /// Multi-jittered (2D), independent shuffles.
    MultiJitter,
    /// Gaussian blue noise: descent of a Gaussian-kernel energy.
    GaussianBlueNoise,
}

/// How a sampler's expected spectrum depends on N: whether one spectrum, estimated at a
/// reference N and read at `ν = ρ / N^{1/d}`, serves another N.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Scaling {
    /// A function of `ν` alone at every N.
    Invariant,
    /// A function of `ν` alone at `N = m^d` (square strata); other strata are other shapes.
    PerfectPowers,
    /// Never: structure at `k/N` on the axes, lattices, or spikes whose height grows with N.
    Never,
}

/// Patterns of a Monte Carlo run: `patterns` independent patterns, each under `shifts` random
/// toroidal shifts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Pool {
    /// Independent patterns (the units of the confidence interval).
    pub patterns: usize,
    /// Shifts per pattern.
    pub shifts: usize,
}

/// The fewest independent patterns a pool uses, so that its interval rests on enough units.
pub const MIN_POOL_PATTERNS: usize = 32;

/// The cost of one integrand evaluation in a Monte Carlo trial, per point, in nanoseconds (a
/// disk or Gaussian with the shift, measured by `benches/montecarlo.rs`): a pattern is worth
/// reusing under as many shifts as its generation costs evaluations.
const EVALUATION_NS: f64 = 140.0;

/// Generation costs per point above this (in nanoseconds) make a sampler costly: its spectrum
/// estimates use fewer realizations, since drawing them would dwarf the transforms.
const COSTLY_NS: f64 = 10_000.0;

impl SamplerKind {
    /// All kinds, in display order.
    pub const ALL: [SamplerKind; 17] = [
        SamplerKind::Random,
        SamplerKind::Regular,
        SamplerKind::Jitter,
        SamplerKind::GaussianJitter,
        SamplerKind::PoissonDisk,
        SamplerKind::Bridson,
        SamplerKind::Ccvt,
        SamplerKind::GaussianBlueNoise,
        SamplerKind::LatinHypercube,
        SamplerKind::Halton,
        SamplerKind::Sobol,
        SamplerKind::MultiJitter,
        SamplerKind::Cmj,
        SamplerKind::Pmj02,
        SamplerKind::Korobov,
        SamplerKind::Fibonacci,
        SamplerKind::Kronecker,
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
            SamplerKind::GaussianJitter => "gjitter",
            SamplerKind::Korobov => "korobov",
            SamplerKind::Fibonacci => "fibonacci",
            SamplerKind::Kronecker => "kronecker",
            SamplerKind::Pmj02 => "pmj02",
            SamplerKind::MultiJitter => "mj",
            SamplerKind::GaussianBlueNoise => "gbn",
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
            SamplerKind::GaussianJitter => {
                "Gaussian jitter (Subr and Kautz 2013): grid centres plus Gaussian offsets of 0.25 \
                 strata"
            }
            SamplerKind::Korobov => {
                "rank-1 lattice frac(i(1,a)/N), a with the best spectral test; deterministic"
            }
            SamplerKind::Fibonacci => "Fibonacci lattice frac(i(1,F_{m-1})/F_m); deterministic",
            SamplerKind::Kronecker => {
                "Kronecker sequence frac(i alpha), alpha from x^(d+1) = x + 1 (R_d); deterministic"
            }
            SamplerKind::Pmj02 => {
                "progressive multi-jittered (0,2) (Christensen et al. 2018): every 2^m prefix a net"
            }
            SamplerKind::MultiJitter => {
                "multi-jittered (Chiu et al. 1994): jittered and N-rooks, independent shuffles"
            }
            SamplerKind::GaussianBlueNoise => {
                "Gaussian blue noise (after Ahmed et al. 2022): descent of a Gaussian-kernel energy"
            }
        }
    }

    /// The dimensions this sampler supports.
    pub fn dimensions(self) -> RangeInclusive<usize> {
        match self {
            SamplerKind::PoissonDisk
            | SamplerKind::Bridson
            | SamplerKind::Ccvt
            | SamplerKind::GaussianBlueNoise => 1..=3,
            SamplerKind::Cmj
            | SamplerKind::MultiJitter
            | SamplerKind::Pmj02
            | SamplerKind::Korobov
            | SamplerKind::Fibonacci => 2..=2,
            _ => 1..=crate::pointset::MAX_DIMENSION,
        }
    }

    /// The rule N must follow, in words.
    pub fn count_rule(self) -> &'static str {
        match self {
            SamplerKind::Regular | SamplerKind::Jitter | SamplerKind::GaussianJitter => {
                "N = m^d; 2D: or a×b, b<a≤2b"
            }
            SamplerKind::Fibonacci => "N = F_m: 1, 2, 3, 5, 8, 13, 21, …",
            _ => "any N >= 1",
        }
    }

    /// The valid count nearest `n` (the smaller on ties), at least 1: for samplers with a
    /// count rule (strata, Fibonacci numbers); `max(n, 1)` for the others.
    ///
    /// # Examples
    /// ```
    /// use specvar::sampler::SamplerKind;
    /// assert_eq!(SamplerKind::Fibonacci.nearest_count(64, 2), 55);
    /// assert_eq!(SamplerKind::Jitter.nearest_count(97, 2), 96);
    /// assert_eq!(SamplerKind::Sobol.nearest_count(97, 2), 97);
    /// ```
    pub fn nearest_count(self, n: usize, d: usize) -> usize {
        let valid = |c: usize| match self {
            SamplerKind::Regular | SamplerKind::Jitter | SamplerKind::GaussianJitter => {
                super::strata(c, d).is_some()
            }
            SamplerKind::Fibonacci => {
                Rank1Lattice::new(2, LatticeRule::Fibonacci).is_ok_and(|s| s.check_count(c).is_ok())
            }
            _ => true,
        };
        let n = n.max(1);
        (0..n)
            .flat_map(|step| [n - step, n + step])
            .find(|&c| c >= 1 && valid(c))
            .unwrap_or(1)
    }

    /// Whether the pattern ignores the seed and the realization: one fixed point set, which
    /// Monte Carlo homogenizes (the regular grid, rank-1 lattices, the Kronecker sequence).
    pub fn is_deterministic(self) -> bool {
        matches!(
            self,
            SamplerKind::Regular
                | SamplerKind::Korobov
                | SamplerKind::Fibonacci
                | SamplerKind::Kronecker
        )
    }

    /// The sampler's exact expected spectrum at `n` points in dimension `d`, if one is known
    /// (with default parameters: Gaussian jitter's is its default width's).
    /// Jitter's follows its strata (`96 = 12 × 8`); the closed radial form needs square ones.
    pub fn closed_form(self, n: usize, d: usize) -> Option<ClosedForm> {
        match self {
            SamplerKind::GaussianJitter
            | SamplerKind::Korobov
            | SamplerKind::Fibonacci
            | SamplerKind::Kronecker => self.build(d).ok()?.closed_form(n),
            SamplerKind::Random => Some(ClosedForm::WhiteNoise),
            SamplerKind::Jitter => super::strata(n, d).map(|_| ClosedForm::Jitter),
            SamplerKind::Regular => super::strata(n, d).map(|_| ClosedForm::RegularGrid),
            SamplerKind::LatinHypercube => Some(ClosedForm::LatinHypercube),
            _ => None,
        }
    }

    /// The low-frequency exponent `α` of `P̆_S(ν) ≈ c ν^α` as `ν → 0`, where it is known (`None`
    /// where it is not meaningful: the anisotropic samplers). CCVT's is 2, not the 4 of an
    /// ideal CCVT: each site is the centroid of exactly `c` points of a jittered discrete
    /// density, so at low frequencies the sites' spectrum is the discrete density's over `c`,
    /// a floor `π²ν²/(3c²)` under the optimized `ν⁴` band (`docs/theory.md`; measured by
    /// [`crate::rate::fit_low_band`]). Gaussian blue noise's is 0: a fixed number of descent
    /// steps relaxes density waves only down to a fixed scale, so below `ν ≈ 0.01` its spectrum
    /// climbs back to white noise's (`docs/theory.md`).
    pub fn known_alpha(self) -> Option<f64> {
        match self {
            SamplerKind::Random
            | SamplerKind::PoissonDisk
            | SamplerKind::Bridson
            | SamplerKind::GaussianBlueNoise => Some(0.0),
            SamplerKind::Jitter | SamplerKind::Ccvt | SamplerKind::GaussianJitter => Some(2.0),
            _ => None,
        }
    }

    /// How the expected spectrum depends on N.
    pub fn scaling(self) -> Scaling {
        match self {
            SamplerKind::Random
            | SamplerKind::PoissonDisk
            | SamplerKind::Bridson
            | SamplerKind::Ccvt
            | SamplerKind::GaussianBlueNoise => Scaling::Invariant,
            SamplerKind::Jitter => Scaling::PerfectPowers,
            SamplerKind::Regular
            | SamplerKind::LatinHypercube
            | SamplerKind::Halton
            | SamplerKind::Sobol
            | SamplerKind::Cmj
            | SamplerKind::MultiJitter
            | SamplerKind::Pmj02
            | SamplerKind::GaussianJitter
            | SamplerKind::Korobov
            | SamplerKind::Fibonacci
            | SamplerKind::Kronecker => Scaling::Never,
        }
    }

    /// Whether the expected spectrum at `n` points in dimension `d` is the common one in `ν`.
    pub fn is_scale_invariant_at(self, n: usize, d: usize) -> bool {
        match self.scaling() {
            Scaling::Invariant => true,
            Scaling::PerfectPowers => super::perfect_root(n, d).is_some(),
            Scaling::Never => false,
        }
    }

    /// Whether the expected spectrum depends on `|k|` alone (up to the torus): samplers with
    /// axis structure (strata, N-rooks, digital nets, lattices) are anisotropic.
    pub fn is_isotropic(self) -> bool {
        matches!(
            self,
            SamplerKind::Random
                | SamplerKind::PoissonDisk
                | SamplerKind::Bridson
                | SamplerKind::Ccvt
                | SamplerKind::GaussianBlueNoise
        )
    }

    /// Whether the distribution of patterns at `n` points is unchanged by the symmetries of the
    /// cube (permutations of the axes and reflections `x_a → 1 - x_a`), so that `E[P_S]` is
    /// too: not for Halton and Sobol (each axis is its own sequence), correlated multi-jitter
    /// (rows and columns are built differently), or rectangular strata.
    pub fn is_symmetric_at(self, n: usize, d: usize) -> bool {
        match self {
            SamplerKind::Random
            | SamplerKind::PoissonDisk
            | SamplerKind::Bridson
            | SamplerKind::Ccvt
            | SamplerKind::GaussianBlueNoise
            | SamplerKind::LatinHypercube => true,
            SamplerKind::Jitter | SamplerKind::Regular | SamplerKind::GaussianJitter => {
                super::perfect_root(n, d).is_some()
            }
            SamplerKind::Halton
            | SamplerKind::Sobol
            | SamplerKind::Cmj
            | SamplerKind::MultiJitter
            | SamplerKind::Pmj02
            | SamplerKind::Korobov
            | SamplerKind::Fibonacci
            | SamplerKind::Kronecker => false,
        }
    }

    /// The time to generate one point of a 2D pattern, in nanoseconds (measured at N = 1024 to
    /// 4096 by `benches/samplers.rs`; it grows slowly with N for the optimizers).
    pub fn cost_per_point_ns(self) -> f64 {
        match self {
            SamplerKind::Random | SamplerKind::Regular => 4.0,
            SamplerKind::Kronecker => 8.0,
            SamplerKind::Jitter => 8.0,
            SamplerKind::GaussianJitter => 55.0,
            SamplerKind::Fibonacci => 5.0,
            SamplerKind::Korobov => 40.0,
            SamplerKind::Pmj02 => 330.0,
            SamplerKind::LatinHypercube | SamplerKind::Cmj | SamplerKind::MultiJitter => 30.0,
            SamplerKind::Sobol => 80.0,
            SamplerKind::Halton => 35.0,
            SamplerKind::PoissonDisk => 4_500.0,
            SamplerKind::Bridson => 8_400.0,
            SamplerKind::Ccvt => 190_000.0,
            SamplerKind::GaussianBlueNoise => 180_000.0,
        }
    }

    /// The memory and time one pattern of `n` points in dimension `d` takes to draw (the time
    /// from [`cost_per_point_ns`](Self::cost_per_point_ns); the memory from the generators'
    /// working sets: CCVT holds its `64 n` discrete points and, while assigning them, about
    /// `5^d` candidate pairs of 24 bytes per discrete point).
    pub fn pattern_needs(self, n: usize, d: usize) -> Needs {
        // In floating point: a product of usizes could wrap and pass the budget.
        let (n, points) = (n as f64, n as f64 * d as f64 * 8.0);
        let working = match self {
            SamplerKind::Ccvt => n * 64.0 * (8.0 * d as f64 + 4.0 + 24.0 * 5f64.powi(d as i32)),
            SamplerKind::PoissonDisk | SamplerKind::Bridson => n * 64.0,
            SamplerKind::Halton | SamplerKind::Sobol => 4096.0,
            _ => n * 8.0,
        };
        Needs {
            memory_bytes: points + working,
            work_seconds: n * self.cost_per_point_ns() * 1e-9,
        }
    }

    /// Whether drawing a pattern costs far more than transforming it (CCVT): spectrum estimates
    /// then use fewer realizations.
    pub fn is_costly(self) -> bool {
        self.cost_per_point_ns() > COSTLY_NS
    }

    /// How Monte Carlo spends `trials` estimator evaluations: each pattern is used under as
    /// many shifts as its generation costs evaluations, with at least
    /// [`MIN_POOL_PATTERNS`] patterns (or every trial a pattern, if there are fewer trials):
    /// one fresh pattern per trial for cheap samplers, a pool for dart throwing and CCVT.
    ///
    /// # Examples
    /// ```
    /// use specvar::sampler::SamplerKind;
    /// assert_eq!(SamplerKind::Jitter.pool(4000).shifts, 1);
    /// let ccvt = SamplerKind::Ccvt.pool(4000);
    /// assert_eq!((ccvt.patterns, ccvt.shifts), (32, 125));
    /// ```
    pub fn pool(self, trials: usize) -> Pool {
        let worth = (self.cost_per_point_ns() / EVALUATION_NS).round().max(1.0) as usize;
        let cap = (trials / MIN_POOL_PATTERNS).max(1);
        let shifts = worth.min(cap);
        Pool {
            patterns: (trials / shifts).max(1),
            shifts,
        }
    }

    /// Builds this sampler in dimension `d`, keeping up to `budget_bytes` of the patterns it
    /// draws when they are worth keeping (a generation cost of a microsecond per point or
    /// more: dart throwing, CCVT); see [`super::Memoized`].
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn build_memoized(self, d: usize, budget_bytes: usize) -> Result<Box<dyn Sampler>> {
        let sampler = self.build(d)?;
        Ok(if self.cost_per_point_ns() >= 1_000.0 {
            Box::new(super::Memoized::new(sampler, budget_bytes))
        } else {
            sampler
        })
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
    /// assert_eq!(jitter.kind(), Some(SamplerKind::Jitter));
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
            SamplerKind::GaussianJitter => Box::new(GaussianJitter::new(d)?),
            SamplerKind::Korobov => Box::new(Rank1Lattice::new(d, LatticeRule::Korobov)?),
            SamplerKind::Fibonacci => Box::new(Rank1Lattice::new(d, LatticeRule::Fibonacci)?),
            SamplerKind::Kronecker => Box::new(Kronecker::new(d)?),
            SamplerKind::Pmj02 => Box::new(Pmj02::new(d)?),
            SamplerKind::MultiJitter => Box::new(MultiJitter::new(d)?),
            SamplerKind::GaussianBlueNoise => Box::new(GaussianBlueNoise::new(d)?),
        })
    }

    /// The kinds that exist in dimension `d`.
    pub fn in_dimension(d: usize) -> Vec<SamplerKind> {
        Self::ALL
            .into_iter()
            .filter(|k| k.dimensions().contains(&d))
            .collect()
    }
}

impl fmt::Display for SamplerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SamplerKind {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Self::from_name(s.trim())
    }
}

impl From<SamplerKind> for &'static str {
    fn from(k: SamplerKind) -> Self {
        k.name()
    }
}
