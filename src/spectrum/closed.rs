//! Closed-form expected power spectra: white noise and jittered sampling.

use crate::quadrature::GaussLegendre;
use crate::sampler::strata;
use std::f64::consts::PI;

/// `sin(x)/x`, with its limit 1 at 0.
#[inline]
pub fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-8 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// A sampler whose expected power spectrum is known exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ClosedForm {
    /// `E[P_S(k)] = 1` for every `k ≠ 0`.
    WhiteNoise,
    /// Jittered sampling with `m^d = N` strata: `E[P_S(k)] = 1 - Π_i sinc²(π k_i / m)`.
    Jitter,
}

impl ClosedForm {
    /// The expected spectrum at scaled frequency `ν = k / N^{1/d}` (a vector), `ν ≠ 0`.
    ///
    /// # Examples
    /// ```
    /// use specvar::spectrum::ClosedForm;
    /// // Jitter is white at non-zero multiples of m along an axis…
    /// assert!((ClosedForm::Jitter.power(&[1.0, 0.0]) - 1.0).abs() < 1e-15);
    /// // …and rises like π²|ν|²/3 from zero at DC.
    /// let nu = [0.01, 0.02];
    /// let expected = std::f64::consts::PI.powi(2) * (0.01f64.powi(2) + 0.02f64.powi(2)) / 3.0;
    /// assert!((ClosedForm::Jitter.power(&nu) / expected - 1.0).abs() < 1e-3);
    /// assert_eq!(ClosedForm::WhiteNoise.power(&[0.3, 0.1]), 1.0);
    /// ```
    pub fn power(self, nu: &[f64]) -> f64 {
        match self {
            ClosedForm::WhiteNoise => 1.0,
            ClosedForm::Jitter => {
                1.0 - nu
                    .iter()
                    .map(|v| {
                        let s = sinc(PI * v);
                        s * s
                    })
                    .product::<f64>()
            }
        }
    }

    /// This form for an `n`-point pattern on the lattice `|k_i| ≤ kmax` in dimension `d`, with
    /// its per-axis factors tabulated once (see [`ClosedLattice`]).
    ///
    /// # Examples
    /// ```
    /// use specvar::spectrum::ClosedForm;
    /// // Jitter with 12 × 8 strata: white at k = (12, 0), zero power along no axis but DC.
    /// let jitter = ClosedForm::Jitter.on_lattice(96, 2, 24);
    /// assert!((jitter.power(&[12, 0]) - 1.0).abs() < 1e-15);
    /// assert!((jitter.power(&[0, 8]) - 1.0).abs() < 1e-15);
    /// assert!(jitter.power(&[1, 1]) < 0.1);
    /// assert_eq!(jitter.power(&[0, 0]), 96.0);
    /// ```
    pub fn on_lattice(self, n: usize, d: usize, kmax: usize) -> ClosedLattice {
        let axes = match self {
            ClosedForm::WhiteNoise => Vec::new(),
            ClosedForm::Jitter => {
                let cells: Vec<f64> = match strata(n, d) {
                    Some(cells) => cells.iter().map(|&m| m as f64).collect(),
                    None => vec![(n as f64).powf(1.0 / d as f64); d],
                };
                cells
                    .iter()
                    .map(|m| {
                        (0..=2 * kmax)
                            .map(|t| {
                                let s = sinc(PI * (t as f64 - kmax as f64) / m);
                                s * s
                            })
                            .collect()
                    })
                    .collect()
            }
        };
        ClosedLattice {
            form: self,
            n,
            kmax,
            axes,
        }
    }

    /// A short name: `white noise` or `jitter`.
    pub fn name(self) -> &'static str {
        match self {
            ClosedForm::WhiteNoise => "white noise",
            ClosedForm::Jitter => "jitter",
        }
    }

    /// The limit of the radial spectrum at `ν → 0⁺`.
    pub fn dc_limit(self) -> f64 {
        match self {
            ClosedForm::WhiteNoise => 1.0,
            ClosedForm::Jitter => 0.0,
        }
    }

    /// The radial spectrum: the mean of [`power`](Self::power) over the sphere `|ν| = nu` in
    /// dimension `d` (1 to 3), by Gauss–Legendre panels over one symmetry sector.
    pub fn radial(self, d: usize, nu: f64) -> f64 {
        match self {
            ClosedForm::WhiteNoise => 1.0,
            ClosedForm::Jitter => jitter_radial(d, nu),
        }
    }
}

/// A closed-form spectrum tabulated for one N on the lattice `|k_i| ≤ K`: evaluating it costs a
/// product of table entries, no trigonometric call and no allocation.
#[derive(Debug, Clone, PartialEq)]
pub struct ClosedLattice {
    form: ClosedForm,
    n: usize,
    kmax: usize,
    /// Jitter: `sinc²(π k / m_a)` for `k = -K..=K`, per axis.
    axes: Vec<Vec<f64>>,
}

impl ClosedLattice {
    /// The form.
    pub fn form(&self) -> ClosedForm {
        self.form
    }

    /// `E[P_S(k)]` at an integer frequency with `|k_i| ≤ K` (`N` at `k = 0`).
    ///
    /// # Panics
    /// If a component of `k` exceeds the lattice's `K`, like slice indexing.
    #[inline]
    pub fn power(&self, k: &[i64]) -> f64 {
        if k.iter().all(|&c| c == 0) {
            return self.n as f64;
        }
        match self.form {
            ClosedForm::WhiteNoise => 1.0,
            ClosedForm::Jitter => {
                let offset = self.kmax as i64;
                1.0 - k
                    .iter()
                    .zip(&self.axes)
                    .map(|(&c, table)| table[(c + offset) as usize])
                    .product::<f64>()
            }
        }
    }
}

/// Angular mean of the jitter spectrum. The integrand oscillates about `ν` times per sector,
/// so the panel count grows with `ν`.
fn jitter_radial(d: usize, nu: f64) -> f64 {
    if nu == 0.0 {
        return 0.0;
    }
    let f = |v: &[f64]| ClosedForm::Jitter.power(v);
    let panels = 2 + (2.0 * nu).ceil() as usize;
    let rule = GaussLegendre::new(12);
    match d {
        1 => f(&[nu]),
        2 => {
            // 8-fold symmetry: the mean over θ ∈ [0, π/4].
            let sector = PI / 4.0;
            let width = sector / panels as f64;
            let mut sum = 0.0;
            for p in 0..panels {
                let a = p as f64 * width;
                sum += rule.integrate(a, a + width, |t| f(&[nu * t.cos(), nu * t.sin()]));
            }
            sum / sector
        }
        _ => {
            // One octant: φ ∈ [0, π/2], u = cos θ ∈ [0, 1], uniform measure dφ du.
            let (wp, wu) = (PI / 2.0 / panels as f64, 1.0 / panels as f64);
            let mut sum = 0.0;
            for i in 0..panels {
                for j in 0..panels {
                    let (a, b) = (i as f64 * wp, j as f64 * wu);
                    sum += rule.integrate(a, a + wp, |phi| {
                        rule.integrate(b, b + wu, |u| {
                            let s = (1.0 - u * u).max(0.0).sqrt();
                            f(&[nu * s * phi.cos(), nu * s * phi.sin(), nu * u])
                        })
                    });
                }
            }
            sum / (PI / 2.0)
        }
    }
}
