//! Step 2: the face rule ("do not cross ○–○ diagonals") and side orientation (SPEC §3).

use crate::cube::{FACES, Face, corner_point, edge_corners};

/// An oriented side from the vertex on edge `from` to the vertex on edge `to`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Side {
    /// Edge of the side's start vertex.
    pub from: u8,
    /// Edge of the side's end vertex.
    pub to: u8,
}

/// Whether corner `c` is filled in `case`.
pub fn filled(case: u8, c: u8) -> bool {
    case >> c & 1 == 1
}

/// Whether an edge joins a filled corner to an empty one.
pub fn occupied(case: u8, e: u8) -> bool {
    let [a, b] = edge_corners(e);
    filled(case, a) != filled(case, b)
}

/// The sides of one face. They depend only on the face's corners, so both cubes sharing the face
/// agree; each is oriented with the filled corners it separates on its left as seen from inside.
pub fn face_sides(case: u8, face: Face) -> Vec<Side> {
    let corners = face.corners();
    let edges = face.edges();
    let occ: Vec<usize> = (0..4).filter(|&i| occupied(case, edges[i])).collect();
    // Pairs of face-edge positions joined by a side, with one filled corner each side cuts off.
    let pairs: Vec<(usize, usize, u8)> = match occ.len() {
        0 => vec![],
        2 => {
            let (i, j) = (occ[0], occ[1]);
            // Face edge i joins corners i and i+1; the corners strictly between edges i and j
            // (going round) lie on one side of the segment: pick a filled one.
            let filled_corner = (0..4)
                .map(|k| corners[k])
                .find(|&c| filled(case, c))
                .expect("an occupied face has a filled corner");
            vec![(i, j, filled_corner)]
        }
        4 => (0..4)
            .filter(|&k| filled(case, corners[k]))
            // Filled corner k sits between face edges k-1 and k: the side cuts it off.
            .map(|k| ((k + 3) % 4, k, corners[k]))
            .collect(),
        _ => unreachable!("a face has an even number of occupied edges"),
    };
    pairs
        .into_iter()
        .map(|(i, j, c)| orient(face, edges[i], edges[j], c))
        .collect()
}

/// Orients the side between edges `a` and `b` so that filled corner `f` is on its left seen from
/// inside the cube: `(d × (f − u)) · n < 0` for outward normal `n`, with vertices at edge midpoints.
fn orient(face: Face, a: u8, b: u8, f: u8) -> Side {
    let mid = |e: u8| {
        let [p, q] = edge_corners(e).map(|c| corner_point(c, 2));
        [0, 1, 2].map(|i| (p[i] + q[i]) / 2)
    };
    let (u, w, fp) = (mid(a), mid(b), corner_point(f, 2));
    let d = sub(w, u);
    let g = sub(fp, u);
    let s = dot(cross(d, g), face.normal());
    debug_assert!(s != 0);
    if s < 0 {
        Side { from: a, to: b }
    } else {
        Side { from: b, to: a }
    }
}

/// All sides of a case, face by face.
pub fn cube_sides(case: u8) -> Vec<Side> {
    FACES.iter().flat_map(|&f| face_sides(case, f)).collect()
}

pub(crate) fn sub(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn cross(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub(crate) fn dot(a: [i64; 3], b: [i64; 3]) -> i64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_corner_loop_runs_4_8_0() {
        // Worked by hand from SPEC §3 and §7: corner 0 filled gives 4 → 8 → 0 → 4.
        let mut s = cube_sides(1);
        s.sort();
        assert_eq!(
            s,
            vec![
                Side { from: 0, to: 4 },
                Side { from: 4, to: 8 },
                Side { from: 8, to: 0 }
            ]
        );
    }

    #[test]
    fn complement_reverses_nothing_but_ambiguous_faces_differ() {
        // Where a face has two occupied edges, complementing the case flips the side.
        for case in 0..=255u8 {
            for f in FACES {
                let s = face_sides(case, f);
                let t = face_sides(!case, f);
                if s.len() == 1 {
                    assert_eq!(
                        t,
                        vec![Side {
                            from: s[0].to,
                            to: s[0].from
                        }]
                    );
                }
            }
        }
    }
}
