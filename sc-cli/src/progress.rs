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
/// progress like reading and meshing do. The writers hand it fields of a few bytes at a time;
/// it tells the bar only every 64 KiB, since each report reads the clock twice: reported per
/// write, progress would cost many times the write itself.
pub struct Counted<'a, W> {
    inner: W,
    progress: &'a dyn Progress,
    /// Bytes written and not yet reported.
    unreported: u64,
}

/// Bytes between two reports: a bar's hundredth of any mesh worth a bar.
const REPORT_EVERY: u64 = 1 << 16;

impl<'a, W: std::io::Write> Counted<'a, W> {
    /// Counts what goes to `inner` into `progress`.
    pub fn new(inner: W, progress: &'a dyn Progress) -> Self {
        Counted {
            inner,
            progress,
            unreported: 0,
        }
    }

    fn report(&mut self) {
        self.progress.inc(self.unreported);
        self.unreported = 0;
    }
}

impl<W: std::io::Write> std::io::Write for Counted<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.unreported += n as u64;
        if self.unreported >= REPORT_EVERY {
            self.report();
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.report();
        self.inner.flush()
    }
}

#[cfg(test)]
mod tests {
    use std::io::Write;
    use std::sync::atomic::{AtomicU64, Ordering};

    use super::*;

    /// Counts reports and their bytes.
    #[derive(Default)]
    struct Tally {
        reports: AtomicU64,
        bytes: AtomicU64,
    }

    impl Progress for Tally {
        fn phase(&self, _: &'static str, _: u64) {}
        fn inc(&self, n: u64) {
            self.reports.fetch_add(1, Ordering::Relaxed);
            self.bytes.fetch_add(n, Ordering::Relaxed);
        }
    }

    /// Every byte is reported by the time the writer is flushed, in a report per
    /// `REPORT_EVERY` bytes or so rather than one per write.
    #[test]
    fn reports_every_byte_in_few_reports() {
        let tally = Tally::default();
        let mut out = Vec::new();
        let mut counted = Counted::new(&mut out, &tally);
        for i in 0..100_000u32 {
            counted.write_all(&i.to_le_bytes()).unwrap();
        }
        counted.write_all(b"tail").unwrap();
        counted.flush().unwrap();
        assert_eq!(out.len(), 400_004);
        assert_eq!(tally.bytes.load(Ordering::Relaxed), 400_004);
        let reports = tally.reports.load(Ordering::Relaxed);
        assert!((6..=8).contains(&reports), "{reports} reports");
    }
}
