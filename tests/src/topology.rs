//! Combinatorial mesh checks: closed oriented 2-manifold, edge multiplicities, Euler
//! characteristic per connected component.
//!
//! These are the properties SPEC §5 promises for embedded mode on a volume with an empty border
//! ("a closed, consistently oriented 2-manifold"), and the ones paper mode breaks (edges shared by
//! four triangles), so they are written to report *what* is wrong, not just whether.

use std::collections::{BTreeMap, HashMap};

/// Undirected edge → number of triangles using it.
pub fn edge_uses(triangles: &[[u32; 3]]) -> HashMap<[u32; 2], usize> {
    let mut uses = HashMap::new();
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *uses.entry([a.min(b), a.max(b)]).or_insert(0) += 1;
        }
    }
    uses
}

/// Histogram: number of triangles on an edge → number of such edges.
pub fn edge_multiplicities(triangles: &[[u32; 3]]) -> BTreeMap<usize, usize> {
    let mut h = BTreeMap::new();
    for (_, n) in edge_uses(triangles) {
        *h.entry(n).or_insert(0) += 1;
    }
    h
}

/// Number of undirected edges used by more than two triangles.
pub fn overused_edges(triangles: &[[u32; 3]]) -> usize {
    edge_uses(triangles).values().filter(|&&n| n > 2).count()
}

/// Everything that keeps `(vertices, triangles)` from being a closed, consistently oriented
/// 2-manifold with no unreferenced vertex and no degenerate triangle. Empty means it is one.
/// At most `limit` problems are listed.
pub fn manifold_problems(vertices: usize, triangles: &[[u32; 3]], limit: usize) -> Vec<String> {
    let mut out = vec![];
    let mut push = |s: String| {
        if out.len() < limit {
            out.push(s);
        }
    };
    let mut referenced = vec![false; vertices];
    for (i, t) in triangles.iter().enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            push(format!("triangle {i} {t:?} repeats a vertex"));
        }
        for &v in t {
            if (v as usize) < vertices {
                referenced[v as usize] = true;
            } else {
                push(format!(
                    "triangle {i} {t:?} refers past {vertices} vertices"
                ));
            }
        }
    }
    for (v, r) in referenced.iter().enumerate() {
        if !r {
            push(format!("vertex {v} is unreferenced"));
        }
    }
    // Directed edges: each must occur once, and its reverse once.
    let mut directed: HashMap<[u32; 2], usize> = HashMap::new();
    for t in triangles {
        for i in 0..3 {
            *directed.entry([t[i], t[(i + 1) % 3]]).or_insert(0) += 1;
        }
    }
    for (&[a, b], &n) in &directed {
        let back = directed.get(&[b, a]).copied().unwrap_or(0);
        if n != 1 || back != 1 {
            push(format!(
                "edge {a}→{b} is used {n} times this way and {back} times the other"
            ));
        }
    }
    // Vertex links: the opposite edges of a vertex's triangles must form one cycle.
    let mut link: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    for t in triangles {
        for i in 0..3 {
            link.entry(t[i])
                .or_default()
                .push((t[(i + 1) % 3], t[(i + 2) % 3]));
        }
    }
    for (v, edges) in &link {
        let next: HashMap<u32, u32> = edges.iter().copied().collect();
        if next.len() != edges.len() {
            push(format!("vertex {v}: link has a repeated start"));
            continue;
        }
        let start = edges[0].0;
        let mut cur = start;
        let mut steps = 0;
        loop {
            let Some(&n) = next.get(&cur) else {
                push(format!("vertex {v}: link is not closed"));
                break;
            };
            steps += 1;
            cur = n;
            if cur == start || steps > edges.len() {
                break;
            }
        }
        if cur == start && steps != edges.len() {
            push(format!(
                "vertex {v}: link is {} cycles or more ({steps} of {} edges in the first)",
                2,
                edges.len()
            ));
        }
    }
    out
}

/// Vertices, edges, faces and χ = V − E + F of one connected component.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Component {
    /// Vertices.
    pub v: i64,
    /// Undirected edges.
    pub e: i64,
    /// Triangles.
    pub f: i64,
}

impl Component {
    /// The Euler characteristic.
    pub fn chi(&self) -> i64 {
        self.v - self.e + self.f
    }
}

/// The connected components (through shared vertices) of a mesh, largest first.
pub fn components(vertices: usize, triangles: &[[u32; 3]]) -> Vec<Component> {
    let mut parent: Vec<usize> = (0..vertices).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for t in triangles {
        for i in 1..3 {
            let (a, b) = (
                find(&mut parent, t[0] as usize),
                find(&mut parent, t[i] as usize),
            );
            parent[a] = b;
        }
    }
    let mut comps: HashMap<usize, Component> = HashMap::new();
    let mut used = vec![false; vertices];
    for t in triangles {
        let r = find(&mut parent, t[0] as usize);
        comps.entry(r).or_default().f += 1;
        for &v in t {
            if !used[v as usize] {
                used[v as usize] = true;
                comps.entry(r).or_default().v += 1;
            }
        }
    }
    for e in edge_uses(triangles).keys() {
        let r = find(&mut parent, e[0] as usize);
        comps.entry(r).or_default().e += 1;
    }
    let mut out: Vec<Component> = comps.into_values().collect();
    out.sort_by_key(|c| std::cmp::Reverse(c.f));
    out
}

/// χ of the whole mesh (referenced vertices only).
pub fn euler(vertices: usize, triangles: &[[u32; 3]]) -> i64 {
    components(vertices, triangles)
        .iter()
        .map(Component::chi)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Outward-wound tetrahedron on vertices `o..o + 4`.
    fn tet(o: u32) -> Vec<[u32; 3]> {
        vec![
            [o, o + 2, o + 1],
            [o, o + 1, o + 3],
            [o + 1, o + 2, o + 3],
            [o, o + 3, o + 2],
        ]
    }

    #[test]
    fn tetrahedron_is_a_closed_sphere() {
        assert!(manifold_problems(4, &tet(0), 10).is_empty());
        assert_eq!(euler(4, &tet(0)), 2);
        assert_eq!(components(8, &[tet(0), tet(4)].concat()).len(), 2);
    }

    #[test]
    fn defects_are_reported() {
        // A hole.
        assert!(!manifold_problems(4, &tet(0)[1..], 10).is_empty());
        // A flipped triangle.
        let mut t = tet(0);
        t[0] = [0, 1, 2];
        assert!(!manifold_problems(4, &t, 10).is_empty());
        // Two tetrahedra sharing vertex 0 (a bowtie): edges fine, the vertex link is two cycles.
        let mut b = tet(0);
        b.extend(
            tet(3)
                .into_iter()
                .map(|t| t.map(|v| if v == 3 { 0 } else { v })),
        );
        let p = manifold_problems(7, &b, 10);
        assert!(p.iter().any(|s| s.contains("vertex 0")), "{p:?}");
        // Unreferenced vertex, degenerate triangle, an edge in four triangles.
        assert!(!manifold_problems(5, &tet(0), 10).is_empty());
        assert!(!manifold_problems(4, &[tet(0), vec![[0, 0, 1]]].concat(), 10).is_empty());
        let doubled = [tet(0), tet(0)].concat();
        assert_eq!(overused_edges(&doubled), 6);
        assert!(!manifold_problems(4, &doubled, 10).is_empty());
    }
}
