//! Radial (angular-mean) spectra in scaled frequency `ν = ρ / N^{1/d}`.

use super::lattice::Lattice;
use serde::{Deserialize, Serialize};

/// One ring of lattice frequencies `b·Δ ≤ |k| < (b+1)·Δ`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RadialBin {
    /// Scaled frequency at the mean radius of the ring's lattice points.
    pub nu: f64,
    /// Mean radius `|k|` of the ring's lattice points.
    pub rho: f64,
    /// Mean power over the ring and the realizations.
    pub power: f64,
    /// Standard error of `power` across realizations (`NaN` with one realization).
    pub stderr: f64,
    /// Number of lattice points in the ring.
    pub count: usize,
    /// PSA's anisotropy: unbiased variance of the expected spectrum over the ring divided by
    /// the squared mean, in dB (`NaN` for rings of one point).
    pub anisotropy_db: f64,
}

/// A radial spectrum estimated at `n` points. Its abscissa is `ν`, so it serves every N for a
/// scale-invariant sampler; `ρ` is kept for reference at the estimation N.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RadialSpectrum {
    /// Dimension.
    pub dimension: usize,
    /// The N the spectrum was estimated at.
    pub n: usize,
    /// Realizations averaged.
    pub realizations: usize,
    /// Ring width in `|k|`.
    pub bin_width: f64,
    /// Rings in increasing radius; empty rings are left out; DC is never in a ring.
    pub bins: Vec<RadialBin>,
    /// Estimate of `P̆_S(0⁺)`; see [`RadialSpectrum::estimate_dc_limit`].
    pub dc_limit: f64,
}

/// Which ring each lattice point falls in (`None` for DC and for rings that leave the cube).
pub(crate) fn ring_assignment(lattice: &Lattice, width: f64) -> (Vec<Option<u32>>, usize) {
    // A ring is complete only if every direction fits in the cube: its outer radius ≤ K.
    let rings = (lattice.kmax as f64 / width).floor() as usize;
    let assign = (0..lattice.len())
        .map(|i| {
            let r = lattice.radius(i);
            let b = (r / width).floor() as usize;
            (i != lattice.dc_index() && b < rings).then_some(b as u32)
        })
        .collect();
    (assign, rings)
}

impl RadialSpectrum {
    /// Assembles a radial spectrum from the expected lattice spectrum and, per ring, the sum
    /// and sum of squares of each realization's ring mean.
    pub(crate) fn from_parts(
        lattice: &Lattice,
        mean: &[f64],
        n: usize,
        realizations: usize,
        width: f64,
        ring_moments: &[(f64, f64)],
    ) -> Self {
        let (assign, rings) = ring_assignment(lattice, width);
        let mut radius_sum = vec![0.0; rings];
        let mut count = vec![0usize; rings];
        let mut power_sum = vec![0.0; rings];
        let mut power_sq = vec![0.0; rings];
        for (i, b) in assign.iter().enumerate() {
            if let Some(b) = b {
                let b = *b as usize;
                radius_sum[b] += lattice.radius(i);
                count[b] += 1;
                power_sum[b] += mean[i];
                power_sq[b] += mean[i] * mean[i];
            }
        }
        let scale = (n as f64).powf(1.0 / lattice.dimension as f64);
        let m = realizations as f64;
        let bins = (0..rings)
            .filter(|&b| count[b] > 0)
            .map(|b| {
                let c = count[b] as f64;
                let rho = radius_sum[b] / c;
                let power = power_sum[b] / c;
                let ring_var = if count[b] > 1 {
                    (power_sq[b] - c * power * power) / (c - 1.0)
                } else {
                    f64::NAN
                };
                let (s, s2) = ring_moments[b];
                let stderr = if realizations > 1 {
                    ((s2 / m - (s / m).powi(2)).max(0.0) * m / (m - 1.0) / m).sqrt()
                } else {
                    f64::NAN
                };
                RadialBin {
                    nu: rho / scale,
                    rho,
                    power,
                    stderr,
                    count: count[b],
                    anisotropy_db: 10.0 * (ring_var.max(0.0) / (power * power)).log10(),
                }
            })
            .collect::<Vec<_>>();
        let dc_limit = Self::estimate_dc_limit(&bins);
        Self {
            dimension: lattice.dimension,
            n,
            realizations,
            bin_width: width,
            bins,
            dc_limit,
        }
    }

    /// `P̆_S(0⁺)` from the two lowest rings, extrapolated as `a + b ν²` (the form of every
    /// smooth isotropic spectrum near 0) and clamped at 0. For jitter and CCVT this gives about
    /// 0, for white noise about 1, for Poisson disk its low-frequency plateau.
    pub fn estimate_dc_limit(bins: &[RadialBin]) -> f64 {
        match bins {
            [] => 1.0,
            [only] => only.power.max(0.0),
            [a, b, ..] => {
                let (x1, x2) = (a.nu * a.nu, b.nu * b.nu);
                ((a.power * x2 - b.power * x1) / (x2 - x1)).max(0.0)
            }
        }
    }

    /// The spectrum at scaled frequency `ν`, interpolated linearly between ring radii, from
    /// `(0, dc_limit)` below the first ring, and 1 (white noise) beyond the last ring.
    pub fn power_at(&self, nu: f64) -> f64 {
        let bins = &self.bins;
        match Some(bins.partition_point(|b| b.nu < nu)).filter(|&i| i < bins.len()) {
            None => 1.0,
            Some(0) => {
                let b = &bins[0];
                self.dc_limit + (b.power - self.dc_limit) * nu / b.nu
            }
            Some(i) => {
                let (a, b) = (&bins[i - 1], &bins[i]);
                a.power + (b.power - a.power) * (nu - a.nu) / (b.nu - a.nu)
            }
        }
    }

    /// The largest `ν` the estimate covers.
    pub fn max_nu(&self) -> f64 {
        self.bins.last().map_or(0.0, |b| b.nu)
    }
}
