//! `specvar anisotropy`: the variance of an edge against its angle, predicted and measured.

use specvar::anisotropy::{edge_rates, variance_against_orientation, OrientationConfig};
use specvar::plot::{line_plot, Axes, Series, Style};
use specvar::predict::PredictParams;
use specvar::sampler::SamplerKind;
use specvar::Result;
use std::path::PathBuf;

/// Arguments of `specvar anisotropy`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sampler name (2D).
    #[arg(long, short = 's')]
    pub sampler: SamplerKind,
    /// Points per pattern.
    #[arg(short = 'n', default_value_t = 256)]
    pub n: usize,
    /// Angles of the edge's normal in degrees: START:END:STEP (inclusive) or a comma list.
    #[arg(long, default_value = "0:90:5")]
    pub angles: String,
    /// Where the edge crosses the square, as a fraction of its extent along the normal.
    #[arg(long, default_value_t = 0.5)]
    pub offset: f64,
    /// Monte Carlo evaluations.
    #[arg(long, default_value_t = 20_000)]
    pub trials: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Rates instead: the predicted and measured variance at each of these N (comma list),
    /// and the log-log slopes for each angle.
    #[arg(long, value_delimiter = ',')]
    pub rates: Vec<usize>,
    /// Plot the variance against the angle (SVG).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Plot the variance against the angle in polar form (SVG): radius the variance.
    #[arg(long)]
    pub polar: Option<PathBuf>,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

/// Predicts and measures every angle, prints the table, writes the plot.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    for path in args.plot.iter().chain(&args.polar) {
        specvar::plot::check_plot_path(path, false)?;
    }
    let angles = specvar::anisotropy::parse_angles(&args.angles)?;
    let sampler = ctx.sampler(args.sampler, 2)?;
    let config = OrientationConfig {
        n: args.n,
        angles,
        offset: args.offset,
        trials: args.trials,
        seed: args.seed,
        predict: PredictParams {
            seed: args.seed,
            budget: ctx.budget,
            ..PredictParams::default()
        },
    };
    if !args.rates.is_empty() {
        return rates(args, sampler.as_ref(), &config);
    }
    let rows = variance_against_orientation(
        sampler.as_ref(),
        args.sampler,
        &config,
        &super::bars::Bars::default(),
    )?;
    plots(args, &rows)?;
    if args.json {
        return super::write_output(None, &(super::to_json(&rows)? + "\n"));
    }
    outln!(
        "{:>7} {:>12} {:>12} {:>25} {:>7}",
        "angle",
        "predicted",
        "Monte Carlo",
        "99% interval",
        "z"
    )?;
    for r in &rows {
        outln!(
            "{:>7.1} {:>12.4e} {:>12.4e} [{:>10.4e}, {:>10.4e}] {:>+7.2}{}",
            r.angle,
            r.predicted.variance,
            r.measured.variance,
            r.measured.ci_low,
            r.measured.ci_high,
            r.z,
            if r.agrees() { "" } else { "  miss" }
        )?;
    }
    Ok(())
}

/// The rate table: per angle, the predicted and measured slopes over `--rates`.
fn rates(args: &Args, sampler: &dyn specvar::Sampler, config: &OrientationConfig) -> Result<()> {
    let rates = edge_rates(
        sampler,
        args.sampler,
        &args.rates,
        config,
        &super::bars::Bars::default(),
    )?;
    if args.json {
        return super::write_output(None, &(super::to_json(&rates)? + "\n"));
    }
    outln!(
        "{:>7} {:>22} {:>32}",
        "angle",
        "predicted slope",
        "Monte Carlo slope [99%]"
    )?;
    for r in &rates {
        outln!(
            "{:>7.1} {:>13.3} ± {:<6.3} {:>10.3} [{:.3}, {:.3}]",
            r.angle,
            r.predicted.slope,
            r.predicted.stderr,
            r.measured.slope,
            r.measured.ci.0,
            r.measured.ci.1
        )?;
    }
    Ok(())
}

/// The variance against the angle, Cartesian (`--plot`) and polar (`--polar`).
fn plots(args: &Args, rows: &[specvar::anisotropy::OrientationRow]) -> Result<()> {
    let [predicted, measured] = specvar::anisotropy::polar_series(rows);
    let title = format!(
        "{} at N = {}: variance of an edge (offset {}) against its angle",
        args.sampler, args.n, args.offset
    );
    if let Some(path) = &args.plot {
        let series = [
            Series {
                label: predicted.label.clone(),
                points: predicted.points.clone(),
                bars: None,
                style: Style::Line,
                color: 0,
            },
            Series {
                label: measured.label.clone(),
                points: measured.points.clone(),
                bars: measured.bars.clone(),
                style: Style::Points,
                color: 1,
            },
        ];
        let axes = Axes {
            title: title.clone(),
            x_label: "angle of the edge's normal (degrees)".into(),
            y_label: "variance".into(),
            log_y: true,
            ..Axes::default()
        };
        line_plot(path, &axes, &series)?;
    }
    if let Some(path) = &args.polar {
        specvar::plot::polar_plot(path, &title, &[predicted, measured])?;
    }
    Ok(())
}
