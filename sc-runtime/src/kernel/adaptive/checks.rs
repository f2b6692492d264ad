//! The geometric tests a box's triangles pass before they replace Steps 1–3's
//! (docs/adaptive.md §2): (F) fold-free and embedded, (P) separating, (E) within the error bound.
//!
//! They run in `f64` on positions in grid steps, with margins far above the rounding of the
//! emitted `f32` positions: a box close to failing a test is left as unit cubes, which only
//! costs triangles.

use super::outline::{Outline, on_line, others};
use super::{BoxSource, MAX_POLYGON, Patch, Tolerance, Vertex};
use crate::geometry::point_triangle_distance_squared;
use crate::kernel::vertex::root::sqrt;

/// The least doubled area, in grid steps², of a triangle's projection across the box's axis.
const MIN_AREA: f64 = 1e-4;
/// The least distance, in grid steps, between a grid line and a projected triangle's side it
/// passes, and between where the surface crosses a grid line and a sample.
const MARGIN: f64 = 1e-3;

/// Twice the signed area of a closed polygon's projection across `axis`, in the plane of the
/// two other axes in cyclic order: positive iff it turns as the normals up `axis` do.
pub(crate) fn double_area(points: &[[f64; 3]], axis: usize) -> f64 {
    let [x, y] = others(axis);
    let n = points.len();
    (0..n)
        .map(|i| {
            let (p, q) = (points[i], points[(i + 1) % n]);
            p[x] * q[y] - q[x] * p[y]
        })
        .sum()
}

/// Twice the signed area of `p, q, r` in 2-D.
#[inline]
fn orient(p: [f64; 2], q: [f64; 2], r: [f64; 2]) -> f64 {
    (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
}

/// A point's projection across `axis`.
#[inline]
fn flat(p: [f64; 3], axis: usize) -> [f64; 2] {
    let [x, y] = others(axis);
    [p[x], p[y]]
}

/// Whether a triangle lies wholly in one face of the box: it would be a wall, shared with no
/// one.
#[inline]
pub(crate) fn in_wall(t: &[Vertex; 3]) -> bool {
    t[0].faces & t[1].faces & t[2].faces != 0
}

/// (F), per triangle: its projection across the box's axis turns the way the surface does, by a
/// margin.
#[inline]
pub(crate) fn faces_up(t: &[Vertex; 3], outline: &Outline) -> bool {
    let a = outline.axis;
    let area = orient(flat(t[0].p, a), flat(t[1].p, a), flat(t[2].p, a));
    if outline.up {
        area > MIN_AREA
    } else {
        area < -MIN_AREA
    }
}

/// (F), per polygon: its projection across the box's axis is a simple closed curve. With every
/// triangle turning the same way (`faces_up`), the projection of the triangulated disk is then
/// one-to-one, so no two triangles meet but along their shared sides and corners. Sides on the
/// faces along the axis project onto the square's border, in runs on one line; they are
/// compared as intervals.
pub(crate) fn simple_projection(polygon: &[Vertex], axis: usize) -> bool {
    let m = polygon.len();
    let mut pts = [[0.0; 2]; MAX_POLYGON];
    for (i, v) in polygon.iter().enumerate() {
        pts[i] = flat(v.p, axis);
    }
    let pts = &pts[..m];
    let tol = 1e-9;
    for i in 0..m {
        let (p, q, r) = (pts[i], pts[(i + 1) % m], pts[(i + 2) % m]);
        let d = [q[0] - p[0], q[1] - p[1]];
        if d[0].abs() + d[1].abs() < MARGIN {
            return false;
        }
        // Consecutive sides must not fold back onto each other.
        let e = [r[0] - q[0], r[1] - q[1]];
        if orient(p, q, r).abs() <= tol && d[0] * e[0] + d[1] * e[1] < 0.0 {
            return false;
        }
        for j in i + 2..m {
            if (j + 1) % m == i {
                continue;
            }
            if segments_meet(p, q, pts[j], pts[(j + 1) % m], tol) {
                return false;
            }
        }
    }
    true
}

/// Whether two closed segments meet, or come too close to tell.
fn segments_meet(p: [f64; 2], q: [f64; 2], r: [f64; 2], s: [f64; 2], tol: f64) -> bool {
    let (o1, o2) = (orient(p, q, r), orient(p, q, s));
    let (o3, o4) = (orient(r, s, p), orient(r, s, q));
    if [o1, o2, o3, o4].iter().all(|o| o.abs() <= tol) {
        // On one line: compare the intervals along the coordinate that varies most.
        let c = usize::from((q[1] - p[1]).abs() > (q[0] - p[0]).abs());
        let (lo1, hi1) = (p[c].min(q[c]), p[c].max(q[c]));
        let (lo2, hi2) = (r[c].min(s[c]), r[c].max(s[c]));
        return lo1 <= hi2 + MARGIN && lo2 <= hi1 + MARGIN;
    }
    let apart = |a: f64, b: f64| (a > tol && b > tol) || (a < -tol && b < -tol);
    !(apart(o1, o2) || apart(o3, o4))
}

/// (P): every grid line through the closed box meets the box's triangles exactly where it has
/// an occupied unit edge, inside that edge and away from its samples, and nowhere else. Lines
/// on the box's edges meet them only at their corner vertices. Lines in a face meet them where
/// they meet that face's arc (the triangles touch the faces only along it), which the box on the
/// other side shares. Lines inside are tested against every triangle's projection.
pub(crate) fn separates(
    src: &impl BoxSource,
    outline: &Outline,
    refined: u8,
    tris: &[[Vertex; 3]],
) -> bool {
    let (corner, side) = (outline.corner, outline.side);
    for axis in 0..3 {
        let [o1, o2] = others(axis);
        for u in 0..=side {
            for v in 0..=side {
                let (edge_u, edge_v) = (u % side == 0, v % side == 0);
                if edge_u && edge_v {
                    continue;
                }
                // The line's occupied edge, if any ((S): at most one).
                let mut below = src.filled(on_line(corner, axis, [u, v], 0));
                let want = (0..side).find_map(|k| {
                    let above = src.filled(on_line(corner, axis, [u, v], k + 1));
                    let occupied = below != above;
                    below = above;
                    occupied.then_some(corner[axis] + k)
                });
                let at = [(corner[o1] + u) as f64, (corner[o2] + v) as f64];
                let mut hits = [0.0; 2];
                let count = if edge_u || edge_v {
                    let face = if edge_u {
                        2 * o1 + u / side
                    } else {
                        2 * o2 + v / side
                    };
                    // The coordinate across the line within the face.
                    let (w, w_at) = if edge_u { (o2, at[1]) } else { (o1, at[0]) };
                    match outline.face_polyline(face, refined) {
                        Some((line, len)) => polyline_hits(&line[..len], axis, w, w_at, &mut hits),
                        None => 0,
                    }
                } else {
                    match interior_hits(tris, axis, at, &mut hits) {
                        Some(c) => c,
                        None => return false,
                    }
                };
                let ok = match (want, count) {
                    (None, 0) => true,
                    (Some(k), 1) => {
                        let k = k as f64;
                        hits[0] > k + MARGIN && hits[0] < k + 1.0 - MARGIN
                    }
                    _ => false,
                };
                if !ok {
                    return false;
                }
            }
        }
    }
    true
}

/// Where a face's polyline meets the line along `axis` at coordinate `w_at` of axis `w`: at a
/// vertex on it, or across a side whose ends lie on either side of it. Returns how many times
/// (at most two are recorded).
fn polyline_hits(line: &[Vertex], axis: usize, w: usize, w_at: f64, hits: &mut [f64; 2]) -> usize {
    let mut count = 0;
    let mut record = |h: f64, count: &mut usize| {
        if *count < 2 {
            hits[*count] = h;
        }
        *count += 1;
    };
    for v in line {
        if v.p[w] == w_at {
            record(v.p[axis], &mut count);
        }
    }
    for pair in line.windows(2) {
        let (a, b) = (pair[0].p, pair[1].p);
        let (da, db) = (a[w] - w_at, b[w] - w_at);
        if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
            let s = da / (da - db);
            record(a[axis] + s * (b[axis] - a[axis]), &mut count);
        }
    }
    count
}

/// Where the triangles meet the line along `axis` through the projected point `at`; `None` when
/// the line passes too close to a corner to tell, or along a side that is not shared by two
/// triangles on either side of it. A line through a shared side (the diagonal of a quad over a
/// box's middle line, often) meets the surface once, where it crosses that side.
fn interior_hits(
    tris: &[[Vertex; 3]],
    axis: usize,
    at: [f64; 2],
    hits: &mut [f64; 2],
) -> Option<usize> {
    let mut count = 0;
    let mut record = |h: f64, count: &mut usize| {
        if *count < 2 {
            hits[*count] = h;
        }
        *count += 1;
    };
    // Sides the line passes through: their ends, where, and the side their triangle lies on.
    const SIDES: usize = 4;
    let mut on_side = [OnSide::default(); SIDES];
    let mut sides = 0;
    for t in tris {
        let q = t.map(|v| flat(v.p, axis));
        let area = orient(q[0], q[1], q[2]);
        if area.abs() < MIN_AREA {
            // Seen edge on: the line misses it if it passes clear of its sides.
            if (0..3).all(|k| segment_distance(at, q[k], q[(k + 1) % 3]) > MARGIN) {
                continue;
            }
            return None;
        }
        // Each side's distance from the point, positive toward the triangle.
        let mut weights = [0.0; 3];
        let mut outside = false;
        let mut near = [false; 3];
        for k in 0..3 {
            let (a, b) = (q[(k + 1) % 3], q[(k + 2) % 3]);
            let o = orient(a, b, at) * area.signum();
            let len = sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]));
            outside |= o < -MARGIN * len;
            near[k] = o.abs() <= MARGIN * len;
            weights[k] = o;
        }
        if outside {
            continue;
        }
        match near.iter().filter(|&&n| n).count() {
            0 => {
                let total: f64 = weights.iter().sum();
                let h = (0..3).map(|k| weights[k] * t[k].p[axis]).sum::<f64>() / total;
                record(h, &mut count);
            }
            1 => {
                let k = near.iter().position(|&n| n).unwrap_or(0);
                let (mut u, mut v) = (t[(k + 1) % 3].p, t[(k + 2) % 3].p);
                if u > v {
                    core::mem::swap(&mut u, &mut v);
                }
                let (fu, fv) = (flat(u, axis), flat(v, axis));
                let third = orient(fu, fv, q[k]) > 0.0;
                let d = [fv[0] - fu[0], fv[1] - fu[1]];
                let s =
                    ((at[0] - fu[0]) * d[0] + (at[1] - fu[1]) * d[1]) / (d[0] * d[0] + d[1] * d[1]);
                let h = u[axis] + s * (v[axis] - u[axis]);
                match on_side[..sides].iter_mut().find(|e| e.ends == [u, v]) {
                    // The side's other triangle must lie across it, and be its only other one.
                    Some(e) if e.left != third && !e.paired => e.paired = true,
                    Some(_) => return None,
                    None if sides < SIDES => {
                        on_side[sides] = OnSide {
                            ends: [u, v],
                            h,
                            left: third,
                            paired: false,
                        };
                        sides += 1;
                    }
                    None => return None,
                }
            }
            _ => return None,
        }
    }
    for e in &on_side[..sides] {
        if !e.paired {
            return None;
        }
        record(e.h, &mut count);
    }
    Some(count)
}

/// A triangle's side that a grid line passes through.
#[derive(Clone, Copy, Default)]
struct OnSide {
    /// Its ends, in increasing order.
    ends: [[f64; 3]; 2],
    /// Where the line meets it, along the line.
    h: f64,
    /// Whether the triangle lies left of it, seen from its first end.
    left: bool,
    /// Whether a second triangle, on its other side, passed it too.
    paired: bool,
}

/// The distance from `p` to the segment `a b`, in 2-D.
fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    let s = if len2 > 0.0 {
        (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let e = [p[0] - a[0] - s * d[0], p[1] - a[1] - s * d[1]];
    sqrt(e[0] * e[0] + e[1] * e[1])
}

/// A point in grid steps, in the tolerance's units.
#[inline]
pub(crate) fn scaled(p: [f64; 3], tolerance: &Tolerance) -> [f64; 3] {
    core::array::from_fn(|d| p[d] * tolerance.scale[d])
}

/// (E): the box's triangles and the Steps 1–3 triangles of the box lie within the bound of each
/// other, every point of each (not only sampled ones): see [`within`]. Steps 1–3's triangles
/// are small, and one of the box's usually covers each whole.
pub(crate) fn within_bound(
    tris: &[[Vertex; 3]],
    patch: &Patch<'_>,
    tolerance: &Tolerance,
    memo: &mut Memo,
) -> bool {
    let mut ours = [[[0.0; 3]; 3]; super::MAX_TRIANGLES];
    for (i, t) in tris.iter().enumerate() {
        ours[i] = t.map(|v| scaled(v.p, tolerance));
    }
    let ours = &ours[..tris.len()];
    // Steps 1–3's triangles come cube by cube, so the one of ours that covered a triangle
    // likely covers the next: it is tried first ([`within_from`]).
    let mut last = 0;
    ours.iter()
        .all(|&t| memo.get_or(t, || within(t, patch, tolerance.limit)))
        && {
            let mut boxes = [[[0.0; 3]; 2]; super::MAX_TRIANGLES];
            for (b, t) in boxes.iter_mut().zip(ours) {
                *b = bounds(t);
            }
            let ours = Boxed {
                tris: ours,
                boxes: &boxes[..ours.len()],
            };
            patch
                .tris
                .iter()
                .all(|&t| within_from(t, &ours, tolerance.limit, &mut last))
        }
}

/// A triangle's bounding box: its lower and upper corner.
pub(crate) fn bounds(t: &[[f64; 3]; 3]) -> [[f64; 3]; 2] {
    [
        core::array::from_fn(|d| t[0][d].min(t[1][d]).min(t[2][d])),
        core::array::from_fn(|d| t[0][d].max(t[1][d]).max(t[2][d])),
    ]
}

/// A few triangles with their bounding boxes, searched whole.
struct Boxed<'a> {
    tris: &'a [[[f64; 3]; 3]],
    boxes: &'a [[[f64; 3]; 2]],
}

/// Which of a box's triangles lie within the bound of its patch, remembered while the box is
/// judged: its variants and candidate triangulations share most triangles.
#[derive(Clone, Debug)]
pub(crate) struct Memo {
    seen: [([[f64; 3]; 3], bool); Memo::SIZE],
    n: usize,
}

impl Memo {
    /// Triangles remembered; later ones are measured each time.
    const SIZE: usize = 96;

    /// Nothing remembered.
    pub fn new() -> Self {
        Memo {
            seen: [([[0.0; 3]; 3], false); Memo::SIZE],
            n: 0,
        }
    }

    /// `t`'s answer, from memory or from `f`.
    fn get_or(&mut self, t: [[f64; 3]; 3], f: impl FnOnce() -> bool) -> bool {
        if let Some(&(_, ok)) = self.seen[..self.n].iter().find(|(s, _)| *s == t) {
            return ok;
        }
        let ok = f();
        if self.n < Memo::SIZE {
            self.seen[self.n] = (t, ok);
            self.n += 1;
        }
        ok
    }
}

/// Triangles [`within`] measures against.
pub(crate) trait Nearby {
    /// All of them.
    fn tris(&self) -> &[[[f64; 3]; 3]];
    /// Triangle `k`'s bounding box ([`bounds`]).
    fn bounds(&self, k: usize) -> [[f64; 3]; 2];
    /// The first index, among the triangles that may meet the box `lo ..= hi`, for which `f`
    /// holds.
    fn find(&self, lo: [f64; 3], hi: [f64; 3], f: impl FnMut(usize) -> bool) -> Option<usize>;
}

impl Nearby for [[[f64; 3]; 3]] {
    fn tris(&self) -> &[[[f64; 3]; 3]] {
        self
    }

    fn bounds(&self, k: usize) -> [[f64; 3]; 2] {
        bounds(&self[k])
    }

    fn find(&self, _: [f64; 3], _: [f64; 3], f: impl FnMut(usize) -> bool) -> Option<usize> {
        (0..self.len()).position(f)
    }
}

impl Nearby for Boxed<'_> {
    fn tris(&self) -> &[[[f64; 3]; 3]] {
        self.tris
    }

    fn bounds(&self, k: usize) -> [[f64; 3]; 2] {
        self.boxes[k]
    }

    fn find(&self, _: [f64; 3], _: [f64; 3], f: impl FnMut(usize) -> bool) -> Option<usize> {
        (0..self.tris.len()).position(f)
    }
}

impl Nearby for Patch<'_> {
    fn tris(&self) -> &[[[f64; 3]; 3]] {
        self.tris
    }

    fn bounds(&self, k: usize) -> [[f64; 3]; 2] {
        self.boxes[k]
    }

    /// Only the cubes whose closed box meets `lo ..= hi`: a Steps 1–3 triangle lies in its cube.
    fn find(&self, lo: [f64; 3], hi: [f64; 3], mut f: impl FnMut(usize) -> bool) -> Option<usize> {
        let mut from = [0; 3];
        let mut to = [0; 3];
        for d in 0..3 {
            // In cubes from the box's corner: cube c spans [c, c + 1]. Casts truncate, which is
            // the floor for the non-negative values they see (`no_std` has no `f64::floor`).
            let at = self.corner[d] as f64;
            let (x, y) = (lo[d] / self.scale[d] - at, hi[d] / self.scale[d] - at);
            if y < 0.0 {
                return None;
            }
            from[d] = if x < 1.0 { 0 } else { x as usize - 1 };
            to[d] = (y as usize).min(self.side - 1);
            if to[d] < from[d] {
                return None;
            }
        }
        for z in from[2]..=to[2] {
            for y in from[1]..=to[1] {
                for x in from[0]..=to[0] {
                    let c = x + self.side * (y + self.side * z);
                    let range = self.starts[c] as usize..self.starts[c + 1] as usize;
                    if let Some(k) = range.into_iter().find(|&k| f(k)) {
                        return Some(k);
                    }
                }
            }
        }
        None
    }
}

/// Sub-triangles `within` may split a triangle into, by halving its sides, before it gives up:
/// pieces of 1/1024 of the side, far below any bound worth asking.
const MAX_DEPTH: usize = 10;

/// Whether every point of triangle `t` lies within `limit` of one of `others`. The distance to
/// one triangle is a convex function, so a piece of `t` whose three corners lie within `limit`
/// of the same triangle of `others` lies within it whole. Pieces that no one triangle covers are
/// split in four, until each is covered, or a corner is farther than `limit` from all of
/// `others` (then `t` is not within), or the pieces reach `MAX_DEPTH` (then `t` is refused
/// though it may be within: the box stays unit cubes, which costs triangles only). The test is
/// therefore exact where it accepts, with no sampling slack.
pub(crate) fn within(t: [[f64; 3]; 3], others: &(impl Nearby + ?Sized), limit: f64) -> bool {
    within_from(t, others, limit, &mut 0)
}

/// [`within`], trying `others[*last]` first and leaving there the last one that covered a
/// piece. A piece is covered iff some triangle covers it, whichever is tried first: the answer
/// is [`within`]'s.
fn within_from(
    t: [[f64; 3]; 3],
    others: &(impl Nearby + ?Sized),
    limit: f64,
    last: &mut usize,
) -> bool {
    let n = others.tris().len();
    if limit.is_nan() || limit <= 0.0 || n == 0 {
        return false;
    }
    if *last >= n {
        *last = 0;
    }
    covered(t, 0, others, limit, last)
}

/// Whether every point of `piece`, at split depth `depth`, lies within `limit` of one of
/// `others` ([`within`]). `last` is the triangle that covered the last piece: neighbouring pieces
/// are usually near the same one, so it is tried first. Depth first, the middle piece before the
/// corners', by recursion rather than an explicit stack: most pieces are covered whole at once,
/// and a stack for every depth would be cleared on each call for nothing.
fn covered(
    piece: [[f64; 3]; 3],
    depth: usize,
    others: &(impl Nearby + ?Sized),
    limit: f64,
    last: &mut usize,
) -> bool {
    let tris = others.tris();
    let limit2 = limit * limit;
    let grown = |lo: [f64; 3], hi: [f64; 3]| -> ([f64; 3], [f64; 3]) {
        (lo.map(|c| c - limit), hi.map(|c| c + limit))
    };
    // Every corner's cheap test before any exact distance: the same conjunction.
    let covers = |k: usize| {
        let b = others.bounds(k);
        piece.iter().all(|&p| box_near(p, &b, limit2))
            && piece
                .iter()
                .all(|&p| point_triangle_distance_squared(p, tris[k]) <= limit2)
    };
    if covers(*last) {
        return true;
    }
    let lo = core::array::from_fn(|d| piece[0][d].min(piece[1][d]).min(piece[2][d]));
    let hi = core::array::from_fn(|d| piece[0][d].max(piece[1][d]).max(piece[2][d]));
    let (lo, hi) = grown(lo, hi);
    if let Some(k) = others.find(lo, hi, covers) {
        *last = k;
        return true;
    }
    let reached = |p: [f64; 3]| {
        let (lo, hi) = grown(p, p);
        others
            .find(lo, hi, |k| {
                box_near(p, &others.bounds(k), limit2)
                    && point_triangle_distance_squared(p, tris[k]) <= limit2
            })
            .is_some()
    };
    if depth == MAX_DEPTH || !piece.iter().all(|&p| reached(p)) {
        return false;
    }
    let mid = |a: [f64; 3], b: [f64; 3]| core::array::from_fn(|d| 0.5 * (a[d] + b[d]));
    let [a, b, c] = piece;
    let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
    [[ab, bc, ca], [ca, bc, c], [ab, b, bc], [a, ab, ca]]
        .into_iter()
        .all(|q| covered(q, depth + 1, others, limit, last))
}

/// Whether `p` lies within `√limit2` of bounding box `b`: a triangle inside it can be that near
/// only then, and the test rules most triangles out at a fraction of the exact distance's cost.
#[inline]
fn box_near(p: [f64; 3], [lo, hi]: &[[f64; 3]; 2], limit2: f64) -> bool {
    let mut outside2 = 0.0;
    for d in 0..3 {
        let gap = (lo[d] - p[d]).max(p[d] - hi[d]).max(0.0);
        outside2 += gap * gap;
    }
    outside2 <= limit2
}

/// The shape of a triangle, from 0 (degenerate) to 1 (equilateral): `48 · area² / (Σ side²)²`.
pub(crate) fn quality(t: &[Vertex; 3]) -> f64 {
    let [a, b, c] = t.map(|v| v.p);
    let sub = |u: [f64; 3], v: [f64; 3]| [u[0] - v[0], u[1] - v[1], u[2] - v[2]];
    let (ab, ac, bc) = (sub(b, a), sub(c, a), sub(c, b));
    let cross = [
        ab[1] * ac[2] - ab[2] * ac[1],
        ab[2] * ac[0] - ab[0] * ac[2],
        ab[0] * ac[1] - ab[1] * ac[0],
    ];
    let norm2 = |u: [f64; 3]| u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    let sides = norm2(ab) + norm2(ac) + norm2(bc);
    if sides == 0.0 {
        0.0
    } else {
        12.0 * norm2(cross) / (sides * sides)
    }
}
