//! Reproducible random streams keyed by (seed, realization, purpose).
//!
//! Realization `i` of seed `s` must be the same on any machine and any thread count, so every
//! randomized routine derives its generator from those numbers alone, never from shared state.
//! The generator is `Pcg64` (portable, 128-bit state); the seed is expanded with SplitMix64.

use rand_pcg::Pcg64;

/// What a stream is used for, so that independent uses of one (seed, realization) never share
/// random numbers (e.g. the points of a pattern and its homogenizing shift).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u64)]
pub enum Stream {
    /// The points of a sampler.
    Points = 1,
    /// The toroidal shift of homogenization.
    Shift = 2,
    /// Monte Carlo trial bookkeeping (e.g. bootstrap resampling).
    Trial = 3,
    /// Integrands drawn at random.
    Integrand = 4,
    /// The independent rays of a reference image.
    Reference = 5,
    /// The digital shift of a digitally shifted pattern.
    DigitalShift = 6,
}

/// SplitMix64 finalizer: a bijective 64-bit mixer.
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The generator for realization `realization` of `seed`, for one `purpose`.
///
/// # Examples
/// ```
/// use rand::RngExt;
/// use specvar::rng::{realization_rng, Stream};
/// let a: f64 = realization_rng(7, 3, Stream::Points).random();
/// let b: f64 = realization_rng(7, 3, Stream::Points).random();
/// assert_eq!(a, b);
/// ```
pub fn realization_rng(seed: u64, realization: u64, purpose: Stream) -> Pcg64 {
    let p = purpose as u64;
    let hi = splitmix64(seed ^ splitmix64(p));
    let lo = splitmix64(hi ^ realization);
    let state = ((hi as u128) << 64) | lo as u128;
    let stream = ((realization as u128) << 8) | p as u128;
    Pcg64::new(state, stream)
}

/// A uniform draw in `[0, 1)` with 53 random bits.
#[inline]
pub(crate) fn uniform<R: rand::Rng>(rng: &mut R) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}
