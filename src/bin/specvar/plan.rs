//! `specvar plan`: for each sampler, the smallest N whose predicted RMSE reaches a target.

use specvar::integrand::IntegrandSpec;
use specvar::pilot::{plan_pilot, Pilot, PilotModel};
use specvar::pixels::PixelStack;
use specvar::plan::{
    default_samplers, plan_many, plan_pixels_many, Plan, PlanParams, Plans, Target,
};
use specvar::predict::PredictParams;
use specvar::randomization::RandomizationChoice;
use specvar::sampler::{Sampler, SamplerKind};
use specvar::Result;

/// Arguments of `specvar plan`.
#[derive(Debug, clap::Args)]
pub struct Args {
    // The forms are the library's own list, so that the help names every one it accepts.
    #[arg(long, short = 'f', help = format!("Integrand: {} [default: disk]", specvar::integrand::INTEGRAND_FORMS))]
    pub integrand: Option<IntegrandSpec>,
    /// An image instead of one integrand: a .npy stack of per-pixel grids (as for predict
    /// --pixels), planned for the image's RMSE (the root of the mean of the pixels' variances;
    /// with --relative, relative to the image's mean).
    #[arg(long, conflicts_with = "integrand")]
    pub pixels: Option<std::path::PathBuf>,
    /// With --pixels: what each pixel's cells are: averages (a finer function's cell averages,
    /// as a renderer's sub-pixels are), samples (its values at the cells' centres) or exact
    /// (the grid is the function).
    #[arg(long, requires = "pixels", default_value = "averages")]
    pub tabulation: specvar::integrand::GridMeaning,
    /// A pilot instead of the pixels' integrands: a .npy array of renders of the image,
    /// (renders, height, width) or (renders, pixels), made at --pilot-n samples per pixel with
    /// the one sampler of --samplers; planned for the image's RMSE, the pilot's variance
    /// carried to N by the sampler's predictions on discontinuities.
    #[arg(long, conflicts_with_all = ["integrand", "pixels"], requires = "pilot_n")]
    pub pilot: Option<std::path::PathBuf>,
    /// The samples per pixel of the pilot's renders.
    #[arg(long, requires = "pilot")]
    pub pilot_n: Option<usize>,
    /// What the pilot's pixels integrate: padded (the default: pairs of dimensions padded
    /// together, film × light, part of whose variance falls like 1/N) or single (one 2D
    /// pattern per pixel).
    #[arg(long, requires = "pilot", default_value = "padded")]
    pub pilot_model: PilotModel,
    /// The target root-mean-square error (with --relative: relative to the integral).
    #[arg(long)]
    pub rmse: f64,
    /// Read --rmse as relative to the magnitude of the integral.
    #[arg(long)]
    pub relative: bool,
    /// Comma-separated samplers (default: random, jitter, cmj and sobol in 2D; random,
    /// jitter and sobol otherwise).
    #[arg(long, value_delimiter = ',')]
    pub samplers: Option<Vec<SamplerKind>>,
    /// Dimension (1 to 3).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// The estimator: native (the default: each sampler as it is used), shift, digital-shift,
    /// or none.
    #[arg(long, default_value = "native")]
    pub randomization: RandomizationChoice,
    /// The largest N to consider (default: 2^20 in 1D and 2D, 2^18 in 3D).
    #[arg(long)]
    pub max_n: Option<usize>,
    /// Seed of the predictions' estimated spectra and occupancies.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// JSON output: a list of {"sampler", "n", "rmse", "budget", "route", …}.
    #[arg(long)]
    pub json: bool,
}

/// Plans and prints.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let target = Target::new(args.rmse, args.relative);
    let base = PlanParams::new(target);
    let params = PlanParams {
        randomization: args.randomization,
        max_n: args.max_n,
        predict: PredictParams {
            seed: args.seed,
            budget: ctx.budget,
            ..base.predict
        },
        ..base
    };
    let mut kinds = match &args.samplers {
        Some(kinds) => kinds.clone(),
        None => default_samplers(args.dimension),
    };
    // A sampler named twice is planned once.
    let mut seen = std::collections::HashSet::new();
    kinds.retain(|k| seen.insert(*k));
    let samplers = kinds
        .iter()
        .map(|&k| ctx.sampler(k, args.dimension))
        .collect::<Result<Vec<Box<dyn Sampler>>>>()?;
    let refs: Vec<&dyn Sampler> = samplers.iter().map(|s| s.as_ref()).collect();
    let bars = super::bars::Bars::default();
    let (label, plans) = match (&args.pixels, &args.pilot) {
        (_, Some(path)) => {
            let [sampler] = refs.as_slice() else {
                return Err(specvar::Error::InvalidParameter {
                    name: "samplers",
                    value: match &args.samplers {
                        Some(_) => kinds
                            .iter()
                            .map(|k| k.to_string())
                            .collect::<Vec<_>>()
                            .join(","),
                        None => format!("none given (the default is {} samplers)", kinds.len()),
                    },
                    allowed: "one sampler with --pilot (--samplers NAME): the one its renders \
                              were made with"
                        .into(),
                });
            };
            let pilot =
                Pilot::read(path, args.pilot_n.unwrap_or_default())?.with_model(args.pilot_model);
            let v = pilot.variance();
            let label = format!(
                "a pilot of {} renders of {} pixels at N = {} ({}; variance {:.4e} ± {:.2e})",
                v.renders,
                v.pixels,
                v.n,
                path.display(),
                v.variance,
                v.standard_error
            );
            let rows = vec![plan_pilot(*sampler, &pilot, &params, &bars)?];
            (
                label,
                Plans {
                    rows,
                    refused: Vec::new(),
                },
            )
        }
        (Some(path), None) => {
            let stack = PixelStack::read(path)?.with_meaning(args.tabulation);
            let plans = plan_pixels_many(&refs, &stack, &params, &bars)?;
            let label = format!(
                "the {} × {} pixels of {}",
                stack.columns(),
                stack.rows(),
                path.display()
            );
            (label, plans)
        }
        (None, None) => {
            let spec = args.integrand.clone().unwrap_or_default();
            let f = spec.build(args.dimension)?;
            (f.label(), plan_many(&refs, f.as_ref(), &params, &bars)?)
        }
    };
    if args.json {
        outln!("{}", super::to_json(&plans)?)?;
    } else {
        print_text(&label, target, &plans)?;
    }
    Ok(())
}

fn print_text(integrand: &str, target: Target, table: &Plans) -> Result<()> {
    let plans: &[Plan] = &table.rows;
    let absolute = plans.first().map_or(0.0, |p| p.target);
    outln!("plan for {target} (RMSE {absolute:.4e}) on {integrand}")?;
    outln!(
        "{:<10} {:<13} {:>8} {:>11} {:>25} {:>20} {:>7}",
        "sampler",
        "estimator",
        "N",
        "RMSE",
        "99% budget",
        "below: N, RMSE",
        "rate"
    )?;
    for p in plans {
        let below = match (p.reached, p.below) {
            (false, _) => "not reached".to_string(),
            (true, Some(b)) => format!("{}, {:.3e}", b.n, b.rmse),
            (true, None) => "-".to_string(),
        };
        let rate = p.rate.map_or("-".to_string(), |r| format!("{r:.2}"));
        outln!(
            "{:<10} {:<13} {:>8} {:>11.4e} [{:>10.4e}, {:>10.4e}] {:>20} {:>7}",
            p.sampler,
            p.randomization.estimator(),
            p.n,
            p.rmse,
            p.rmse_interval.0,
            p.rmse_interval.1,
            below,
            rate
        )?;
    }
    for p in plans {
        outln!(
            "{}: {} predictions, N among {}; {}",
            p.sampler,
            p.predictions,
            p.counts,
            p.route
        )?;
    }
    for p in plans.iter().filter(|p| !p.reached) {
        outln!(
            "{} does not reach the target within {}: its N is the largest predicted",
            p.sampler,
            p.limit.as_deref().unwrap_or("the limit")
        )?;
    }
    for r in &table.refused {
        outln!("{} is not planned: {}", r.sampler, r.reason)?;
    }
    Ok(())
}
