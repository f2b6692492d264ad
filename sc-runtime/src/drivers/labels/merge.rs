//! Step 4 on a label volume: a grey edge is merged as the binary engine would merge it, and only
//! where the binary engine's promises carry over.
//!
//! The four cubes around the edge must be binary cubes with the same background label `W`, so
//! their ears are the ones the binary engine makes of the indicator "label ≠ `W`". In embedded
//! mode, the edge must also pass SPEC §5 (a) and (b) on that indicator, and every sample (b)
//! reads must be `W` or the edge's other label, so that the merge decision sees a two-label
//! neighbourhood, as in the binary volumes the rules were checked on. The merged pair stays in
//! the box of the four cubes and meets its faces only at vertices, so it cannot cross another
//! cube's triangles.

use alloc::vec::Vec;

use core::sync::atomic::Ordering::Relaxed;
use core::sync::atomic::{AtomicBool, AtomicU8, AtomicU32};

use super::sweep::{Ear, Padded};
use super::{Atlas, Label, LabelParams, chunks};
use crate::Mode;

/// The outcome of Step 4 on an atlas.
pub(super) struct Merged {
    /// Each old vertex's new id, `u32::MAX` if it was merged away.
    pub kept: Vec<u32>,
    /// Each old triangle's fate (see [`KEEP`]).
    fate: Vec<AtomicU8>,
}

impl Merged {
    /// Whether old triangle `t` was merged away.
    pub fn gone(&self, t: usize) -> bool {
        self.fate[t].load(Relaxed) == GONE
    }
}

/// A triangle's fate: [`KEEP`], [`GONE`], or `REPLACED + r`, replaced by the `r`-th triangle of
/// the merged pair of its grey vertex, the ear's middle one.
const KEEP: u8 = 0;
const GONE: u8 = 1;
const REPLACED: u8 = 2;

/// Merges what may merge among `ears`, then drops the vertices and triangles merged away;
/// returns, if any ear was looked at, what became of each old vertex and triangle.
pub(super) fn merge<L: Label>(
    grid: &Padded<'_, L>,
    params: &LabelParams<L>,
    ears: Vec<Ear<L>>,
    atlas: &mut Atlas<L>,
) -> Option<Merged> {
    if ears.is_empty() {
        return None;
    }
    let threads = params.threads;
    let (groups, slot) = around(&ears, atlas.positions.len(), threads);
    // Each ear is one grey vertex's, so the decisions are independent: made on threads.
    let decide = |g: usize| {
        let [a, b, c, d] = groups[g].map(|e| &ears[e as usize]);
        let w = a.background;
        let allowed = [b, c, d].iter().all(|e| e.background == w)
            && (params.mode == Mode::Paper
                || [a, b, c, d].iter().all(|e| e.mergeable) && !blocks(grid, a.lower, a.axis, w));
        allowed.then(|| quad(atlas, [a, b, c, d])).flatten()
    };
    let decisions: Vec<Option<[[u32; 3]; 2]>> = chunks::fill(groups.len(), threads, decide);
    // Applied on threads too, as marks: each triangle is one ear's at most, each ear one
    // group's, so no two groups mark the same triangle or vertex.
    let fate = chunks::fill(atlas.triangles.len(), threads, |_| AtomicU8::new(KEEP));
    let gone_vertex = chunks::fill(atlas.positions.len(), threads, |_| AtomicBool::new(false));
    let size = chunks::size(groups.len(), threads);
    let jobs = groups.chunks(size).zip(decisions.chunks(size)).collect();
    let merged = chunks::map(jobs, |(groups, decisions)| {
        let mut merged = 0;
        for (group, decision) in groups.iter().zip(decisions) {
            if decision.is_some() {
                let [a, b, c, d] = group.map(|e| &ears[e as usize]);
                fate[a.triangle as usize].store(REPLACED, Relaxed);
                fate[b.triangle as usize].store(REPLACED + 1, Relaxed);
                fate[c.triangle as usize].store(GONE, Relaxed);
                fate[d.triangle as usize].store(GONE, Relaxed);
                gone_vertex[a.vertex as usize].store(true, Relaxed);
                merged += 1;
            }
        }
        merged
    })
    .into_iter()
    .sum::<u64>();
    atlas.stats.merged += merged;
    atlas.stats.blocked += groups.len() as u64 - merged;
    // A replaced triangle is an ear, its middle vertex the grey one: that names its group.
    let merged_pair = |t: &[u32; 3], r: u8| {
        let pair = decisions[slot[t[1] as usize] as usize - 1].as_ref();
        pair.map_or(*t, |pair| pair[usize::from(r)])
    };
    let kept = compact(atlas, &gone_vertex, &fate, merged_pair, threads);
    Some(Merged { kept, fate })
}

/// The ears of each grey vertex with four, by ascending vertex, each group in the order the ears
/// came: a counting sort, the ears being many and their vertices dense, in chunks on threads
/// unless one was asked for; with, per vertex, its group plus one (0 for none).
fn around<L: Sync>(ears: &[Ear<L>], vertices: usize, threads: usize) -> (Vec<[u32; 4]>, Vec<u32>) {
    // At most four ears a vertex, one per cube around its grid edge: a byte counts them.
    let count = chunks::fill(vertices, threads, |_| AtomicU8::new(0));
    let size = chunks::size(ears.len(), threads);
    chunks::map(ears.chunks(size).collect(), |ears| {
        for ear in ears {
            add(&count[ear.vertex as usize], 1, threads);
        }
    });
    // Fewer than four ears: a cube around the edge is not binary, or lies outside the grid.
    // Each chunk of vertices numbers its groups after those of the chunks before.
    let four = |c: &AtomicU8| c.load(Relaxed) == 4;
    let vsize = chunks::size(vertices, threads);
    let fours = chunks::map(count.chunks(vsize).collect(), |c| {
        c.iter().filter(|&c| four(c)).count()
    });
    // Per vertex its group plus one, 0 for none.
    let mut slot = chunks::fill(vertices, threads, |_| 0u32);
    let jobs = count.chunks(vsize).zip(slot.chunks_mut(vsize));
    let jobs = jobs.zip(chunks::offsets(&fours)).collect();
    chunks::map(jobs, |((count, slot), before)| {
        let mut g = before as u32;
        for (c, s) in count.iter().zip(slot) {
            if four(c) {
                g += 1;
                *s = g;
            }
        }
    });
    let groups = fours.iter().sum::<usize>();
    // Each ear takes the next place in its group as the count comes down, so on one thread the
    // ears are in the order they came already; on several, they are sorted back into it.
    let out = chunks::fill(4 * groups, threads, |_| AtomicU32::new(0));
    chunks::map(ears.chunks(size).enumerate().collect(), |(k, ears)| {
        for (i, ear) in ears.iter().enumerate() {
            let v = ear.vertex as usize;
            if slot[v] != 0 {
                let place = 4 - usize::from(add(&count[v], u8::MAX, threads));
                out[4 * (slot[v] as usize - 1) + place].store((k * size + i) as u32, Relaxed);
            }
        }
    });
    let groups = chunks::fill(groups, threads, |g| {
        let mut group: [u32; 4] = core::array::from_fn(|i| out[4 * g + i].load(Relaxed));
        group.sort_unstable();
        group
    });
    (groups, slot)
}

/// Adds `n` to `count` (wrapping), returning the count before: as one atomic step on threads,
/// as a plain load and store on one, where the work runs as one chunk on this thread alone and
/// an atomic read-modify-write would cost tens of cycles for nothing.
fn add(count: &AtomicU8, n: u8, threads: usize) -> u8 {
    if threads == 1 {
        let c = count.load(Relaxed);
        count.store(c.wrapping_add(n), Relaxed);
        c
    } else {
        count.fetch_add(n, Relaxed)
    }
}

/// The two triangles replacing the four ears `[back, grey, forward]` around a grey vertex, split
/// along the diagonal whose corners the ears mark; `None` if the ears do not close a fan.
fn quad<L>(atlas: &Atlas<L>, ears: [&Ear<L>; 4]) -> Option<[[u32; 3]; 2]> {
    let t = ears.map(|e| atlas.triangles[e.triangle as usize]);
    // Around the grey vertex the fan runs forward → back: q0 = forward of the first ear.
    let mut q = [0u32; 4];
    let mut marked = [false; 4];
    let mut ear = 0;
    q[0] = t[0][2];
    marked[0] = ears[0].diagonal & 2 != 0;
    for k in 1..4 {
        q[k] = t[ear][0];
        marked[k] = ears[ear].diagonal & 1 != 0;
        ear = (0..4).find(|&n| t[n][2] == q[k])?;
    }
    if t[ear][0] != q[0] {
        return None;
    }
    match marked {
        [true, false, true, false] => Some([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]),
        [false, true, false, true] => Some([[q[1], q[2], q[3]], [q[1], q[3], q[0]]]),
        _ => None,
    }
}

/// The samples SPEC §5 (b) reads around a grey edge's lower end, as offsets: the 3 × 3 square
/// across z (`x + 3y`, the centre at 4), then the two along z.
const AROUND: [[isize; 3]; 11] = {
    let mut out = [[0; 3]; 11];
    let mut i = 0;
    while i < 9 {
        out[i] = [i as isize % 3 - 1, i as isize / 3 - 1, 0];
        i += 1;
    }
    out[9] = [0, 0, -1];
    out[10] = [0, 0, 1];
    out
};

/// Whether SPEC §5 (b) blocks the grey edge from `p` along `axis` on the indicator "label ≠
/// `w`", or a sample it reads has a third label.
fn blocks<L: Label>(grid: &Padded<'_, L>, p: [usize; 3], axis: usize, w: L) -> bool {
    let s = grid.around(p, &AROUND);
    // The edge's other end: along x and y in the square, along z in the column.
    let up = [5, 7, 10][axis];
    let x = if s[4] == Some(w) { s[up] } else { s[4] };
    let read = if axis == 2 { &s[..] } else { &s[..9] };
    if read.iter().flatten().any(|&l| l != w && Some(l) != x) {
        return true;
    }
    let n = grid.n;
    let inside = |a: usize| p[a] >= 1 && p[a] + 1 < n[a];
    if !(inside(0) && inside(1)) || axis == 2 && !inside(2) {
        return false;
    }
    let filled = |i: usize| s[i].is_some_and(|l| l != w);
    let centre = filled(4);
    // −x, +x, −y, +y.
    let faces = [3, 5, 1, 7].into_iter().all(|i| filled(i) != centre);
    if axis == 2 {
        faces && [9, 10].into_iter().all(|i| filled(i) != centre)
    } else {
        faces && (centre || [0, 2, 6, 8].into_iter().all(filled))
    }
}

/// Drops the vertices marked gone and the triangles whose fate is [`GONE`], puts `merged_pair`
/// of each triangle replaced (and its fate's `r`) in its place, and renumbers the vertices in
/// their order; returns the new ids. Runs in chunks, on threads unless one was asked for: each
/// chunk keeps its own items at its start, then the chunks' kept runs are gathered.
fn compact<L: Label>(
    atlas: &mut Atlas<L>,
    gone_vertex: &[AtomicBool],
    fate: &[AtomicU8],
    merged_pair: impl Fn(&[u32; 3], u8) -> [u32; 3] + Sync,
    threads: usize,
) -> Vec<u32> {
    // Vertices: each chunk's first new id is the number kept before it.
    let size = chunks::size(gone_vertex.len(), threads);
    let kept = chunks::map(gone_vertex.chunks(size).collect(), |gone| {
        gone.iter().filter(|g| !g.load(Relaxed)).count()
    });
    let mut new_id = chunks::fill(gone_vertex.len(), threads, |_| u32::MAX);
    let jobs = atlas
        .positions
        .chunks_mut(size)
        .zip(gone_vertex.chunks(size));
    let jobs = jobs.zip(new_id.chunks_mut(size));
    let jobs = jobs.zip(chunks::offsets(&kept)).collect();
    chunks::map(jobs, |(((p, gone), ids), first)| {
        let mut n = 0;
        for v in 0..p.len() {
            if !gone[v].load(Relaxed) {
                ids[v] = (first + n) as u32;
                p[n] = p[v];
                n += 1;
            }
        }
    });
    chunks::gather(&mut atlas.positions, size, &kept, threads);
    let size = chunks::size(fate.len(), threads);
    let kept = chunks::map(fate.chunks(size).collect(), |fate| {
        fate.iter().filter(|f| f.load(Relaxed) != GONE).count()
    });
    let jobs = atlas
        .triangles
        .chunks_mut(size)
        .zip(atlas.pairs.chunks_mut(size));
    let jobs = jobs.zip(fate.chunks(size)).collect();
    chunks::map(jobs, |((t, p), fate)| {
        let mut n = 0;
        for i in 0..t.len() {
            let kept = match fate[i].load(Relaxed) {
                GONE => continue,
                KEEP => t[i],
                f => merged_pair(&t[i], f - REPLACED),
            };
            t[n] = kept.map(|v| new_id[v as usize]);
            p[n] = p[i];
            n += 1;
        }
    });
    chunks::gather(&mut atlas.triangles, size, &kept, threads);
    chunks::gather(&mut atlas.pairs, size, &kept, threads);
    new_id
}
