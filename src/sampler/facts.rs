//! The descriptor of a sampler: every fact the predictions, the atlas, the command line, the
//! Python module and the docs need, stated once per sampler in its own file as a
//! [`SamplerFacts`] constant. A struct literal names every field, so a new sampler cannot leave
//! a fact out: the compiler lists what is missing.

use super::ClosedForm;
use crate::randomization::Randomization;
use serde::Serialize;
use std::fmt;
use std::ops::RangeInclusive;

/// Every fact about one sampler.
#[derive(Debug, Clone)]
pub struct SamplerFacts {
    /// The command-line name.
    pub name: &'static str,
    /// One line saying what the sampler is.
    pub description: &'static str,
    /// The dimensions it supports.
    pub dimensions: RangeInclusive<usize>,
    /// The rule N must follow.
    pub count: CountRule,
    /// The counts at which its patterns are complete (a net's powers of two, a grid's strata),
    /// where the variance follows the sampler's rate; between them it may be worse (the first
    /// N points of a net that is not yet complete). A planner looks for N among these. Equal
    /// to `count` where every admitted N is as good as its neighbours.
    pub balanced_counts: CountRule,
    /// What is random in a pattern as drawn.
    pub randomness: Randomness,
    /// The randomization the sampler is used with in practice (by renderers and
    /// quasi-Monte Carlo libraries): its patterns as drawn, or, for a fixed rule whose
    /// unshifted estimator has a bias and no variance, a random toroidal shift.
    pub native_randomization: Randomization,
    /// The grid of cells in which its points, used as drawn, are independent and uniform
    /// once their cells are known: the form of its unshifted estimator.
    pub cells: CellRule,
    /// How its points occupy those cells beyond the rule: what the cell form of its unshifted
    /// estimator reads (the pairs of occupied cells, or a net's pair counts).
    pub cell_law: CellLaw,
    /// Its exact expected spectrum, where one is known.
    pub closed_form: ClosedFormRule,
    /// The low-frequency exponent `α` of `P̆_S(ν) ≈ c ν^α` as `ν → 0`, where it is known.
    pub known_alpha: Option<f64>,
    /// How the expected spectrum depends on N.
    pub scaling: Scaling,
    /// Whether the expected spectrum depends on `|k|` alone (up to the torus).
    pub isotropic: bool,
    /// Which symmetries of the cube leave the law of its patterns unchanged.
    pub symmetry: Symmetry,
    /// How far its pair correlations reach, in mean spacings `N^{-1/d}` (largest component).
    pub correlation_reach: f64,
    /// The finest scale at which its patterns are structured along an axis: what a tabulated
    /// integrand must resolve for its coarser averages to show the variance.
    pub axis_strata: AxisStrata,
    /// The time to generate one point of a 2D pattern, in nanoseconds, measured at N = 1024 to
    /// 4096 by `benches/samplers.rs` (which fails when a measurement leaves
    /// [`COST_TOLERANCE`] of it). It sizes work estimates and Monte Carlo pools.
    pub cost_per_point_ns: f64,
    /// How the cost per point grows beyond the count it was measured at
    /// ([`COST_REFERENCE_N`]): `cost_per_point_ns · max(1, N / COST_REFERENCE_N)^cost_growth`
    /// (0 where it stays flat; PMJ02's occupancy tables leave the caches).
    pub cost_growth: f64,
    /// How the cost per point changes with the dimension, from the 2D cost declared.
    pub cost_dimension: DimensionCost,
    /// The generator's working memory, in bytes, for `n` points in dimension `d` (beyond the
    /// points themselves).
    pub working_bytes: fn(n: f64, d: usize) -> f64,
}

/// The finest scale at which a sampler's patterns are structured along one axis
/// ([`SamplerFacts::axis_strata`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisStrata {
    /// Independent uniform points: no scale of their own.
    Independent,
    /// Structure at the points' spacing, `N^{1/d}` intervals per axis (jitter's strata, the
    /// spacing of blue noise and of a regular grid).
    Spacing,
    /// Every axis's projection stratified into about `N` intervals (N-rooks, nets, Halton's
    /// radical inverses, rank-1 lattices and Kronecker sequences).
    Projections,
}

impl AxisStrata {
    /// Intervals per axis at which `n` points in dimension `d` are structured (0 for
    /// independent points).
    pub fn intervals(self, n: usize, d: usize) -> f64 {
        match self {
            AxisStrata::Independent => 0.0,
            AxisStrata::Spacing => (n as f64).powf(1.0 / d as f64),
            AxisStrata::Projections => n as f64,
        }
    }
}

/// How a sampler's cost per point changes with the dimension, from its 2D cost.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DimensionCost {
    /// In proportion to the coordinates drawn: `d/2` of the 2D cost (strata, nets, lattices).
    PerCoordinate,
    /// By a measured factor per dimension above two: the optimizers, whose work per point is
    /// over neighbourhoods that grow as a ball of a few spacings does (measured at N = 4096 in
    /// 2D and 3D). 1D is counted at the 2D cost, an upper bound (CCVT's 1D cost is 0.8 of its
    /// 2D one).
    PerDimension(f64),
}

impl DimensionCost {
    /// The factor on the 2D cost per point in dimension `d`.
    pub fn factor(self, d: usize) -> f64 {
        match self {
            Self::PerCoordinate => d as f64 / 2.0,
            Self::PerDimension(step) => step.powi(d.max(2) as i32 - 2),
        }
    }
}

/// The count at which [`SamplerFacts::cost_per_point_ns`] holds (1024 for the optimizers,
/// which `benches/sampler_costs.rs` measures there), beyond which
/// [`SamplerFacts::cost_growth`] applies.
pub const COST_REFERENCE_N: f64 = 4096.0;

/// How far a measured cost per point may stray from the declared one (either way) before
/// `benches/samplers.rs` fails: the decisions it drives (pools, the costly class) change at
/// factors of ten, so a factor of three still leaves each sampler in its class.
pub const COST_TOLERANCE: f64 = 3.0;

/// The rule N must follow.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CountRule {
    /// Any `N ≥ 1`.
    Any,
    /// `N = m^d` strata, or in 2D `a × b` with `b < a ≤ 2b`.
    Strata,
    /// A Fibonacci number.
    Fibonacci,
    /// `N = p²` for a prime `p` (an orthogonal array of strength 2 on `p` levels).
    PrimeSquare,
    /// `N = 2^m` (the complete nets of a base-2 sequence).
    PowerOfTwo,
}

impl CountRule {
    /// Whether `n` points follow the rule in dimension `d`.
    pub fn admits(self, n: usize, d: usize) -> bool {
        match self {
            CountRule::Any => n >= 1,
            CountRule::Strata => super::strata(n, d).is_some(),
            CountRule::Fibonacci => super::fibonacci::is_fibonacci(n),
            CountRule::PrimeSquare => {
                super::perfect_root(n, 2).is_some_and(|p| is_prime(p) && p + 1 >= d)
            }
            CountRule::PowerOfTwo => n.is_power_of_two(),
        }
    }

    /// The least admitted count `≥ n` (`None` beyond the range of `usize`).
    pub fn at_least(self, n: usize, d: usize) -> Option<usize> {
        let n = n.max(1);
        match self {
            CountRule::Any => Some(n),
            CountRule::PowerOfTwo => n.checked_next_power_of_two(),
            CountRule::Strata if d != 2 => {
                let root = integer_root(n, d);
                let m = if checked_power(root, d) == Some(n) {
                    root
                } else {
                    root + 1
                };
                checked_power(m, d)
            }
            CountRule::PrimeSquare => {
                let least = d.saturating_sub(1).max(2);
                let root = n.isqrt();
                let from = if root * root == n { root } else { root + 1 };
                (from.max(least)..)
                    .take_while(|p| p.checked_mul(*p).is_some())
                    .find(|&p| is_prime(p))
                    .map(|p| p * p)
            }
            // Strata in 2D (a × b, b < a ≤ 2b, every few counts) and Fibonacci numbers (a
            // geometric ladder): the next admitted count is a short walk away.
            CountRule::Strata | CountRule::Fibonacci => (n..).find(|&c| self.admits(c, d)),
        }
    }

    /// The greatest admitted count `< n` (`None` when there is none).
    pub fn below(self, n: usize, d: usize) -> Option<usize> {
        if n <= 1 {
            return None;
        }
        match self {
            CountRule::Any => Some(n - 1),
            CountRule::PowerOfTwo => Some(1 << (usize::BITS - 1 - (n - 1).leading_zeros())),
            CountRule::Strata if d != 2 => {
                checked_power(integer_root(n - 1, d), d).filter(|&c| c >= 1)
            }
            CountRule::PrimeSquare => {
                let least = d.saturating_sub(1).max(2);
                (least..=(n - 1).isqrt())
                    .rev()
                    .find(|&p| is_prime(p))
                    .map(|p| p * p)
            }
            CountRule::Strata | CountRule::Fibonacci => (1..n).rev().find(|&c| self.admits(c, d)),
        }
    }

    /// The admitted count nearest `n` (the smaller on ties), at least 1.
    pub fn nearest(self, n: usize, d: usize) -> usize {
        let n = n.max(1);
        match (self.below(n.saturating_add(1), d), self.at_least(n, d)) {
            (Some(b), Some(a)) if n - b <= a - n => b,
            (_, Some(a)) => a,
            (Some(b), None) => b,
            (None, None) => 1,
        }
    }
}

impl fmt::Display for CountRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CountRule::Any => "any N >= 1",
            CountRule::Strata => "N = m^d; 2D: or a×b, b<a≤2b",
            CountRule::Fibonacci => "N = F_m: 1, 2, 3, 5, 8, 13, 21, …",
            CountRule::PrimeSquare => "N = p² for a prime p: 4, 9, 25, 49, 121, …",
            CountRule::PowerOfTwo => "N = 2^m: 1, 2, 4, 8, 16, …",
        })
    }
}

/// `⌊n^{1/d}⌋`, exactly (the floating-point root corrected by one either way).
fn integer_root(n: usize, d: usize) -> usize {
    let guess = (n as f64).powf(1.0 / d as f64).round() as usize;
    let fits = |m: usize| checked_power(m, d).is_some_and(|p| p <= n);
    (guess.saturating_sub(1)..=guess + 1)
        .rev()
        .find(|&m| fits(m))
        .unwrap_or(0)
}

/// `m^d`, or `None` on overflow.
fn checked_power(m: usize, d: usize) -> Option<usize> {
    m.checked_pow(u32::try_from(d).ok()?)
}

/// Whether `p` is prime (trial division: the counts are squares of small numbers).
pub(crate) fn is_prime(p: usize) -> bool {
    p >= 2
        && (2..)
            .take_while(|q| q * q <= p)
            .all(|q| !p.is_multiple_of(q))
}

/// How a sampler's points occupy its cells ([`SamplerFacts::cells`]), as far as the cell form of
/// its unshifted estimator needs to know.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CellLaw {
    /// No cells in which its points are independent (or none the cell form reads).
    NoCells,
    /// A fixed number of points in every cell: jitter's strata, independent points' one cell.
    Fixed,
    /// N-rooks by independent uniform permutations of every axis's rows (Latin hypercube).
    Permutations,
    /// Strata and rows, each column's sub-rows and each row's sub-columns shuffled
    /// independently (multi-jitter, Chiu et al. 1994).
    IndependentShuffles,
    /// Strata and rows, one shuffle shared by every column and one by every row (correlated
    /// multi-jitter, Kensler 2013).
    CorrelatedShuffles,
    /// An orthogonal array of strength 2 with multi-jittered offsets: in 2D, correlated
    /// multi-jitter's law on `p × p` cells (relabelling the strata leaves one uniform
    /// permutation of the sub-columns and one of the sub-rows).
    OrthogonalArray,
    /// One base-2 net under nested uniform scrambling: every pattern has the net's pair counts
    /// on dyadic grids, and a digital shift leaves the law as it is (Owen-scrambled Sobol').
    OwenScrambledNet,
    /// A progressive sequence whose every `2^m` prefix is a `(0,m,2)`-net and whose law nested
    /// uniform scrambling and digital shifts leave unchanged (PMJ02): at a power of two its pair
    /// counts are any such net's; between two they differ from pattern to pattern.
    ProgressiveNet,
}

impl CellLaw {
    /// Whether the law is a scrambled base-2 net's, which a digital shift leaves unchanged.
    pub fn is_scrambled_net(self) -> bool {
        matches!(self, CellLaw::OwenScrambledNet | CellLaw::ProgressiveNet)
    }

    /// Whether its pairs of occupied cells are N-rooks permutations in closed form.
    pub fn is_rooks(self) -> bool {
        matches!(
            self,
            CellLaw::Permutations
                | CellLaw::IndependentShuffles
                | CellLaw::CorrelatedShuffles
                | CellLaw::OrthogonalArray
        )
    }
}

/// What is random in a pattern as drawn, before any randomization is added.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Randomness {
    /// Nothing: one fixed point set (the regular grid, rank-1 lattices, Kronecker).
    Deterministic,
    /// Independent uniform points.
    Independent,
    /// One uniform point in each stratum, with random choices of the strata's rows and columns
    /// (jitter, multi-jitter, Latin hypercube, orthogonal arrays, Gaussian jitter's offsets).
    Stratified,
    /// A digital net under random digit scrambling (Owen's nested scrambling; the random
    /// choices of the progressive construction).
    ScrambledNet,
    /// Radical inverses under random digit permutations.
    PermutedDigits,
    /// A random start relaxed by a translation-equivariant process on the torus (dart
    /// throwing, Lloyd-like descents).
    Relaxed,
}

impl Randomness {
    /// Whether the law of the patterns is invariant under every toroidal translation, so that a
    /// random shift leaves the estimator's law unchanged: independent points and processes on
    /// the torus that treat every position alike.
    pub fn is_stationary(self) -> bool {
        matches!(self, Randomness::Independent | Randomness::Relaxed)
    }

    /// Whether patterns of this randomness under `randomization` integrate with the variance
    /// of the shifted (homogenized) estimator: always under the shift itself; used as drawn,
    /// for stationary laws, which a shift does not change; under a digital shift, for
    /// independent points, which stay independent and uniform.
    pub fn has_shifted_variance(self, randomization: Randomization) -> bool {
        self.why_shifted_variance(randomization).is_some()
    }

    /// Why patterns of this randomness under `randomization` integrate with the shifted
    /// estimator's variance, in words, or `None` where they do not
    /// ([`has_shifted_variance`](Self::has_shifted_variance)).
    pub fn why_shifted_variance(self, randomization: Randomization) -> Option<&'static str> {
        match randomization {
            Randomization::Shift => Some("the shift is the routes' own estimator"),
            Randomization::None => self.is_stationary().then_some(
                "the patterns' law is invariant under translation on the torus, so a shift \
                 leaves the estimator's law unchanged",
            ),
            Randomization::DigitalShift => (self == Randomness::Independent)
                .then_some("independent points stay independent and uniform under a digital shift"),
        }
    }
}

/// The cells of a sampler's patterns as drawn: a grid such that, given the cell each point
/// falls in, the points are independent and uniform in their cells. Its unshifted estimator is
/// then the cells' means weighted by their random occupancy, plus the variance within the cells
/// (`docs/theory.md`, "Strata in space").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CellRule {
    /// No such grid is known.
    None,
    /// One cell, the whole cube: independent uniform points.
    Whole,
    /// The strata ([`super::strata`]), one point in each: the occupancy is fixed.
    Strata,
    /// `N` cells on each axis: one point in each row of every axis (N-rooks), uniform inside
    /// its cell of the `N^d` grid.
    Rows,
    /// `2^⌈log2 N⌉` cells on each axis: a base-2 net scrambled so that the digits below those
    /// its points all differ in are independent and uniform.
    Dyadic,
}

impl std::str::FromStr for CellRule {
    type Err = crate::error::Error;
    /// `whole`, `strata`, `rows` or `dyadic`.
    fn from_str(s: &str) -> crate::error::Result<Self> {
        match s.trim() {
            "whole" => Ok(CellRule::Whole),
            "strata" => Ok(CellRule::Strata),
            "rows" => Ok(CellRule::Rows),
            "dyadic" => Ok(CellRule::Dyadic),
            other => Err(crate::error::invalid(
                "cells",
                other,
                "whole, strata, rows or dyadic",
            )),
        }
    }
}

impl CellRule {
    /// The cells on each axis for `n` points in dimension `d`, or `None` where the rule has no
    /// grid (or `n` has no strata).
    pub fn grid(self, n: usize, d: usize) -> Option<Vec<usize>> {
        match self {
            CellRule::None => None,
            CellRule::Whole => Some(vec![1; d]),
            CellRule::Strata => super::strata(n, d),
            CellRule::Rows => Some(vec![n; d]),
            CellRule::Dyadic => {
                let bits = usize::BITS - n.max(1).saturating_sub(1).leading_zeros();
                Some(vec![1usize << bits; d])
            }
        }
    }

    /// Whether the occupancy of the cells is fixed (one point in each stratum).
    pub fn is_fixed(self) -> bool {
        matches!(self, CellRule::Whole | CellRule::Strata)
    }
}

/// Where a sampler's exact expected spectrum comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClosedFormRule {
    /// None is known.
    None,
    /// This one, at every N.
    Always(ClosedForm),
    /// This one, where N has strata ([`super::strata`]).
    WithStrata(ClosedForm),
    /// The built sampler's own, which depends on its parameters ([`super::Sampler::closed_form`]).
    OfSampler,
}

impl ClosedFormRule {
    /// Where the closed form comes from, in words, for tables.
    pub fn describe(self) -> String {
        match self {
            ClosedFormRule::None => "none".into(),
            ClosedFormRule::Always(c) => format!("{} (every N)", c.name()),
            ClosedFormRule::WithStrata(c) => format!("{} (N with strata)", c.name()),
            ClosedFormRule::OfSampler => "from its parameters (every valid N)".into(),
        }
    }
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

/// Which symmetries of the cube (permutations of the axes, reflections `x_a → 1 - x_a`) leave
/// the law of a sampler's patterns, and so `E[P_S]`, unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Symmetry {
    /// All of them.
    Cube,
    /// All of them where the strata are square (`N = m^d`); rectangular strata break the
    /// transpositions.
    CubeWithSquareStrata,
    /// Not all: each axis is its own sequence (Halton, Sobol'), rows and columns are built
    /// differently (correlated multi-jitter), or a lattice's generator is not symmetric.
    Partial,
}

/// Working memory of samplers that hold nothing beyond a point's worth per point.
pub(crate) fn one_word_per_point(n: f64, _d: usize) -> f64 {
    n * 8.0
}

/// The names of the facts' values, as in JSON (`snake_case`).
macro_rules! display_as_serialized {
    ($($t:ty),*) => {$(
        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                // Unit variants serialize to their name, so the `else` is never taken.
                let Ok(serde_json::Value::String(name)) = serde_json::to_value(self) else {
                    return Err(fmt::Error);
                };
                f.write_str(&name)
            }
        }
    )*};
}

display_as_serialized!(Randomness, Scaling, Symmetry, CellRule);
