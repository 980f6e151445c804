//! The crate's single error type.

use std::path::Path;
use std::sync::Arc;
use thiserror::Error;

/// Every failure the library reports. Messages say what was wrong and what is allowed.
#[derive(Debug, Error, Clone)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is outside its allowed range.
    #[error("invalid {name}: {value} ({allowed})")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// The offending value, as text.
        value: String,
        /// What is allowed.
        allowed: String,
    },
    /// The sampler does not support this dimension.
    #[error("sampler '{sampler}' does not support dimension {dimension} (supported: {supported})")]
    UnsupportedDimension {
        /// Sampler name.
        sampler: &'static str,
        /// Requested dimension.
        dimension: usize,
        /// Supported dimensions, as text.
        supported: String,
    },
    /// The sampler cannot produce this number of points.
    #[error("sampler '{sampler}' cannot produce N = {n} in dimension {dimension}: {rule}; nearest: {nearest}")]
    UnsupportedCount {
        /// Sampler name.
        sampler: &'static str,
        /// Requested N.
        n: usize,
        /// Dimension.
        dimension: usize,
        /// The rule N must follow.
        rule: String,
        /// The nearest N it can produce, as text.
        nearest: String,
    },
    /// A dart thrower filled the domain before reaching N points.
    #[error("Poisson disk ({method}) placed only {placed} of {requested} points at radius {radius:.6} before the torus was full; lower the relative radius")]
    Saturated {
        /// Generator name.
        method: &'static str,
        /// Points placed.
        placed: usize,
        /// Points requested.
        requested: usize,
        /// Minimum distance in use.
        radius: f64,
    },
    /// A constructive generator found no valid place for its next point.
    #[error("{generator} found no valid place for point {placed} of {requested}: {reason}")]
    Stuck {
        /// Generator name.
        generator: &'static str,
        /// Points placed.
        placed: usize,
        /// Points requested.
        requested: usize,
        /// Which constraint could not be met.
        reason: String,
    },
    /// A file or text could not be parsed.
    #[error("line {line}: {message}")]
    Parse {
        /// 1-based line number.
        line: usize,
        /// What was wrong.
        message: String,
    },
    /// Point sets, spectra or integrands that must agree do not.
    #[error("mismatch: {0}")]
    Mismatch(String),
    /// A route of prediction asked for outside the domain where it is valid.
    #[error("{route} is not valid here: {reason}")]
    OutsideValidity {
        /// The route asked for.
        route: String,
        /// Which of its assumptions fails, and what to use instead.
        reason: String,
    },
    /// A grid that tabulates a finer function too coarsely for the sampler at N: its coarser
    /// levels cannot show the variance (a finer tabulation, or a grid declared exact, can).
    #[error(
        "the tabulated grid {grid} is too coarse for the sampler at N = {n}: {cells} cells per \
         axis, where its coarser averages must resolve {what}, which needs at least {needed} \
         cells per axis; tabulate the function that finely, or declare the grid the function \
         itself (grid:FILE,exact)"
    )]
    TabulationTooCoarse {
        /// The grid's label.
        grid: String,
        /// The points per pattern.
        n: usize,
        /// Its cells along its narrower side.
        cells: usize,
        /// What the coarser levels must resolve.
        what: String,
        /// The cells per axis needed.
        needed: usize,
    },
    /// A computation would need more memory or work than the budget allows.
    #[error("{what} would need {needed}, above the budget of {budget}; {advice}")]
    TooLarge {
        /// What would be computed.
        what: String,
        /// The memory or work it needs, in words.
        needed: String,
        /// The budget, in words.
        budget: String,
        /// What to lower (or how to raise the budget).
        advice: String,
    },
    /// A target error that no admitted N up to the limit reaches.
    #[error("{sampler} does not reach an RMSE of {target:.4e} within {limit}: the largest N it allows is {largest_n}, where the predicted RMSE is {rmse:.4e}")]
    Unreachable {
        /// The sampler.
        sampler: String,
        /// The target RMSE.
        target: f64,
        /// What limits N, in words.
        limit: String,
        /// The largest N the limit allows.
        largest_n: usize,
        /// The predicted RMSE there.
        rmse: f64,
    },
    /// The system refused memory that the budget allowed (an allocation failed).
    #[error("{what} could not allocate {needed}: the system has less memory free than the budget allows; lower the size or --budget-memory")]
    OutOfMemory {
        /// What was being allocated.
        what: String,
        /// The size asked for, in words.
        needed: String,
    },
    /// An output would replace a file that specvar did not write.
    #[error("{path} exists and was not written by specvar (it is not in {manifest}); move it, or choose another output directory")]
    WouldOverwrite {
        /// The file that would be replaced.
        path: String,
        /// The manifest that lists specvar's own files in that directory.
        manifest: String,
    },
    /// A result that cannot be represented (infinite or not a number), with the reason.
    #[error("no finite answer: {0}")]
    NotFinite(String),
    /// An input/output failure, with the path or stream it concerns.
    #[error("{context}: {source}")]
    Io {
        /// The file, directory or stream.
        context: String,
        /// The operating system's error.
        #[source]
        source: Arc<std::io::Error>,
    },
    /// Data that could not be encoded or decoded (JSON, PNG, plots).
    #[error("{context}: {message}")]
    Format {
        /// What was being encoded or decoded.
        context: String,
        /// The encoder's or decoder's message.
        message: String,
    },
}

impl Error {
    /// An I/O error about `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io {
            context: path.display().to_string(),
            source: Arc::new(source),
        }
    }

    /// A format error about `context`.
    pub fn format(context: impl Into<String>, message: impl std::fmt::Display) -> Self {
        Error::Format {
            context: context.into(),
            message: message.to_string(),
        }
    }
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Error::Io {
            context: "i/o".into(),
            source: Arc::new(e),
        }
    }
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, Error>;

/// Shorthand for an [`Error::InvalidParameter`].
pub(crate) fn invalid(name: &'static str, value: impl ToString, allowed: impl ToString) -> Error {
    Error::InvalidParameter {
        name,
        value: readable(value.to_string()),
        allowed: allowed.to_string(),
    }
}

/// `value` if it is finite, else [`Error::NotFinite`] saying what it was.
pub(crate) fn finite(value: f64, what: impl FnOnce() -> String) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::NotFinite(what()))
    }
}

/// A value as a reader wants it: a number with a long decimal expansion (`1e-300` prints as
/// 300 digits) in exponent notation, anything else as it is.
fn readable(value: String) -> String {
    match value.parse::<f64>() {
        Ok(x) if (value.len() > 15 && value.contains('.')) || value.len() > 24 => format!("{x:e}"),
        // A small number printed in full (`0.0000001`) is read back in the form typed.
        Ok(x) if x != 0.0 && x.abs() < 1e-4 && value.contains('.') => format!("{x:e}"),
        _ => value,
    }
}

/// A token of the user's input quoted for a message: control characters escaped (a binary
/// file read as text must not drive the terminal) and at most 40 characters.
pub(crate) fn quoted(token: &str) -> String {
    let mut escaped: String = token
        .chars()
        .flat_map(char::escape_debug)
        .take(40)
        .collect();
    if token.chars().flat_map(char::escape_debug).nth(40).is_some() {
        escaped.push('…');
    }
    format!("'{escaped}'")
}
