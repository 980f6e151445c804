//! Command-line argument types and the actions behind each subcommand.
//!
//! The binary only parses and dispatches; everything printed here is computed by the public
//! library API, so a user can compute the same numbers from Rust.

use crate::error::{Error, Result};
use crate::io;
use crate::sampler::{Homogenized, Sampler, SamplerKind};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `specvar samplers`.
#[derive(Debug, Args)]
pub struct SamplersArgs {
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `specvar sample`.
#[derive(Debug, Args)]
pub struct SampleArgs {
    /// Sampler name (see `specvar samplers`).
    #[arg(long, short = 's')]
    pub sampler: String,
    /// Number of points per realization.
    #[arg(short = 'n')]
    pub n: usize,
    /// Dimension.
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// Seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of realizations (0, 1, … M-1 of the seed).
    #[arg(long, short = 'm', default_value_t = 1)]
    pub realizations: u64,
    /// Apply a random toroidal shift to each realization.
    #[arg(long)]
    pub homogenize: bool,
    /// Output file (standard output if absent).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Write JSON instead of UTK text.
    #[arg(long)]
    pub json: bool,
}

/// Builds a sampler by name, homogenized on request.
///
/// # Errors
/// An unknown name or an unsupported dimension.
pub fn build_sampler(name: &str, d: usize, homogenized: bool) -> Result<Box<dyn Sampler>> {
    let inner = SamplerKind::from_name(name)?.build(d)?;
    Ok(if homogenized {
        Box::new(Homogenized::new(inner))
    } else {
        inner
    })
}

/// The sampler table.
pub fn sampler_table() -> String {
    let mut out = format!(
        "{:<8} {:<11} {:<12} {}\n",
        "name", "dimensions", "N", "description"
    );
    for k in SamplerKind::ALL {
        let dims = k.dimensions();
        out.push_str(&format!(
            "{:<8} {:<11} {:<12} {}\n",
            k.name(),
            format!("{}-{}", dims.start(), dims.end()),
            k.count_rule(),
            k.description()
        ));
    }
    out
}

/// `specvar samplers`.
///
/// # Errors
/// Writing to standard output fails.
pub fn samplers(args: &SamplersArgs) -> Result<()> {
    if args.json {
        let rows: Vec<serde_json::Value> = SamplerKind::ALL
            .iter()
            .map(|k| {
                serde_json::json!({
                    "name": k.name(),
                    "min_dimension": k.dimensions().start(),
                    "max_dimension": k.dimensions().end(),
                    "n_rule": k.count_rule(),
                    "description": k.description(),
                })
            })
            .collect();
        println!("{}", serde_json::Value::Array(rows));
    } else {
        print!("{}", sampler_table());
    }
    Ok(())
}

/// `specvar sample`.
///
/// # Errors
/// Bad sampler, dimension or N, or an unwritable output.
pub fn sample(args: &SampleArgs) -> Result<()> {
    if args.realizations == 0 {
        return Err(crate::error::invalid("realizations", 0, "at least 1"));
    }
    let sampler = build_sampler(&args.sampler, args.dimension, args.homogenize)?;
    let sets = (0..args.realizations)
        .map(|r| sampler.sample(args.n, args.seed, r))
        .collect::<Result<Vec<_>>>()?;
    let text = if args.json {
        io::write_json(&sets)? + "\n"
    } else {
        io::write_text(&sets)
    };
    write_output(args.output.as_deref(), &text)
}

/// Writes `text` to a file, or to standard output when `path` is `None`.
///
/// # Errors
/// The file cannot be written.
pub fn write_output(path: Option<&std::path::Path>, text: &str) -> Result<()> {
    match path {
        Some(p) => std::fs::write(p, text).map_err(|e| Error::Io(format!("{}: {e}", p.display()))),
        None => std::io::stdout()
            .write_all(text.as_bytes())
            .map_err(|e| Error::Io(e.to_string())),
    }
}

/// What `specvar` does with no subcommand.
///
/// # Errors
/// As the job it runs.
pub fn default_job() -> Result<()> {
    print!("{}", sampler_table());
    Ok(())
}

/// Arguments of `specvar spectrum`.
#[derive(Debug, Args)]
pub struct SpectrumArgs {
    /// Sampler name (ignored with --input).
    #[arg(long, short = 's', default_value = "random")]
    pub sampler: String,
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
    /// Engine: direct, fast, or auto.
    #[arg(long, default_value = "auto")]
    pub method: String,
    /// Relative tolerance of the fast engine.
    #[arg(long, default_value_t = crate::spectrum::nufft::DEFAULT_TOLERANCE)]
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

/// Parses an engine name.
///
/// # Errors
/// An unknown name.
pub fn parse_engine(name: &str, tolerance: f64) -> Result<crate::spectrum::Engine> {
    use crate::spectrum::Engine;
    match name {
        "direct" => Ok(Engine::Direct),
        "fast" => Ok(Engine::Fast { tolerance }),
        "auto" => Ok(Engine::Auto),
        other => Err(crate::error::invalid(
            "method",
            other,
            "direct, fast or auto",
        )),
    }
}

/// `specvar spectrum`.
///
/// # Errors
/// Bad arguments, an unreadable input file, or an unwritable output.
pub fn spectrum(args: &SpectrumArgs) -> Result<()> {
    use crate::spectrum::{estimate, estimate_from_sets, SpectrumParams};
    let params = SpectrumParams {
        kmax: args.kmax,
        realizations: args.realizations,
        seed: args.seed,
        engine: parse_engine(&args.method, args.tolerance)?,
        bin_width: args.bin_width,
    };
    let (est, label) = match &args.input {
        Some(path) => {
            let sets = io::read_file(path)?;
            (
                estimate_from_sets(&sets, &params)?,
                path.display().to_string(),
            )
        }
        None => {
            let sampler = build_sampler(&args.sampler, args.dimension, false)?;
            (
                estimate(sampler.as_ref(), args.n, &params)?,
                args.sampler.clone(),
            )
        }
    };
    if let Some(plot) = &args.plot {
        crate::report::plot_spectrum(plot, &label, &est, args.radial)?;
    }
    let text = if args.radial {
        format_radial(&est.radial, est.lattice.engine.name(), args.json, args.csv)?
    } else {
        format_lattice(&est.lattice, args.json)?
    };
    write_output(args.output.as_deref(), &text)
}

fn format_radial(
    radial: &crate::spectrum::RadialSpectrum,
    method: &str,
    json: bool,
    csv: bool,
) -> Result<String> {
    if json {
        let doc = serde_json::json!({
            "n": radial.n,
            "dimension": radial.dimension,
            "realizations": radial.realizations,
            "method": method,
            "bin_width": radial.bin_width,
            "dc_limit": radial.dc_limit,
            "bins": radial.bins,
        });
        return Ok(doc.to_string() + "\n");
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
        out.push_str(&format!(
            "{:.6}{sep}{:.4}{sep}{:.6}{sep}{:.3e}{sep}{}{sep}{:.3}\n",
            b.nu, b.rho, b.power, b.stderr, b.count, b.anisotropy_db
        ));
    }
    Ok(out)
}

fn format_lattice(spectrum: &crate::spectrum::LatticeSpectrum, json: bool) -> Result<String> {
    let lattice = spectrum.lattice;
    if json {
        let doc = serde_json::json!({
            "n": spectrum.n,
            "dimension": lattice.dimension,
            "realizations": spectrum.realizations,
            "method": spectrum.engine.name(),
            "kmax": lattice.kmax,
            "shape": vec![lattice.side(); lattice.dimension],
            "order": "row-major, first axis slowest; index i along an axis is frequency i - kmax; the centre is DC (value N)",
            "values": spectrum.mean,
            "stderr": spectrum.stderr,
        });
        return Ok(doc.to_string() + "\n");
    }
    let axes = ["k0", "k1", "k2"];
    let mut out = axes[..lattice.dimension].join(",") + ",power,stderr,dc\n";
    for i in 0..lattice.len() {
        let k = lattice.frequency(i);
        for c in &k[..lattice.dimension] {
            out.push_str(&format!("{c},"));
        }
        out.push_str(&format!(
            "{},{},{}\n",
            spectrum.mean[i],
            spectrum.stderr[i],
            spectrum.is_dc(i)
        ));
    }
    Ok(out)
}
