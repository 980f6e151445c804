//! The low band of a stationary, isotropic sampler's spectrum, read from a fit over a disc of
//! frequencies rather than from the few frequencies an integrand's energy sits on.
//!
//! Where a pattern's pair correlations reach `L` (a few mean spacings), its expected spectrum
//! `E P(k) = 1 + N ∫ (g − 1) e^{−2πi k·r} dr` is a smooth function of `k`, varying on the scale
//! `1/(2πL)`; for an isotropic law it is a function of `u = |k|²` alone. One pattern's
//! periodogram scatters by its own size at every frequency (an exponential variable in the
//! plane), so where an integrand's energy sits on the few lowest frequencies (a smooth bump:
//! under Poisson disk at N = 65536, 94% of a Gaussian's variance comes from `|k| ≤ 2`) each
//! pattern's sum `Σ_k w(k) P(k)` scatters by about 60% and the mean needs hundreds of patterns.
//!
//! Fitting `E P ≈ a + b u` by least squares over the disc `D = {0 < |k| ≤ R}` reads the low
//! band from every frequency of the disc instead. The fit is linear in the periodogram, so it
//! is a change of weights: `Σ_{k∈D} w(k) fit(k) = Σ_{k∈D} w̃(k) P(k)` with
//! `w̃(k') = φ(k')ᵀ (ΦᵀΦ)⁻¹ Σ_{k∈D} w(k) φ(k)`, `φ(k) = (1, u/R², …)`; outside the disc the
//! weights are kept. Every per-pattern sum, its spread and its standard error stay what they
//! were, and the mean is unbiased wherever `E P` is linear in `u` on the disc. What the line
//! leaves out is measured, not assumed: the same sums with a fit one degree higher; their
//! difference, per pattern (so its standard error is paired), bounds the model term
//! (`docs/theory.md`, "The low band of stationary samplers").

use crate::sampler::{Randomness, SamplerKind};
use crate::spectrum::Lattice;

/// The degree in `u = |k|²` of the fit whose value is reported.
pub const FIT_DEGREE: usize = 1;

/// Distinct values of `|k|²` per fitted coefficient the disc must hold for the check's fit (one
/// degree higher) to be a fit and not an interpolation.
const VALUES_PER_COEFFICIENT: usize = 3;

/// The disc of frequencies on which a sampler's low band is fitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LowBand {
    /// The disc's radius `R` in frequency units.
    pub radius: f64,
}

impl LowBand {
    /// The disc for patterns of `kind` at `n` points in dimension `d`: samplers whose law is
    /// invariant under translations and rotations (dart throwing, relaxations) with pair
    /// correlations reaching `ℓ` mean spacings have a spectrum smooth on the scale
    /// `N^{1/d}/(2πℓ)`; the disc is twice that, `R = N^{1/d}/(πℓ)`. `None` for other samplers
    /// (strata, nets, lattices: their spectra are neither isotropic nor smooth) and for
    /// independent points (white: nothing to fit).
    pub fn for_sampler(kind: SamplerKind, n: usize, d: usize) -> Option<Self> {
        let facts = kind.facts();
        let relaxed = facts.randomness == Randomness::Relaxed;
        if !(relaxed && facts.isotropic && facts.correlation_reach > 0.0) {
            return None;
        }
        let radius =
            (n as f64).powf(1.0 / d as f64) / (std::f64::consts::PI * facts.correlation_reach);
        Some(Self { radius })
    }

    /// The least-squares fit of degree `degree` over the disc (clipped to `lattice`), ready to
    /// change any number of weight vectors; `None` where the disc holds too few distinct `|k|²`
    /// for a fit of degree `degree + 1`.
    pub fn fit(&self, lattice: Lattice, degree: usize) -> Option<DiscFit> {
        let members = self.disc(lattice);
        let mut values: Vec<u64> = members.iter().map(|&(_, u)| u).collect();
        values.sort_unstable();
        values.dedup();
        if values.len() < VALUES_PER_COEFFICIENT * (degree + 2) {
            return None;
        }
        let fit = DiscFit {
            members,
            scale: self.radius * self.radius,
            degree,
            gram: Vec::new(),
        };
        let m = degree + 1;
        let mut gram = vec![0.0; m * m];
        for &(_, u) in &fit.members {
            let phi = fit.basis(u);
            for a in 0..m {
                for b in 0..m {
                    gram[a * m + b] += phi[a] * phi[b];
                }
            }
        }
        Some(DiscFit { gram, ..fit })
    }

    /// The lattice's frequencies in the disc, as (flat index, `|k|²`), DC excluded, visited over
    /// the disc's bounding box only.
    fn disc(&self, lattice: Lattice) -> Vec<(usize, u64)> {
        let r2 = self.radius * self.radius;
        let reach = (self.radius.floor() as i64).min(lattice.kmax as i64);
        let d = lattice.dimension;
        let side = 2 * reach + 1;
        let mut members = Vec::new();
        for flat in 0..side.pow(d as u32) {
            let mut k = [0i64; 3];
            let mut rest = flat;
            for c in k.iter_mut().take(d) {
                *c = rest % side - reach;
                rest /= side;
            }
            let u = k.iter().map(|c| (c * c) as u64).sum::<u64>();
            if u > 0
                && u as f64 <= r2
                && let Some(i) = lattice.index(&k[..d])
            {
                members.push((i, u));
            }
        }
        members
    }
}

/// A least-squares fit polynomial in `u = |k|²` over a disc of lattice frequencies: its members
/// and Gram matrix, computed once for every weight vector it changes.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscFit {
    members: Vec<(usize, u64)>,
    scale: f64,
    degree: usize,
    gram: Vec<f64>,
}

impl DiscFit {
    /// `(1, x, x², …)` at `x = u / R²`.
    fn basis(&self, u: u64) -> Vec<f64> {
        let x = u as f64 / self.scale;
        (0..=self.degree)
            .scan(1.0, |p, _| {
                let v = *p;
                *p *= x;
                Some(v)
            })
            .collect()
    }

    /// The weights `w̃` whose sum against a periodogram is `w`'s sum against this fit of that
    /// periodogram over the disc, `w` kept outside it; `None` if the fit's system is singular.
    pub fn smoothed(&self, weights: &[f64]) -> Option<Vec<f64>> {
        let m = self.degree + 1;
        let mut moments = vec![0.0; m];
        for &(i, u) in &self.members {
            for (moment, phi) in moments.iter_mut().zip(self.basis(u)) {
                *moment += weights[i] * phi;
            }
        }
        let coefficients = solve(self.gram.clone(), moments)?;
        let mut out = weights.to_vec();
        for &(i, u) in &self.members {
            out[i] = self
                .basis(u)
                .iter()
                .zip(&coefficients)
                .map(|(p, c)| p * c)
                .sum();
        }
        Some(out)
    }
}

/// Solves the symmetric positive definite system `a x = b` (`m × m`, row-major) by Gaussian
/// elimination with partial pivoting; `None` if it is singular to rounding.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let m = b.len();
    for col in 0..m {
        let pivot =
            (col..m).max_by(|&r, &s| a[r * m + col].abs().total_cmp(&a[s * m + col].abs()))?;
        if a[pivot * m + col].abs() <= 1e-12 * a[col * m + col].abs().max(f64::MIN_POSITIVE) {
            return None;
        }
        for c in 0..m {
            a.swap(col * m + c, pivot * m + c);
        }
        b.swap(col, pivot);
        for r in col + 1..m {
            let factor = a[r * m + col] / a[col * m + col];
            for c in col..m {
                a[r * m + c] -= factor * a[col * m + c];
            }
            b[r] -= factor * b[col];
        }
    }
    let mut x = vec![0.0; m];
    for r in (0..m).rev() {
        let rest: f64 = (r + 1..m).map(|c| a[r * m + c] * x[c]).sum();
        x[r] = (b[r] - rest) / a[r * m + r];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A periodogram that is a polynomial of the fit's degree in `|k|²` on the disc is its own
    /// fit: the smoothed weights give the same sum as the raw ones, to rounding.
    #[test]
    fn a_spectrum_of_the_fits_degree_is_read_unchanged() {
        let lattice = Lattice {
            dimension: 2,
            kmax: 20,
        };
        let band = LowBand { radius: 12.5 };
        let weights: Vec<f64> = (0..lattice.len())
            .map(|i| {
                let k = lattice.frequency(i);
                (-0.3 * ((k[0] - 1) * (k[0] - 1) + 2 * k[1] * k[1]) as f64).exp()
            })
            .collect();
        for degree in 0..=2 {
            let smooth = band
                .fit(lattice, degree)
                .unwrap()
                .smoothed(&weights)
                .unwrap();
            let spectrum = |i: usize| {
                let k = lattice.frequency(i);
                let u = (k[0] * k[0] + k[1] * k[1]) as f64;
                (0..=degree)
                    .map(|j| (0.1 + j as f64) * (u / 100.0).powi(j as i32))
                    .sum::<f64>()
            };
            let raw: f64 = (0..lattice.len()).map(|i| weights[i] * spectrum(i)).sum();
            let fitted: f64 = (0..lattice.len()).map(|i| smooth[i] * spectrum(i)).sum();
            assert!(
                (raw - fitted).abs() <= 1e-12 * raw,
                "degree {degree}: {raw} vs {fitted}"
            );
            // …while one of a higher degree is not (the fit does smooth).
            let curved = |i: usize| {
                spectrum(i) + {
                    let k = lattice.frequency(i);
                    ((k[0] * k[0] + k[1] * k[1]) as f64 / 100.0).powi(degree as i32 + 1)
                }
            };
            let raw: f64 = (0..lattice.len()).map(|i| weights[i] * curved(i)).sum();
            let fitted: f64 = (0..lattice.len()).map(|i| smooth[i] * curved(i)).sum();
            assert!((raw - fitted).abs() > 1e-6 * raw, "degree {degree}");
        }
    }

    /// Too small a disc is refused rather than interpolated.
    #[test]
    fn a_disc_with_few_distinct_radii_is_refused() {
        let lattice = Lattice {
            dimension: 2,
            kmax: 8,
        };
        assert!(LowBand { radius: 2.3 }.fit(lattice, 1).is_none());
        assert!(LowBand { radius: 5.0 }.fit(lattice, 1).is_some());
        // The disc is clipped to the lattice.
        let fit = LowBand { radius: 50.0 }.fit(lattice, 1).unwrap();
        assert_eq!(fit.members.len(), lattice.len() - 1);
    }

    /// Only relaxed, isotropic samplers have a low band to fit.
    #[test]
    fn the_low_band_belongs_to_relaxed_isotropic_samplers() {
        for kind in SamplerKind::in_dimension(2) {
            let band = LowBand::for_sampler(kind, 4096, 2);
            let expected = matches!(
                kind,
                SamplerKind::PoissonDisk
                    | SamplerKind::Bridson
                    | SamplerKind::Ccvt
                    | SamplerKind::GaussianBlueNoise
            );
            assert_eq!(band.is_some(), expected, "{kind}");
        }
    }
}
