//! Progress reporting for long routines, without drawing anything.
//!
//! Long library routines take a `&dyn Progress` and tell it which stage they are in and how far
//! it has got; the command line turns that into progress bars, a notebook could print it, and
//! [`Silent`] ignores it. The library itself never writes to the terminal.

/// Receives the progress of a long computation. Every method has an empty default, so an
/// observer implements only what it shows. Called from several threads at once.
pub trait Progress: Sync {
    /// A stage of `total` steps begins (`total = 0`: unknown length).
    fn begin(&self, stage: &str, total: u64) {
        let _ = (stage, total);
    }
    /// `steps` more steps of the current stage are done.
    fn advance(&self, steps: u64) {
        let _ = steps;
    }
    /// The current stage is done.
    fn end(&self) {}
}

/// Shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {}

/// Runs `work` as one stage of `total` steps of `progress`, ending the stage whatever happens.
pub(crate) fn stage<T>(
    progress: &dyn Progress,
    name: &str,
    total: u64,
    work: impl FnOnce() -> T,
) -> T {
    progress.begin(name, total);
    let out = work();
    progress.end();
    out
}
