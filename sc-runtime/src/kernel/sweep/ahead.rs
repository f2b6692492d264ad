//! The next slice to classify, fetched into the cache while the triangle pass runs.
//!
//! Classifying a slice is the only pass that reads every sample, and on large volumes it waits
//! on memory while the other passes work from the cache. Spreading prefetches of slice `k + 3`
//! over layer `k`'s triangle pass, a share per cube row, overlaps that read with the pass's work,
//! so that layer `k + 1` classifies from L2; the larger the volume, the more it saves
//! (docs/speed-log.md).

use core::ops::Range;

use crate::kernel::prefetch::{self, LINE};

/// The bytes of a slice ahead, cut into one share per cube row of a triangle pass.
pub(super) struct Ahead {
    start: *const u8,
    len: usize,
    /// Bytes per row, a whole number of lines.
    share: usize,
}

impl Ahead {
    /// The slice `ahead` (empty when there is none to fetch) shared among `rows` rows.
    pub fn new<T>(ahead: &[T], rows: usize) -> Ahead {
        let len = size_of_val(ahead);
        Ahead {
            start: ahead.as_ptr().cast(),
            len,
            share: len.div_ceil(rows.max(1)).next_multiple_of(LINE),
        }
    }

    /// The bytes row `row` fetches, from the slice's start: its share, clipped to the slice.
    fn share(&self, row: usize) -> Range<usize> {
        let first = row.saturating_mul(self.share).min(self.len);
        first..first.saturating_add(self.share).min(self.len)
    }

    /// Asks for row `row`'s share of the slice to be brought into the cache ([`prefetch::line`]).
    #[inline(always)]
    pub fn fetch(&self, row: usize) {
        prefetch::lines(self.start, self.share(row));
    }
}

#[cfg(test)]
mod tests {
    use super::{Ahead, LINE};
    use alloc::vec;
    use alloc::vec::Vec;

    /// The rows' shares cover every line of the slice exactly once, in order, for slices of
    /// whole and partial lines, of several sample sizes, among fewer and more rows than lines;
    /// an empty slice fetches nothing.
    #[test]
    fn shares_cover_every_line_once() {
        for samples in [0, 1, 63, 64, 65, 1000, 45_901] {
            for rows in [0, 1, 2, 7, 232, 5000] {
                let check = |size: usize, ahead: Ahead| {
                    let len = samples * size;
                    let lines: Vec<usize> = (0..rows.max(1))
                        .flat_map(|row| ahead.share(row).step_by(LINE))
                        .collect();
                    let want: Vec<usize> = (0..len).step_by(LINE).collect();
                    assert_eq!(
                        lines, want,
                        "{samples} samples of {size} bytes, {rows} rows"
                    );
                };
                check(1, Ahead::new(&vec![0u8; samples], rows));
                check(2, Ahead::new(&vec![0i16; samples], rows));
                check(4, Ahead::new(&vec![0f32; samples], rows));
            }
        }
    }
}
