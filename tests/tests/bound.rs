//! The error bound on Step 4 (`Params::max_error`): the runtime agrees with the reference's
//! independent implementation of the rule, every removed vertex lies within the bound of the
//! final surface, the surface stays a closed embedded 2-manifold, the bound trades triangles
//! monotonically (zero merges nothing, a huge bound is the unbounded mode), and threads,
//! streaming and blocks give the same mesh with the bound as without.

use sc_runtime::{
    BlockMesh, ErrorBound, Mesh, Mode, Params, Volume, block_samples, demo, extract, extract_block,
    extract_par,
};
use sc_tests::checks::{assert_closed_manifold, assert_no_self_intersections, compare};
use sc_tests::geometry::point_triangle_distance;
use sc_tests::reference::{self, RefMode};
use sc_tests::volumes::{
    self, Sample, Vol, brainsmall_crop, integer_noise, itk_t1_crop, stent_crop,
};

const BOUNDS: [f64; 4] = [0.05, 0.1, 0.25, 0.5];

fn bounded<T: Sample>(vol: &Vol<T>, mode: Mode, bound: ErrorBound) -> Params {
    Params {
        max_error: Some(bound),
        ..vol.params(mode)
    }
}

fn run<T: Sample>(vol: &Vol<T>, params: &Params) -> Mesh {
    extract(&Volume::new(&vol.data, vol.dims).expect("v"), params).expect("extract")
}

/// The runtime equals the reference with the same bound, and every vertex the merges removed
/// lies closer than the bound to the final surface.
fn agrees_and_holds<T: Sample>(vol: &Vol<T>, what: &str) {
    let field = vol.field();
    for mode in [Mode::Embedded, Mode::Paper] {
        for b in BOUNDS {
            for (bound, voxels) in [(ErrorBound::Voxels(b), true), (ErrorBound::World(b), false)] {
                let mesh = run(vol, &bounded(vol, mode, bound));
                let r = reference::extract_bounded(&field, RefMode::of(mode), Some((b, voxels)));
                if let Err(e) = compare(&field, &mesh, &r) {
                    panic!("{what} {mode:?} {bound:?}: {e}");
                }
                assert!(r.merged > 0, "{what} {mode:?} {bound:?}: nothing merged");
                // Distances in the bound's own units.
                let scale = |p: [f32; 3]| -> [f64; 3] {
                    std::array::from_fn(|d| {
                        let c = f64::from(p[d]);
                        if voxels {
                            (c - vol.origin[d]) / vol.spacing[d]
                        } else {
                            c
                        }
                    })
                };
                let tris: Vec<[[f64; 3]; 3]> = mesh
                    .triangles
                    .iter()
                    .map(|t| t.map(|i| scale(mesh.positions[i as usize])))
                    .collect();
                // Triangles are shorter than a cube's diagonal: only those near `g` can be closest.
                let reach = b + if voxels {
                    3.0
                } else {
                    3.0 * vol.spacing.iter().copied().fold(0.0, f64::max)
                };
                for &key in &r.merged_keys {
                    let g = field.exact_position(key, voxels);
                    let d = tris
                        .iter()
                        .filter(|t| (0..3).all(|d| (t[0][d] - g[d]).abs() < reach))
                        .map(|&t| point_triangle_distance(g, t))
                        .fold(f64::INFINITY, f64::min);
                    // f32 positions: allow their rounding.
                    assert!(
                        d < b + 1e-4,
                        "{what} {mode:?} {bound:?}: {key:?} is {d} away"
                    );
                }
            }
        }
    }
}

#[test]
fn bounded_merges_match_the_reference_and_hold() {
    agrees_and_holds(&volumes::demo(demo::knot(40)), "knot");
    agrees_and_holds(&volumes::demo(demo::sphere_noise(24)), "noise");
    agrees_and_holds(&integer_noise([14, 13, 12], 3, 5), "integer ties");
    agrees_and_holds(&brainsmall_crop(), "brainsmall");
    agrees_and_holds(&stent_crop(250.0), "stent");
    agrees_and_holds(&itk_t1_crop(), "itk-t1 (anisotropic)");
}

#[test]
fn bounded_surfaces_stay_closed_and_embedded() {
    let vols: Vec<(&str, Vol<f64>)> = vec![
        ("knot", volumes::demo(demo::knot(48))),
        ("noise", volumes::demo(demo::sphere_noise(28))),
    ];
    for (what, vol) in &vols {
        for b in BOUNDS {
            let mesh = run(vol, &bounded(vol, Mode::Embedded, ErrorBound::Voxels(b)));
            let what = format!("{what} bound {b}");
            assert_closed_manifold(&mesh, &what);
            assert_no_self_intersections(&mesh, &what);
        }
    }
    for (what, vol) in [
        ("stent", stent_crop(281.0).padded(0)),
        ("itk-t1", itk_t1_crop().padded(0)),
    ] {
        for b in BOUNDS {
            let mesh = run(
                &vol,
                &bounded(&vol, Mode::Embedded, ErrorBound::World(b * 2.0)),
            );
            let what = format!("{what} bound {}", b * 2.0);
            assert_closed_manifold(&mesh, &what);
            assert_no_self_intersections(&mesh, &what);
        }
    }
}

#[test]
fn the_bound_trades_triangles_monotonically() {
    let vol = volumes::demo(demo::knot(48));
    let unbounded = run(&vol, &vol.params(Mode::Embedded));
    let zero = run(
        &vol,
        &bounded(&vol, Mode::Embedded, ErrorBound::Voxels(0.0)),
    );
    assert_eq!(zero.stats.merged, 0);
    assert_eq!(
        zero.stats.triangles, zero.stats.t13,
        "bound 0: Steps 1–3's count"
    );
    assert_eq!(zero.stats.bounded, unbounded.stats.merged);
    let huge = run(
        &vol,
        &bounded(&vol, Mode::Embedded, ErrorBound::Voxels(1e9)),
    );
    assert_eq!(
        huge.triangles, unbounded.triangles,
        "a huge bound changes nothing"
    );
    assert_eq!(huge.stats.bounded, 0);
    let mut last = zero.stats.triangles;
    for b in [0.01, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0] {
        let m = run(&vol, &bounded(&vol, Mode::Embedded, ErrorBound::Voxels(b)));
        assert!(
            m.stats.triangles <= last,
            "bound {b}: more triangles than a tighter bound"
        );
        assert_eq!(m.stats.merged + m.stats.bounded, unbounded.stats.merged);
        last = m.stats.triangles;
    }
    assert!(last < zero.stats.triangles);
}

#[test]
fn threads_and_blocks_keep_the_bounded_mesh() {
    let vol = volumes::demo(demo::knot(40));
    let params = bounded(&vol, Mode::Embedded, ErrorBound::Voxels(0.25));
    let v = Volume::new(&vol.data, vol.dims).expect("v");
    let whole = extract(&v, &params).expect("x");
    assert_eq!(extract_par(&v, &params, 3, &|_| {}).expect("par"), whole);
    let [nx, ny, nz] = vol.dims;
    let mut joined = BlockMesh::default();
    for (x, z) in [
        (0..17, 0..20),
        (17..nx - 1, 0..20),
        (0..17, 20..nz - 1),
        (17..nx - 1, 20..nz - 1),
    ] {
        let cubes = [x, 0..ny - 1, z];
        let need = block_samples(vol.dims, cubes.clone(), &params).expect("inside");
        let mut data = vec![];
        for z in need[2].clone() {
            for y in need[1].clone() {
                data.extend_from_slice(&vol.data[nx * (y + ny * z)..][need[0].clone()]);
            }
        }
        let dims = need.clone().map(|r| r.len());
        let part = extract_block(
            &Volume::new(&data, dims).expect("box"),
            need.map(|r| r.start),
            vol.dims,
            cubes,
            &params,
        )
        .expect("block");
        joined = joined.merge(part).expect("join");
    }
    assert_eq!(joined.into_mesh().expect("whole"), whole);
}
