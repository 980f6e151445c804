//! Closed-form expected power spectra: white noise, jitter, Gaussian jitter, Latin hypercube,
//! the regular grid, rank-1 lattices and Kronecker sequences.

use super::strata;
use crate::pointset::MAX_DIMENSION;
use crate::quadrature::GaussLegendre;
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

/// A sampler whose expected power spectrum (homogenized) is known exactly.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ClosedForm {
    /// `E[P_S(k)] = 1` for every `k ≠ 0`.
    WhiteNoise,
    /// Jittered sampling with strata `m_i` per axis: `E[P_S(k)] = 1 - Π_i sinc²(π k_i / m_i)`.
    Jitter,
    /// Latin hypercube with N strata per axis: `E[P_S(k)] = 1 + (N - 1) Π_i g(k_i)` with
    /// `g(0) = 1` and `g(k) = -sinc²(πk/N)/(N - 1)`: along an axis `1 - sinc²(πk/N)` (1D jitter
    /// of N strata), off the axes `1 + sinc² sinc² / (N - 1)` in 2D.
    LatinHypercube,
    /// The cell-centred regular grid with strata `m_i`, homogenized: `N` on the replicas
    /// `k ∈ m Z^d`, 0 elsewhere.
    RegularGrid,
    /// Gaussian jitter of `width` strata (standard deviation) on the grid of strata `m_i`:
    /// `E[P_S(k)] = 1 - φ² + N φ² [k ∈ m Z^d]` with `φ = Π_i exp(-2π² w² k_i² / m_i²)`.
    GaussianJitter {
        /// The offsets' standard deviation, in strata.
        width: f64,
    },
    /// The 2D rank-1 lattice `x_i = frac(i (1, a) / N)`, homogenized: `N` on its dual lattice
    /// `k_0 + a k_1 ≡ 0 (mod N)`, 0 elsewhere.
    Rank1Lattice {
        /// The second component `a` of the generating vector `(1, a)`.
        generator: u64,
    },
    /// The Kronecker sequence `x_i = frac(i α)`, `i < N`, homogenized: with `t = k·α`,
    /// `E[P_S(k)] = sin²(π N t) / (N sin²(π t))`, the Fejér kernel.
    Kronecker {
        /// Each component of `α` as a 64-bit binary fraction, `α_j = alpha[j] / 2^64`
        /// (components beyond the dimension are 0).
        alpha: [u64; MAX_DIMENSION],
    },
}

/// Bounds on `|E[P_S(k)] - 1|` outside a lattice `|k_i| ≤ K`: on the axis lines and elsewhere.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TailDeviation {
    /// On the axis lines `k = k_a e_a`, `|k_a| > K`.
    pub axis: f64,
    /// At every other frequency outside the lattice.
    pub off_axis: f64,
}

impl ClosedForm {
    /// Whether the form is a function of `ν = k / N^{1/d}` alone (white noise and square
    /// jitter), so that it has a radial form for the polar form.
    pub fn is_scale_invariant(self) -> bool {
        matches!(self, ClosedForm::WhiteNoise | ClosedForm::Jitter)
    }

    /// The expected spectrum at scaled frequency `ν = k / N^{1/d}` (a vector), `ν ≠ 0`, for the
    /// scale-invariant forms; `None` for the others, whose spectrum depends on N itself.
    ///
    /// # Examples
    /// ```
    /// use specvar::spectrum::ClosedForm;
    /// // Jitter is white at non-zero multiples of m along an axis…
    /// assert!((ClosedForm::Jitter.power(&[1.0, 0.0]).unwrap() - 1.0).abs() < 1e-15);
    /// // …and rises like π²|ν|²/3 from zero at DC.
    /// let nu = [0.01, 0.02];
    /// let expected = std::f64::consts::PI.powi(2) * (0.01f64.powi(2) + 0.02f64.powi(2)) / 3.0;
    /// assert!((ClosedForm::Jitter.power(&nu).unwrap() / expected - 1.0).abs() < 1e-3);
    /// assert_eq!(ClosedForm::WhiteNoise.power(&[0.3, 0.1]), Some(1.0));
    /// assert_eq!(ClosedForm::LatinHypercube.power(&[0.3, 0.1]), None);
    /// ```
    pub fn power(self, nu: &[f64]) -> Option<f64> {
        match self {
            ClosedForm::WhiteNoise => Some(1.0),
            ClosedForm::Jitter => Some(
                1.0 - nu
                    .iter()
                    .map(|v| {
                        let s = sinc(PI * v);
                        s * s
                    })
                    .product::<f64>(),
            ),
            _ => None,
        }
    }

    /// This form for an `n`-point pattern on the lattice `|k_i| ≤ kmax` in dimension `d`, with
    /// its per-axis factors tabulated once (see [`ClosedLattice`]).
    ///
    /// # Examples
    /// ```
    /// use specvar::spectrum::ClosedForm;
    /// // Jitter with 12 × 8 strata: white at k = (12, 0) and (0, 8), deep near DC.
    /// let jitter = ClosedForm::Jitter.on_lattice(96, 2, 24);
    /// assert!((jitter.power(&[12, 0]) - 1.0).abs() < 1e-15);
    /// assert!((jitter.power(&[0, 8]) - 1.0).abs() < 1e-15);
    /// assert!(jitter.power(&[1, 1]) < 0.1);
    /// assert_eq!(jitter.power(&[0, 0]), 96.0);
    /// // Latin hypercube: 1D jitter of N strata along the axes, nearly white elsewhere.
    /// let lhs = ClosedForm::LatinHypercube.on_lattice(64, 2, 8);
    /// assert!(lhs.power(&[3, 0]) < 0.03 && (lhs.power(&[3, 2]) - 1.0).abs() < 0.02);
    /// ```
    pub fn on_lattice(self, n: usize, d: usize, kmax: usize) -> ClosedLattice {
        let cells: Vec<f64> = match self {
            ClosedForm::LatinHypercube => vec![n as f64; d],
            _ => match strata(n, d) {
                Some(cells) => cells.iter().map(|&m| m as f64).collect(),
                None => vec![(n as f64).powf(1.0 / d as f64); d],
            },
        };
        let table = |f: &dyn Fn(f64, f64) -> f64| -> Vec<Vec<f64>> {
            cells
                .iter()
                .map(|&m| {
                    (0..=2 * kmax)
                        .map(|t| f(t as f64 - kmax as f64, m))
                        .collect()
                })
                .collect()
        };
        let sinc2 = |k: f64, m: f64| sinc(PI * k / m).powi(2);
        let on_replica = |k: f64, m: f64| (k / m).fract() == 0.0;
        let mut replicas = Vec::new();
        let axes = match self {
            ClosedForm::WhiteNoise
            | ClosedForm::Rank1Lattice { .. }
            | ClosedForm::Kronecker { .. } => Vec::new(),
            ClosedForm::GaussianJitter { width } => {
                let phi2 =
                    move |k: f64, m: f64| (-4.0 * PI * PI * width * width * k * k / (m * m)).exp();
                replicas = table(&|k: f64, m: f64| if on_replica(k, m) { phi2(k, m) } else { 0.0 });
                table(&phi2)
            }
            ClosedForm::Jitter => table(&sinc2),
            ClosedForm::LatinHypercube => {
                let scale = (n as f64 - 1.0).max(1.0);
                table(&|k: f64, m: f64| if k == 0.0 { 1.0 } else { -sinc2(k, m) / scale })
            }
            ClosedForm::RegularGrid => {
                table(&|k: f64, m: f64| if on_replica(k, m) { 1.0 } else { 0.0 })
            }
        };
        ClosedLattice {
            form: self,
            n,
            kmax,
            cells,
            axes,
            replicas,
        }
    }

    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            ClosedForm::WhiteNoise => "white noise",
            ClosedForm::Jitter => "jitter",
            ClosedForm::LatinHypercube => "Latin hypercube",
            ClosedForm::RegularGrid => "regular grid",
            ClosedForm::GaussianJitter { .. } => "Gaussian jitter",
            ClosedForm::Rank1Lattice { .. } => "rank-1 lattice",
            ClosedForm::Kronecker { .. } => "Kronecker sequence",
        }
    }

    /// The limit of the radial spectrum at `ν → 0⁺` (scale-invariant forms; else `None`).
    pub fn dc_limit(self) -> Option<f64> {
        match self {
            ClosedForm::WhiteNoise => Some(1.0),
            ClosedForm::Jitter => Some(0.0),
            _ => None,
        }
    }

    /// The radial spectrum: the mean of [`power`](Self::power) over the sphere `|ν| = nu` in
    /// dimension `d` (1 to 3), by Gauss–Legendre panels over one symmetry sector; `None` for
    /// the forms that are not scale invariant.
    pub fn radial(self, d: usize, nu: f64) -> Option<f64> {
        match self {
            ClosedForm::WhiteNoise => Some(1.0),
            ClosedForm::Jitter => Some(jitter_radial(d, nu)),
            _ => None,
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
    /// Strata per axis.
    cells: Vec<f64>,
    /// Per axis, for `k = -K..=K`: jitter `sinc²(π k / m)`; Latin hypercube `g(k)`; regular
    /// grid 1 on the replicas; Gaussian jitter `φ²`.
    axes: Vec<Vec<f64>>,
    /// Gaussian jitter only: per axis `φ²` on the replicas, 0 elsewhere.
    replicas: Vec<Vec<f64>>,
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
        let offset = self.kmax as i64;
        let product = |tables: &[Vec<f64>]| {
            k.iter()
                .zip(tables)
                .map(|(&c, table)| table[(c + offset) as usize])
                .product::<f64>()
        };
        let n = self.n as f64;
        match self.form {
            ClosedForm::WhiteNoise => 1.0,
            ClosedForm::Jitter => 1.0 - product(&self.axes),
            ClosedForm::LatinHypercube => 1.0 + (n - 1.0) * product(&self.axes),
            ClosedForm::RegularGrid => n * product(&self.axes),
            ClosedForm::GaussianJitter { .. } => {
                1.0 - product(&self.axes) + n * product(&self.replicas)
            }
            ClosedForm::Rank1Lattice { generator } => {
                let residue =
                    (k[0] as i128 + generator as i128 * k[1] as i128).rem_euclid(n as i128);
                if residue == 0 {
                    n
                } else {
                    0.0
                }
            }
            ClosedForm::Kronecker { alpha } => {
                let phase = k.iter().zip(alpha).fold(0u64, |t, (&c, a)| {
                    t.wrapping_add((c as u64).wrapping_mul(a))
                });
                fejer(self.n as u64, phase)
            }
        }
    }

    /// Bounds on `|E[P_S(k)] - 1|` outside the lattice, or `None` for the regular grid, rank-1
    /// lattices and Kronecker sequences, whose peaks (power up to N) continue beyond any
    /// lattice.
    ///
    /// Jitter: outside the lattice some `|k_i| > K`, so `1 - P = Π sinc² ≤ (m_i/(πK))²`. Latin
    /// hypercube: on an axis `1 - P = sinc²(πk/N) ≤ min(1, (N/(πK))²)`; elsewhere
    /// `|P - 1| ≤ 1/(N - 1)` (two non-zero components) or `1/(N - 1)²` (three). Gaussian
    /// jitter: outside the lattice some `|k_i| ≥ K + 1`, so `φ² ≤ exp(-4π² w² (K+1)² / m²)`
    /// with `m` the widest strata, and `|P - 1| ≤ max(1, N - 1) φ²` (on a replica
    /// `P - 1 = (N - 1) φ²`, elsewhere `-φ²`).
    pub fn tail_deviation(&self) -> Option<TailDeviation> {
        let k = self.kmax.max(1) as f64;
        let widest = self.cells.iter().fold(0.0f64, |a, &m| a.max(m));
        match self.form {
            ClosedForm::WhiteNoise => Some(TailDeviation {
                axis: 0.0,
                off_axis: 0.0,
            }),
            ClosedForm::Jitter => {
                let delta = (widest / (PI * k)).powi(2).min(1.0);
                Some(TailDeviation {
                    axis: delta,
                    off_axis: delta,
                })
            }
            ClosedForm::LatinHypercube => Some(TailDeviation {
                axis: (self.n as f64 / (PI * k)).powi(2).min(1.0),
                off_axis: 1.0 / (self.n as f64 - 1.0).max(1.0),
            }),
            ClosedForm::GaussianJitter { width } => {
                let phi2 =
                    (-4.0 * PI * PI * width * width * (k + 1.0).powi(2) / (widest * widest)).exp();
                let delta = ((self.n as f64 - 1.0).max(1.0) * phi2).min(self.n as f64);
                Some(TailDeviation {
                    axis: delta,
                    off_axis: delta,
                })
            }
            ClosedForm::RegularGrid
            | ClosedForm::Rank1Lattice { .. }
            | ClosedForm::Kronecker { .. } => None,
        }
    }
}

/// The Fejér kernel `sin²(π N t) / (N sin²(π t))` at `t = phase / 2^64`: the power spectrum of
/// `N` consecutive points of a Kronecker sequence. Both phases are reduced exactly in 64-bit
/// fixed point (`N t mod 1` by a wrapping product), so the sines see arguments in `[-π/2, π/2)`.
pub fn fejer(n: u64, phase: u64) -> f64 {
    if phase == 0 {
        return n as f64;
    }
    let angle = |fraction: u64| PI * (fraction as i64) as f64 / 2f64.powi(64);
    let numerator = libm::sin(angle(phase.wrapping_mul(n)));
    let denominator = libm::sin(angle(phase));
    numerator * numerator / (n as f64 * denominator * denominator)
}

/// Angular mean of the jitter spectrum. The integrand oscillates about `ν` times per sector,
/// so the panel count grows with `ν`.
fn jitter_radial(d: usize, nu: f64) -> f64 {
    if nu == 0.0 {
        return 0.0;
    }
    // One rule for every call: a study evaluates this at thousands of radii.
    static RULE: std::sync::OnceLock<GaussLegendre> = std::sync::OnceLock::new();
    let rule = RULE.get_or_init(|| GaussLegendre::new(12));
    let f = |v: &[f64]| ClosedForm::Jitter.power(v).unwrap_or(1.0);
    let panels = 2 + (2.0 * nu).ceil() as usize;
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
            // One octant: φ ∈ [0, π/2], u = cos θ ∈ [0, 1], uniform measure dφ du. The power
            // is 1 − Π_i sinc²(π ν_i): the third axis's factor depends on u alone, and the φ
            // nodes' cosines and sines are the same for every u, so each is taken once.
            let (wp, wu) = (PI / 2.0 / panels as f64, 1.0 / panels as f64);
            let axis = |v: f64| sinc(PI * v).powi(2);
            let phis: Vec<(f64, f64, f64)> = (0..panels)
                .flat_map(|i| rule.on(i as f64 * wp, (i + 1) as f64 * wp))
                .map(|(phi, w)| (w, phi.cos(), phi.sin()))
                .collect();
            let mut sum = 0.0;
            for j in 0..panels {
                for (u, w_u) in rule.on(j as f64 * wu, (j + 1) as f64 * wu) {
                    let s = (1.0 - u * u).max(0.0).sqrt();
                    let z = axis(nu * u);
                    let ring: f64 = phis
                        .iter()
                        .map(|&(w, c, sn)| w * (1.0 - axis(nu * s * c) * axis(nu * s * sn) * z))
                        .sum();
                    sum += w_u * ring;
                }
            }
            sum / (PI / 2.0)
        }
    }
}
