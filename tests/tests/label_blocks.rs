//! Label volumes meshed in blocks: a volume cut into blocks of any shape (one cube thick, not
//! aligned to the sweep's pieces of 16 layers), each meshed from exactly the samples
//! `block_samples` asks for, and the shares joined in any order, gives `extract_labels`'s atlas
//! bit for bit — in every mode, padded or not, smoothed or not, on chosen and random volumes and
//! cuts. A halo one sample short, cubes outside the grid, overlapping, missing or mismatched
//! shares are refused.

use std::ops::Range;

use proptest::prelude::*;
use sc_runtime::labels::{
    Atlas, AtlasBlock, LabelParams, block_samples, extract_block, extract_labels,
};
use sc_runtime::{Error, Mode, Volume};
use sc_tests::volumes::{blocks_between, label_noise, splitmix, sub_box, voronoi_labels};

/// The modes a label volume has.
const MODES: [Mode; 3] = [Mode::Embedded, Mode::Paper, Mode::Steps123];

struct Labels {
    data: Vec<u16>,
    dims: [usize; 3],
}

impl Labels {
    fn volume(&self) -> Volume<'_, u16> {
        Volume::new(&self.data, self.dims).unwrap()
    }

    /// The cubes of the grid as meshed, per axis.
    fn cubes(&self, pad: bool) -> [usize; 3] {
        self.dims.map(|n| n + 2 * usize::from(pad) - 1)
    }
}

fn params(mode: Mode, pad: bool, smoothing: f64) -> LabelParams<u16> {
    LabelParams {
        mode,
        pad,
        smoothing,
        spacing: [1.0, 1.25, 0.75],
        origin: [-2.0, 1.0, 0.5],
        ..LabelParams::default()
    }
}

/// One block's share, meshed from exactly the samples `block_samples` asks for.
fn share(vol: &Labels, params: &LabelParams<u16>, cubes: [Range<usize>; 3]) -> AtlasBlock<u16> {
    let need = block_samples(vol.dims, cubes.clone(), params).expect("cubes inside the grid");
    let data = sub_box(&vol.data, vol.dims, &need);
    let samples = Volume::new(&data, need.clone().map(|r| r.len())).unwrap();
    extract_block(
        samples,
        need.map(|r| r.start),
        vol.dims,
        cubes.clone(),
        params,
    )
    .unwrap_or_else(|e| panic!("block {cubes:?}: {e}"))
}

/// Meshes every block, then joins the shares in an order and grouping drawn from `seed`: two
/// to four shares at a time, by `merge` or `merge_all`.
fn joined(
    vol: &Labels,
    params: &LabelParams<u16>,
    cuts: &[Vec<usize>; 3],
    seed: u64,
) -> Atlas<u16> {
    let mut parts: Vec<AtlasBlock<u16>> = blocks_between(vol.cubes(params.pad), cuts)
        .into_iter()
        .map(|b| share(vol, params, b))
        .collect();
    let mut s = seed;
    while parts.len() > 1 {
        s = splitmix(s);
        let k = (2 + s as usize % 3).min(parts.len());
        let mut group: Vec<AtlasBlock<u16>> = (0..k)
            .map(|_| {
                s = splitmix(s);
                parts.swap_remove(s as usize % parts.len())
            })
            .collect();
        let one = if k == 2 {
            let b = group.pop().unwrap();
            group.pop().unwrap().merge(b)
        } else {
            AtlasBlock::merge_all(group)
        };
        parts.push(one.expect("disjoint shares"));
    }
    parts.pop().unwrap().into_atlas().expect("complete")
}

/// Bit for bit: positions by their bits, then triangles, pairs and counts.
fn assert_same(got: &Atlas<u16>, whole: &Atlas<u16>, what: &str) {
    let bits = |a: &Atlas<u16>| -> Vec<[u32; 3]> {
        a.positions.iter().map(|p| p.map(f32::to_bits)).collect()
    };
    assert_eq!(got.stats, whole.stats, "{what}: stats");
    assert!(bits(got) == bits(whole), "{what}: positions");
    assert!(got.triangles == whole.triangles, "{what}: triangles");
    assert!(got.pairs == whole.pairs, "{what}: pairs");
}

/// Every mode, padded and not, for each cut.
fn every_setting_agrees(vol: &Labels, smoothing: f64, cuts: &[[Vec<usize>; 3]], what: &str) {
    for mode in MODES {
        for pad in [false, true] {
            let params = params(mode, pad, smoothing);
            let whole = extract_labels(vol.volume(), &params).unwrap();
            assert!(!whole.triangles.is_empty(), "{what}: empty");
            for (n, cut) in cuts.iter().enumerate() {
                let got = joined(vol, &params, cut, n as u64 + 1);
                assert_same(
                    &got,
                    &whole,
                    &format!("{what} {mode:?} pad {pad} cut {cut:?}"),
                );
            }
        }
    }
}

/// Cuts every `width` cubes along each axis, from `phase`.
fn regular(cubes: [usize; 3], width: usize, phase: usize) -> [Vec<usize>; 3] {
    cubes.map(|n| (1..n).filter(|c| c % width == phase % width).collect())
}

/// Cuts at random places, a few per axis.
fn random(cubes: [usize; 3], seed: u64) -> [Vec<usize>; 3] {
    let mut s = seed;
    cubes.map(|n| {
        let mut cuts: Vec<usize> = (0..3)
            .map(|_| {
                s = splitmix(s);
                s as usize % n
            })
            .collect();
        cuts.sort_unstable();
        cuts.dedup();
        cuts
    })
}

fn cuts(vol: &Labels, seed: u64) -> Vec<[Vec<usize>; 3]> {
    let cubes = vol.cubes(true);
    vec![
        regular(cubes, 1, 0),
        regular(cubes, 3, 1),
        regular(cubes, 7, 2),
        random(cubes, seed),
        random(cubes, seed + 1),
    ]
}

#[test]
fn noise_cut_into_blocks_joins_exactly() {
    let vol = Labels {
        data: label_noise([9, 8, 7], 5, 3),
        dims: [9, 8, 7],
    };
    every_setting_agrees(&vol, 0.0, &cuts(&vol, 11), "noise");
}

#[test]
fn voronoi_cells_cut_into_blocks_join_exactly() {
    let dims = [13, 12, 11];
    let vol = Labels {
        data: voronoi_labels(dims, 12, 5),
        dims,
    };
    let whole = extract_labels(vol.volume(), &params(Mode::Embedded, true, 0.0)).unwrap();
    assert!(
        whole.stats.merged > 0 && whole.stats.blocked > 0,
        "Step 4 is exercised"
    );
    every_setting_agrees(&vol, 0.0, &cuts(&vol, 21), "cells");
}

/// Slabs across the sweep's pieces of 16 layers, on several threads, and blocks 17 wide.
#[test]
fn blocks_across_the_sweeps_pieces_join_exactly() {
    let dims = [10, 9, 40];
    let vol = Labels {
        data: voronoi_labels(dims, 20, 9),
        dims,
    };
    let cubes = vol.cubes(true);
    let cut = [vec![], vec![4], vec![5, 16, 17, 33]];
    every_setting_agrees(&vol, 0.0, &[cut, regular(cubes, 17, 3)], "tall cells");
}

/// The Gaussian reads further than the cubes do: narrow and wide widths, through thin blocks.
#[test]
fn smoothed_blocks_join_exactly() {
    let dims = [11, 10, 9];
    let cells = Labels {
        data: voronoi_labels(dims, 10, 2),
        dims,
    };
    let noise = Labels {
        data: label_noise(dims, 3, 4),
        dims,
    };
    for smoothing in [0.3, 0.75, 1.7] {
        let cubes = cells.cubes(true);
        let cuts = [regular(cubes, 2, 1), random(cubes, 5)];
        every_setting_agrees(
            &cells,
            smoothing,
            &cuts,
            &format!("cells smoothed {smoothing}"),
        );
        every_setting_agrees(
            &noise,
            smoothing,
            &cuts[1..],
            &format!("noise smoothed {smoothing}"),
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// Any volume (one sample thick included), any cuts, any setting.
    #[test]
    fn random_volumes_cuts_and_settings_join_exactly(
        dims in prop::array::uniform3(1usize..11),
        labels in 2u64..6,
        seed in 0u64..1 << 40,
        cut_bits in any::<u64>(),
        pad in any::<bool>(),
        mode in prop::sample::select(MODES.to_vec()),
        smoothing in prop::sample::select(vec![0.0, 0.4, 1.1]),
    ) {
        let vol = Labels { data: label_noise(dims, labels, seed), dims };
        let params = params(mode, pad, smoothing);
        let whole = extract_labels(vol.volume(), &params).unwrap();
        // Each cube index is a cut with probability 1/4.
        let mut bit = 0;
        let cuts = vol.cubes(pad).map(|n| {
            (1..n).filter(|_| { bit += 2; cut_bits >> (bit % 64) & 3 == 0 }).collect()
        });
        let got = joined(&vol, &params, &cuts, seed);
        assert_same(&got, &whole, &format!("{dims:?} {mode:?} pad {pad} σ {smoothing} {cuts:?}"));
    }
}

/// A block given one sample less than `block_samples` asks for, at either end of any axis, is
/// refused; so is one whose samples run past the grid.
#[test]
fn a_halo_one_sample_short_is_refused() {
    let dims = [12, 11, 10];
    let vol = Labels {
        data: voronoi_labels(dims, 8, 1),
        dims,
    };
    for (pad, smoothing) in [(false, 0.0), (true, 0.0), (true, 1.0)] {
        let params = params(Mode::Embedded, pad, smoothing);
        let cubes = [4..7, 3..6, 5..7];
        let need = block_samples(dims, cubes.clone(), &params).unwrap();
        let mut short_by_one = 0;
        for axis in 0..3 {
            for end in [false, true] {
                let mut r = need.clone();
                if end {
                    r[axis].end -= 1;
                } else {
                    r[axis].start += 1;
                }
                let data = sub_box(&vol.data, dims, &r);
                let samples = Volume::new(&data, r.clone().map(|r| r.len())).unwrap();
                let at = r.clone().map(|r| r.start);
                match extract_block(samples, at, dims, cubes.clone(), &params) {
                    Err(Error::HaloTooSmall { axis: a, .. }) if a == axis => short_by_one += 1,
                    other => panic!("{r:?}: {other:?}"),
                }
            }
        }
        assert_eq!(short_by_one, 6);
        // The right samples said to start one further on: past the grid's end along x.
        let data = sub_box(&vol.data, dims, &need);
        let samples = Volume::new(&data, need.clone().map(|r| r.len())).unwrap();
        let at = [need[0].start + 1, need[1].start, need[2].start];
        let e = extract_block(samples, at, dims, cubes.clone(), &params).unwrap_err();
        assert!(matches!(e, Error::HaloTooSmall { axis: 0, .. }), "{e}");
    }
}

/// Cubes are those of the grid as meshed: `n − 1` per axis, `n + 1` padded.
#[test]
fn cubes_outside_the_grid_are_refused() {
    let dims = [6, 5, 4];
    let vol = Labels {
        data: label_noise(dims, 3, 1),
        dims,
    };
    for pad in [false, true] {
        let params = params(Mode::Embedded, pad, 0.0);
        let last = vol.cubes(pad);
        assert!(block_samples(dims, [0..last[0], 0..last[1], 0..last[2]], &params).is_ok());
        for axis in 0..3 {
            let mut cubes = [0..last[0], 0..last[1], 0..last[2]];
            cubes[axis].end += 1;
            let e = block_samples(dims, cubes.clone(), &params).unwrap_err();
            assert!(
                matches!(e, Error::BlockOutsideGrid { axis: a, .. } if a == axis),
                "{e}"
            );
            let e = extract_block(vol.volume(), [0; 3], dims, cubes, &params).unwrap_err();
            assert!(matches!(e, Error::BlockOutsideGrid { .. }), "{e}");
        }
        #[allow(clippy::reversed_empty_ranges)]
        let backwards = [3..2, 0..1, 0..1];
        let e = block_samples(dims, backwards, &params).unwrap_err();
        assert!(matches!(e, Error::BlockOutsideGrid { axis: 0, .. }), "{e}");
    }
    let wide = LabelParams::<u16> {
        smoothing: 4.5,
        ..LabelParams::default()
    };
    let e = block_samples(dims, [0..1, 0..1, 0..1], &wide).unwrap_err();
    assert!(e.to_string().contains("smoothing"), "{e}");
    let adaptive = LabelParams::<u16> {
        mode: Mode::Adaptive,
        ..LabelParams::default()
    };
    let e = extract_block(vol.volume(), [0; 3], dims, [0..1, 0..1, 0..1], &adaptive);
    assert!(matches!(e, Err(Error::NotAdaptive { .. })), "{e:?}");
}

/// Shares that overlap, leave cubes out, or were made padded and not, do not join.
#[test]
fn overlapping_missing_or_mismatched_shares_are_refused() {
    let dims = [8, 7, 6];
    let vol = Labels {
        data: voronoi_labels(dims, 6, 3),
        dims,
    };
    let padded = params(Mode::Embedded, true, 0.0);
    let c = vol.cubes(true);
    let low = share(&vol, &padded, [0..c[0], 0..c[1], 0..3]);
    let high = share(&vol, &padded, [0..c[0], 0..c[1], 3..c[2]]);
    let across = share(&vol, &padded, [0..c[0], 0..c[1], 2..4]);
    let e = low.clone().merge(across).unwrap_err();
    assert!(matches!(e, Error::BlocksOverlap { .. }), "{e}");
    let e = low.clone().into_atlas().unwrap_err();
    assert!(matches!(e, Error::BlocksMissing { .. }), "{e}");
    let bare = params(Mode::Embedded, false, 0.0);
    let unpadded = share(
        &vol,
        &bare,
        [0..dims[0] - 1, 0..dims[1] - 1, 3..dims[2] - 1],
    );
    let e = low.clone().merge(unpadded).unwrap_err();
    assert_eq!(e, Error::BlocksDiffer);
    // An empty share joins anything.
    let whole = AtlasBlock::merge_all([AtlasBlock::default(), high, low]).unwrap();
    assert_same(
        &whole.into_atlas().unwrap(),
        &extract_labels(vol.volume(), &padded).unwrap(),
        "with an empty share",
    );
}

/// `check` passes what `extract_block` makes and refuses each broken rule.
#[test]
fn check_refuses_broken_shares() {
    let dims = [8, 7, 6];
    let vol = Labels {
        data: voronoi_labels(dims, 6, 3),
        dims,
    };
    let good = share(&vol, &params(Mode::Embedded, true, 0.0), [0..5, 0..8, 1..4]);
    assert!(good.check().is_ok() && good.triangles.len() > 10);
    let mut breaks: Vec<AtlasBlock<u16>> = vec![good.clone(); 5];
    breaks[0].pairs.pop();
    breaks[1].positions.pop();
    breaks[2].keys.swap(0, 1);
    breaks[3].cubes.swap(0, good.cubes.len() - 1);
    breaks[4].triangles[0][1] = good.keys.len() as u32;
    for (n, b) in breaks.iter().enumerate() {
        assert!(
            matches!(b.check(), Err(Error::BlockMalformed { .. })),
            "break {n} passed"
        );
    }
}
