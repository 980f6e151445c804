//! `specvar spectrum`: the expected power spectrum of a sampler or of point sets from a file.

use specvar::sampler::SamplerKind;
use specvar::spectrum::{
    estimate, estimate_from_sets, nufft, Engine, LatticeSpectrum, RadialSpectrum, SpectrumParams,
};
use specvar::Result;
use std::fmt::Write as _;
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
pub fn run(args: &Args) -> Result<()> {
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
            let sampler = args.sampler.build(args.dimension)?;
            let stage = format!("spectrum of {} at N = {}", args.sampler, args.n);
            specvar::progress::Progress::begin(&bars, &stage, 0);
            let est = estimate(sampler.as_ref(), args.n, &params)?;
            specvar::progress::Progress::end(&bars);
            (est, args.sampler.to_string())
        }
    };
    if let Some(plot) = &args.plot {
        specvar::plot::spectrum_plot(plot, &label, &est, args.radial)?;
    }
    let text = if args.radial {
        format_radial(&est.radial, est.lattice.engine.name(), args.json, args.csv)?
    } else {
        format_lattice(&est.lattice, args.json)?
    };
    super::write_output(args.output.as_deref(), &text)
}

#[derive(serde::Serialize)]
struct RadialDoc<'a> {
    n: usize,
    dimension: usize,
    realizations: usize,
    method: &'a str,
    bin_width: f64,
    dc_limit: f64,
    bins: &'a [specvar::spectrum::RadialBin],
}

fn format_radial(radial: &RadialSpectrum, method: &str, json: bool, csv: bool) -> Result<String> {
    if json {
        let doc = RadialDoc {
            n: radial.n,
            dimension: radial.dimension,
            realizations: radial.realizations,
            method,
            bin_width: radial.bin_width,
            dc_limit: radial.dc_limit,
            bins: &radial.bins,
        };
        return Ok(super::to_json(&doc)? + "\n");
    }
    let sep = if csv { "," } else { " " };
    let mut out = if csv {
        String::from("nu,rho,power,stderr,count,anisotropy_db\n")
    } else {
        format!(
            "# radial spectrum: N = {}, d = {}, {} realizations, {method}; P(0+) ≈ {:.4}\n# nu rho power stderr count anisotropy_db\n",
            radial.n, radial.dimension, radial.realizations, radial.dc_limit
        )
    };
    for b in &radial.bins {
        let _ = writeln!(
            out,
            "{:.6}{sep}{:.4}{sep}{:.6}{sep}{:.3e}{sep}{}{sep}{:.3}",
            b.nu, b.rho, b.power, b.stderr, b.count, b.anisotropy_db
        );
    }
    Ok(out)
}

#[derive(serde::Serialize)]
struct LatticeDoc<'a> {
    n: usize,
    dimension: usize,
    realizations: usize,
    method: &'a str,
    kmax: usize,
    shape: Vec<usize>,
    order: &'a str,
    values: &'a [f64],
    stderr: &'a [f64],
}

fn format_lattice(spectrum: &LatticeSpectrum, json: bool) -> Result<String> {
    let lattice = spectrum.lattice;
    if json {
        let doc = LatticeDoc {
            n: spectrum.n,
            dimension: lattice.dimension,
            realizations: spectrum.realizations,
            method: spectrum.engine.name(),
            kmax: lattice.kmax,
            shape: vec![lattice.side(); lattice.dimension],
            order: "row-major, first axis slowest; index i along an axis is frequency i - kmax; the centre is DC (value N)",
            values: &spectrum.mean,
            stderr: &spectrum.stderr,
        };
        return Ok(super::to_json(&doc)? + "\n");
    }
    let axes = ["k0", "k1", "k2"];
    let mut out = axes[..lattice.dimension].join(",") + ",power,stderr,dc\n";
    for i in 0..lattice.len() {
        for c in &lattice.frequency(i)[..lattice.dimension] {
            let _ = write!(out, "{c},");
        }
        let _ = writeln!(
            out,
            "{},{},{}",
            spectrum.mean[i],
            spectrum.stderr[i],
            spectrum.is_dc(i)
        );
    }
    Ok(out)
}
