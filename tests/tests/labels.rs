//! Label volumes (docs/labels.md): every labelling of a cube, checked against a reference face
//! rule written here; random and structured volumes checked whole, per label (closed,
//! oriented, embedded, separating); two-label volumes against the binary engine.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use sc_runtime::labels::{
    Atlas, FACES, Junction, Kind, LabelParams, Local, MAX_TRIANGLES, classify, corner_edge,
    extract_labels, junction,
};
use sc_runtime::{Mode, Params, Volume};
use sc_tests::geometry::{signed_volume, winding_and_distance};
use sc_tests::self_intersect::self_intersections;
use sc_tests::topology::manifold_problems;
use sc_tests::volumes::splitmix;

/// The modes a label volume has: every one but adaptive, which `extract_labels` refuses
/// (tests/adaptive.rs).
const MODES: [Mode; 3] = [Mode::Embedded, Mode::Paper, Mode::Steps123];

/// Every ordered labelling of a cube's corners: each set partition of the eight corners (as a
/// restricted growth string), with every order of its blocks. 545,835 in all.
fn labellings(mut visit: impl FnMut(&[u8; 8])) {
    fn blocks(prefix: &mut Vec<u8>, top: u8, out: &mut Vec<[u8; 8]>) {
        if prefix.len() == 8 {
            out.push(prefix.as_slice().try_into().unwrap());
            return;
        }
        for v in 0..=top + 1 {
            prefix.push(v);
            blocks(prefix, top.max(v), out);
            prefix.pop();
        }
    }
    let mut partitions = vec![];
    blocks(&mut vec![0], 0, &mut partitions);
    for p in partitions {
        let k = usize::from(*p.iter().max().unwrap()) + 1;
        let mut order: Vec<u8> = (0..k as u8).collect();
        permutations(&mut order, 0, &mut |order| {
            visit(&p.map(|b| order[usize::from(b)]))
        });
    }
}

fn permutations(items: &mut Vec<u8>, at: usize, visit: &mut impl FnMut(&[u8])) {
    if at == items.len() {
        visit(items);
        return;
    }
    for i in at..items.len() {
        items.swap(at, i);
        permutations(items, at + 1, visit);
        items.swap(at, i);
    }
}

/// A side's two nodes and the two labels it separates, each pair ascending.
type Side = ([u8; 2], [u8; 2]);

/// The reference face rule: which of a face's four positions share a piece, and the sides as
/// pairs of nodes (`0..12` an edge, `12 + f` a face centre), each with its two labels.
fn reference_face(f: usize, l: [u8; 4]) -> (Vec<Vec<usize>>, Vec<Side>) {
    let face = FACES[f];
    let distinct: BTreeSet<u8> = l.iter().copied().collect();
    let node = |i: usize| corner_edge(face[i % 4], face[(i + 1) % 4]);
    let connector = match distinct.len() {
        1 => return (vec![vec![0, 1, 2, 3]], vec![]),
        2 => Some(*distinct.first().unwrap()),
        3 if l[0] == l[2] => Some(l[0]),
        3 if l[1] == l[3] => Some(l[1]),
        _ => None,
    };
    let mut pieces = vec![];
    let mut sides = vec![];
    match connector {
        Some(w) => {
            pieces.push((0..4).filter(|&i| l[i] == w).collect());
            for i in 0..4 {
                if l[i] != w && l[(i + 3) % 4] != l[i] {
                    let run: Vec<usize> = (i..i + 4)
                        .take_while(|&j| l[j % 4] == l[i])
                        .map(|j| j % 4)
                        .collect();
                    let last = i + run.len() - 1;
                    let mut ends = [node(i + 3), node(last)];
                    ends.sort();
                    let mut pair = [l[i], w];
                    pair.sort();
                    sides.push((ends, pair));
                    pieces.push(run);
                }
            }
        }
        None => {
            for i in 0..4 {
                if l[(i + 3) % 4] != l[i] {
                    pieces.push(
                        (i..i + 4)
                            .take_while(|&j| l[j % 4] == l[i])
                            .map(|j| j % 4)
                            .collect(),
                    );
                }
                if l[i] != l[(i + 1) % 4] {
                    let mut pair = [l[i], l[(i + 1) % 4]];
                    pair.sort();
                    sides.push(([node(i), 12 + f as u8], pair));
                }
            }
        }
    }
    for p in &mut pieces {
        p.sort();
    }
    pieces.sort();
    (pieces, sides)
}

fn node_of(v: Local) -> Option<u8> {
    match v {
        Local::Edge(e) => Some(e),
        Local::Face(f) => Some(12 + f),
        _ => None,
    }
}

/// Whether the segment between two vertices lies on the cube's surface.
fn on_surface(a: Local, b: Local) -> bool {
    let (p, q) = (a.quarters(), b.quarters());
    (0..3).any(|k| p[k] == q[k] && (p[k] == 0 || p[k] == 4))
}

/// Checks one junction cube: per label, its triangles (turned to face away from it) are a
/// surface whose interior edges are used twice in opposite directions, whose border is exactly
/// the reference sides around the label's regions, and whose every vertex has one fan.
fn check_junction(labels: &[u8; 8], built: &Junction) -> Result<(), String> {
    if built.len > MAX_TRIANGLES {
        return Err(format!("{} triangles", built.len));
    }
    let mut sides: BTreeMap<[u8; 2], BTreeSet<u8>> = BTreeMap::new();
    for (f, face) in FACES.iter().enumerate() {
        for (ends, pair) in reference_face(f, face.map(|c| labels[usize::from(c)])).1 {
            sides.entry(ends).or_default().extend(pair);
        }
    }
    for n in 0..built.len {
        let q = built.triangles[n].map(Local::quarters);
        let u = [0, 1, 2].map(|k| q[1][k] - q[0][k]);
        let w = [0, 1, 2].map(|k| q[2][k] - q[0][k]);
        let cross = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        if cross == [0; 3] {
            return Err(format!("triangle {n} is flat"));
        }
        let [a, b] = built.pairs[n].map(|c| labels[usize::from(c)]);
        if a == b {
            return Err(format!("triangle {n} has both sides {a}"));
        }
    }
    let present: BTreeSet<u8> = labels.iter().copied().collect();
    for &label in &present {
        let mut tris = vec![];
        for n in 0..built.len {
            let [a, b] = built.pairs[n].map(|c| labels[usize::from(c)]);
            let t = built.triangles[n];
            if a == label {
                tris.push(t);
            } else if b == label {
                tris.push([t[0], t[2], t[1]]);
            }
        }
        let mut directed: HashMap<(Local, Local), usize> = HashMap::new();
        for t in &tris {
            for i in 0..3 {
                *directed.entry((t[i], t[(i + 1) % 3])).or_default() += 1;
            }
        }
        let mut border = BTreeSet::new();
        for (&(a, b), &n) in &directed {
            let back = directed.get(&(b, a)).copied().unwrap_or(0);
            if on_surface(a, b) {
                if n != 1 || back != 0 {
                    return Err(format!(
                        "label {label}: surface edge {a:?}-{b:?} used {n}+{back}"
                    ));
                }
                let (Some(p), Some(q)) = (node_of(a), node_of(b)) else {
                    return Err(format!(
                        "label {label}: surface edge {a:?}-{b:?} off the nodes"
                    ));
                };
                border.insert([p.min(q), p.max(q)]);
            } else if n != 1 || back != 1 {
                return Err(format!(
                    "label {label}: inner edge {a:?}-{b:?} used {n}+{back}"
                ));
            }
        }
        let expected: BTreeSet<[u8; 2]> = sides
            .iter()
            .filter(|(_, pair)| pair.contains(&label))
            .map(|(ends, _)| *ends)
            .collect();
        if border != expected {
            return Err(format!(
                "label {label}: border {border:?}, sides {expected:?}"
            ));
        }
        // One fan per vertex: its triangles' far edges chain into one path or cycle.
        let mut fans: HashMap<Local, Vec<(Local, Local)>> = HashMap::new();
        for t in &tris {
            for i in 0..3 {
                fans.entry(t[i])
                    .or_default()
                    .push((t[(i + 1) % 3], t[(i + 2) % 3]));
            }
        }
        for (v, edges) in fans {
            let next: HashMap<Local, Local> = edges.iter().copied().collect();
            let prev: HashMap<Local, Local> = edges.iter().map(|&(a, b)| (b, a)).collect();
            let start = edges
                .iter()
                .map(|e| e.0)
                .find(|a| !prev.contains_key(a))
                .unwrap_or(edges[0].0);
            let (mut at, mut walked) = (start, 0);
            while let Some(&to) = next.get(&at) {
                walked += 1;
                at = to;
                if at == start || walked > edges.len() {
                    break;
                }
            }
            if walked != edges.len() {
                return Err(format!("label {label}: vertex {v:?} has more than one fan"));
            }
        }
    }
    Ok(())
}

/// Every labelling of a cube: a binary cube splits every face as its binary case does (its
/// background's runs held together), and a junction cube's construction passes
/// [`check_junction`] for every label.
#[test]
fn every_labelling_of_a_cube() {
    let mut counts = BTreeMap::new();
    let mut built = Junction::default();
    let mut failures = vec![];
    labellings(|labels| {
        let kind = classify(labels);
        let name = match kind {
            Kind::Uniform => "uniform",
            Kind::Binary { background, case } => {
                let w = labels[usize::from(background)];
                let binary = labels.map(|l| u8::from(l != w));
                for (c, &bit) in binary.iter().enumerate() {
                    assert_eq!(case >> c & 1, bit, "{labels:?}: case {case}");
                }
                for (f, face) in FACES.iter().enumerate() {
                    let quad = |l: &[u8; 8]| face.map(|c| l[usize::from(c)]);
                    let (label_pieces, _) = reference_face(f, quad(labels));
                    let (binary_pieces, _) = reference_face(f, quad(&binary));
                    assert_eq!(
                        label_pieces, binary_pieces,
                        "{labels:?}: face {f} against case {case}"
                    );
                }
                "binary"
            }
            Kind::Junction => {
                junction(labels, &mut built);
                if let Err(e) = check_junction(labels, &built)
                    && failures.len() < 10
                {
                    failures.push(format!("{labels:?}: {e}"));
                }
                if built.triangles[..built.len]
                    .iter()
                    .flatten()
                    .any(|v| *v == Local::Centre)
                {
                    "cone"
                } else {
                    "hub"
                }
            }
        };
        *counts.entry(name).or_insert(0usize) += 1;
    });
    assert!(failures.is_empty(), "{failures:#?}");
    assert_eq!(counts.values().sum::<usize>(), 545_835);
    assert_eq!(counts["uniform"], 1);
    // Every two-label labelling (127 partitions in two blocks, both orders) is binary.
    assert!(counts["binary"] >= 254, "{counts:?}");
    eprintln!("{counts:?}");
}

/// A label volume for the whole-mesh checks.
struct Labels {
    data: Vec<u16>,
    dims: [usize; 3],
}

impl Labels {
    fn at(&self, p: [usize; 3]) -> u16 {
        self.data[p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])]
    }

    fn atlas(&self, mode: Mode) -> Atlas<u16> {
        let params = LabelParams {
            mode,
            spacing: [1.0, 1.25, 0.75],
            origin: [-2.0, 1.0, 0.5],
            ..LabelParams::default()
        };
        extract_labels(Volume::new(&self.data, self.dims).unwrap(), &params).unwrap()
    }

    fn world(&self, p: [usize; 3]) -> [f64; 3] {
        [
            -2.0 + p[0] as f64,
            1.0 + 1.25 * p[1] as f64,
            0.5 + 0.75 * p[2] as f64,
        ]
    }
}

/// Independent labels per sample: the most junctions a volume can have.
fn noise(dims: [usize; 3], labels: u64, seed: u64) -> Labels {
    let n = dims.iter().product::<usize>();
    let data = (0..n)
        .map(|i| (splitmix(seed * 1_000_003 + i as u64) % labels) as u16)
        .collect();
    Labels { data, dims }
}

/// Voronoi cells of a few random seeds, with some cells given the background: regions large
/// enough for Step 4 to merge, with junction curves between them.
fn cells(dims: [usize; 3], count: u64, seed: u64) -> Labels {
    let seeds: Vec<[f64; 3]> = (0..count)
        .map(|s| {
            [0, 1, 2].map(|a| {
                (splitmix(seed * 7919 + s * 3 + a as u64) % 10_000) as f64 / 10_000.0
                    * dims[a] as f64
            })
        })
        .collect();
    let mut data = vec![];
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let p = [x as f64, y as f64, z as f64];
                let d = |s: &[f64; 3]| (0..3).map(|a| (s[a] - p[a]).powi(2)).sum::<f64>();
                let best = (0..seeds.len())
                    .min_by(|&a, &b| d(&seeds[a]).total_cmp(&d(&seeds[b])))
                    .unwrap();
                data.push(if best % 4 == 3 { 0 } else { 1 + best as u16 });
            }
        }
    }
    Labels { data, dims }
}

/// Every label's mesh is closed, oriented outward and manifold; the atlas has no crossing
/// triangles; every sample is inside (or on) its own label's mesh and outside every other's.
/// Paper mode promises none of it (SPEC §5), so it is only checked for its pairs.
fn check_volume(vol: &Labels, mode: Mode, what: &str) {
    let atlas = vol.atlas(mode);
    for (t, pair) in atlas.triangles.iter().zip(&atlas.pairs) {
        assert_ne!(pair[0], pair[1], "{what}: triangle {t:?}");
    }
    if mode == Mode::Paper {
        return;
    }
    let crossings = self_intersections(&atlas.positions, &atlas.triangles);
    assert!(
        crossings.is_empty(),
        "{what} ({mode:?}): {} crossings, first {:?}",
        crossings.len(),
        &crossings[..crossings.len().min(4)]
    );
    let labels = atlas.labels(0);
    let meshes = atlas.meshes(&labels, false);
    let present: BTreeSet<u16> = vol.data.iter().copied().filter(|&l| l != 0).collect();
    assert_eq!(
        labels.iter().copied().collect::<BTreeSet<_>>(),
        present,
        "{what}"
    );
    for (label, mesh) in &meshes {
        let problems = manifold_problems(mesh.positions.len(), &mesh.triangles, 5);
        assert!(
            problems.is_empty(),
            "{what} ({mode:?}) label {label}: {problems:?}"
        );
        assert!(
            signed_volume(&mesh.positions, &mesh.triangles) > 0.0,
            "{what} label {label}"
        );
    }
    let [nx, ny, nz] = vol.dims;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let p = [x, y, z];
                let own = vol.at(p);
                let w = vol.world(p);
                for (label, mesh) in &meshes {
                    let (winding, distance) =
                        winding_and_distance(w, &mesh.positions, &mesh.triangles);
                    let on = distance < 1e-6;
                    if *label == own {
                        assert!(
                            on || (winding - 1.0).abs() < 1e-6,
                            "{what} ({mode:?}): sample {p:?} of {own} has winding {winding} in its own mesh"
                        );
                    } else {
                        assert!(
                            on || winding.abs() < 1e-6,
                            "{what} ({mode:?}): sample {p:?} of {own} is inside label {label} (winding {winding})"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn noise_volumes_are_closed_embedded_and_separating() {
    for seed in 0..12 {
        for labels in [3, 4, 6] {
            for mode in MODES {
                check_volume(
                    &noise([6, 5, 5], labels, seed),
                    mode,
                    &format!("noise {labels} labels, seed {seed}"),
                );
            }
        }
    }
}

#[test]
fn voronoi_cells_are_closed_embedded_and_separating() {
    for seed in 0..4 {
        for mode in MODES {
            check_volume(
                &cells([14, 12, 11], 9, seed),
                mode,
                &format!("cells, seed {seed}"),
            );
        }
    }
    // Tall enough for three pieces of the sweep, joined.
    check_volume(&cells([7, 6, 40], 8, 5), Mode::Embedded, "tall cells");
}

/// With one region and the background, the atlas is the binary engine's mesh of the region's
/// indicator on the padded grid, triangle for triangle.
#[test]
fn two_labels_are_the_binary_mesh() {
    for seed in 0..6 {
        let vol = cells([12, 11, 10], 5, seed);
        let data: Vec<u16> = vol.data.iter().map(|&l| u16::from(l % 2 == 1)).collect();
        let two = Labels {
            data,
            dims: vol.dims,
        };
        for mode in MODES {
            let atlas = two.atlas(mode);
            let [nx, ny, nz] = two.dims;
            let pd = [nx + 2, ny + 2, nz + 2];
            let mut padded = vec![0f32; pd.iter().product()];
            for z in 0..nz {
                for y in 0..ny {
                    for x in 0..nx {
                        padded[(x + 1) + pd[0] * ((y + 1) + pd[1] * (z + 1))] =
                            f32::from(two.at([x, y, z]));
                    }
                }
            }
            let params = Params {
                mode,
                normals: false,
                spacing: [1.0, 1.25, 0.75],
                origin: [-3.0, -0.25, -0.25],
                ..Params::new(0.5)
            };
            let mesh = sc_runtime::extract(&Volume::new(&padded, pd).unwrap(), &params).unwrap();
            let canonical = |positions: &[[f32; 3]], tris: &[[u32; 3]]| {
                let mut out: Vec<[[u32; 3]; 3]> = tris
                    .iter()
                    .map(|t| {
                        let p = t.map(|v| positions[v as usize].map(f32::to_bits));
                        let r = (0..3).min_by_key(|&i| p[i]).unwrap();
                        [p[r], p[(r + 1) % 3], p[(r + 2) % 3]]
                    })
                    .collect();
                out.sort();
                out
            };
            assert!(atlas.pairs.iter().all(|&p| p == [1, 0]), "seed {seed}");
            assert_eq!(
                canonical(&atlas.positions, &atlas.triangles),
                canonical(&mesh.positions, &mesh.triangles),
                "seed {seed}, {mode:?}"
            );
            assert_eq!(
                atlas.stats.merged, mesh.stats.merged,
                "seed {seed}, {mode:?}"
            );
        }
    }
}

/// The sweep runs in pieces of layers on threads: the atlas is the same, vertex for vertex, for
/// any number of threads, and the same as one piece per layer would make it.
#[test]
fn any_thread_count_gives_the_same_atlas() {
    let vol = cells([9, 8, 53], 14, 7);
    let volume = Volume::new(&vol.data, vol.dims).unwrap();
    let atlas = |threads| {
        extract_labels(
            volume,
            &LabelParams {
                threads,
                ..LabelParams::default()
            },
        )
        .unwrap()
    };
    let one = atlas(1);
    assert!(one.stats.merged > 0 && one.triangles.len() > 1000);
    for threads in [2, 3, 0] {
        assert_eq!(atlas(threads), one, "{threads} threads");
    }
}
