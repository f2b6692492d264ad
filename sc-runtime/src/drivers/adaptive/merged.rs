//! Step 4 among the unit cubes no box covers (docs/adaptive.md, "Kept"): embedded mode's merges,
//! kept wherever the four cubes a merge touches all stay unit cubes.
//!
//! A merge removes the vertex on a grey edge and replaces the four triangles around it, one in
//! each cube around the edge, by two on the same four outer vertices; the sides on the four
//! cubes' outer faces stay as they were. So a merge whose four cubes are outside every box can be
//! kept as embedded mode makes it: the walls it shares with boxes are unchanged, and the boxes'
//! tests still hold beside it. Merges are read back from the two sweeps: a removed vertex, its
//! fan of four Steps 1–3 triangles, and the two embedded triangles on the fan's ring.

use alloc::vec::Vec;

use super::record::{MERGED, Recorded};
use crate::kernel::adaptive::Tolerance;
use crate::kernel::adaptive::checks::{scaled, within};

/// A triangle as its vertices' edge keys, rotated to start at the least (the winding kept).
fn canonical(t: [u32; 3], edges: &[u64]) -> [u64; 3] {
    let k = t.map(|v| edges[v as usize]);
    let i = (0..3).min_by_key(|&i| k[i]).unwrap_or(0);
    [k[i], k[(i + 1) % 3], k[(i + 2) % 3]]
}

/// One merge read back from the sweeps: Steps 1–3's fan around the removed vertex and
/// embedded mode's triangles on its ring. Held in place, not in lists of their own: a scan has
/// tens of thousands of merges, and a whole one has four and two.
#[derive(Default)]
struct Merge {
    fan: [usize; 4],
    fans: u8,
    new: [[u64; 3]; 2],
    news: u8,
}

impl Merge {
    fn push_fan(&mut self, triangle: usize) {
        if let Some(slot) = self.fan.get_mut(usize::from(self.fans)) {
            *slot = triangle;
        }
        self.fans = self.fans.saturating_add(1);
    }

    fn push_new(&mut self, triangle: [u64; 3]) {
        if let Some(slot) = self.new.get_mut(usize::from(self.news)) {
            *slot = triangle;
        }
        self.news = self.news.saturating_add(1);
    }

    /// A fan of four and two triangles replacing it, as Step 4 makes every merge.
    fn whole(&self) -> bool {
        self.fans == 4 && self.news == 2
    }
}

/// Triangles with the key of the cube that owns each, and the owner of each merge kept.
pub(super) struct Units {
    pub triangles: Vec<(u64, [u32; 3])>,
    pub merges: Vec<u64>,
}

/// The triangles of the cubes outside boxes, as ids of the Steps 1–3 vertices: Steps 1–3's
/// (`triangles`, recorded in `steps`), except that each merge of `merged` (embedded mode's sweep
/// of the same volume under the same bound) whose four cubes are outside boxes replaces its fan.
/// A unit cube owns its own triangles; a merge's two belong to the least of its four cubes, one
/// a merge always reads, so the owner is found wherever the merge is. `vertex_id` maps an edge key to its Steps 1–3
/// vertex and `place` to its position in grid steps; `in_box` says whether a cube (by key) lies
/// in a box. A merge is kept only if its two triangles and its fan lie within the tolerance of
/// each other, every point (embedded mode's bound measures the removed vertex and the new
/// diagonal only), and, unless the tolerance allows wrong-side samples, if no corner of its
/// four cubes changes side ([`keeps_sides`]).
pub(super) fn unit_triangles(
    triangles: &[[u32; 3]],
    steps: &Recorded,
    merged: &Recorded,
    vertex_id: impl Fn(u64) -> u32,
    place: impl Fn(u64) -> [f64; 3],
    in_box: impl Fn(u64) -> bool,
    tolerance: &Tolerance,
) -> Units {
    // The Steps 1–3 vertices embedded mode merged away: used by Steps 1–3's triangles and not
    // by embedded mode's, one merge each, in the order of their edges.
    let mut kept = alloc::vec![false; steps.edges.len()];
    for t in &merged.mesh.triangles {
        for &v in t {
            kept[vertex_id(merged.edges[v as usize]) as usize] = true;
        }
    }
    let mut old: Vec<u32> = Vec::new();
    for t in triangles {
        for &v in t {
            if !kept[v as usize] {
                // Marked once listed, so each is listed once.
                kept[v as usize] = true;
                old.push(v);
            }
        }
    }
    old.sort_unstable_by_key(|&v| steps.edges[v as usize]);
    let mut merge_of = alloc::vec![u32::MAX; steps.edges.len()];
    for (m, &v) in old.iter().enumerate() {
        merge_of[v as usize] = m as u32;
    }
    drop(kept);
    let mut merges: Vec<Merge> = (0..old.len()).map(|_| Merge::default()).collect();
    let mut corners = 0;
    for (i, t) in triangles.iter().enumerate() {
        for &v in t {
            let m = merge_of[v as usize];
            if m != u32::MAX {
                merges[m as usize].push_fan(i);
                corners += 2;
            }
        }
    }
    drop(merge_of);
    // Each ring vertex (by key) with the merges whose ring holds it: the fans' other corners.
    let mut ring: Vec<(u64, u32)> = Vec::with_capacity(corners);
    for (m, (merge, &v)) in merges.iter().zip(&old).enumerate() {
        let key = steps.edges[v as usize];
        for &i in merge.fan.iter().take(usize::from(merge.fans)) {
            for &r in &triangles[i] {
                let r = steps.edges[r as usize];
                if r != key {
                    ring.push((r, m as u32));
                }
            }
        }
    }
    ring.sort_unstable();
    ring.dedup();
    // Embedded mode's merged pairs, each given to the merge whose ring holds its corners.
    for (&t, &cube) in merged.mesh.triangles.iter().zip(&merged.cubes) {
        if cube & MERGED == 0 {
            continue;
        }
        let k = canonical(t, &merged.edges);
        let on_ring = |m: u32| k.iter().all(|&v| ring.binary_search(&(v, m)).is_ok());
        let from = ring.partition_point(|&(v, _)| v < k[0]);
        if let Some(&(_, m)) = ring[from..]
            .iter()
            .take_while(|&&(v, _)| v == k[0])
            .find(|&&(_, m)| on_ring(m))
        {
            merges[m as usize].push_new(k);
        }
    }
    // What is held from here on is the output: the lists that only found it go first.
    drop(ring);
    let mut dropped = alloc::vec![false; triangles.len()];
    let mut out = Vec::new();
    let mut kept = Vec::new();
    for m in &merges {
        let whole = m.whole();
        if whole
            && m.fan.iter().all(|&i| !in_box(steps.cubes[i]))
            && within_each_other(m, triangles, steps, &place, tolerance)
            && (tolerance.allow_wrong_side || keeps_sides(m, triangles, steps, &place))
        {
            for &i in &m.fan {
                dropped[i] = true;
            }
            let owner = m
                .fan
                .iter()
                .map(|&i| steps.cubes[i])
                .min()
                .unwrap_or(u64::MAX);
            out.extend(m.new.iter().map(|k| (owner, k.map(&vertex_id))));
            kept.push(owner);
        }
    }
    drop(merges);
    let units = triangles
        .iter()
        .zip(&steps.cubes)
        .zip(&dropped)
        .filter(|&((_, &c), &d)| !d && !in_box(c))
        .map(|((&t, &c), _)| (c, t));
    let mut all: Vec<(u64, [u32; 3])> = units.collect();
    all.append(&mut out);
    Units {
        triangles: all,
        merges: kept,
    }
}

/// (E) for a merge: its two triangles and its fan within the bound of each other, both ways.
fn within_each_other(
    m: &Merge,
    triangles: &[[u32; 3]],
    steps: &Recorded,
    place: impl Fn(u64) -> [f64; 3],
    tolerance: &Tolerance,
) -> bool {
    // Called for whole merges only: a fan of four, two new triangles.
    let at = |key: u64| scaled(place(key), tolerance);
    let fan: [[[f64; 3]; 3]; 4] =
        core::array::from_fn(|s| triangles[m.fan[s]].map(|v| at(steps.edges[v as usize])));
    let new: [[[f64; 3]; 3]; 2] = core::array::from_fn(|s| m.new[s].map(at));
    new.iter().all(|&t| within(t, &fan[..], tolerance.limit))
        && fan.iter().all(|&t| within(t, &new[..], tolerance.limit))
}

/// Whether no corner of a merge's four cubes lies inside the closed surface its fan and its two
/// triangles (reversed) make: the samples that would change side. By the parity of a ray's
/// crossings; a ray that grazes a side or starts on the surface counts as a change, so the
/// merge is refused (which only costs triangles).
fn keeps_sides(
    m: &Merge,
    triangles: &[[u32; 3]],
    steps: &Recorded,
    place: impl Fn(u64) -> [f64; 3],
) -> bool {
    let mut shell = [[[0.0; 3]; 3]; 6];
    for (s, &i) in m.fan.iter().enumerate() {
        shell[s] = triangles[i].map(|v| place(steps.edges[v as usize]));
    }
    for (s, k) in m.new.iter().enumerate() {
        shell[4 + s] = k.map(&place);
    }
    // A direction no grid line or face diagonal follows.
    const RAY: [f64; 3] = [1.0, 0.313_7, 0.271_9];
    for &i in &m.fan {
        let cube = super::unkey(steps.cubes[i] as usize, steps.dims);
        for corner in 0..8 {
            let p: [f64; 3] = core::array::from_fn(|d| (cube[d] + (corner >> d & 1)) as f64);
            let mut crossings = 0;
            for t in &shell {
                match ray_hits(p, RAY, t) {
                    Some(true) => crossings += 1,
                    Some(false) => {}
                    None => return false,
                }
            }
            if crossings % 2 == 1 {
                return false;
            }
        }
    }
    true
}

/// Whether the ray `p + s · d`, `s > 0`, crosses triangle `t` (Möller–Trumbore); `None` where
/// it comes too close to a side, a corner or its own start to tell.
fn ray_hits(p: [f64; 3], d: [f64; 3], t: &[[f64; 3]; 3]) -> Option<bool> {
    const EPS: f64 = 1e-9;
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (e1, e2) = (sub(t[1], t[0]), sub(t[2], t[0]));
    let h = cross(d, e2);
    let det = dot(e1, h);
    if det.abs() < EPS {
        // Parallel to the plane: no crossing, unless the start lies in it.
        let n = cross(e1, e2);
        return (dot(n, sub(p, t[0])).abs() > EPS).then_some(false);
    }
    let q = sub(p, t[0]);
    let u = dot(q, h) / det;
    let r = cross(q, e1);
    let v = dot(d, r) / det;
    let s = dot(e2, r) / det;
    let near = |x: f64| x.abs() < EPS;
    if near(u) || near(v) || near(1.0 - u - v) {
        let inside = u > -EPS && v > -EPS && u + v < 1.0 + EPS;
        return if inside && s > -EPS {
            None
        } else {
            Some(false)
        };
    }
    if u < 0.0 || v < 0.0 || u + v > 1.0 {
        return Some(false);
    }
    if near(s) {
        return None;
    }
    Some(s > 0.0)
}
