//! How long work reports how far it has got, without this crate choosing how that is shown: the
//! command line draws a bar, Python may call back, tests and libraries ignore it.

/// Receives progress of the current phase (reading bytes, extracting layers). Shared by reference
/// with the extractor's worker threads, hence `Sync` and `&self`.
pub trait Progress: Sync {
    /// Starts a phase of `total` units.
    fn phase(&self, label: &'static str, total: u64);
    /// Records `n` more units done.
    fn inc(&self, n: u64);
}

/// Progress that goes nowhere.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {
    fn phase(&self, _: &'static str, _: u64) {}
    fn inc(&self, _: u64) {}
}
