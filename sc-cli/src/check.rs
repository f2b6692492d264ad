//! `extract --check`: how the mesh's edges are shared, so a user (or the README) can see that
//! embedded mode is a closed 2-manifold and paper mode is not.

use std::collections::HashMap;

use serde_json::{Value, json};

/// Undirected edges by the number of triangles around them, and orientation conflicts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EdgeReport {
    /// Edges in one triangle: a border (open surface).
    pub border: u64,
    /// Edges in exactly two triangles.
    pub manifold: u64,
    /// Edges in three or more triangles.
    pub non_manifold: u64,
    /// Directed edges used by two triangles the same way: inconsistent winding.
    pub misoriented: u64,
}

impl EdgeReport {
    /// Counts over a triangle list.
    pub fn of(triangles: &[[u32; 3]]) -> EdgeReport {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * triangles.len());
        for t in triangles {
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        let mut r = EdgeReport::default();
        for (&(a, b), &n) in &directed {
            r.misoriented += u64::from(n > 1);
            // Count each undirected edge once, from its smaller-first direction or its only one.
            let back = directed.get(&(b, a)).copied().unwrap_or(0);
            if a < b || back == 0 {
                match n + back {
                    1 => r.border += 1,
                    2 => r.manifold += 1,
                    _ => r.non_manifold += 1,
                }
            }
        }
        r
    }

    /// The JSON form for `--stats-json`.
    pub fn to_json(self) -> Value {
        json!({
            "border_edges": self.border,
            "manifold_edges": self.manifold,
            "non_manifold_edges": self.non_manifold,
            "misoriented_edges": self.misoriented,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetrahedron_is_closed_and_oriented() {
        let t = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        assert_eq!(
            EdgeReport::of(&t),
            EdgeReport {
                border: 0,
                manifold: 6,
                non_manifold: 0,
                misoriented: 0
            }
        );
    }

    #[test]
    fn border_fins_and_flips_are_counted() {
        // One triangle: three border edges.
        assert_eq!(EdgeReport::of(&[[0, 1, 2]]).border, 3);
        // Four triangles on edge 0–1, alternating orientation: one non-manifold edge.
        let fan = [[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 0, 5]];
        let r = EdgeReport::of(&fan);
        assert_eq!((r.non_manifold, r.border), (1, 8));
        assert_eq!(r.misoriented, 2);
        // The same triangle twice, same winding: misoriented.
        assert_eq!(EdgeReport::of(&[[0, 1, 2], [0, 1, 2]]).misoriented, 3);
    }
}
