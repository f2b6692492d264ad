//! The bridge from a typed [`Grid`] to the generic extractor.

use std::path::Path;
use std::time::{Duration, Instant};

use sc_runtime::{
    ErrorBound, Mesh, Mode, Params, Scratch, SliceStreamer, Volume, block_samples, extract_block,
    extract_par,
};

use crate::distance::{self, Distance};
use crate::error::Result;
use crate::progress::{Progress, Silent};
use crate::read::stream::Stream;
use crate::separation;
use crate::shard::{MANIFEST_NAME, Manifest, ShardEntry, blocks, write_shard};
use crate::slabs::stream_blocks;
use crate::space::{Coordinates, World};
use crate::volume::{Grid, Range, Sample, cut};
use crate::{with_dtype, with_samples};

/// What to extract.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Request {
    /// Surface value in real units (after any rescale slope/intercept).
    pub iso: f64,
    /// Which steps run.
    pub mode: Mode,
    /// Whether to compute normals.
    pub normals: bool,
    /// Worker threads, 0 for all cores.
    pub threads: usize,
    /// Which coordinates the mesh is in.
    pub coordinates: Coordinates,
    /// The bound on Step 4's displacement of the surface, if any.
    pub max_error: Option<ErrorBound>,
    /// Adaptive mode's largest box, in cubes per side (its default if `None`).
    pub max_box: Option<u32>,
    /// Adaptive mode: whether boxes may leave samples on the wrong side of the surface.
    pub allow_wrong_side: bool,
}

impl Request {
    /// Embedded mode with normals on all cores: what a user wants unless they say otherwise.
    pub fn new(iso: f64) -> Self {
        Request {
            iso,
            mode: Mode::Embedded,
            normals: true,
            threads: 0,
            coordinates: Coordinates::Native,
            max_error: None,
            max_box: None,
            allow_wrong_side: false,
        }
    }
}

/// The runtime's parameters for `request` on `grid`: the iso value in stored units, and the
/// origin when the world map is a translation (otherwise the mesh is placed afterwards).
fn params(grid: &Grid, request: &Request, world: &World) -> Params {
    let mut params = Params::new(grid.scale.invert(request.iso));
    params.mode = request.mode;
    params.normals = request.normals;
    params.spacing = grid.spacing;
    params.max_error = request.max_error;
    params.max_box = request.max_box;
    params.allow_wrong_side = request.allow_wrong_side;
    if world.is_translation() {
        params.origin = world.offset;
    }
    params
}

/// The map from sample positions to the coordinates `request` asks for.
pub fn world(grid: &Grid, request: &Request) -> World {
    World::new(grid.frame, grid.origin, request.coordinates)
}

/// Extracts the surface of `grid` in world units: the scanner's world when the file places the
/// volume in one (see [`crate::space`]), otherwise index × spacing + origin.
pub fn extract(grid: &Grid, request: &Request, progress: &dyn Progress) -> Result<Mesh> {
    Ok(extract_measured(grid, request, false, progress)?.0)
}

/// What [`extract_measured`] measures of a mesh beside it, and how long measuring took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measures {
    /// Adaptive mode: the mesh's sampled symmetric distance to the Steps 1–3 surface of the
    /// same grid, in the units of the error bound it holds (world units, or grid steps for a
    /// bound in voxels), sampled every quarter grid step: what the bound promises, measured.
    /// `None` in the other modes, whose bound is not a distance between surfaces.
    pub distance: Option<Distance>,
    /// The samples on the wrong side of the mesh ([`separation`]), in every mode: adaptive mode
    /// keeps it 0 unless wrong sides are allowed, Steps 1–3 always does, and embedded and paper
    /// modes' merges can move samples across. `None` where a sample on the grid's border is
    /// filled: the surface is open there.
    pub wrong_side_samples: Option<u64>,
    /// The time measuring took.
    pub time: Duration,
}

/// [`extract`], and with `measure` also the figures of [`Measures`].
pub fn extract_measured(
    grid: &Grid,
    request: &Request,
    measure: bool,
    progress: &dyn Progress,
) -> Result<(Mesh, Option<Measures>)> {
    let world = world(grid, request);
    let params = params(grid, request, &world);
    progress.phase("meshing", grid.dims[2].saturating_sub(1) as u64);
    let mut mesh =
        with_samples!(&grid.samples, v => run(v, grid.dims, &params, request.threads, progress))?;
    let mut measured = None;
    if measure {
        progress.phase("measuring", 1);
        let clock = Instant::now();
        // Measured before any placement, where grid steps are `spacing` apart along each axis.
        let wrong_side_samples = with_samples!(&grid.samples, v => {
            separation::wrong_side_samples(&Volume::new(v, grid.dims)?, &params, &mesh)
        });
        let distance = if params.mode == Mode::Adaptive {
            Some(distance_to_steps123(grid, &params, request, &mesh)?)
        } else {
            None
        };
        measured = Some(Measures {
            distance,
            wrong_side_samples,
            time: clock.elapsed(),
        });
        progress.inc(1);
    }
    if !world.is_translation() {
        world.place(&mut mesh);
    }
    Ok((mesh, measured))
}

/// [`Measures::distance`] of an adaptive mesh not yet placed in the world.
fn distance_to_steps123(
    grid: &Grid,
    params: &Params,
    request: &Request,
    mesh: &Mesh,
) -> Result<Distance> {
    let steps123 = Params {
        mode: Mode::Steps123,
        normals: false,
        max_error: None,
        max_box: None,
        allow_wrong_side: false,
        ..*params
    };
    let reference =
        with_samples!(&grid.samples, v => run(v, grid.dims, &steps123, request.threads, &Silent))?;
    let least = params.spacing.iter().copied().fold(f64::INFINITY, f64::min);
    let (scale, step) = match request.max_error {
        Some(ErrorBound::Voxels(_)) => (params.spacing.map(|s| 1.0 / s), 0.25),
        _ => ([1.0; 3], 0.25 * least),
    };
    Ok(distance::symmetric(
        (&mesh.positions, &mesh.triangles),
        (&reference.positions, &reference.triangles),
        scale,
        step,
    ))
}

/// Extracts the surface of a volume read slab by slab: the same mesh as [`extract`] of the
/// whole volume, holding a few slices instead of all of them (in adaptive mode, a block of
/// slices with its halo: up to some 250 slices with boxes of 16), on one thread.
pub fn extract_stream(
    stream: &mut Stream,
    request: &Request,
    progress: &dyn Progress,
) -> Result<Mesh> {
    let grid = &stream.grid;
    let world = world(grid, request);
    let params = params(grid, request, &world);
    progress.phase("meshing", grid.dims[2] as u64);
    let mut mesh =
        with_dtype!(grid.samples.dtype(), T => stream_typed::<T>(stream, &params, progress))?;
    if !world.is_translation() {
        world.place(&mut mesh);
    }
    Ok(mesh)
}

/// Extracts the surface of `grid` as shards in the directory `dir` (made if missing): blocks
/// of `block`³ cubes, each meshed on its own and written to its own file, then the manifest
/// [`crate::shard::merge`] joins them by. Meant for testing and for splitting work by hand;
/// volumes too large for one machine are split by the Dask driver instead.
pub fn extract_shards(
    grid: &Grid,
    request: &Request,
    block: usize,
    dir: &Path,
    progress: &dyn Progress,
) -> Result<Manifest> {
    let world = world(grid, request);
    let params = params(grid, request, &world);
    let mut manifest = Manifest::new(grid.dims, &params);
    manifest.world = world;
    std::fs::create_dir_all(dir).map_err(|e| crate::Error::io(dir, e))?;
    let cubes = grid.dims.map(|n| n.saturating_sub(1));
    progress.phase("meshing", blocks(cubes, block).count() as u64);
    for cubes in blocks(cubes, block) {
        let mesh =
            with_samples!(&grid.samples, v => block_of(v, grid.dims, cubes.clone(), &params))?;
        let file = ShardEntry::file_name(&cubes);
        write_shard(&dir.join(&file), &mesh, &manifest.settings)?;
        manifest.shards.push(ShardEntry::new(file, cubes, &mesh));
        progress.inc(1);
    }
    manifest.write(&dir.join(MANIFEST_NAME))?;
    Ok(manifest)
}

/// Meshes the block of cubes `cubes` from a copy of the samples it reads.
fn block_of<T: Sample>(
    data: &[T],
    dims: [usize; 3],
    cubes: [core::ops::Range<usize>; 3],
    params: &Params,
) -> Result<sc_runtime::BlockMesh> {
    let need = block_samples(dims, cubes.clone(), params)?;
    let samples = cut(data, dims, &need);
    let box_dims = need.clone().map(|r| r.len());
    let volume = Volume::new(&samples, box_dims)?;
    Ok(extract_block(
        &volume,
        need.map(|r| r.start),
        dims,
        cubes,
        params,
    )?)
}

fn stream_typed<T: Sample>(
    stream: &mut Stream,
    params: &Params,
    progress: &dyn Progress,
) -> Result<Mesh> {
    if params.mode == Mode::Adaptive {
        return stream_boxes::<T>(stream, params, progress);
    }
    let dims = stream.grid.dims;
    let nxy = dims[0] * dims[1];
    let len = Scratch::len(dims)?;
    let (mut bytes, mut words) = (vec![0u8; len.bytes], vec![0u32; len.words]);
    let mut ring = vec![T::zeroed(); SliceStreamer::<T, Mesh>::ring_len(dims)];
    let scratch = Scratch::new(&mut bytes, &mut words, dims)?;
    let mut streamer = SliceStreamer::new(dims, params, scratch, &mut ring, Mesh::default())?;
    let per_slab = stream.slab();
    let mut done = 0;
    while done < dims[2] {
        let slab = stream.read::<T>(per_slab)?;
        for slice in slab.chunks_exact(nxy) {
            streamer.push(slice)?;
        }
        let n = slab.len() / nxy;
        done += n;
        progress.inc(n as u64);
    }
    let (mut mesh, stats) = streamer.finish()?;
    mesh.stats = stats;
    Ok(mesh)
}

/// Adaptive mode's surface of a volume read slab by slab, in blocks of whole cube layers
/// ([`crate::slabs`]): a cube layer's boxes and their balancing read up to `2 × max_box + 2`
/// cubes before it and `3 × max_box + 2` past it, rounded out to whole boxes (115 slices with
/// boxes of 16), far more than the slice streamer holds. Each block is at least as thick as
/// that halo, so that it sweeps at most about twice the cubes it owns.
fn stream_boxes<T: Sample>(
    stream: &mut Stream,
    params: &Params,
    progress: &dyn Progress,
) -> Result<Mesh> {
    let dims = stream.grid.dims;
    let cubes = dims.map(|n| n.saturating_sub(1));
    let halo = if cubes.contains(&0) {
        0
    } else {
        let middle = cubes[2] / 2;
        let layer = [0..cubes[0], 0..cubes[1], middle..middle + 1];
        block_samples(dims, layer, params)?[2].len()
    };
    let slab = stream.slab();
    let next = || stream.read::<T>(slab);
    let share = stream_blocks(params, dims, halo.max(16), next, progress)?;
    Ok(share.into_mesh()?)
}

fn run<T: Sample>(
    data: &[T],
    dims: [usize; 3],
    params: &Params,
    threads: usize,
    progress: &dyn Progress,
) -> Result<Mesh> {
    let volume = Volume::new(data, dims)?;
    Ok(extract_par(&volume, params, threads, &|layers| {
        progress.inc(layers as u64)
    })?)
}

/// Why no sample can be on both sides of `iso`, if that is so: then the mesh is empty, which a
/// user almost always wants to hear about.
pub fn why_empty(range: &Range, iso: f64) -> Option<String> {
    if range.finite == 0 {
        Some(if range.nan > 0 {
            "every sample is NaN".into()
        } else {
            "the volume has no finite sample".into()
        })
    } else if iso > range.max {
        Some(format!(
            "iso {iso} is above the largest sample, {}",
            range.max
        ))
    } else if iso <= range.min && range.nan == 0 {
        Some(format!(
            "iso {iso} is at or below the smallest sample, {}: every sample is inside",
            range.min
        ))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_cases_are_explained() {
        let r = Range {
            min: 0.0,
            max: 10.0,
            finite: 5,
            nan: 0,
        };
        assert!(why_empty(&r, 11.0).unwrap().contains("above"));
        assert!(why_empty(&r, 0.0).unwrap().contains("below"));
        assert_eq!(why_empty(&r, 5.0), None);
        let nan = Range {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            finite: 0,
            nan: 8,
        };
        assert!(why_empty(&nan, 0.0).unwrap().contains("NaN"));
    }
}
