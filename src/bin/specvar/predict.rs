//! `specvar predict`: the variance of an estimator, from spectra, in one library call.

use super::problem::{ProblemArgs, Source};
use specvar::predict::{
    plan_analysis, predict_with, AnalysisKind, AnalysisPlan, Form, FormChoice, PredictParams,
    Prediction, Problem, SpectrumChoice,
};
use specvar::sampler::CellRule;
use specvar::Result;

/// Arguments of `specvar predict`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sampler or point-set file, integrand, N and dimension.
    #[command(flatten)]
    pub problem: ProblemArgs,
    /// Spectrum: auto (a closed form where the sampler has one, else an estimate), closed, or
    /// estimated.
    #[arg(long, default_value_t = SpectrumChoice::default())]
    pub spectrum: SpectrumChoice,
    /// Form: auto (the lattice form, exact on the torus, with the polar form beside it where
    /// valid; the cell form for strata and nets as drawn), lattice, polar (where it is valid),
    /// or cells (where the estimator has a cell form: strata and nets as drawn, and strata and
    /// Sobol' under a shift).
    #[arg(long, default_value_t = FormChoice::default())]
    pub form: FormChoice,
    /// The polar form's reference N for an estimated spectrum, rescaled to N.
    #[arg(long)]
    pub reference_n: Option<usize>,
    /// Realizations of an estimated spectrum (default: adaptive, from 32).
    #[arg(long, short = 'm')]
    pub realizations: Option<usize>,
    /// Relative standard error an estimated prediction aims at.
    #[arg(long)]
    pub target_noise: Option<f64>,
    /// The lattice extent K (default: chosen from N and the integrand's tail).
    #[arg(long)]
    pub kmax: Option<usize>,
    /// With --input: the cells in which the sets' points are independent and uniform once their
    /// cells are known, as their sampler guarantees (strata: jittered strata; rows: N-rooks
    /// such as multi-jitter and orthogonal arrays; dyadic: Owen-scrambled base-2 nets; whole:
    /// independent points). The sets are then predicted as given, by the cell form.
    #[arg(long, requires = "input")]
    pub cells: Option<CellRule>,
    /// Every pixel of an image instead of one integrand: a .npy array of per-pixel grids,
    /// (pixels, height, width) or (rows, columns, height, width), or a directory of grid files
    /// (one pixel each, in the order of their names). Prints the image's MSE; --json adds every
    /// pixel's variance.
    #[arg(long, conflicts_with = "input")]
    pub pixels: Option<std::path::PathBuf>,
    /// With --pixels: what each pixel's cells are: averages (a finer function's cell averages,
    /// as a renderer's sub-pixels are), samples (its values at the cells' centres) or exact
    /// (the grid is the function).
    #[arg(long, requires = "pixels", default_value = "averages")]
    pub tabulation: specvar::integrand::GridMeaning,
    /// With --pixels: write the image of predicted variance as a grey PNG (255 at the largest).
    #[arg(long, requires = "pixels")]
    pub png: Option<std::path::PathBuf>,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Show the plan without running it: the analysis that would answer, why, and what it
    /// needs (seconds of one core, bytes), checked against the budget.
    #[arg(long, conflicts_with = "pixels")]
    pub explain: bool,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// Predicts and prints.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let defaults = PredictParams::default();
    let params = PredictParams {
        spectrum: args.spectrum,
        form: args.form,
        reference_n: args.reference_n,
        realizations: args.realizations,
        target_noise: args.target_noise.unwrap_or(defaults.target_noise),
        kmax: args.kmax,
        seed: args.seed,
        budget: ctx.budget,
        ..defaults
    };
    if let Some(path) = &args.pixels {
        return run_pixels(args, path, &params, ctx);
    }
    let (source, f, n) = args.problem.build(ctx)?;
    let problem = match &source {
        Source::Sampler(_, sampler) => Problem::new(sampler.as_ref(), f.as_ref(), n)?,
        Source::Sets(_, sets) => match args.cells {
            Some(rule) => Problem::from_point_sets(sets, f.as_ref())?.with_cells(rule)?,
            None => Problem::from_point_sets(sets, f.as_ref())?,
        },
    }
    .with_randomization(source.randomization(args.problem.randomization));
    if args.explain {
        return print_plan(&plan_analysis(&problem, &params)?, args.json);
    }
    let p = predict_with(&problem, &params, &super::bars::Bars::default())?;
    if args.json {
        outln!(
            "{}",
            super::to_json(&Doc::new(&source.label(), &f.label(), &p))?
        )?;
    } else {
        print_text(&source.label(), &f.label(), &p)?;
    }
    Ok(())
}

/// Predicts every pixel of a stack and prints the image's MSE (and writes the PNG).
fn run_pixels(
    args: &Args,
    path: &std::path::Path,
    params: &PredictParams,
    ctx: &super::Context,
) -> Result<()> {
    use specvar::pixels::{pixel_params, predict_pixels, PixelStack};
    if args.problem.integrand.is_some() {
        return Err(specvar::Error::InvalidParameter {
            name: "integrand",
            value: "given with --pixels".into(),
            allowed: "one or the other: --pixels names every pixel's integrand".into(),
        });
    }
    let (Some(kind), Some(n)) = (args.problem.sampler, args.problem.n) else {
        return Err(specvar::Error::InvalidParameter {
            name: "pixels",
            value: path.display().to_string(),
            allowed: "with --sampler and -n".into(),
        });
    };
    if args.problem.dimension != 2 {
        return Err(specvar::Error::InvalidParameter {
            name: "dimension",
            value: args.problem.dimension.to_string(),
            allowed: "2 with --pixels: every pixel is a 2D grid (padded predicts 4D pixels)".into(),
        });
    }
    let stack = PixelStack::read(path)?.with_meaning(args.tabulation);
    let sampler = ctx.sampler(kind, 2)?;
    sampler.check_count(n)?;
    let pixel = pixel_params(params);
    let own = PredictParams {
        target_noise: args.target_noise.unwrap_or(pixel.target_noise),
        ..pixel
    };
    let image = predict_pixels(
        &stack,
        sampler.as_ref(),
        n,
        args.problem.randomization,
        &own,
        &super::bars::Bars::default(),
    )?;
    if let Some(png) = &args.png {
        specvar::output::write_atomic(png, &image.variance_png()?)?;
    }
    if args.json {
        outln!("{}", super::to_json(&image)?)?;
        return Ok(());
    }
    let b = &image.budget;
    outln!(
        "sampler      {kind} ({}), N = {n}, {} × {} pixels of {}",
        image.randomization.estimator(),
        image.columns,
        image.rows,
        path.display()
    )?;
    outln!(
        "route        {} (first pixel; each takes its own default)",
        image.route
    )?;
    outln!("image MSE    {:.6e} ({})", image.mse, budget_terms(b))?;
    let largest = image
        .pixels
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.variance.total_cmp(&b.1.variance));
    if let Some((i, p)) = largest {
        outln!(
            "largest      {:.6e} at pixel {i} (row {}, column {})",
            p.variance,
            i / image.columns,
            i % image.columns
        )?;
    }
    Ok(())
}

/// Prints the plan of a prediction.
fn print_plan(plan: &AnalysisPlan, json: bool) -> Result<()> {
    if json {
        return outln!("{}", super::to_json(plan)?);
    }
    outln!("analysis     {}", plan.analysis)?;
    outln!("reason       {}", plan.reason)?;
    outln!(
        "needs        {} on one core and {} before any further step{}",
        specvar::budget::seconds(plan.needs.seconds),
        specvar::budget::bytes(plan.needs.bytes),
        if plan.needs.tables_checked_as_built {
            "; its tables are sized as they are built, each checked against the budget first"
        } else {
            ""
        }
    )
}

#[derive(serde::Serialize)]
struct Doc<'a> {
    analysis: Option<AnalysisKind>,
    sampler: &'a str,
    integrand: &'a str,
    n: usize,
    dimension: usize,
    randomization: specvar::randomization::Randomization,
    form: Form,
    variance: f64,
    variance_lattice: Option<f64>,
    dc_term: f64,
    spectrum_source: String,
    quadrature_error: f64,
    spectrum_stderr: f64,
    route: String,
    reason: &'a str,
    budget: specvar::predict::ErrorBudget,
    alternatives: &'a [specvar::predict::Alternative],
}

impl<'a> Doc<'a> {
    fn new(sampler: &'a str, integrand: &'a str, p: &'a Prediction) -> Self {
        let lattice = std::iter::once((p.route.form, p.variance))
            .chain(p.alternatives.iter().map(|a| (a.route.form, a.variance)))
            .find(|(form, _)| *form == Form::Lattice)
            .map(|(_, v)| v);
        Self {
            analysis: p.analysis,
            sampler,
            integrand,
            n: p.n,
            dimension: p.dimension,
            randomization: p.randomization,
            form: p.route.form,
            variance: p.variance,
            variance_lattice: lattice,
            dc_term: p.dc_term,
            spectrum_source: p.route.spectrum.to_string(),
            quadrature_error: p.budget.quadrature,
            spectrum_stderr: p.budget.spectrum_noise,
            route: p.route.to_string(),
            reason: &p.reason,
            budget: p.budget,
            alternatives: &p.alternatives,
        }
    }
}

fn print_text(sampler: &str, integrand: &str, p: &Prediction) -> Result<()> {
    outln!(
        "sampler      {sampler} ({}), N = {}, d = {}",
        p.randomization.estimator(),
        p.n,
        p.dimension
    )?;
    outln!("integrand    {integrand}")?;
    if let Some(analysis) = p.analysis {
        outln!("analysis     {analysis}")?;
    }
    outln!("route        {} ({})", p.route, p.reason)?;
    let b = &p.budget;
    outln!("variance     {:.6e} ({})", p.variance, budget_terms(b))?;
    if p.route.form == Form::Polar {
        outln!("DC term      {:.6e} (already subtracted)", p.dc_term)?;
    }
    for a in &p.alternatives {
        outln!("also         {:.6e} by the {}", a.variance, a.route)?;
    }
    Ok(())
}

/// A budget's terms in words; the tabulation term where the integrand is a tabulated grid.
fn budget_terms(b: &specvar::predict::ErrorBudget) -> String {
    let mut terms = format!(
        "spectrum noise ±{:.1e}, quadrature {:.1e}, truncation {:.1e}, model {:.1e}",
        b.spectrum_noise, b.quadrature, b.truncation, b.model
    );
    if b.tabulation > 0.0 {
        terms += &format!(", tabulation {:.1e}", b.tabulation);
    }
    terms
}
