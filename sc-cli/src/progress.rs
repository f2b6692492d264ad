//! A progress bar that stays out of the way: nothing for runs shorter than half a second, nothing
//! when stderr is not a terminal (logs, pipes, tests) or with `-q`.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use sc_io::progress::Progress;

/// Runs shorter than this finish before a bar would be readable, so it would only flicker.
const SHOW_AFTER: Duration = Duration::from_millis(500);

/// A terminal progress bar for the current phase (reading bytes, extracting layers).
pub struct Bar {
    bar: ProgressBar,
    wanted: bool,
    shown: AtomicBool,
    started: Instant,
}

impl Bar {
    /// A bar that shows itself after `SHOW_AFTER` if `enabled` and stderr is a terminal.
    pub fn new(enabled: bool) -> Self {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        if let Ok(style) = ProgressStyle::with_template(
            "{msg:>10} [{elapsed_precise}] {wide_bar} {percent:>3}% eta {eta}",
        ) {
            bar.set_style(style);
        }
        Bar {
            bar,
            wanted: enabled && std::io::stderr().is_terminal(),
            shown: AtomicBool::new(false),
            started: Instant::now(),
        }
    }

    /// Removes the bar before the summary is printed.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Progress for Bar {
    fn phase(&self, label: &'static str, total: u64) {
        self.bar.set_message(label);
        self.bar.set_length(total);
        self.bar.set_position(0);
    }

    fn inc(&self, n: u64) {
        self.bar.inc(n);
        if self.wanted
            && !self.shown.load(Ordering::Relaxed)
            && self.started.elapsed() > SHOW_AFTER
            && !self.shown.swap(true, Ordering::Relaxed)
        {
            self.bar.set_draw_target(ProgressDrawTarget::stderr());
        }
    }
}

/// A writer that reports the bytes passing through it, so that writing a large mesh shows
/// progress like reading and meshing do.
pub struct Counted<'a, W> {
    inner: W,
    progress: &'a dyn Progress,
}

impl<'a, W: std::io::Write> Counted<'a, W> {
    /// Counts what goes to `inner` into `progress`.
    pub fn new(inner: W, progress: &'a dyn Progress) -> Self {
        Counted { inner, progress }
    }
}

impl<W: std::io::Write> std::io::Write for Counted<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.progress.inc(n as u64);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}
