//! Block extraction: a grid cut into blocks of any shape, each meshed from its own samples plus
//! halo, and the shares joined in any order, gives the whole-volume mesh bit for bit — in every
//! mode, with normals, for cuts anywhere (through merged pairs, blocks one cube wide). A halo one
//! sample short is refused, and so are overlapping or missing blocks.

use std::ops::Range;

use proptest::prelude::*;
use sc_runtime::{
    BlockMesh, Error, ErrorBound, Mesh, Mode, Params, Volume, block_samples, demo, extract,
    extract_block,
};
use sc_tests::volumes::{
    self, Sample, Vol, blocks_between, brainsmall_crop, integer_noise, itk_t1_crop, splitmix,
    stent_crop, sub_box,
};

/// One block's share, meshed from exactly the samples `block_samples` asks for.
fn share<T: Sample>(vol: &Vol<T>, params: &Params, cubes: [Range<usize>; 3]) -> BlockMesh {
    let need = block_samples(vol.dims, cubes.clone(), params).expect("cubes inside the grid");
    let data = sub_box(&vol.data, vol.dims, &need);
    let dims = need.clone().map(|r| r.len());
    let samples = Volume::new(&data, dims).expect("box");
    extract_block(
        &samples,
        need.map(|r| r.start),
        vol.dims,
        cubes.clone(),
        params,
    )
    .unwrap_or_else(|e| panic!("block {cubes:?}: {e}"))
}

/// Meshes every block, then joins the shares in an order and tree shape drawn from `seed`: each
/// join takes two to five shares at once.
fn joined<T: Sample>(vol: &Vol<T>, params: &Params, cuts: &[Vec<usize>; 3], seed: u64) -> Mesh {
    let mut parts: Vec<BlockMesh> = blocks_between(vol.dims.map(|n| n - 1), cuts)
        .into_iter()
        .map(|b| share(vol, params, b))
        .collect();
    let mut s = seed;
    while parts.len() > 1 {
        s = splitmix(s);
        let k = (2 + s as usize % 4).min(parts.len());
        let group: Vec<BlockMesh> = (0..k)
            .map(|_| {
                s = splitmix(s);
                parts.swap_remove(s as usize % parts.len())
            })
            .collect();
        let one = match <[BlockMesh; 2]>::try_from(group) {
            Ok([a, b]) => a.merge(b),
            Err(group) => BlockMesh::merge_all(group),
        };
        parts.push(one.expect("disjoint shares"));
    }
    parts.pop().expect("one").into_mesh().expect("complete")
}

fn assert_same(a: &Mesh, b: &Mesh, what: &str) {
    let bits = |v: &[[f32; 3]]| v.iter().map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(a.stats, b.stats, "{what}: stats");
    assert!(
        bits(&a.positions) == bits(&b.positions),
        "{what}: positions"
    );
    assert!(bits(&a.normals) == bits(&b.normals), "{what}: normals");
    assert!(a.triangles == b.triangles, "{what}: triangles");
}

fn every_mode_agrees<T: Sample>(vol: &Vol<T>, cuts: &[Vec<usize>; 3], seed: u64, what: &str) {
    for mode in [Mode::Steps123, Mode::Embedded, Mode::Paper] {
        let params = vol.params(mode);
        let whole = extract(&Volume::new(&vol.data, vol.dims).expect("v"), &params).expect("x");
        assert!(!whole.triangles.is_empty(), "{what}: empty");
        let got = joined(vol, &params, cuts, seed);
        assert_same(&got, &whole, &format!("{what} {mode:?} cut at {cuts:?}"));
    }
}

/// Cuts every `width` cubes along each axis, starting at `phase`.
fn regular(dims: [usize; 3], width: usize, phase: usize) -> [Vec<usize>; 3] {
    dims.map(|n| (1..n - 1).filter(|c| c % width == phase % width).collect())
}

#[test]
fn real_and_demo_volumes_cut_into_blocks_join_exactly() {
    let knot = volumes::demo(demo::knot(48));
    for (width, phase) in [(7, 3), (16, 0), (5, 0)] {
        every_mode_agrees(&knot, &regular(knot.dims, width, phase), 11, "knot");
    }
    every_mode_agrees(
        &brainsmall_crop(),
        &regular([40, 40, 30], 9, 4),
        1,
        "brainsmall",
    );
    every_mode_agrees(
        &stent_crop(250.0),
        &regular([40, 40, 30], 13, 1),
        2,
        "stent",
    );
    every_mode_agrees(&itk_t1_crop(), &regular([40, 40, 30], 6, 5), 3, "itk-t1");
    every_mode_agrees(
        &volumes::demo(demo::sphere_noise(24)),
        &regular([24; 3], 4, 2),
        4,
        "noise",
    );
}

/// Every single cut position along each axis: a cut through every merged pair's two cubes,
/// at both parities, and blocks one cube wide at the grid's ends.
#[test]
fn every_single_cut_position_joins_exactly() {
    let vol = volumes::demo(demo::knot(20));
    let n = vol.dims;
    for axis in 0..3 {
        for c in 1..n[axis] - 1 {
            let mut cuts = [vec![], vec![], vec![]];
            cuts[axis].push(c);
            every_mode_agrees(&vol, &cuts, c as u64, &format!("knot20 axis {axis}"));
        }
    }
}

/// Blocks one, two and three cubes wide on every axis at once, on tied integer data.
#[test]
fn thin_blocks_join_exactly() {
    let vol = integer_noise([13, 12, 11], 3, 7);
    for width in 1..=3 {
        for phase in 0..width {
            every_mode_agrees(&vol, &regular(vol.dims, width, phase), width as u64, "thin");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_volumes_and_cuts_join_exactly(
        dims in prop::array::uniform3(2usize..14),
        levels in 2u8..5,
        seed in any::<u64>(),
        cut_bits in any::<u64>(),
    ) {
        let vol = integer_noise(dims, levels, seed);
        // Each interior cube index is a cut with probability 1/4.
        let mut bit = 0;
        let cuts = dims.map(|n| {
            (1..n.saturating_sub(1)).filter(|_| { bit += 2; cut_bits >> (bit % 64) & 3 == 0 }).collect()
        });
        for mode in [Mode::Steps123, Mode::Embedded, Mode::Paper] {
            let params = vol.params(mode);
            let whole = extract(&Volume::new(&vol.data, vol.dims).unwrap(), &params).unwrap();
            if dims.iter().all(|&n| n >= 2) {
                let got = joined(&vol, &params, &cuts, seed);
                assert_same(&got, &whole, &format!("{dims:?} {mode:?} {cuts:?}"));
            }
        }
    }
}

#[test]
fn a_halo_one_sample_short_is_refused() {
    let vol = volumes::demo(demo::knot(24));
    let params = vol.params(Mode::Embedded);
    let blocks = [[5..12, 4..9, 7..15], [6..12, 5..9, 8..15]];
    for (params, cubes) in [params]
        .into_iter()
        .chain([2, 4].map(|m| adaptive(&vol, m, 0.5, false)))
        .flat_map(|p| blocks.clone().map(|c| (p, c)))
    {
        let need = block_samples(vol.dims, cubes.clone(), &params).expect("inside");
        for axis in 0..3 {
            for far in [false, true] {
                let mut r = need.clone();
                if far {
                    r[axis].end -= 1;
                } else {
                    r[axis].start += 1;
                }
                let data = sub_box(&vol.data, vol.dims, &r);
                let samples = Volume::new(&data, r.clone().map(|r| r.len())).expect("box");
                let got = extract_block(
                    &samples,
                    r.clone().map(|r| r.start),
                    vol.dims,
                    cubes.clone(),
                    &params,
                );
                assert!(
                    matches!(got, Err(Error::HaloTooSmall { axis: a, .. }) if a == axis),
                    "{cubes:?} with {r:?}: {got:?}"
                );
            }
        }
    }
    // Cubes outside the grid.
    assert!(matches!(
        block_samples([10, 10, 10], [0..10, 0..9, 0..9], &params),
        Err(Error::BlockOutsideGrid { axis: 0, .. })
    ));
}

#[test]
fn overlapping_or_missing_blocks_are_refused() {
    let vol = volumes::demo(demo::knot(20));
    let params = vol.params(Mode::Embedded);
    let a = share(&vol, &params, [0..19, 0..19, 0..10]);
    let b = share(&vol, &params, [0..19, 0..19, 8..19]);
    assert!(matches!(
        a.clone().merge(b.clone()),
        Err(Error::BlocksOverlap { .. })
    ));
    // Among several shares at once, and between shares that are not next to each other in the
    // list.
    let top = share(&vol, &params, [0..19, 0..10, 10..19]);
    assert!(matches!(
        BlockMesh::merge_all([a.clone(), top, b]),
        Err(Error::BlocksOverlap { .. })
    ));
    assert!(matches!(
        a.into_mesh(),
        Err(Error::BlocksMissing {
            covered: 3610,
            cubes: 6859
        })
    ));
    // Shares of different grids do not join.
    let other = volumes::demo(demo::knot(22));
    let c = share(&other, &other.params(Mode::Embedded), [0..21, 0..21, 0..5]);
    let d = share(&vol, &params, [0..19, 0..19, 10..19]);
    assert!(matches!(c.merge(d), Err(Error::BlocksDiffer)));
}

/// `BlockMesh::check` passes every share `extract_block` makes and refuses each way a share
/// read from a damaged file could break the rules `merge` relies on.
#[test]
fn check_refuses_broken_shares() {
    let vol = brainsmall_crop();
    let share = share(&vol, &Params::new(20.0), [3..20, 5..30, 2..17]);
    assert!(share.keys.len() > 100);
    assert_eq!(share.check(), Ok(()));
    type Damage = fn(&mut BlockMesh);
    let broken: [(&str, Damage); 5] = [
        ("differ in length", |b| {
            b.positions.pop();
        }),
        ("owning-cube", |b| {
            b.cubes.pop();
        }),
        ("strictly increasing", |b| b.keys.swap(0, 1)),
        ("not in order", |b| b.cubes.reverse()),
        ("not there", |b| b.triangles[0][1] = b.keys.len() as u32),
    ];
    for (needle, damage) in broken {
        let mut b = share.clone();
        damage(&mut b);
        let err = b.check().unwrap_err();
        assert!(matches!(err, Error::BlockMalformed { .. }), "{err}");
        assert!(err.to_string().contains(needle), "{needle}: {err}");
    }
}

/// Adaptive mode with boxes up to `max_box` cubes, a bound of `bound` voxels and, if asked,
/// samples allowed on the wrong side.
fn adaptive<T: Sample>(vol: &Vol<T>, max_box: u32, bound: f64, wrong_side: bool) -> Params {
    Params {
        max_box: Some(max_box),
        max_error: Some(ErrorBound::Voxels(bound)),
        allow_wrong_side: wrong_side,
        ..vol.params(Mode::Adaptive)
    }
}

/// Joins the shares of every cut in `cuts`, in an order drawn from the cut's index, and checks
/// each against the whole grid's adaptive mesh. Returns that mesh's stats.
fn adaptive_agrees<T: Sample>(
    vol: &Vol<T>,
    params: &Params,
    cuts: &[[Vec<usize>; 3]],
    what: &str,
) -> sc_runtime::Stats {
    let whole = extract(&Volume::new(&vol.data, vol.dims).expect("v"), params).expect("x");
    for (i, c) in cuts.iter().enumerate() {
        let got = joined(vol, params, c, 7 + i as u64);
        assert_same(&got, &whole, &format!("{what} cut at {c:?}"));
        assert_eq!(got, whole, "{what} cut at {c:?}");
    }
    whole.stats
}

/// Adaptive mode's shares join into `extract`'s adaptive mesh exactly: boxes of every size up to
/// 2, 4 and 16 cubes, (P) kept and waived, volumes whose surface is closed and one it leaves
/// through the border (padded and not), cut into slabs one cube thick, at multiples of the box
/// lattice and off it. The meshes have boxes (fewer triangles than Steps 1–3) and merges among
/// unit cubes, so every kind of owner is exercised.
#[test]
fn adaptive_blocks_join_exactly() {
    let mut merges = 0;
    let torus = volumes::demo(demo::torus(32));
    let thin_and_aligned = [vec![], vec![16], vec![15, 16, 17]];
    let off = [vec![7], vec![20], vec![11]];
    for (max_box, bound, wrong_side) in [(16, 1.0, false), (16, 1.0, true), (4, 0.5, false)] {
        let params = adaptive(&torus, max_box, bound, wrong_side);
        let what = format!("torus 32, max_box {max_box}, bound {bound}, wrong side {wrong_side}");
        let cuts = [thin_and_aligned.clone(), off.clone()];
        let stats = adaptive_agrees(&torus, &params, &cuts, &what);
        assert!(stats.triangles < stats.t13, "{what}: no box");
        merges += stats.merged;
    }
    // Slabs one cube thick with boxes of two cubes: every cut position, at both parities.
    let knot = volumes::demo(demo::knot(20));
    let params = adaptive(&knot, 2, 0.5, false);
    let every: Vec<usize> = (1..knot.dims[2] - 1).collect();
    let cuts = [[vec![], vec![], every], [vec![9], vec![10], vec![]]];
    let stats = adaptive_agrees(&knot, &params, &cuts, "knot 20");
    assert!(stats.triangles < stats.t13, "knot 20: no box");
    merges += stats.merged;
    // A surface through the grid's border, padded and not.
    let noise = volumes::demo(demo::sphere_noise(24));
    for vol in [noise.clone(), noise.padded(f64::MIN)] {
        let params = adaptive(&vol, 4, 0.5, false);
        let last = vol.dims[0] - 2;
        let cuts = [
            [vec![], vec![5], vec![4, 13]],
            [vec![last], vec![1], vec![8]],
        ];
        let what = format!("noise {:?}", vol.dims);
        let stats = adaptive_agrees(&vol, &params, &cuts, &what);
        assert!(stats.triangles < stats.t13, "{what}: no box");
        merges += stats.merged;
    }
    // Where boxes of four and eight cubes are balanced across a cut: a block needs more than
    // the halo of the other modes here (with it, these joins differ).
    for (vol, max_box, bound) in [
        (volumes::demo(demo::torus(48)), 4, 0.5),
        (volumes::demo(demo::knot(48)), 8, 1.0),
    ] {
        let params = adaptive(&vol, max_box, bound, false);
        let what = format!("{:?} max_box {max_box}", vol.dims);
        let cuts = [[vec![5], vec![], vec![21]], [vec![], vec![13], vec![17]]];
        merges += adaptive_agrees(&vol, &params, &cuts, &what).merged;
    }
    assert!(merges > 0, "no merge among unit cubes");
}

/// Random cuts, up to two along each axis, on noisy spheres and every box size, the shares
/// joined in random order and tree shape.
#[test]
fn adaptive_blocks_at_random_cuts_join_exactly() {
    let vol = volumes::demo(demo::sphere_noise(32));
    let cubes = vol.dims.map(|n| n - 1);
    for seed in 0..6u64 {
        let mut s = splitmix(seed);
        let cuts = cubes.map(|n| {
            s = splitmix(s);
            let mut c: Vec<usize> = (0..s % 3)
                .map(|k| 1 + (splitmix(s + k) as usize) % (n - 1))
                .collect();
            c.sort_unstable();
            c.dedup();
            c
        });
        let max_box = 1 << (seed % 5);
        let params = adaptive(&vol, max_box, 0.5, seed % 2 == 1);
        let what = format!("noise 32, max_box {max_box}, seed {seed}");
        adaptive_agrees(&vol, &params, &[cuts], &what);
    }
}
