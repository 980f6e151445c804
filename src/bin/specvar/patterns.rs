//! The arguments that name a set of patterns, shared by `spectrum` and `metrics`: a sampler's
//! realizations, or point sets read from a file.

use specvar::sampler::SamplerKind;
use std::path::PathBuf;

/// A sampler's first M realizations of a seed, or every realization in a file.
#[derive(Debug, clap::Args)]
pub struct PatternArgs {
    /// Sampler name (ignored with --input).
    #[arg(long, short = 's', default_value = "random")]
    pub sampler: SamplerKind,
    /// Points per pattern (ignored with --input).
    #[arg(short = 'n', default_value_t = 1024)]
    pub n: usize,
    /// Dimension, 1 to 3 (ignored with --input).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Realizations to average (ignored with --input: every realization in the file is used).
    #[arg(long, short = 'm', default_value_t = 16)]
    pub realizations: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Read point sets (UTK text or binary, or JSON) instead of sampling.
    #[arg(long)]
    pub input: Option<PathBuf>,
}
