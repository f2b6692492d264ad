//! The simplicity test (S) and a box's loop (docs/adaptive.md §2).
//!
//! Along each axis, every grid line through the closed box may hold at most one occupied unit
//! edge, and all of them must cross the same way. The filled samples of the box are then a
//! down-set after flipping axes, their boundary is one disk, and every face of the box carries at
//! most one arc of the Step 2 curve: the loop is one polygon through at most six corner vertices
//! (one per box edge crossed), and each arc passes through the occupied midline edges of its face
//! in between. The loop is oriented as the surface is (filled → empty), from the crossings'
//! direction along the axis that has the most of them.

use super::{BoxSource, MAX_CORNERS, MAX_MIDS, Vertex};
use crate::kernel::adaptive::checks::double_area;

/// A box's loop: its corner vertices in order, and per arc (from corner `i` to corner `i + 1`,
/// cyclically) the face it lies on and its midline vertices in the order the arc visits them.
#[derive(Clone, Debug)]
pub(crate) struct Outline {
    /// The box's lower corner, in samples.
    pub corner: [usize; 3],
    /// The box's side, in cubes.
    pub side: usize,
    /// Corner vertices, in the loop's order.
    pub corners: [Vertex; MAX_CORNERS],
    /// How many corners (3 to 6).
    pub n: usize,
    /// The face of arc `i`, as `2 · axis + side`.
    pub arc_face: [u8; MAX_CORNERS],
    /// The midline vertices of arc `i`, from corner `i` on.
    pub mids: [[Vertex; MAX_MIDS]; MAX_CORNERS],
    /// How many of them.
    pub mid_count: [u8; MAX_CORNERS],
    /// The axis with the most occupied edges: the surface is meant to be a graph over the plane
    /// across it, and (F) checks that it is.
    pub axis: usize,
    /// Whether the surface's normal points up `axis` (the filled end of its edges is the lower).
    pub up: bool,
}

/// What the simplicity test makes of a box. Returned once per box and matched at once; the
/// kernel has no heap to box the outline on.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)]
pub(crate) enum Shape {
    /// No occupied edge in the closed box: nothing to emit.
    Empty,
    /// One loop, as (S) promises.
    Simple(Outline),
    /// (S) fails: the box stays unit cubes.
    Complex,
}

/// The two other axes, in cyclic order.
#[inline]
pub(crate) fn others(axis: usize) -> [usize; 2] {
    [(axis + 1) % 3, (axis + 2) % 3]
}

/// The point `corner + u · e(o₁) + v · e(o₂) + k · e(axis)`.
#[inline]
pub(crate) fn on_line(corner: [usize; 3], axis: usize, [u, v]: [usize; 2], k: usize) -> [usize; 3] {
    let [o1, o2] = others(axis);
    let mut p = corner;
    p[o1] += u;
    p[o2] += v;
    p[axis] += k;
    p
}

/// The vertex on the grid line along `axis` at `(u, v)` through the box, if the line has one.
fn line_vertex(
    src: &impl BoxSource,
    corner: [usize; 3],
    side: usize,
    axis: usize,
    uv: [usize; 2],
) -> Option<Vertex> {
    (0..side).find_map(|k| {
        let lower = on_line(corner, axis, uv, k);
        src.crossing(lower, axis)
            .map(|c| Vertex::new(lower, axis, c, corner, side))
    })
}

/// Runs (S) on the box of side `side` at `corner` and traces its loop.
pub(crate) fn outline(src: &impl BoxSource, corner: [usize; 3], side: usize) -> Shape {
    let mut totals = [0usize; 3];
    let mut dirs: [Option<bool>; 3] = [None; 3];
    for axis in 0..3 {
        for u in 0..=side {
            for v in 0..=side {
                // Each sample once: an edge is occupied where the filled state changes.
                let mut count = 0;
                let mut below = src.filled(on_line(corner, axis, [u, v], 0));
                for k in 0..side {
                    let above = src.filled(on_line(corner, axis, [u, v], k + 1));
                    if below != above {
                        count += 1;
                        match dirs[axis] {
                            None => dirs[axis] = Some(below),
                            Some(d) if d != below => return Shape::Complex,
                            Some(_) => {}
                        }
                    }
                    below = above;
                }
                if count > 1 {
                    return Shape::Complex;
                }
                totals[axis] += count;
            }
        }
    }
    if totals == [0; 3] {
        return Shape::Empty;
    }
    // Box edges: along `axis` at (u, v) ∈ {0, side}², numbered 4 · axis + u/side + 2 · v/side.
    let edge_uv = |e: usize| [(e & 1) * side, (e >> 1 & 1) * side];
    let edge_vertex: [Option<Vertex>; 12] =
        core::array::from_fn(|e| line_vertex(src, corner, side, e / 4, edge_uv(e % 4)));
    // The two faces (2 · axis + side) each box edge lies on.
    let edge_faces = |e: usize| {
        let [o1, o2] = others(e / 4);
        let [u, v] = edge_uv(e % 4);
        [2 * o1 + u / side, 2 * o2 + v / side]
    };
    // Each face's crossed box edges: none or two.
    let mut face_ends = [[usize::MAX; 2]; 6];
    let mut face_count = [0usize; 6];
    for (e, vertex) in edge_vertex.iter().enumerate() {
        if vertex.is_some() {
            for f in edge_faces(e) {
                if face_count[f] < 2 {
                    face_ends[f][face_count[f]] = e;
                }
                face_count[f] += 1;
            }
        }
    }
    if face_count.iter().any(|&c| c != 0 && c != 2) {
        return Shape::Complex;
    }
    // Walk the loop from the first crossed box edge.
    let Some(start) = edge_vertex.iter().position(Option::is_some) else {
        return Shape::Complex;
    };
    let mut out = Outline {
        corner,
        side,
        corners: [Vertex::default(); MAX_CORNERS],
        n: 0,
        arc_face: [0; MAX_CORNERS],
        mids: [[Vertex::default(); MAX_MIDS]; MAX_CORNERS],
        mid_count: [0; MAX_CORNERS],
        axis: 0,
        up: false,
    };
    let (mut at, mut came) = (start, usize::MAX);
    loop {
        if out.n == MAX_CORNERS {
            return Shape::Complex;
        }
        let [f0, f1] = edge_faces(at);
        let face = if f0 == came { f1 } else { f0 };
        let [a, b] = face_ends[face];
        let next = if a == at { b } else { a };
        out.corners[out.n] = edge_vertex[at].unwrap_or_default();
        out.arc_face[out.n] = face as u8;
        out.n += 1;
        (at, came) = (next, face);
        if at == start {
            break;
        }
    }
    let crossed = edge_vertex.iter().filter(|v| v.is_some()).count();
    if out.n != crossed || out.n < 3 {
        return Shape::Complex;
    }
    for i in 0..out.n {
        let (count, mids) = face_mids(src, &out, i);
        out.mid_count[i] = count;
        out.mids[i] = mids;
    }
    out.axis = (0..3).max_by_key(|&a| (totals[a], 3 - a)).unwrap_or(0);
    out.up = dirs[out.axis].unwrap_or(false);
    // Orient the loop as the surface: its projection across `axis` turns positively iff the
    // normal points up the axis.
    let mut loop_points = [[0.0; 3]; super::MAX_POLYGON];
    let mut m = 0;
    for i in 0..out.n {
        loop_points[m] = out.corners[i].p;
        m += 1;
        for w in &out.mids[i][..usize::from(out.mid_count[i])] {
            loop_points[m] = w.p;
            m += 1;
        }
    }
    let turn = double_area(&loop_points[..m], out.axis);
    if turn.abs() < 1e-9 {
        return Shape::Complex;
    }
    if (turn > 0.0) != out.up {
        reverse(&mut out);
    }
    Shape::Simple(out)
}

/// The occupied midline edges of arc `i`'s face, in the order the arc visits them from corner
/// `i`. The arc is monotone in both directions of its face, so that order is the order of the
/// coordinates' sum, each signed toward the arc's end.
fn face_mids(src: &impl BoxSource, out: &Outline, i: usize) -> (u8, [Vertex; MAX_MIDS]) {
    let face = usize::from(out.arc_face[i]);
    let (normal, high, s) = (face / 2, face % 2, out.side);
    let mut mids = [Vertex::default(); MAX_MIDS];
    let mut count = 0;
    for axis in others(normal) {
        // The line along `axis` through the middle of the face.
        let [o1, _] = others(axis);
        let uv = if o1 == normal {
            [high * s, s / 2]
        } else {
            [s / 2, high * s]
        };
        if let Some(w) = line_vertex(src, out.corner, s, axis, uv) {
            mids[count] = w;
            count += 1;
        }
    }
    let (a, b) = (out.corners[i].p, out.corners[(i + 1) % out.n].p);
    let key = |w: &Vertex| -> f64 {
        others(normal)
            .iter()
            .map(|&d| (w.p[d] - a[d]) * (b[d] - a[d]).signum())
            .sum()
    };
    if count == 2 && key(&mids[1]) < key(&mids[0]) {
        mids.swap(0, 1);
    }
    (count as u8, mids)
}

/// Turns the loop around: corner `i` becomes corner `n − 1 − i`, and each arc runs backwards.
fn reverse(out: &mut Outline) {
    let n = out.n;
    let old = out.clone();
    for i in 0..n {
        out.corners[i] = old.corners[n - 1 - i];
        // The new arc i joins old corners n − 1 − i and n − 2 − i: the old arc n − 2 − i.
        let j = (2 * n - 2 - i) % n;
        out.arc_face[i] = old.arc_face[j];
        let count = usize::from(old.mid_count[j]);
        out.mid_count[i] = old.mid_count[j];
        for k in 0..count {
            out.mids[i][k] = old.mids[j][count - 1 - k];
        }
    }
}

impl Outline {
    /// Whether arc `i` has midline vertices: only then does its neighbour's size matter.
    pub fn has_mids(&self, i: usize) -> bool {
        self.mid_count[i] > 0
    }

    /// The polygon of a variant: each corner, followed by its arc's midline vertices when bit
    /// `i` of `refined` is set.
    pub fn polygon(&self, refined: u8) -> ([Vertex; super::MAX_POLYGON], usize) {
        let mut out = [Vertex::default(); super::MAX_POLYGON];
        let mut m = 0;
        for i in 0..self.n {
            out[m] = self.corners[i];
            m += 1;
            if refined >> i & 1 == 1 {
                for &w in &self.mids[i][..usize::from(self.mid_count[i])] {
                    out[m] = w;
                    m += 1;
                }
            }
        }
        (out, m)
    }

    /// The arc on face `face` in a variant, corner to corner, if the loop crosses that face.
    pub fn face_polyline(
        &self,
        face: usize,
        refined: u8,
    ) -> Option<([Vertex; 2 + MAX_MIDS], usize)> {
        let i = (0..self.n).find(|&i| usize::from(self.arc_face[i]) == face)?;
        let mut out = [Vertex::default(); 2 + MAX_MIDS];
        out[0] = self.corners[i];
        let mut m = 1;
        if refined >> i & 1 == 1 {
            for &w in &self.mids[i][..usize::from(self.mid_count[i])] {
                out[m] = w;
                m += 1;
            }
        }
        out[m] = self.corners[(i + 1) % self.n];
        Some((out, m + 1))
    }
}
