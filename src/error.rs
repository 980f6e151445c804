//! The crate's single error type.

use thiserror::Error;

/// Every failure the library reports. Messages say what was wrong and what is allowed.
#[derive(Debug, Error, Clone, PartialEq)]
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
    /// A file or text could not be parsed.
    #[error("line {line}: {message}")]
    Parse {
        /// 1-based line number.
        line: usize,
        /// What was wrong.
        message: String,
    },
    /// Point sets or spectra that must agree do not.
    #[error("mismatch: {0}")]
    Mismatch(String),
    /// An input/output failure.
    #[error("i/o error: {0}")]
    Io(String),
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Error::Io(e.to_string())
    }
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, Error>;

/// Shorthand for an [`Error::InvalidParameter`].
pub(crate) fn invalid(name: &'static str, value: impl ToString, allowed: impl ToString) -> Error {
    Error::InvalidParameter {
        name,
        value: value.to_string(),
        allowed: allowed.to_string(),
    }
}
