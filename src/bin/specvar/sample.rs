//! `specvar sample`: point sets as UTK text, UTK binary or JSON.

use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::sampler::{draw_realizations, SamplerKind};
use specvar::Result;
use std::path::PathBuf;

/// Arguments of `specvar sample`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Sampler name (see `specvar samplers`).
    #[arg(long, short = 's')]
    pub sampler: SamplerKind,
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
    /// How each realization is randomized: none (as drawn), shift (a random toroidal shift),
    /// digital-shift (a random XOR of the binary digits), or native (the sampler's own).
    #[arg(long, default_value = "none")]
    pub randomization: RandomizationChoice,
    /// Apply a random toroidal shift to each realization: the same as --randomization shift.
    #[arg(long, conflicts_with = "randomization")]
    pub homogenize: bool,
    /// Output file (standard output if absent).
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Write JSON instead of UTK text.
    #[arg(long, conflicts_with = "binary")]
    pub json: bool,
    /// Write UTK's binary format (doubles, "UTK!" header) to the output file.
    #[arg(long, requires = "output")]
    pub binary: bool,
}

/// Writes the realizations.
pub fn run(args: &Args, ctx: &super::Context) -> Result<()> {
    // Formatted text, besides the sets the library holds.
    let coordinates = args.realizations as f64 * args.n as f64 * args.dimension as f64;
    let text = coordinates * specvar::io::TEXT_BYTES_PER_COORDINATE;
    ctx.budget.check(
        "writing the points",
        specvar::budget::Needs::memory(text),
        "lower N or the realizations",
    )?;
    let sampler = ctx.sampler(args.sampler, args.dimension)?;
    let sets = draw_realizations(
        sampler.as_ref(),
        args.n,
        args.seed,
        0..args.realizations,
        match args.homogenize {
            true => Randomization::Shift,
            false => args
                .randomization
                .resolve(args.sampler.native_randomization()),
        },
        &ctx.budget,
    )?;
    if args.binary {
        let bytes = specvar::io::write_utk_binary(&sets)?;
        let path = args
            .output
            .as_deref()
            .unwrap_or(std::path::Path::new("points.bin"));
        return specvar::output::write_atomic(path, &bytes);
    }
    let text = if args.json {
        specvar::io::write_json(&sets)? + "\n"
    } else {
        specvar::io::write_text(&sets)
    };
    super::write_output(args.output.as_deref(), &text)
}
