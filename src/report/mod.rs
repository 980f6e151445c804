//! The reproduction report that `cargo run --release` writes, in three layers: [`model`] (what
//! was computed: plain data), [`compute`](mod@compute) (configuration to data through the public API, no
//! output) and `write` (Markdown, JSON and plots; with the `plot` feature).
//!
//! The report reproduces the seed talk's table in 2D from first principles: it estimates the
//! spectra of random, jitter, Poisson disk and CCVT, predicts the variance of Monte Carlo
//! integration of a disk and a Gaussian over a range of N, measures it by Monte Carlo, fits
//! rates, finds crossovers, renders ambient occlusion with every sampler, and checks every
//! prediction against its measurement.

pub mod compute;
pub mod coverage;
pub mod estimators;
pub mod model;
#[cfg(feature = "plot")]
mod write;

pub use compute::compute;
pub use coverage::{CoverageCase, CoverageConfig, CoverageRow, CoverageSection};
pub use estimators::{EstimatorRow, EstimatorsConfig, EstimatorsSection};
pub use model::{
    AmbientSection, Check, ClosureConfig, ClosureRow, ClosureTable, Crossover, EdgesConfig,
    EdgesSection, Illustration, PolarComparison, Report, ReportConfig, SeriesExtras, Timing,
    DEFAULT_SEED, TALK_SAMPLERS,
};
#[cfg(feature = "plot")]
pub use write::write;
