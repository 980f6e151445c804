//! Radial (angular-mean) spectra in scaled frequency `ν = ρ / N^{1/d}`.

use super::lattice::Lattice;
use serde::{Deserialize, Serialize};

/// Rings up to this `ν` enter the fit of `P̆_S(0⁺)`.
const DC_FIT_NU: f64 = 0.2;

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

/// The ring of each of the first `count` lattice frequencies in flat order, and the number of
/// complete rings `R`; DC and frequencies in no complete ring get `R` (a spare slot).
pub(crate) fn ring_assignment(lattice: &Lattice, width: f64, count: usize) -> (Vec<u32>, usize) {
    // A ring is complete only if every direction fits in the cube: its outer radius ≤ K.
    let rings = (lattice.kmax as f64 / width).floor() as usize;
    let dc = lattice.dc_index();
    let mut assign = Vec::with_capacity(count);
    lattice.for_each_squared_radius(count, |i, r2| {
        // r / width ≥ 0: truncation is the floor, without a library call per frequency
        // (the baseline x86-64 target has no rounding instruction).
        let b = ((r2 as f64).sqrt() / width) as usize;
        assign.push(if i != dc && b < rings { b } else { rings } as u32);
    });
    (assign, rings)
}

impl RadialSpectrum {
    /// Assembles a radial spectrum from the expected lattice spectrum and the ring of each
    /// frequency, both on the half lattice `0..=dc` (the other half mirrors them, `-k` at
    /// `len - 1 - i`; rings from [`ring_assignment`]), and per ring the sum and sum of squares
    /// of each realization's ring mean.
    pub(crate) fn from_parts(
        lattice: &Lattice,
        half_mean: &[f64],
        n: usize,
        realizations: usize,
        (half_rings, rings): (&[u32], usize),
        width: f64,
        ring_moments: &[(f64, f64)],
    ) -> Self {
        let mut radius_sum = vec![0.0; rings];
        let mut count = vec![0usize; rings];
        let mut power_sum = vec![0.0; rings];
        let mut power_sq = vec![0.0; rings];
        let len = lattice.len();
        lattice.for_each_squared_radius(len, |i, r2| {
            let half = i.min(len - 1 - i);
            let b = half_rings[half] as usize;
            if b < rings {
                let mean = half_mean[half];
                radius_sum[b] += (r2 as f64).sqrt();
                count[b] += 1;
                power_sum[b] += mean;
                power_sq[b] += mean * mean;
            }
        });
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

    /// `P̆_S(0⁺)`: the intercept `a` of a least-squares fit `P = a + b ν²` (the form of every
    /// smooth isotropic spectrum near 0) over the rings with `ν ≤ 0.2` (at least the lowest 3),
    /// each weighted by its lattice-point count, clamped at 0. It gives about 0 for jitter and
    /// CCVT, about 1 for white noise, and the low-frequency plateau of Poisson disk.
    pub fn estimate_dc_limit(bins: &[RadialBin]) -> f64 {
        Self::dc_weights(bins)
            .iter()
            .map(|&(i, c)| c * bins[i].power)
            .sum::<f64>()
            .max(0.0)
    }

    /// The estimate of [`estimate_dc_limit`](Self::estimate_dc_limit) before clamping is linear
    /// in the ring powers: `a = Σ c_i P_i`. Returns the pairs `(i, c_i)`.
    pub fn dc_weights(bins: &[RadialBin]) -> Vec<(usize, f64)> {
        let used = bins
            .iter()
            .take_while(|b| b.nu <= DC_FIT_NU)
            .count()
            .max(3)
            .min(bins.len());
        match used {
            0 => Vec::new(),
            1 => vec![(0, 1.0)],
            _ => {
                // Weighted least squares of P on x = ν²: a = Σ w_i (Sxx - x̄ Sx... ) in closed form.
                let w: Vec<f64> = bins[..used].iter().map(|b| b.count as f64).collect();
                let x: Vec<f64> = bins[..used].iter().map(|b| b.nu * b.nu).collect();
                let sw: f64 = w.iter().sum();
                let xm = w.iter().zip(&x).map(|(w, x)| w * x).sum::<f64>() / sw;
                let sxx: f64 = w.iter().zip(&x).map(|(w, x)| w * (x - xm).powi(2)).sum();
                // a = ȳ - b x̄ with b = Σ w (x - x̄) y / Sxx: linear in y.
                (0..used)
                    .map(|i| (i, w[i] / sw - xm * w[i] * (x[i] - xm) / sxx))
                    .collect()
            }
        }
    }

    /// The spectrum at scaled frequency `ν`: between rings, interpolated linearly in
    /// `(ln ν, ln P)` (exact for power laws, which low-frequency spectra are); below the first
    /// ring, `a + (P_0 - a)(ν/ν_0)^γ` from the DC limit `a`, with `γ` the log-log slope of
    /// `P - a` between the first two rings (1 when that is undefined); beyond the last ring,
    /// 1 (white noise).
    pub fn power_at(&self, nu: f64) -> f64 {
        let bins = &self.bins;
        match Some(bins.partition_point(|b| b.nu < nu)).filter(|&i| i < bins.len()) {
            None => 1.0,
            Some(0) => {
                let a = self.dc_limit;
                a + (bins[0].power - a) * (nu / bins[0].nu).powf(self.first_segment_exponent())
            }
            Some(i) => {
                let (lo, hi) = (&bins[i - 1], &bins[i]);
                let t = (nu / lo.nu).ln() / (hi.nu / lo.nu).ln();
                if lo.power > 0.0 && hi.power > 0.0 {
                    lo.power * (hi.power / lo.power).powf(t)
                } else {
                    lo.power + (hi.power - lo.power) * t
                }
            }
        }
    }

    /// `γ` of the segment below the first ring (see [`power_at`](Self::power_at)), in `[0, 8]`.
    pub fn first_segment_exponent(&self) -> f64 {
        match &self.bins[..] {
            [b0, b1, ..] => {
                let (d0, d1) = (b0.power - self.dc_limit, b1.power - self.dc_limit);
                let g = (d1 / d0).ln() / (b1.nu / b0.nu).ln();
                if d0 > 0.0 && d1 > 0.0 && g.is_finite() {
                    g.clamp(0.0, 8.0)
                } else {
                    1.0
                }
            }
            _ => 1.0,
        }
    }

    /// The largest `ν` the estimate covers.
    pub fn max_nu(&self) -> f64 {
        self.bins.last().map_or(0.0, |b| b.nu)
    }
}
