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

use alloc::vec;
use alloc::vec::Vec;

use super::sweep::{Ear, Padded};
use super::{Atlas, Label, LabelParams, chunks};
use crate::Mode;

/// Merges what may merge among `ears`, then drops the vertices and triangles merged away;
/// returns, if any ear was looked at, each old vertex's new id (`u32::MAX` if dropped) and
/// which old triangles were dropped.
pub(super) fn merge<L: Label>(
    grid: &Padded<'_, L>,
    params: &LabelParams<L>,
    ears: Vec<Ear<L>>,
    atlas: &mut Atlas<L>,
) -> Option<(Vec<u32>, Vec<bool>)> {
    if ears.is_empty() {
        return None;
    }
    let mut gone_vertex = vec![false; atlas.positions.len()];
    let mut gone_triangle = vec![false; atlas.triangles.len()];
    let groups = around(&ears, atlas.positions.len());
    // Each ear is one grey vertex's, so the decisions are independent: made on threads, applied
    // in order.
    let decide = |group: &[u32; 4]| {
        let [a, b, c, d] = group.map(|e| &ears[e as usize]);
        let w = a.background;
        let allowed = [b, c, d].iter().all(|e| e.background == w)
            && (params.mode == Mode::Paper
                || [a, b, c, d].iter().all(|e| e.mergeable) && !blocks(grid, a.lower, a.axis, w));
        allowed.then(|| quad(atlas, [a, b, c, d])).flatten()
    };
    let decisions: Vec<Option<[[u32; 3]; 2]>> = decide_all(&groups, decide, params.threads);
    for (group, decision) in groups.iter().zip(decisions) {
        let [a, b, c, d] = group.map(|e| &ears[e as usize]);
        let Some([first, second]) = decision else {
            atlas.stats.blocked += 1;
            continue;
        };
        atlas.triangles[a.triangle as usize] = first;
        atlas.triangles[b.triangle as usize] = second;
        gone_triangle[c.triangle as usize] = true;
        gone_triangle[d.triangle as usize] = true;
        gone_vertex[a.vertex as usize] = true;
        atlas.stats.merged += 1;
    }
    let kept = compact(atlas, &gone_vertex, &gone_triangle, params.threads);
    Some((kept, gone_triangle))
}

/// `decide` for every group, on threads unless one was asked for.
#[cfg(feature = "std")]
fn decide_all<T: Send>(
    groups: &[[u32; 4]],
    decide: impl Fn(&[u32; 4]) -> T + Sync,
    threads: usize,
) -> Vec<T> {
    use rayon::prelude::*;
    if threads == 1 {
        groups.iter().map(decide).collect()
    } else {
        groups.par_iter().map(&decide).collect()
    }
}

/// `decide` for every group.
#[cfg(not(feature = "std"))]
fn decide_all<T>(groups: &[[u32; 4]], decide: impl Fn(&[u32; 4]) -> T, _threads: usize) -> Vec<T> {
    groups.iter().map(decide).collect()
}

/// The ears of each grey vertex with four, by ascending vertex, each group in the order the ears
/// came: a counting sort, the ears being many and their vertices dense.
fn around<L>(ears: &[Ear<L>], vertices: usize) -> Vec<[u32; 4]> {
    let mut count = vec![0u8; vertices];
    for ear in ears {
        let c = &mut count[ear.vertex as usize];
        *c = c.saturating_add(1);
    }
    // Fewer than four ears: a cube around the edge is not binary, or lies outside the grid.
    let mut slot = vec![u32::MAX; vertices];
    let mut groups = 0u32;
    for (s, &c) in slot.iter_mut().zip(&count) {
        if c == 4 {
            *s = groups;
            groups += 1;
        }
    }
    let mut out = vec![[0u32; 4]; groups as usize];
    let mut filled = vec![0u8; groups as usize];
    for (n, ear) in ears.iter().enumerate() {
        let g = slot[ear.vertex as usize];
        if g != u32::MAX {
            let f = &mut filled[g as usize];
            out[g as usize][usize::from(*f)] = n as u32;
            *f += 1;
        }
    }
    out
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

/// Drops the marked vertices and triangles, renumbering the vertices in their order; returns
/// the new ids. Runs in chunks, on threads unless one was asked for: each chunk counts what it
/// keeps, then copies it to its place in new lists, those before it having kept the rest.
fn compact<L: Label>(
    atlas: &mut Atlas<L>,
    gone_vertex: &[bool],
    gone_triangle: &[bool],
    threads: usize,
) -> Vec<u32> {
    // Vertices: each chunk's first new id is the number kept before it.
    let size = chunks::size(gone_vertex.len(), threads);
    let kept = chunks::kept(gone_vertex, size);
    // Zeroed lists are fresh pages, written first by the chunks, on their threads.
    let mut new_id = vec![0u32; gone_vertex.len()];
    let mut positions = vec![[0f32; 3]; kept.iter().sum()];
    let jobs = atlas.positions.chunks(size).zip(gone_vertex.chunks(size));
    let jobs = jobs.zip(new_id.chunks_mut(size));
    let jobs = jobs.zip(chunks::split(&mut positions, &kept));
    let jobs = jobs.zip(chunks::offsets(&kept)).collect();
    chunks::map(jobs, |((((p, gone), ids), out), first)| {
        let mut n = 0;
        for ((p, &gone), id) in p.iter().zip(gone).zip(ids) {
            if gone {
                *id = u32::MAX;
            } else {
                *id = (first + n) as u32;
                out[n] = *p;
                n += 1;
            }
        }
    });
    atlas.positions = positions;
    let size = chunks::size(gone_triangle.len(), threads);
    let kept = chunks::kept(gone_triangle, size);
    let mut triangles = vec![[0u32; 3]; kept.iter().sum()];
    let mut pairs = vec![[L::ZERO; 2]; triangles.len()];
    let jobs = atlas.triangles.chunks(size).zip(atlas.pairs.chunks(size));
    let jobs = jobs.zip(gone_triangle.chunks(size));
    let jobs = jobs.zip(chunks::split(&mut triangles, &kept));
    let jobs = jobs.zip(chunks::split(&mut pairs, &kept)).collect();
    chunks::map(jobs, |((((t, p), gone), out_t), out_p)| {
        let mut n = 0;
        for ((t, p), &gone) in t.iter().zip(p).zip(gone) {
            if !gone {
                out_t[n] = t.map(|v| new_id[v as usize]);
                out_p[n] = *p;
                n += 1;
            }
        }
    });
    atlas.triangles = triangles;
    atlas.pairs = pairs;
    new_id
}
