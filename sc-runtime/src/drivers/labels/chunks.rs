//! Work cut into chunks, each chunk writing its own part of the output: with `std` the chunks
//! run on the current Rayon pool, without it one after another. The output does not depend on
//! how the work was cut, so the atlas is the same for any number of threads.

use alloc::vec::Vec;

/// The items in a chunk of `n`: all of them on one thread, else about 64 chunks, so that
/// threads slowed by other work still share it out, but not so small that a chunk costs more
/// to hand out than to do.
pub(super) fn size(n: usize, threads: usize) -> usize {
    match threads {
        1 => n.max(1),
        _ => n.div_ceil(64).max(SMALLEST),
    }
}

/// The fewest items in a chunk; a few in unit tests, so that a small volume runs in many
/// chunks there.
const SMALLEST: usize = if cfg!(test) { 3 } else { 1 << 10 };

/// `f` of each job, in order; one job runs on this thread, not handed to the pool.
#[cfg(feature = "std")]
pub(super) fn map<T: Send, R: Send>(jobs: Vec<T>, f: impl Fn(T) -> R + Sync + Send) -> Vec<R> {
    use rayon::prelude::*;
    if jobs.len() <= 1 {
        return jobs.into_iter().map(f).collect();
    }
    jobs.into_par_iter().map(f).collect()
}

/// `f` of each job, in order.
#[cfg(not(feature = "std"))]
pub(super) fn map<T, R>(jobs: Vec<T>, f: impl Fn(T) -> R) -> Vec<R> {
    jobs.into_iter().map(f).collect()
}

/// `f` of each of `0..n`, in order, on threads unless one was asked for.
#[cfg(feature = "std")]
pub(super) fn fill<T: Send>(
    n: usize,
    threads: usize,
    f: impl Fn(usize) -> T + Sync + Send,
) -> Vec<T> {
    use rayon::prelude::*;
    if threads == 1 {
        return (0..n).map(f).collect();
    }
    (0..n).into_par_iter().map(f).collect()
}

/// `f` of each of `0..n`, in order.
#[cfg(not(feature = "std"))]
pub(super) fn fill<T>(n: usize, _threads: usize, f: impl Fn(usize) -> T) -> Vec<T> {
    (0..n).map(f).collect()
}

/// The running sums before each count.
pub(super) fn offsets(counts: &[usize]) -> Vec<usize> {
    counts
        .iter()
        .scan(0, |sum, &c| {
            let at = *sum;
            *sum += c;
            Some(at)
        })
        .collect()
}

/// `out` cut into consecutive parts of `lengths` (which sum to at most its length).
pub(super) fn split<'a, T>(mut out: &'a mut [T], lengths: &[usize]) -> Vec<&'a mut [T]> {
    lengths
        .iter()
        .map(|&n| {
            let (part, rest) = core::mem::take(&mut out).split_at_mut(n);
            out = rest;
            part
        })
        .collect()
}

/// Keeps, in order and in place, `value(i, item)` of each item `i` that `keep(i)`, and drops
/// the rest: in place, as new lists would cost a page fault per page. On the pool, in one part
/// per worker: each part moves its kept items down within itself, but those whose place lies in
/// a part before it wait aside until every part is done (moving a part down in place waits for
/// the parts before it to move).
pub(super) fn sieve<T: Copy + Send + Sync>(
    items: &mut Vec<T>,
    threads: usize,
    keep: impl Fn(usize) -> bool + Sync,
    value: impl Fn(usize, &T) -> T + Sync,
) {
    let n = items.len();
    let size = n.div_ceil(super::workers(threads)).max(SMALLEST);
    let starts: Vec<usize> = (0..n).step_by(size).collect();
    let kept = map(starts, |start| {
        (start..n.min(start + size)).filter(|&i| keep(i)).count()
    });
    let before = offsets(&kept);
    let jobs = items.chunks_mut(size).zip(before.iter().copied());
    let aside = map(jobs.enumerate().collect(), |(k, (part, first))| {
        let start = k * size;
        let mut aside = Vec::new();
        let mut to = first;
        for i in 0..part.len() {
            if keep(start + i) {
                let item = value(start + i, &part[i]);
                if to < start {
                    aside.push(item);
                } else {
                    part[to - start] = item;
                }
                to += 1;
            }
        }
        aside
    });
    for (aside, first) in aside.iter().zip(before) {
        items[first..first + aside.len()].copy_from_slice(aside);
    }
    items.truncate(kept.iter().sum());
}
