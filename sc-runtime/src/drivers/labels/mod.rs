//! Label volumes: every region of a segmentation meshed in one sweep, as an atlas whose
//! interfaces exist once (docs/labels.md).
//!
//! [`extract_labels`] sweeps the volume cube by cube ([`sweep`]), then merges grey edges where
//! the volume is locally two-labelled ([`merge`]). The result, an [`Atlas`], holds each
//! interface once, tagged with its two labels; [`Atlas::meshes`] cuts it into one closed mesh
//! per label, as [`AtlasView::meshes`] does from an atlas's arrays held elsewhere.
//! [`extract_block`] meshes one block of a volume into a share ([`blocks`]); shares join into
//! that same atlas.

use alloc::vec;
use alloc::vec::Vec;

use hashbrown::{HashMap, HashSet};

use crate::{Error, Mesh, Mode, Stats, Volume};

mod blocks;
mod chunks;
mod join;
mod merge;
mod smooth;
mod sweep;
#[cfg(test)]
mod tests;

use core::ops::Range;

use crate::kernel::labels::MAX_SMOOTHING;
use sweep::Padded;

pub use blocks::{AtlasBlock, block_samples, extract_block};

/// A sample type that can hold labels: an integer whose values name regions.
pub trait Label:
    Copy + Ord + core::hash::Hash + Send + Sync + core::fmt::Debug + 'static + sealed::Sealed
{
    /// Zero, the default background.
    const ZERO: Self;
}

mod sealed {
    pub trait Sealed {
        /// The label as an index, if it is a non-negative integer that fits one.
        fn index(self) -> Option<usize>;
    }
}

macro_rules! label {
    ($($t:ty),*) => {$(
        impl sealed::Sealed for $t {
            #[inline]
            fn index(self) -> Option<usize> {
                usize::try_from(self).ok()
            }
        }
        impl Label for $t {
            const ZERO: Self = 0;
        }
    )*};
}
label!(u8, u16, u32, u64, i16, i32);

/// Everything about a label extraction besides the labels.
#[derive(Clone, Copy, Debug)]
pub struct LabelParams<L> {
    /// The label of "no region": ordered before every other label, and never meshed by
    /// [`Atlas::meshes`]. Outside the volume is background.
    pub background: L,
    /// Which steps run: [`Mode::Embedded`] merges grey edges where it keeps every region's
    /// surface a closed 2-manifold, [`Mode::Paper`] wherever the four cubes around one are
    /// binary, [`Mode::Steps123`] nowhere.
    pub mode: Mode,
    /// Surround the volume with one sample of background, so that every region's mesh is closed
    /// where it touches the volume's border.
    pub pad: bool,
    /// World distance between samples along x, y, z.
    pub spacing: [f64; 3],
    /// World position of sample `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// The case tables; [`crate::tables::DEFAULT`] unless a crate brings its own.
    pub tables: &'static crate::tables::CaseTables,
    /// Places each vertex on its grid edge where the region on one side stops outweighing the
    /// region on the other, both indicators smoothed by a Gaussian this wide (in voxels), instead
    /// of at the midpoint: 0 (the default) for midpoints, 0.75 for surface areas within 1 % of a
    /// sphere's. Every vertex stays strictly inside its edge, so every sample stays on its own
    /// side. Vertices of hub cubes stay at midpoints.
    pub smoothing: f64,
    /// Threads to sweep on: 0 for as many as the machine has, 1 for the calling thread alone.
    /// The atlas does not depend on it. Without the `std` feature, the calling thread alone.
    pub threads: usize,
}

impl<L: Label> Default for LabelParams<L> {
    /// Background 0, embedded mode, padded, unit spacing, the origin at zero, every thread.
    fn default() -> Self {
        LabelParams {
            background: L::ZERO,
            mode: Mode::Embedded,
            pad: true,
            spacing: [1.0; 3],
            origin: [0.0; 3],
            tables: &crate::tables::DEFAULT,
            smoothing: 0.0,
            threads: 0,
        }
    }
}

/// The surfaces between the regions of a label volume, each interface once.
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas<L> {
    /// Vertex positions in world units.
    pub positions: Vec<[f32; 3]>,
    /// Triangles, wound so that `(b − a) × (c − a)` points from the first label of their pair
    /// to the second.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, the label it faces away from, then the label it faces toward.
    pub pairs: Vec<[L; 2]>,
    /// Counts: `v13`/`t13` before Step 4, the grey edges merged and blocked, the output.
    pub stats: Stats,
}

/// Meshes the regions of a label volume.
///
/// The grid is swept in pieces of layers, one per thread of [`LabelParams::threads`], and the
/// pieces are joined in order, so the atlas is the same for any number of threads.
pub fn extract_labels<L: Label>(
    volume: Volume<'_, L>,
    params: &LabelParams<L>,
) -> Result<Atlas<L>, Error> {
    check(params)?;
    let grid = Padded::new(volume, params);
    on_threads(params.threads, || {
        let pieces = sweep_pieces(&grid, params, pieces(&grid, workers(params.threads)))?;
        let (mut atlas, ears, mut edges, mut pinned) = join::join(pieces);
        atlas.stats.v13 = atlas.positions.len() as u64;
        atlas.stats.t13 = atlas.triangles.len() as u64;
        if let Some(merged) = merge::merge(&grid, params, ears, &mut atlas) {
            renumber(&mut edges, &mut pinned, &merged.kept);
        }
        if params.smoothing > 0.0 {
            smooth::place(&grid, params, &mut atlas.positions, &edges, &pinned);
        }
        atlas.stats.vertices = atlas.positions.len() as u64;
        atlas.stats.triangles = atlas.triangles.len() as u64;
        Ok(atlas)
    })?
}

/// The layers of each piece of the sweep: one piece per worker, since joining copies every
/// piece but the first and each piece sweeps its first plane anew, cut so that the pieces hold
/// about as much of the surface (label changes) as of the grid's cubes, each half of the
/// weight. The atlas is the same for any split.
fn pieces<L: Label>(grid: &Padded<'_, L>, workers: usize) -> Vec<Range<usize>> {
    if grid.n.iter().any(|&n| n < 2) {
        return Vec::new();
    }
    let layers = grid.n[2] - 1;
    if workers <= 1 || layers < 2 {
        return core::iter::once(0..layers).collect();
    }
    let changes = layer_changes(grid, layers);
    let total_changes = changes.iter().sum::<usize>().max(1) as f64;
    // Each layer's share of the work, from 0 to 1 over the grid.
    let weight = |z: usize| 0.5 / layers as f64 + 0.5 * changes[z] as f64 / total_changes;
    let mut ranges = Vec::with_capacity(workers);
    let (mut start, mut done) = (0, 0.0);
    for z in 0..layers {
        done += weight(z);
        let target = (ranges.len() + 1) as f64 / workers as f64;
        if done >= target && ranges.len() + 1 < workers && z + 1 < layers {
            ranges.push(start..z + 1);
            start = z + 1;
        }
    }
    ranges.push(start..layers);
    ranges
}

/// [`Padded::changes`] of each layer's lower plane, on the current pool.
#[cfg(feature = "std")]
fn layer_changes<L: Label>(grid: &Padded<'_, L>, layers: usize) -> Vec<usize> {
    use rayon::prelude::*;
    (0..layers)
        .into_par_iter()
        .map(|z| grid.changes(z))
        .collect()
}

/// [`Padded::changes`] of each layer's lower plane.
#[cfg(not(feature = "std"))]
fn layer_changes<L: Label>(grid: &Padded<'_, L>, layers: usize) -> Vec<usize> {
    (0..layers).map(|z| grid.changes(z)).collect()
}

/// The threads work is shared over, called where [`on_threads`] runs its job.
#[cfg(feature = "std")]
fn workers(threads: usize) -> usize {
    match threads {
        1 => 1,
        _ => rayon::current_num_threads(),
    }
}

/// One thread: the caller's.
#[cfg(not(feature = "std"))]
fn workers(_threads: usize) -> usize {
    1
}

/// Refuses what no label extraction runs: a smoothing width out of range, adaptive mode.
fn check<L>(params: &LabelParams<L>) -> Result<(), Error> {
    if !(0.0..=MAX_SMOOTHING).contains(&params.smoothing) {
        return Err(Error::Smoothing);
    }
    if params.mode == Mode::Adaptive {
        return Err(Error::NotAdaptive {
            what: "label volumes have no adaptive mode (use embedded, paper or steps123)",
        });
    }
    Ok(())
}

/// Runs `job` where Rayon's threads are the number asked for: its global pool when it has
/// them (starting a pool costs a noticeable share of a small volume's extraction), a pool of
/// its own otherwise; one thread runs on the caller's and sweeps nothing in parallel.
#[cfg(feature = "std")]
fn on_threads<R: Send>(threads: usize, job: impl FnOnce() -> R + Send) -> Result<R, Error> {
    if threads == 0 || threads == 1 || threads == rayon::current_num_threads() {
        return Ok(job());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|_| Error::ThreadPool)?;
    Ok(pool.install(job))
}

/// Runs `job` on this thread.
#[cfg(not(feature = "std"))]
fn on_threads<R>(_threads: usize, job: impl FnOnce() -> R) -> Result<R, Error> {
    Ok(job())
}

/// `edges` and `pinned` after the merge dropped vertices: `kept[v]` is vertex `v`'s new id,
/// `u32::MAX` if it was merged away.
fn renumber(edges: &mut Vec<sweep::Edge>, pinned: &mut Vec<u32>, kept: &[u32]) {
    if !edges.is_empty() {
        let mut n = 0;
        for v in 0..edges.len() {
            if kept[v] != u32::MAX {
                edges[n] = edges[v];
                n += 1;
            }
        }
        edges.truncate(n);
    }
    pinned.retain(|&v| kept[v as usize] != u32::MAX);
    for v in pinned.iter_mut() {
        *v = kept[*v as usize];
    }
}

/// The pieces of `ranges`, in order, on the pool [`on_threads`] chose.
#[cfg(feature = "std")]
fn sweep_pieces<L: Label>(
    grid: &Padded<'_, L>,
    params: &LabelParams<L>,
    ranges: Vec<Range<usize>>,
) -> Result<Vec<sweep::Piece<L>>, Error> {
    use rayon::prelude::*;
    if params.threads == 1 {
        return ranges
            .into_iter()
            .map(|r| sweep::sweep(grid, params, whole(grid, r), false))
            .collect();
    }
    ranges
        .par_iter()
        .map(|r| sweep::sweep(grid, params, whole(grid, r.clone()), false))
        .collect()
}

/// The pieces of `ranges`, in order, on this thread.
#[cfg(not(feature = "std"))]
fn sweep_pieces<L: Label>(
    grid: &Padded<'_, L>,
    params: &LabelParams<L>,
    ranges: Vec<Range<usize>>,
) -> Result<Vec<sweep::Piece<L>>, Error> {
    ranges
        .into_iter()
        .map(|r| sweep::sweep(grid, params, whole(grid, r), false))
        .collect()
}

/// Every cube of the layers `layers`.
fn whole<L: Label>(grid: &Padded<'_, L>, layers: Range<usize>) -> [Range<usize>; 3] {
    [0..grid.n[0] - 1, 0..grid.n[1] - 1, layers]
}

/// An empty atlas, for any label type (a derived `Default` would ask `L: Default`).
impl<L> Default for Atlas<L> {
    fn default() -> Self {
        Atlas {
            positions: Vec::new(),
            triangles: Vec::new(),
            pairs: Vec::new(),
            stats: Stats::default(),
        }
    }
}

impl<L: Label> Atlas<L> {
    /// The labels with a surface, ascending, without the background (`background`). Found on
    /// `threads` threads (0 for all, 1 for the calling thread alone; the labels do not depend on
    /// it); where a pool cannot be started, on this thread.
    pub fn labels(&self, background: L, threads: usize) -> Vec<L> {
        let n = self.pairs.len();
        #[cfg(not(feature = "std"))]
        let _ = threads;
        #[cfg(feature = "std")]
        if threads != 1
            && let Ok(labels) = on_threads(threads, || {
                labels_of(&self.pairs, chunks::size(n, threads), background)
            })
        {
            return labels;
        }
        labels_of(&self.pairs, n.max(1), background)
    }

    /// One closed mesh per label of `labels` (ascending, as [`Atlas::labels`] gives them), each
    /// wound outward: the atlas's triangles with the label first, and those with it second,
    /// flipped. With `normals`, each vertex gets the normalised sum of its triangles' area
    /// normals in that mesh. Cut on `threads` threads (0 for all, 1 for the calling thread
    /// alone; the meshes do not depend on it); where a pool cannot be started, on this thread.
    pub fn meshes(&self, labels: &[L], normals: bool, threads: usize) -> Vec<(L, Mesh)> {
        self.view().meshes(labels, normals, threads)
    }

    /// The atlas's arrays, borrowed.
    pub fn view(&self) -> AtlasView<'_, L> {
        AtlasView {
            positions: &self.positions,
            triangles: &self.triangles,
            pairs: &self.pairs,
        }
    }
}

/// An atlas's positions, triangles and pairs, borrowed from wherever they are kept (the Python
/// package holds them as NumPy arrays, and cuts the meshes only when one is asked for).
#[derive(Clone, Copy, Debug)]
pub struct AtlasView<'a, L> {
    positions: &'a [[f32; 3]],
    triangles: &'a [[u32; 3]],
    pairs: &'a [[L; 2]],
}

impl<'a, L: Label> AtlasView<'a, L> {
    /// The atlas of these arrays, as [`Atlas`]'s fields of the same names; refused
    /// ([`Error::AtlasMalformed`]) unless every triangle has a pair and its vertices are among
    /// `positions`.
    pub fn new(
        positions: &'a [[f32; 3]],
        triangles: &'a [[u32; 3]],
        pairs: &'a [[L; 2]],
    ) -> Result<Self, Error> {
        if pairs.len() != triangles.len() {
            return Err(Error::AtlasMalformed {
                what: "not one pair of labels per triangle",
            });
        }
        let count = positions.len();
        if triangles.iter().flatten().any(|&v| v as usize >= count) {
            return Err(Error::AtlasMalformed {
                what: "a triangle's vertex is not among the positions",
            });
        }
        Ok(AtlasView {
            positions,
            triangles,
            pairs,
        })
    }

    /// [`Atlas::meshes`] of these arrays.
    pub fn meshes(&self, labels: &[L], normals: bool, threads: usize) -> Vec<(L, Mesh)> {
        let find = Find::new(labels, self.triangles.len());
        #[cfg(not(feature = "std"))]
        let _ = threads;
        #[cfg(feature = "std")]
        if threads != 1
            && let Ok(meshes) = on_threads(threads, || self.meshes_on_pool(&find, normals))
        {
            return meshes;
        }
        let mut local = vec![u32::MAX; self.positions.len()];
        labels
            .iter()
            .zip(self.sides(&find, 0..self.triangles.len()))
            .map(|(&label, triangles)| (label, self.mesh_of(triangles, &mut local, normals)))
            .collect()
    }

    /// [`Atlas::meshes`] on the current pool: the triangles in one run per thread, each split
    /// by label, then the labels' meshes, each worker with its own renumbering array.
    #[cfg(feature = "std")]
    fn meshes_on_pool(&self, find: &Find<'_, L>, normals: bool) -> Vec<(L, Mesh)> {
        use rayon::prelude::*;
        let n = self.triangles.len();
        let run = n.div_ceil(rayon::current_num_threads()).max(1);
        let runs: Vec<Vec<Vec<[u32; 3]>>> = (0..n.div_ceil(run))
            .into_par_iter()
            .map(|k| self.sides(find, k * run..n.min((k + 1) * run)))
            .collect();
        let mut per_label: Vec<Vec<Vec<[u32; 3]>>> =
            find.labels.iter().map(|_| Vec::new()).collect();
        for sides in runs {
            for (parts, part) in per_label.iter_mut().zip(sides) {
                parts.push(part);
            }
        }
        find.labels
            .par_iter()
            .zip(per_label)
            .map_init(
                || vec![u32::MAX; self.positions.len()],
                |local, (&label, mut parts)| {
                    let triangles = match parts.len() {
                        1 => parts.pop().unwrap_or_default(),
                        _ => parts.concat(),
                    };
                    (label, self.mesh_of(triangles, local, normals))
                },
            )
            .collect()
    }

    /// Per label of `find`, the triangles of `range` it bounds, wound outward from it.
    fn sides(&self, find: &Find<'_, L>, range: Range<usize>) -> Vec<Vec<[u32; 3]>> {
        // Counted first, so that each label's triangles are one allocation, not a doubling
        // series of copies.
        let (triangles, pairs) = (&self.triangles[range.clone()], &self.pairs[range]);
        let mut counts = vec![0usize; find.labels.len()];
        each_side(triangles, pairs, find, |i, _, _| counts[i] += 1);
        let mut buckets: Vec<Vec<[u32; 3]>> =
            counts.iter().map(|&n| Vec::with_capacity(n)).collect();
        each_side(triangles, pairs, find, |i, t, first| {
            buckets[i].push(if first { *t } else { [t[0], t[2], t[1]] });
        });
        buckets
    }

    /// The mesh of `triangles` (atlas indices), renumbered in order of first use; `local` is
    /// all `u32::MAX` on entry and on return.
    fn mesh_of(&self, mut triangles: Vec<[u32; 3]>, local: &mut [u32], normals: bool) -> Mesh {
        // A closed surface has about half as many vertices as triangles.
        let mut positions = Vec::with_capacity(triangles.len() / 2 + 2);
        let mut used = Vec::with_capacity(positions.capacity());
        for t in &mut triangles {
            for v in t.iter_mut() {
                let slot = &mut local[*v as usize];
                if *slot == u32::MAX {
                    *slot = positions.len() as u32;
                    positions.push(self.positions[*v as usize]);
                    used.push(*v);
                }
                *v = *slot;
            }
        }
        for v in used {
            local[v as usize] = u32::MAX;
        }
        let normals = if normals {
            area_normals(&positions, &triangles)
        } else {
            Vec::new()
        };
        let stats = Stats {
            vertices: positions.len() as u64,
            triangles: triangles.len() as u64,
            ..Stats::default()
        };
        Mesh {
            positions,
            normals,
            values: Vec::new(),
            triangles,
            stats,
        }
    }
}

/// The labels of `pairs` but `background`, ascending: those of each chunk of `size` pairs, on
/// the current pool, then joined.
fn labels_of<L: Label>(pairs: &[[L; 2]], size: usize, background: L) -> Vec<L> {
    let mut labels = chunks::map(pairs.chunks(size).collect(), labels_in).concat();
    labels.sort_unstable();
    labels.dedup();
    labels.retain(|&l| l != background);
    labels
}

/// The labels of `pairs`, each once, in no order.
fn labels_in<L: Label>(pairs: &[[L; 2]]) -> Vec<L> {
    // Neighbouring triangles often share their pair, and labels are mostly small integers,
    // which a table marks as met; larger ones (a connectomics volume's ids) go in a set.
    let mut labels: Vec<L> = Vec::new();
    let mut met: Vec<bool> = Vec::new();
    let mut large: HashSet<L> = HashSet::new();
    let mut last = None;
    for &pair in pairs {
        if last == Some(pair) {
            continue;
        }
        last = Some(pair);
        for l in pair {
            match l.index().filter(|&i| i < 1 << 16) {
                Some(i) => {
                    if i >= met.len() {
                        met.resize(i + 1, false);
                    }
                    if !met[i] {
                        met[i] = true;
                        labels.push(l);
                    }
                }
                None => {
                    if large.insert(l) {
                        labels.push(l);
                    }
                }
            }
        }
    }
    labels
}

/// Calls `side(i, triangle, first)` for each triangle and each of its labels that is
/// `find`'s `i`-th: `first` if it is the label the triangle faces away from.
fn each_side<L: Label>(
    triangles: &[[u32; 3]],
    pairs: &[[L; 2]],
    find: &Find<'_, L>,
    mut side: impl FnMut(usize, &[u32; 3], bool),
) {
    // Neighbouring triangles mostly share their pair: it is looked up once per run of them.
    let mut last: Option<([L; 2], [Option<usize>; 2])> = None;
    for (t, &pair) in triangles.iter().zip(pairs) {
        let found = match last {
            Some((p, found)) if p == pair => found,
            // Not `pair.map`: an array's `map` is a call per element here.
            _ => [find.get(pair[0]), find.get(pair[1])],
        };
        last = Some((pair, found));
        if let Some(i) = found[0] {
            side(i, t, true);
        }
        if let Some(i) = found[1] {
            side(i, t, false);
        }
    }
}

/// Where each label is in an ascending list of labels: by a table when the labels are small
/// non-negative integers, as a segmentation's are, by a hash map otherwise (binary search
/// would cost a dozen unpredictable branches per triangle).
struct Find<'a, L> {
    labels: &'a [L],
    /// Per label value, its index in `labels`, `u32::MAX` for none; empty for the map.
    table: Vec<u32>,
    map: HashMap<L, u32>,
}

impl<'a, L: Label> Find<'a, L> {
    /// The table is kept no longer than 2¹⁶ or `size` entries, whichever is more: a few
    /// lookups' worth of memory per triangle at most.
    fn new(labels: &'a [L], size: usize) -> Self {
        // Labels out of order must not index past the table, though they come ascending.
        let small = labels.iter().all(|l| l.index().is_some());
        let mut find = Find {
            labels,
            table: Vec::new(),
            map: HashMap::new(),
        };
        match labels.iter().filter_map(|l| l.index()).max() {
            Some(max) if small && max < size.max(1 << 16) => {
                find.table = vec![u32::MAX; max + 1];
                for (i, l) in labels.iter().enumerate() {
                    if let Some(v) = l.index() {
                        find.table[v] = i as u32;
                    }
                }
            }
            _ => {
                find.map = labels
                    .iter()
                    .enumerate()
                    .map(|(i, &l)| (l, i as u32))
                    .collect()
            }
        }
        find
    }

    #[inline]
    fn get(&self, l: L) -> Option<usize> {
        if self.table.is_empty() {
            return self.map.get(&l).map(|&i| i as usize);
        }
        let i = *self.table.get(l.index()?)?;
        (i != u32::MAX).then_some(i as usize)
    }
}

/// Per vertex, the normalised sum of its triangles' `(b − a) × (c − a)`: a label's surface has
/// no gradient to read normals from, and area weights follow the surface's shape.
fn area_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut sums = vec![[0f64; 3]; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|v| positions[v as usize].map(f64::from));
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        for &v in t {
            for k in 0..3 {
                sums[v as usize][k] += n[k];
            }
        }
    }
    sums.into_iter()
        .map(|s| {
            let len = libm::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
            if len > 0.0 {
                s.map(|x| (x / len) as f32)
            } else {
                [0.0; 3]
            }
        })
        .collect()
}
