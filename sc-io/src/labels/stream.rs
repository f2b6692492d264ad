//! Label volumes read a slab of z-slices at a time, meshed in blocks as they come
//! ([`crate::slabs`]), into exactly the atlas of the whole volume (docs/labels.md, "Blocks").

use sc_runtime::labels::{Atlas, Label, LabelParams};

use super::mesh::{self, LabelMeshes, LabelRequest};
use crate::error::Result;
use crate::progress::Progress;
use crate::read::stream::Stream;
use crate::slabs::stream_blocks;
use crate::space::World;
use crate::volume::{Dtype, Sample};

/// Cube layers meshed as one block, at least (fewer only at the end of the volume): a block
/// sweeps two layers more on each side than it owns, so thin blocks would sweep most layers
/// several times; 16 costs a quarter more than the whole sweep.
const BLOCK_LAYERS: usize = 16;

/// Meshes the labels `request` selects in a volume read slab by slab: the same meshes and
/// counts as [`extract`](super::extract) of the whole volume, holding the slices of one slab and
/// one block with its halo (more with smoothing, up to 27 slices more at the widest) besides
/// the output, on one thread.
pub fn extract_stream(
    stream: &mut Stream,
    request: &LabelRequest,
    progress: &dyn Progress,
) -> Result<LabelMeshes> {
    mesh::check_scale(&stream.grid)?;
    let world = World::new(stream.grid.frame, stream.grid.origin, request.coordinates);
    progress.phase("meshing labels", stream.grid.dims[2] as u64);
    let out = match stream.grid.samples.dtype() {
        Dtype::U8 => typed::<u8, u8>(stream, request, &world, progress),
        Dtype::I8 => typed::<i8, i16>(stream, request, &world, progress),
        Dtype::U16 => typed::<u16, u16>(stream, request, &world, progress),
        Dtype::I16 => typed::<i16, i16>(stream, request, &world, progress),
        Dtype::U32 => typed::<u32, u32>(stream, request, &world, progress),
        Dtype::I32 => typed::<i32, i32>(stream, request, &world, progress),
        Dtype::F32 | Dtype::F64 => Err(mesh::not_integers(&stream.grid)),
    }?;
    Ok(mesh::placed(out, &world))
}

/// [`extract_stream`] for samples stored as `T`, meshed as labels of type `L`.
fn typed<T, L>(
    stream: &mut Stream,
    request: &LabelRequest,
    world: &World,
    progress: &dyn Progress,
) -> Result<LabelMeshes>
where
    T: Sample,
    L: Label + From<T> + TryFrom<u64> + TryInto<i64>,
{
    let params = mesh::params::<L>(&stream.grid, request, world)?;
    let dims = stream.grid.dims;
    let slab = stream.slab();
    let next = || {
        let samples = stream.read::<T>(slab)?;
        Ok(samples.into_iter().map(L::from).collect())
    };
    let atlas = stream_atlas(dims, &params, BLOCK_LAYERS, next, progress)?;
    mesh::select(atlas, params.background, request)
}

/// The atlas of a volume of `dims` samples whose slabs of whole z-slices `next` gives in order,
/// meshed in blocks of at least `block_layers` cube layers ([`stream_blocks`]).
fn stream_atlas<L: Label>(
    dims: [usize; 3],
    params: &LabelParams<L>,
    block_layers: usize,
    next: impl FnMut() -> Result<Vec<L>>,
    progress: &dyn Progress,
) -> Result<Atlas<L>> {
    Ok(stream_blocks(params, dims, block_layers, next, progress)?.into_atlas()?)
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::progress::Silent;
    use sc_runtime::labels::extract_labels;
    use sc_runtime::{Mode, Volume};

    /// Labels of a volume with regions of every shape: cells around a few seeds, cut by noise
    /// in a band, so that the volume has junctions of three and more labels and merges.
    pub(in crate::labels) fn volume(dims: [usize; 3], seed: u64) -> Vec<u16> {
        let [nx, ny, nz] = dims;
        let mut state = seed;
        let mut random = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        let seeds: Vec<[usize; 3]> = (0..7)
            .map(|_| [random() % nx, random() % ny, random() % nz])
            .collect();
        let mut labels = Vec::with_capacity(nx * ny * nz);
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let d = |s: &[usize; 3]| {
                        let p = [x, y, z];
                        (0..3).map(|a| p[a].abs_diff(s[a]).pow(2)).sum::<usize>()
                    };
                    let cell = (0..seeds.len()).min_by_key(|&i| d(&seeds[i])).unwrap();
                    labels.push(if (x + z) % 5 == 0 && random() % 3 == 0 {
                        (random() % 4) as u16
                    } else {
                        cell as u16
                    });
                }
            }
        }
        labels
    }

    /// Parameters with anisotropic spacing and an origin, on one thread.
    pub(in crate::labels) fn params(
        pad: bool,
        mode: Mode,
        smoothing: f64,
        background: u16,
    ) -> LabelParams<u16> {
        LabelParams {
            pad,
            mode,
            smoothing,
            background,
            spacing: [0.5, 1.0, 2.0],
            origin: [1.0, -2.0, 3.0],
            threads: 1,
            ..LabelParams::default()
        }
    }

    /// Streams `labels` in slabs of `slab` slices with blocks of `block_layers`.
    fn streamed(
        labels: &[u16],
        dims: [usize; 3],
        params: &LabelParams<u16>,
        slab: usize,
        block_layers: usize,
    ) -> Atlas<u16> {
        let nxy = dims[0] * dims[1];
        let mut slabs = labels.chunks(slab * nxy).map(<[u16]>::to_vec);
        let next = || Ok(slabs.next().expect("read past the end"));
        stream_atlas(dims, params, block_layers, next, &Silent).unwrap()
    }

    /// Every slab size and block size gives the whole volume's atlas, bit for bit, stats
    /// included: padded or not, in every mode, with and without smoothing, with the background
    /// a label inside the volume or not.
    #[test]
    fn streamed_atlases_are_the_whole_atlas() {
        let dims = [9, 7, 23];
        let labels = volume(dims, 5);
        for (pad, mode, smoothing, background) in [
            (true, Mode::Embedded, 0.0, 0),
            (false, Mode::Embedded, 0.0, 0),
            (true, Mode::Paper, 0.0, 3),
            (false, Mode::Steps123, 0.0, 1),
            (true, Mode::Embedded, 0.75, 0),
            (false, Mode::Embedded, 2.0, 2),
        ] {
            let params = params(pad, mode, smoothing, background);
            let volume = Volume::new(&labels, dims).unwrap();
            let whole = extract_labels(volume, &params).unwrap();
            assert!(whole.stats.triangles > 500);
            assert!(whole.stats.merged > 0 || mode == Mode::Steps123, "{mode:?}");
            for (slab, block_layers) in [
                (1, 1),
                (1, 3),
                (2, 1),
                (3, 5),
                (4, 16),
                (7, 2),
                (23, 1),
                (30, 16),
            ] {
                let atlas = streamed(&labels, dims, &params, slab, block_layers);
                assert!(
                    atlas == whole,
                    "pad {pad}, {mode:?}, smoothing {smoothing}, background {background}, \
                     slabs of {slab}, blocks of {block_layers}"
                );
            }
        }
    }

    /// Volumes too thin for any cube, and a single slice, stream to the whole volume's atlas.
    #[test]
    fn thin_volumes_stream_too() {
        for dims in [[1, 1, 1], [5, 4, 1], [1, 6, 5], [3, 3, 2]] {
            let labels = volume(dims, 9);
            for pad in [true, false] {
                let params = LabelParams {
                    pad,
                    threads: 1,
                    ..LabelParams::default()
                };
                let whole = extract_labels(Volume::new(&labels, dims).unwrap(), &params).unwrap();
                assert_eq!(
                    streamed(&labels, dims, &params, 1, 1),
                    whole,
                    "{dims:?} {pad}"
                );
            }
        }
    }
}
