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
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|_| Error::ThreadPool)?;
    let layers = dims[2] - 1;
    let workers = pool.current_num_threads();
    // A few chunks per thread balance uneven surfaces without much re-reading at the seams.
    let chunks = (workers * 4).min(layers.div_ceil(MIN_CHUNK_LAYERS)).max(1);
    let bounds: Vec<(usize, usize)> = (0..chunks)
        .map(|c| (c * layers / chunks, (c + 1) * layers / chunks))
        .collect();
    let src = InMemory {
        data: volume.data(),
        nxy: dims[0] * dims[1],
    };
    let parts: Vec<Result<Part, Error>> = pool.install(|| {
        bounds
            .par_iter()
            .map(|&(z0, z1)| {
                let mut scratch = OwnedScratch::new(dims)?;
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
            })
            .collect()
    });
    stitch(parts.into_iter().collect::<Result<Vec<_>, _>>()?)
}

/// Concatenates chunk meshes, shifting each chunk's ids by its start in the global order.
fn stitch(parts: Vec<Part>) -> Result<Mesh, Error> {
    let mut out = Mesh::default();
    let total_v: usize = parts.iter().map(|p| p.mesh.positions.len()).sum();
    let total_t: usize = parts.iter().map(|p| p.mesh.triangles.len()).sum();
    if u32::try_from(total_v).is_err() {
        return Err(Error::TooManyVertices);
    }
    out.positions.reserve_exact(total_v);
    out.normals
        .reserve_exact(parts.iter().map(|p| p.mesh.normals.len()).sum());
    out.triangles.reserve_exact(total_t);
    let mut stats = Stats::default();
    for part in parts {
        // This chunk's id `first_plane` is the first vertex it emitted.
        let shift = out.positions.len() as u32 - part.first_plane;
        out.positions.extend_from_slice(&part.mesh.positions);
        out.normals.extend_from_slice(&part.mesh.normals);
        out.triangles
            .extend(part.mesh.triangles.iter().map(|t| t.map(|i| i + shift)));
        let s = part.mesh.stats;
        stats.v13 += s.v13;
        stats.t13 += s.t13;
        stats.merged += s.merged;
        stats.blocked += s.blocked;
        stats.vertices += s.vertices;
        stats.triangles += s.triangles;
    }
    out.stats = stats;
    Ok(out)
}
