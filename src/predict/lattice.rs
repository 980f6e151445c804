//! The lattice form, exact on the torus:
//! `Var[μ_N] = (1/N) Σ_{k≠0} |f̂(k)|² E[P_S(k)]`, summed over `|k_i| ≤ K`, and beyond `K` the
//! remaining energy (by Parseval) times `P_S = 1`.

use super::{check_dimension, check_n, ErrorBudget, Form, Prediction, Route, SpectrumSource};
use crate::error::{invalid, Error, Result};
use crate::integrand::Integrand;
use crate::quadrature::CompensatedSum;
use crate::spectrum::{ClosedLattice, Lattice, LatticeSpectrum};
use rayon::prelude::*;

/// An integrand's power `|f̂(k)|²` on a lattice of integer frequencies, with the energy beyond
/// it: everything the lattice form needs from the integrand. The mean of these over many
/// integrands (the pixels of an image) predicts their mean variance, since the variance is
/// linear in the power.
#[derive(Debug, Clone, PartialEq)]
pub struct LatticePower {
    /// The frequencies.
    pub lattice: Lattice,
    /// `|f̂(k)|²` in lattice order (0 at DC, which the variance excludes).
    pub power: Vec<f64>,
    /// `∫ f² - I² - Σ_{k≠0 in the lattice} |f̂(k)|²` by Parseval: the energy beyond the lattice.
    pub beyond: f64,
    /// What it is the power of.
    pub label: String,
}

impl LatticePower {
    /// The power of `f` on `lattice` (computed in parallel over rows).
    ///
    /// # Errors
    /// A lattice of another dimension than `f`.
    pub fn of(f: &dyn Integrand, lattice: Lattice) -> Result<Self> {
        let d = f.dimension();
        check_dimension(d)?;
        if lattice.dimension != d {
            return Err(Error::Mismatch(format!(
                "lattice of dimension {} for an integrand of dimension {d}",
                lattice.dimension
            )));
        }
        let side = lattice.side();
        let mut power = vec![0.0; lattice.len()];
        power.par_chunks_mut(side).enumerate().for_each(|(r, row)| {
            let mut omega = [0.0; 3];
            for (j, slot) in row.iter_mut().enumerate() {
                let i = r * side + j;
                if i == lattice.dc_index() {
                    continue;
                }
                let k = lattice.frequency(i);
                for a in 0..d {
                    omega[a] = k[a] as f64;
                }
                *slot = f.fourier(&omega[..d]).norm_sqr();
            }
        });
        let mut inside = CompensatedSum::default();
        power.iter().for_each(|&p| inside.add(p));
        let i0 = f.spectral_integral();
        Ok(Self {
            lattice,
            beyond: (f.spectral_energy() - i0 * i0 - inside.value()).max(0.0),
            power,
            label: f.label(),
        })
    }

    /// The mean of several powers on one lattice.
    ///
    /// # Errors
    /// No parts, or parts on different lattices.
    pub fn mean(parts: &[LatticePower], label: impl Into<String>) -> Result<Self> {
        let first = parts
            .first()
            .ok_or_else(|| invalid("lattice powers", 0, "at least one"))?;
        if parts.iter().any(|p| p.lattice != first.lattice) {
            return Err(Error::Mismatch(
                "lattice powers on different lattices".into(),
            ));
        }
        let scale = 1.0 / parts.len() as f64;
        let mut power = vec![0.0; first.power.len()];
        for part in parts {
            for (acc, p) in power.iter_mut().zip(&part.power) {
                *acc += p * scale;
            }
        }
        Ok(Self {
            lattice: first.lattice,
            power,
            beyond: parts.iter().map(|p| p.beyond).sum::<f64>() * scale,
            label: label.into(),
        })
    }
}

/// The lattice-form variance of the homogenized estimator with `n` points, summed over
/// `|k_i| ≤ kmax` (for an estimated spectrum, its own K), with `P_S = 1` assumed beyond.
///
/// # Errors
/// `n = 0`, a dimension mismatch, or an estimated spectrum at another N.
///
/// # Examples
/// ```
/// use specvar::integrand::{Ball, Integrand};
/// use specvar::predict::{predict_lattice, SpectrumSource};
/// use specvar::spectrum::ClosedForm;
/// let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0).unwrap();
/// let p = predict_lattice(&disk, &SpectrumSource::Closed(ClosedForm::WhiteNoise), 64, 32).unwrap();
/// let exact = (disk.integral_of_square() - disk.integral().powi(2)) / 64.0;
/// assert!((p.variance - exact).abs() < 1e-12 * exact);
/// ```
pub fn predict_lattice(
    f: &dyn Integrand,
    source: &SpectrumSource<'_>,
    n: usize,
    kmax: usize,
) -> Result<Prediction> {
    let lattice = match source {
        SpectrumSource::Closed(_) => Lattice {
            dimension: f.dimension(),
            kmax,
        },
        SpectrumSource::Estimated(e) => e.lattice.lattice,
    };
    // A lattice of another dimension is refused by `LatticePower::of`.
    predict_from_power(&LatticePower::of(f, lattice)?, source, n)
}

/// The lattice-form variance from an integrand's power on the lattice (see [`LatticePower`]):
/// `(Σ_{k≠0} |f̂(k)|² P_S(k) + beyond) / N`, the energy beyond the lattice counted as white.
///
/// # Errors
/// `n = 0`, or an estimated spectrum at another N or on another lattice.
pub fn predict_from_power(
    power: &LatticePower,
    source: &SpectrumSource<'_>,
    n: usize,
) -> Result<Prediction> {
    check_n(n)?;
    let lattice = power.lattice;
    let d = lattice.dimension;
    check_dimension(d)?;
    let spectrum = LatticeSpectrumAt::new(source, lattice, n)?;
    let side = lattice.side();
    let edge = lattice.kmax as u64;
    // Per row: Σ |f̂|² P, the edge's Σ |f̂|² |1 - P|, and Σ (|f̂|² se(P))².
    let per_row: Vec<[f64; 3]> = power
        .power
        .par_chunks(side)
        .enumerate()
        .map(|(r, row)| {
            let mut acc = [0.0; 3];
            for (j, &power_f) in row.iter().enumerate() {
                let i = r * side + j;
                if i == lattice.dc_index() {
                    continue;
                }
                let k = lattice.frequency(i);
                let (power_s, se) = spectrum.at(i, &k[..d]);
                acc[0] += power_f * power_s;
                if k[..d].iter().any(|c| c.unsigned_abs() == edge) {
                    acc[1] += power_f * (1.0 - power_s).abs();
                }
                if se.is_finite() {
                    acc[2] += (power_f * se).powi(2);
                }
            }
            acc
        })
        .collect();
    let mut weighted = CompensatedSum::default();
    let (mut edge_sum, mut noise) = (0.0, 0.0);
    for [w, e, q] in per_row {
        weighted.add(w);
        edge_sum += e;
        noise += q;
    }
    Ok(Prediction {
        variance: (weighted.value() + power.beyond) / n as f64,
        route: Route {
            form: Form::Lattice,
            spectrum: source.origin(),
        },
        reason: String::new(),
        budget: ErrorBudget {
            // P(k) = P(-k) exactly, so the two halves add coherently: 2 Σ (w se)².
            spectrum_noise: (2.0 * noise).sqrt() / n as f64,
            quadrature: 0.0,
            truncation: edge_sum.min(power.beyond) / n as f64,
            model: 0.0,
        },
        n,
        dimension: d,
        dc_term: 0.0,
        evaluations: lattice.len() as u64,
        alternatives: Vec::new(),
    })
}

/// A spectrum read on one lattice for one N: a tabulated closed form, or an estimate there.
enum LatticeSpectrumAt<'a> {
    Closed(ClosedLattice),
    Estimated(&'a LatticeSpectrum),
}

impl<'a> LatticeSpectrumAt<'a> {
    fn new(source: &SpectrumSource<'a>, lattice: Lattice, n: usize) -> Result<Self> {
        match source {
            SpectrumSource::Closed(c) => Ok(Self::Closed(c.on_lattice(
                n,
                lattice.dimension,
                lattice.kmax,
            ))),
            SpectrumSource::Estimated(e) => {
                let s = &e.lattice;
                if s.n != n || s.lattice != lattice {
                    return Err(Error::Mismatch(format!(
                        "lattice spectrum of N = {} in {}D with K = {} for N = {n} in {}D with K = {}",
                        s.n, s.lattice.dimension, s.lattice.kmax, lattice.dimension, lattice.kmax
                    )));
                }
                Ok(Self::Estimated(s))
            }
        }
    }

    /// The mean power and its standard error at flat index `i`, frequency `k`.
    #[inline]
    fn at(&self, i: usize, k: &[i64]) -> (f64, f64) {
        match self {
            Self::Closed(c) => (c.power(k), 0.0),
            Self::Estimated(s) => (s.mean[i], s.stderr[i]),
        }
    }
}
