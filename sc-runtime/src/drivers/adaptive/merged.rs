//! Step 4 among the unit cubes no box covers (docs/adaptive.md, "Kept"): embedded mode's merges,
//! kept wherever the four cubes a merge touches all stay unit cubes.
//!
//! A merge removes the vertex on a grey edge and replaces the four triangles around it, one in
//! each cube around the edge, by two on the same four outer vertices; the sides on the four
//! cubes' outer faces stay as they were. So a merge whose four cubes are outside every box can be
//! kept as embedded mode makes it: the walls it shares with boxes are unchanged, and the boxes'
//! tests still hold beside it.
//!
//! Of embedded mode's sweep only the vertices its merges removed are kept ([`Removed`]): the
//! rest follows from the Steps 1–3 mesh. A removed vertex's fan is the four triangles around it,
//! and the two triangles replacing them split the fan's ring along the diagonal SPEC §5 chooses
//! ([`Merge::pair`]). Holding embedded mode's mesh, and matching its triangles to the fans, would
//! take a third of adaptive mode's peak memory.

use alloc::vec::Vec;

use super::Owned;
use super::record::Recorded;
use crate::Sink;
use crate::kernel::adaptive::Tolerance;
use crate::kernel::adaptive::checks::{scaled, within};

/// Embedded mode's sweep, read for the Steps 1–3 vertices its merges removed. It sends Steps
/// 1–3's vertices in the same order, less those (a merged grey edge's vertex is never made), so
/// one pass along Steps 1–3's edge keys finds them.
pub(super) struct Removed<'a> {
    /// Steps 1–3's record: its edge keys come in the order its sweep sent them.
    steps: &'a Recorded,
    /// The next Steps 1–3 vertex embedded mode may send.
    next: usize,
    /// The ones it skipped, ascending.
    ids: Vec<u32>,
    /// Set if embedded mode sent a vertex out of that order, which the sweeps do not do: then
    /// no merge is kept (more triangles, the same guarantees).
    lost: bool,
}

impl<'a> Removed<'a> {
    pub fn new(steps: &'a Recorded) -> Self {
        Removed {
            steps,
            next: 0,
            ids: Vec::new(),
            lost: false,
        }
    }

    fn sent(&mut self, key: u64) {
        while let Some(&k) = self.steps.edges.get(self.next) {
            self.next += 1;
            if k == key {
                return;
            }
            self.ids.push((self.next - 1) as u32);
        }
        debug_assert!(
            false,
            "embedded mode sent edge {key} out of Steps 1–3's order"
        );
        self.lost = true;
    }

    /// The Steps 1–3 vertex ids embedded mode's merges removed, ascending.
    pub fn finish(mut self) -> Vec<u32> {
        if self.lost {
            return Vec::new();
        }
        self.ids
            .extend((self.next..self.steps.edges.len()).map(|v| v as u32));
        self.ids.shrink_to_fit();
        self.ids
    }
}

impl Sink for Removed<'_> {
    fn vertex(&mut self, _: [f32; 3], _: Option<[f32; 3]>) {
        // As `Recorded` keys a vertex sent without its edge.
        self.sent(u64::MAX);
    }

    fn edge_vertex(&mut self, lower: [usize; 3], axis: usize, _: [f32; 3], _: Option<[f32; 3]>) {
        self.sent(3 * self.steps.point_key(lower) + axis as u64);
    }

    fn triangle(&mut self, _: [u32; 3]) {}
}

/// A triangle rotated to start at the vertex with the least edge key (the winding kept), as
/// embedded mode's sweep makes a merged one.
fn from_least(t: [u32; 3], edges: &[u64]) -> [u32; 3] {
    let i = (0..3).min_by_key(|&i| edges[t[i] as usize]).unwrap_or(0);
    [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
}

/// The fan of a removed vertex: the Steps 1–3 triangles around it, one per cube around its grey
/// edge.
#[derive(Clone, Copy, Default)]
struct Merge {
    fan: [usize; 4],
    fans: u8,
}

impl Merge {
    fn push_fan(&mut self, triangle: usize) {
        if let Some(slot) = self.fan.get_mut(usize::from(self.fans)) {
            *slot = triangle;
        }
        self.fans = self.fans.saturating_add(1);
    }

    /// The two triangles (each from its least edge key) that replace the fan of `removed`,
    /// in the order embedded mode's sweep makes them; `None` unless the fan is four triangles
    /// whose outer sides close one ring with one diagonal on SPEC §5's plane.
    ///
    /// The fan's triangles `(removed, q_i, q_i+1)` chain into the ring `q_0 … q_3`, wound as
    /// they are. The diagonal joins the two ring vertices that lie in the edge's plane `z = n`
    /// for an x- or y-grey edge, in `x = l` (`n` even) or `y = m` (`n` odd) for a z-grey edge:
    /// a vertex lies in a plane when its edge does. Each new triangle takes the place of the two
    /// fan triangles on its side of the diagonal, and comes out, as in the sweep, with the lower
    /// of their two cubes.
    fn pair(
        &self,
        removed: u32,
        triangles: &[[u32; 3]],
        steps: &Recorded,
    ) -> Option<[[u32; 3]; 2]> {
        if self.fans != 4 {
            return None;
        }
        // Each fan triangle from the removed vertex: its outer side, and its cube.
        let mut sides = [(0u32, 0u32, 0u64); 4];
        for (side, &i) in sides.iter_mut().zip(&self.fan) {
            let t = triangles[i];
            let at = t.iter().position(|&v| v == removed)?;
            *side = (t[(at + 1) % 3], t[(at + 2) % 3], steps.cubes[i]);
        }
        // The ring, side by side from the first.
        let mut ring = [(0u32, 0u64); 4];
        let (mut from, mut to, mut cube) = sides[0];
        for slot in &mut ring {
            *slot = (from, cube);
            (from, to, cube) = *sides.iter().find(|s| s.0 == to)?;
        }
        let distinct = (0..4).all(|i| (i + 1..4).all(|j| ring[i].0 != ring[j].0));
        if from != ring[0].0 || !distinct {
            return None;
        }
        let (edge, dims) = (steps.edges[removed as usize], steps.dims);
        let lower = super::unkey((edge / 3) as usize, dims);
        // The plane: the coordinate fixed, and its value.
        let (fixed, value) = match edge % 3 {
            2 if lower[2].is_multiple_of(2) => (0, lower[0]),
            2 => (1, lower[1]),
            _ => (2, lower[2]),
        };
        let in_plane = |v: u32| {
            let key = steps.edges[v as usize];
            key % 3 != fixed as u64 && super::unkey((key / 3) as usize, dims)[fixed] == value
        };
        let on = |a: usize| in_plane(ring[a].0) && in_plane(ring[a + 2].0);
        let a = match (on(0), on(1)) {
            (true, false) => 0,
            (false, true) => 1,
            _ => return None,
        };
        let q = |i: usize| ring[(a + i) % 4];
        let first = [q(0).0, q(1).0, q(2).0];
        let second = [q(2).0, q(3).0, q(0).0];
        let (c1, c2) = (q(0).1.min(q(1).1), q(2).1.min(q(3).1));
        let (first, second) = (
            from_least(first, &steps.edges),
            from_least(second, &steps.edges),
        );
        Some(if c1 <= c2 {
            [first, second]
        } else {
            [second, first]
        })
    }
}

/// Pushes onto `out` the triangles of the cubes outside boxes, as ids of the Steps 1–3 vertices,
/// each with the key of the cube that owns it, and returns the owner of each merge kept. They
/// are Steps 1–3's (`triangles`, recorded in `steps`), except that each merge of embedded mode
/// (by the vertex it `removed`, ascending: see [`Removed`]) whose four cubes are outside boxes
/// replaces its fan. A unit cube owns its own triangles; a merge's two belong to the least of
/// its four cubes, one a merge always reads, so the owner is found wherever the merge is, and
/// come after that cube's own. `place` maps an edge key to its position in grid steps; `in_box`
/// says whether a cube (by key) lies in a box. A merge is kept only if its two triangles and its
/// fan lie within the tolerance of each other, every point (embedded mode's bound measures the
/// removed vertex and the new diagonal only), and, unless the tolerance allows wrong-side
/// samples, if no corner of its four cubes changes side ([`keeps_sides`]).
pub(super) fn unit_triangles(
    triangles: &[[u32; 3]],
    steps: &Recorded,
    removed: &[u32],
    place: impl Fn(u64) -> [f64; 3],
    in_box: impl Fn(u64) -> bool,
    tolerance: &Tolerance,
    out: &mut Vec<Owned>,
) -> Vec<u64> {
    // A bit per Steps 1–3 vertex, so that most triangle corners cost one test.
    let mut is_removed = alloc::vec![0u64; steps.edges.len().div_ceil(64)];
    for &v in removed {
        is_removed[v as usize / 64] |= 1 << (v % 64);
    }
    let mut merges = alloc::vec![Merge::default(); removed.len()];
    for (i, t) in triangles.iter().enumerate() {
        for &v in t {
            if is_removed[v as usize / 64] >> (v % 64) & 1 == 1
                && let Ok(m) = removed.binary_search(&v)
            {
                merges[m].push_fan(i);
            }
        }
    }
    drop(is_removed);
    // In the order of the removed vertices' edges: merges with one owner keep that order
    // wherever the vertices are numbered (a block's sweep numbers them apart).
    let mut order: Vec<u32> = (0..removed.len() as u32).collect();
    order.sort_unstable_by_key(|&m| steps.edges[removed[m as usize] as usize]);
    let mut dropped = alloc::vec![false; triangles.len()];
    let mut new = Vec::new();
    let mut kept = Vec::new();
    for m in order {
        let (merge, v) = (&merges[m as usize], removed[m as usize]);
        if !merge.fan.iter().all(|&i| !in_box(steps.cubes[i])) {
            continue;
        }
        let Some(pair) = merge.pair(v, triangles, steps) else {
            continue;
        };
        if within_each_other(merge, &pair, triangles, steps, &place, tolerance)
            && (tolerance.allow_wrong_side || keeps_sides(merge, &pair, triangles, steps, &place))
        {
            for &i in &merge.fan {
                dropped[i] = true;
            }
            let owner = merge
                .fan
                .iter()
                .map(|&i| steps.cubes[i])
                .min()
                .unwrap_or(u64::MAX);
            new.extend(pair.map(|t| Owned::new(owner, t)));
            kept.push(owner);
        }
    }
    drop(merges);
    let units = || {
        triangles
            .iter()
            .zip(&steps.cubes)
            .zip(&dropped)
            .filter(|&((_, &c), &d)| !d && !in_box(c))
            .map(|((&t, &c), _)| Owned::new(c, t))
    };
    // Counted first: `out` may already hold the boxes' triangles, the largest list adaptive
    // mode makes, and is grown once.
    out.reserve_exact(units().count() + new.len());
    out.extend(units());
    out.append(&mut new);
    kept
}

/// (E) for a merge: its two triangles and its fan within the bound of each other, both ways.
fn within_each_other(
    m: &Merge,
    new: &[[u32; 3]; 2],
    triangles: &[[u32; 3]],
    steps: &Recorded,
    place: impl Fn(u64) -> [f64; 3],
    tolerance: &Tolerance,
) -> bool {
    // Called for whole merges only: a fan of four, two new triangles.
    let at = |key: u64| scaled(place(key), tolerance);
    let fan: [[[f64; 3]; 3]; 4] =
        core::array::from_fn(|s| triangles[m.fan[s]].map(|v| at(steps.edges[v as usize])));
    let new: [[[f64; 3]; 3]; 2] =
        core::array::from_fn(|s| new[s].map(|v| at(steps.edges[v as usize])));
    new.iter().all(|&t| within(t, &fan[..], tolerance.limit))
        && fan.iter().all(|&t| within(t, &new[..], tolerance.limit))
}

/// Whether no corner of a merge's four cubes lies inside the closed surface its fan and its two
/// triangles (reversed) make: the samples that would change side. By the parity of a ray's
/// crossings; a ray that grazes a side or starts on the surface counts as a change, so the
/// merge is refused (which only costs triangles).
fn keeps_sides(
    m: &Merge,
    new: &[[u32; 3]; 2],
    triangles: &[[u32; 3]],
    steps: &Recorded,
    place: impl Fn(u64) -> [f64; 3],
) -> bool {
    let mut shell = [[[0.0; 3]; 3]; 6];
    for (s, &i) in m.fan.iter().enumerate() {
        shell[s] = triangles[i].map(|v| place(steps.edges[v as usize]));
    }
    for (s, t) in new.iter().enumerate() {
        shell[4 + s] = t.map(|v| place(steps.edges[v as usize]));
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
