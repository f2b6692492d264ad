//! Human-readable views of a table set: entry text, statistics, diffs and selections.

use std::fmt::Write;

use sc_tablegen::cube::{FACES, Face, edge_corners, greys};
use sc_tablegen::nibble::Loops;
use sc_tablegen::sides::{face_sides, filled, occupied};
use sc_tablegen::{ClassTable, Entry, Grey, Rule, TableSet};

/// An edge's readable name: its axis, then its offsets along the other two axes in axis order
/// (`x01` is the x-edge at y = 0, z = 1).
pub fn edge_name(e: u8) -> String {
    let [a, _] = edge_corners(e);
    let axis = usize::from(e / 4);
    let off: Vec<String> = (0..3)
        .filter(|&i| i != axis)
        .map(|i| ((a >> i) & 1).to_string())
        .collect();
    format!("{}{}", ["x", "y", "z"][axis], off.concat())
}

fn face_name(f: Face) -> String {
    format!("{}={}", ["x", "y", "z"][f.axis], f.side)
}

fn greys_text(grey: &[Grey]) -> String {
    if grey.is_empty() {
        return "none occupied".into();
    }
    grey.iter()
        .map(|g| {
            let ear = g.ear.map_or("no ear".into(), |i| format!("ear {i}"));
            let m = if g.mergeable {
                "mergeable"
            } else {
                "NOT mergeable (forced fold)"
            };
            format!("{} {} ({ear}, {m})", g.edge, edge_name(g.edge))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn triangles_text(out: &mut String, triangles: &[[u8; 3]]) {
    for (i, t) in triangles.iter().enumerate() {
        let names: Vec<String> = t.iter().map(|&e| edge_name(e)).collect();
        let _ = writeln!(
            out,
            "  {i}: {:>2} {:>2} {:>2}   {}",
            t[0],
            t[1],
            t[2],
            names.join(" → ")
        );
    }
}

/// The full text view of one entry, with a small drawing of the cube.
pub fn text(set: &TableSet, p: u8, case: u8) -> String {
    let e = set.entry(p, case);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "class {p} case {case} ({case:#04x}, {case:#010b})  rule: {}",
        e.rule.name()
    );
    let corners: Vec<String> = (0..8)
        .filter(|&c| filled(case, c))
        .map(|c| c.to_string())
        .collect();
    let _ = writeln!(
        out,
        "filled corners: {}",
        if corners.is_empty() {
            "none".into()
        } else {
            corners.join(" ")
        }
    );
    let occ: Vec<String> = (0..12)
        .filter(|&x| occupied(case, x))
        .map(|x| format!("{x} {}", edge_name(x)))
        .collect();
    let _ = writeln!(
        out,
        "occupied edges: {}",
        if occ.is_empty() {
            "none".into()
        } else {
            occ.join(", ")
        }
    );
    let _ = writeln!(out, "class greys: {:?}", greys(p));
    let _ = writeln!(
        out,
        "face sides (seen from inside, filled corners on the left):"
    );
    for f in FACES {
        let s: Vec<String> = face_sides(case, f)
            .iter()
            .map(|s| format!("{}→{}", s.from, s.to))
            .collect();
        if !s.is_empty() {
            let _ = writeln!(out, "  {}: {}", face_name(f), s.join(", "));
        }
    }
    if let Ok(loops) = Loops::of_case(case) {
        let l: Vec<String> = loops
            .cycles()
            .iter()
            .map(|c| {
                format!(
                    "[{}]",
                    c.iter().map(u8::to_string).collect::<Vec<_>>().join(" → ")
                )
            })
            .collect();
        let _ = writeln!(
            out,
            "loops: {}",
            if l.is_empty() {
                "none".into()
            } else {
                l.join("  ")
            }
        );
    }
    let _ = writeln!(out, "triangles ({}):", e.triangles.len());
    triangles_text(&mut out, &e.triangles);
    let _ = writeln!(out, "greys: {}", greys_text(&e.grey));
    if let Some(paper) = &e.paper {
        let _ = writeln!(
            out,
            "paper-mode alternative (rule {}, the ear's fold kept):",
            paper.rule.name()
        );
        triangles_text(&mut out, &paper.triangles);
        let _ = writeln!(out, "  greys: {}", greys_text(&paper.grey));
    }
    out.push_str(&drawing(case));
    out
}

/// A cube drawing with ● for filled and ○ for empty corners, numbered.
fn drawing(case: u8) -> String {
    let c = |i: u8| format!("{}{i}", if filled(case, i) { '●' } else { '○' });
    format!(
        "       {6}--------{7}\n      /|         /|\n    {4}--------{5} |      z\n     | {2}-------|-{3}     | y\n     |/         |/      |/\n    {0}--------{1}        +-- x\n",
        c(0),
        c(1),
        c(2),
        c(3),
        c(4),
        c(5),
        c(6),
        c(7)
    )
}

/// The summary printed by `dump --stats`.
pub fn stats(set: &TableSet) -> String {
    let mut out = String::new();
    let rules = [
        Rule::Base,
        Rule::Rot1,
        Rule::Rot2,
        Rule::Demoted,
        Rule::Fallback,
    ];
    let _ = writeln!(out, "order (class 0): greys 8 3 5, then {:?}", set.order);
    let _ = writeln!(out, "entries per rule:");
    for r in rules {
        let n = set
            .classes
            .iter()
            .flat_map(|c| &c.cases)
            .filter(|e| e.rule == r)
            .count();
        let _ = writeln!(out, "  {:<8}{n:>5}", r.name());
    }
    let _ = writeln!(
        out,
        "forced folds per class (entries marked not mergeable):"
    );
    for c in &set.classes {
        let forced: Vec<u8> = c
            .cases
            .iter()
            .filter(|e| e.grey.iter().any(|g| !g.mergeable))
            .map(|e| e.case)
            .collect();
        let _ = writeln!(
            out,
            "  class {}: {:>2}  cases {forced:?}",
            c.class,
            forced.len()
        );
    }
    let _ = writeln!(out, "triangles per entry:");
    for n in 0..=5 {
        let k = set
            .classes
            .iter()
            .flat_map(|c| &c.cases)
            .filter(|e| e.triangles.len() == n)
            .count();
        let _ = writeln!(out, "  {n}: {k:>5}");
    }
    out
}

/// One line per entry that differs between two sets.
pub fn diff(a: &TableSet, b: &TableSet) -> Vec<String> {
    let mut out = vec![];
    for p in 0..8u8 {
        for case in 0..=255u8 {
            let (x, y) = (a.classes.get(usize::from(p)), b.classes.get(usize::from(p)));
            let (x, y) = (
                x.and_then(|c| c.cases.get(usize::from(case))),
                y.and_then(|c| c.cases.get(usize::from(case))),
            );
            if x != y {
                out.push(format!("class {p} case {case}: {}", describe_diff(x, y)));
            }
        }
    }
    out
}

fn describe_diff(x: Option<&Entry>, y: Option<&Entry>) -> String {
    match (x, y) {
        (Some(x), Some(y)) => {
            let mut parts = vec![];
            if x.triangles != y.triangles {
                parts.push(format!(
                    "triangles {:?} vs fresh {:?}",
                    x.triangles, y.triangles
                ));
            }
            if x.grey != y.grey {
                parts.push("grey records".into());
            }
            if x.rule != y.rule {
                parts.push(format!("rule {} vs fresh {}", x.rule.name(), y.rule.name()));
            }
            if x.paper != y.paper {
                parts.push("paper alternative".into());
            }
            parts.join(", ")
        }
        (None, _) => "missing from the file".into(),
        (_, None) => "extra in the file".into(),
    }
}

/// The selected classes and cases as a smaller set, for RON or JSON output.
pub fn select(set: &TableSet, classes: &[u8], cases: &[u8]) -> TableSet {
    TableSet {
        order: set.order,
        classes: classes
            .iter()
            .map(|&p| ClassTable {
                class: p,
                cases: cases.iter().map(|&c| set.entry(p, c).clone()).collect(),
            })
            .collect(),
    }
}
