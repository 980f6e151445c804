//! The `specvar` command line: parses arguments, calls the library, prints.

use clap::{Parser, Subcommand};
use specvar::cli;
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
    Samplers(cli::SamplersArgs),
    /// Write point sets (UTK text by default, or JSON).
    Sample(cli::SampleArgs),
    /// Power spectrum of a sampler or of point sets from a file: lattice or radial.
    Spectrum(cli::SpectrumArgs),
    /// Predict the variance of the homogenized estimator from spectra.
    Predict(cli::PredictArgs),
    /// Bias of a fixed (not homogenized) pattern, from its spectrum and directly.
    Bias(cli::BiasArgs),
    /// Reproduce the talk's table with predictions, Monte Carlo, plots and report.md.
    Report(cli::ReportArgs),
    /// Monte Carlo variance of the estimator, with a 99% interval.
    Mc(cli::McArgs),
    /// Convergence rates: theory, predicted from spectra, measured by Monte Carlo.
    Rates(cli::RatesArgs),
    /// Render ambient occlusion with a sampler (or all): image, MSE, MSE predicted from spectra.
    RenderAo(cli::RenderAoArgs),
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
        Some(Command::Samplers(a)) => cli::samplers(&a),
        Some(Command::Sample(a)) => cli::sample(&a),
        Some(Command::Spectrum(a)) => cli::spectrum(&a),
        Some(Command::Predict(a)) => cli::predict(&a),
        Some(Command::Bias(a)) => cli::bias(&a),
        Some(Command::Report(a)) => cli::report(&a),
        Some(Command::Mc(a)) => cli::mc(&a),
        Some(Command::Rates(a)) => cli::rates(&a),
        Some(Command::RenderAo(a)) => cli::render_ao(&a),
        None => cli::default_job(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
