//! Digits: Owen's gains of scrambled nets, and Halton's permuted digits through their supports and levels.

pub(crate) mod dyadic_levels;
pub(crate) mod halton_remainder;
pub(crate) mod owen_gains;
pub(crate) mod permuted_digits;
pub(crate) mod permuted_level;
pub(crate) mod shifted_gains;
