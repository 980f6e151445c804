//! `specvar report`, and the main job (`specvar` with no subcommand): the reproduction report.

use specvar::report::{compute, write, ReportConfig, DEFAULT_SEED};
use specvar::Result;
use std::path::PathBuf;

/// Arguments of `specvar report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output directory: specvar's earlier report there is replaced once the new one is
    /// complete; other files stay.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    /// The short run.
    #[arg(long)]
    pub quick: bool,
    /// Seed.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
}

impl Default for Args {
    fn default() -> Self {
        Self {
            out: PathBuf::from("report"),
            quick: false,
            seed: DEFAULT_SEED,
        }
    }
}

/// Computes and writes the report, then prints its rate table and any failed check.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let mut config = if args.quick {
        ReportConfig::quick(args.seed)
    } else {
        ReportConfig::full(args.seed)
    };
    config.set_cache(ctx.cache.clone());
    config.set_budget(ctx.budget);
    specvar::output::check_output_dir(&args.out)?;
    let start = std::time::Instant::now();
    let report = compute(&config, &super::bars::Bars::default())?;
    write(&report, &args.out)?;
    outln!(
        "report written to {}/report.md in {:.0} s: {} of {} cross-checks passed",
        args.out.display(),
        start.elapsed().as_secs_f64(),
        report.passed(),
        report.checks.len()
    )?;
    outln!(
        "{:<8} {:<9} {:>7} {:>10} {:>12}",
        "sampler",
        "integrand",
        "theory",
        "predicted",
        "Monte Carlo"
    )?;
    for (row, series) in report.study.rows.iter().zip(&report.study.series) {
        outln!(
            "{:<8} {:<9} {:>7} {:>10.3} {:>12.3}",
            row.sampler,
            series.integrand.kind(),
            specvar::rate::theory_text(row.theory_rate, 2),
            row.predicted_rate.slope,
            row.empirical_rate.slope
        )?;
    }
    for c in report.checks.iter().filter(|c| !c.pass) {
        outln!("FAIL {}: {}", c.what, c.detail)?;
    }
    Ok(())
}
