//! What a computation may spend, checked before it starts: every entry point estimates the
//! memory and the work its parameters imply and refuses, with an error that says what it would
//! need and what to lower, above the budget. The default is 8 GiB and one hour of one core's
//! work; parameters (and the command line's `--budget-memory`, `--budget-seconds`) raise it.

use crate::error::{Error, Result};
use serde::Serialize;

/// Memory and work a computation may spend.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Budget {
    /// Bytes.
    pub memory_bytes: f64,
    /// Seconds of one core's work, as estimated from measured costs (the estimates are rough:
    /// they tell an afternoon from a minute, not a minute from two).
    pub work_seconds: f64,
}

/// The default memory budget: 8 GiB.
pub const DEFAULT_MEMORY_BYTES: f64 = 8.0 * GIB;
/// The default work budget: one hour of one core.
pub const DEFAULT_WORK_SECONDS: f64 = 3600.0;

impl Default for Budget {
    fn default() -> Self {
        Self {
            memory_bytes: DEFAULT_MEMORY_BYTES,
            work_seconds: DEFAULT_WORK_SECONDS,
        }
    }
}

const GIB: f64 = (1u64 << 30) as f64;

/// What a computation is estimated to need.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Needs {
    /// Bytes held at once.
    pub memory_bytes: f64,
    /// Seconds of one core's work.
    pub work_seconds: f64,
}

impl Needs {
    /// Memory only.
    pub fn memory(bytes: f64) -> Self {
        Self {
            memory_bytes: bytes,
            work_seconds: 0.0,
        }
    }

    /// Work only.
    pub fn work(seconds: f64) -> Self {
        Self {
            memory_bytes: 0.0,
            work_seconds: seconds,
        }
    }

    /// Both needs together: memory at its larger, work added.
    pub fn and(self, other: Needs) -> Self {
        Self {
            memory_bytes: self.memory_bytes.max(other.memory_bytes),
            work_seconds: self.work_seconds + other.work_seconds,
        }
    }
}

impl Budget {
    /// Checks `needs` for `what`, naming the parameter to lower in the error.
    ///
    /// # Errors
    /// [`Error::TooLarge`] when either need exceeds the budget (or is not a number).
    ///
    /// # Examples
    /// ```
    /// use specvar::budget::{Budget, Needs};
    /// let huge = Needs::memory(1e15);
    /// let err = Budget::default().check("sampling 1e12 points", huge, "lower N").unwrap_err();
    /// assert!(err.to_string().contains("lower N"));
    /// ```
    pub fn check(&self, what: &str, needs: Needs, advice: &str) -> Result<()> {
        let memory_ok = needs.memory_bytes <= self.memory_bytes;
        let work_ok = needs.work_seconds <= self.work_seconds;
        if memory_ok && work_ok {
            return probe(what, needs.memory_bytes);
        }
        let (needed, budget) = if !memory_ok {
            (bytes(needs.memory_bytes), bytes(self.memory_bytes))
        } else {
            (seconds(needs.work_seconds), seconds(self.work_seconds))
        };
        Err(Error::TooLarge {
            what: what.to_string(),
            needed,
            budget,
            advice: format!(
                "{advice}, or raise the budget (--budget-memory and --budget-seconds on the \
                 command line, set_budget in Python)"
            ),
        })
    }
}

/// Asks the system for `bytes` of address space and gives it back at once (no page is
/// touched): a system that would refuse the memory later (a limit on the address space, no
/// overcommit) refuses it here, as [`Error::OutOfMemory`], before the work starts, instead of
/// aborting the process in the middle of it.
fn probe(what: &str, bytes: f64) -> Result<()> {
    if bytes < PROBE_FROM {
        return Ok(());
    }
    let mut reserve: Vec<u8> = Vec::new();
    reserve
        .try_reserve_exact(bytes as usize)
        .map_err(|_| out_of_memory(what, bytes))
}

/// The error of an allocation of `bytes` for `what` that the system refused.
fn out_of_memory(what: &str, bytes: f64) -> Error {
    Error::OutOfMemory {
        what: what.to_string(),
        needed: self::bytes(bytes),
    }
}

/// Needs below 16 MiB are not probed: the process's own allocations are of that order.
const PROBE_FROM: f64 = (16u64 << 20) as f64;

/// A size in words: MiB below a GiB, GiB above, with at most three significant digits (very
/// large sizes in exponent notation).
pub fn bytes(b: f64) -> String {
    if !b.is_finite() {
        return "an unbounded amount of memory".into();
    }
    if b >= 1e6 * GIB {
        format!("{:.2e} GiB", b / GIB)
    } else if b >= GIB {
        format!("{:.1} GiB", b / GIB)
    } else {
        format!("{:.0} MiB", b / (1u64 << 20) as f64)
    }
}

/// A work estimate in words: `about 6 minutes of work`, `about 0.05 s of work`.
pub fn seconds(s: f64) -> String {
    if !s.is_finite() {
        "unbounded work".into()
    } else if s >= 3.6e9 {
        format!("about {:.1e} hours of work", s / 3600.0)
    } else if s >= 7200.0 {
        format!("about {:.0} hours of work", s / 3600.0)
    } else if s >= 120.0 {
        format!("about {:.0} minutes of work", s / 60.0)
    } else if s >= 10.0 {
        format!("about {s:.0} s of work")
    } else {
        format!("about {s:.2} s of work")
    }
}

/// A vector of `len` copies of `value`, allocated fallibly: a refusal by the system becomes
/// [`Error::OutOfMemory`] naming `what`, instead of aborting the process. Sizes that overflow
/// the address space are refused the same way.
///
/// # Errors
/// [`Error::OutOfMemory`] when the allocation fails.
///
/// # Examples
/// ```
/// let v = specvar::budget::try_filled(4, 0.0f64, "a small buffer")?;
/// assert_eq!(v, vec![0.0; 4]);
/// assert!(specvar::budget::try_filled(usize::MAX / 2, 0.0f64, "a huge buffer").is_err());
/// # Ok::<(), specvar::Error>(())
/// ```
pub fn try_filled<T: Clone>(len: usize, value: T, what: &str) -> Result<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len)
        .map_err(|_| out_of_memory(what, len as f64 * std::mem::size_of::<T>() as f64))?;
    v.resize(len, value);
    Ok(v)
}
