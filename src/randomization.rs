//! How a pattern is randomized before it integrates: the estimator a prediction is for.
//!
//! The estimator `μ_N = (1/N) Σ f(x_j)` depends on the law of its points, and a sampler's
//! pattern as drawn is only part of that law: renderers and quasi-Monte Carlo libraries add a
//! randomization on top (or none). Each randomization decides the harmonic analysis:
//!
//! - **shift** (Cranley–Patterson rotation, the homogenized estimator): one uniform vector
//!   added to every point modulo 1. The cross terms between frequencies vanish, and the
//!   variance is `Σ_{k≠0} |f̂(k)|² E[P_S(k)] / N` over the Fourier lattice (`docs/theory.md`).
//! - **digital shift**: one uniform binary fraction XOR-ed into the digits of every coordinate.
//!   It is to Walsh functions what the toroidal shift is to Fourier: the variance is a sum
//!   over Walsh coefficients.
//! - **none**: the pattern as drawn, with only its own randomness (per-stratum jitter, Owen
//!   scrambling, random digit permutations); a deterministic pattern then has a bias and no
//!   variance.
//!
//! Each sampler declares the randomization it is used with in practice
//! ([`SamplerFacts::native_randomization`](crate::sampler::SamplerFacts)); a caller may choose
//! another ([`RandomizationChoice`]). Unit `u` of seed `s` draws its shift from the pair
//! `(s, u)` alone, so Monte Carlo runs are the same bits on any machine and thread count.

use crate::error::{invalid, Error, Result};
use crate::pointset::{wrap, PointSet, MAX_DIMENSION};
use crate::rng::{realization_rng, Stream};
use serde::{Deserialize, Serialize};
use std::fmt;

/// How a pattern is randomized before it integrates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "&'static str", try_from = "String")]
pub enum Randomization {
    /// A uniform random toroidal shift of the whole pattern: the homogenized estimator.
    Shift,
    /// A uniform random digital (XOR) shift of the base-2 digits of every coordinate.
    DigitalShift,
    /// The pattern as drawn, with only its own randomness.
    None,
}

impl Randomization {
    /// Every randomization, in display order.
    pub const ALL: [Randomization; 3] = [
        Randomization::Shift,
        Randomization::DigitalShift,
        Randomization::None,
    ];

    /// The name on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Randomization::Shift => "shift",
            Randomization::DigitalShift => "digital-shift",
            Randomization::None => "none",
        }
    }

    /// Words for the estimator, as tables and reports print it.
    pub fn estimator(self) -> &'static str {
        match self {
            Randomization::Shift => "randomly shifted",
            Randomization::DigitalShift => "digitally shifted",
            Randomization::None => "as drawn",
        }
    }

    /// What it does to each trial's pattern, in words.
    pub fn per_trial(self) -> &'static str {
        match self {
            Randomization::Shift => "a random toroidal shift per trial",
            Randomization::DigitalShift => "a random digital shift per trial",
            Randomization::None => "each pattern as drawn",
        }
    }

    /// Whether one pattern serves many independent randomizations, so that a costly pattern is
    /// worth reusing in a Monte Carlo pool: every randomization but none.
    pub fn reuses_patterns(self) -> bool {
        self != Randomization::None
    }

    /// The transform unit `unit` of `seed` applies in dimension `d`.
    pub fn draw(self, d: usize, seed: u64, unit: u64) -> UnitTransform {
        match self {
            Randomization::Shift => UnitTransform::Shift(toroidal_shift(d, seed, unit)),
            Randomization::DigitalShift => UnitTransform::Digital(digital_shift(d, seed, unit)),
            Randomization::None => UnitTransform::Identity,
        }
    }
}

impl fmt::Display for Randomization {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl TryFrom<String> for Randomization {
    type Error = Error;
    fn try_from(name: String) -> Result<Self> {
        name.parse()
    }
}

impl From<Randomization> for &'static str {
    fn from(r: Randomization) -> Self {
        r.name()
    }
}

impl std::str::FromStr for Randomization {
    type Err = Error;
    /// `shift`, `digital-shift` or `none`.
    fn from_str(s: &str) -> Result<Self> {
        let s = s.trim();
        Self::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| invalid("randomization", s, "shift, digital-shift or none"))
    }
}

/// A randomization asked for: the sampler's native one, or a given one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum RandomizationChoice {
    /// The sampler's native randomization
    /// ([`SamplerFacts::native_randomization`](crate::sampler::SamplerFacts)).
    Native,
    /// This one.
    Given(Randomization),
}

impl RandomizationChoice {
    /// The randomization for a sampler whose native one is `native`.
    pub fn resolve(self, native: Randomization) -> Randomization {
        match self {
            RandomizationChoice::Native => native,
            RandomizationChoice::Given(r) => r,
        }
    }

    /// Words for the estimator, as tables and reports print it.
    pub fn estimator(self) -> &'static str {
        match self {
            RandomizationChoice::Native => "as-used",
            RandomizationChoice::Given(r) => r.estimator(),
        }
    }

    /// What it does to each trial's pattern, in words.
    pub fn per_trial(self) -> &'static str {
        match self {
            RandomizationChoice::Native => "each sampler's own randomization per trial",
            RandomizationChoice::Given(r) => r.per_trial(),
        }
    }
}

impl From<RandomizationChoice> for String {
    fn from(c: RandomizationChoice) -> Self {
        c.to_string()
    }
}

impl TryFrom<String> for RandomizationChoice {
    type Error = Error;
    fn try_from(name: String) -> Result<Self> {
        name.parse()
    }
}

impl fmt::Display for RandomizationChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RandomizationChoice::Native => f.write_str("native"),
            RandomizationChoice::Given(r) => r.fmt(f),
        }
    }
}

impl std::str::FromStr for RandomizationChoice {
    type Err = Error;
    /// `native`, `shift`, `digital-shift` or `none`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "native" => Ok(RandomizationChoice::Native),
            other => other.parse().map(RandomizationChoice::Given).map_err(|_| {
                invalid(
                    "randomization",
                    other,
                    "native, shift, digital-shift or none",
                )
            }),
        }
    }
}

/// One unit's randomization of a pattern.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum UnitTransform {
    /// Add this vector modulo 1 (components beyond the dimension are 0).
    Shift([f64; MAX_DIMENSION]),
    /// XOR these 53-bit binary fractions into the coordinates' first 53 binary digits.
    Digital([u64; MAX_DIMENSION]),
    /// Leave the pattern as it is.
    Identity,
}

impl UnitTransform {
    /// Writes `base` so transformed into `out` (of `base`'s length).
    pub fn apply_into(&self, base: &PointSet, out: &mut [f64]) {
        let d = base.dimension();
        let pairs = out.chunks_exact_mut(d).zip(base.coords().chunks_exact(d));
        match self {
            UnitTransform::Shift(shift) => {
                for (x, c) in pairs {
                    for a in 0..d {
                        x[a] = wrap(c[a] + shift[a]);
                    }
                }
            }
            UnitTransform::Digital(mask) => {
                for (x, c) in pairs {
                    for a in 0..d {
                        x[a] = xor_digits(c[a], mask[a]);
                    }
                }
            }
            UnitTransform::Identity => out.copy_from_slice(base.coords()),
        }
    }

    /// Coordinate `axis` of one point, `c`, so transformed.
    #[inline]
    pub fn coordinate(&self, axis: usize, c: f64) -> f64 {
        match self {
            UnitTransform::Shift(shift) => wrap(c + shift[axis]),
            UnitTransform::Digital(mask) => xor_digits(c, mask[axis]),
            UnitTransform::Identity => c,
        }
    }

    /// `base`'s coordinates so transformed: `base`'s own for the identity, otherwise written
    /// into `scratch` (resized to fit), whose allocation the caller reuses from call to call.
    pub fn applied<'a>(&self, base: &'a PointSet, scratch: &'a mut Vec<f64>) -> &'a [f64] {
        if matches!(self, UnitTransform::Identity) {
            return base.coords();
        }
        scratch.resize(base.coords().len(), 0.0);
        self.apply_into(base, scratch);
        scratch
    }

    /// `base` so transformed, as a new set.
    pub fn apply(&self, base: &PointSet) -> PointSet {
        let mut coords = vec![0.0; base.coords().len()];
        self.apply_into(base, &mut coords);
        // Every transform maps the unit cube into itself.
        PointSet::new(base.dimension(), coords).expect("a randomized pattern stays in the cube")
    }
}

/// Binary digits a digital shift acts on: an `f64` in `[0, 1)` times `2^53` truncates to an
/// integer below `2^53` that keeps every digit down to `2^-53`, and any such integer times
/// `2^-53` is exact.
pub const DIGITAL_SHIFT_BITS: u32 = 53;

/// `x` with its first [`DIGITAL_SHIFT_BITS`] binary digits XOR-ed with `mask`'s (digits below
/// `2^-53` are dropped: at most `2^-53`, below the spacing of the doubles near 1).
#[inline]
pub fn xor_digits(x: f64, mask: u64) -> f64 {
    let scale = (1u64 << DIGITAL_SHIFT_BITS) as f64;
    (((x * scale) as u64 ^ mask) as f64) / scale
}

/// The uniform toroidal shift of unit `unit` of `seed` in dimension `d` (components beyond
/// `d` are 0).
pub fn toroidal_shift(d: usize, seed: u64, unit: u64) -> [f64; MAX_DIMENSION] {
    let mut rng = realization_rng(seed, unit, Stream::Shift);
    let mut shift = [0.0; MAX_DIMENSION];
    for s in shift.iter_mut().take(d) {
        *s = crate::rng::uniform(&mut rng);
    }
    shift
}

/// The uniform digital shift of unit `unit` of `seed` in dimension `d`: one
/// [`DIGITAL_SHIFT_BITS`]-bit mask per axis (components beyond `d` are 0).
pub fn digital_shift(d: usize, seed: u64, unit: u64) -> [u64; MAX_DIMENSION] {
    use rand::Rng;
    let mut rng = realization_rng(seed, unit, Stream::DigitalShift);
    let mut mask = [0u64; MAX_DIMENSION];
    for m in mask.iter_mut().take(d) {
        *m = rng.next_u64() >> (64 - DIGITAL_SHIFT_BITS);
    }
    mask
}

/// Errors unless a run with `shifts` randomizations per pattern suits `randomization`: at least
/// one, and exactly one for patterns used as drawn.
pub(crate) fn check_shifts(randomization: Randomization, shifts: usize) -> Result<()> {
    if shifts == 0 || (!randomization.reuses_patterns() && shifts != 1) {
        return Err(invalid(
            "shifts",
            shifts,
            "at least 1, and exactly 1 for patterns used as drawn (randomization none)",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for r in Randomization::ALL {
            assert_eq!(r.to_string().parse::<Randomization>().unwrap(), r);
            let c = RandomizationChoice::Given(r);
            assert_eq!(c.to_string().parse::<RandomizationChoice>().unwrap(), c);
        }
        let native = RandomizationChoice::Native;
        assert_eq!(
            native.to_string().parse::<RandomizationChoice>().unwrap(),
            native
        );
        assert!("xor".parse::<RandomizationChoice>().is_err());
    }

    #[test]
    fn a_digital_shift_is_an_involution_on_dyadic_points() {
        let mask = digital_shift(1, 7, 3)[0];
        for j in 0..64 {
            let x = j as f64 / 64.0;
            let y = xor_digits(x, mask);
            assert!((0.0..1.0).contains(&y));
            assert_eq!(xor_digits(y, mask), x);
        }
    }

    #[test]
    fn a_digital_shift_permutes_dyadic_intervals() {
        // Points in distinct intervals of width 2^-6 stay in distinct ones: a (0,m,s)-net stays
        // a net.
        let mask = digital_shift(1, 11, 0)[0];
        let mut hit = [false; 64];
        for j in 0..64 {
            let y = xor_digits((j as f64 + 0.5) / 64.0, mask);
            let cell = (y * 64.0) as usize;
            assert!(!hit[cell]);
            hit[cell] = true;
        }
    }
}
