//! `specvar bias`: the bias of a fixed (not homogenized) pattern, from its spectrum and directly.

use specvar::integrand::IntegrandSpec;
use specvar::predict::sampler_bias;
use specvar::sampler::SamplerKind;
use specvar::Result;

/// Arguments of `specvar bias`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sampler (fixed, not homogenized); `regular` uses its exact spectrum.
    #[arg(long, short = 's', default_value = "regular")]
    pub sampler: SamplerKind,
    // The forms are the library's own list, as in `predict`.
    #[arg(long, short = 'f', default_value = "gaussian", help = format!("Integrand: {}", specvar::integrand::INTEGRAND_FORMS))]
    pub integrand: IntegrandSpec,
    /// Points.
    #[arg(short = 'n')]
    pub n: usize,
    /// Dimension (1 to 3).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Seed of a randomized fixed pattern (realization 0).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Largest frequency per axis for patterns without a closed-form spectrum.
    #[arg(long, default_value_t = 64)]
    pub kmax: usize,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize)]
struct Doc {
    sampler: SamplerKind,
    integrand: String,
    n: usize,
    dimension: usize,
    /// μ_N - I, exactly.
    bias: f64,
    bias_direct: f64,
    bias_spectral: f64,
    remainder: f64,
    terms: usize,
    method: String,
}

/// Computes the bias exactly and as a spectral sum, and prints both.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let f = args.integrand.build(args.dimension)?;
    let (b, method) = sampler_bias(
        args.sampler,
        f.as_ref(),
        args.n,
        args.seed,
        args.kmax,
        &ctx.budget,
    )?;
    let doc = Doc {
        sampler: args.sampler,
        integrand: f.label(),
        n: args.n,
        dimension: args.dimension,
        bias: b.bias,
        bias_direct: b.bias,
        bias_spectral: b.spectral,
        remainder: b.remainder,
        terms: b.terms,
        method: method.to_string(),
    };
    if args.json {
        outln!("{}", super::to_json(&doc)?)?;
    } else {
        outln!(
            "bias of the fixed {} pattern, N = {}, on {}",
            doc.sampler,
            doc.n,
            doc.integrand
        )?;
        outln!("μ_N - I (exact):        {:.9e}", b.bias)?;
        outln!(
            "spectral sum:           {:.9e} ({method}, {} terms)",
            b.spectral,
            b.terms
        )?;
        outln!("left by the truncation: {:.3e}", b.remainder)?;
    }
    Ok(())
}
