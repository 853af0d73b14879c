//! The per-scene progress bar of every command that walks a dataset (evaluation, the
//! baseline, prediction).

use indicatif::{ProgressBar, ProgressStyle};

/// A progress bar on stderr, hidden when `quiet` (indicatif also hides it off a terminal).
pub fn progress(len: usize, message: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template(
        "{msg} [{bar:30}] {pos}/{len} scenes, {elapsed_precise} (eta {eta})",
    )
    .expect("valid template")
    .progress_chars("=> ");
    ProgressBar::new(len as u64)
        .with_style(style)
        .with_message(message.to_string())
}
