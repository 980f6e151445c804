//! `specvar rates`: the rate study (theory, predicted and Monte Carlo slopes), the same library
//! call the report makes.

use specvar::integrand::IntegrandSpec;
use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::rate::{rate_ns, run_study, StudyConfig};
use specvar::sampler::SamplerKind;
use specvar::Result;

/// Arguments of `specvar rates`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Dimension (1 to 3).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Comma-separated samplers (scale-invariant ones: random, jitter, poisson, bridson, ccvt).
    #[arg(long, value_delimiter = ',')]
    pub samplers: Option<Vec<SamplerKind>>,
    /// Comma-separated integrand specs (isotropic: disk, ball, gaussian with overrides).
    #[arg(long, value_delimiter = ',')]
    pub integrands: Option<Vec<IntegrandSpec>>,
    /// Smallest and largest N of the fit (about five N = m^d values in between, log-spaced).
    #[arg(long, num_args = 2)]
    pub range: Option<Vec<usize>>,
    /// Monte Carlo evaluations per N (pools for costly samplers).
    #[arg(long)]
    pub trials: Option<usize>,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// How each pattern is randomized, for the predictions and the Monte Carlo alike: shift
    /// (the default: the homogenized estimator of the talk's rates), native (each sampler as it
    /// is used: strata and nets as drawn, fixed rules shifted), digital-shift, or none (the
    /// patterns as drawn).
    #[arg(long, default_value_t = RandomizationChoice::Given(Randomization::Shift))]
    pub randomization: RandomizationChoice,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

impl Args {
    /// The study these arguments ask for: the library's defaults for what is not given.
    pub fn config(&self, ctx: &super::Context) -> StudyConfig {
        let defaults = StudyConfig::in_dimension(self.dimension);
        StudyConfig {
            samplers: self.samplers.clone().unwrap_or(defaults.samplers),
            integrands: self.integrands.clone().unwrap_or(defaults.integrands),
            ns: match self.range.as_deref() {
                Some(&[lo, hi]) => rate_ns(lo, hi, self.dimension),
                _ => defaults.ns,
            },
            trials: self.trials.unwrap_or(defaults.trials),
            seed: self.seed,
            randomization: self.randomization,
            predict: specvar::predict::PredictParams {
                budget: ctx.budget,
                ..defaults.predict
            },
            patterns_cache: ctx.cache.clone(),
            ..defaults
        }
    }
}

/// Runs the study and prints its rows.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let study = run_study(&args.config(ctx), &super::bars::Bars::default())?;
    if args.json {
        #[derive(serde::Serialize)]
        struct Doc<'a> {
            n_values: &'a [usize],
            randomization: RandomizationChoice,
            rows: &'a [specvar::rate::StudyRow],
        }
        let doc = Doc {
            n_values: &study.config.ns,
            randomization: study.config.randomization,
            rows: &study.rows,
        };
        outln!("{}", super::to_json(&doc)?)?;
        return Ok(());
    }
    outln!(
        "rates r in Var ∝ N^r over N = {:?}, d = {}, {} estimator ({})",
        study.config.ns,
        args.dimension,
        study.config.randomization.estimator(),
        study.config.randomization.per_trial()
    )?;
    outln!(
        "{:<8} {:<40} {:>12} {:>9} {:>10} {:>19} {:>6}",
        "sampler",
        "integrand",
        "theory",
        "predicted",
        "empirical",
        "99% interval",
        "alpha"
    )?;
    for r in &study.rows {
        outln!(
            "{:<8} {:<40} {:>12} {:>9.3} {:>10.3}   [{:>6.3}, {:>6.3}] {:>6.2}",
            r.sampler,
            r.integrand,
            specvar::rate::theory_text(r.theory_rate, 3),
            r.predicted_rate.slope,
            r.empirical_rate.slope,
            r.empirical_rate.ci.0,
            r.empirical_rate.ci.1,
            r.alpha,
        )?;
    }
    for r in study.rows.iter().filter(|r| r.floor_n.is_some()) {
        outln!(
            "{} on {}: fitted below N = {}, where the variance reaches the floor of double \
             precision",
            r.sampler,
            r.integrand,
            r.floor_n.unwrap_or_default()
        )?;
    }
    Ok(())
}
