//! The arguments that name an integration problem, shared by `predict` and `mc`.

use specvar::integrand::{Integrand, IntegrandSpec};
use specvar::io::read_file;
use specvar::pointset::PointSet;
use specvar::randomization::{Randomization, RandomizationChoice};
use specvar::sampler::{native_randomization, Sampler, SamplerKind};
use specvar::Result;
use std::path::PathBuf;

/// Sampler (or point-set file), integrand, N and dimension.
#[derive(Debug, clap::Args)]
pub struct ProblemArgs {
    /// Sampler name (see `specvar samplers`).
    #[arg(
        long,
        short = 's',
        required_unless_present = "input",
        conflicts_with = "input"
    )]
    pub sampler: Option<SamplerKind>,
    /// Point sets of your own (UTK text or JSON): every realization in the file, of one N,
    /// is a pattern of the sampler that produced them.
    #[arg(long)]
    pub input: Option<PathBuf>,
    // The forms are the library's own list, so that the help names every one it accepts.
    #[arg(long, short = 'f', help = format!("Integrand: {} [default: disk]", specvar::integrand::INTEGRAND_FORMS))]
    pub integrand: Option<IntegrandSpec>,
    /// Points per pattern (with --input: taken from the file).
    #[arg(short = 'n', required_unless_present = "input")]
    pub n: Option<usize>,
    /// Dimension (with --input: taken from the file).
    #[arg(short = 'd', default_value_t = 2)]
    pub dimension: usize,
    /// How each pattern is randomized, which decides the estimator: native (the default: the
    /// sampler's own use, as drawn for strata, nets and random samplers, under a shift for
    /// fixed rules; as given for --input), shift (a random toroidal shift: the homogenized
    /// estimator of the talk), digital-shift (a random XOR of the binary digits), or none (the
    /// patterns as drawn, or as given).
    #[arg(long, default_value = "native")]
    pub randomization: RandomizationChoice,
}

/// What the arguments name: the patterns' source, the integrand, N.
pub enum Source {
    /// A sampler.
    Sampler(SamplerKind, Box<dyn Sampler>),
    /// Point sets read from a file.
    Sets(PathBuf, Vec<PointSet>),
}

impl ProblemArgs {
    /// The integrand named, or the disk.
    pub fn integrand(&self) -> IntegrandSpec {
        self.integrand.clone().unwrap_or_default()
    }

    /// Builds the sampler or reads the file, and builds the integrand in its dimension.
    pub fn build(&self, ctx: &super::Context) -> Result<(Source, Box<dyn Integrand>, usize)> {
        match (&self.input, self.sampler) {
            (Some(path), _) => {
                let sets = read_file(path)?;
                let (d, n) = (sets[0].dimension(), sets[0].len());
                let f = self.integrand().build(d)?;
                Ok((Source::Sets(path.clone(), sets), f, n))
            }
            (None, Some(kind)) => {
                let n = self.n.unwrap_or_default();
                let sampler = ctx.sampler(kind, self.dimension)?;
                sampler.check_count(n)?;
                let f = self.integrand().build(self.dimension)?;
                Ok((Source::Sampler(kind, sampler), f, n))
            }
            (None, None) => unreachable!("clap requires --sampler or --input"),
        }
    }
}

impl Source {
    /// The randomization `choice` names for these patterns: a sampler's native one, or for
    /// given sets their use as given.
    pub fn randomization(&self, choice: RandomizationChoice) -> Randomization {
        choice.resolve(native_randomization(match self {
            Source::Sampler(kind, _) => Some(*kind),
            Source::Sets(..) => None,
        }))
    }

    /// The sampler's name or the file's path.
    pub fn label(&self) -> String {
        match self {
            Source::Sampler(kind, _) => kind.to_string(),
            Source::Sets(path, _) => path.display().to_string(),
        }
    }
}
