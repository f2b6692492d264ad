//! The vertex passes' reads of an edge's two samples and writes of its vertex id, with one bounds
//! test per row instead of three per vertex.

use super::for_each_differing;
use crate::Error;

/// The edges of one row along one axis, indexed by their `x`: the samples at their lower and
/// upper ends, and the slots for their vertex ids.
pub(super) struct EdgeRow<'a, T> {
    lower: &'a [T],
    upper: &'a [T],
    ids: &'a mut [u32],
}

impl<'a, T: Copy> EdgeRow<'a, T> {
    pub fn new(lower: &'a [T], upper: &'a [T], ids: &'a mut [u32]) -> EdgeRow<'a, T> {
        EdgeRow { lower, upper, ids }
    }

    /// Calls `f(x, (a, b))` for each edge `x` in `start..end` whose ends the classified rows
    /// `changes.0` and `changes.1` tell apart (see [`for_each_differing`]), with the edge's
    /// samples, and stores the vertex id `f` returns in the edge's slot.
    #[inline(always)]
    pub fn scan(
        &mut self,
        changes: (&[u8], &[u8]),
        start: usize,
        end: usize,
        mut f: impl FnMut(usize, (T, T)) -> Result<u32, Error>,
    ) -> Result<(), Error> {
        let EdgeRow { lower, upper, ids } = self;
        // Holds for every row the passes scan; tested once here, since the reads below rely on
        // it.
        assert!(
            end <= lower.len().min(upper.len()).min(ids.len()),
            "a row's edge scan ends within its samples and ids"
        );
        for_each_differing(changes.0, changes.1, start, end, |x| {
            // SAFETY: `for_each_differing` calls with `x < end` only, and `end` is at most each
            // slice's length (tested above).
            let ends = unsafe { (*lower.get_unchecked(x), *upper.get_unchecked(x)) };
            let id = f(x, ends)?;
            // SAFETY: as above.
            unsafe { *ids.get_unchecked_mut(x) = id };
            Ok(())
        })
    }
}
