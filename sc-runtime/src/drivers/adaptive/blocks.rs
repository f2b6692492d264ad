//! Adaptive mode block by block (docs/adaptive.md §8): a block's share of the mesh, joined with
//! the others by [`BlockMesh::merge`] into exactly what [`super::extract`] makes of the whole grid.
//!
//! A block meshes its samples plus a halo as if they were the whole grid, on the whole grid's box
//! lattice, and keeps the triangles its cubes own: a unit cube's own, a merge's at the least of
//! its four cubes, a box's at its lower corner cube ([`super::run`]). The halo is wide enough
//! that every decision those triangles follow from is the whole grid's ([`halo`]).

use alloc::borrow::Cow;
use alloc::vec::Vec;
use core::ops::Range;

use super::{InOrder, LARGEST_BOX, run, unkey, vertices};
use crate::drivers::blocks::{BlockMesh, edge_key};
use crate::drivers::keep_used;
use crate::{Error, Params, Scalar, Stats, Volume};

/// Cubes before and past a block's own whose decisions its triangles read, before rounding
/// out to the lattice of the largest box `M`:
///
/// - A block's triangles read the balanced box size over its cubes, over the `M − 1` cubes past
///   them that a box it owns spans, and over two more on either side: the neighbours that set a
///   box's variant, and the four cubes of a merge (a merge its cubes' triangles give way to
///   belongs to a cube at most one before them).
/// - Balancing splits a box of side `s` only for a face neighbour of side `s/4` or less after
///   balancing, which lies within `s/4` of it, or inside a neighbour of side `s/2` split in
///   turn. So what splits a box of side `s` lies within `r(s) ≤ s/2 + r(s/2)` of it, with
///   `r(4) = 2` (a pair of unit cubes next to it): `r(s) = s − 2`. The balanced size over a cube
///   therefore follows from the unbalanced sizes within `(M − 1) + (M − 2) < 2M` cubes of it.
/// - The unbalanced sizes over a cube follow from the boxes of its tile (the aligned box of side
///   `M` holding it), each decided on its own samples; whether a face has a box across is asked
///   of the whole grid. So they are exact wherever the samples hold whole tiles, which the
///   rounding out to multiples of `M` gives.
///
/// Step 4's merges read two samples past their cubes, and normals one: less than either reach.
fn halo(params: &Params) -> (usize, usize, usize) {
    let m = params.max_box.unwrap_or(LARGEST_BOX) as usize;
    (2 * m + 2, 3 * m + 2, m)
}

/// The samples adaptive mode reads to mesh the cubes `cubes` of a grid of `grid` samples: the
/// cubes within [`halo`], rounded out to multiples of the largest box, clipped to the grid.
pub(crate) fn block_samples(
    grid: [usize; 3],
    cubes: &[Range<usize>; 3],
    params: &Params,
) -> [Range<usize>; 3] {
    let (before, after, m) = halo(params);
    core::array::from_fn(|d| {
        let start = cubes[d].start.saturating_sub(before) / m * m;
        let end = (cubes[d].end + after).next_multiple_of(m) + 1;
        start..end.min(grid[d])
    })
}

/// [`crate::extract_block`] in adaptive mode, once `samples` (from global index `at`) are known
/// to cover `need` ([`block_samples`]) and `out` (the share, empty) to own some cube.
pub(crate) fn extract_block<T: Scalar>(
    samples: &Volume<'_, T>,
    at: [usize; 3],
    need: [Range<usize>; 3],
    cubes: [Range<usize>; 3],
    params: &Params,
    mut out: BlockMesh,
) -> Result<BlockMesh, Error> {
    let grid = out.grid;
    // Exactly the samples `need`, which start on the lattice of every box size.
    let dims = need.clone().map(|r| r.len());
    let start = need.clone().map(|r| r.start);
    let data = if at == start && samples.dims() == dims {
        Cow::Borrowed(samples.data())
    } else {
        let [nx, ny, _] = samples.dims();
        let mut cut = Vec::with_capacity(dims.iter().product());
        for z in need[2].clone() {
            for y in need[1].clone() {
                let row = (z - at[2]) * ny * nx + (y - at[1]) * nx;
                cut.extend_from_slice(&samples.data()[row + need[0].start - at[0]..][..dims[0]]);
            }
        }
        Cow::Owned(cut)
    };
    let volume = Volume::new(&data, dims)?;
    let run = run(&volume, start, grid, params, &InOrder)?;
    let owned = |key: u64| {
        let c = unkey(key as usize, grid);
        (0..3).all(|d| cubes[d].contains(&c[d]))
    };
    // The edges whose vertices the block counts, as a sweep restricted to its cubes does: the
    // grid's last samples count with the block that ends there.
    let owned_edge = |key: u64| {
        let lower = unkey((key / 3) as usize, grid);
        (0..3).all(|d| {
            let end = if cubes[d].end + 1 == grid[d] {
                grid[d]
            } else {
                cubes[d].end
            };
            (cubes[d].start..end).contains(&lower[d])
        })
    };
    let rec = &run.rec;
    for (&owner, t) in run.owners.iter().zip(&run.triangles) {
        if owned(owner) {
            // Owners are keyed as blocks key cubes (x fastest, then y, then z).
            out.cubes.push(owner);
            out.triangles.push(*t);
        }
    }
    // Kept in sweep order, which is edge-key order.
    let kept = keep_used(rec.edges.len(), &mut out.triangles);
    out.keys = kept
        .iter()
        .map(|&v| {
            let key = rec.edges[v];
            edge_key(grid, unkey((key / 3) as usize, grid), (key % 3) as usize)
        })
        .collect();
    let vertices = vertices(&volume, start, params, &kept)?;
    out.positions = vertices.positions;
    out.normals = vertices.normals;
    let count = |keys: &[u64], owned: &dyn Fn(u64) -> bool| {
        keys.iter().filter(|&&k| owned(k)).count() as u64
    };
    out.stats = Stats {
        v13: count(&rec.edges, &owned_edge),
        t13: count(&rec.cubes, &owned),
        merged: count(&run.merges, &owned),
        vertices: out.keys.len() as u64,
        triangles: out.triangles.len() as u64,
        ..Stats::default()
    };
    debug_assert!(out.check().is_ok());
    Ok(out)
}
