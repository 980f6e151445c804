//! `specvar mc`: the Monte Carlo variance of the estimator, with a 99% interval.

use super::problem::{ProblemArgs, Source};
use specvar::montecarlo::{empirical_variances, empirical_variances_of_sets, McParams, McResult};
use specvar::randomization::Randomization;
use specvar::Result;

/// Arguments of `specvar mc`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sampler or point-set file, integrand, N and dimension.
    #[command(flatten)]
    pub problem: ProblemArgs,
    /// Estimator evaluations (for costly samplers: a pool of patterns × shifts).
    #[arg(long, short = 't', default_value_t = 10000)]
    pub trials: usize,
    /// Random shifts per pattern (default: the sampler's pool; with --input, trials / sets).
    #[arg(long)]
    pub shifts: Option<usize>,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Use the patterns as drawn: the same as --randomization none.
    #[arg(long, conflicts_with = "randomization")]
    pub fixed: bool,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// Runs Monte Carlo and prints the variance with its interval.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let (source, f, n) = args.problem.build(ctx)?;
    let bars = super::bars::Bars::default();
    let stage = format!("monte carlo: {}", source.label());
    let randomization = match args.fixed {
        true => Randomization::None,
        false => source.randomization(args.problem.randomization),
    };
    if let Some(shifts) = args.shifts.filter(|&s| s > args.trials) {
        return Err(specvar::Error::InvalidParameter {
            name: "shifts",
            value: shifts.to_string(),
            allowed: format!(
                "at most --trials ({}): every pattern's shifts are trials of the run",
                args.trials
            ),
        });
    }
    let result = match &source {
        Source::Sampler(kind, sampler) => {
            let params = McParams {
                budget: ctx.budget,
                ..McParams::for_sampler(*kind, args.trials, args.shifts, args.seed, randomization)
            };
            specvar::progress::Progress::begin(&bars, &stage, params.patterns as u64);
            empirical_variances(sampler.as_ref(), &[f.as_ref()], n, &params, &bars)
        }
        Source::Sets(_, sets) => {
            let params = McParams {
                budget: ctx.budget,
                ..McParams::for_sets(
                    sets.len(),
                    args.trials,
                    args.shifts,
                    args.seed,
                    randomization,
                )
            };
            specvar::progress::Progress::begin(&bars, &stage, sets.len() as u64);
            empirical_variances_of_sets(sets, &[f.as_ref()], &params, &bars)
        }
    };
    specvar::progress::Progress::end(&bars);
    let r = result?.remove(0);
    if args.json {
        outln!(
            "{}",
            super::to_json(&Doc {
                sampler: source.label(),
                integrand: f.label(),
                result: &r
            })?
        )?;
        return Ok(());
    }
    let how = r.randomization.estimator();
    let units = if r.shifts > 1 {
        format!("{} patterns × {} shifts", r.patterns, r.shifts)
    } else {
        format!("{} trials", r.trials)
    };
    outln!(
        "{} ({how}), N = {}, {units} on {}",
        source.label(),
        r.n,
        f.label()
    )?;
    outln!(
        "variance {:.6e}, 99% interval [{:.6e}, {:.6e}] ({:?})",
        r.variance,
        r.ci_low,
        r.ci_high,
        r.interval
    )?;
    outln!("bias     {:.3e} ± {:.1e}", r.bias, r.bias_stderr)?;
    Ok(())
}

#[derive(serde::Serialize)]
struct Doc<'a> {
    sampler: String,
    integrand: String,
    #[serde(flatten)]
    result: &'a McResult,
}
