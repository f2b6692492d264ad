//! The threads driver: z chunks of one volume swept on threads, into one output.

mod claims;
mod region;

use std::ops::Range;
use std::sync::Mutex;
use std::time::Instant;
use std::vec;
use std::vec::Vec;

use rayon::prelude::*;

use claims::{Claims, Progress};
use region::{Filled, Stretch};

use crate::Mode;
use crate::drivers::spare::SPARES;
use crate::drivers::survey::{self, Survey};
use crate::drivers::{InMemory, has_cubes};
use crate::drivers::{adaptive, reuse};
use crate::kernel::sink::Unsettled;
use crate::kernel::{Binary, Engine, Layers};
use crate::mesh::{OwnedScratch, push_to_columns, release_spare};
use crate::{Error, Mesh, Params, Scalar, Sink, Stats, Volume};

/// Layers per chunk at least: a chunk re-reads up to three slices of its neighbour, so tiny
/// chunks waste work.
const MIN_CHUNK_LAYERS: usize = 8;

/// Where a chunk writes: its stretches of the output's vectors. It scales normals a layer at a
/// time ([`Sink::settle_normals`]).
struct Region<'a> {
    positions: Stretch<'a, [f32; 3]>,
    normals: Stretch<'a, [f32; 3]>,
    values: Stretch<'a, f32>,
    triangles: Stretch<'a, [u32; 3]>,
    unsettled: Unsettled,
}

impl Sink for Region<'_> {
    push_to_columns!(values and triangles);

    #[inline]
    fn vertex(&mut self, position: [f32; 3], normal: Option<[f32; 3]>) {
        self.positions.push(position);
        if let Some(n) = normal {
            self.unsettled.push_unit(&mut self.normals, n);
        }
    }

    #[inline]
    fn edge_vertex_toward(
        &mut self,
        _: [usize; 3],
        _: usize,
        position: [f32; 3],
        toward: [f32; 3],
    ) {
        self.positions.push(position);
        self.normals.push(toward);
    }

    fn settle_normals(&mut self) {
        self.unsettled.settle(&mut self.normals);
    }
}

impl Region<'_> {
    /// Cuts this region after its own room for the layers `next..end` still to come (as
    /// [`extract_par`] sizes a chunk's, by the survey) and returns the rest: the room of the
    /// tail from `end` on, which a thief takes over.
    fn split_off(&mut self, survey: &Survey, next: usize, end: usize) -> Self {
        let vertices = Mesh::room_for(survey.between(next, end + 1));
        let keep = |len: usize| len + vertices;
        Region {
            positions: self.positions.split_off(keep(self.positions.len())),
            normals: self.normals.split_off(keep(self.normals.len())),
            values: self.values.split_off(keep(self.values.len())),
            triangles: self
                .triangles
                .split_off(self.triangles.len() + Mesh::triangle_room(vertices)),
            unsettled: Unsettled::default(),
        }
    }
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
    /// The part's first layer: parts are joined in this order.
    z0: usize,
}

/// Extracts the surface on `threads` threads (0 = all cores). The z range is cut into chunks of
/// layers; each chunk numbers vertices exactly as a full sweep would, offset by a constant, so
/// stitching is an addition and the mesh is byte-identical to [`crate::extract`]'s for any thread
/// count. `progress` is called with the number of z layers just finished.
///
/// Each thread's scratch (about 13 bytes per sample of one z-slice) is kept for the next
/// extraction, this one's or [`crate::extract`]'s, up to 64 MiB in all: allocated afresh, it
/// makes glibc hand the heap back to the kernel after every call and fault it in again on the
/// next, which can double the time of small extractions.
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
    if params.mode == Mode::Adaptive {
        let mesh = if threads == 1 {
            adaptive::extract(volume, params, &adaptive::InOrder)?
        } else {
            let pool = pool_for(threads)?;
            in_pool(pool.as_ref(), || adaptive::extract(volume, params, &OnPool))?
        };
        progress(volume.dims()[2].saturating_sub(1));
        return Ok(mesh);
    }
    super::not_adaptive(params, "")?;
    sweep_par(&Binary::new(params), volume, params, threads, progress)
}

/// [`extract_par`] with any engine.
pub(crate) fn sweep_par<T: Scalar>(
    engine: &impl Engine<T>,
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
        let mesh = reuse::sweep(engine, volume, params)?;
        progress(dims[2] - 1);
        return Ok(mesh);
    }
    let own_pool = pool_for(threads)?;
    let layers = dims[2] - 1;
    let workers = own_pool
        .as_ref()
        .map_or_else(rayon::current_num_threads, |p| p.current_num_threads());
    let chunks = chunk_count(layers, workers);
    let src = InMemory::new(volume);
    let step = survey::slice_step(dims[2], chunks);
    let survey = Survey::from_sampled(
        step,
        (0..dims[2])
            .step_by(step)
            .collect::<Vec<_>>()
            .par_iter()
            .map_init(Vec::new, |signs, &z| {
                survey::sampled_slice(&src, dims, engine, z, signs)
            })
            .collect(),
    );
    let work = layer_work(&survey, dims);
    let bounds = balanced_bounds(&work, chunks);
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
            unsettled: Unsettled::default(),
        })
        .collect();
    let scratches = (0..workers)
        .map(|_| SPARES.take(dims).map(Mutex::new))
        .collect::<Result<Vec<_>, _>>()?;
    // Each chunk's worker claims its layers one by one, so that a worker done with its own can
    // take over the tail of another's (see `claims`).
    let claims: Vec<Claims<Region<'_>>> = bounds.iter().map(|&b| Claims::new(b)).collect();
    let run = || {
        bounds
            .par_iter()
            .zip(regions)
            .enumerate()
            .map(|(c, (&(z0, _), region))| {
                // Each worker takes the scratch of its own index: the lock is never contended.
                // A poisoned lock means a worker panicked, and that panic is on its way.
                let slot = rayon::current_thread_index().unwrap_or(0) % scratches.len();
                let mut scratch = scratches[slot].lock().unwrap_or_else(|p| p.into_inner());
                let began = Instant::now();
                // Where the worker's own layers ended: at `z1`, or where a thief cut them.
                let mut own_end = z0;
                let own = {
                    let _worker = claims[c].begin();
                    let own = &claims[c];
                    sweep_part(
                        &mut scratch,
                        (engine, &src, dims, params),
                        z0,
                        region,
                        progress,
                        |r| {
                            let k = own.claim(|next, end| r.split_off(&survey, next, end));
                            own_end = k.map_or(own_end, |k| k + 1);
                            k
                        },
                    )?
                };
                let mut parts = vec![own];
                let mut done = work[own_end] - work[z0];
                let thief = |done| (done, began.elapsed().as_secs_f64());
                while let Some((victim, (at, end))) = steal(&claims, &work, thief(done)) {
                    let Some(room) = claims[victim].take() else {
                        break;
                    };
                    let mut layers = at..end;
                    let src = (engine, &src, dims, params);
                    parts.push(sweep_part(&mut scratch, src, at, room, progress, |_| {
                        layers.next()
                    })?);
                    done += work[end] - work[at];
                }
                Ok(parts)
            })
            .collect::<Result<Vec<Vec<Part>>, Error>>()
    };
    let parts = in_pool(own_pool.as_ref(), run);
    for scratch in scratches {
        SPARES.give(scratch.into_inner().unwrap_or_else(|p| p.into_inner()));
    }
    let mut parts: Vec<Part> = parts?.into_iter().flatten().collect();
    parts.sort_unstable_by_key(|p| p.z0);
    in_pool(own_pool.as_ref(), || stitch(&mut out, parts))?;
    Ok(out)
}

/// Sweeps the layers `next` hands out, from `z0` on, into `region`.
fn sweep_part<'r, T: Scalar, E: Engine<T>>(
    scratch: &mut OwnedScratch,
    (engine, src, dims, params): (&E, &InMemory<'_, T>, [usize; 3], &Params),
    z0: usize,
    mut region: Region<'r>,
    progress: &(dyn Fn(usize) + Sync),
    mut next: impl FnMut(&mut Region<'r>) -> Option<usize>,
) -> Result<Part, Error> {
    let mut sweep = engine.sweep(dims, params, scratch.lend());
    sweep.start(z0, src, &mut region, z0 == 0)?;
    let first_plane = if z0 == 0 { 0 } else { sweep.ids_used() };
    while let Some(k) = next(&mut region) {
        sweep.layer(k, src, &mut region)?;
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
        z0,
    })
}

/// A tail to take over, for a worker that has done `work` in `seconds`: of the chunk with the
/// most work left, cut where [`cut`] says. Returns the chunk and the tail's layers.
fn steal<R>(
    claims: &[Claims<R>],
    work: &[usize],
    thief: (usize, f64),
) -> Option<(usize, (usize, usize))> {
    let (victim, _) = claims
        .iter()
        .enumerate()
        .filter_map(|(c, claims)| claims.left().map(|(next, end)| (c, work[end] - work[next])))
        .max_by_key(|&(_, left)| left)?;
    let tail = claims[victim].steal(|p| cut(work, thief, &p))?;
    Some((victim, tail))
}

/// A tail shorter than this is left to its chunk: taking it over costs a seam (the tail's first
/// plane classified and numbered again), about a layer's work.
const MIN_TAIL: usize = 2;

/// Where a thief that did `work` in `seconds` cuts a chunk: so that both finish together if each
/// keeps the speed it has shown (half the work left, before the chunk's worker has claimed a
/// layer). `None` if the tail would have fewer than [`MIN_TAIL`] layers.
fn cut(work: &[usize], (did, seconds): (usize, f64), p: &Progress) -> Option<usize> {
    // The worker keeps at least the layer after the one under way.
    let from = p.next + 1;
    if from + MIN_TAIL > p.end {
        return None;
    }
    // Layer `next - 1` is under way, and counted as done: a worker that has not finished its
    // first layer when the thief has finished a chunk is slow, but not as slow as nothing.
    let done = work[p.next] - work[p.start];
    let left = (work[p.end] - work[p.next]) as f64;
    let share = if done == 0 {
        left / 2.0
    } else {
        let (thief, worker) = (did as f64 / seconds, done as f64 / p.seconds);
        left * thief / (thief + worker)
    };
    if !share.is_finite() {
        return None;
    }
    // The first layer from which the tail's work is at most the thief's share.
    let at = from + work[from..p.end].partition_point(|&w| (work[p.end] - w) as f64 > share);
    (at + MIN_TAIL <= p.end).then_some(at)
}

/// A pool of `threads` threads (0 = all cores), or none when rayon's global pool has that many:
/// building a pool starts threads, which costs a noticeable share of a small volume's
/// extraction.
fn pool_for(threads: usize) -> Result<Option<rayon::ThreadPool>, Error> {
    if threads == 0 || threads == rayon::current_num_threads() {
        return Ok(None);
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map(Some)
        .map_err(|_| Error::ThreadPool)
}

/// Adaptive mode's boxes shared out over the current pool, in ranges of at least 64 boxes and
/// some 16 per thread: boxes differ widely in cost (most are empty), so many ranges balance the
/// work, and each range reuses one buffer.
struct OnPool;

impl adaptive::Spread for OnPool {
    fn ranges<R: Send>(&self, n: usize, f: impl Fn(Range<usize>) -> R + Sync) -> Vec<R> {
        let chunk = n.div_ceil(16 * rayon::current_num_threads()).max(64);
        (0..n.div_ceil(chunk))
            .into_par_iter()
            .map(|k| f(k * chunk..n.min((k + 1) * chunk)))
            .collect()
    }
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
/// when chunks would get fewer than [`MIN_CHUNK_LAYERS`]. More chunks would not balance the
/// work better (the survey's estimate is interpolated, and a slow thread's tail is taken over,
/// see `claims`), and every chunk after the first costs a move when the output is joined and a
/// plane re-read at its seam.
fn chunk_count(layers: usize, workers: usize) -> usize {
    layers.div_ceil(MIN_CHUNK_LAYERS).clamp(1, workers)
}

/// What one estimated vertex costs, in units of one sample's fixed cost (classifying it, its
/// cube's case, scanning its row): some hundred times more (`bench/profile.sh`).
const VERTEX_WEIGHT: usize = 100;

/// The work of layers `0..k` for every `k` up to the layer count: a layer's samples plus its
/// surface, as the survey estimates it.
fn layer_work(survey: &Survey, dims: [usize; 3]) -> Vec<usize> {
    let [nx, ny, nz] = dims;
    let mut sum = 0;
    core::iter::once(0)
        .chain((0..nz - 1).map(|k| {
            sum += nx * ny + VERTEX_WEIGHT * survey.at(k);
            sum
        }))
        .collect()
}

/// Cuts the layers into `chunks` runs of about equal [`layer_work`]. Equal ranges of layers left
/// one thread meshing the MNI brain's white matter band alone (a chunk with half the
/// triangles), and two threads were no faster than one.
fn balanced_bounds(work: &[usize], chunks: usize) -> Vec<(usize, usize)> {
    let layers = work.len() - 1;
    let total = work[layers];
    let mut bounds = Vec::with_capacity(chunks);
    let mut start = 0;
    for k in 0..layers {
        // Chunk `c` ends at the first layer where the work so far reaches its share.
        if work[k + 1] * chunks >= total * (bounds.len() + 1) && bounds.len() + 1 < chunks {
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
    // The triangles beside the vertices' vectors, each join on every thread (`region::join`):
    // the joins are copies of memory, a large share of a two-thread extraction of a large mesh
    // when one thread does them all.
    let Mesh {
        positions: p,
        normals: n,
        values: v,
        triangles: t,
        ..
    } = out;
    // SAFETY (both sides): each list is the finished stretches of its vector, all of them: the
    // chunks' and the tails' split off them, in the order of their starts (the parts are sorted
    // by first layer, and a tail's stretch is the end of its chunk's), and nothing touched the
    // vectors since; the two sides join different vectors.
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
    use super::claims::Progress;
    use super::{MIN_CHUNK_LAYERS, MIN_TAIL, balanced_bounds, chunk_count, cut};
    use crate::drivers::InMemory;
    use crate::drivers::survey::Survey;
    use crate::kernel::Binary;
    use crate::{Mode, Params, Volume, demo, extract, extract_par};
    use std::format;
    use std::sync::OnceLock;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::thread::{self, ThreadId};
    use std::time::Duration;
    use std::vec::Vec;

    /// One thread sleeps after each of its layers, as a slow vCPU would be slow: the other
    /// finishes its chunk and takes over most of the slow one's, and the mesh is still exactly
    /// the one-thread mesh, in every mode, with and without normals.
    #[test]
    fn a_slow_thread_s_tail_is_taken_over() {
        let v = demo::torus(40);
        let vol = Volume::new(&v.data, v.dims).unwrap();
        let layers = v.dims[2] - 1;
        for mode in [Mode::Steps123, Mode::Paper, Mode::Embedded] {
            for normals in [false, true] {
                let params = Params {
                    mode,
                    normals,
                    ..Params::new(v.iso)
                };
                // The first thread to finish a layer is the slow one.
                let slow: OnceLock<ThreadId> = OnceLock::new();
                let (slow_layers, all) = (AtomicUsize::new(0), AtomicUsize::new(0));
                let progress = |n: usize| {
                    all.fetch_add(n, Ordering::Relaxed);
                    if *slow.get_or_init(|| thread::current().id()) == thread::current().id() {
                        slow_layers.fetch_add(n, Ordering::Relaxed);
                        thread::sleep(Duration::from_millis(5));
                    }
                };
                let mesh = extract_par(&vol, &params, 2, &progress).unwrap();
                assert_eq!(mesh, extract(&vol, &params).unwrap(), "{mode:?} {normals}");
                assert_eq!(all.into_inner(), layers);
                // Its own chunk was about half the layers.
                let slow_layers = slow_layers.into_inner();
                assert!(
                    slow_layers <= layers / 4,
                    "{slow_layers} of {layers} layers"
                );
            }
        }
    }

    /// The cut gives the thief the share of the work left that its speed says: all layers of
    /// equal work, a thief twice as fast as the chunk's worker takes two thirds; before the
    /// worker has claimed a layer, half; a tail of fewer than `MIN_TAIL` layers is not cut.
    #[test]
    fn cuts_share_the_work_by_speed() {
        let work: Vec<usize> = (0..=40).map(|k| 10 * k).collect();
        let at = |start: usize, next: usize, end: usize, seconds: f64| Progress {
            start,
            next,
            end,
            seconds,
        };
        // The worker began at 10 and has done 10..16 (15 under way) in 1.2 seconds; the
        // thief did 10 layers in a second, twice as fast. Of the 24 layers left it takes 16.
        assert_eq!(cut(&work, (100, 1.0), &at(10, 16, 40, 1.2)), Some(24));
        // No layer claimed: half of what is left.
        assert_eq!(cut(&work, (100, 1.0), &at(10, 10, 30, 0.001)), Some(20));
        // A first layer under way for a long time: the thief takes all but the next one.
        assert_eq!(cut(&work, (100, 0.001), &at(10, 11, 30, 1.0)), Some(12));
        // Equal speeds, 2 · MIN_TAIL layers left: cut in the middle.
        let end = 20 + 2 * MIN_TAIL;
        assert_eq!(
            cut(&work, (200, 1.0), &at(0, 20, end, 1.0)),
            Some(20 + MIN_TAIL)
        );
        // Too little left, or nothing.
        let end = 20 + MIN_TAIL;
        assert_eq!(cut(&work, (200, 1.0), &at(0, 20, end, 1.0)), None);
        assert_eq!(cut(&work, (200, 1.0), &at(0, 30, 30, 1.0)), None);
    }

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
        let survey = Survey::new(&src, dims, &Binary::<u8>::new(&Params::new(0.5)));
        let bounds = balanced_bounds(&super::layer_work(&survey, dims), 4);
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
