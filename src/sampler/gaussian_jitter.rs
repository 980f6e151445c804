//! Gaussian jitter: grid centres moved by Gaussian offsets (Subr and Kautz 2013).

use super::facts::{
    CellLaw, CellRule, ClosedFormRule, CountRule, DimensionCost, Randomness, SamplerFacts, Scaling,
    Symmetry,
};
use super::regular::{check_strata, for_each_cell};
use super::ClosedForm;
use super::{check_supported, uniform, Sampler, SamplerKind};
use crate::error::{invalid, Result};
use crate::pointset::{wrap, PointSet};
use crate::randomization::Randomization;
use crate::rng::{realization_rng, Stream};

/// Gaussian jitter: its closed form depends on its width.
pub(crate) const FACTS: SamplerFacts = SamplerFacts {
    name: "gjitter",
    description:
        "Gaussian jitter (Subr and Kautz 2013): grid centres plus Gaussian offsets of 0.25 \
                  strata",
    dimensions: 1..=crate::pointset::MAX_DIMENSION,
    count: CountRule::Strata,
    balanced_counts: CountRule::Strata,
    randomness: Randomness::Stratified,
    native_randomization: Randomization::None,
    cells: CellRule::None,
    cell_law: CellLaw::NoCells,
    closed_form: ClosedFormRule::OfSampler,
    known_alpha: Some(2.0),
    scaling: Scaling::Never,
    isotropic: false,
    symmetry: Symmetry::CubeWithSquareStrata,
    correlation_reach: 2.0,
    axis_strata: super::AxisStrata::Spacing,
    cost_per_point_ns: 55.0,
    cost_growth: 0.0,
    cost_dimension: DimensionCost::PerCoordinate,
    working_bytes: super::facts::one_word_per_point,
};

/// The default width: a standard deviation of a quarter stratum, close to uniform jitter's
/// `1/√12 ≈ 0.29`.
pub const DEFAULT_GAUSSIAN_WIDTH: f64 = 0.25;

/// The widest offset allowed, in strata: at 4 strata the grid's replicas carry a relative
/// power `exp(-4π²·16) ≈ 10^-275`, so the pattern is white noise to the last bit.
pub const MAX_GAUSSIAN_WIDTH: f64 = 4.0;

/// The narrowest offset allowed, in strata: below it the replicas of the grid, of power
/// `N exp(-4π² w²)` at the first one, make the truncated lattice form slow to converge; use
/// the regular grid for `w = 0`.
pub const MIN_GAUSSIAN_WIDTH: f64 = 0.05;

/// The centres `(j + 1/2)/m_a` of a grid of [`super::strata`], each moved along every axis by
/// an independent Gaussian offset of standard deviation `w / m_a` (`w` in strata), wrapped
/// onto the torus. One knob spans the regular grid (`w → 0`: no variance from the pattern,
/// aliasing on the replicas) to white noise (`w ≳ 1`).
///
/// Its expected power spectrum at integer `k ≠ 0` is
/// `1 - φ(k)² + N φ(k)² [k ∈ m Z^d]` with `φ(k) = Π_a exp(-2π² w² k_a² / m_a²)` the
/// characteristic function of the offset: the pairs of distinct points see the grid through
/// `φ²`, each point itself contributes 1.
///
/// Offsets are drawn by the Box–Muller transform with `libm`'s logarithm and cosine, so the
/// bits are the same on every platform.
///
/// # Examples
/// ```
/// use specvar::sampler::{GaussianJitter, Sampler};
/// let wide = GaussianJitter::new(2)?.with_width(0.5)?;
/// let points = wide.sample(64, 1, 0)?;
/// assert_eq!(points.len(), 64);
/// # Ok::<(), specvar::Error>(())
/// ```
#[derive(Debug, Clone, Copy)]
pub struct GaussianJitter {
    dimension: usize,
    width: f64,
}

impl GaussianJitter {
    /// Gaussian jitter in dimension `d` (1 to 8) with the [`DEFAULT_GAUSSIAN_WIDTH`].
    ///
    /// # Errors
    /// An unsupported dimension.
    pub fn new(d: usize) -> Result<Self> {
        check_supported(&FACTS, d)?;
        Ok(Self {
            dimension: d,
            width: DEFAULT_GAUSSIAN_WIDTH,
        })
    }

    /// Sets the offsets' standard deviation `w`, in strata.
    ///
    /// # Errors
    /// `w` outside [`MIN_GAUSSIAN_WIDTH`]`..=`[`MAX_GAUSSIAN_WIDTH`].
    pub fn with_width(mut self, width: f64) -> Result<Self> {
        if !(MIN_GAUSSIAN_WIDTH..=MAX_GAUSSIAN_WIDTH).contains(&width) {
            return Err(invalid(
                "width",
                width,
                format!("a standard deviation in strata from {MIN_GAUSSIAN_WIDTH} to {MAX_GAUSSIAN_WIDTH}"),
            ));
        }
        self.width = width;
        Ok(self)
    }

    /// The offsets' standard deviation, in strata.
    pub fn width(&self) -> f64 {
        self.width
    }
}

/// Two independent standard normal values from two uniforms (Box–Muller).
fn standard_normal_pair<R: rand::Rng>(rng: &mut R) -> (f64, f64) {
    // 1 - u lies in (0, 1], so the logarithm is finite.
    let radius = (-2.0 * libm::log(1.0 - uniform(rng))).sqrt();
    let angle = 2.0 * std::f64::consts::PI * uniform(rng);
    (radius * libm::cos(angle), radius * libm::sin(angle))
}

impl Sampler for GaussianJitter {
    fn name(&self) -> &'static str {
        FACTS.name
    }
    fn dimension(&self) -> usize {
        self.dimension
    }
    fn kind(&self) -> Option<SamplerKind> {
        Some(SamplerKind::GaussianJitter)
    }
    fn check_count(&self, n: usize) -> Result<()> {
        check_strata(self.name(), self.dimension, n).map(|_| ())
    }
    fn closed_form(&self, n: usize) -> Option<ClosedForm> {
        super::strata(n, self.dimension).map(|_| ClosedForm::GaussianJitter { width: self.width })
    }
    fn sample(&self, n: usize, seed: u64, realization: u64) -> Result<PointSet> {
        let d = self.dimension;
        let cells = check_strata(self.name(), d, n)?;
        let mut rng = realization_rng(seed, realization, Stream::Points);
        let mut coords = vec![0.0; n * d];
        let mut spare = None;
        for_each_cell(&cells, |i, axis, cell| {
            let z = spare.take().unwrap_or_else(|| {
                let (a, b) = standard_normal_pair(&mut rng);
                spare = Some(b);
                a
            });
            let m = cells[axis] as f64;
            coords[i * d + axis] = wrap((cell as f64 + 0.5 + self.width * z) / m);
        });
        Ok(PointSet::from_trusted(d, coords))
    }
}
