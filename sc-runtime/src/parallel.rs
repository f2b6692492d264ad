use std::sync::Mutex;
use std::vec;
use std::vec::Vec;

use rayon::prelude::*;

use crate::extract::{InMemory, has_cubes};
use crate::mesh::{push_to_columns, release_spare};
use crate::region::{self, Filled, Stretch};
use crate::spare::SPARES;
use crate::survey::{self, Survey};
use crate::sweep::Sweep;
use crate::{Error, Mesh, Params, Scalar, Sink, Stats, Volume};

/// Layers per chunk at least: a chunk re-reads up to three slices of its neighbour, so tiny
/// chunks waste work.
const MIN_CHUNK_LAYERS: usize = 8;

/// Where a chunk writes: its stretches of the output's vectors.
struct Region<'a> {
    positions: Stretch<'a, [f32; 3]>,
    normals: Stretch<'a, [f32; 3]>,
    values: Stretch<'a, f32>,
    triangles: Stretch<'a, [u32; 3]>,
}

impl Sink for Region<'_> {
    push_to_columns!();
}

/// One chunk's output, with vertex ids local to the chunk. Ids below `first_plane` belong to the
/// previous chunk's last plane, which this chunk numbered but did not emit.
struct Part {
    positions: Filled<[f32; 3]>,
    normals: Filled<[f32; 3]>,
    values: Filled<f32>,
    triangles: Filled<[u32; 3]>,
    vertices: usize,
    first_plane: u32,
    stats: Stats,
}

/// Extracts the surface on `threads` threads (0 = all cores). The z range is cut into chunks of
/// layers; each chunk numbers vertices exactly as a full sweep would, offset by a constant, so
/// stitching is an addition and the mesh is byte-identical to [`crate::extract`]'s for any thread
/// count. `progress` is called with the number of z layers just finished.
///
/// Each thread's scratch (about 13 bytes per sample of one z-slice) is kept for the next
/// extraction, this one's or [`crate::extract`]'s, up to 64 MiB in all: allocated afresh, it
/// made glibc hand the heap back to the kernel after every call and fault it in again on the
/// next, which doubled the time of small extractions.
///
/// ```
/// use sc_runtime::{Params, Volume, demo, extract, extract_par};
///
/// let v = demo::torus(32);
/// let vol = Volume::new(&v.data, v.dims).unwrap();
/// let params = Params::new(v.iso);
/// assert_eq!(extract_par(&vol, &params, 3, &|_| {}).unwrap(), extract(&vol, &params).unwrap());
/// ```
pub fn extract_par<T: Scalar>(
    volume: &Volume<'_, T>,
    params: &Params,
    threads: usize,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Mesh, Error> {
    let dims = volume.dims();
    if !has_cubes(dims) {
        return Ok(Mesh::default());
    }
    if threads == 1 {
        // No pool, no chunks, no stitching copy.
        let mesh = crate::extract(volume, params)?;
        progress(dims[2] - 1);
        return Ok(mesh);
    }
    // Rayon's global pool when it has the threads asked for: building a pool starts threads,
    // which costs a noticeable share of a small volume's extraction.
    let own_pool = if threads == 0 || threads == rayon::current_num_threads() {
        None
    } else {
        Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|_| Error::ThreadPool)?,
        )
    };
    let layers = dims[2] - 1;
    let workers = own_pool
        .as_ref()
        .map_or_else(rayon::current_num_threads, |p| p.current_num_threads());
    let chunks = chunk_count(layers, workers);
    let src = InMemory {
        data: volume.data(),
        nxy: dims[0] * dims[1],
    };
    let threshold = T::threshold(params.iso);
    let step = survey::slice_step(dims[2], chunks);
    let survey = Survey::from_sampled(
        step,
        (0..dims[2])
            .step_by(step)
            .collect::<Vec<_>>()
            .par_iter()
            .map_init(Vec::new, |signs, &z| {
                survey::sampled_slice(&src, dims, threshold, z, signs)
            })
            .collect(),
    );
    let bounds = balanced_bounds(&survey, dims, chunks);
    // One output, each chunk writing into its own stretch of it (see `region`), and scratch
    // from the spares: an extraction allocates what a one-thread one does. Both are taken here,
    // not on the workers: glibc gives each worker thread an arena of its own and returns what
    // is freed there to the kernel. One scratch per worker, indexed by the worker's index, so
    // that no two running chunks share one.
    let room: Vec<usize> = bounds
        .iter()
        .map(|&(z0, z1)| Mesh::room_for(survey.between(z0, z1 + 1)))
        .collect();
    let room_if = |asked: bool| {
        if asked {
            room.clone()
        } else {
            vec![0; room.len()]
        }
    };
    let (normal_room, value_room) = (room_if(params.normals), room_if(params.values));
    let triangle_room: Vec<usize> = room.iter().map(|&v| Mesh::triangle_room(v)).collect();
    let mut out = Mesh::default();
    let regions: Vec<Region<'_>> = region::stretches(&mut out.positions, &room)
        .into_iter()
        .zip(region::stretches(&mut out.normals, &normal_room))
        .zip(region::stretches(&mut out.values, &value_room))
        .zip(region::stretches(&mut out.triangles, &triangle_room))
        .map(|(((positions, normals), values), triangles)| Region {
            positions,
            normals,
            values,
            triangles,
        })
        .collect();
    let scratches = (0..workers)
        .map(|_| SPARES.take(dims).map(Mutex::new))
        .collect::<Result<Vec<_>, _>>()?;
    let run = || {
        bounds
            .par_iter()
            .zip(regions)
            .map(|(&(z0, z1), mut region)| {
                // Each worker takes the scratch of its own index: the lock is never contended.
                // A poisoned lock means a worker panicked, and that panic is on its way.
                let slot = rayon::current_thread_index().unwrap_or(0) % scratches.len();
                let mut scratch = scratches[slot].lock().unwrap_or_else(|p| p.into_inner());
                let mut sweep = Sweep::<T>::new(dims, params, scratch.lend());
                sweep.start(z0, &src, &mut region, z0 == 0)?;
                let first_plane = if z0 == 0 { 0 } else { sweep.ids_used() };
                for k in z0..z1 {
                    sweep.layer(k, &src, &mut region)?;
                    progress(1);
                }
                Ok(Part {
                    vertices: region.positions.len(),
                    positions: region.positions.finish(),
                    normals: region.normals.finish(),
                    values: region.values.finish(),
                    triangles: region.triangles.finish(),
                    first_plane,
                    stats: sweep.stats(),
                })
            })
            .collect::<Result<Vec<Part>, Error>>()
    };
    let parts = in_pool(own_pool.as_ref(), run);
    for scratch in scratches {
        SPARES.give(scratch.into_inner().unwrap_or_else(|p| p.into_inner()));
    }
    let parts = parts?;
    in_pool(own_pool.as_ref(), || stitch(&mut out, parts))?;
    Ok(out)
}

/// Runs `job` in `pool`, or in rayon's global pool (which has the threads asked for) when there
/// is none.
fn in_pool<R: Send>(pool: Option<&rayon::ThreadPool>, job: impl FnOnce() -> R + Send) -> R {
    match pool {
        Some(pool) => pool.install(job),
        None => job(),
    }
}

/// One chunk per thread, of about equal work ([`balanced_bounds`]), and fewer chunks than threads
/// when chunks would get fewer than [`MIN_CHUNK_LAYERS`]. Two per thread had balanced uneven
/// surfaces when each sampled slice stood for the slices after it; with the estimate
/// interpolated, they no longer finish apart, and every chunk after the first is moved when the
/// output is joined and re-reads a plane at its seam: one per thread took 0.87–1.00× the time of
/// two (`time_extract --threads 2`, two runs of alternating rounds on six volumes).
fn chunk_count(layers: usize, workers: usize) -> usize {
    layers.div_ceil(MIN_CHUNK_LAYERS).clamp(1, workers)
}

/// What one estimated vertex costs, in units of one sample's fixed cost (classifying it, its
/// cube's case, scanning its row): some hundred times more (`bench/profile.sh`).
const VERTEX_WEIGHT: usize = 100;

/// Cuts the z layers into `chunks` runs of about equal work: a layer's samples plus its
/// surface, as the survey estimates it. Equal ranges of layers left one thread meshing the MNI
/// brain's white matter band alone (a chunk with half the triangles), and two threads were no
/// faster than one.
fn balanced_bounds(survey: &Survey, dims: [usize; 3], chunks: usize) -> Vec<(usize, usize)> {
    let [nx, ny, nz] = dims;
    let layers = nz - 1;
    let cost = |k: usize| nx * ny + VERTEX_WEIGHT * survey.at(k);
    let total: usize = (0..layers).map(cost).sum();
    let mut bounds = Vec::with_capacity(chunks);
    let (mut start, mut done) = (0, 0);
    for k in 0..layers {
        done += cost(k);
        // Chunk `c` ends at the first layer where the work so far reaches its share.
        if done * chunks >= total * (bounds.len() + 1) && bounds.len() + 1 < chunks {
            bounds.push((start, k + 1));
            start = k + 1;
        }
    }
    bounds.push((start, layers));
    bounds
}

/// Joins the chunks' stretches of `out`, shifting each chunk's ids by its start in the global
/// order: its id `first_plane` is the first vertex it emitted.
fn stitch(out: &mut Mesh, parts: Vec<Part>) -> Result<(), Error> {
    let total_v: usize = parts.iter().map(|p| p.vertices).sum();
    if u32::try_from(total_v).is_err() {
        return Err(Error::TooManyVertices);
    }
    out.stats = parts.iter().fold(Stats::default(), |s, p| s + p.stats);
    let mut emitted = 0u32;
    let mut shifts = Vec::with_capacity(parts.len());
    let (mut positions, mut normals, mut values, mut triangles) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for p in parts {
        shifts.push(emitted - p.first_plane);
        emitted += p.vertices as u32;
        positions.push(p.positions);
        normals.push(p.normals);
        values.push(p.values);
        triangles.push(p.triangles);
    }
    // The triangles on one thread, the vertices' vectors on another: the joins are copies of
    // memory, and on large meshes they were a sixth of a two-thread extraction (the stent CT
    // upsampled to 256³ at its skin: 21 of 128 ms).
    let Mesh {
        positions: p,
        normals: n,
        values: v,
        triangles: t,
        ..
    } = out;
    // SAFETY (both sides): each list is the finished stretches of its vector, all of them, in
    // order (one part per stretch, as `extract_par` made them), and nothing touched the vectors
    // since; the two sides join different vectors.
    rayon::join(
        || unsafe {
            let written = region::join(p, &positions, |_, _| {});
            release_spare(p, written);
            let written = region::join(n, &normals, |_, _| {});
            release_spare(n, written);
            let written = region::join(v, &values, |_, _| {});
            release_spare(v, written);
        },
        || unsafe {
            // The first part's shift is zero: it stays where it is, untouched.
            let written = region::join(t, &triangles, |i, t| {
                if shifts[i] != 0 {
                    t.as_flattened_mut()
                        .iter_mut()
                        .for_each(|v| *v += shifts[i]);
                }
            });
            release_spare(t, written);
        },
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{MIN_CHUNK_LAYERS, balanced_bounds, chunk_count};
    use crate::Scalar;
    use crate::extract::InMemory;
    use crate::survey::Survey;
    use std::format;
    use std::vec::Vec;

    /// All of the surface lies in ten slices in the middle of 101: the chunks cover every layer
    /// once, in order, and most of them go to the band, where equal ranges of layers would give
    /// it two of four.
    #[test]
    fn chunks_split_the_surface_not_the_layers() {
        let dims = [32, 32, 101];
        let band = 45..55;
        let data: Vec<u8> = (0..dims.iter().product::<usize>())
            .map(|i| {
                let (x, z) = (i % 32, i / (32 * 32));
                u8::from(band.contains(&z) && x % 2 == 0)
            })
            .collect();
        let src = InMemory {
            data: &data,
            nxy: 32 * 32,
        };
        let survey = Survey::new(&src, dims, u8::threshold(0.5));
        let bounds = balanced_bounds(&survey, dims, 4);
        assert_eq!(bounds.len(), 4);
        assert_eq!(bounds.first().map(|b| b.0), Some(0));
        assert_eq!(bounds.last().map(|b| b.1), Some(100));
        assert!(bounds.windows(2).all(|w| w[0].1 == w[1].0));
        assert!(bounds.iter().all(|&(a, b)| a < b));
        let touching = bounds
            .iter()
            .filter(|&&(a, b)| a < band.end && band.start < b + 1)
            .count();
        assert!(touching >= 3, "{bounds:?}");
    }

    /// For every layer count up to 300 and 1 to 8 threads: one chunk per thread once every
    /// thread can have a chunk of [`MIN_CHUNK_LAYERS`], and chunks of that many layers on average
    /// otherwise (at least one).
    #[test]
    fn chunk_counts_give_each_thread_one() {
        for workers in 1..=8 {
            for layers in 1..=300 {
                let chunks = chunk_count(layers, workers);
                let at = format!("{layers} layers, {workers} threads: {chunks} chunks");
                if layers >= workers * MIN_CHUNK_LAYERS {
                    assert_eq!(chunks, workers, "{at}");
                } else {
                    assert!((1..=workers).contains(&chunks), "{at}");
                    assert!(
                        chunks == 1 || (chunks - 1) * MIN_CHUNK_LAYERS < layers,
                        "{at}"
                    );
                    assert!(chunks * MIN_CHUNK_LAYERS >= layers, "{at}");
                }
            }
        }
    }
}
