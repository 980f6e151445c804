//! `specvar padded`: the variance of a 4D integrand under two 2D patterns padded together.

use specvar::montecarlo::{McResult, Z_99};
use specvar::padded::{
    padded_monte_carlo, plan_padded, predict_padded, PaddedGrid, PaddedSamplers,
};
use specvar::plan::{PlanParams, Target};
use specvar::predict::PredictParams;
use specvar::randomization::RandomizationChoice;
use specvar::sampler::SamplerKind;
use specvar::Result;

/// Arguments of `specvar padded`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The 4D integrand: a .npy array (first height, first width, second height, second
    /// width) of cell values, f[ay, ax, by, bx].
    #[arg(long, short = 'f')]
    pub integrand: std::path::PathBuf,
    /// The first pair's sampler (e.g. the film's).
    #[arg(long, short = 's')]
    pub sampler: SamplerKind,
    /// The second pair's sampler (e.g. the light's; default: the first's).
    #[arg(long)]
    pub second: Option<SamplerKind>,
    /// Samples (points of each pattern).
    #[arg(short = 'n', required_unless_present = "rmse")]
    pub n: Option<usize>,
    /// Plan instead of predicting: the smallest balanced N whose predicted RMSE reaches this
    /// target (with --relative, relative to the integral).
    #[arg(long, conflicts_with_all = ["n", "mc"])]
    pub rmse: Option<f64>,
    /// Read --rmse as relative to the magnitude of the integral.
    #[arg(long, requires = "rmse")]
    pub relative: bool,
    /// How both patterns are randomized: native (each sampler as it is used), shift,
    /// digital-shift or none.
    #[arg(long, default_value = "native")]
    pub randomization: RandomizationChoice,
    /// Also measure the padded estimator by Monte Carlo with this many trials.
    #[arg(long)]
    pub mc: Option<usize>,
    /// What the grid's cells are: averages (a finer function's cell averages, as a renderer's
    /// sub-pixels are), samples (its values at the cells' centres) or exact (the grid is the
    /// function).
    #[arg(long, default_value = "averages")]
    pub tabulation: specvar::integrand::GridMeaning,
    /// Seed of the pattern pairs (prediction) and of the trials (Monte Carlo).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// JSON output: {"prediction": {"variance", "first", "second", "interaction", …},
    /// "measured": {…} or null}.
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize)]
struct Doc<'a> {
    prediction: &'a specvar::padded::PaddedPrediction,
    measured: Option<&'a McResult>,
}

/// Predicts (and with --mc measures) and prints.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let f = PaddedGrid::read(&args.integrand)?.with_meaning(args.tabulation);
    let first = ctx.sampler(args.sampler, 2)?;
    let second = ctx.sampler(args.second.unwrap_or(args.sampler), 2)?;
    let samplers = PaddedSamplers::new(first.as_ref(), second.as_ref(), args.randomization)?;
    let params = PredictParams {
        seed: args.seed,
        budget: ctx.budget,
        ..PredictParams::default()
    };
    let bars = super::bars::Bars::default();
    let n = match (args.rmse, args.n) {
        (Some(rmse), _) => return plan(args, &f, samplers, rmse, params, &bars),
        (None, Some(n)) => n,
        (None, None) => unreachable!("clap requires -n without --rmse"),
    };
    let p = predict_padded(&f, samplers, n, &params, &bars)?;
    let measured = args
        .mc
        .map(|trials| padded_monte_carlo(&f, samplers, n, trials, args.seed, &ctx.budget))
        .transpose()?;
    if args.json {
        let doc = Doc {
            prediction: &p,
            measured: measured.as_ref(),
        };
        return outln!("{}", super::to_json(&doc)?);
    }
    let [ah, aw, bh, bw] = f.shape();
    outln!(
        "padded estimator, N = {n}: {} ({}) on the first pair ({ah} × {aw} cells), {} ({}) on the second ({bh} × {bw})",
        first.name(),
        samplers.randomizations.0.estimator(),
        second.name(),
        samplers.randomizations.1.estimator()
    )?;
    outln!(
        "variance {:.4e} ± {:.2e} (99%)",
        p.variance,
        p.budget.half_width(Z_99)
    )?;
    outln!(
        "  first pair's marginal   {:.4e}  ({})",
        p.first.variance,
        p.first.route
    )?;
    outln!(
        "  second pair's marginal  {:.4e}  ({})",
        p.second.variance,
        p.second.route
    )?;
    outln!(
        "  interaction             {:.4e}  (‖h‖² = {:.4e}; as independent points ‖h‖²/N = {:.4e})",
        p.interaction,
        p.interaction_energy,
        p.interaction_white
    )?;
    if let Some(m) = measured {
        outln!(
            "measured {:.4e} [{:.4e}, {:.4e}] (99%, {} trials)",
            m.variance,
            m.ci_low,
            m.ci_high,
            m.patterns
        )?;
    }
    Ok(())
}

/// Plans the padded estimator's samples for `rmse` and prints the plan.
fn plan(
    args: &Args,
    f: &PaddedGrid,
    samplers: PaddedSamplers,
    rmse: f64,
    predict: PredictParams,
    bars: &super::bars::Bars,
) -> Result<()> {
    let target = Target::new(rmse, args.relative);
    let params = PlanParams {
        predict,
        ..PlanParams::new(target)
    };
    let p = plan_padded(f, samplers, &params, bars)?;
    if args.json {
        return outln!("{}", super::to_json(&p)?);
    }
    outln!(
        "padded plan for {target} (RMSE {:.4e}): N = {}, predicted RMSE {:.4e} [{:.4e}, {:.4e}] (99%)",
        p.target,
        p.n,
        p.rmse,
        p.rmse_interval.0,
        p.rmse_interval.1
    )?;
    if let Some(below) = p.below {
        outln!("below: N = {}, RMSE {:.4e}", below.n, below.rmse)?;
    }
    outln!(
        "{} predictions, N among {}; {}",
        p.predictions,
        p.counts,
        p.reason
    )
}
