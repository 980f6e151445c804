//! `specvar metrics`: discrepancies, distances, the effective Nyquist frequency and the pair
//! correlation function of a sampler or of point sets from a file.

use specvar::metrics::{
    discrepancy_means, distance_summary, effective_nyquist, hexagonal_nyquist, pair_correlation,
    DiscrepancyKind, Mean, PcfParams,
};
use specvar::plot::{line_plot, Axes, Series, Style};
use specvar::pointset::PointSet;
use specvar::spectrum::{estimate_with_progress, PatternSource, SpectrumParams};
use specvar::Result;
use std::path::PathBuf;

/// Arguments of `specvar metrics`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The patterns.
    #[command(flatten)]
    pub patterns: super::patterns::PatternArgs,
    /// The pair correlation function's kernel width, in mean spacings N^(-1/d).
    #[arg(long, default_value_t = 0.05)]
    pub pcf_sigma: f64,
    /// The pair correlation function's largest radius, in mean spacings.
    #[arg(long, default_value_t = 3.0)]
    pub pcf_rmax: f64,
    /// Write the pair correlation function as CSV (radius in spacings, g, standard error).
    #[arg(long)]
    pub pcf: Option<PathBuf>,
    /// Plot the pair correlation function (SVG).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// JSON output.
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize)]
struct Summary {
    source: String,
    n: usize,
    dimension: usize,
    patterns: usize,
    /// Squared discrepancies: mean over the patterns and its standard error.
    discrepancies: Vec<(DiscrepancyKind, Mean)>,
    min_distance: f64,
    mean_min_distance: f64,
    effective_nyquist: Option<f64>,
    effective_nyquist_over_hexagonal: Option<f64>,
}

/// Measures the patterns and prints the summary; writes the PCF if asked.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    if let Some(path) = &args.plot {
        specvar::plot::check_plot_path(path, false)?;
    }
    let (label, patterns) = patterns(args, ctx)?;
    let (n, d) = (patterns[0].len(), patterns[0].dimension());
    let pcf_params = PcfParams {
        sigma: args.pcf_sigma,
        r_max: args.pcf_rmax,
        budget: ctx.budget,
        ..PcfParams::default()
    };
    let pcf = pair_correlation(&patterns, &pcf_params)?;
    let summary = summarize(&label, &patterns, ctx)?;
    if let Some(path) = &args.pcf {
        let mut csv = String::from("radius_in_spacings,g,stderr\n");
        for ((r, g), s) in pcf.radius_in_spacings.iter().zip(&pcf.g).zip(&pcf.stderr) {
            csv.push_str(&format!("{r},{g},{s}\n"));
        }
        specvar::output::write_atomic(path, csv.as_bytes())?;
    }
    if let Some(path) = &args.plot {
        let series = Series {
            label: label.clone(),
            points: pcf
                .radius_in_spacings
                .iter()
                .copied()
                .zip(pcf.g.iter().copied())
                .collect(),
            bars: None,
            style: Style::Line,
            color: 0,
        };
        let axes = Axes {
            title: format!(
                "pair correlation function, {label}: N = {n}, {d}D, {} patterns",
                pcf.patterns
            ),
            x_label: "r / N^(-1/d)".into(),
            y_label: "g(r)".into(),
            ..Axes::default()
        };
        line_plot(path, &axes, &[series])?;
    }
    if args.json {
        outln!("{}", super::to_json(&summary)?)?;
    } else {
        print_summary(&summary)?;
    }
    Ok(())
}

fn patterns(args: &Args, ctx: &super::Context) -> Result<(String, Vec<PointSet>)> {
    if let Some(path) = &args.patterns.input {
        return Ok((path.display().to_string(), specvar::io::read_file(path)?));
    }
    if args.patterns.realizations == 0 {
        return Err(specvar::Error::InvalidParameter {
            name: "realizations",
            value: "0".into(),
            allowed: "at least 1".into(),
        });
    }
    // The summary's pair loops and the patterns' drawing against the budget before any
    // pattern is drawn.
    let (kind, n, d) = (
        args.patterns.sampler,
        args.patterns.n,
        args.patterns.dimension,
    );
    let count = args.patterns.realizations;
    let draw = kind.pattern_needs(n, d);
    ctx.budget.check(
        &format!("the metrics of {count} patterns of {kind} at N = {n}"),
        specvar::metrics::summary_needs(count, n, d).and(specvar::budget::Needs::work(
            draw.work_seconds * count as f64,
        )),
        "lower N or fewer realizations",
    )?;
    let sampler = ctx.sampler(kind, d)?;
    let sets = specvar::sampler::draw_realizations(
        sampler.as_ref(),
        args.patterns.n,
        args.patterns.seed,
        0..args.patterns.realizations as u64,
        specvar::randomization::Randomization::None,
        &ctx.budget,
    )?;
    Ok((args.patterns.sampler.to_string(), sets))
}

fn summarize(label: &str, patterns: &[PointSet], ctx: &super::Context) -> Result<Summary> {
    let (n, d) = (patterns[0].len(), patterns[0].dimension());
    let discrepancies = discrepancy_means(patterns)?;
    let near = distance_summary(patterns, &ctx.budget)?;
    let params = SpectrumParams {
        kmax: specvar::metrics::summary_kmax(n, d),
        budget: ctx.budget,
        ..SpectrumParams::default()
    };
    let bars = super::bars::Bars::default();
    let spectrum = estimate_with_progress(PatternSource::Sets(patterns), &params, &bars)?;
    let nu = effective_nyquist(&spectrum.radial);
    Ok(Summary {
        source: label.to_string(),
        n,
        dimension: d,
        patterns: patterns.len(),
        discrepancies,
        min_distance: near.min_distance,
        mean_min_distance: near.mean_min_distance,
        effective_nyquist: nu,
        effective_nyquist_over_hexagonal: nu.filter(|_| d == 2).map(|v| v / hexagonal_nyquist()),
    })
}

fn print_summary(s: &Summary) -> Result<()> {
    outln!(
        "{}: N = {}, {}D, {} patterns",
        s.source,
        s.n,
        s.dimension,
        s.patterns
    )?;
    for (
        kind,
        Mean {
            mean,
            stderr: error,
        },
    ) in &s.discrepancies
    {
        outln!(
            "  {:<22} {mean:.6e} ± {error:.1e}",
            format!("{} discrepancy²", kind.name())
        )?;
    }
    outln!(
        "  {:<22} {:.4} (of the densest packing's)",
        "min distance",
        s.min_distance
    )?;
    outln!("  {:<22} {:.4}", "mean min distance", s.mean_min_distance)?;
    match (s.effective_nyquist, s.effective_nyquist_over_hexagonal) {
        (Some(nu), Some(rel)) => outln!(
            "  {:<22} ν = {nu:.3} ({:.1}% of the hexagonal lattice's)",
            "effective Nyquist",
            100.0 * rel
        )?,
        (Some(nu), None) => outln!("  {:<22} ν = {nu:.3}", "effective Nyquist")?,
        _ => outln!(
            "  {:<22} none (the spectrum is above 0.1 from the first ring)",
            "effective Nyquist"
        )?,
    }
    Ok(())
}
