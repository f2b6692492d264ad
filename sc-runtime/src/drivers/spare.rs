//! Scratch buffers kept between extractions, up to a budget.
//!
//! A sweep needs about 13 bytes per sample of a slice (1.8 MB for 256 × 256). Allocated afresh
//! for every extraction and freed with it, that scratch tips glibc's `malloc` into returning the
//! heap's top to the kernel after each call, so that the next call faults every page of its mesh
//! in again, which can double a small extraction's time. Kept here, an extraction allocates only
//! its mesh.

use std::sync::Mutex;
use std::vec::Vec;

use crate::Error;
use crate::mesh::OwnedScratch;

/// The process's spare scratch: enough for two threads on slices of about 1,500 × 1,500, or
/// sixteen threads on 512 × 512.
pub(crate) static SPARES: Spares = Spares::new(64 << 20);

/// Scratch buffers not in use, holding at most `budget` bytes in all.
pub(crate) struct Spares {
    list: Mutex<Vec<OwnedScratch>>,
    budget: usize,
}

impl Spares {
    pub const fn new(budget: usize) -> Self {
        Spares {
            list: Mutex::new(Vec::new()),
            budget,
        }
    }

    /// A scratch sized for `dims`: a spare one if there is one, else a new one.
    pub fn take(&self, dims: [usize; 3]) -> Result<OwnedScratch, Error> {
        let mut scratch = self.lock().pop().unwrap_or_default();
        scratch.fit(dims)?;
        Ok(scratch)
    }

    /// Keeps `scratch` for a later [`Spares::take`], unless that would exceed the budget.
    pub fn give(&self, scratch: OwnedScratch) {
        let mut list = self.lock();
        let held: usize = list.iter().map(OwnedScratch::bytes).sum();
        if held + scratch.bytes() <= self.budget {
            list.push(scratch);
        }
    }

    /// The list, even after a panic elsewhere while it was held: a list of spare buffers is
    /// valid in any state.
    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<OwnedScratch>> {
        self.list.lock().unwrap_or_else(|p| p.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::Spares;
    use crate::Scratch;

    /// A scratch given back is the one taken next, even for smaller dims; one that would exceed
    /// the budget is dropped.
    #[test]
    fn scratch_is_kept_within_the_budget() {
        let dims = [64, 64, 10];
        let len = Scratch::len(dims).unwrap();
        let spares = Spares::new(len.bytes + 4 * len.words);
        let mut first = spares.take(dims).unwrap();
        let at = first.lend().bytes.as_ptr();
        spares.give(first);
        let mut again = spares.take([32, 64, 10]).unwrap();
        assert_eq!(again.lend().bytes.as_ptr(), at);
        let bigger = spares.take([65, 64, 10]).unwrap();
        spares.give(again);
        spares.give(bigger);
        assert_eq!(spares.lock().len(), 1);
    }
}
