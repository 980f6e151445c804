//! `specvar spectrum`: the expected power spectrum of a sampler or of point sets from a file.

use specvar::progress::Progress;
use specvar::spectrum::export::{lattice_table, radial_table, TableFormat};
use specvar::spectrum::{estimate_with_progress, EngineChoice, PatternSource, SpectrumParams};
use specvar::Result;
use std::path::PathBuf;

/// Arguments of `specvar spectrum`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The patterns.
    #[command(flatten)]
    pub patterns: super::patterns::PatternArgs,
    /// Largest frequency per axis K: the lattice is (2K+1)^d.
    #[arg(long, default_value_t = 64)]
    pub kmax: usize,
    /// Engine: direct (exact sums), fast (non-uniform FFT at --tolerance), or auto (the cheaper
    /// of the two, the fast one at the tolerance the statistics need).
    #[arg(long, default_value_t = EngineChoice::Auto)]
    pub method: EngineChoice,
    /// Guaranteed error of the fast engine, |S_fast - S| ≤ tolerance · N at every frequency
    /// [default: the statistical tolerance for N and the realizations, which keeps the error
    /// in P below 1% of its standard error and below 1e-8]
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Ring width in |k| for --radial.
    #[arg(long, default_value_t = 1.0)]
    pub bin_width: f64,
    /// Output the radial spectrum instead of the lattice.
    #[arg(long, conflicts_with = "sectors")]
    pub radial: bool,
    /// Output the power in this many angular sectors of the half plane (2D), ring by ring:
    /// the directional spectrum of anisotropic samplers.
    #[arg(long)]
    pub sectors: Option<usize>,
    /// JSON output.
    #[arg(long, conflicts_with = "csv")]
    pub json: bool,
    /// CSV output.
    #[arg(long)]
    pub csv: bool,
    /// Also write a plot (SVG; the lattice image may be .png).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Output file (standard output if absent).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
}

/// Estimates the spectrum and writes it.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    let sets = match &args.patterns.input {
        Some(path) => Some(specvar::io::read_file(path)?),
        None => None,
    };
    let (n, realizations) = match &sets {
        Some(sets) => (sets.first().map_or(0, |s| s.len()), sets.len()),
        None => (args.patterns.n, args.patterns.realizations),
    };
    let engine = args.method.engine(args.tolerance, n, realizations)?;
    let params = SpectrumParams {
        kmax: args.kmax,
        realizations: args.patterns.realizations,
        seed: args.patterns.seed,
        engine,
        bin_width: args.bin_width,
        budget: ctx.budget,
    };
    let bars = super::bars::Bars::default();
    let sampler;
    let (source, label) = match &sets {
        Some(sets) => (
            PatternSource::Sets(sets),
            args.patterns
                .input
                .as_ref()
                .map_or(String::new(), |p| p.display().to_string()),
        ),
        None => {
            sampler = ctx.sampler(args.patterns.sampler, args.patterns.dimension)?;
            let source = PatternSource::Sampler {
                sampler: sampler.as_ref(),
                n,
                seed: args.patterns.seed,
            };
            (source, args.patterns.sampler.to_string())
        }
    };
    let stage = format!("spectrum of {label} at N = {n}");
    bars.begin(&stage, realizations as u64);
    let est = estimate_with_progress(source, &params, &bars)?;
    bars.end();
    if let Some(sectors) = args.sectors {
        let s = specvar::spectrum::sector_spectrum(&est.lattice, sectors, args.bin_width)?;
        if let Some(plot) = &args.plot {
            specvar::plot::check_plot_path(plot, false)?;
            sector_plot(plot, &label, &s)?;
        }
        return super::write_output(args.output.as_deref(), &sector_table(&s, args.json)?);
    }
    if let Some(plot) = &args.plot {
        specvar::plot::check_plot_path(plot, !args.radial)?;
        specvar::plot::spectrum_plot(plot, &label, &est, args.radial)?;
    }
    let format = match (args.json, args.csv) {
        (true, _) => TableFormat::Json,
        (_, true) => TableFormat::Csv,
        _ => TableFormat::Text,
    };
    let text = if args.radial {
        radial_table(&est.radial, est.lattice.engine.name(), format)?
    } else {
        lattice_table(&est.lattice, format)?
    };
    super::write_output(args.output.as_deref(), &text)
}

/// The sector spectrum as JSON or CSV (`nu`, then one column per sector's direction).
fn sector_table(s: &specvar::spectrum::SectorSpectrum, json: bool) -> Result<String> {
    if json {
        return Ok(super::to_json(s)? + "\n");
    }
    let mut out = String::from("nu");
    for d in &s.directions {
        out.push_str(&format!(",power_{d:.1}deg"));
    }
    out.push('\n');
    for ring in &s.rings {
        out.push_str(&format!("{}", ring.nu));
        for p in &ring.power {
            out.push_str(&format!(",{p}"));
        }
        out.push('\n');
    }
    Ok(out)
}

/// One curve per sector (at most eight, evenly chosen, so that the legend stays readable).
fn sector_plot(
    path: &std::path::Path,
    label: &str,
    s: &specvar::spectrum::SectorSpectrum,
) -> Result<()> {
    use specvar::plot::{line_plot, Axes, Series, Style};
    let count = s.directions.len();
    let shown = count.min(8);
    let series: Vec<Series> = (0..shown)
        .map(|j| {
            let sector = j * count / shown;
            Series {
                label: format!("{:.1}°", s.directions[sector]),
                points: s.rings.iter().map(|r| (r.nu, r.power[sector])).collect(),
                bars: None,
                style: Style::Line,
                color: j,
            }
        })
        .collect();
    let axes = Axes {
        title: format!("power by direction, {label}: N = {}", s.n),
        x_label: "ν = |k| / √N".into(),
        y_label: "mean power in the sector".into(),
        ..Axes::default()
    };
    line_plot(path, &axes, &series)
}
