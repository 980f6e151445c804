//! Rank-1 lattices in 2D: Korobov's with the best spectral test, and Fibonacci's.

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::fibonacci::{fibonacci_below, fibonacci_numbers};
use super::ClosedForm;
use super::{check_supported, Sampler, SamplerKind};
use crate::error::{Error, Result};
use crate::pointset::PointSet;
use crate::randomization::Randomization;

/// Korobov's lattice: fixed, so used under a random shift.
pub(crate) const KOROBOV_FACTS: SamplerFacts = SamplerFacts {
    name: "korobov",
    description: "rank-1 lattice frac(i(1,a)/N), a with the best spectral test; deterministic",
    dimensions: 2..=2,
    count: CountRule::Any,
    balanced_counts: CountRule::Any,
    randomness: Randomness::Deterministic,
    native_randomization: Randomization::Shift,
    cells: CellRule::None,
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::OfSampler,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 40.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// The Fibonacci lattice: fixed, so used under a random shift.
pub(crate) const FIBONACCI_FACTS: SamplerFacts = SamplerFacts {
    name: "fibonacci",
    description: "Fibonacci lattice frac(i(1,F_{m-1})/F_m); deterministic",
    dimensions: 2..=2,
    count: CountRule::Fibonacci,
    balanced_counts: CountRule::Fibonacci,
    randomness: Randomness::Deterministic,
    native_randomization: Randomization::Shift,
    cells: CellRule::None,
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::OfSampler,
    known_alpha: None,
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::Partial,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Projections,
    cost_per_point_ns: 16.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// How the generating vector `(1, a)` is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LatticeRule {
    /// Korobov's lattice at any N, with the `a` whose dual lattice has the longest shortest
    /// non-zero vector (the best spectral test: the widest empty zone around DC in the power
    /// spectrum), the smallest such `a ≤ N/2` on ties.
    Korobov,
    /// The Fibonacci lattice: `N = F_m` and `a = F_{m-1}`.
    Fibonacci,
}

/// The 2D rank-1 lattice `x_i = frac(i (1, a) / N)`, `i = 0 … N-1`. Deterministic: the seed
/// and the realization are ignored; Monte Carlo homogenizes it (a Cranley–Patterson shift).
///
/// Its points form a group under addition mod 1, so its power spectrum is exactly `N` on the
/// dual lattice `{k : k_0 + a k_1 ≡ 0 (mod N)}` and 0 elsewhere.
///
/// # Examples
/// ```
/// use specvar::sampler::{LatticeRule, Rank1Lattice, Sampler};
/// let fibonacci = Rank1Lattice::new(2, LatticeRule::Fibonacci)?;
/// assert_eq!(fibonacci.generator(89)?, 55);
/// assert!(fibonacci.sample(90, 0, 0).is_err()); // not a Fibonacci number
/// let korobov = Rank1Lattice::new(2, LatticeRule::Korobov)?;
/// assert_eq!(korobov.sample(100, 0, 0)?.len(), 100);
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct Rank1Lattice {
    rule: LatticeRule,
}

impl Rank1Lattice {
    /// A rank-1 lattice with `rule`; `d` must be 2.
    ///
    /// # Errors
    /// A dimension other than 2.
    pub fn new(d: usize, rule: LatticeRule) -> Result<Self> {
        let lattice = Self { rule };
        check_supported(lattice.facts(), d)?;
        Ok(lattice)
    }

    /// This rule's facts.
    fn facts(&self) -> &'static SamplerFacts {
        match self.rule {
            LatticeRule::Korobov => &KOROBOV_FACTS,
            LatticeRule::Fibonacci => &FIBONACCI_FACTS,
        }
    }

    /// The second component `a` of the generating vector at `n` points.
    ///
    /// # Errors
    /// `n = 0`, or (Fibonacci) an `n` that is not a Fibonacci number.
    pub fn generator(&self, n: usize) -> Result<u64> {
        self.check_count(n)?;
        Ok(match self.rule {
            LatticeRule::Korobov => korobov_generator(n as u64),
            LatticeRule::Fibonacci => fibonacci_below(n as u64).unwrap_or(1),
        })
    }
}

/// The squared length of the shortest non-zero vector of the dual lattice of `(1, a)` mod `n`,
/// spanned by `(n, 0)` and `(-a, 1)`: Lagrange–Gauss reduction, exact in integers.
pub fn shortest_dual_vector_sq(n: u64, a: u64) -> u128 {
    let norm = |v: (i128, i128)| (v.0 * v.0 + v.1 * v.1) as u128;
    let (mut u, mut v) = ((n as i128, 0i128), (-(a as i128), 1i128));
    if norm(u) < norm(v) {
        std::mem::swap(&mut u, &mut v);
    }
    loop {
        // u is the longer: subtract the nearest multiple of v.
        let dot = u.0 * v.0 + u.1 * v.1;
        let len = norm(v) as i128;
        let q = (2 * dot + len).div_euclid(2 * len);
        let w = (u.0 - q * v.0, u.1 - q * v.1);
        if norm(w) >= norm(v) {
            return norm(v);
        }
        u = v;
        v = w;
    }
}

/// Korobov's `a` for `n` points: the best spectral test over `1 ≤ a ≤ max(1, n/2)`.
fn korobov_generator(n: u64) -> u64 {
    (1..=(n / 2).max(1))
        .map(|a| (shortest_dual_vector_sq(n, a), a))
        .max_by(|x, y| x.0.cmp(&y.0).then(y.1.cmp(&x.1)))
        .map_or(1, |(_, a)| a)
}

impl Sampler for Rank1Lattice {
    fn name(&self) -> &'static str {
        self.facts().name
    }
    fn dimension(&self) -> usize {
        2
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(match self.rule {
            LatticeRule::Korobov => SamplerKind::Korobov,
            LatticeRule::Fibonacci => SamplerKind::Fibonacci,
        })
    }
    fn check_count(&self, n: usize) -> Result<()> {
        super::check_positive(self.name(), 2, n)?;
        if self.rule == LatticeRule::Korobov || fibonacci_below(n as u64).is_some() {
            return Ok(());
        }
        let below = fibonacci_numbers()
            .take_while(|&f| f < n as u64)
            .last()
            .unwrap_or(1);
        let above = fibonacci_numbers().find(|&f| f > n as u64).unwrap_or(below);
        Err(Error::UnsupportedCount {
            sampler: self.name(),
            n,
            dimension: 2,
            rule: "N must be a Fibonacci number (1, 2, 3, 5, 8, 13, …)".into(),
            nearest: format!("{below} or {above}"),
        })
    }
    fn closed_form(&self, n: usize) -> Option<ClosedForm> {
        self.generator(n)
            .ok()
            .map(|generator| ClosedForm::Rank1Lattice { generator })
    }
    fn sample(&self, n: usize, _seed: u64, _realization: u64) -> Result<PointSet> {
        let a = self.generator(n)? as u128;
        let mut coords = Vec::with_capacity(2 * n);
        for i in 0..n as u128 {
            coords.push(i as f64 / n as f64);
            coords.push(((i * a) % n as u128) as f64 / n as f64);
        }
        Ok(PointSet::from_trusted(2, coords))
    }
}
