//! Cube numbering of SPEC §1–2: corners, edges, faces, parity mirrors and the rotation ρ.
//!
//! Everything here is a pure function of small integers, so the rest of the generator can treat
//! edges and corners as plain `u8` ids and still agree with every other tool that uses the SPEC.

/// Corner `c` sits at offset `(c & 1, (c >> 1) & 1, (c >> 2) & 1)`.
pub fn corner_offset(c: u8) -> [u8; 3] {
    [c & 1, (c >> 1) & 1, (c >> 2) & 1]
}

fn corner_at(p: [u8; 3]) -> u8 {
    p[0] | p[1] << 1 | p[2] << 2
}

/// The axis an edge runs along: 0 = x, 1 = y, 2 = z.
pub fn edge_axis(e: u8) -> usize {
    usize::from(e / 4)
}

/// The edge's two corners, lower one first.
pub fn edge_corners(e: u8) -> [u8; 2] {
    let axis = edge_axis(e);
    let r = e % 4;
    // The two coordinates off the axis, in increasing axis order, are (r & 1, r >> 1).
    let mut p = [0u8; 3];
    let others = other_axes(axis);
    p[others[0]] = r & 1;
    p[others[1]] = r >> 1;
    let a = corner_at(p);
    p[axis] = 1;
    [a, corner_at(p)]
}

/// The two axes other than `axis`, in increasing order.
pub fn other_axes(axis: usize) -> [usize; 2] {
    match axis {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    }
}

/// The edge joining two corners that differ in exactly one coordinate.
pub fn edge_between(a: u8, b: u8) -> u8 {
    let d = a ^ b;
    debug_assert!(d.is_power_of_two() && d < 8);
    let axis = d.trailing_zeros() as usize;
    let lo = corner_offset(a & b);
    let others = other_axes(axis);
    (axis as u8) * 4 + lo[others[0]] + 2 * lo[others[1]]
}

/// A face: `axis` is the normal direction, `side` 0 the low face and 1 the high one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Face {
    /// Normal axis.
    pub axis: usize,
    /// 0 for the face at coordinate 0, 1 for the face at 1.
    pub side: u8,
}

/// The six faces in the order x=0, x=1, y=0, y=1, z=0, z=1.
pub const FACES: [Face; 6] = [
    Face { axis: 0, side: 0 },
    Face { axis: 0, side: 1 },
    Face { axis: 1, side: 0 },
    Face { axis: 1, side: 1 },
    Face { axis: 2, side: 0 },
    Face { axis: 2, side: 1 },
];

impl Face {
    /// The face's four corners, going round it.
    pub fn corners(self) -> [u8; 4] {
        let [u, v] = other_axes(self.axis);
        let at = |a: u8, b: u8| {
            let mut p = [0u8; 3];
            p[self.axis] = self.side;
            p[u] = a;
            p[v] = b;
            corner_at(p)
        };
        [at(0, 0), at(1, 0), at(1, 1), at(0, 1)]
    }

    /// The face's four edges: edge `i` joins corners `i` and `i + 1` (mod 4) of [`Face::corners`].
    pub fn edges(self) -> [u8; 4] {
        let c = self.corners();
        [0, 1, 2, 3].map(|i| edge_between(c[i], c[(i + 1) % 4]))
    }

    /// Whether the edge lies in this face.
    pub fn contains_edge(self, e: u8) -> bool {
        self.edges().contains(&e)
    }

    /// Outward unit normal as integers.
    pub fn normal(self) -> [i64; 3] {
        let mut n = [0; 3];
        n[self.axis] = if self.side == 1 { 1 } else { -1 };
        n
    }
}

/// The two faces that contain an edge.
pub fn edge_faces(e: u8) -> [Face; 2] {
    let [a, _] = edge_corners(e);
    let p = corner_offset(a);
    let [u, v] = other_axes(edge_axis(e));
    [
        Face {
            axis: u,
            side: p[u],
        },
        Face {
            axis: v,
            side: p[v],
        },
    ]
}

/// Whether two distinct edges lie in a common face.
pub fn share_face(a: u8, b: u8) -> bool {
    a != b && edge_faces(a).iter().any(|f| f.contains_edge(b))
}

/// The grey edges of parity class `p`, ordered x-grey, y-grey, z-grey (SPEC §2).
pub fn greys(p: u8) -> [u8; 3] {
    let (a, b, c) = (p & 1, (p >> 1) & 1, (p >> 2) & 1);
    [(1 - b) + 2 * (1 - c), 4 + (1 - a) + 2 * c, 8 + a + 2 * b]
}

/// Mirrors an edge across the cube's mid-planes for the bits set in `p`.
pub fn mirror_edge(e: u8, p: u8) -> u8 {
    let [a, b] = edge_corners(e);
    edge_between(a ^ p, b ^ p)
}

/// Mirrors a case (a corner bit set) across the mid-planes for the bits set in `p`.
pub fn mirror_case(case: u8, p: u8) -> u8 {
    (0..8)
        .filter(|&c| case >> c & 1 == 1)
        .fold(0, |m, c| m | 1 << (c ^ p))
}

/// ρ, the 3-fold rotation about the diagonal through corners 2 and 5, which maps class 0's greys
/// 8 → 3 → 5 → 8. In coordinates: `(x, y, z) ↦ (z, 1 − x, 1 − y)`.
pub fn rho_corner(c: u8) -> u8 {
    let [x, y, z] = corner_offset(c);
    corner_at([z, 1 - x, 1 - y])
}

/// ρ applied to an edge of class 0.
pub fn rho_edge(e: u8) -> u8 {
    let [a, b] = edge_corners(e);
    edge_between(rho_corner(a), rho_corner(b))
}

/// A corner's position scaled by `scale` (integer coordinates for exact geometry).
pub fn corner_point(c: u8, scale: i64) -> [i64; 3] {
    corner_offset(c).map(|v| i64::from(v) * scale)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_match_spec_numbering() {
        // x-edges: (y, z) = (e & 1, e >> 1)
        assert_eq!(edge_corners(0), [0, 1]);
        assert_eq!(edge_corners(1), [2, 3]);
        assert_eq!(edge_corners(2), [4, 5]);
        assert_eq!(edge_corners(3), [6, 7]);
        // y-edges: (x, z) = (r & 1, r >> 1)
        assert_eq!(edge_corners(4), [0, 2]);
        assert_eq!(edge_corners(5), [1, 3]);
        assert_eq!(edge_corners(6), [4, 6]);
        assert_eq!(edge_corners(7), [5, 7]);
        // z-edges: (x, y) = (r & 1, r >> 1)
        assert_eq!(edge_corners(8), [0, 4]);
        assert_eq!(edge_corners(9), [1, 5]);
        assert_eq!(edge_corners(10), [2, 6]);
        assert_eq!(edge_corners(11), [3, 7]);
        for e in 0..12 {
            let [a, b] = edge_corners(e);
            assert_eq!(edge_between(a, b), e);
            assert_eq!(edge_between(b, a), e);
        }
    }

    #[test]
    fn faces_have_four_edges_and_each_edge_two_faces() {
        for f in FACES {
            for e in f.edges() {
                assert!(edge_faces(e).contains(&f));
            }
        }
        for e in 0..12 {
            let [f, g] = edge_faces(e);
            assert!(f.contains_edge(e) && g.contains_edge(e) && f != g);
        }
    }

    #[test]
    fn greys_share_no_face_and_mirror_consistently() {
        assert_eq!(greys(0), [3, 5, 8]);
        for p in 0..8 {
            let g = greys(p);
            for i in 0..3 {
                assert_eq!(edge_axis(g[i]), i);
                for j in 0..3 {
                    assert!(i == j || !share_face(g[i], g[j]));
                }
                assert_eq!(mirror_edge(greys(0)[i], p), g[i]);
            }
        }
    }

    #[test]
    fn rho_cycles_the_greys_and_has_order_three() {
        assert_eq!(rho_edge(8), 3);
        assert_eq!(rho_edge(3), 5);
        assert_eq!(rho_edge(5), 8);
        for c in 0..8 {
            assert_eq!(rho_corner(rho_corner(rho_corner(c))), c);
        }
        assert_eq!(rho_corner(2), 2);
        assert_eq!(rho_corner(5), 5);
    }
}
