//! `specvar bias`: the bias of a fixed (not homogenized) pattern, from its spectrum and directly.

use specvar::integrand::IntegrandSpec;
use specvar::montecarlo::estimate_integral;
use specvar::predict::{bias_of_pattern, regular_grid_bias};
use specvar::sampler::SamplerKind;
use specvar::Result;

/// Arguments of `specvar bias`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sampler (fixed, not homogenized); `regular` uses its exact spectrum.
    #[arg(long, short = 's', default_value = "regular")]
    pub sampler: SamplerKind,
    /// Integrand spec.
    #[arg(long, short = 'f', default_value = "gaussian")]
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
    bias: f64,
    bias_direct: f64,
    method: &'static str,
    truncation: Option<f64>,
}

/// Computes and prints the bias both ways.
pub fn run(args: &Args) -> Result<()> {
    let f = args.integrand.build(args.dimension)?;
    // One fixed pattern serves both the spectral bias and the direct check.
    let points = args
        .sampler
        .build(args.dimension)?
        .sample(args.n, args.seed, 0)?;
    let (bias, truncation, method) = if args.sampler == SamplerKind::Regular {
        let (b, t) = regular_grid_bias(f.as_ref(), args.n)?;
        (b, Some(t), "exact regular-grid spectrum")
    } else {
        let b = bias_of_pattern(f.as_ref(), &points, args.kmax)?;
        (b, None, "lattice sum over realization 0")
    };
    let direct = estimate_integral(f.as_ref(), &points) - f.integral();
    let doc = Doc {
        sampler: args.sampler,
        integrand: f.label(),
        n: args.n,
        dimension: args.dimension,
        bias,
        bias_direct: direct,
        method,
        truncation,
    };
    if args.json {
        println!("{}", super::to_json(&doc)?);
    } else {
        println!(
            "bias of the fixed {} pattern, N = {}, on {}",
            doc.sampler, doc.n, doc.integrand
        );
        println!("from its spectrum ({method}): {bias:.9e}");
        println!("direct (μ_N - I):              {direct:.9e}");
    }
    Ok(())
}
