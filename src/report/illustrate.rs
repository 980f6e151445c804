//! The talk's 1D illustrations, computed: a regular pattern's spectrum and its replicas, an
//! integrand's spectrum, and the integration error as the replicas reach DC when N falls.

use crate::error::Result;
use crate::integrand::{Gaussian, Integrand};
use crate::montecarlo::estimate_integral;
use crate::predict::regular_grid_bias;
use crate::sampler::{Regular, Sampler};
use crate::spectrum::{periodogram, Engine};
use serde::Serialize;

/// The numbers behind the 1D figures.
#[derive(Debug, Clone, Serialize)]
pub struct Illustration {
    /// Points of the regular grid whose spectrum is shown.
    pub grid_n: usize,
    /// `(k, P_S(k))` of that grid for `|k| ≤ 48`: `N` at multiples of N (the replicas), 0 else.
    pub grid_spectrum: Vec<(i64, f64)>,
    /// The integrand.
    pub integrand: String,
    /// `(k, |f̂(k)|²)` on a fine grid of real `|k| ≤ 24` (beyond, below 1e-16 of the peak).
    pub integrand_spectrum: Vec<(f64, f64)>,
    /// `(N, error from the spectrum Σ f̂(Nq)* Ŝ(Nq), error μ_N - I measured directly)`.
    pub errors: Vec<(usize, f64, f64)>,
}

/// Computes the illustration: a cell-centred grid of 8 points and a Gaussian of σ = 0.05.
///
/// # Errors
/// Never for these fixed parameters; propagated from the library otherwise.
pub fn compute() -> Result<Illustration> {
    let grid_n = 8;
    let grid = Regular::new(1)?.sample(grid_n, 0, 0)?;
    let kmax = 48;
    let p = periodogram(&grid, kmax, Engine::Direct)?;
    let grid_spectrum = p
        .iter()
        .enumerate()
        .map(|(i, &v)| (i as i64 - kmax as i64, v))
        .collect();
    let f = Gaussian::new(0.05, vec![0.5], 1.0)?;
    let integrand_spectrum = (0..=240)
        .map(|i| {
            let k = -24.0 + 0.2 * i as f64;
            (k, f.fourier(&[k]).norm_sqr())
        })
        .collect();
    let mut errors = Vec::new();
    for n in [2usize, 3, 4, 5, 6, 8, 10, 12, 16] {
        let (spectral, _) = regular_grid_bias(&f, n)?;
        let points = Regular::new(1)?.sample(n, 0, 0)?;
        errors.push((n, spectral, estimate_integral(&f, &points) - f.integral()));
    }
    Ok(Illustration {
        grid_n,
        grid_spectrum,
        integrand: f.label(),
        integrand_spectrum,
        errors,
    })
}
