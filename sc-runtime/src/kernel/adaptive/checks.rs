//! The geometric tests a box's triangles pass before they replace Steps 1–3's
//! (docs/adaptive.md §2): (F) fold-free and embedded, (P) separating, (E) within the error bound.
//!
//! They run in `f64` on positions in grid steps, with margins far above the rounding of the
//! emitted `f32` positions: a box close to failing a test is left as unit cubes, which only
//! costs triangles.

use super::outline::{Outline, on_line, others};
use super::{BoxSource, MAX_POLYGON, Tolerance, Vertex};
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
                let want = (0..side).find_map(|k| {
                    let lower = on_line(corner, axis, [u, v], k);
                    src.crossing(lower, axis).map(|_| lower[axis])
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

/// (E): the box's triangles and the Steps 1–3 triangles of the box (`patch`, in the tolerance's
/// units) lie within the bound of each other, every point of each (not only sampled ones): see
/// [`within`].
pub(crate) fn within_bound(
    tris: &[[Vertex; 3]],
    patch: &[[[f64; 3]; 3]],
    tolerance: &Tolerance,
) -> bool {
    let mut ours = [[[0.0; 3]; 3]; super::MAX_TRIANGLES];
    for (i, t) in tris.iter().enumerate() {
        ours[i] = t.map(|v| scaled(v.p, tolerance));
    }
    let ours = &ours[..tris.len()];
    ours.iter().all(|&t| within(t, patch, tolerance.limit))
        && patch.iter().all(|&t| within(t, ours, tolerance.limit))
}

/// Whether every point of triangle `t` lies within `limit` of one of `others`. The distance to
/// a set is 1-Lipschitz, and every point of a triangle whose longest side is `l` lies within
/// `l / √3` of one of its corners (the circumradius when it is acute, at most `l / 2`
/// otherwise). So sampling `t` on a lattice of `n` steps per side and requiring each sample
/// within `limit − l / (n√3)` bounds every point; `n` is chosen so that this slack is at most
/// a quarter of the limit (half would halve the work but leave most boxes at half the bound).
pub(crate) fn within(t: [[f64; 3]; 3], others: &[[[f64; 3]; 3]], limit: f64) -> bool {
    if limit.is_nan() || limit <= 0.0 {
        return false;
    }
    let len2 =
        |a: [f64; 3], b: [f64; 3]| (0..3).map(|d| (a[d] - b[d]) * (a[d] - b[d])).sum::<f64>();
    let longest = sqrt(len2(t[0], t[1]).max(len2(t[1], t[2])).max(len2(t[2], t[0])));
    let sqrt3 = sqrt(3.0);
    let n = ((longest / (sqrt3 * 0.25 * limit)) as usize + 1).min(64);
    let slack = longest / (n as f64 * sqrt3);
    let reach = limit - slack;
    if reach <= 0.0 {
        return false;
    }
    let reach2 = reach * reach;
    // Neighbouring samples are usually near the same triangle: try the last one found first.
    let mut last = 0;
    for i in 0..=n {
        for j in 0..=n - i {
            let (s, r) = (i as f64 / n as f64, j as f64 / n as f64);
            let p: [f64; 3] = core::array::from_fn(|d| {
                t[0][d] + s * (t[1][d] - t[0][d]) + r * (t[2][d] - t[0][d])
            });
            let near = |o: &[[f64; 3]; 3]| point_triangle_distance_squared(p, *o) <= reach2;
            if others.get(last).is_some_and(near) {
                continue;
            }
            match others.iter().position(near) {
                Some(k) => last = k,
                None => return false,
            }
        }
    }
    true
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
