//! `specvar atlas`: every 2D sampler on one page.

use specvar::atlas::{compute_atlas, write_atlas, AtlasConfig};
use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::report::DEFAULT_SEED;
use specvar::sampler::SamplerKind;
use specvar::Result;
use std::path::PathBuf;

/// Arguments of `specvar atlas`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output directory: specvar's earlier atlas there is replaced once the new one is
    /// complete; other files stay.
    #[arg(long, default_value = "atlas")]
    pub out: PathBuf,
    /// The short run (16 patterns, α at N = 1024, 4000 Monte Carlo evaluations).
    #[arg(long)]
    pub quick: bool,
    /// Points per pattern (the nearest valid count for samplers with a count rule).
    #[arg(short = 'n', default_value_t = 256)]
    pub n: usize,
    /// Samplers, comma-separated (default: every 2D sampler).
    #[arg(long, value_delimiter = ',')]
    pub samplers: Vec<SamplerKind>,
    /// Seed.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
    /// How each pattern is randomized, for the predictions and the Monte Carlo alike: shift
    /// (the default: the homogenized estimator, whose rate the spectrum's α gives), native
    /// (each sampler as it is used: strata and nets as drawn, fixed rules shifted),
    /// digital-shift, or none (the patterns as drawn).
    #[arg(long, default_value_t = RandomizationChoice::Given(Randomization::Shift))]
    pub randomization: RandomizationChoice,
}

/// Computes and writes the atlas, then prints its summary.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let mut config = if args.quick {
        AtlasConfig::quick(args.seed)
    } else {
        AtlasConfig::full(args.seed)
    };
    config.n = args.n;
    config.randomization = args.randomization;
    config.check()?;
    if !args.samplers.is_empty() {
        if let Some(k) = args.samplers.iter().find(|k| !k.dimensions().contains(&2)) {
            return Err(specvar::Error::UnsupportedDimension {
                sampler: k.name(),
                dimension: 2,
                supported: format!("{:?}", k.dimensions()),
            });
        }
        config.samplers = args.samplers.clone();
    }
    config.cache = ctx.cache.clone();
    config.budget = ctx.budget;
    specvar::output::check_output_dir(&args.out)?;
    let start = std::time::Instant::now();
    let atlas = compute_atlas(&config, &super::bars::Bars::default())?;
    write_atlas(&atlas, &args.out)?;
    let rows: Vec<_> = atlas.entries.iter().flat_map(|e| &e.rows).collect();
    let predicted = rows.iter().filter(|r| r.predicted.is_some()).count();
    let agreeing = rows.iter().filter(|r| r.agrees() == Some(true)).count();
    outln!(
        "atlas of {} samplers written to {}/atlas.md in {:.0} s: {agreeing} of {predicted} \
         predictions inside Monte Carlo's 99% interval{}",
        atlas.entries.len(),
        args.out.display(),
        start.elapsed().as_secs_f64(),
        match (
            rows.iter()
                .filter(|r| r.predicted.is_none() && r.measured.is_some())
                .count(),
            rows.iter().filter(|r| r.measured.is_none()).count(),
        ) {
            (0, 0) => String::new(),
            (k, 0) => format!(" ({k} measured without a route)"),
            (0, fixed) => format!(
                " ({fixed} of fixed patterns as drawn, biased, neither predicted nor measured)"
            ),
            (k, fixed) => format!(
                " ({k} measured without a route; {fixed} of fixed patterns as drawn, biased, \
                 neither predicted nor measured)"
            ),
        }
    )?;
    Ok(())
}
