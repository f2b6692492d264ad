//! Pictures in the style of the paper's Figs. 3 and 6: an oblique cube, filled corners black,
//! grey edges marked, face sides drawn, triangles shaded (vertices at edge midpoints).

use std::fmt::Write;
use std::path::Path;

use sc_tablegen::TableSet;
use sc_tablegen::cube::{corner_offset, edge_corners, greys};
use sc_tablegen::sides::{cube_sides, filled};

/// Oblique projection: y recedes up and to the right.
fn project(p: [f64; 3]) -> (f64, f64) {
    (
        40.0 + 120.0 * p[0] + 55.0 * p[1],
        200.0 - 120.0 * p[2] - 45.0 * p[1],
    )
}

fn corner(c: u8) -> [f64; 3] {
    corner_offset(c).map(f64::from)
}

fn midpoint(e: u8) -> (f64, f64) {
    let [a, b] = edge_corners(e).map(corner);
    project([0, 1, 2].map(|i| (a[i] + b[i]) / 2.0))
}

/// One picture.
pub fn picture(set: &TableSet, p: u8, case: u8) -> String {
    let entry = set.entry(p, case);
    let mut s = String::new();
    let _ = write!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="300" height="250" viewBox="0 0 300 250" font-family="sans-serif" font-size="11">"#
    );
    let _ = write!(s, r#"<rect width="300" height="250" fill="white"/>"#);
    let blocked: Vec<u8> = entry
        .grey
        .iter()
        .filter(|g| !g.mergeable)
        .map(|g| g.edge)
        .collect();
    for e in 0..12u8 {
        let [a, b] = edge_corners(e).map(|c| project(corner(c)));
        let (colour, width) = match (greys(p).contains(&e), blocked.contains(&e)) {
            (true, true) => ("#c0392b", 5.0),
            (true, false) => ("#999999", 5.0),
            _ => ("#333333", 1.0),
        };
        let _ = write!(
            s,
            r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{colour}" stroke-width="{width}" stroke-linecap="round"/>"#,
            a.0, a.1, b.0, b.1
        );
    }
    for t in &entry.triangles {
        let pts: Vec<String> = t
            .iter()
            .map(|&e| midpoint(e))
            .map(|(x, y)| format!("{x:.1},{y:.1}"))
            .collect();
        let _ = write!(
            s,
            r##"<polygon points="{}" fill="#5dade2" fill-opacity="0.45" stroke="#1b4f72" stroke-width="0.8"/>"##,
            pts.join(" ")
        );
    }
    for side in cube_sides(case) {
        let (a, b) = (midpoint(side.from), midpoint(side.to));
        let _ = write!(
            s,
            r##"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="#1b4f72" stroke-width="2.2"/>"##,
            a.0, a.1, b.0, b.1
        );
    }
    for c in 0..8u8 {
        let (x, y) = project(corner(c));
        let fill = if filled(case, c) { "black" } else { "white" };
        let _ = write!(
            s,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="6" fill="{fill}" stroke="black" stroke-width="1.5"/>"#
        );
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}">{c}</text>"#,
            x + 7.0,
            y + 14.0
        );
    }
    let _ = write!(
        s,
        r#"<text x="8" y="240">class {p} case {case} ({case:#04x}) rule {} · {} triangles</text></svg>"#,
        entry.rule.name(),
        entry.triangles.len()
    );
    s.push('\n');
    s
}

/// Writes `class{p}-case{NNN}.svg` for every selected entry.
pub fn write_all(set: &TableSet, classes: &[u8], cases: &[u8], dir: &Path) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    for &p in classes {
        for &c in cases {
            let path = dir.join(format!("class{p}-case{c:03}.svg"));
            std::fs::write(&path, picture(set, p, c))
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
        }
    }
    println!(
        "wrote {} pictures to {}",
        classes.len() * cases.len(),
        dir.display()
    );
    Ok(())
}
