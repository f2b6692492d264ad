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

/// Keeps the first `kept[k]` items of each chunk `k` of `size` items, in order, and drops the
/// rest, in place: new lists would cost a page fault per page. On the pool, in one part of
/// consecutive chunks per worker: each part moves its runs down within itself, but what belongs
/// in a part before it waits aside until every part is done (moving a part down in place would
/// wait for the parts before it to move).
pub(super) fn gather<T: Copy + Send + Sync>(
    items: &mut Vec<T>,
    size: usize,
    kept: &[usize],
    threads: usize,
) {
    if let [n] = kept {
        return items.truncate(*n);
    }
    let before = offsets(kept);
    let per_part = kept.len().div_ceil(super::workers(threads)).max(1);
    let jobs = items.chunks_mut(per_part * size).enumerate();
    let jobs = jobs.map(|(p, part)| (p * per_part * size, part, p * per_part));
    let aside = map(jobs.collect(), |(start, part, first_chunk)| {
        let mut aside = Vec::new();
        let runs = kept.iter().zip(&before).enumerate().skip(first_chunk);
        for (k, (&n, &to)) in runs.take(per_part) {
            let from = k * size - start;
            // The run's first items belong before this part.
            let early = start.saturating_sub(to).min(n);
            aside.extend_from_slice(&part[from..from + early]);
            if early < n && k * size != to {
                part.copy_within(from + early..from + n, to + early - start);
            }
        }
        aside
    });
    for (aside, p) in aside.iter().zip((0..kept.len()).step_by(per_part)) {
        let to = before[p];
        items[to..to + aside.len()].copy_from_slice(aside);
    }
    items.truncate(kept.iter().sum());
}
