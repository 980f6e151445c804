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
//! ## Example
//! ```
//! use specvar::sampler::{Homogenized, Jitter, Sampler};
//! let jitter = Homogenized::new(Jitter::new(2).unwrap());
//! let points = jitter.sample(64, 42, 0).unwrap();
//! assert_eq!(points.len(), 64);
//! ```

#![warn(missing_docs)]

pub mod cli;
pub mod error;
pub mod integrand;
pub mod io;
pub mod montecarlo;
pub mod plot;
pub mod pointset;
pub mod predict;
pub mod progress;
pub mod quadrature;
pub mod rate;
pub mod report;
pub mod rng;
pub mod sampler;
pub mod spectrum;

pub use error::{Error, Result};
pub use pointset::PointSet;
pub use sampler::{Sampler, SamplerKind};
