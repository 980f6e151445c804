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
