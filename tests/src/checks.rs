//! The checks the integration tests run on a volume: runtime against reference, SPEC §6 counts
//! done independently, closed manifold, separation, no self-intersection.
//!
//! Each check returns a description of what failed rather than panicking inside, so a test can
//! also assert that a check *fails* (the rule-off reference on the rule volumes).

use std::collections::HashMap;

use sc_runtime::{Mesh, Mode};
use sc_tablegen::nibble::Loops;

use crate::geometry::winding_and_distance;
use crate::reference::{self, Field, Key, RefMesh, canonical};
use crate::topology::manifold_problems;
use crate::volumes::{Sample, Vol};

/// Maps runtime vertices to edge keys through their positions, which the reference computes
/// with the same SPEC §1 formula. Fails if two occupied edges share a position (the mapping
/// would be ambiguous) or a runtime vertex is on no occupied edge.
pub fn keys_of(field: &Field, mesh: &Mesh) -> Result<Vec<Key>, String> {
    let mut by_pos: HashMap<[u32; 3], Key> = HashMap::new();
    for k in field.occupied_edges() {
        let p = field.position(k).map(f32::to_bits);
        if let Some(old) = by_pos.insert(p, k) {
            return Err(format!("edges {old:?} and {k:?} share a position"));
        }
    }
    mesh.positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            by_pos
                .get(&p.map(f32::to_bits))
                .copied()
                .ok_or_else(|| format!("runtime vertex {i} at {p:?} is on no occupied edge"))
        })
        .collect()
}

/// Whether the runtime mesh is the reference's, exactly: the same vertices (one per key, same
/// `f32` positions), the same oriented triangles up to renumbering and rotation, and the same
/// counts.
pub fn compare(field: &Field, mesh: &Mesh, r: &RefMesh) -> Result<(), String> {
    let keys = keys_of(field, mesh)?;
    let mut seen = std::collections::BTreeSet::new();
    for (i, k) in keys.iter().enumerate() {
        if !seen.insert(*k) {
            return Err(format!("two runtime vertices on edge {k:?} (vertex {i})"));
        }
        if !r.positions.contains_key(k) {
            return Err(format!(
                "runtime vertex {i} on {k:?}, which the reference does not use"
            ));
        }
    }
    if keys.len() != r.positions.len() {
        return Err(format!(
            "runtime has {} vertices, reference {}",
            keys.len(),
            r.positions.len()
        ));
    }
    let mut got: Vec<[Key; 3]> = mesh
        .triangles
        .iter()
        .map(|t| canonical(t.map(|i| keys[i as usize])))
        .collect();
    let mut want: Vec<[Key; 3]> = r.triangles.iter().map(|&t| canonical(t)).collect();
    got.sort();
    want.sort();
    if got != want {
        let extra: Vec<_> = got.iter().filter(|t| !want.contains(t)).take(3).collect();
        let missing: Vec<_> = want.iter().filter(|t| !got.contains(t)).take(3).collect();
        return Err(format!(
            "triangles differ: runtime {} vs reference {}; runtime only {extra:?}; reference only {missing:?}",
            got.len(),
            want.len()
        ));
    }
    let s = mesh.stats;
    let want_stats = [
        r.v13,
        r.t13,
        r.merged,
        r.blocked,
        r.bounded,
        r.positions.len() as u64,
        r.triangles.len() as u64,
    ];
    let got_stats = s.to_array();
    if got_stats != want_stats {
        return Err(format!(
            "stats (v13, t13, merged, blocked, bounded, vertices, triangles) {got_stats:?} vs reference {want_stats:?}"
        ));
    }
    if !mesh.normals.is_empty() {
        if mesh.normals.len() != mesh.positions.len() {
            return Err("not one normal per vertex".into());
        }
        if let Some(n) = mesh.normals.iter().find(|n| {
            let l = n.iter().map(|c| f64::from(*c).powi(2)).sum::<f64>().sqrt();
            !(l - 1.0).abs().lt(&1e-4)
        }) {
            return Err(format!("normal {n:?} is not unit length"));
        }
    }
    Ok(())
}

/// Runs the runtime and the reference on `vol` in `mode`, asserts they agree exactly and returns
/// the runtime's mesh.
pub fn matches_reference<T: Sample>(vol: &Vol<T>, mode: Mode) -> Mesh {
    let mesh = vol.extract(mode);
    let field = vol.field();
    let r = reference::extract(&field, reference::RefMode::of(mode));
    if let Err(e) = compare(&field, &mesh, &r) {
        panic!("{mode:?} on {:?} iso {}: {e}", vol.dims, vol.iso);
    }
    mesh
}

/// SPEC §6 counted independently of both implementations' triangles: `V13` = occupied grid
/// edges, `T13 = Σ_cubes (occupied − 2·loops)` with loops from `sc_tablegen::nibble::Loops`.
pub fn spec6_counts(field: &Field) -> (u64, u64) {
    let per_case: Vec<u64> = (0..=255u8)
        .map(|case| {
            let cycles = Loops::of_case(case)
                .expect("every case forms loops")
                .cycles();
            let occ: usize = cycles.iter().map(Vec::len).sum();
            (occ - 2 * cycles.len()) as u64
        })
        .collect();
    let t13 = field
        .cubes()
        .iter()
        .map(|&c| per_case[usize::from(field.case(c))])
        .sum();
    (field.occupied_edges().len() as u64, t13)
}

/// Asserts SPEC §6 on a runtime mesh: `T13`, `V13` as counted by [`spec6_counts`];
/// `T = T13 − 2M` and `V = V13 − M` with `M` the reference's merge count; and the mesh's actual
/// lengths equal the stats.
pub fn assert_spec6<T: Sample>(vol: &Vol<T>, mode: Mode, mesh: &Mesh) {
    let field = vol.field();
    let (v13, t13) = spec6_counts(&field);
    let m = reference::extract(&field, reference::RefMode::of(mode)).merged;
    let s = mesh.stats;
    assert_eq!((s.v13, s.t13), (v13, t13), "{mode:?}: V13, T13");
    assert_eq!(s.merged, m, "{mode:?}: merged grey edges");
    assert_eq!(s.triangles, t13 - 2 * m, "{mode:?}: T14 = T13 − 2M");
    assert_eq!(s.vertices, v13 - m, "{mode:?}: V14 = V13 − M");
    assert_eq!(
        (mesh.positions.len() as u64, mesh.triangles.len() as u64),
        (s.vertices, s.triangles),
        "{mode:?}: mesh lengths match stats"
    );
}

/// Asserts the mesh is a closed, consistently oriented 2-manifold, with no unreferenced vertex
/// and no degenerate triangle.
pub fn assert_closed_manifold(mesh: &Mesh, what: &str) {
    let p = manifold_problems(mesh.positions.len(), &mesh.triangles, 8);
    assert!(p.is_empty(), "{what}: not a closed 2-manifold: {p:#?}");
}

/// Result of a separation check.
#[derive(Clone, Debug, Default)]
pub struct Separation {
    /// Grid points checked.
    pub checked: usize,
    /// Grid points within `1e-6` spacings of the surface, skipped.
    pub on_surface: usize,
    /// Points where the winding number is not within 1e-3 of 1 (filled) or 0 (empty).
    pub wrong: Vec<([usize; 3], bool, f64)>,
}

/// Winding number of the mesh at every `stride`-th grid point: ≈ 1 at filled, ≈ 0 at empty
/// samples. Points closer than `1e-6` spacings to the surface are counted, not judged (a merged
/// quad's diagonal can pass through a sample).
pub fn separation<T: Sample>(vol: &Vol<T>, mesh: &Mesh, stride: usize) -> Separation {
    let mut s = Separation::default();
    let tol = 1e-6 * vol.spacing.iter().copied().fold(f64::INFINITY, f64::min);
    for p in vol.points() {
        if p.iter().any(|&c| c % stride != 0) {
            continue;
        }
        let (w, d) = winding_and_distance(vol.world(p), &mesh.positions, &mesh.triangles);
        if d < tol {
            s.on_surface += 1;
            continue;
        }
        s.checked += 1;
        let filled = vol.filled(p);
        let want = if filled { 1.0 } else { 0.0 };
        if (w - want).abs() > 1e-3 {
            s.wrong.push((p, filled, w));
        }
    }
    s
}

/// Asserts separation holds at every `stride`-th grid point.
pub fn assert_separates<T: Sample>(
    vol: &Vol<T>,
    mesh: &Mesh,
    stride: usize,
    what: &str,
) -> Separation {
    let s = separation(vol, mesh, stride);
    assert!(
        s.wrong.is_empty(),
        "{what}: winding number wrong at {} of {} points, e.g. {:?}",
        s.wrong.len(),
        s.checked,
        &s.wrong[..s.wrong.len().min(5)]
    );
    assert!(s.checked > 0, "{what}: no point checked");
    s
}

/// Asserts no two triangles intersect other than along shared sides and vertices, and none is
/// degenerate (exact predicates, `crate::self_intersect`).
pub fn assert_no_self_intersections(mesh: &Mesh, what: &str) {
    let hits = crate::self_intersect::self_intersections(&mesh.positions, &mesh.triangles);
    assert!(
        hits.is_empty(),
        "{what}: {} intersecting pairs, e.g. {:?}",
        hits.len(),
        hits.iter()
            .take(3)
            .map(|&(i, j)| (mesh.triangles[i], mesh.triangles[j]))
            .collect::<Vec<_>>()
    );
}
