//! The `specvar` command line: each subcommand parses its arguments, makes one library call and
//! prints the result. Every decision of substance (routes, reference N, lattice extents,
//! pools) is the library's.

mod bars;
mod bias;
mod mc;
mod predict;
mod problem;
mod rates;
mod render_ao;
mod report;
mod sample;
mod samplers;
mod spectrum;

use clap::{Parser, Subcommand};
use std::path::Path;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "specvar",
    version,
    about = "Predict Monte Carlo integration variance from power spectra, and check it",
    long_about = "Predict Monte Carlo integration variance from power spectra, and check it \
                  against Monte Carlo. With no subcommand, runs the reproduction report."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// List the samplers with their dimensions and N constraints.
    Samplers(samplers::Args),
    /// Write point sets (UTK text by default, or JSON).
    Sample(sample::Args),
    /// Power spectrum of a sampler or of point sets from a file: lattice or radial.
    Spectrum(spectrum::Args),
    /// Predict the variance of the homogenized estimator from spectra.
    Predict(predict::Args),
    /// Bias of a fixed (not homogenized) pattern, from its spectrum and directly.
    Bias(bias::Args),
    /// Reproduce the talk's table with predictions, Monte Carlo, plots and report.md.
    Report(report::Args),
    /// Monte Carlo variance of the estimator, with a 99% interval.
    Mc(mc::Args),
    /// Convergence rates: theory, predicted from spectra, measured by Monte Carlo.
    Rates(rates::Args),
    /// Render ambient occlusion with a sampler (or all): image, MSE, MSE predicted from spectra.
    RenderAo(render_ao::Args),
}

fn main() -> ExitCode {
    let parsed = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                print!("{e}");
                return ExitCode::SUCCESS;
            }
            // One clear line: clap's first line names the problem.
            let text = e.to_string();
            eprintln!("{}", text.lines().next().unwrap_or("invalid arguments"));
            return ExitCode::from(2);
        }
    };
    let result = match parsed.command {
        Some(Command::Samplers(a)) => samplers::run(&a),
        Some(Command::Sample(a)) => sample::run(&a),
        Some(Command::Spectrum(a)) => spectrum::run(&a),
        Some(Command::Predict(a)) => predict::run(&a),
        Some(Command::Bias(a)) => bias::run(&a),
        Some(Command::Report(a)) => report::run(&a),
        Some(Command::Mc(a)) => mc::run(&a),
        Some(Command::Rates(a)) => rates::run(&a),
        Some(Command::RenderAo(a)) => render_ao::run(&a),
        None => report::run(&report::Args::default()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// Writes `text` atomically to a file, or to standard output when `path` is `None`.
fn write_output(path: Option<&Path>, text: &str) -> specvar::Result<()> {
    use std::io::Write;
    match path {
        Some(p) => specvar::output::write_atomic(p, text.as_bytes()),
        None => std::io::stdout()
            .write_all(text.as_bytes())
            .map_err(|e| specvar::Error::io(Path::new("standard output"), e)),
    }
}

/// Serializes `value` as one line of JSON.
fn to_json(value: &impl serde::Serialize) -> specvar::Result<String> {
    serde_json::to_string(value).map_err(|e| specvar::Error::format("JSON output", e))
}
