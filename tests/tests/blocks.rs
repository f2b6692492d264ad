//! Block extraction: a grid cut into blocks of any shape, each meshed from its own samples plus
//! halo, and the shares joined in any order, gives the whole-volume mesh bit for bit — in every
//! mode, with normals, for cuts anywhere (through merged pairs, blocks one cube wide). A halo one
//! sample short is refused, and so are overlapping or missing blocks.

use std::ops::Range;

use proptest::prelude::*;
use sc_runtime::{
    BlockMesh, Error, Mesh, Mode, Params, Volume, block_samples, demo, extract, extract_block,
};
use sc_tests::volumes::{
    self, Sample, Vol, blocks_between, brainsmall_crop, integer_noise, itk_t1_crop, splitmix,
    stent_crop, sub_box,
};

/// One block's share, meshed from exactly the samples `block_samples` asks for.
fn share<T: Sample>(vol: &Vol<T>, params: &Params, cubes: [Range<usize>; 3]) -> BlockMesh {
    let need = block_samples(vol.dims, cubes.clone()).expect("cubes inside the grid");
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
    for cubes in [[5..12, 4..9, 7..15], [6..12, 5..9, 8..15]] {
        let need = block_samples(vol.dims, cubes.clone()).expect("inside");
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
        block_samples([10, 10, 10], [0..10, 0..9, 0..9]),
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
