//! One output vector shared by the chunks of a parallel extraction: each chunk writes into its
//! own stretch of the vector's spare capacity, sized from the survey, and the stretches are then
//! slid together in place.
//!
//! Chunk meshes of their own, copied into a fresh output, would hold the surface two and a half
//! times over at the end of each extraction, and glibc would return that memory to the kernel
//! when it was freed, for the next extraction to fault in again. Shared, the two-thread
//! extraction allocates what the one-thread one does.

use alloc::vec::Vec;
use core::mem::MaybeUninit;
use core::ops::Range;

use rayon::prelude::*;

#[cfg(doc)]
use crate::Mesh;
use crate::kernel::sink::NormalColumn;
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

impl NormalColumn for Stretch<'_, [f32; 3]> {
    #[inline]
    fn push(&mut self, normal: [f32; 3]) {
        Stretch::push(self, normal);
    }

    /// Those in the stretch's slots, then those spilled.
    fn written_mut(&mut self) -> (&mut [[f32; 3]], &mut [[f32; 3]]) {
        let head: *mut [MaybeUninit<[f32; 3]>] = &mut self.slots[..self.len];
        // SAFETY: pushes wrote the first `len` slots (a slot written but not kept lies past
        // them), and `MaybeUninit<T>` has `T`'s layout.
        (unsafe { &mut *(head as *mut [[f32; 3]]) }, &mut self.spill)
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
/// The pieces are moved on every thread rayon has, in rounds: no piece lands on one not yet
/// read. A part after the first moves down by the room left unused before it, so over the
/// least such distance the moves of one round cannot meet (see [`Plan::new`]). On one thread the
/// join of a large mesh's triangles is a noticeable share of its extraction.
///
/// # Safety
/// `parts` are the finished stretches of [`stretches`] on this `buf` and those split off them
/// ([`Stretch::split_off`]), all of them, in the order of their starts, and `buf` has not been
/// touched since.
pub(crate) unsafe fn join<T: Copy + Send>(
    buf: &mut Vec<T>,
    parts: &[Filled<T>],
    adjust: impl Fn(usize, &mut [T]) + Sync,
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
    let base = Base(buf.as_mut_ptr());
    // Each piece is adjusted where it lands, while it is in the cache: moving the parts and
    // then adjusting them went through the memory twice.
    let place = |piece: &Piece| {
        // SAFETY: stretches start at the sum of the room before them, at or past the sum of the
        // lengths before them (where the piece lands): both ranges lie within the capacity, and
        // `copy` is `memmove`, which allows them to overlap. In order, pieces land at or below
        // where they are read, so none lands on one not yet moved; in a round of `Plan`, none
        // lands where another of the round is read, and what it lands on was read in an earlier
        // round, so the round's threads write disjoint pieces. The parts' first `len` elements
        // were written (the caller's contract), so the landed piece is initialised.
        let landed = unsafe {
            if piece.from != piece.to {
                core::ptr::copy(base.at(piece.from), base.at(piece.to), piece.len);
            }
            core::slice::from_raw_parts_mut(base.at(piece.to), piece.len)
        };
        adjust(piece.part, landed);
    };
    let plan = Plan::new(parts);
    match plan.rounds {
        Some(rounds) => rounds
            .into_iter()
            .for_each(|round| plan.pieces[round].par_iter().for_each(place)),
        None => plan.pieces.iter().for_each(place),
    }
    // SAFETY: the first `total` elements are now the parts' elements, all initialised.
    unsafe { buf.set_len(total) };
    written
}

/// The vector's start, shared by the threads that move pieces of it.
#[derive(Clone, Copy)]
struct Base<T>(*mut T);

// SAFETY: the threads write disjoint pieces (see `join`), of elements that are `Send`.
unsafe impl<T: Send> Send for Base<T> {}
unsafe impl<T: Send> Sync for Base<T> {}

impl<T> Base<T> {
    /// A method, so that closures capture the `Base`, which is `Sync`, not its pointer.
    ///
    /// # Safety
    /// `i` is within the vector's capacity.
    unsafe fn at(self, i: usize) -> *mut T {
        // SAFETY: the caller's.
        unsafe { self.0.add(i) }
    }
}

/// Up to [`BLOCK`] elements of part `part`, read at `from` and landing at `to`.
#[derive(Debug, PartialEq)]
struct Piece {
    part: usize,
    from: usize,
    to: usize,
    len: usize,
}

/// The pieces of a join, in the order they land, and how they go.
struct Plan {
    pieces: Vec<Piece>,
    /// Rounds of pieces, each moved in any order and at once once the rounds before are done;
    /// `None`: one piece after another, on one thread.
    rounds: Option<Vec<Range<usize>>>,
}

impl Plan {
    /// An element landing at `f` from `f + d` (`d` the room left unused before its part) lands
    /// on what the element `d` places before it was read from. A round spans at most the least
    /// `d` of a moving part: what its pieces land on was read in earlier rounds, and what they
    /// read lies past the round's end. Where that distance is short, rounds of a few pieces
    /// would each wait for the slowest, and the pieces go in order instead.
    fn new<T>(parts: &[Filled<T>]) -> Plan {
        let mut pieces = Vec::new();
        let mut least = None::<usize>;
        let mut to = 0;
        for (part, p) in parts.iter().enumerate() {
            let d = p.start - to;
            if d > 0 && p.len > 0 {
                least = Some(least.map_or(d, |l| l.min(d)));
            }
            for at in (0..p.len).step_by(BLOCK) {
                let len = BLOCK.min(p.len - at);
                pieces.push(Piece {
                    part,
                    from: p.start + at,
                    to: to + at,
                    len,
                });
            }
            to += p.len;
        }
        let rounds = match least {
            // Nothing moves: the pieces are adjusted in place, in any order.
            None => Some(core::iter::once(0..pieces.len()).collect()),
            Some(d) if d >= 4 * BLOCK => {
                // Pieces start at multiples of `BLOCK` within their parts, not of the rounds'
                // span: a round ends before the first piece that reaches past it.
                let mut rounds: Vec<Range<usize>> = Vec::new();
                let mut end = 0;
                for (i, piece) in pieces.iter().enumerate() {
                    match rounds.last_mut() {
                        Some(round) if piece.to + piece.len <= end => round.end = i + 1,
                        _ => {
                            end = piece.to + d;
                            rounds.push(i..i + 1);
                        }
                    }
                }
                Some(rounds)
            }
            Some(_) => None,
        };
        Plan { pieces, rounds }
    }
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

    /// Plans of joins with little room left over (pieces in order) and much (rounds): the pieces
    /// cover each part once, in order, landing one after another; in rounds, no piece lands where
    /// a piece of its round or a later one is read, except a piece on itself.
    #[test]
    fn rounds_never_land_on_what_is_still_to_be_read() {
        let b = super::BLOCK;
        for (lens, counts, in_rounds) in [
            ([4 * b, 3 * b, 5 * b], [3 * b, 3 * b, 4 * b], false),
            (
                [10 * b, 3 * b, 9 * b + 5],
                [5 * b + 3, 3 * b - 1, 9 * b + 5],
                true,
            ),
            ([9 * b, 9 * b, 9 * b], [b + 1, 2 * b, 9 * b], true),
            ([2 * b, 0, b], [2 * b, 0, b], true),
        ] {
            let mut buf: Vec<u32> = Vec::new();
            let mut parts = stretches(&mut buf, &lens);
            for (part, &n) in parts.iter_mut().zip(&counts) {
                (0..n as u32).for_each(|x| part.push(x));
            }
            let filled: Vec<_> = parts.into_iter().map(|p| p.finish()).collect();
            let plan = super::Plan::new(&filled);
            let mut to = 0;
            for (i, &n) in counts.iter().enumerate() {
                let start: usize = lens[..i].iter().sum();
                let mine: Vec<_> = plan.pieces.iter().filter(|p| p.part == i).collect();
                assert_eq!(mine.iter().map(|p| p.len).sum::<usize>(), n);
                for (k, p) in mine.iter().enumerate() {
                    assert_eq!((p.from, p.to), (start + k * b, to + k * b), "{lens:?}");
                }
                to += n;
            }
            assert_eq!(plan.rounds.is_some(), in_rounds, "{lens:?} {counts:?}");
            let Some(rounds) = plan.rounds else { continue };
            assert_eq!(
                rounds.iter().map(|r| r.len()).sum::<usize>(),
                plan.pieces.len()
            );
            for (r, round) in rounds.iter().enumerate() {
                for p in &plan.pieces[round.clone()] {
                    let later = rounds[r..].iter().flat_map(|r| &plan.pieces[r.clone()]);
                    for q in later.filter(|q| *q != p) {
                        let apart = p.to + p.len <= q.from || q.from + q.len <= p.to;
                        assert!(apart, "{p:?} lands on {q:?} in {lens:?} {counts:?}");
                    }
                }
            }
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
            // Room enough that the pieces move in rounds, on every thread.
            (
                [10 * b, 3 * b, 9 * b + 5],
                [5 * b + 3, 3 * b - 1, 9 * b + 5],
            ),
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
