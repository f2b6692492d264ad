//! A slow, obviously-correct reference implementation of Skeleton Climbing Steps 1–4, written
//! straight from SPEC §1–5 over the generator's table *data* (`tables/skeleton-climbing.ron` read
//! through `sc_tablegen::TableSet`), sharing no code with `sc_runtime`.
//!
//! Why it exists: the runtime is a fast layer sweep with row trimming, id planes and an owner/partner
//! trick for merged quads, all of which can go wrong in ways that still produce plausible meshes.
//! This module does the obvious thing instead — per cube, look up the entry and emit triangles over
//! global edge keys; per occupied interior grey edge, gather the four ears and replace them by two
//! triangles — so a runtime mesh can be compared with it triangle for triangle.
//!
//! Each embedded-mode rule can be switched off ([`Rules`]), which is how the tests show that each
//! rule is needed: with a rule off, a constructed volume gives a broken surface.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::sync::OnceLock;

use sc_tablegen::cube::{edge_axis, edge_corners};

use crate::geometry::point_triangle_distance;
use sc_tablegen::{Entry, Grey, TableSet};

/// A grid edge: its lower end `(x, y, z)` and its axis (0 = x, 1 = y, 2 = z).
pub type Key = [usize; 4];

/// The committed tables, parsed once.
pub fn tables() -> &'static TableSet {
    static SET: OnceLock<TableSet> = OnceLock::new();
    SET.get_or_init(|| {
        TableSet::from_ron(include_str!("../../tables/skeleton-climbing.ron"))
            .expect("the committed tables parse")
    })
}

/// The switchable embedded-mode rules of SPEC §5.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rules {
    /// (a) Forced folds: use the embedded tables and merge only edges all four cubes mark
    /// mergeable. Off: use the paper-mode triangulation (ear first, fold kept) and ignore the mark.
    pub forced_fold: bool,
    /// (b) Do not merge a grey edge whose lower end is a pinch.
    pub pinch: bool,
    /// z-grey diagonals alternate by layer (plane `x = l` for even `n`, `y = m` for odd). Off: always
    /// the plane `x = l`, or `y = m` if [`Rules::fixed_z_in_y`] is set.
    pub alternate_z: bool,
    /// With `alternate_z` off, which fixed plane z-grey diagonals use: false `x = l`, true `y = m`.
    pub fixed_z_in_y: bool,
    /// Our addition to (b), which the runtime follows (README, "Where we depart from the SPEC"):
    /// for z-greys, the lower end `P` is a pinch whenever it differs from its six neighbours,
    /// whatever the diagonal corners (the `P or D filled` clause is dropped). Without it, an empty
    /// `P` with an empty diagonal below lets both z-greys at `P` merge into overlapping flat
    /// triangles (see `tests/rules.rs`, the flat z quad).
    pub z_pinch_six_neighbours: bool,
}

impl Rules {
    /// All rules on: the SPEC's embedded mode with our stricter z-grey pinch.
    pub const EMBEDDED: Rules = Rules {
        forced_fold: true,
        pinch: true,
        alternate_z: true,
        fixed_z_in_y: false,
        z_pinch_six_neighbours: true,
    };
    /// The paper's Step 4: every interior occupied grey edge merges.
    pub const PAPER: Rules = Rules {
        forced_fold: false,
        pinch: false,
        alternate_z: true,
        fixed_z_in_y: false,
        z_pinch_six_neighbours: false,
    };
}

/// What the reference runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RefMode {
    /// Steps 1–3: no merging.
    Steps123,
    /// Steps 1–4 with the given rules.
    Merge(Rules),
}

impl RefMode {
    /// The reference mode for a runtime mode.
    ///
    /// # Panics
    /// For adaptive mode, which the reference does not model: its meshes are checked against
    /// Steps 1–3's instead (`tests/adaptive.rs`).
    pub fn of(mode: sc_runtime::Mode) -> RefMode {
        match mode {
            sc_runtime::Mode::Steps123 => RefMode::Steps123,
            sc_runtime::Mode::Embedded => RefMode::Merge(Rules::EMBEDDED),
            sc_runtime::Mode::Paper => RefMode::Merge(Rules::PAPER),
            sc_runtime::Mode::Adaptive => {
                panic!("the reference has no adaptive mode; compare with Steps 1–3")
            }
        }
    }
}

/// A sampled volume, values as `f64` (every supported scalar type converts exactly).
#[derive(Clone, Debug)]
pub struct Field {
    /// Samples, x fastest.
    pub values: Vec<f64>,
    /// `[nx, ny, nz]`.
    pub dims: [usize; 3],
    /// Filled iff `value >= iso`; NaN is empty.
    pub iso: f64,
    /// World distance between samples.
    pub spacing: [f64; 3],
    /// World position of sample 0.
    pub origin: [f64; 3],
}

impl Field {
    /// A field with unit spacing and zero origin.
    pub fn new(values: Vec<f64>, dims: [usize; 3], iso: f64) -> Field {
        assert_eq!(values.len(), dims[0] * dims[1] * dims[2]);
        Field {
            values,
            dims,
            iso,
            spacing: [1.0; 3],
            origin: [0.0; 3],
        }
    }

    /// The sample at a grid point.
    pub fn value(&self, p: [usize; 3]) -> f64 {
        self.values[p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])]
    }

    /// SPEC §1: filled iff `f >= iso`; NaN compares false, so it is empty.
    pub fn filled(&self, p: [usize; 3]) -> bool {
        self.value(p) >= self.iso
    }

    /// Filled, with points outside the grid reported as `None`.
    fn filled_at(&self, p: [i64; 3]) -> Option<bool> {
        let inside = (0..3).all(|d| p[d] >= 0 && (p[d] as usize) < self.dims[d]);
        inside.then(|| self.filled(p.map(|c| c as usize)))
    }

    /// The far end of an edge.
    pub fn upper(key: Key) -> [usize; 3] {
        let mut q = [key[0], key[1], key[2]];
        q[key[3]] += 1;
        q
    }

    /// Whether a grid edge joins a filled end to an empty one.
    pub fn occupied(&self, key: Key) -> bool {
        self.filled([key[0], key[1], key[2]]) != self.filled(Self::upper(key))
    }

    /// A vertex's position before rounding to `f32`: world units, or sample indices when
    /// `voxels` is set.
    pub fn exact_position(&self, key: Key, voxels: bool) -> [f64; 3] {
        let t = self.crossing(key);
        std::array::from_fn(|d| {
            let c = key[d] as f64 + if d == key[3] { t } else { 0.0 };
            if voxels {
                c
            } else {
                self.origin[d] + c * self.spacing[d]
            }
        })
    }

    /// SPEC §1's crossing along an edge: `t = (iso − a) / (b − a)` clamped to
    /// `[1/1024, 1 − 1/1024]`, `1/2` at a NaN end.
    fn crossing(&self, key: Key) -> f64 {
        let (a, b) = (
            self.value([key[0], key[1], key[2]]),
            self.value(Self::upper(key)),
        );
        if a.is_nan() || b.is_nan() {
            0.5
        } else {
            let t = (self.iso - a) / (b - a);
            if t.is_finite() {
                t.clamp(1.0 / 1024.0, 1.0 - 1.0 / 1024.0)
            } else {
                0.5
            }
        }
    }

    /// SPEC §1's vertex: `t = (iso − a) / (b − a)` clamped to `[1/1024, 1 − 1/1024]`, `1/2` at a NaN
    /// end; world position `index × spacing + origin`, rounded once to `f32`.
    pub fn position(&self, key: Key) -> [f32; 3] {
        self.exact_position(key, false).map(|c| c as f32)
    }

    /// All occupied grid edges, in key order. A grid with fewer than 2 samples along an axis has
    /// no cube, and so (issue 3) an empty mesh: no edge counts.
    pub fn occupied_edges(&self) -> Vec<Key> {
        let [nx, ny, nz] = self.dims;
        if self.cubes().is_empty() {
            return vec![];
        }
        let mut out = vec![];
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    for axis in 0..3 {
                        let key = [x, y, z, axis];
                        if Self::upper(key)[axis] < self.dims[axis] && self.occupied(key) {
                            out.push(key);
                        }
                    }
                }
            }
        }
        out
    }

    /// The case of cube `(i, j, k)`: bit `c` set iff corner `c` is filled.
    pub fn case(&self, cube: [usize; 3]) -> u8 {
        (0..8u8).fold(0, |case, c| {
            let p = [0, 1, 2].map(|d| cube[d] + usize::from(c >> d & 1));
            case | u8::from(self.filled(p)) << c
        })
    }

    /// Every cube of the grid, z slowest.
    pub fn cubes(&self) -> Vec<[usize; 3]> {
        let [nx, ny, nz] = self.dims;
        if nx < 2 || ny < 2 || nz < 2 {
            return vec![];
        }
        let mut out = vec![];
        for k in 0..nz - 1 {
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    out.push([i, j, k]);
                }
            }
        }
        out
    }
}

/// SPEC §2: whether a grid edge is grey, by global parity.
pub fn is_grey(key: Key) -> bool {
    let [l, m, n, axis] = key;
    match axis {
        0 => m % 2 == 1 && n % 2 == 1,
        1 => l % 2 == 1 && n % 2 == 0,
        _ => l % 2 == 0 && m % 2 == 0,
    }
}

/// The parity class of a cube.
pub fn class(cube: [usize; 3]) -> u8 {
    (cube[0] & 1 | (cube[1] & 1) << 1 | (cube[2] & 1) << 2) as u8
}

/// The global key of a cube-local edge.
pub fn global_edge(cube: [usize; 3], e: u8) -> Key {
    let [a, _] = edge_corners(e);
    [
        cube[0] + usize::from(a & 1),
        cube[1] + usize::from(a >> 1 & 1),
        cube[2] + usize::from(a >> 2 & 1),
        edge_axis(e),
    ]
}

/// The triangles and grey records a cube uses: the paper alternative where it exists and the
/// forced-fold rule is off.
pub fn entry_for(class: u8, case: u8, paper: bool) -> (&'static [[u8; 3]], &'static [Grey]) {
    let e: &'static Entry = tables().entry(class, case);
    match (&e.paper, paper) {
        (Some(p), true) => (&p.triangles, &p.grey),
        _ => (&e.triangles, &e.grey),
    }
}

/// The four cubes around a grid edge, if all lie inside the grid.
pub fn cubes_around(dims: [usize; 3], key: Key) -> Option<[[usize; 3]; 4]> {
    let [l, m, n, axis] = key;
    let p = [l, m, n];
    let [u, v] = match axis {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    };
    if p[u] == 0
        || p[v] == 0
        || p[u] + 1 >= dims[u]
        || p[v] + 1 >= dims[v]
        || p[axis] + 1 >= dims[axis]
    {
        return None;
    }
    let mut out = [p; 4];
    for (i, c) in out.iter_mut().enumerate() {
        c[u] -= 1 - (i & 1);
        c[v] -= 1 - (i >> 1);
    }
    Some(out)
}

/// SPEC §5 (b): whether the lower end `p` of a grey edge along `axis` is a pinch.
///
/// In a face with corner `P`, neighbours `A`, `B` and diagonal `D`, `P` is cut off iff `P ≠ A`,
/// `P ≠ B` and `P` or `D` is filled. x/y-greys test the four faces of the plane `z = n` at `P`,
/// z-greys the eight vertical ones. A face outside the grid cannot cut `P` off. Without
/// `diagonal_clause`, the `P or D filled` part is dropped ([`Rules::z_pinch_six_neighbours`]).
pub fn is_pinch_with(field: &Field, p: [usize; 3], axis: usize, diagonal_clause: bool) -> bool {
    let planes: &[[usize; 2]] = if axis == 2 {
        &[[1, 2], [0, 2]]
    } else {
        &[[0, 1]]
    };
    let at = |q: [usize; 3], du: (usize, i64), dv: (usize, i64)| {
        let mut r = q.map(|c| c as i64);
        r[du.0] += du.1;
        r[dv.0] += dv.1;
        field.filled_at(r)
    };
    let fp = field.filled(p);
    for &[u, v] in planes {
        for su in [-1i64, 1] {
            for sv in [-1i64, 1] {
                let a = at(p, (u, su), (v, 0));
                let b = at(p, (u, 0), (v, sv));
                let d = at(p, (u, su), (v, sv));
                let (Some(a), Some(b), Some(d)) = (a, b, d) else {
                    return false;
                };
                let cut = fp != a && fp != b && (fp || d || !diagonal_clause);
                if !cut {
                    return false;
                }
            }
        }
    }
    true
}

/// The reference's output: triangles over edge keys, the surviving vertices' positions, and the
/// SPEC §6 counts.
#[derive(Clone, Debug, Default)]
pub struct RefMesh {
    /// Surviving vertices: every key some triangle uses.
    pub positions: BTreeMap<Key, [f32; 3]>,
    /// Triangles, wound as the tables wind them.
    pub triangles: Vec<[Key; 3]>,
    /// Occupied grid edges.
    pub v13: u64,
    /// Triangles of Steps 1–3 (with the triangulation this mode uses).
    pub t13: u64,
    /// Merged grey edges.
    pub merged: u64,
    /// Occupied interior grey edges left alone by the rules.
    pub blocked: u64,
    /// Of those, the ones only the error bound left alone.
    pub bounded: u64,
    /// The merged grey edges themselves.
    pub merged_keys: BTreeSet<Key>,
}

impl RefMesh {
    /// The mesh as an indexed triangle list (vertices in key order), for the topology and
    /// self-intersection checks.
    pub fn indexed(&self) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
        let index: HashMap<Key, u32> = self
            .positions
            .keys()
            .enumerate()
            .map(|(i, k)| (*k, i as u32))
            .collect();
        (
            self.positions.values().copied().collect(),
            self.triangles
                .iter()
                .map(|t| t.map(|k| index[&k]))
                .collect(),
        )
    }
}

/// Runs Steps 1–4 on `field` in `mode`.
pub fn extract(field: &Field, mode: RefMode) -> RefMesh {
    extract_bounded(field, mode, None)
}

/// Runs Steps 1–4 with an error bound: a grey edge merges only if its vertex lies closer than
/// `bound` to the two triangles replacing its ears, and the new diagonal's quarter points and
/// middle closer than `bound` to the ears, measured on world positions, or on index positions
/// when `voxels` is set.
pub fn extract_bounded(field: &Field, mode: RefMode, bound: Option<(f64, bool)>) -> RefMesh {
    let (merging, rules) = match mode {
        RefMode::Steps123 => (false, Rules::EMBEDDED),
        RefMode::Merge(r) => (true, r),
    };
    let paper_tables = merging && !rules.forced_fold;
    let mut out = RefMesh::default();

    // Steps 1–3: per cube, its entry's triangles over global edge keys.
    let mut per_cube: HashMap<[usize; 3], Vec<Option<[Key; 3]>>> = HashMap::new();
    let mut order: Vec<[usize; 3]> = vec![];
    for cube in field.cubes() {
        let case = field.case(cube);
        let (tris, _) = entry_for(class(cube), case, paper_tables);
        if tris.is_empty() {
            continue;
        }
        out.t13 += tris.len() as u64;
        let tris = tris
            .iter()
            .map(|t| Some(t.map(|e| global_edge(cube, e))))
            .collect();
        per_cube.insert(cube, tris);
        order.push(cube);
    }
    let occupied = field.occupied_edges();
    out.v13 = occupied.len() as u64;

    // Step 4: per occupied interior grey edge, decide and replace the four ears.
    let mut extra: Vec<[Key; 3]> = vec![];
    for &key in occupied.iter().filter(|&&k| merging && is_grey(k)) {
        let Some(cubes) = cubes_around(field.dims, key) else {
            continue;
        };
        let axis = key[3];
        let mergeable = !rules.forced_fold
            || cubes.iter().all(|&c| {
                let (_, greys) = entry_for(class(c), field.case(c), false);
                let local = greys
                    .iter()
                    .find(|g| global_edge(c, g.edge) == key)
                    .expect("an occupied grey edge has a grey record in each of its cubes");
                local.mergeable
            });
        let diagonal_clause = !(axis == 2 && rules.z_pinch_six_neighbours);
        let pinch =
            rules.pinch && is_pinch_with(field, [key[0], key[1], key[2]], axis, diagonal_clause);
        if !mergeable || pinch {
            out.blocked += 1;
            continue;
        }
        // The ears: in each cube, the only triangle touching the grey vertex.
        let mut ring: HashMap<Key, Key> = HashMap::new();
        let mut ears = vec![];
        for c in cubes {
            let tris = &per_cube[&c];
            let touching: Vec<usize> = (0..tris.len())
                .filter(|&i| tris[i].is_some_and(|t| t.contains(&key)))
                .collect();
            assert_eq!(
                touching.len(),
                1,
                "grey edge {key:?} has no single ear in cube {c:?}"
            );
            ears.push((c, touching[0]));
            let t = tris[touching[0]].expect("present");
            let r = t.iter().position(|&k| k == key).expect("contains");
            let (a, b) = (t[(r + 1) % 3], t[(r + 2) % 3]);
            assert!(
                ring.insert(a, b).is_none(),
                "ears around {key:?} do not chain"
            );
        }
        // The quad q0 → q1 → q2 → q3, in the ears' orientation.
        let q0 = *ring.keys().min().expect("four ears");
        let mut quad = vec![q0];
        while quad.len() < 4 {
            quad.push(ring[quad.last().expect("non-empty")]);
        }
        assert_eq!(
            ring[&quad[3]], q0,
            "ears around {key:?} do not close a quad"
        );
        // The diagonal's plane: z = n for x/y-greys; x = l or y = m (by layer) for z-greys.
        let [l, m, n, _] = key;
        let in_plane = |q: Key| -> bool {
            match axis {
                0 | 1 => q[3] != 2 && q[2] == n,
                _ => {
                    let use_y = if rules.alternate_z {
                        n % 2 == 1
                    } else {
                        rules.fixed_z_in_y
                    };
                    if use_y {
                        q[3] != 1 && q[1] == m
                    } else {
                        q[3] != 0 && q[0] == l
                    }
                }
            }
        };
        let on: Vec<usize> = (0..4).filter(|&i| in_plane(quad[i])).collect();
        assert!(
            on.len() == 2 && on[1] - on[0] == 2,
            "quad around {key:?} does not have two opposite corners in the diagonal's plane: {quad:?}"
        );
        let s = on[0];
        let q = |i: usize| quad[(s + i) % 4];
        let replacing = [[q(0), q(1), q(2)], [q(0), q(2), q(3)]];
        if let Some((limit, voxels)) = bound {
            let at = |k: Key| field.exact_position(k, voxels);
            let g = at(key);
            // The removed vertex near the new triangles, and the new diagonal q0–q2 (at its
            // quarter points and middle) near the old ones.
            let fan: Vec<[[f64; 3]; 3]> = ring.iter().map(|(&a, &b)| [g, at(a), at(b)]).collect();
            let (d0, d2) = (at(q(0)), at(q(2)));
            let diagonal_close = [0.25, 0.5, 0.75].iter().all(|&t| {
                let m: [f64; 3] = std::array::from_fn(|d| d0[d] + t * (d2[d] - d0[d]));
                fan.iter().any(|&f| point_triangle_distance(m, f) < limit)
            });
            let close = diagonal_close
                && replacing
                    .iter()
                    .all(|t| point_triangle_distance(g, t.map(at)) < limit);
            if !close {
                out.blocked += 1;
                out.bounded += 1;
                continue;
            }
        }
        out.merged += 1;
        out.merged_keys.insert(key);
        for (c, i) in ears {
            per_cube.get_mut(&c).expect("cube")[i] = None;
        }
        extra.extend(replacing);
    }

    for cube in order {
        out.triangles
            .extend(per_cube[&cube].iter().flatten().copied());
    }
    out.triangles.extend(extra);
    for t in &out.triangles {
        for &k in t {
            out.positions.entry(k).or_insert_with(|| field.position(k));
        }
    }
    out
}

/// A triangle rotated so its smallest key comes first: equal for equal oriented triangles.
pub fn canonical(t: [Key; 3]) -> [Key; 3] {
    let r = (0..3).min_by_key(|&i| t[i]).expect("three");
    [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
}
