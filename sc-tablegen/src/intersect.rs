//! Exact triangle–triangle intersection predicates.
//!
//! Extracted meshes are checked for self-intersections, and a checker that
//! misses a touching pair (or reports a phantom one) because of rounding is
//! worse than none. Every decision below is therefore made from the *signs*
//! of Shewchuk's adaptive `orient2d`/`orient3d` (exact for finite `f64`
//! input barring overflow/underflow) and from exact coordinate comparisons.
//! No intersection point is ever constructed and no tolerance is used.

use robust::{Coord, Coord3D, orient2d, orient3d};

pub type Point = [f64; 3];

/// Sign of `orient3d`, so that callers compare signs and never magnitudes
/// (the magnitude is not exact, only its sign is).
fn o3(a: &Point, b: &Point, c: &Point, d: &Point) -> i8 {
    let c3 = |p: &Point| Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    };
    sign(orient3d(c3(a), c3(b), c3(c), c3(d)))
}

fn sign(v: f64) -> i8 {
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        // NaN lands here too; `projection` rejects non-finite input first.
        0
    }
}

/// Which coordinate plane a set of coplanar points is projected onto: the two
/// kept axes. Projection along an axis not parallel to the plane is an affine
/// bijection of that plane, so incidences are preserved and all orientations
/// are scaled by one common sign — which is all the 2D tests need.
#[derive(Clone, Copy)]
struct Proj(usize, usize);

impl Proj {
    fn p(self, a: &Point) -> Coord<f64> {
        Coord {
            x: a[self.0],
            y: a[self.1],
        }
    }

    fn o2(self, a: &Point, b: &Point, c: &Point) -> i8 {
        sign(orient2d(self.p(a), self.p(b), self.p(c)))
    }

    /// Exact collinear-point-on-segment test: only coordinate comparisons,
    /// valid once `o2(a, b, p) == 0` is known.
    fn between(self, a: &Point, b: &Point, p: &Point) -> bool {
        let within = |k: usize| a[k].min(b[k]) <= p[k] && p[k] <= a[k].max(b[k]);
        within(self.0) && within(self.1)
    }
}

/// The projection in which `t` keeps non-zero area, or `None` if `t` has zero
/// area. The three projected orientations are exactly the signs of the three
/// components of the triangle's normal, so "all zero" is exact degeneracy.
/// Non-finite coordinates also give `None`: the orientations would be NaN or
/// meaningless, and no caller can do anything sound with such a triangle.
fn projection(t: &[Point; 3]) -> Option<Proj> {
    if !t.iter().flatten().all(|x| x.is_finite()) {
        return None;
    }
    [Proj(0, 1), Proj(1, 2), Proj(2, 0)]
        .into_iter()
        .find(|pr| pr.o2(&t[0], &t[1], &t[2]) != 0)
}

/// True if the triangle has zero area (its three points are collinear or coincide), exactly.
///
/// A triangle with a NaN or infinite coordinate counts as degenerate too.
pub fn is_degenerate(t: &[Point; 3]) -> bool {
    projection(t).is_none()
}

/// A non-degenerate triangle with its supporting-plane projection cached, so
/// the projection is chosen once per triangle rather than once per edge test.
struct Tri<'a> {
    v: &'a [Point; 3],
    proj: Proj,
}

impl Tri<'_> {
    /// Side of the triangle's plane (orientation sign).
    fn side(&self, p: &Point) -> i8 {
        o3(&self.v[0], &self.v[1], &self.v[2], p)
    }

    /// Closed point-in-triangle for a point known to be in the plane.
    fn contains_coplanar(&self, p: &Point) -> bool {
        let [a, b, c] = self.v;
        let pr = self.proj;
        let s = [pr.o2(a, b, p), pr.o2(b, c, p), pr.o2(c, a, p)];
        s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0)
    }

    /// Closed segment `pq` against the closed triangle, given the plane sides
    /// of `p` and `q` (callers usually have them already).
    fn meets_segment(&self, p: &Point, q: &Point, sp: i8, sq: i8) -> bool {
        if sp * sq > 0 {
            return false;
        }
        let [a, b, c] = self.v;
        if sp == 0 && sq == 0 {
            // Coplanar: a segment meets a convex polygon iff an endpoint is
            // inside or it crosses the boundary.
            return self.contains_coplanar(p)
                || self.contains_coplanar(q)
                || segments_meet(self.proj, p, q, a, b)
                || segments_meet(self.proj, p, q, b, c)
                || segments_meet(self.proj, p, q, c, a);
        }
        // The line pq is not in the plane and meets it at a single point that
        // lies on the closed segment (sides differ or one is zero). That point
        // is in the closed triangle iff the line passes no edge on the
        // "wrong" side: the three orientations of pq against the edges must
        // not have strictly opposite signs. They cannot all be zero because
        // the line is not in the plane.
        let s0 = o3(p, q, a, b);
        let s1 = o3(p, q, b, c);
        if s0 * s1 < 0 {
            return false;
        }
        let s2 = o3(p, q, c, a);
        s0 * s2 >= 0 && s1 * s2 >= 0
    }
}

/// Closed segments `ab` and `cd`, all four points coplanar, meet — including
/// touching at an endpoint and collinear overlap.
fn segments_meet(pr: Proj, a: &Point, b: &Point, c: &Point, d: &Point) -> bool {
    let d1 = pr.o2(a, b, c);
    let d2 = pr.o2(a, b, d);
    let d3 = pr.o2(c, d, a);
    let d4 = pr.o2(c, d, b);
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    // Otherwise they can only meet at an endpoint of one lying on the other:
    // if, say, c is on line ab but outside segment ab while d is off the
    // line, the two lines meet only at c, so there is no contact.
    (d1 == 0 && pr.between(a, b, c))
        || (d2 == 0 && pr.between(a, b, d))
        || (d3 == 0 && pr.between(c, d, a))
        || (d4 == 0 && pr.between(c, d, b))
}

/// True if two non-degenerate closed triangles intersect anywhere other than in what they share.
/// Shared vertices are found by exact coordinate equality. Allowed contact:
///  - 0 shared vertices: no contact at all (touching at a point counts as a conflict);
///  - 1 shared vertex A: the intersection must be exactly {A};
///  - 2 shared vertices A,B: the intersection must be exactly the segment AB (a coplanar pair
///    lying on the same side of AB overlaps → conflict);
///  - 3 shared vertices: the same triangle twice → conflict.
///
/// A degenerate (zero-area or non-finite) input is reported as a conflict: it has no
/// well-defined "allowed contact", and a mesh containing one is defective
/// anyway, so failing loudly is safer than guessing.
pub fn triangles_conflict(a: &[Point; 3], b: &[Point; 3]) -> bool {
    let (Some(pa), Some(pb)) = (projection(a), projection(b)) else {
        return true;
    };
    let ta = Tri { v: a, proj: pa };
    let tb = Tri { v: b, proj: pb };

    // Vertices within a non-degenerate triangle are distinct, so each vertex
    // of `a` matches at most one of `b`.
    let mut shared = [None::<usize>; 3];
    let mut count = 0;
    for (i, s) in shared.iter_mut().enumerate() {
        *s = b.iter().position(|q| *q == a[i]);
        count += usize::from(s.is_some());
    }

    match count {
        0 => disjoint_conflict(&ta, &tb),
        1 => {
            let i = shared.iter().position(Option::is_some).unwrap();
            let j = shared[i].unwrap();
            vertex_conflict(&ta, i, &tb, j)
        }
        2 => {
            let k = shared.iter().position(Option::is_none).unwrap();
            let l = (0..3).find(|m| !shared.contains(&Some(*m))).unwrap();
            edge_conflict(&ta, k, b[l])
        }
        _ => true,
    }
}

/// No shared vertices: any contact is a conflict. Two closed triangles meet
/// iff an edge of one meets the other: if they are not coplanar the
/// intersection is a segment on the planes' common line whose ends lie on
/// edges; if coplanar, either boundaries cross or one contains the other
/// (and then its edges lie inside the other).
fn disjoint_conflict(ta: &Tri, tb: &Tri) -> bool {
    let sb = tb.v.map(|p| ta.side(&p));
    if sb.iter().all(|&s| s > 0) || sb.iter().all(|&s| s < 0) {
        return false;
    }
    let sa = ta.v.map(|p| tb.side(&p));
    if sa.iter().all(|&s| s > 0) || sa.iter().all(|&s| s < 0) {
        return false;
    }
    (0..3).any(|i| {
        let j = (i + 1) % 3;
        tb.meets_segment(&ta.v[i], &ta.v[j], sa[i], sa[j])
            || ta.meets_segment(&tb.v[i], &tb.v[j], sb[i], sb[j])
    })
}

/// One shared vertex `A = a[i] = b[j]`; the rest must touch only at `A`.
///
/// Only the opposite edges need testing. If the (convex) intersection holds
/// some `X != A`, follow the ray from `A` through `X`: it leaves `a` at a
/// point `Y1` of the opposite edge of `a`, and leaves `b` at `Y2` on the
/// opposite edge of `b`. Both `[A, Y1]` and `[A, Y2]` lie in the
/// intersection's ray, so the nearer of `Y1`, `Y2` is in both triangles —
/// an opposite edge meets the other triangle. Conversely a meeting point on
/// an opposite edge cannot be `A` (that edge misses `A` in a non-degenerate
/// triangle). This also covers the "a direction lies in the other's cone"
/// situations, e.g. coplanar fold-over or an edge lying along the other face.
///
/// If both free vertices of one triangle are strictly on one side of the
/// other's plane, that triangle meets the plane only in `A`, so the answer
/// is known before the second pair of orientations (the common case for
/// neighbours on a smooth surface, which the mesh checker sees millions of).
fn vertex_conflict(ta: &Tri, i: usize, tb: &Tri, j: usize) -> bool {
    let (b1, c1) = (&ta.v[(i + 1) % 3], &ta.v[(i + 2) % 3]);
    let (s1, t1) = (tb.side(b1), tb.side(c1));
    if s1 * t1 > 0 {
        return false;
    }
    let (b2, c2) = (&tb.v[(j + 1) % 3], &tb.v[(j + 2) % 3]);
    let (s2, t2) = (ta.side(b2), ta.side(c2));
    if s2 * t2 > 0 {
        return false;
    }
    tb.meets_segment(b1, c1, s1, t1) || ta.meets_segment(b2, c2, s2, t2)
}

/// Shared edge: `a[k]` is the vertex of `a` off the shared edge, `d` the one
/// of `b`. Non-coplanar triangles meet only on the planes' common line, which
/// is the shared edge's line, and each triangle meets that line in exactly
/// the edge. Coplanar ones overlap iff the free vertices are on the same
/// side of the edge (neither can be on it: that would be zero area).
fn edge_conflict(ta: &Tri, k: usize, d: Point) -> bool {
    let (e0, e1, c) = (&ta.v[(k + 1) % 3], &ta.v[(k + 2) % 3], &ta.v[k]);
    if ta.side(&d) != 0 {
        return false;
    }
    ta.proj.o2(e0, e1, c) == ta.proj.o2(e0, e1, &d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn conflict(a: [Point; 3], b: [Point; 3]) -> bool {
        // The predicate must be symmetric and independent of vertex order and
        // orientation; check all of that on every hand-built case.
        let r = triangles_conflict(&a, &b);
        for (x, y) in [(a, b), (b, a)] {
            for rot in 0..3 {
                let xr = [x[rot], x[(rot + 1) % 3], x[(rot + 2) % 3]];
                let xf = [xr[0], xr[2], xr[1]];
                for xx in [xr, xf] {
                    for yy in [y, [y[1], y[0], y[2]]] {
                        assert_eq!(triangles_conflict(&xx, &yy), r, "{xx:?} {yy:?}");
                    }
                }
            }
        }
        r
    }

    const O: Point = [0.0, 0.0, 0.0];
    const X: Point = [1.0, 0.0, 0.0];
    const Y: Point = [0.0, 1.0, 0.0];
    const Z: Point = [0.0, 0.0, 1.0];

    #[test]
    fn degeneracy() {
        assert!(!is_degenerate(&[O, X, Y]));
        assert!(!is_degenerate(&[O, Y, Z]));
        assert!(!is_degenerate(&[O, Z, X]));
        assert!(is_degenerate(&[O, O, Y]));
        assert!(is_degenerate(&[O, [1.0, 1.0, 1.0], [2.0, 2.0, 2.0]]));
        assert!(is_degenerate(&[O, O, O]));
        assert!(is_degenerate(&[O, X, [f64::NAN, 0.0, 0.0]]));
        assert!(is_degenerate(&[O, X, [0.0, 1.0, f64::NAN]]));
        assert!(is_degenerate(&[O, X, [0.0, f64::INFINITY, 0.0]]));
        assert!(triangles_conflict(
            &[O, X, [0.0, 1.0, f64::NAN]],
            &[Y, Z, [5.0; 3]]
        ));
        // Nearly collinear: naive cross products round to zero here.
        let e = f64::EPSILON / 4.0;
        assert!(!is_degenerate(&[
            [0.1, 0.1, 0.1],
            [0.2, 0.2, 0.2 + e],
            [0.3, 0.3, 0.3]
        ]));
        assert!(is_degenerate(&[
            [0.5, 0.5, 0.5],
            [0.25, 0.25, 0.25],
            [0.75, 0.75, 0.75]
        ]));
        // Degenerate input is a conflict, never silently accepted.
        assert!(triangles_conflict(
            &[O, X, [2.0, 0.0, 0.0]],
            &[Y, Z, [5.0; 3]]
        ));
    }

    #[test]
    fn disjoint_vertices() {
        let t = [O, [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        // Crossing: a vertical triangle piercing the interior.
        assert!(conflict(
            t,
            [[1.0, 1.0, -1.0], [1.0, 1.0, 1.0], [2.0, 0.5, 1.0]]
        ));
        // Far apart.
        assert!(!conflict(
            t,
            [[1.0, 1.0, 1.0], [2.0, 1.0, 1.0], [1.0, 2.0, 1.0]]
        ));
        // Touching at a point: a vertex on the face interior.
        assert!(conflict(
            t,
            [[1.0, 1.0, 0.0], [1.0, 1.0, 1.0], [2.0, 1.0, 1.0]]
        ));
        // A vertex exactly on an edge of the other.
        assert!(conflict(
            t,
            [[2.0, 0.0, 0.0], [2.0, -1.0, 1.0], [3.0, -1.0, 1.0]]
        ));
        // Edge crossing edge at a single point (non-coplanar): the second
        // triangle's plane x = 2 meets the first only at (2, 0, 0).
        assert!(conflict(
            t,
            [[2.0, -1.0, 1.0], [2.0, 1.0, -1.0], [2.0, -3.0, -3.0]]
        ));
        // The same, shifted just off the first triangle.
        assert!(!conflict(
            t,
            [[2.0, -1.5, 1.0], [2.0, 0.5, -1.0], [2.0, -3.5, -3.0]]
        ));
        // Edge lying on the face.
        assert!(conflict(
            t,
            [[1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [1.5, 1.0, 3.0]]
        ));
        // Plane crosses but the other triangle is beside it.
        assert!(!conflict(
            t,
            [[3.0, 3.0, -1.0], [3.0, 3.0, 1.0], [4.0, 2.0, 1.0]]
        ));
        // Line through the triangle's plane just outside an edge.
        assert!(!conflict(
            t,
            [[2.5, 2.0, -1.0], [2.5, 2.0, 1.0], [5.0, 5.0, 0.0]]
        ));
    }

    #[test]
    fn disjoint_vertices_coplanar() {
        let t = [O, [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        // Overlap.
        assert!(conflict(
            t,
            [[1.0, 1.0, 0.0], [5.0, 1.0, 0.0], [1.0, 5.0, 0.0]]
        ));
        // Contained.
        assert!(conflict(
            t,
            [[1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [1.0, 2.0, 0.0]]
        ));
        // Disjoint in the plane.
        assert!(!conflict(
            t,
            [[3.0, 3.0, 0.0], [5.0, 3.0, 0.0], [3.0, 5.0, 0.0]]
        ));
        // Touching at a point: vertex on the hypotenuse.
        assert!(conflict(
            t,
            [[2.0, 2.0, 0.0], [5.0, 3.0, 0.0], [3.0, 5.0, 0.0]]
        ));
        // Collinear edge overlap along the x axis, on opposite sides.
        assert!(conflict(
            t,
            [[1.0, 0.0, 0.0], [6.0, 0.0, 0.0], [3.0, -2.0, 0.0]]
        ));
        // Collinear along the x axis but disjoint intervals.
        assert!(!conflict(
            t,
            [[5.0, 0.0, 0.0], [6.0, 0.0, 0.0], [5.0, -2.0, 0.0]]
        ));
        // Star of David.
        assert!(conflict(
            [[0.0, 0.0, 0.0], [6.0, 0.0, 0.0], [3.0, 5.0, 0.0]],
            [[0.0, 3.0, 0.0], [6.0, 3.0, 0.0], [3.0, -2.0, 0.0]]
        ));
        // A plane where only one projection is non-degenerate (x = 7).
        let v = [[7.0, 0.0, 0.0], [7.0, 4.0, 0.0], [7.0, 0.0, 4.0]];
        assert!(conflict(
            v,
            [[7.0, 1.0, 1.0], [7.0, 5.0, 1.0], [7.0, 1.0, 5.0]]
        ));
        assert!(!conflict(
            v,
            [[7.0, 3.0, 3.0], [7.0, 5.0, 3.0], [7.0, 3.0, 5.0]]
        ));
    }

    #[test]
    fn one_shared_vertex() {
        let t = [O, [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        // Fan around the shared vertex, not overlapping.
        assert!(!conflict(t, [O, [0.0, -4.0, 0.0], [-4.0, 0.0, 0.0]]));
        // Out of plane, only touching at O.
        assert!(!conflict(t, [O, [1.0, 1.0, 1.0], [-1.0, 2.0, 1.0]]));
        // Out of plane, but swinging through the face.
        assert!(conflict(t, [O, [1.0, 1.0, 1.0], [1.0, 1.0, -1.0]]));
        // An edge from O lying along the face interior.
        assert!(conflict(t, [O, [1.0, 1.0, 0.0], [1.0, 1.0, 1.0]]));
        // An edge from O lying along a shared edge direction (out of plane).
        assert!(conflict(t, [O, [2.0, 0.0, 0.0], [0.0, 0.0, 3.0]]));
        // Coplanar fold-over: overlapping wedges.
        assert!(conflict(t, [O, [4.0, 1.0, 0.0], [1.0, 4.0, 0.0]]));
        // Coplanar, the second nested inside the first.
        assert!(conflict(t, [O, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]));
        // Coplanar, adjacent wedges sharing only the ray direction of an edge
        // but with a different edge length: the edges overlap → conflict.
        assert!(conflict(t, [O, [2.0, 0.0, 0.0], [1.0, -3.0, 0.0]]));
        // Coplanar wedges pointing in opposite directions.
        assert!(!conflict(t, [O, [-4.0, -1.0, 0.0], [-1.0, -4.0, 0.0]]));
        // Coplanar, opposite ray along x: collinear edges, only O shared.
        assert!(!conflict(t, [O, [-3.0, 0.0, 0.0], [-1.0, -2.0, 0.0]]));
        // The far vertex of the second touches the first's opposite edge.
        assert!(conflict(t, [O, [2.0, 2.0, 0.0], [1.0, 1.0, 3.0]]));
        // Shared vertex while the other triangle passes under it.
        assert!(conflict(t, [O, [-1.0, -1.0, 1.0], [2.0, 2.0, -1.0]]));
    }

    #[test]
    fn two_shared_vertices() {
        let t = [O, [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]];
        // Opposite sides, coplanar: a flat quad.
        assert!(!conflict(t, [O, [4.0, 0.0, 0.0], [2.0, -3.0, 0.0]]));
        // Folded flat onto the same side.
        assert!(conflict(t, [O, [4.0, 0.0, 0.0], [3.0, 3.0, 0.0]]));
        assert!(conflict(t, [O, [4.0, 0.0, 0.0], [9.0, 1.0, 0.0]]));
        // Dihedral angles, including a very sharp one.
        assert!(!conflict(t, [O, [4.0, 0.0, 0.0], [2.0, 3.0, 1.0]]));
        assert!(!conflict(t, [O, [4.0, 0.0, 0.0], [2.0, 3.0, -1.0]]));
        assert!(!conflict(t, [O, [4.0, 0.0, 0.0], [2.0, 3.0, 1e-300]]));
        // Same triangle twice, in any order.
        assert!(conflict(t, t));
        assert!(conflict(t, [t[2], t[1], t[0]]));
    }

    /// Adjacent floats, so offsets are exactly one ulp and survive rounding.
    fn up(x: f64) -> f64 {
        assert!(x > 0.0);
        f64::from_bits(x.to_bits() + 1)
    }
    fn down(x: f64) -> f64 {
        assert!(x > 0.0);
        f64::from_bits(x.to_bits() - 1)
    }

    /// The plain floating-point determinant a non-exact implementation would
    /// use; here only to show the cases below defeat it.
    fn naive_orient(a: Point, b: Point, c: Point, d: Point) -> f64 {
        let s = |p: Point| [p[0] - d[0], p[1] - d[1], p[2] - d[2]];
        let (a, b, c) = (s(a), s(b), s(c));
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0])
    }

    #[test]
    fn nearly_coplanar_shared_edge() {
        // Plane x + y + z = 1; the free vertex (0.5, 0, 0.5) is exactly in
        // it, on the same side of the shared edge as t[2] → overlap.
        let t = [X, Y, Z];
        assert!(conflict(t, [X, Y, [0.5, 0.0, 0.5]]));
        // A 1e-17 lift makes the pair a (very sharp) fold: allowed.
        assert!(!conflict(t, [X, Y, [0.5, 1e-17, 0.5]]));
        assert!(!conflict(t, [X, Y, [0.5, -1e-17, 0.5]]));
        // Exactly coplanar on the far side of the edge: a flat quad.
        assert!(!conflict(t, [X, Y, [0.75, 0.5, -0.25]]));
        // One ulp off the plane.
        assert!(!conflict(t, [X, Y, [up(0.25), 0.5, 0.25]]));
        assert!(!conflict(t, [X, Y, [down(0.25), 0.5, 0.25]]));
        assert!(conflict(t, [X, Y, [0.25, 0.5, 0.25]]));
        // Decimal coordinates: d is 5.6e-20 off the plane of (a, b, c), on
        // the same side of ab as c. The naive determinant rounds to exactly
        // zero and would call this a flat fold-over.
        let (a, b, c) = ([0.8, 0.1, 0.2], [0.4, 0.1, 0.5], [0.8, 0.6, 0.8]);
        let d = [0.9, 0.42500000000000004, 0.5150000000000001];
        assert_eq!(naive_orient(a, b, c, d), 0.0);
        assert!(!conflict([a, b, c], [a, b, d]));
        assert!(!conflict([a, b, c], [b, a, d]));
    }

    #[test]
    fn nearly_coplanar_pierce() {
        let t = [X, Y, Z];
        // A segment along z through (0.5, y0), crossing the plane at
        // z = 0.5 - y0: on the edge (y0 = 0.5), just inside, or just outside.
        let other = |y0: f64| [[0.5, y0, -1.0], [0.5, y0, 1.0], [2.0, 2.0, 1.0]];
        assert!(conflict(t, other(0.5)));
        assert!(conflict(t, other(down(0.5))));
        assert!(!conflict(t, other(up(0.5))));
        // A vertex an ulp above/below the face interior with the rest of the
        // triangle above it.
        let p = |z: f64| [[0.25, 0.25, z], [0.25, 0.25, 2.0], [0.5, 0.25, 2.0]];
        assert!(conflict(t, p(0.5)));
        assert!(!conflict(t, p(up(0.5))));
        assert!(conflict(t, p(down(0.5))));
        // Far from the origin the plane offset of one ulp is large in
        // absolute terms but still tiny relative to the coordinates.
        let big = 1e6;
        let u = [[big, 0.0, 0.0], [0.0, big, 0.0], [0.0, 0.0, big]];
        let q = |z: f64| {
            [
                [big / 4.0, big / 4.0, z],
                [big / 4.0, big / 4.0, 2.0 * big],
                [big / 2.0, big / 4.0, 2.0 * big],
            ]
        };
        assert!(conflict(u, q(big / 2.0)));
        assert!(!conflict(u, q(up(big / 2.0))));
        assert!(conflict(u, q(down(big / 2.0))));
    }

    #[test]
    fn nearly_coplanar_two_faces() {
        // A smaller triangle in the same plane, nested inside: conflict; one
        // vertex lifted by an ulp still leaves an in-plane edge: conflict...
        let t = [X, Y, Z];
        let inner = [[0.5, 0.25, 0.25], [0.25, 0.5, 0.25], [0.25, 0.25, 0.5]];
        assert!(conflict(t, inner));
        assert!(conflict(t, [inner[0], inner[1], [0.25, 0.25, up(0.5)]]));
        // ...while a copy lifted wholly by one ulp in z misses it.
        let lift = |p: Point| [p[0], p[1], up(p[2])];
        assert!(!conflict(t, inner.map(lift)));
        // Shared vertex, second triangle an ulp out of the plane at one
        // vertex and exactly in it at the other: the in-plane edge lies in
        // the face → conflict; lift both and only the shared vertex touches.
        assert!(conflict(t, [X, [0.5, 0.25, 0.25], [0.5, 0.5, 1e-17]]));
        assert!(!conflict(
            t,
            [X, [0.5, 0.25, up(0.25)], [0.25, 0.5, up(0.25)]]
        ));
    }

    /// Exact rational reference, independent of the predicates above: it
    /// *constructs* the intersection polygon by clipping with exact
    /// rationals and then compares it with the allowed shared part. Integer
    /// inputs in a small range keep all rationals within `i128`.
    mod reference {
        #[derive(Clone, Copy, PartialEq, Eq, Debug)]
        pub struct Q(i128, i128); // numerator, positive denominator, reduced

        fn gcd(mut a: i128, mut b: i128) -> i128 {
            while b != 0 {
                (a, b) = (b, a % b);
            }
            a.abs()
        }

        impl Q {
            pub fn int(n: i64) -> Q {
                Q(n.into(), 1)
            }
            fn new(n: i128, d: i128) -> Q {
                assert!(d != 0);
                let g = gcd(n, d).max(1) * d.signum();
                Q(n / g, d / g)
            }
            pub fn sign(self) -> i128 {
                self.0.signum()
            }
            pub fn add(self, o: Q) -> Q {
                let n = self.0.checked_mul(o.1).unwrap();
                let m = o.0.checked_mul(self.1).unwrap();
                Q::new(n.checked_add(m).unwrap(), self.1.checked_mul(o.1).unwrap())
            }
            pub fn neg(self) -> Q {
                Q(-self.0, self.1)
            }
            pub fn sub(self, o: Q) -> Q {
                self.add(o.neg())
            }
            pub fn mul(self, o: Q) -> Q {
                let (g1, g2) = (gcd(self.0, o.1).max(1), gcd(o.0, self.1).max(1));
                Q::new(
                    (self.0 / g1).checked_mul(o.0 / g2).unwrap(),
                    (self.1 / g2).checked_mul(o.1 / g1).unwrap(),
                )
            }
            pub fn div(self, o: Q) -> Q {
                self.mul(Q::new(o.1, o.0))
            }
        }

        pub type V = [Q; 3];

        pub fn sub(a: V, b: V) -> V {
            [a[0].sub(b[0]), a[1].sub(b[1]), a[2].sub(b[2])]
        }
        pub fn dot(a: V, b: V) -> Q {
            a[0].mul(b[0]).add(a[1].mul(b[1])).add(a[2].mul(b[2]))
        }
        pub fn cross(a: V, b: V) -> V {
            [
                a[1].mul(b[2]).sub(a[2].mul(b[1])),
                a[2].mul(b[0]).sub(a[0].mul(b[2])),
                a[0].mul(b[1]).sub(a[1].mul(b[0])),
            ]
        }

        /// Half-space `n·x >= k`.
        struct Half(V, Q);

        fn clip(poly: &[V], h: &Half) -> Vec<V> {
            let f = |p: V| dot(h.0, p).sub(h.1);
            let mut out: Vec<V> = Vec::new();
            let mut push = |p: V| {
                if !out.contains(&p) {
                    out.push(p);
                }
            };
            for i in 0..poly.len() {
                let (c, n) = (poly[i], poly[(i + 1) % poly.len()]);
                let (fc, fnx) = (f(c), f(n));
                if fc.sign() >= 0 {
                    push(c);
                }
                if fc.sign() * fnx.sign() < 0 {
                    let t = fc.div(fc.sub(fnx));
                    let d = sub(n, c);
                    push([0, 1, 2].map(|k| c[k].add(t.mul(d[k]))));
                }
            }
            out
        }

        /// Vertices of the closed intersection of two non-degenerate triangles.
        pub fn intersection(a: [V; 3], b: [V; 3]) -> Vec<V> {
            let n = cross(sub(b[1], b[0]), sub(b[2], b[0]));
            let k = dot(n, b[0]);
            let mut poly = clip(&a, &Half(n, k));
            poly = clip(&poly, &Half(n.map(Q::neg), k.neg()));
            for i in 0..3 {
                let (p, q, r) = (b[i], b[(i + 1) % 3], b[(i + 2) % 3]);
                let mut m = cross(n, sub(q, p));
                if dot(m, sub(r, p)).sign() < 0 {
                    m = m.map(Q::neg);
                }
                poly = clip(&poly, &Half(m, dot(m, p)));
            }
            poly
        }

        pub fn on_segment(x: V, a: V, b: V) -> bool {
            let (u, w) = (sub(x, a), sub(b, a));
            cross(u, w).iter().all(|c| c.sign() == 0)
                && dot(u, w).sign() >= 0
                && dot(w, w).sub(dot(u, w)).sign() >= 0
        }
    }

    /// The specification, evaluated on the constructed intersection.
    fn reference_conflict(a: [[i64; 3]; 3], b: [[i64; 3]; 3]) -> bool {
        use reference::*;
        let q = |t: [[i64; 3]; 3]| t.map(|p| p.map(Q::int));
        let (qa, qb) = (q(a), q(b));
        let shared: Vec<V> = qa.iter().copied().filter(|p| qb.contains(p)).collect();
        let inter = intersection(qa, qb);
        match shared.len() {
            0 => !inter.is_empty(),
            1 => inter.iter().any(|&x| x != shared[0]),
            2 => inter.iter().any(|&x| !on_segment(x, shared[0], shared[1])),
            _ => true,
        }
    }

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            // xorshift64*: deterministic, dependency-free.
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
    }

    fn int_degenerate(t: [[i64; 3]; 3]) -> bool {
        let d = |p: [i64; 3], q: [i64; 3]| [0, 1, 2].map(|k| p[k] - q[k]);
        let (u, v) = (d(t[1], t[0]), d(t[2], t[0]));
        u[1] * v[2] == u[2] * v[1] && u[2] * v[0] == u[0] * v[2] && u[0] * v[1] == u[1] * v[0]
    }

    /// Random small-integer configurations are dense in the special cases
    /// (coplanarity, shared vertices, vertices on edges, collinear edges);
    /// the predicate must agree with the constructive reference on all of
    /// them, and also after an exact change of coordinates (axis
    /// permutation, power-of-two scale, representable translation), which
    /// moves the work to other projections and magnitudes.
    #[test]
    fn matches_exact_reference() {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        // [shared count][result] tallies, to prove every branch was reached.
        let mut seen = [[0u32; 2]; 4];
        for iter in 0..100_000 {
            let mode = iter % 3;
            let npool = 4 + rng.below(3) as usize;
            let pool: Vec<[i64; 3]> = (0..npool)
                .map(|_| {
                    let mut c = || rng.below(5) as i64 - 2;
                    match mode {
                        0 => [c(), c(), c()],
                        1 => [c(), c(), 0],
                        _ => {
                            let (x, y) = (c(), c());
                            [x, y, 1 - x - y + (rng.below(8) == 0) as i64]
                        }
                    }
                })
                .collect();
            let pick = |rng: &mut Rng| {
                let i = rng.below(npool as u64) as usize;
                let mut j = rng.below(npool as u64 - 1) as usize;
                j += usize::from(j >= i);
                let mut k = rng.below(npool as u64) as usize;
                while k == i || k == j {
                    k = rng.below(npool as u64) as usize;
                }
                [pool[i], pool[j], pool[k]]
            };
            // Half the time use six separate points, for mostly unshared pairs.
            let (a, b) = if npool == 6 && rng.below(2) == 0 {
                ([pool[0], pool[1], pool[2]], [pool[3], pool[4], pool[5]])
            } else {
                (pick(&mut rng), pick(&mut rng))
            };
            if int_degenerate(a) || int_degenerate(b) {
                continue;
            }
            let expected = reference_conflict(a, b);
            let shared = a.iter().filter(|p| b.contains(p)).count();
            seen[shared][usize::from(expected)] += 1;

            let perm = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [1, 0, 2]][rng.below(4) as usize];
            let scale = [1.0, 0.5, 1024.0, 1.0 / 1024.0][rng.below(4) as usize];
            let shift = [0.0, 0.125, -3.0, 1048576.0][rng.below(4) as usize];
            let conv = |t: [[i64; 3]; 3]| t.map(|p| perm.map(|k| p[k] as f64 * scale + shift));
            let (fa, fb) = (conv(a), conv(b));
            assert!(!is_degenerate(&fa) && !is_degenerate(&fb));
            assert_eq!(
                triangles_conflict(&fa, &fb),
                expected,
                "a = {a:?}, b = {b:?}"
            );
            assert_eq!(triangles_conflict(&fb, &fa), expected, "swapped");
        }
        for (s, counts) in seen.iter().enumerate().take(3) {
            assert!(
                counts[0] > 1000 && counts[1] > 1000,
                "{s} shared: {counts:?}"
            );
        }
        assert!(seen[3][1] > 0);
    }
}
