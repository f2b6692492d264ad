//! A volume read a slab of z-slices at a time and meshed in blocks of whole cube layers: each
//! block once the slices its halo reaches are in, from a ring that keeps the slices later blocks
//! read again and drops the rest, and the blocks' shares joined as they come, into exactly the
//! whole volume's result. Label volumes stream so in every mode, and surfaces in adaptive mode,
//! whose halo is far deeper than the few slices the slice streamer holds.

use std::ops::Range;

use sc_runtime::labels::{AtlasBlock, Label, LabelParams};
use sc_runtime::{BlockMesh, Error as RuntimeError, Params, Scalar, Volume};

use crate::error::Result;
use crate::progress::Progress;

/// A block's share of a result: shares join into the whole (`merge_all`), in any order.
pub(crate) trait Share: Sized {
    fn join(shares: Vec<Self>) -> std::result::Result<Self, RuntimeError>;
}

impl<L: Label> Share for AtlasBlock<L> {
    fn join(shares: Vec<Self>) -> std::result::Result<Self, RuntimeError> {
        AtlasBlock::merge_all(shares)
    }
}

impl Share for BlockMesh {
    fn join(shares: Vec<Self>) -> std::result::Result<Self, RuntimeError> {
        BlockMesh::merge_all(shares)
    }
}

/// What a block stream meshes with: which samples a block of cubes reads, and how a block is
/// meshed into its share.
pub(crate) trait Blocks<S> {
    type Share: Share;
    /// The cubes along each axis of a grid of `dims` samples.
    fn cubes(&self, dims: [usize; 3]) -> [usize; 3];
    /// The samples the block of `cubes` reads (`block_samples`).
    fn samples(
        &self,
        dims: [usize; 3],
        cubes: [Range<usize>; 3],
    ) -> std::result::Result<[Range<usize>; 3], RuntimeError>;
    /// The share of the block of `cubes`, from `samples` lying at global index `at`.
    fn mesh(
        &self,
        samples: &Volume<'_, S>,
        at: [usize; 3],
        dims: [usize; 3],
        cubes: [Range<usize>; 3],
    ) -> std::result::Result<Self::Share, RuntimeError>;
}

impl<L: Label> Blocks<L> for LabelParams<L> {
    type Share = AtlasBlock<L>;
    fn cubes(&self, dims: [usize; 3]) -> [usize; 3] {
        dims.map(|n| (n + 2 * usize::from(self.pad)).saturating_sub(1))
    }
    fn samples(
        &self,
        dims: [usize; 3],
        cubes: [Range<usize>; 3],
    ) -> std::result::Result<[Range<usize>; 3], RuntimeError> {
        sc_runtime::labels::block_samples(dims, cubes, self)
    }
    fn mesh(
        &self,
        samples: &Volume<'_, L>,
        at: [usize; 3],
        dims: [usize; 3],
        cubes: [Range<usize>; 3],
    ) -> std::result::Result<AtlasBlock<L>, RuntimeError> {
        sc_runtime::labels::extract_block(*samples, at, dims, cubes, self)
    }
}

impl<T: Scalar> Blocks<T> for Params {
    type Share = BlockMesh;
    fn cubes(&self, dims: [usize; 3]) -> [usize; 3] {
        dims.map(|n| n.saturating_sub(1))
    }
    fn samples(
        &self,
        dims: [usize; 3],
        cubes: [Range<usize>; 3],
    ) -> std::result::Result<[Range<usize>; 3], RuntimeError> {
        sc_runtime::block_samples(dims, cubes, self)
    }
    fn mesh(
        &self,
        samples: &Volume<'_, T>,
        at: [usize; 3],
        dims: [usize; 3],
        cubes: [Range<usize>; 3],
    ) -> std::result::Result<BlockMesh, RuntimeError> {
        sc_runtime::extract_block(samples, at, dims, cubes, self)
    }
}

/// The joined share of a volume of `dims` samples whose slabs of whole z-slices `next` gives in
/// order: blocks of at least `block_layers` cube layers (all x and y; fewer only at the end),
/// each meshed once the slices it reads are in.
pub(crate) fn stream_blocks<S: Copy, B: Blocks<S>>(
    blocks: &B,
    dims: [usize; 3],
    block_layers: usize,
    mut next: impl FnMut() -> Result<Vec<S>>,
    progress: &dyn Progress,
) -> Result<B::Share> {
    let [nx, ny, nz] = dims;
    let nxy = nx * ny;
    let cubes = blocks.cubes(dims);
    let layers = if cubes.contains(&0) { 0 } else { cubes[2] };
    let block = |z: Range<usize>| [0..cubes[0], 0..cubes[1], z];
    // The slices `held` of the volume, x fastest.
    let mut ring: Vec<S> = Vec::new();
    let mut held = 0..0;
    // Cube layers meshed, and those whose samples are all held.
    let (mut done, mut ready) = (0, 0);
    let mut shares = Joiner::default();
    while held.end < nz || done < layers {
        if held.end < nz {
            let slab = next()?;
            // Whole slices, at least one while any is left (the reader checked the dims are not
            // zero); should a slab be empty, the blocks missing are reported when joined.
            let slices = slab.len() / nxy;
            debug_assert_eq!(slab.len(), slices * nxy);
            if slices == 0 {
                break;
            }
            ring.extend(slab);
            held.end += slices;
            progress.inc(slices as u64);
        }
        while ready < layers && blocks.samples(dims, block(ready..ready + 1))?[2].end <= held.end {
            ready += 1;
        }
        if ready == done || (ready - done < block_layers && ready < layers) {
            continue;
        }
        let cubes = block(done..ready);
        let need = blocks.samples(dims, cubes.clone())?[2].clone();
        let from = (need.start - held.start) * nxy;
        let samples = Volume::new(&ring[from..from + need.len() * nxy], [nx, ny, need.len()])?;
        let share = blocks.mesh(&samples, [0, 0, need.start], dims, cubes)?;
        shares.push(share)?;
        done = ready;
        // Later blocks read from where the next one starts: the slices before are dropped.
        if done < layers {
            let keep = blocks.samples(dims, block(done..done + 1))?[2].start;
            ring.drain(..(keep - held.start) * nxy);
            held.start = keep;
        }
    }
    Ok(shares.finish()?)
}

/// Shares joined as they come, like a binary counter: two joins of as many blocks each merge,
/// so each share is copied about log₂(blocks) times rather than once per later block.
pub(crate) struct Joiner<S> {
    /// Joined shares, with the blocks each holds, fewer blocks further up.
    stack: Vec<(S, usize)>,
}

impl<S> Default for Joiner<S> {
    fn default() -> Self {
        Joiner { stack: Vec::new() }
    }
}

impl<S: Share> Joiner<S> {
    pub(crate) fn push(&mut self, share: S) -> std::result::Result<(), RuntimeError> {
        let mut top = (share, 1);
        while let Some((below, blocks)) = self.stack.pop_if(|(_, blocks)| *blocks == top.1) {
            top = (S::join(vec![below, top.0])?, blocks + top.1);
        }
        self.stack.push(top);
        Ok(())
    }

    /// Every share joined (an empty one if none came).
    pub(crate) fn finish(self) -> std::result::Result<S, RuntimeError> {
        S::join(self.stack.into_iter().map(|(share, _)| share).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::Silent;
    use sc_runtime::{Mode, demo, extract};

    /// Adaptive mode streamed in slabs of every size, in blocks thinner and thicker than the
    /// halo, gives the whole volume's mesh, stats included, for boxes of every size; a
    /// volume too thin for a cube too. (Label volumes: `labels::stream`'s tests.)
    #[test]
    fn streamed_adaptive_meshes_are_the_whole_mesh() {
        for (v, max_box) in [
            (demo::torus(20), 2),
            (demo::sphere_noise(24), 4),
            (demo::knot(22), 16),
        ] {
            let params = Params {
                mode: Mode::Adaptive,
                max_box: Some(max_box),
                ..Params::new(v.iso)
            };
            let whole = extract(&Volume::new(&v.data, v.dims).unwrap(), &params).unwrap();
            assert!(whole.stats.triangles < whole.stats.t13, "boxes formed");
            let nxy = v.dims[0] * v.dims[1];
            for (slab, block_layers) in [(1, 1), (2, 5), (3, 16), (7, 3), (30, 40)] {
                let mut slabs = v.data.chunks(slab * nxy).map(<[f64]>::to_vec);
                let next = || Ok(slabs.next().expect("read past the end"));
                let mesh = stream_blocks(&params, v.dims, block_layers, next, &Silent)
                    .unwrap()
                    .into_mesh()
                    .unwrap();
                assert!(
                    mesh == whole,
                    "boxes of {max_box}, slabs of {slab}, blocks of {block_layers}"
                );
            }
        }
        let thin = [1.0f64, 2.0, 3.0, 4.0];
        let params = Params {
            mode: Mode::Adaptive,
            ..Params::new(2.5)
        };
        let mut once = Some(thin.to_vec());
        let next = || Ok(once.take().expect("read past the end"));
        let mesh = stream_blocks(&params, [2, 2, 1], 16, next, &Silent)
            .unwrap()
            .into_mesh()
            .unwrap();
        assert!(mesh.triangles.is_empty());
    }
}
