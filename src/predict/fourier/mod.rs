//! The Fourier forms: the lattice and polar sums with closed or estimated spectra, their tails, and the sums in space they equal by Poisson summation.

pub(crate) mod bias;
pub(crate) mod dual_lattice;
pub(crate) mod gaussian_jitter;
pub(crate) mod jitter_tent;
pub(crate) mod lattice;
pub(crate) mod low_band;
pub(crate) mod measured_tail;
pub(crate) mod pair;
pub(crate) mod polar;
pub(crate) mod radial_table;
pub(crate) mod space;
