//! The `specvar` command line: each subcommand parses its arguments, makes one library call and
//! prints the result. Every decision of substance (routes, reference N, lattice extents,
//! pools) is the library's.

/// `println!` that returns a [`specvar::Error`] instead of panicking when standard output fails
/// (a full device); a closed pipe ends the process quietly (see [`quiet_on_closed_pipe`]).
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*).map_err($crate::stdout_error)
    }};
}

/// `print!` that returns a [`specvar::Error`] instead of panicking, as [`outln!`].
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*).map_err($crate::stdout_error)
    }};
}

mod anisotropy;
mod atlas;
mod bars;
mod bias;
mod mc;
mod metrics;
mod padded;
mod patterns;
mod plan;
mod predict;
mod problem;
mod rates;
mod render_ao;
mod report;
mod sample;
mod samplers;
mod spectrum;

use clap::{Parser, Subcommand};
use specvar::budget::Budget;
use specvar::sampler::{Sampler, SamplerKind};
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
    /// Memory a computation may use, in GiB (checked before it starts) [default: 8].
    #[arg(long, global = true)]
    budget_memory: Option<f64>,
    /// Work a computation may do, in seconds of one core (estimated before it starts)
    /// [default: 3600].
    #[arg(long, global = true)]
    budget_seconds: Option<f64>,
    /// Draw every pattern anew instead of reading costly ones (CCVT, Poisson disk) from the
    /// cache directory ($SPECVAR_CACHE_DIR, else the user's cache directory).
    #[arg(long, global = true)]
    no_cache: bool,
}

/// What every subcommand receives besides its own arguments.
pub struct Context {
    /// The budget.
    pub budget: Budget,
    /// The cache directory, unless --no-cache.
    pub cache: Option<std::path::PathBuf>,
}

impl Context {
    /// A sampler by kind, its costly patterns cached.
    pub fn sampler(&self, kind: SamplerKind, d: usize) -> specvar::Result<Box<dyn Sampler>> {
        specvar::cache::cached_sampler(
            kind,
            d,
            self.cache.as_deref(),
            specvar::cache::PATTERN_MEMORY,
        )
    }
}

#[derive(Subcommand)]
enum Command {
    /// List the samplers with their dimensions and N constraints.
    Samplers(samplers::Args),
    /// Write point sets (UTK text by default, or JSON).
    Sample(sample::Args),
    /// Power spectrum of a sampler or of point sets from a file: lattice or radial.
    Spectrum(spectrum::Args),
    /// Predict the variance of a sampler's estimator (as it is used, or randomized as asked)
    /// from spectra, cells or Walsh sums.
    Predict(predict::Args),
    /// How many samples: for each sampler, the smallest N whose predicted RMSE reaches a
    /// target.
    Plan(plan::Args),
    /// The variance of a 4D integrand under two 2D patterns padded together (a pixel with
    /// antialiasing and a light sample).
    Padded(padded::Args),
    /// Bias of a fixed (not homogenized) pattern, from its spectrum and directly.
    Bias(bias::Args),
    /// Reproduce the talk's table with predictions, Monte Carlo, plots and report.md.
    Report(report::Args),
    /// Monte Carlo variance of the estimator, with a 99% interval.
    Mc(mc::Args),
    /// Discrepancies, distances, effective Nyquist frequency and pair correlation function.
    Metrics(metrics::Args),
    /// Every 2D sampler on one page: points, spectra, α, ν_eff, PCF, discrepancies, predicted
    /// variance beside Monte Carlo.
    Atlas(atlas::Args),
    /// The variance of an edge against its angle: predicted from the sampler's 2D spectrum and
    /// measured by Monte Carlo.
    Anisotropy(anisotropy::Args),
    /// Convergence rates: theory, predicted from spectra, measured by Monte Carlo.
    Rates(rates::Args),
    /// Render ambient occlusion with a sampler (or all): image, MSE, MSE predicted from spectra.
    RenderAo(render_ao::Args),
}

fn main() -> ExitCode {
    quiet_on_closed_pipe();
    let parsed = match parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                return finish(out!("{e}").and_then(|()| flush_stdout()));
            }
            // One clear line: clap's first line names the problem, and where it ends with a
            // colon (missing arguments), the next line names what is missing.
            let text = e.to_string();
            let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
            let first = lines.next().unwrap_or("invalid arguments");
            match lines.next() {
                Some(next) if first.ends_with(':') => eprintln!("{first} {next}"),
                _ => eprintln!("{first}"),
            }
            return ExitCode::from(2);
        }
    };
    let result = context(&parsed).and_then(|ctx| match parsed.command {
        Some(Command::Samplers(a)) => samplers::run(&a),
        Some(Command::Sample(a)) => sample::run(&a, &ctx),
        Some(Command::Spectrum(a)) => spectrum::run(&a, &ctx),
        Some(Command::Predict(a)) => predict::run(&a, &ctx),
        Some(Command::Plan(a)) => plan::run(&a, &ctx),
        Some(Command::Padded(a)) => padded::run(&a, &ctx),
        Some(Command::Bias(a)) => bias::run(&a, &ctx),
        Some(Command::Report(a)) => report::run(&a, &ctx),
        Some(Command::Mc(a)) => mc::run(&a, &ctx),
        Some(Command::Metrics(a)) => metrics::run(&a, &ctx),
        Some(Command::Atlas(a)) => atlas::run(&a, &ctx),
        Some(Command::Anisotropy(a)) => anisotropy::run(&a, &ctx),
        Some(Command::Rates(a)) => rates::run(&a, &ctx),
        Some(Command::RenderAo(a)) => render_ao::run(&a, &ctx),
        None => report::run(&report::Args::default(), &ctx),
    });
    finish(result.and_then(|()| flush_stdout()))
}

/// The command line parsed, with negative numbers taken as values on every command, so that
/// `-n -1` reaches the option that refuses it instead of reading as an unknown flag.
fn parse() -> Result<Cli, clap::Error> {
    use clap::{CommandFactory, FromArgMatches};
    let command = Cli::command()
        .allow_negative_numbers(true)
        .mut_subcommands(|sub| sub.allow_negative_numbers(true));
    command
        .try_get_matches()
        .and_then(|matches| Cli::from_arg_matches(&matches))
}

/// The exit code of a run: success; quiet success when standard output was closed by its
/// reader (as `cat` and `grep` end); otherwise one error line and 2.
fn finish(result: specvar::Result<()>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(specvar::Error::Io { source, .. })
            if source.kind() == std::io::ErrorKind::BrokenPipe =>
        {
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

/// Lets a write to a closed pipe end the process as it ends `cat` (by the default action of
/// SIGPIPE, which Rust's runtime ignores so that writes fail with `BrokenPipe` instead; where
/// that cannot be set, [`finish`] ends quietly on `BrokenPipe`).
fn quiet_on_closed_pipe() {
    #[cfg(target_os = "linux")]
    // SAFETY: resetting a signal's disposition to its default has no preconditions, and it
    // runs before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// The error of a failed write to standard output.
fn stdout_error(e: std::io::Error) -> specvar::Error {
    specvar::Error::io(Path::new("standard output"), e)
}

/// Flushes standard output, so that a full device is reported rather than lost at exit.
fn flush_stdout() -> specvar::Result<()> {
    use std::io::Write;
    std::io::stdout().flush().map_err(stdout_error)
}

/// The context from the global flags.
fn context(cli: &Cli) -> specvar::Result<Context> {
    let defaults = Budget::default();
    let positive = |name: &'static str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(specvar::Error::InvalidParameter {
                name,
                value: v.to_string(),
                allowed: "a positive number".into(),
            })
        }
    };
    let budget = Budget {
        memory_bytes: match cli.budget_memory {
            Some(gib) => positive("budget memory", gib)? * (1u64 << 30) as f64,
            None => defaults.memory_bytes,
        },
        work_seconds: match cli.budget_seconds {
            Some(s) => positive("budget seconds", s)?,
            None => defaults.work_seconds,
        },
    };
    let cache = (!cli.no_cache).then(specvar::cache::default_dir);
    if let Some(dir) = &cache
        && let Err(e) = specvar::cache::check_writable(dir)
    {
        eprintln!("warning: {e}; costly patterns and references will be drawn anew");
    }
    Ok(Context { budget, cache })
}

/// Writes `text` atomically to a file, or to standard output when `path` is `None`.
fn write_output(path: Option<&Path>, text: &str) -> specvar::Result<()> {
    use std::io::Write;
    match path {
        Some(p) => specvar::output::write_atomic(p, text.as_bytes()),
        None => std::io::stdout()
            .write_all(text.as_bytes())
            .map_err(stdout_error),
    }
}

/// Serializes `value` as one line of JSON.
fn to_json(value: &impl serde::Serialize) -> specvar::Result<String> {
    serde_json::to_string(value).map_err(|e| specvar::Error::format("JSON output", e))
}
