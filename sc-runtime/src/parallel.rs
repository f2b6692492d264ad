use std::vec;
use std::vec::Vec;

use rayon::prelude::*;

use crate::extract::{InMemory, has_cubes};
use crate::mesh::OwnedScratch;
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
    // A few chunks per thread balance uneven surfaces without much re-reading at the seams.
    let chunks = (workers * 2).min(layers.div_ceil(MIN_CHUNK_LAYERS)).max(1);
    let bounds: Vec<(usize, usize)> = (0..chunks)
        .map(|c| (c * layers / chunks, (c + 1) * layers / chunks))
        .collect();
    let src = InMemory {
        data: volume.data(),
        nxy: dims[0] * dims[1],
    };
    let run = || {
        let parts: Vec<Result<Part, Error>> = bounds
            .par_iter()
            // Scratch is reused by the chunks one worker runs, rather than faulted in per chunk.
            .map_init(
                || OwnedScratch::new(dims),
                |scratch, &(z0, z1)| {
                    let scratch = scratch.as_mut().map_err(|e| e.clone())?;
                    let mut mesh = Mesh::default();
                    let mut sweep = Sweep::<T>::new(dims, params, scratch.lend());
                    sweep.start(z0, &src, &mut mesh, z0 == 0)?;
                    let first_plane = if z0 == 0 { 0 } else { sweep.ids_used() };
                    for k in z0..z1 {
                        sweep.layer(k, &src, &mut mesh)?;
                        progress(1);
                    }
                    mesh.stats = sweep.stats();
                    Ok(Part { mesh, first_plane })
                },
            )
            .collect();
        stitch(parts.into_iter().collect::<Result<Vec<_>, _>>()?)
    };
    match own_pool {
        Some(pool) => pool.install(run),
        None => run(),
    }
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
