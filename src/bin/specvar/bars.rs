//! Progress on standard error, drawn from the library's progress events: bars on a terminal;
//! elsewhere (a log file, a pipe, CI) one line per finished stage that took a second or more, so
//! that a long run shows where it is without bars' control characters.

use indicatif::{ProgressBar, ProgressStyle};
use specvar::progress::Progress;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// One bar (or spinner, for a stage of unknown length) at a time.
#[derive(Default)]
pub struct Bars {
    current: Mutex<Option<ProgressBar>>,
    /// Without a terminal: the stage in progress and when it began.
    plain: Mutex<Option<(String, Instant)>>,
}

/// Stages shorter than this print no line without a terminal.
const PLAIN_LINE_AFTER: Duration = Duration::from_secs(1);

fn terminal() -> bool {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal()
}

impl Bars {
    fn slot(&self) -> std::sync::MutexGuard<'_, Option<ProgressBar>> {
        // A panic elsewhere cannot leave a bar in an inconsistent state worth refusing.
        self.current.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn plain_slot(&self) -> std::sync::MutexGuard<'_, Option<(String, Instant)>> {
        self.plain.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Bars {
    /// Prints the stage that just finished, if it was long enough to be worth a line.
    fn finish_plain(&self) {
        let finished = self.plain_slot().take();
        if let Some((stage, start)) = finished {
            let took = start.elapsed();
            if took >= PLAIN_LINE_AFTER {
                eprintln!("{stage}: {:.1} s", took.as_secs_f64());
            }
        }
    }
}

impl Progress for Bars {
    fn begin(&self, stage: &str, total: u64) {
        if !terminal() {
            self.finish_plain();
            *self.plain_slot() = Some((stage.to_string(), Instant::now()));
            return;
        }
        let bar = if total > 0 {
            let bar = ProgressBar::new(total);
            bar.set_style(
                ProgressStyle::with_template(
                    "{msg:40} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta})",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            bar
        } else {
            let spinner = ProgressBar::new_spinner();
            spinner.enable_steady_tick(Duration::from_millis(120));
            spinner
        };
        bar.set_message(stage.to_string());
        if let Some(old) = self.slot().replace(bar) {
            old.finish_and_clear();
        }
    }

    fn advance(&self, steps: u64) {
        if let Some(bar) = self.slot().as_ref() {
            bar.inc(steps);
        }
    }

    fn end(&self) {
        self.finish_plain();
        if let Some(bar) = self.slot().take() {
            bar.finish_and_clear();
        }
    }
}
