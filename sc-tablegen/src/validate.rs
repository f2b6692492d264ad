//! Exhaustive validation of a table set, entry by entry, independent of how it was generated.
//!
//! Each check recomputes what it needs from the case bits (face sides, loops, the forced-fold
//! configuration), so a generator bug cannot hide behind its own bookkeeping.

use std::collections::HashMap;
use std::fmt;

use crate::cube::{FACES, edge_corners, edge_faces, greys, share_face};
use crate::embed;
use crate::nibble::Loops;
use crate::sides::{Side, cube_sides, filled, occupied};
use crate::table::{Entry, Grey, Rule, TableSet};

/// A validation failure, naming the class and case it concerns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Invalid {
    /// Parity class, when the problem is in one entry.
    pub class: Option<u8>,
    /// Case, when the problem is in one entry.
    pub case: Option<u8>,
    /// What is wrong.
    pub problem: String,
}

impl Invalid {
    /// A problem with the set as a whole.
    pub fn set(problem: String) -> Invalid {
        Invalid {
            class: None,
            case: None,
            problem,
        }
    }
}

impl fmt::Display for Invalid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.class, self.case) {
            (Some(p), Some(c)) => write!(f, "class {p} case {c} ({c:#04x}): {}", self.problem),
            (Some(p), None) => write!(f, "class {p}: {}", self.problem),
            _ => f.write_str(&self.problem),
        }
    }
}

/// Validates all 2048 entries; returns every failure found.
pub fn validate(set: &TableSet) -> Result<(), Vec<Invalid>> {
    let mut errors = vec![];
    if !crate::order::is_valid_nine(&set.order) {
        errors.push(Invalid::set(format!(
            "order {:?} is not class 0's nine non-grey edges",
            set.order
        )));
    }
    if set.classes.len() != 8 {
        errors.push(Invalid::set(format!(
            "{} classes, expected 8",
            set.classes.len()
        )));
    }
    for (p, class) in set.classes.iter().enumerate() {
        let p = p as u8;
        if class.class != p || class.cases.len() != 256 {
            errors.push(Invalid {
                class: Some(p),
                case: None,
                problem: format!(
                    "class {} with {} cases, expected class {p} with 256",
                    class.class,
                    class.cases.len()
                ),
            });
            continue;
        }
        let mut forced = 0;
        for (case, entry) in class.cases.iter().enumerate() {
            let case = case as u8;
            forced += usize::from(entry.rule == Rule::Demoted);
            if let Err(problem) = check_entry(p, case, entry) {
                errors.push(Invalid {
                    class: Some(p),
                    case: Some(case),
                    problem,
                });
            }
        }
        if forced != 12 {
            errors.push(Invalid {
                class: Some(p),
                case: None,
                problem: format!("{forced} forced folds, expected 12"),
            });
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}

/// Whether grey edge `g` is a forced fold in `case`, from the corners alone (SPEC §4): its empty
/// end `P` is cut off in both faces along `g` (the other three corners of each are filled), and
/// the third face at `P` is ambiguous (its corner diagonal to `P` is empty too).
pub fn forced_fold(case: u8, g: u8) -> bool {
    if !occupied(case, g) {
        return false;
    }
    let [a, b] = edge_corners(g);
    let p = if filled(case, a) { b } else { a };
    let cut_off_along_g = edge_faces(g)
        .iter()
        .all(|f| f.corners().iter().all(|&c| c == p || filled(case, c)));
    let third = FACES
        .iter()
        .find(|f| f.corners().contains(&p) && !f.contains_edge(g))
        .expect("every corner has three faces");
    let diagonal = third
        .corners()
        .into_iter()
        .find(|&c| (c ^ p).count_ones() == 2)
        .expect("a face has a diagonal");
    cut_off_along_g && !filled(case, diagonal)
}

/// Checks one entry, and its paper alternative if any.
pub fn check_entry(p: u8, case: u8, entry: &Entry) -> Result<(), String> {
    if entry.case != case {
        return Err(format!("entry says case {}", entry.case));
    }
    let forced: Vec<u8> = greys(p)
        .into_iter()
        .filter(|&g| forced_fold(case, g))
        .collect();
    if (entry.rule == Rule::Demoted) == forced.is_empty() {
        return Err(format!(
            "rule {} but forced greys {forced:?}",
            entry.rule.name()
        ));
    }
    check_triangulation(case, &entry.triangles, None)?;
    check_greys(p, case, &entry.triangles, &entry.grey, &forced, false)?;
    embed::check(&entry.triangles, embed::entry_seed(p, case))?;
    match (&entry.paper, forced.is_empty()) {
        (None, true) => Ok(()),
        (Some(paper), false) => {
            check_triangulation(case, &paper.triangles, Some(&forced))
                .map_err(|e| format!("paper: {e}"))?;
            check_greys(p, case, &paper.triangles, &paper.grey, &forced, true)
                .map_err(|e| format!("paper: {e}"))?;
            embed::check(&paper.triangles, embed::entry_seed(p, case))
                .map_err(|e| format!("paper: {e}"))
        }
        (Some(_), true) => Err("a paper alternative on an entry without a forced fold".into()),
        (None, false) => Err("a forced fold without its paper alternative".into()),
    }
}

/// Loops filled by `|loop| − 2` triangles on occupied edges only; face sides used once with their
/// orientation; interior sides twice, opposite; no folds, except a forced grey's ear in paper mode.
fn check_triangulation(
    case: u8,
    triangles: &[[u8; 3]],
    paper_forced: Option<&[u8]>,
) -> Result<(), String> {
    let loops = Loops::of_case(case).map_err(|e| e.0)?;
    let cycles = loops.cycles();
    let loop_of = |e: u8| cycles.iter().position(|c| c.contains(&e));
    let mut per_loop = vec![0usize; cycles.len()];
    let mut directed: HashMap<(u8, u8), usize> = HashMap::new();
    for t in triangles {
        if t.iter().any(|&e| e >= 12 || !occupied(case, e)) {
            return Err(format!("triangle {t:?} uses an unoccupied edge"));
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(format!("triangle {t:?} repeats a vertex"));
        }
        let l = loop_of(t[0]);
        if t.iter().any(|&e| loop_of(e) != l) {
            return Err(format!("triangle {t:?} spans two loops"));
        }
        per_loop[l.expect("occupied edges are on loops")] += 1;
        for i in 0..3 {
            *directed.entry((t[i], t[(i + 1) % 3])).or_default() += 1;
        }
    }
    for (l, c) in cycles.iter().enumerate() {
        if per_loop[l] != c.len() - 2 {
            return Err(format!(
                "loop {c:?} has {} triangles, expected {}",
                per_loop[l],
                c.len() - 2
            ));
        }
    }
    let face: Vec<(u8, u8)> = cube_sides(case)
        .into_iter()
        .map(|Side { from, to }| (from, to))
        .collect();
    for &(a, b) in &face {
        if directed.get(&(a, b)) != Some(&1) || directed.contains_key(&(b, a)) {
            return Err(format!(
                "face side {a}→{b} is not used exactly once in its direction"
            ));
        }
    }
    for (&(a, b), &n) in &directed {
        if face.contains(&(a, b)) {
            continue;
        }
        if n != 1 || directed.get(&(b, a)) != Some(&1) {
            return Err(format!("interior side {a}→{b} is not used once each way"));
        }
        let allowed = paper_forced.is_some_and(|fs| {
            fs.iter().any(|&g| {
                let (pb, nf) = (loops.prev(g), loops.next(g));
                (pb, nf) == (Some(a), Some(b)) || (pb, nf) == (Some(b), Some(a))
            })
        });
        if share_face(a, b) && !allowed {
            return Err(format!("fold: interior side {a}–{b} lies in a face"));
        }
    }
    if let Some(t) = triangles
        .iter()
        .find(|t| FACES.iter().any(|f| t.iter().all(|&e| f.contains_edge(e))))
    {
        return Err(format!("fold: triangle {t:?} lies in a face"));
    }
    Ok(())
}

/// Grey records list the occupied greys x, y, z; ears are right; exactly the forced greys are not
/// mergeable; every mergeable grey lies in its ear only, with face sides at its vertex.
fn check_greys(
    p: u8,
    case: u8,
    triangles: &[[u8; 3]],
    grey: &[Grey],
    forced: &[u8],
    paper: bool,
) -> Result<(), String> {
    let expected: Vec<u8> = greys(p)
        .into_iter()
        .filter(|&g| occupied(case, g))
        .collect();
    let listed: Vec<u8> = grey.iter().map(|g| g.edge).collect();
    if listed != expected {
        return Err(format!(
            "grey records {listed:?}, expected occupied greys {expected:?}"
        ));
    }
    let face: Vec<Side> = cube_sides(case);
    for g in grey {
        let touching: Vec<usize> = (0..triangles.len())
            .filter(|&i| triangles[i].contains(&g.edge))
            .collect();
        if g.mergeable == forced.contains(&g.edge) {
            return Err(format!(
                "grey {} mergeable = {}, but forced = {}",
                g.edge, g.mergeable, !g.mergeable
            ));
        }
        let needs_ear = g.mergeable || paper;
        match g.ear {
            Some(i) => {
                let t = triangles
                    .get(usize::from(i))
                    .ok_or(format!("grey {} ear {i} out of range", g.edge))?;
                let k = t
                    .iter()
                    .position(|&e| e == g.edge)
                    .ok_or(format!("grey {} not in its ear", g.edge))?;
                let into = Side {
                    from: t[(k + 2) % 3],
                    to: g.edge,
                };
                let out = Side {
                    from: g.edge,
                    to: t[(k + 1) % 3],
                };
                if touching != [usize::from(i)] || !face.contains(&into) || !face.contains(&out) {
                    return Err(format!(
                        "grey {}: ear {t:?} is not its only triangle with face sides",
                        g.edge
                    ));
                }
            }
            None if needs_ear => return Err(format!("grey {} needs an ear", g.edge)),
            None => {}
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forced_folds_of_class_zero_match_the_spec() {
        let got: Vec<u8> = (0..=255u8)
            .filter(|&c| greys(0).iter().any(|&g| forced_fold(c, g)))
            .collect();
        assert_eq!(
            got,
            vec![103, 111, 118, 124, 125, 167, 173, 183, 188, 190, 237, 246]
        );
    }

    #[test]
    fn forced_fold_predicate_agrees_with_the_ear_geometry() {
        for p in 0..8 {
            for case in 0..=255u8 {
                let loops = Loops::of_case(case).unwrap();
                for g in greys(p) {
                    assert_eq!(
                        forced_fold(case, g),
                        loops.ear_folds(g),
                        "class {p} case {case} grey {g}"
                    );
                }
            }
        }
    }
}
