//! Progress display on standard error (hidden when it is not a terminal).

use indicatif::{ProgressBar, ProgressStyle};

/// A bar for `len` steps of `stage`.
pub fn bar(len: u64, stage: impl Into<String>) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(
            "{msg:40} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    bar.set_message(stage.into());
    bar
}

/// A spinner for a stage of unknown length.
pub fn spinner(stage: impl Into<String>) -> ProgressBar {
    let bar = ProgressBar::new_spinner();
    bar.set_message(stage.into());
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    bar
}
