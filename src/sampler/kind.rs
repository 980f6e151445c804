//! Every sampler this crate provides: the registry of their descriptors (each states its facts
//! in its own file), and the policies the library derives from them.

use super::facts::{
    CellRule, ClosedFormRule, CountRule, Randomness, SamplerFacts, Scaling, Symmetry,
};
use super::ClosedForm;
use super::{
    Ccvt, CorrelatedMultiJitter, GaussianBlueNoise, GaussianJitter, Halton, Jitter, Kronecker,
    LatinHypercube, LatticeRule, MultiJitter, OrthogonalArray, Pmj02, PoissonDisk, PoissonMethod,
    Random, Rank1Lattice, Regular, Sampler, Sobol, SobolNet,
};
use crate::budget::Needs;
use crate::error::{Error, Result};
use crate::randomization::Randomization;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::RangeInclusive;

/// Every sampler this crate provides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(into = "&'static str", try_from = "String")]
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
    /// Orthogonal arrays of strength 2 with multi-jittered offsets.
    OrthogonalArray,
    /// Randomly scrambled Halton.
    Halton,
    /// Owen-scrambled Sobol.
    Sobol,
    /// The unscrambled Sobol' net under a digital shift.
    SobolNet,
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

/// Generation costs per point above this (in nanoseconds) make a sampler costly: its spectrum
/// estimates use fewer realizations, since drawing them would dwarf the transforms.
const COSTLY_NS: f64 = 10_000.0;

/// Generation costs per point from which patterns are worth keeping in memory and on disk
/// (dart throwing, CCVT, Gaussian blue noise): a microsecond a point, above the cost of reading
/// them back.
const KEEP_NS: f64 = 1_000.0;

/// The fewest realizations a costly sampler's spectrum estimate uses.
const MIN_COSTLY_REALIZATIONS: usize = 4;

/// The realizations a costly sampler's spectrum estimate uses where a cheap sampler's would
/// use `cheap`: a quarter of them, at least 4.
pub fn costly_realizations(cheap: usize) -> usize {
    (cheap / 4).max(MIN_COSTLY_REALIZATIONS)
}

impl SamplerKind {
    /// All kinds, in display order.
    pub const ALL: [SamplerKind; 19] = [
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
        SamplerKind::SobolNet,
        SamplerKind::MultiJitter,
        SamplerKind::Cmj,
        SamplerKind::OrthogonalArray,
        SamplerKind::Pmj02,
        SamplerKind::Korobov,
        SamplerKind::Fibonacci,
        SamplerKind::Kronecker,
    ];

    /// Every fact about this sampler, stated once in its own file.
    pub const fn facts(self) -> &'static SamplerFacts {
        match self {
            SamplerKind::Random => &super::random::FACTS,
            SamplerKind::Regular => &super::regular::FACTS,
            SamplerKind::Jitter => &super::jitter::FACTS,
            SamplerKind::PoissonDisk => &super::poisson::DART_FACTS,
            SamplerKind::Bridson => &super::poisson::BRIDSON_FACTS,
            SamplerKind::Ccvt => &super::ccvt::FACTS,
            SamplerKind::LatinHypercube => &super::latin::FACTS,
            SamplerKind::OrthogonalArray => &super::orthogonal::FACTS,
            SamplerKind::Halton => &super::halton::FACTS,
            SamplerKind::Sobol => &super::sobol::FACTS,
            SamplerKind::SobolNet => &super::sobol_net::FACTS,
            SamplerKind::Cmj => &super::cmj::FACTS,
            SamplerKind::GaussianJitter => &super::gaussian_jitter::FACTS,
            SamplerKind::Korobov => &super::rank1::KOROBOV_FACTS,
            SamplerKind::Fibonacci => &super::rank1::FIBONACCI_FACTS,
            SamplerKind::Kronecker => &super::kronecker::FACTS,
            SamplerKind::Pmj02 => &super::pmj02::FACTS,
            SamplerKind::MultiJitter => &super::multi_jitter::FACTS,
            SamplerKind::GaussianBlueNoise => &super::gbn::FACTS,
        }
    }

    /// The command-line name.
    pub fn name(self) -> &'static str {
        self.facts().name
    }

    /// One line saying what the sampler is.
    pub fn description(self) -> &'static str {
        self.facts().description
    }

    /// The dimensions this sampler supports.
    pub fn dimensions(self) -> RangeInclusive<usize> {
        self.facts().dimensions.clone()
    }

    /// The rule N must follow.
    pub fn count_rule(self) -> CountRule {
        self.facts().count
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
        self.count_rule().nearest(n, d)
    }

    /// The valid count nearest each of `ns` in dimension `d`, in order, without repeats next to
    /// each other (two wanted counts may share their nearest valid one).
    pub fn nearest_counts(self, ns: &[usize], d: usize) -> Vec<usize> {
        let mut out: Vec<usize> = ns.iter().map(|&n| self.nearest_count(n, d)).collect();
        out.dedup();
        out
    }

    /// Whether the pattern ignores the seed and the realization: one fixed point set, which
    /// Monte Carlo homogenizes (the regular grid, rank-1 lattices, the Kronecker sequence).
    pub fn is_deterministic(self) -> bool {
        self.facts().randomness == Randomness::Deterministic
    }

    /// The sampler's exact expected spectrum at `n` points in dimension `d`, if one is known
    /// (with default parameters: Gaussian jitter's is its default width's).
    /// Jitter's follows its strata (`96 = 12 × 8`); the closed radial form needs square ones.
    pub fn closed_form(self, n: usize, d: usize) -> Option<ClosedForm> {
        match self.facts().closed_form {
            ClosedFormRule::None => None,
            ClosedFormRule::Always(c) => Some(c),
            ClosedFormRule::WithStrata(c) => super::strata(n, d).map(|_| c),
            ClosedFormRule::OfSampler => self.build(d).ok()?.closed_form(n),
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
        self.facts().known_alpha
    }

    /// How the expected spectrum depends on N.
    pub fn scaling(self) -> Scaling {
        self.facts().scaling
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
        self.facts().isotropic
    }

    /// Whether the distribution of patterns at `n` points is unchanged by the symmetries of the
    /// cube (permutations of the axes and reflections `x_a → 1 - x_a`), so that `E[P_S]` is
    /// too: not for Halton and Sobol (each axis is its own sequence), correlated multi-jitter
    /// (rows and columns are built differently), or rectangular strata.
    pub fn is_symmetric_at(self, n: usize, d: usize) -> bool {
        match self.facts().symmetry {
            Symmetry::Cube => true,
            Symmetry::CubeWithSquareStrata => super::perfect_root(n, d).is_some(),
            Symmetry::Partial => false,
        }
    }

    /// How far the sampler's pair correlations reach at `n` points in dimension `d` (largest
    /// component).
    pub fn correlation_range(self, n: usize, d: usize) -> f64 {
        self.facts().correlation_reach * (n as f64).powf(-1.0 / d as f64)
    }

    /// The randomization this sampler is used with in practice.
    pub fn native_randomization(self) -> Randomization {
        self.facts().native_randomization
    }

    /// The time to generate one point of a 2D pattern, in nanoseconds (measured at N = 1024 to
    /// 4096 by `benches/samplers.rs`; it grows slowly with N for the optimizers).
    pub fn cost_per_point_ns(self) -> f64 {
        self.facts().cost_per_point_ns
    }

    /// The time to generate one point of a pattern of `n` points in dimension `d`, in
    /// nanoseconds: the declared 2D cost, grown beyond
    /// [`COST_REFERENCE_N`](super::facts::COST_REFERENCE_N) by
    /// [`SamplerFacts::cost_growth`](super::SamplerFacts) and scaled to the dimension by
    /// [`SamplerFacts::cost_dimension`](super::SamplerFacts).
    ///
    /// # Examples
    /// ```
    /// use specvar::sampler::SamplerKind;
    /// let pmj = SamplerKind::Pmj02;
    /// assert_eq!(pmj.cost_per_point_ns_at(1024, 2), pmj.cost_per_point_ns());
    /// assert!(pmj.cost_per_point_ns_at(65536, 2) > 2.0 * pmj.cost_per_point_ns());
    /// let jitter = SamplerKind::Jitter;
    /// assert_eq!(jitter.cost_per_point_ns_at(1 << 20, 2), jitter.cost_per_point_ns());
    /// // Gaussian blue noise's neighbourhoods grow with the dimension far faster than its
    /// // coordinates do.
    /// let gbn = SamplerKind::GaussianBlueNoise;
    /// assert!(gbn.cost_per_point_ns_at(4096, 3) > 5.0 * gbn.cost_per_point_ns_at(4096, 2));
    /// ```
    pub fn cost_per_point_ns_at(self, n: usize, d: usize) -> f64 {
        let f = self.facts();
        let beyond = (n as f64 / super::facts::COST_REFERENCE_N).max(1.0);
        f.cost_per_point_ns * beyond.powf(f.cost_growth) * f.cost_dimension.factor(d)
    }

    /// The memory and time one pattern of `n` points in dimension `d` takes to draw (the time
    /// from [`cost_per_point_ns`](Self::cost_per_point_ns), the memory from the generator's
    /// working set).
    pub fn pattern_needs(self, n: usize, d: usize) -> Needs {
        // In floating point: a product of usizes could wrap and pass the budget.
        let (n, points) = (n as f64, n as f64 * d as f64 * 8.0);
        Needs {
            memory_bytes: points + (self.facts().working_bytes)(n, d),
            work_seconds: n * self.cost_per_point_ns_at(n as usize, d) * 1e-9,
        }
    }

    /// Whether drawing a pattern costs far more than transforming it (CCVT): spectrum estimates
    /// then use fewer realizations.
    pub fn is_costly(self) -> bool {
        self.cost_per_point_ns() > COSTLY_NS
    }

    /// The realizations a spectrum estimate of this sampler uses where a cheap sampler's would
    /// use `cheap`: a quarter of them (at least 4) for a costly sampler, whose patterns cost
    /// far more to draw than to transform.
    ///
    /// # Examples
    /// ```
    /// use specvar::sampler::SamplerKind;
    /// assert_eq!(SamplerKind::Jitter.spectrum_realizations(32), 32);
    /// assert_eq!(SamplerKind::Ccvt.spectrum_realizations(32), 8);
    /// ```
    pub fn spectrum_realizations(self, cheap: usize) -> usize {
        if self.is_costly() {
            costly_realizations(cheap)
        } else {
            cheap
        }
    }

    /// Whether patterns are worth keeping once drawn (in memory, and on disk between runs):
    /// those that cost a microsecond a point or more to draw.
    pub fn patterns_worth_keeping(self) -> bool {
        self.cost_per_point_ns() >= KEEP_NS
    }

    /// Every sampler's facts as a Markdown table (the README's list of samplers is this table,
    /// and a test keeps it so).
    pub fn markdown_table() -> String {
        let mut table = String::from(
            "| name | dimensions | N | drawn with | used with | closed form | what it is |\n\
             |---|---|---|---|---|---|---|\n",
        );
        for kind in Self::ALL {
            let f = kind.facts();
            let (lo, hi) = (f.dimensions.start(), f.dimensions.end());
            let dims = if lo == hi {
                lo.to_string()
            } else {
                format!("{lo}–{hi}")
            };
            let randomness = f.randomness.to_string().replace('_', " ");
            table.push_str(&format!(
                "| `{}` | {dims} | {} | {randomness} | {} | {} | {} |\n",
                f.name,
                f.count,
                f.native_randomization.estimator(),
                f.closed_form.describe(),
                f.description
            ));
        }
        table
    }

    /// The facts a table of samplers shows, as one serializable row.
    pub fn summary(self) -> SamplerSummary {
        let f = self.facts();
        SamplerSummary {
            name: self,
            description: f.description,
            min_dimension: *f.dimensions.start(),
            max_dimension: *f.dimensions.end(),
            count_rule: f.count.to_string(),
            balanced_counts: f.balanced_counts,
            randomness: f.randomness,
            native_randomization: f.native_randomization,
            cells: f.cells,
            deterministic: self.is_deterministic(),
            scaling: f.scaling,
            isotropic: f.isotropic,
            symmetry: f.symmetry,
            known_alpha: f.known_alpha,
            cost_per_point_ns: f.cost_per_point_ns,
            cost_dimension: f.cost_dimension,
        }
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
        let worth = (self.cost_per_point_ns() / crate::costs::POOL_NS_PER_SHIFT)
            .round()
            .max(1.0) as usize;
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
        Ok(if self.patterns_worth_keeping() {
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
            SamplerKind::OrthogonalArray => Box::new(OrthogonalArray::new(d)?),
            SamplerKind::Halton => Box::new(Halton::new(d)?),
            SamplerKind::Sobol => Box::new(Sobol::new(d)?),
            SamplerKind::SobolNet => Box::new(SobolNet::new(d)?),
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

/// A sampler's facts as a table shows them ([`SamplerKind::summary`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SamplerSummary {
    /// The sampler.
    pub name: SamplerKind,
    /// What it is.
    pub description: &'static str,
    /// The lowest dimension it supports.
    pub min_dimension: usize,
    /// The highest dimension it supports.
    pub max_dimension: usize,
    /// The rule N must follow, in words.
    pub count_rule: String,
    /// The counts at which its patterns are complete, where a plan looks for N.
    pub balanced_counts: CountRule,
    /// What is random in a pattern as drawn.
    pub randomness: Randomness,
    /// The randomization it is used with in practice.
    pub native_randomization: Randomization,
    /// The cells in which its points, used as drawn, are independent and uniform.
    pub cells: CellRule,
    /// Whether it draws one fixed pattern.
    pub deterministic: bool,
    /// How its expected spectrum depends on N.
    pub scaling: Scaling,
    /// Whether its expected spectrum is isotropic.
    pub isotropic: bool,
    /// Which symmetries of the cube leave it unchanged.
    pub symmetry: Symmetry,
    /// Its low-frequency exponent, where known.
    pub known_alpha: Option<f64>,
    /// Its generation cost per 2D point, in nanoseconds.
    pub cost_per_point_ns: f64,
    /// How that cost changes with the dimension.
    pub cost_dimension: super::DimensionCost,
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

impl TryFrom<String> for SamplerKind {
    type Error = Error;
    fn try_from(name: String) -> Result<Self> {
        name.parse()
    }
}

impl From<SamplerKind> for &'static str {
    fn from(k: SamplerKind) -> Self {
        k.name()
    }
}
