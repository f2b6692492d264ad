//! One output vector shared by the chunks of a parallel extraction: each chunk writes into its
//! own stretch of the vector's spare capacity, sized from the survey, and the stretches are then
//! slid together in place.
//!
//! Chunk meshes of their own, copied into a fresh output, held the surface two and a half times
//! over at the end of each extraction. glibc returned that memory to the kernel when it was
//! freed, and the next extraction faulted it in again: on the 128 × 128 × 84 MRI about 1,400 page
//! faults per two-thread extraction, 4.5 ms where the same work without trimming took 2.6 ms.
//! Shared, the two-thread extraction allocates what the one-thread one does.

use alloc::vec::Vec;
use core::mem::MaybeUninit;

#[cfg(doc)]
use crate::Mesh;
use crate::mesh::{PushIf, huge_pages};

/// A chunk's stretch of a shared vector: pushes go to the stretch until it is full, then to a
/// vector of the chunk's own (the survey fell short, which the join handles by copying).
pub(crate) struct Stretch<'a, T> {
    start: usize,
    slots: &'a mut [MaybeUninit<T>],
    len: usize,
    spill: Vec<T>,
}

impl<T> Stretch<'_, T> {
    #[inline]
    pub fn push(&mut self, value: T) {
        match self.slots.get_mut(self.len) {
            Some(slot) => {
                slot.write(value);
                self.len += 1;
            }
            None => self.spill.push(value),
        }
    }

    /// Elements pushed.
    pub fn len(&self) -> usize {
        self.len + self.spill.len()
    }

    /// Cuts this stretch after its first `keep` slots (at least those written) and returns the
    /// rest as a stretch of its own: the room for a tail of the chunk's layers that another
    /// worker takes over. After the cut this one spills past `keep`.
    pub fn split_off(&mut self, keep: usize) -> Self {
        let keep = keep.clamp(self.len, self.slots.len());
        let (head, tail) = core::mem::take(&mut self.slots).split_at_mut(keep);
        self.slots = head;
        Stretch {
            start: self.start + keep,
            slots: tail,
            len: 0,
            spill: Vec::new(),
        }
    }

    /// What the join needs, without the borrow of the vector.
    pub fn finish(self) -> Filled<T> {
        Filled {
            start: self.start,
            len: self.len,
            spill: self.spill,
        }
    }
}

/// Into the stretch's next slot while it has one, else spilled if kept.
impl<T> PushIf<T> for Stretch<'_, T> {
    #[inline(always)]
    fn push_if(&mut self, value: T, keep: bool) {
        match self.slots.get_mut(self.len) {
            Some(slot) => {
                slot.write(value);
                self.len += usize::from(keep);
            }
            None if keep => self.spill.push(value),
            None => {}
        }
    }
}

/// A finished [`Stretch`]: `len` elements written from `start`, then `spill`.
pub(crate) struct Filled<T> {
    start: usize,
    len: usize,
    spill: Vec<T>,
}

/// Cuts the spare capacity of the empty `buf` into stretches of `lens` elements, in order,
/// reserving what is missing (and asking for huge pages, as [`Mesh::reserve_for`] does).
pub(crate) fn stretches<'a, T>(buf: &'a mut Vec<T>, lens: &[usize]) -> Vec<Stretch<'a, T>> {
    debug_assert!(buf.is_empty());
    buf.reserve_exact(lens.iter().sum());
    huge_pages(buf);
    let mut rest = buf.spare_capacity_mut();
    let mut start = 0;
    lens.iter()
        .map(|&n| {
            let (slots, tail) = core::mem::take(&mut rest).split_at_mut(n);
            rest = tail;
            start += n;
            Stretch {
                start: start - n,
                slots,
                len: 0,
                spill: Vec::new(),
            }
        })
        .collect()
}

/// Elements moved and adjusted at a time by [`join`]: 24 KiB of triangles, within a core's L1
/// data cache.
const BLOCK: usize = 2048;

/// Makes `buf` the concatenation of `parts` in order, each part's elements passed to `adjust`
/// with the part's index (in pieces, where they land). Returns how far into `buf` the parts had
/// been written (the end of the last written stretch), for [`release_spare`](crate::mesh).
///
/// # Safety
/// `parts` are the finished stretches of [`stretches`] on this `buf` and those split off them
/// ([`Stretch::split_off`]), all of them, in the order of their starts, and `buf` has not been
/// touched since.
pub(crate) unsafe fn join<T: Copy>(
    buf: &mut Vec<T>,
    parts: &[Filled<T>],
    adjust: impl Fn(usize, &mut [T]),
) -> usize {
    let total: usize = parts.iter().map(|p| p.len + p.spill.len()).sum();
    if parts.iter().any(|p| !p.spill.is_empty()) {
        // Rare: copy everything into a vector of the right size.
        let mut joined = Vec::with_capacity(total);
        for (i, p) in parts.iter().enumerate() {
            // SAFETY: the stretch's first `len` elements were written (the caller's contract).
            let written = unsafe { core::slice::from_raw_parts(buf.as_ptr().add(p.start), p.len) };
            let from = joined.len();
            joined.extend_from_slice(written);
            joined.extend_from_slice(&p.spill);
            adjust(i, &mut joined[from..]);
        }
        *buf = joined;
        return total;
    }
    let written = parts.iter().map(|p| p.start + p.len).max().unwrap_or(0);
    let base = buf.as_mut_ptr();
    let mut to = 0;
    for (i, p) in parts.iter().enumerate() {
        // A block at a time, each adjusted where it lands while it is in the cache: moving the
        // parts and then adjusting them went through the memory twice.
        for at in (0..p.len).step_by(BLOCK) {
            let n = BLOCK.min(p.len - at);
            // SAFETY: stretches start at the sum of the room before them, at or past the sum of
            // the lengths before them (`to`): both ranges lie within the capacity, and `copy`
            // is `memmove`, which allows them to overlap. Blocks go in ascending order and land
            // at or below where they were read, so no block overwrites one not yet moved. The
            // part's first `len` elements were written (the caller's contract), so the landed
            // block is initialised.
            let block = unsafe {
                if p.start != to {
                    core::ptr::copy(base.add(p.start + at), base.add(to + at), n);
                }
                core::slice::from_raw_parts_mut(base.add(to + at), n)
            };
            adjust(i, block);
        }
        to += p.len;
    }
    // SAFETY: the first `total` elements are now the parts' elements, all initialised.
    unsafe { buf.set_len(total) };
    written
}

#[cfg(test)]
mod tests {
    use super::{join, stretches};
    use crate::mesh::PushIf;
    use alloc::vec::Vec;

    /// Conditional pushes, kept and dropped in turn, into stretches with no room, a little and
    /// plenty, and into vectors with no spare capacity, a little and plenty: each holds exactly
    /// the kept values, in order, the stretches spilling past their room.
    #[test]
    fn conditional_pushes_hold_what_is_kept() {
        let values: Vec<(u32, bool)> = (0..9).map(|x| (x, x % 3 != 1)).collect();
        let want: Vec<u32> = values.iter().filter(|v| v.1).map(|v| v.0).collect();
        let mut buf = Vec::new();
        let mut parts = stretches(&mut buf, &[0, 2, 20]);
        for part in &mut parts {
            values.iter().for_each(|&(x, keep)| part.push_if(x, keep));
            assert_eq!(part.len(), want.len());
        }
        let filled: Vec<_> = parts.into_iter().map(|p| p.finish()).collect();
        // SAFETY: all the stretches of `buf`, finished, in order.
        unsafe { join(&mut buf, &filled, |_, _| {}) };
        assert_eq!(buf, want.repeat(3));
        for capacity in [0, 4, 20] {
            let mut v = Vec::with_capacity(capacity);
            values.iter().for_each(|&(x, keep)| v.push_if(x, keep));
            assert_eq!(v, want, "capacity {capacity}");
        }
    }

    /// A stretch split after its written part, into a head that spills past the cut and a tail
    /// that another writer fills (and one split below what was written, which keeps that, and
    /// one past its end, which leaves the tail no room): joined in the order of their starts,
    /// they are the concatenation of what each got.
    #[test]
    fn split_stretches_join_in_order() {
        for (keep, kept) in [(5, 5), (1, 3), (99, 10)] {
            let mut buf: Vec<u32> = Vec::new();
            let mut parts = stretches(&mut buf, &[10, 6]);
            let mut second = parts.pop().unwrap();
            let mut head = parts.pop().unwrap();
            (0..3).for_each(|x| head.push(x));
            let mut tail = head.split_off(keep);
            // The head fills its room up to the cut, then spills; the tail has the rest.
            (3..7).for_each(|x| head.push(x));
            (100..104).for_each(|x| tail.push(x));
            (200..202).for_each(|x| second.push(x));
            assert_eq!(head.len(), 7);
            let filled = [head.finish(), tail.finish(), second.finish()];
            assert_eq!(filled[1].start, kept, "cut at {keep}");
            // SAFETY: all the stretches of `buf` and the one split off, finished, in order.
            unsafe { join(&mut buf, &filled, |_, _| {}) };
            let want: Vec<u32> = (0..7).chain(100..104).chain(200..202).collect();
            assert_eq!(buf, want, "cut at {keep}");
        }
    }

    /// Parts that fit their stretches, and parts that overflow them (one of them a stretch of
    /// none), and parts of several blocks moved a little or a long way down (over themselves):
    /// the vector is their concatenation, each mapped by its index, and the join says how far
    /// the stretches were written.
    #[test]
    fn joined_parts_are_concatenated_in_order() {
        let b = super::BLOCK;
        for (lens, counts) in [
            ([3, 0, 5], [3usize, 0, 2]),
            ([3, 4, 5], [1, 4, 0]),
            ([3, 0, 5], [3, 2, 5]),
            ([2, 2, 2], [4, 0, 3]),
            ([2 * b + 9, 3 * b, b + 1], [2 * b + 8, 3 * b - 7, b + 1]),
            ([3 * b, 5, 2 * b + 3], [7, 5, 2 * b + 3]),
        ] {
            let mut buf: Vec<u32> = Vec::new();
            let mut want = Vec::new();
            let mut parts = stretches(&mut buf, &lens);
            for (i, (part, &n)) in parts.iter_mut().zip(&counts).enumerate() {
                for k in 0..n {
                    let x = (i as u32) << 24 | k as u32;
                    part.push(x);
                    want.push(x + i as u32);
                }
                assert_eq!(part.len(), n);
            }
            let filled: Vec<_> = parts.into_iter().map(|p| p.finish()).collect();
            // SAFETY: all the stretches of `buf`, finished, in order.
            let written = unsafe {
                join(&mut buf, &filled, |i, xs| {
                    xs.iter_mut().for_each(|x| *x += i as u32)
                })
            };
            assert_eq!(buf, want, "{lens:?} {counts:?}");
            // Where every part fit, the end of the last stretch written into; else the joined
            // copy, as long as the parts.
            let fit = lens.iter().zip(&counts).all(|(l, c)| c <= l);
            let ends = (0..3).map(|i| lens[..i].iter().sum::<usize>() + counts[i]);
            let expected = if fit { ends.max().unwrap() } else { want.len() };
            assert_eq!(written, expected, "{lens:?} {counts:?}");
        }
    }
}
