//! Directional spectra: the expected power of a 2D spectrum in angular sectors, ring by ring, so
//! that anisotropic samplers (Latin hypercube, Sobol, the regular grid) show what the radial
//! mean hides.

use super::LatticeSpectrum;
use crate::error::{invalid, Result};
use serde::Serialize;

/// The most sectors (one degree each).
pub const MAX_SECTORS: usize = 180;

/// One ring of a [`SectorSpectrum`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SectorRing {
    /// Scaled frequency `ν = ρ/√N` at the ring's middle radius.
    pub nu: f64,
    /// Mean power in each sector (`NaN`-free: a sector with no lattice point in this ring takes
    /// the mean of the ring).
    pub power: Vec<f64>,
    /// Standard error of each sector's mean, from the frequencies' own standard errors
    /// (distinct frequencies' estimates are nearly uncorrelated).
    pub stderr: Vec<f64>,
    /// Lattice points in each sector.
    pub count: Vec<usize>,
}

/// A 2D spectrum's power in `S` sectors of the half plane (`P(k) = P(−k)`, so directions are
/// taken modulo 180°): sector `s` holds the directions `[s, s + 1) · 180°/S`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SectorSpectrum {
    /// Points per pattern.
    pub n: usize,
    /// The sectors' centre directions, in degrees.
    pub directions: Vec<f64>,
    /// Ring width in `|k|`.
    pub bin_width: f64,
    /// Complete rings (outer radius at most K), innermost first.
    pub rings: Vec<SectorRing>,
}

/// Splits the 2D lattice spectrum `spectrum` into `sectors` directions and rings of width
/// `bin_width` in `|k|`, each frequency pair `±k` counted once.
///
/// # Errors
/// A spectrum not in 2D, `sectors` outside 1 to [`MAX_SECTORS`], or a bin width not positive.
///
/// # Examples
/// ```
/// use specvar::sampler::LatinHypercube;
/// use specvar::spectrum::{estimate, sector_spectrum, SpectrumParams};
/// let e = estimate(&LatinHypercube::new(2)?, 256, &SpectrumParams { kmax: 32, ..Default::default() })?;
/// let s = sector_spectrum(&e.lattice, 180, 4.0)?;
/// // N-rooks is 1D jitter of N strata along each axis and nearly white elsewhere: in the
/// // ring 8 ≤ |k| < 12 the 0° sector (the k_0 axis) is almost empty, the 45° one is not.
/// let ring = &s.rings[2];
/// assert!(ring.power[0] < 0.05 && ring.power[45] > 0.5);
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn sector_spectrum(
    spectrum: &LatticeSpectrum,
    sectors: usize,
    bin_width: f64,
) -> Result<SectorSpectrum> {
    let lattice = spectrum.lattice;
    if lattice.dimension != 2 {
        return Err(invalid(
            "dimension",
            lattice.dimension,
            "2 for sector spectra",
        ));
    }
    if !(1..=MAX_SECTORS).contains(&sectors) {
        return Err(invalid("sectors", sectors, format!("1 to {MAX_SECTORS}")));
    }
    if !(bin_width.is_finite() && bin_width > 0.0) {
        return Err(invalid("bin width", bin_width, "positive"));
    }
    let rings = (lattice.kmax as f64 / bin_width).floor() as usize;
    let mut sum = vec![vec![0.0; sectors]; rings];
    let mut var = vec![vec![0.0; sectors]; rings];
    let mut count = vec![vec![0usize; sectors]; rings];
    for i in 0..lattice.len() {
        let k = lattice.frequency(i);
        // Half plane: k_1 > 0, or k_1 = 0 and k_0 > 0 (DC excluded).
        if !(k[1] > 0 || (k[1] == 0 && k[0] > 0)) {
            continue;
        }
        // Non-negative: truncation is the floor, without a library call.
        let b = (lattice.radius(i) / bin_width) as usize;
        if b >= rings {
            continue;
        }
        let angle = (k[1] as f64).atan2(k[0] as f64).to_degrees(); // in [0, 180)
        let s = ((angle / 180.0 * sectors as f64) as usize).min(sectors - 1);
        sum[b][s] += spectrum.mean[i];
        let se = spectrum.stderr[i];
        var[b][s] += if se.is_finite() { se * se } else { 0.0 };
        count[b][s] += 1;
    }
    let root = (spectrum.n as f64).sqrt();
    let rings = (0..rings)
        .map(|b| {
            let total: f64 = sum[b].iter().sum();
            let points: usize = count[b].iter().sum();
            let ring_mean = if points > 0 {
                total / points as f64
            } else {
                0.0
            };
            let power = (0..sectors)
                .map(|s| match count[b][s] {
                    0 => ring_mean,
                    c => sum[b][s] / c as f64,
                })
                .collect();
            let stderr = (0..sectors)
                .map(|s| match count[b][s] {
                    0 => 0.0,
                    c => var[b][s].sqrt() / c as f64,
                })
                .collect();
            SectorRing {
                nu: (b as f64 + 0.5) * bin_width / root,
                power,
                stderr,
                count: count[b].clone(),
            }
        })
        .collect();
    Ok(SectorSpectrum {
        n: spectrum.n,
        directions: (0..sectors)
            .map(|s| (s as f64 + 0.5) * 180.0 / sectors as f64)
            .collect(),
        bin_width,
        rings,
    })
}
