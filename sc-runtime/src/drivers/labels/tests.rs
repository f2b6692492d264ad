//! The steps that run in chunks on threads, cut into chunks of a few items (see
//! `chunks::SMALLEST`), so that a small volume runs each in many: the atlas and its labels are
//! the same as one chunk on one thread makes them.

use alloc::format;
use alloc::vec::Vec;

use super::{Atlas, AtlasView, LabelParams, extract_labels};
use crate::{Error, Mode, Volume};

/// Cells around `seeds` pseudo-random points, labelled `scale` times their seed's index (0, the
/// background, for the first), so that labels past 2¹⁶ take the hash set's path.
fn cells(dims: [usize; 3], seeds: usize, scale: u32) -> Vec<u32> {
    let mut state = 0x2545_f491_u64;
    let mut next = |n: usize| {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        ((state >> 33) % n as u64) as i64
    };
    let points: Vec<[i64; 3]> = (0..seeds)
        .map(|_| [next(dims[0]), next(dims[1]), next(dims[2])])
        .collect();
    let mut data = Vec::with_capacity(dims.iter().product());
    for z in 0..dims[2] as i64 {
        for y in 0..dims[1] as i64 {
            for x in 0..dims[0] as i64 {
                let d = |p: &[i64; 3]| (p[0] - x).pow(2) + (p[1] - y).pow(2) + (p[2] - z).pow(2);
                let nearest = (0..seeds).min_by_key(|&i| (d(&points[i]), i)).unwrap_or(0);
                data.push(nearest as u32 * scale);
            }
        }
    }
    data
}

#[test]
fn many_chunks_give_the_same_atlas_as_one() {
    let dims = [13, 11, 29];
    for scale in [1, 70_001] {
        let data = cells(dims, 14, scale);
        let volume = Volume::new(&data, dims).unwrap();
        for (mode, smoothing) in [
            (Mode::Embedded, 0.0),
            (Mode::Paper, 0.0),
            (Mode::Embedded, 0.75),
        ] {
            let atlas = |threads| -> Atlas<u32> {
                let params = LabelParams {
                    mode,
                    smoothing,
                    threads,
                    ..LabelParams::default()
                };
                extract_labels(volume, &params).unwrap()
            };
            let one = atlas(1);
            let what = format!("scale {scale}, {mode:?}, smoothing {smoothing}");
            assert!(
                one.stats.merged > 0 && one.stats.blocked > 0,
                "{what}: {:?}",
                one.stats
            );
            let labels = one.labels(0, 1);
            assert_eq!(labels.len(), 13, "{what}");
            for threads in [2, 3] {
                let many = atlas(threads);
                assert_eq!(many, one, "{what}, {threads} threads");
                assert_eq!(many.labels(0, threads), labels, "{what}, {threads} threads");
            }
        }
    }
}

#[test]
fn a_view_of_the_arrays_cuts_the_atlas_s_meshes() {
    let dims = [9, 10, 11];
    let data = cells(dims, 9, 1);
    let atlas = extract_labels(Volume::new(&data, dims).unwrap(), &LabelParams::default()).unwrap();
    let labels = atlas.labels(0, 1);
    assert_eq!(labels.len(), 8);
    let view = AtlasView::new(&atlas.positions, &atlas.triangles, &atlas.pairs).unwrap();
    for (normals, threads) in [(true, 1), (false, 2)] {
        let meshes = view.meshes(&labels, normals, threads);
        assert_eq!(meshes, atlas.meshes(&labels, normals, threads));
        assert!(meshes.iter().all(|(_, m)| !m.triangles.is_empty()));
    }
    // Out of order, each label still gets its own mesh: nothing indexes past the lookup table.
    let backwards: Vec<u32> = labels.iter().rev().copied().collect();
    let mut reversed = view.meshes(&backwards, true, 1);
    reversed.reverse();
    assert_eq!(reversed, atlas.meshes(&labels, true, 1));

    let short = &atlas.pairs[1..];
    assert!(matches!(
        AtlasView::new(&atlas.positions, &atlas.triangles, short),
        Err(Error::AtlasMalformed { .. })
    ));
    let missing = &atlas.positions[..atlas.positions.len() - 1];
    let err = AtlasView::new(missing, &atlas.triangles, &atlas.pairs).unwrap_err();
    assert_eq!(
        format!("{err}"),
        "the atlas is malformed: a triangle's vertex is not among the positions"
    );
}
