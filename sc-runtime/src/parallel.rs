use std::sync::Mutex;
use std::vec;
use std::vec::Vec;

use rayon::prelude::*;

use crate::extract::{InMemory, has_cubes};
use crate::mesh::{OwnedScratch, Presized};
use crate::survey::{self, Survey};
use crate::sweep::Sweep;
use crate::{Error, Mesh, Params, Scalar, Stats, Volume};

/// Layers per chunk at least: a chunk re-reads up to three slices of its neighbour, so tiny
/// chunks waste work.
const MIN_CHUNK_LAYERS: usize = 8;

/// One chunk's output, with vertex ids local to the chunk. Ids below `first_plane` belong to the
/// previous chunk's last plane, which this chunk numbered but did not emit.
struct Part {
    mesh: Mesh,
    first_plane: u32,
}

/// Extracts the surface on `threads` threads (0 = all cores). The z range is cut into chunks of
/// layers; each chunk numbers vertices exactly as a full sweep would, offset by a constant, so
/// stitching is an addition and the mesh is byte-identical to [`crate::extract`]'s for any thread
/// count. `progress` is called with the number of z layers just finished.
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
    // A few chunks per thread, of about equal work, balance uneven surfaces without much
    // re-reading at the seams.
    let chunks = (workers * 2).min(layers.div_ceil(MIN_CHUNK_LAYERS)).max(1);
    let src = InMemory {
        data: volume.data(),
        nxy: dims[0] * dims[1],
    };
    let threshold = T::threshold(params.iso);
    let survey = Survey::from_sampled(
        (0..dims[2])
            .step_by(survey::SLICE_STEP)
            .collect::<Vec<_>>()
            .par_iter()
            .map_init(Vec::new, |signs, &z| {
                survey::sampled_slice(&src, dims, threshold, z, signs)
            })
            .collect(),
    );
    let bounds = balanced_bounds(&survey, dims, chunks);
    // The chunks' meshes and the workers' scratch are allocated here, not on the workers: glibc
    // gives each worker thread an arena of its own and returns what is freed there to the
    // kernel, so every extraction faulted those pages in again (on the MNI brain's white matter,
    // 3,100 page faults per two-thread extraction; 670 allocated here). One scratch per worker,
    // indexed by the worker's index, so that no two running chunks share one.
    let meshes: Vec<Mesh> = bounds
        .iter()
        .map(|&(z0, z1)| {
            let mut mesh = Mesh::default();
            mesh.reserve_for(survey.between(z0, z1 + 1), params.normals);
            mesh
        })
        .collect();
    let scratches = (0..workers)
        .map(|_| OwnedScratch::new(dims).map(Mutex::new))
        .collect::<Result<Vec<_>, _>>()?;
    let run = || {
        let parts: Vec<Result<Part, Error>> = bounds
            .par_iter()
            .zip(meshes)
            .map(|(&(z0, z1), mut mesh)| {
                // Each worker takes the scratch of its own index: the lock is never contended.
                // A poisoned lock means a worker panicked, and that panic is on its way.
                let slot = rayon::current_thread_index().unwrap_or(0) % scratches.len();
                let mut scratch = scratches[slot].lock().unwrap_or_else(|p| p.into_inner());
                let mut sweep = Sweep::<T>::new(dims, params, scratch.lend());
                let sink = &mut Presized(&mut mesh);
                sweep.start(z0, &src, sink, z0 == 0)?;
                let first_plane = if z0 == 0 { 0 } else { sweep.ids_used() };
                for k in z0..z1 {
                    sweep.layer(k, &src, sink)?;
                    progress(1);
                }
                mesh.stats = sweep.stats();
                Ok(Part { mesh, first_plane })
            })
            .collect();
        stitch(parts.into_iter().collect::<Result<Vec<_>, _>>()?)
    };
    match own_pool {
        Some(pool) => pool.install(run),
        None => run(),
    }
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

/// Concatenates chunk meshes, shifting each chunk's ids by its start in the global order. The
/// output is allocated zeroed (pages the kernel provides lazily) and filled in parallel.
fn stitch(parts: Vec<Part>) -> Result<Mesh, Error> {
    let total_v: usize = parts.iter().map(|p| p.mesh.positions.len()).sum();
    let total_n: usize = parts.iter().map(|p| p.mesh.normals.len()).sum();
    let total_t: usize = parts.iter().map(|p| p.mesh.triangles.len()).sum();
    if u32::try_from(total_v).is_err() {
        return Err(Error::TooManyVertices);
    }
    let mut out = Mesh {
        positions: vec![[0.0; 3]; total_v],
        normals: vec![[0.0; 3]; total_n],
        triangles: vec![[0; 3]; total_t],
        stats: Stats::default(),
    };
    out.advise_huge_pages();
    // Each chunk's destination slices, and the shift that makes its ids global: its id
    // `first_plane` is the first vertex it emitted.
    let mut jobs = Vec::with_capacity(parts.len());
    let (mut pos, mut nor, mut tri) = (
        &mut out.positions[..],
        &mut out.normals[..],
        &mut out.triangles[..],
    );
    let mut emitted = 0u32;
    for part in &parts {
        let m = &part.mesh;
        let (p, rest_p) = core::mem::take(&mut pos).split_at_mut(m.positions.len());
        let (n, rest_n) = core::mem::take(&mut nor).split_at_mut(m.normals.len());
        let (t, rest_t) = core::mem::take(&mut tri).split_at_mut(m.triangles.len());
        (pos, nor, tri) = (rest_p, rest_n, rest_t);
        jobs.push((part, p, n, t, emitted - part.first_plane));
        emitted += m.positions.len() as u32;
    }
    jobs.into_par_iter().for_each(|(part, p, n, t, shift)| {
        p.copy_from_slice(&part.mesh.positions);
        n.copy_from_slice(&part.mesh.normals);
        for (d, s) in t.iter_mut().zip(&part.mesh.triangles) {
            *d = s.map(|i| i + shift);
        }
    });
    out.stats = parts.iter().fold(Stats::default(), |s, p| s + p.mesh.stats);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::balanced_bounds;
    use crate::Scalar;
    use crate::extract::InMemory;
    use crate::survey::Survey;
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
}
