//! Progress bars (`--progress`) that the library's callbacks drive.

use indicatif::{ProgressBar, ProgressStyle};
use ktree::stacking::{Progress, Stage};

/// A progress bar that the library's callbacks can drive, or none.
pub fn progress_bar(enabled: bool, what: &str) -> Option<ProgressBar> {
    enabled.then(|| {
        let bar = ProgressBar::new(1);
        bar.set_style(
            ProgressStyle::with_template("{msg} [{bar:40}] {percent}% {elapsed}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_message(what.to_string());
        bar
    })
}

/// Shows the progress of an out-of-core build on `bar`, if any.
pub fn report_progress(bar: Option<&ProgressBar>, p: Progress) {
    let Some(bar) = bar else {
        return;
    };
    let message = match p.stage {
        Stage::Stacking => "stacking slabs",
        Stage::Writing => "writing levels",
    };
    if bar.length() != Some(p.total) || bar.message() != message {
        bar.set_message(message);
        bar.set_length(p.total);
        bar.reset_elapsed();
    }
    bar.set_position(p.done);
}
