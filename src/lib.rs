//! # specvar: Fourier analysis of Monte Carlo sampling
//!
//! specvar predicts the variance of Monte Carlo integration from power spectra and checks each
//! prediction against real Monte Carlo runs.
//!
//! ## The theory in a page
//!
//! The estimator of `I = ∫_{[0,1)^d} f` from `N` points is `μ_N = (1/N) Σ f(x_k)`, the integral
//! of `f` against the sampling function `S(x) = (1/N) Σ δ(x - x_k)`. On the unit torus, with
//! `f̂(k) = ∫ f(x) e^{-2πi k·x} dx` and `Ŝ(k) = (1/N) Σ e^{-2πi k·x_k}`,
//!
//! `μ_N - I = Σ_{k ≠ 0} f̂(k)* Ŝ(k)`:
//!
//! the error is the leakage of the sampling spectrum's replicas into the DC term. A random
//! toroidal shift of the whole pattern (homogenization, a Cranley–Patterson rotation) makes
//! `E[Ŝ(k)] = 0` for `k ≠ 0`, so the estimator is unbiased, and its variance is
//!
//! `Var[μ_N] = (1/N) Σ_{k ≠ 0} |f̂(k)|² E[P_S(k)]`, with `P_S(k) = N |Ŝ(k)|²`
//!
//! (the *lattice form*). White noise has `E[P_S] = 1`, which gives `(∫f² - I²)/N` by Parseval.
//! For isotropic spectra the sum becomes one radial integral (the *polar form*),
//!
//! `Var[μ_N] = (1/N) [ M(S^{d-1}) ∫_0^∞ ρ^{d-1} P̆_f(ρ) P̆_S(ρ / N^{1/d}) dρ - P̆_S(0⁺) I² ]`,
//!
//! where `M(S^{d-1}) = 2π^{d/2}/Γ(d/2)` is the sphere measure, `P̆` a radial (angular-mean)
//! spectrum, and the last term removes the DC frequency that the lattice sum leaves out.
//! Scale-invariant samplers have a spectrum that depends on `ν = ρ / N^{1/d}` only, so one
//! spectrum estimated at a reference N serves every N. If `P̆_S(ν) ≈ c ν^α` near 0 and
//! `P̆_f(ρ) ~ ρ^{-β}`, the variance falls like `N^{-1 - min(α, β - d)/d}`: jitter (α = 2) on a
//! disk (β = 3) in 2D converges as `N^{-1.5}`, on a Gaussian as `N^{-2}`.
//!
//! Renderers use other estimators, and each has its own exact analysis. Strata and
//! Owen-scrambled nets as drawn are uniform inside known cells, so their variance is a sum over
//! cells in space: the per-stratum form for jitter, closed pair sums for Latin hypercube and
//! multi-jitter, and Owen's gains times the integrand's variance at each dyadic level for
//! scrambled Sobol' (the *cell form*); the same gains averaged over random shifts give
//! scrambled Sobol' under the toroidal shift without truncating anything. A fixed net under a
//! random digital shift is a sum over
//! Walsh frequencies (the *Walsh form*), and a fixed pattern under the toroidal shift is
//! `(1/N²) Σ_{i,j} a_f(x_i − x_j) − I²` over its pairs. Every prediction names its estimator
//! (`docs/theory.md`, "The estimator").
//!
//! ## Map of the crate
//!
//! - [`sampler`]: nineteen samplers behind one [`Sampler`] trait, keyed by (seed, realization),
//!   from white noise to PMJ02, orthogonal arrays, rank-1 lattices and the Kronecker sequence;
//!   each states every fact about itself once, in its own file, as a
//!   [`sampler::SamplerFacts`] descriptor (N rule, randomness, native randomization, closed
//!   form, scale invariance, symmetry, cost), which [`SamplerKind`] reads.
//! - [`randomization`]: how a pattern is randomized before it integrates (a random shift, a
//!   digital shift, none), which decides the estimator a prediction and a Monte Carlo run are
//!   for.
//! - [`pointset`] and [`io`]: point sets and their files (UTK text and binary, JSON).
//! - [`spectrum`]: periodograms (direct and NUFFT engines, with caller-owned scratch), expected,
//!   radial and directional spectra, closed forms.
//! - [`metrics`]: discrepancies, the pair correlation function, nearest distances, the
//!   effective Nyquist frequency.
//! - [`integrand`]: balls, Gaussians, polygons and edges with closed-form transforms, and
//!   functions tabulated on a grid (images, text files) whose transforms come from an FFT;
//!   [`integrand::IntegrandKind`] and [`integrand::IntegrandSpec`] name them.
//! - [`predict`]: the one call [`predict::predict`] that chooses a valid route; the polar and
//!   lattice forms with the DC term; exact sums in space for lattices; the pair-correlation
//!   route; bias of fixed patterns.
//! - [`pixels`]: image-level predictions: every pixel of a stack of tabulated integrands
//!   (`.npy`), its variance, and the image's MSE.
//! - [`plan`]: how many samples: for each sampler, the smallest of its balanced counts whose
//!   predicted RMSE reaches a target, found along the predictions' own rate.
//! - [`padded`]: a 4D pixel (film × light) under two 2D patterns padded together, as
//!   renderers draw them: the two marginals on their routes and the interaction by the
//!   permutation identity; its plan.
//! - [`pilot`]: the same from a pilot (a few renders at a small count) instead of the pixels'
//!   integrands, carried to N by the sampler's predictions on discontinuities.
//! - [`anisotropy`]: the variance of an edge against its angle, and its rates against N.
//! - [`atlas`]: every 2D sampler on one page.
//! - [`montecarlo`]: empirical variance with 99% intervals, pools for costly samplers.
//! - [`rate`]: theoretical, predicted and measured convergence rates; the rate study.
//! - [`render`]: ambient occlusion rendered with every sampler, its measured MSE, and its MSE
//!   predicted from the pixels' visibility spectra by the lattice form.
//! - [`report`]: the reproduction report that `cargo run --release` writes.
//! - [`progress`], [`output`], [`cache`]: progress observers, atomic outputs, the cache
//!   directory.
//!
//! The `cli` feature (on by default) builds the `specvar` command line; without it the library
//! compiles no clap, indicatif or plotters (`default-features = false`; add `plot` for SVG
//! plots).
//!
//! ## Example: predict, then check
//! ```
//! use specvar::prelude::*;
//!
//! let disk = Ball::new(0.25, vec![0.5, 0.5], 1.0)?;
//! let jitter = Jitter::new(2)?;
//! // One call: the route, its reason and its error budget. Jitter is used as drawn (its native
//! // randomization), so the route is the per-stratum cell form, exact.
//! let problem = Problem::new(&jitter, &disk, 64)?;
//! let predicted = predict(&problem, &PredictParams::default())?;
//! assert_eq!(predicted.route.form, Form::Cells);
//! // Monte Carlo of the same estimator at N = 64.
//! let mc = McParams { patterns: 4000, randomization: problem.randomization, ..Default::default() };
//! let measured = empirical_variance(&jitter, &disk, 64, &mc)?;
//! let band = predicted.budget.half_width(3.0);
//! assert!(predicted.variance + band > measured.ci_low && predicted.variance - band < measured.ci_high);
//! # Ok::<(), specvar::Error>(())
//! ```

#![warn(missing_docs)]

pub mod anisotropy;
pub mod atlas;
pub mod budget;
pub mod cache;
pub mod costs;
mod crosscheck;
pub mod error;
pub mod integrand;
pub mod io;
pub mod metrics;
pub mod montecarlo;
pub mod npy;
pub mod output;
pub mod padded;
pub mod pilot;
pub mod pixels;
pub mod plan;
pub mod plot;
pub mod pointset;
pub mod predict;
pub mod progress;
pub mod quadrature;
pub mod randomization;
pub mod rate;
pub mod render;
pub mod report;
pub mod rng;
pub mod sampler;
pub mod spectrum;
mod spread;
mod vector_exp;

pub use error::{Error, Result};
pub use pointset::PointSet;
pub use sampler::{Sampler, SamplerKind};

/// The names most programs need: `use specvar::prelude::*;`.
pub mod prelude {
    pub use crate::error::{Error, Result};
    pub use crate::integrand::{
        parse_integrand, Ball, Gaussian, GridIntegrand, Integrand, IntegrandKind, IntegrandSpec,
    };
    pub use crate::montecarlo::{empirical_variance, McParams, McResult};
    pub use crate::pointset::PointSet;
    pub use crate::predict::{
        predict, predict_many, Form, PredictParams, Prediction, Problem, SpectrumChoice,
    };
    pub use crate::progress::{Progress, Silent};
    pub use crate::randomization::Randomization;
    pub use crate::rate::{run_study, StudyConfig};
    pub use crate::sampler::{
        Ccvt, CorrelatedMultiJitter, Halton, Homogenized, Jitter, LatinHypercube, PoissonDisk,
        Random, Regular, Sampler, SamplerKind, Sobol,
    };
    pub use crate::spectrum::{estimate, estimate_from_sets, SpectrumEstimate, SpectrumParams};
}
