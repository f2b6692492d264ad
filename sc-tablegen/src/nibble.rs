//! Step 3: spanning each loop of face sides by triangles, nibbling edges in a fixed order (SPEC §4).

use crate::cube::share_face;
use crate::sides::{Side, cube_sides};

/// Loop neighbours of every occupied edge: `next[e]` is where the side leaving `e` ends.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Loops {
    next: [Option<u8>; 12],
    prev: [Option<u8>; 12],
}

/// Why a case's sides do not form loops: each occupied edge must start one side and end one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoopError(pub String);

impl Loops {
    /// Links the case's face sides into loops.
    pub fn of_case(case: u8) -> Result<Loops, LoopError> {
        let mut loops = Loops {
            next: [None; 12],
            prev: [None; 12],
        };
        for Side { from, to } in cube_sides(case) {
            let (f, t) = (usize::from(from), usize::from(to));
            if loops.next[f].replace(to).is_some() || loops.prev[t].replace(from).is_some() {
                return Err(LoopError(format!(
                    "edge {from} or {to} has two sides one way"
                )));
            }
        }
        if loops
            .next
            .iter()
            .zip(&loops.prev)
            .any(|(n, p)| n.is_some() != p.is_some())
        {
            return Err(LoopError(
                "an occupied edge has a side in only one direction".into(),
            ));
        }
        Ok(loops)
    }

    /// The side leaving `e` ends here, if `e` is occupied.
    pub fn next(&self, e: u8) -> Option<u8> {
        self.next[usize::from(e)]
    }

    /// The side arriving at `e` starts here, if `e` is occupied.
    pub fn prev(&self, e: u8) -> Option<u8> {
        self.prev[usize::from(e)]
    }

    /// The grey edge's ear `(back, e, forward)` would be a fold: its closing side lies in a face.
    /// No order avoids this while nibbling `e` first (SPEC §4, forced folds).
    pub fn ear_folds(&self, e: u8) -> bool {
        match (self.prev(e), self.next(e)) {
            (Some(b), Some(f)) => self.next(f) != Some(b) && share_face(b, f),
            _ => false,
        }
    }

    /// The occupied edges, each loop as a cycle starting at its smallest edge.
    pub fn cycles(&self) -> Vec<Vec<u8>> {
        let mut seen = [false; 12];
        let mut out = Vec::new();
        for start in 0..12u8 {
            if seen[usize::from(start)] || self.next[usize::from(start)].is_none() {
                continue;
            }
            let mut cycle = vec![];
            let mut e = start;
            while !seen[usize::from(e)] {
                seen[usize::from(e)] = true;
                cycle.push(e);
                e = self.next[usize::from(e)].expect("loops are closed");
            }
            out.push(cycle);
        }
        out
    }
}

/// The result of nibbling one case with one order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Nibbled {
    /// Triangles `(back(E), E, forward(E))` in emission order.
    pub triangles: Vec<[u8; 3]>,
    /// For each edge, the index of the triangle emitted when it was nibbled.
    pub emitted_at: [Option<u8>; 12],
    /// Interior sides as unordered pairs of edges, in creation order.
    pub interior: Vec<[u8; 2]>,
}

impl Nibbled {
    /// Interior sides joining two edges of one face, and triangles with all vertices on one face.
    pub fn folds(&self) -> Vec<Fold> {
        let mut folds: Vec<Fold> = self
            .interior
            .iter()
            .filter(|s| share_face(s[0], s[1]))
            .map(|&s| Fold::Side(s))
            .collect();
        folds.extend(
            self.triangles
                .iter()
                .filter(|t| {
                    crate::cube::FACES
                        .iter()
                        .any(|f| t.iter().all(|&e| f.contains_edge(e)))
                })
                .map(|&t| Fold::Triangle(t)),
        );
        folds
    }
}

/// A way a triangulation leaves the cube's interior (SPEC §4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fold {
    /// An interior side lying in a face.
    Side([u8; 2]),
    /// A triangle lying in a face.
    Triangle([u8; 3]),
}

/// Nibbles the loops of a case, visiting edges in `order` (a permutation of 0..12).
pub fn nibble(loops: &Loops, order: &[u8; 12]) -> Nibbled {
    let mut next = loops.next;
    let mut prev = loops.prev;
    let mut out = Nibbled {
        triangles: vec![],
        emitted_at: [None; 12],
        interior: vec![],
    };
    for &e in order {
        let ei = usize::from(e);
        let (Some(f), Some(b)) = (next[ei], prev[ei]) else {
            continue;
        };
        out.emitted_at[ei] = Some(out.triangles.len() as u8);
        out.triangles.push([b, e, f]);
        next[ei] = None;
        prev[ei] = None;
        if next[usize::from(f)] == Some(b) {
            // The loop was a triangle: it is done.
            for x in [b, f] {
                next[usize::from(x)] = None;
                prev[usize::from(x)] = None;
            }
        } else {
            next[usize::from(b)] = Some(f);
            prev[usize::from(f)] = Some(b);
            out.interior.push([b, f]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_case_forms_loops_of_three_to_seven() {
        for case in 0..=255u8 {
            let loops = Loops::of_case(case).unwrap();
            let cycles = loops.cycles();
            assert!(cycles.len() <= 4, "case {case}");
            assert!(
                cycles.iter().all(|c| (3..=7).contains(&c.len())),
                "case {case}"
            );
        }
    }

    #[test]
    fn nibbling_gives_occupied_minus_two_per_loop() {
        let order: [u8; 12] = core::array::from_fn(|i| i as u8);
        for case in 0..=255u8 {
            let loops = Loops::of_case(case).unwrap();
            let n = nibble(&loops, &order);
            let occ: usize = loops.cycles().iter().map(Vec::len).sum();
            assert_eq!(
                n.triangles.len(),
                occ - 2 * loops.cycles().len(),
                "case {case}"
            );
        }
    }
}
