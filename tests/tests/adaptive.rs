//! Adaptive mode (docs/adaptive.md) on padded volumes: built-in, real crops and random noise.
//!
//! Each mesh is checked against the Steps 1–3 mesh of the same volume:
//! - a closed, consistently oriented 2-manifold, no self-intersections (exact predicates);
//! - every vertex a Steps 1–3 vertex (same position and normal bits);
//! - every point of each mesh within the error bound of the other: sampled on a lattice of each
//!   triangle that differs, against every triangle of the other mesh;
//! - no sample on the wrong side: the two meshes differ by closed surfaces (each box's new patch
//!   against its old one), and a sample changes side iff its winding number about them is ±1,
//!   counted exactly by the crossings of a ray along x (a sample on the surface is on neither
//!   side), and `sc_io::separation`'s count of them, which `--stats-json` reports, agrees.

use std::collections::{HashMap, HashSet};

use sc_io::separation;
use sc_runtime::labels::{LabelParams, extract_labels};
use sc_runtime::{
    Error, ErrorBound, Mesh, Mode, Params, Volume, block_samples, demo, extract, extract_par,
};
use sc_tests::checks::{assert_closed_manifold, assert_no_self_intersections};
use sc_tests::geometry::{RowWinding, point_triangle_distance};
use sc_tests::volumes::{
    self, Sample, Vol, brainsmall_crop, integer_noise, itk_t1_crop, stent_crop,
};

type P = [f64; 3];

fn adaptive_params<T: Sample>(vol: &Vol<T>, bound: ErrorBound) -> Params {
    Params {
        max_error: Some(bound),
        ..vol.params(Mode::Adaptive)
    }
}

fn run<T: Sample>(vol: &Vol<T>, params: &Params) -> Mesh {
    let volume = Volume::new(&vol.data, vol.dims).unwrap();
    extract(&volume, params).expect("adaptive extraction succeeds")
}

/// A triangle's corners, as bits: equal triangles of the two meshes compare equal, whatever
/// their vertex ids, from any starting corner.
fn canonical(positions: &[[f32; 3]], t: [u32; 3]) -> [[u32; 3]; 3] {
    let c = t.map(|i| positions[i as usize].map(f32::to_bits));
    let r = (0..3).min_by_key(|&k| c[k]).unwrap();
    [c[r], c[(r + 1) % 3], c[(r + 2) % 3]]
}

fn corners(positions: &[[f32; 3]], t: [u32; 3]) -> [P; 3] {
    t.map(|i| positions[i as usize].map(f64::from))
}

/// Triangles of `mesh` bucketed by the cells of side `h` their boxes, grown by `reach`, touch:
/// a dense grid of cells over the grown boxes, `lo` its first cell.
struct Buckets {
    tris: Vec<[P; 3]>,
    h: f64,
    lo: [i64; 3],
    n: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl Buckets {
    fn new(mesh: &Mesh, h: f64, reach: f64) -> Self {
        let tris: Vec<[P; 3]> = mesh
            .triangles
            .iter()
            .map(|&t| corners(&mesh.positions, t))
            .collect();
        // Each triangle's cells, from its box grown by the reach.
        let span = |c: &[P; 3]| -> [[i64; 3]; 2] {
            let cell = |v: f64| (v / h).floor() as i64;
            let least = |d: usize| c.iter().map(|p| p[d]).fold(f64::INFINITY, f64::min);
            let most = |d: usize| c.iter().map(|p| p[d]).fold(f64::NEG_INFINITY, f64::max);
            [
                std::array::from_fn(|d| cell(least(d) - reach)),
                std::array::from_fn(|d| cell(most(d) + reach)),
            ]
        };
        let spans: Vec<[[i64; 3]; 2]> = tris.iter().map(span).collect();
        let lo: [i64; 3] =
            std::array::from_fn(|d| spans.iter().map(|s| s[0][d]).min().unwrap_or(0));
        let hi: [i64; 3] =
            std::array::from_fn(|d| spans.iter().map(|s| s[1][d]).max().unwrap_or(-1));
        let n: [usize; 3] = std::array::from_fn(|d| (hi[d] - lo[d] + 1).max(0) as usize);
        let mut cells = vec![Vec::new(); n.iter().product()];
        for (i, [a, b]) in spans.iter().enumerate() {
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    for x in a[0]..=b[0] {
                        let at = [x, y, z];
                        let k = (0..3)
                            .rev()
                            .fold(0, |k, d| k * n[d] + (at[d] - lo[d]) as usize);
                        cells[k].push(i as u32);
                    }
                }
            }
        }
        Buckets {
            tris,
            h,
            lo,
            n,
            cells,
        }
    }

    /// The distance from `p` to the mesh, if some triangle is within the reach and it exceeds
    /// `floor`; otherwise some value at most `floor`, found as soon as a triangle that near is:
    /// the largest of such distances over many points is their largest distance.
    fn distance_above(&self, p: P, floor: f64) -> f64 {
        let at: [i64; 3] = p.map(|c| (c / self.h).floor() as i64);
        let inside = (0..3).all(|d| at[d] >= self.lo[d] && at[d] - self.lo[d] < self.n[d] as i64);
        let cell: &[u32] = if inside {
            let k = (0..3)
                .rev()
                .fold(0, |k, d| k * self.n[d] + (at[d] - self.lo[d]) as usize);
            &self.cells[k]
        } else {
            &[]
        };
        let mut least = f64::INFINITY;
        for &i in cell {
            least = least.min(point_triangle_distance(p, self.tris[i as usize]));
            if least <= floor {
                break;
            }
        }
        least
    }
}

/// The largest distance from a lattice of `n` steps per side on each triangle of `from` that is
/// not in `to` (those in both are at distance 0) to the mesh `to`, or some value at most
/// `floor` when that is larger: no point's distance is sought below it.
fn one_way(from: &Mesh, to: &Mesh, reach: f64, n: usize, floor: f64) -> f64 {
    let shared: HashSet<[[u32; 3]; 3]> = to
        .triangles
        .iter()
        .map(|&t| canonical(&to.positions, t))
        .collect();
    // Cells as wide as the reach: each holds the triangles within reach of it, a few dozen.
    let buckets = Buckets::new(to, reach.max(0.25), reach);
    let mut worst: f64 = 0.0;
    for &t in &from.triangles {
        if shared.contains(&canonical(&from.positions, t)) {
            continue;
        }
        let [a, b, c] = corners(&from.positions, t);
        for i in 0..=n {
            for j in 0..=n - i {
                let (s, r) = (i as f64 / n as f64, j as f64 / n as f64);
                let p: P = std::array::from_fn(|d| a[d] + s * (b[d] - a[d]) + r * (c[d] - a[d]));
                worst = worst.max(buckets.distance_above(p, worst.max(floor)));
            }
        }
    }
    worst
}

/// Samples on the wrong side of `mesh`, given that `reference` (Steps 1–3) separates them all:
/// the triangles in one mesh and not the other form closed surfaces, one per connected piece,
/// and a sample inside one of them (winding number ±1) has changed side.
fn wrong_side<T: Sample>(vol: &Vol<T>, mesh: &Mesh, reference: &Mesh) -> usize {
    let mut count: HashMap<[[u32; 3]; 3], i32> = HashMap::new();
    for &t in &mesh.triangles {
        *count.entry(canonical(&mesh.positions, t)).or_default() += 1;
    }
    let mut diff: Vec<[P; 3]> = Vec::new();
    for &t in &reference.triangles {
        let k = canonical(&reference.positions, t);
        match count.get_mut(&k) {
            Some(c) if *c > 0 => *c -= 1,
            _ => {
                let [a, b, c] = corners(&reference.positions, t);
                diff.push([a, c, b]);
            }
        }
    }
    for &t in &mesh.triangles {
        let k = canonical(&mesh.positions, t);
        if let Some(c) = count.get_mut(&k)
            && *c > 0
        {
            *c -= 1;
            diff.push(corners(&mesh.positions, t));
        }
    }
    // Connected pieces, by shared corners.
    let key = |p: P| p.map(|c| (c as f32).to_bits());
    let mut parent: Vec<usize> = (0..diff.len()).collect();
    fn find(parent: &mut [usize], i: usize) -> usize {
        let mut r = i;
        while parent[r] != r {
            r = parent[r];
        }
        parent[i] = r;
        r
    }
    let mut first: HashMap<[u32; 3], usize> = HashMap::new();
    for (i, t) in diff.iter().enumerate() {
        for &p in t {
            let j = *first.entry(key(p)).or_insert(i);
            let (a, b) = (find(&mut parent, i), find(&mut parent, j));
            parent[a] = b;
        }
    }
    let mut pieces: HashMap<usize, Vec<usize>> = HashMap::new();
    for i in 0..diff.len() {
        let r = find(&mut parent, i);
        pieces.entry(r).or_default().push(i);
    }
    let mut wrong = 0;
    for tris in pieces.values() {
        let lo: P = std::array::from_fn(|d| {
            tris.iter()
                .flat_map(|&i| diff[i])
                .map(|p| p[d])
                .fold(f64::INFINITY, f64::min)
        });
        let hi: P = std::array::from_fn(|d| {
            tris.iter()
                .flat_map(|&i| diff[i])
                .map(|p| p[d])
                .fold(f64::NEG_INFINITY, f64::max)
        });
        let index = |w: f64, d: usize| (w - vol.origin[d]) / vol.spacing[d];
        let (a, b): ([usize; 3], [usize; 3]) = (
            std::array::from_fn(|d| index(lo[d], d).ceil().max(0.0) as usize),
            std::array::from_fn(|d| (index(hi[d], d).floor() as usize).min(vol.dims[d] - 1)),
        );
        // The piece's triangles by the rows of samples their y–z extent reaches (one row more
        // either way: rounding of the extent only adds candidates, which the ray test sorts).
        let mut rows: HashMap<[usize; 2], Vec<usize>> = HashMap::new();
        for &i in tris {
            let t = diff[i];
            let reach = |d: usize| {
                let (lo, hi) = t
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                        (l.min(p[d]), h.max(p[d]))
                    });
                let lo = (index(lo, d).floor() - 1.0).max(a[d] as f64) as usize;
                let hi = (index(hi, d).ceil() + 1.0).min(b[d] as f64) as usize;
                lo..=hi
            };
            for z in reach(2) {
                for y in reach(1) {
                    rows.entry([y, z]).or_default().push(i);
                }
            }
        }
        for ([y, z], near) in &rows {
            let [_, py, pz] = vol.world([0, *y, *z]);
            let row = RowWinding::new(py, pz, near.iter().map(|&i| &diff[i]));
            for x in a[0]..=b[0] {
                let p = vol.world([x, *y, *z]);
                // On the surface (for the moved line): on neither side, so not on the wrong one
                // (the Steps 1–3 surface passes through no sample).
                if row.at(p).is_some_and(|w| w != 0) {
                    wrong += 1;
                }
            }
        }
    }
    wrong
}

/// Every check on one padded volume at one bound (in grid steps); returns the triangle counts
/// (Steps 1–3, adaptive).
fn holds<T: Sample>(vol: &Vol<T>, bound: f64, what: &str) -> (usize, usize) {
    holds_with(vol, bound, FULL, what)
}

/// How closely [`holds_allowing`] looks: whether it checks the mesh is the same on threads, the
/// steps per side of the lattice on which it samples each triangle's distance, and whether it
/// finds the largest distance (printed) or only that none exceeds the bound.
#[derive(Clone, Copy)]
struct Effort {
    threads: bool,
    lattice: usize,
    exact_distance: bool,
}

/// For the volumes of the tests below but the exhaustive one.
const FULL: Effort = Effort {
    threads: true,
    lattice: 6,
    exact_distance: true,
};

/// For the exhaustive test's 8,820 volumes of a few hundred triangles each, whose triangles
/// are at most a box of two cubes across: corners, side midpoints and thirds, and centroids.
const LIGHT: Effort = Effort {
    threads: false,
    lattice: 3,
    exact_distance: false,
};

/// [`holds`], looking as closely as `effort` says.
fn holds_with<T: Sample>(vol: &Vol<T>, bound: f64, effort: Effort, what: &str) -> (usize, usize) {
    let (s123, ours, wrong) = holds_allowing(vol, bound, false, effort, what);
    assert_eq!(wrong, 0, "{what} at {bound} voxel");
    (s123, ours)
}

/// Every check of `holds` but separation, which `allow_wrong_side` waives; returns the triangle
/// counts (Steps 1–3, adaptive) and the samples on the wrong side.
fn holds_allowing<T: Sample>(
    vol: &Vol<T>,
    bound: f64,
    allow_wrong_side: bool,
    effort: Effort,
    what: &str,
) -> (usize, usize, usize) {
    let steps123 = vol.extract(Mode::Steps123);
    let params = Params {
        allow_wrong_side,
        ..adaptive_params(vol, ErrorBound::Voxels(bound))
    };
    let mesh = run(vol, &params);
    let what = format!("{what} at {bound} voxel, allow_wrong_side {allow_wrong_side}");
    // Its boxes shared out over threads, in ranges of some 64 boxes: the same mesh.
    let volume = Volume::new(&vol.data, vol.dims).unwrap();
    if effort.threads {
        assert_eq!(
            extract_par(&volume, &params, 3, &|_| {}).unwrap(),
            mesh,
            "{what}: 3 threads"
        );
    }
    assert_eq!(mesh.stats.t13, steps123.triangles.len() as u64, "{what}");
    assert_eq!(mesh.stats.triangles, mesh.triangles.len() as u64, "{what}");
    assert_eq!(mesh.stats.vertices, mesh.positions.len() as u64, "{what}");
    assert_closed_manifold(&mesh, &what);
    assert_no_self_intersections(&mesh, &what);
    // Every vertex is a Steps 1–3 vertex, with its normal.
    let old: HashMap<[u32; 3], [u32; 3]> = steps123
        .positions
        .iter()
        .zip(&steps123.normals)
        .map(|(p, n)| (p.map(f32::to_bits), n.map(f32::to_bits)))
        .collect();
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        assert_eq!(
            old.get(&p.map(f32::to_bits)),
            Some(&n.map(f32::to_bits)),
            "{what}: {p:?}"
        );
    }
    assert_eq!(mesh.normals.len(), mesh.positions.len());
    // The bound, both ways, in grid steps (unit spacing on the volumes here, or scaled).
    let least = vol.spacing.iter().copied().fold(f64::INFINITY, f64::min);
    let bound_world = bound * least;
    assert!(
        vol.spacing.iter().all(|&s| s == least),
        "{what}: isotropic volumes only"
    );
    let tol = 1e-4 * least;
    let floor = if effort.exact_distance {
        0.0
    } else {
        bound_world
    };
    let there = one_way(&mesh, &steps123, bound_world, effort.lattice, floor);
    let back = one_way(&steps123, &mesh, bound_world, effort.lattice, floor);
    assert!(
        there <= bound_world + tol,
        "{what}: adaptive → Steps 1–3 {there}"
    );
    assert!(
        back <= bound_world + tol,
        "{what}: Steps 1–3 → adaptive {back}"
    );
    let wrong = wrong_side(vol, &mesh, &steps123);
    // The figure `--stats-json` reports, by crossings of the mesh alone, agrees.
    assert_eq!(
        separation::wrong_side_samples(&volume, &params, &mesh),
        Some(wrong as u64),
        "{what}: wrong_side_samples"
    );
    if effort.exact_distance {
        println!(
            "{what}: Steps 1–3 {} triangles, adaptive {} ({:.2}×), {} vertices of {}; distance {:.3} / {:.3} voxel; {wrong} samples on the wrong side",
            steps123.triangles.len(),
            mesh.triangles.len(),
            steps123.triangles.len() as f64 / mesh.triangles.len().max(1) as f64,
            mesh.positions.len(),
            steps123.positions.len(),
            there / least,
            back / least,
        );
    }
    (steps123.triangles.len(), mesh.triangles.len(), wrong)
}

/// Waiving separation keeps every other check and saves triangles on the smooth demo volumes.
#[test]
fn allowing_wrong_side_holds_the_other_checks() {
    for (v, what) in [
        (demo::sphere(32), "sphere 32³"),
        (demo::torus(48), "torus 48³"),
    ] {
        let vol = volumes::demo(v);
        let (_, kept, _) = holds_allowing(&vol, 1.0, false, FULL, what);
        let (_, allowed, _) = holds_allowing(&vol, 1.0, true, FULL, what);
        assert!(allowed < kept, "{what}: {allowed} ≥ {kept}");
    }
    let b = brainsmall_crop().padded(0);
    holds_allowing(&b, 0.5, true, FULL, "brainsmall crop");
}

#[test]
fn demo_volumes_hold_every_check() {
    for (v, what) in [
        (demo::knot(64), "knot 64³"),
        (demo::torus(48), "torus 48³"),
        (demo::sphere_noise(40), "sphere 40³"),
    ] {
        let vol = volumes::demo(v);
        let mut last = usize::MAX;
        for bound in [0.0, 0.25, 0.5, 1.0] {
            let (s123, ours) = holds(&vol, bound, what);
            if bound == 0.0 {
                assert_eq!(ours, s123, "{what}: a zero bound keeps Steps 1–3");
            } else {
                assert!(ours < s123, "{what}: boxes at {bound} save triangles");
            }
            assert!(ours <= last, "{what}: a looser bound never adds triangles");
            last = ours;
        }
    }
}

#[test]
fn real_crops_hold_every_check() {
    let b = brainsmall_crop().padded(0);
    let s = stent_crop(281.0).padded(-2000);
    for bound in [0.5, 1.0] {
        holds(&b, bound, "brainsmall crop");
        holds(&s, bound, "stent crop");
    }
}

#[test]
fn random_noise_holds_every_check() {
    for seed in 0..12 {
        let vol = integer_noise([9, 8, 7], 4, seed);
        let padded = vol.padded(0);
        for iso in [1.0, 1.5, 2.0, 3.0] {
            let v = Vol {
                iso,
                ..padded.clone()
            };
            holds(&v, 0.75, &format!("noise seed {seed} iso {iso}"));
        }
    }
}

/// Smooth noise: values from a few random waves, where boxes are common and varied.
#[test]
fn smooth_noise_holds_every_check() {
    for seed in 0..6u64 {
        let r = |k: u64| (volumes::splitmix(seed * 16 + k) % 1000) as f64 / 1000.0;
        let (a, b, c, d) = (
            r(0) * 0.6 + 0.2,
            r(1) * 0.6 + 0.2,
            r(2) * 0.6 + 0.2,
            r(3) * 6.0,
        );
        let vol = volumes::sampled([18, 17, 16], 0.0, |x, y, z| {
            (a * x + d).sin() + (b * y).cos() + (c * z + a * y).sin() - 0.3
        });
        let padded = vol.padded(-10.0);
        holds(&padded, 0.5, &format!("waves seed {seed}"));
    }
}

/// The anisotropic crop in world units: closed, embedded, vertices from Steps 1–3, and the one
/// thread and the threaded entry point give the same mesh.
#[test]
fn anisotropic_crop_and_entry_points() {
    let vol = itk_t1_crop().padded(0);
    let params = adaptive_params(&vol, ErrorBound::World(1.0));
    let mesh = run(&vol, &params);
    assert_closed_manifold(&mesh, "itk crop");
    assert_no_self_intersections(&mesh, "itk crop");
    let steps123 = vol.extract(Mode::Steps123);
    assert!(mesh.triangles.len() < steps123.triangles.len());
    let volume = Volume::new(&vol.data, vol.dims).unwrap();
    assert_eq!(extract_par(&volume, &params, 2, &|_| {}).unwrap(), mesh);
    // No bound given: half the smallest spacing.
    let default = run(&vol, &vol.params(Mode::Adaptive));
    let half = run(&vol, &adaptive_params(&vol, ErrorBound::World(1.0)));
    assert_eq!(default, half);
}

#[test]
fn bad_options_are_refused() {
    let vol = volumes::demo(demo::torus(16));
    let volume = Volume::new(&vol.data, vol.dims).unwrap();
    let base = vol.params(Mode::Adaptive);
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        let p = Params {
            max_error: Some(ErrorBound::Voxels(bad)),
            ..base
        };
        assert_eq!(extract(&volume, &p), Err(Error::MaxError), "{bad}");
    }
    // 15 cubes along each axis: boxes up to 8.
    for (given, ok) in [
        (0, false),
        (1, true),
        (2, true),
        (3, false),
        (8, true),
        (12, false),
        (16, false),
    ] {
        let p = Params {
            max_box: Some(given),
            ..base
        };
        let got = extract(&volume, &p);
        assert_eq!(got.is_ok(), ok, "max_box {given}");
        if !ok {
            assert_eq!(got, Err(Error::MaxBox { given, largest: 8 }));
        }
    }
    // A box of one cube is Steps 1–3.
    let one = extract(
        &volume,
        &Params {
            max_box: Some(1),
            ..base
        },
    )
    .unwrap();
    assert_eq!(one.triangles, vol.extract(Mode::Steps123).triangles);
    // The box option needs adaptive mode; entry points without it refuse the mode.
    for p in [
        Params {
            max_box: Some(2),
            ..vol.params(Mode::Embedded)
        },
        Params {
            allow_wrong_side: true,
            ..vol.params(Mode::Steps123)
        },
    ] {
        assert!(matches!(
            extract(&volume, &p),
            Err(Error::NotAdaptive { .. })
        ));
    }
    let labels = [0u8, 1, 1, 0, 0, 1, 1, 0];
    let label_params = LabelParams {
        mode: Mode::Adaptive,
        ..LabelParams::default()
    };
    assert!(matches!(
        extract_labels(Volume::new(&labels, [2, 2, 2]).unwrap(), &label_params),
        Err(Error::NotAdaptive { .. })
    ));
    // Blocks check the box against the whole grid, and refuse it without adaptive mode.
    let cubes = [0..15, 0..15, 0..15];
    let wide = Params {
        max_box: Some(16),
        ..base
    };
    let too_wide = Error::MaxBox {
        given: 16,
        largest: 8,
    };
    let block = sc_runtime::extract_block(&volume, [0; 3], vol.dims, cubes.clone(), &wide);
    assert_eq!(block, Err(too_wide.clone()));
    assert_eq!(block_samples(vol.dims, cubes.clone(), &wide), Err(too_wide));
    let boxed = Params {
        max_box: Some(2),
        ..vol.params(Mode::Embedded)
    };
    assert!(matches!(
        block_samples(vol.dims, cubes, &boxed),
        Err(Error::NotAdaptive { .. })
    ));
}

/// Boxes larger than two cubes grow and are kept: on the torus, `max_box` 16 gives fewer
/// triangles than 2, and some triangle side is longer than any in a box of two cubes (its
/// diagonal, 2√3 grid steps). Every check of `holds` runs on this volume and bound above, with
/// `max_box` 16.
#[test]
fn larger_boxes_grow() {
    let vol = volumes::demo(demo::torus(48));
    let params = |max_box| Params {
        max_box: Some(max_box),
        ..adaptive_params(&vol, ErrorBound::Voxels(1.0))
    };
    let longest = |m: &Mesh| -> f64 {
        let grid = |i: u32| -> P {
            let p = m.positions[i as usize];
            std::array::from_fn(|d| (f64::from(p[d]) - vol.origin[d]) / vol.spacing[d])
        };
        m.triangles
            .iter()
            .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
            .map(|(a, b)| {
                let (a, b) = (grid(a), grid(b));
                (0..3).map(|d| (a[d] - b[d]).powi(2)).sum::<f64>().sqrt()
            })
            .fold(0.0, f64::max)
    };
    let (small, large) = (run(&vol, &params(2)), run(&vol, &params(16)));
    let diagonal = 2.0 * 3f64.sqrt();
    assert!(longest(&small) <= diagonal + 1e-4, "{}", longest(&small));
    assert!(longest(&large) > diagonal, "{}", longest(&large));
    assert!(large.triangles.len() < small.triangles.len());
    println!(
        "torus 48³ at 1 voxel: max_box 2 {} triangles, 16 {}",
        small.triangles.len(),
        large.triangles.len()
    );
}

/// The down-sets of the 3×3×3 sample block (filled at a sample means filled at every sample
/// below it on all three axes): the plane partitions in a 3×3×3 box, 980 of them, as heights
/// `h[x][y]` that never grow along x or y, filled iff `z < h[x][y]`.
fn down_sets() -> Vec<[[u8; 3]; 3]> {
    (0..4u32.pow(9))
        .map(|code| {
            std::array::from_fn(|x| std::array::from_fn(|y| (code >> (2 * (3 * x + y)) & 3) as u8))
        })
        .filter(|h: &[[u8; 3]; 3]| {
            (0..3).all(|x| {
                (0..3).all(|y| {
                    (x == 0 || h[x][y] <= h[x - 1][y]) && (y == 0 || h[x][y] <= h[x][y - 1])
                })
            })
        })
        .collect()
}

/// Every down-set sign pattern of a box of two cubes (docs/adaptive.md §11), in each of its 8
/// orientations with crossings at the midpoints, and in one of them (in turn) with crossings at
/// random places out to the clamp's limits: 8,820 volumes. Each pattern is a tile of two cubes
/// on the boxes' lattice, with its mirror images below it along each axis (each shared face the
/// same from both sides) and the empty border above, so the box meets boxes of its size or
/// larger on three sides and unit cubes on the other three, whatever each is accepted as. Every
/// check of `holds` runs on each. Two tests of four orientations each, which the two test
/// threads share.
#[test]
fn every_down_set_box_of_two_cubes_flips_0_to_3() {
    down_set_boxes(0..4);
}

#[test]
fn every_down_set_box_of_two_cubes_flips_4_to_7() {
    down_set_boxes(4..8);
}

/// The volumes of [`every_down_set_box_of_two_cubes_flips_0_to_3`] with orientations `flips`
/// (bit `d` mirrors axis `d`).
fn down_set_boxes(flips: std::ops::Range<usize>) {
    let sets = down_sets();
    assert_eq!(sets.len(), 980, "plane partitions in a 3×3×3 box");
    // The sample's place in its tile along one axis: the tile spans 4..=6, its mirror image
    // 2..=4; the rest is the empty border.
    let tile = |i: f64| -> Option<usize> {
        let i = i as usize;
        (2..=6).contains(&i).then(|| [2, 1, 0, 1, 2][i - 2])
    };
    let (mut volumes, mut fewer) = (0, 0);
    for (k, h) in sets.iter().enumerate() {
        for flip in flips.clone() {
            for random in [false, true] {
                if random && flip != k % 8 {
                    continue;
                }
                let seed = ((k * 8 + flip) * 2 + usize::from(random)) as u64;
                let vol = volumes::sampled([8, 8, 8], 0.0, |x, y, z| {
                    let filled = match [x, y, z].map(tile) {
                        [Some(a), Some(b), Some(c)] => {
                            let u = |d: usize, v: usize| if flip >> d & 1 == 1 { 2 - v } else { v };
                            u(2, c) < usize::from(h[u(0, a)][u(1, b)])
                        }
                        _ => false,
                    };
                    // Magnitudes from 10⁻³ to 1: crossings anywhere along their edges, out to
                    // the clamp near either sample.
                    let m = if random {
                        let at = (x + 8.0 * (y + 8.0 * z)) as u64;
                        match volumes::splitmix(seed * 4096 + at) % 1000 {
                            r if r < 100 => 1e-3,
                            r => r as f64 / 1000.0,
                        }
                    } else {
                        1.0
                    };
                    if filled { m } else { -m }
                });
                let what = format!("down-set {k} flip {flip} random {random}");
                let (s123, ours) = holds_with(&vol, 1.0, LIGHT, &what);
                volumes += 1;
                fewer += usize::from(ours < s123);
            }
        }
    }
    // Every pattern in each orientation, and those whose turn it is with random crossings.
    let turns = (0..980).filter(|k| flips.contains(&(k % 8))).count();
    assert_eq!(volumes, flips.len() * 980 + turns);
    // Boxes are accepted, so the test reaches them: most volumes have fewer triangles.
    assert!(
        fewer > volumes / 2,
        "boxes saved triangles in {fewer} of {volumes}"
    );
    println!("boxes saved triangles in {fewer} of {volumes} volumes");
}
