//! A progress bar that stays out of the way: nothing for runs shorter than half a second, nothing
//! when stderr is not a terminal (logs, pipes, tests) or with `-q`.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Runs shorter than this finish before a bar would be readable, so it would only flicker.
const SHOW_AFTER: Duration = Duration::from_millis(500);

/// Progress of the current phase (reading bytes, extracting layers). Shared by reference with the
/// extractor's worker threads, hence `Sync` and `&self` everywhere.
pub struct Progress {
    bar: ProgressBar,
    wanted: bool,
    shown: AtomicBool,
    started: Instant,
}

impl Progress {
    /// A bar that shows itself after [`SHOW_AFTER`] if `enabled` and stderr is a terminal.
    pub fn new(enabled: bool) -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(
            "{msg:>10} [{elapsed_precise}] {wide_bar} {percent:>3}% eta {eta}",
        ) {
            bar.set_style(style);
        }
        Progress {
            bar,
            wanted: enabled && std::io::stderr().is_terminal(),
            shown: AtomicBool::new(false),
            started: Instant::now(),
        }
    }

    /// A bar that never shows, for library callers and tests.
    pub fn hidden() -> Self {
        Progress::new(false)
    }

    /// Starts a phase of `total` units.
    pub fn phase(&self, label: &'static str, total: u64) {
        self.bar.set_message(label);
        self.bar.set_length(total);
        self.bar.set_position(0);
    }

    /// Records `n` more units done.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
        if self.wanted
            && !self.shown.load(Ordering::Relaxed)
            && self.started.elapsed() > SHOW_AFTER
            && !self.shown.swap(true, Ordering::Relaxed)
        {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }

    /// Removes the bar before the summary is printed.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
