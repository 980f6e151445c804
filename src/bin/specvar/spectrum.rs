//! `specvar spectrum`: the expected power spectrum of a sampler or of point sets from a file.

use specvar::sampler::SamplerKind;
use specvar::spectrum::export::{lattice_table, radial_table, TableFormat};
use specvar::spectrum::{estimate, estimate_from_sets, nufft, Engine, SpectrumParams};
use specvar::Result;
use std::path::PathBuf;

/// The engine, as named on the command line.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum Method {
    /// Exact sum by phase recurrence.
    Direct,
    /// Non-uniform FFT at --tolerance.
    Fast,
    /// The cheaper of the two.
    Auto,
}

/// Arguments of `specvar spectrum`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sampler name (ignored with --input).
    #[arg(long, short = 's', default_value = "random")]
    pub sampler: SamplerKind,
    /// Points per pattern (ignored with --input).
    #[arg(short = 'n', default_value_t = 1024)]
    pub n: usize,
    /// Dimension, 1 to 3 (ignored with --input).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Realizations to average (ignored with --input: every realization in the file is used).
    #[arg(long, short = 'm', default_value_t = 16)]
    pub realizations: usize,
    /// Largest frequency per axis K: the lattice is (2K+1)^d.
    #[arg(long, default_value_t = 64)]
    pub kmax: usize,
    /// Engine.
    #[arg(long, value_enum, default_value = "auto")]
    pub method: Method,
    /// Relative tolerance of the fast engine.
    #[arg(long, default_value_t = nufft::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    /// Ring width in |k| for --radial.
    #[arg(long, default_value_t = 1.0)]
    pub bin_width: f64,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output the radial spectrum instead of the lattice.
    #[arg(long)]
    pub radial: bool,
    /// Read point sets (UTK text or JSON) instead of sampling.
    #[arg(long)]
    pub input: Option<PathBuf>,
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
    let engine = match args.method {
        Method::Direct => Engine::Direct,
        Method::Fast => Engine::Fast {
            tolerance: args.tolerance,
        },
        Method::Auto => Engine::Auto,
    };
    let params = SpectrumParams {
        kmax: args.kmax,
        realizations: args.realizations,
        seed: args.seed,
        engine,
        bin_width: args.bin_width,
        budget: ctx.budget,
    };
    let bars = super::bars::Bars::default();
    let (est, label) = match &args.input {
        Some(path) => {
            let sets = specvar::io::read_file(path)?;
            (
                estimate_from_sets(&sets, &params)?,
                path.display().to_string(),
            )
        }
        None => {
            let sampler = ctx.sampler(args.sampler, args.dimension)?;
            let stage = format!("spectrum of {} at N = {}", args.sampler, args.n);
            specvar::progress::Progress::begin(&bars, &stage, 0);
            let est = estimate(sampler.as_ref(), args.n, &params)?;
            specvar::progress::Progress::end(&bars);
            (est, args.sampler.to_string())
        }
    };
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
