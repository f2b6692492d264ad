//! Meshing a grid block by block — on other threads, processes or machines — into exactly the
//! mesh one sweep makes.
//!
//! Every decision of Steps 1–4 is local (SPEC §5), so a block's triangles follow from its samples
//! plus a thin halo, and vertices have global names: the grid edge they lie on. A block owns the
//! triangles its cubes emit (a merged pair's triangle belongs to the pair's lower cube, which the
//! sweep already makes its emitter), so every triangle of the whole mesh belongs to exactly one
//! block. Joining blocks is then a merge of sorted lists: vertex keys are numbered in the order a
//! sweep numbers vertices, and triangles are ordered by owning cube, so the joined mesh is
//! byte-identical to [`crate::extract`]'s whatever the block shapes and the order of arrival.

use alloc::collections::BinaryHeap;
use alloc::vec::Vec;
use core::cmp::Reverse;
use core::ops::Range;

use crate::drivers::{InMemory, adaptive, keep_used};
use crate::kernel::sink::Unsettled;
use crate::kernel::{Binary, Engine, Layers};
use crate::mesh::OwnedScratch;
use crate::{Error, Mesh, Mode, Params, Scalar, Sink, Stats, Volume};

/// The samples meshing the cubes `cubes` (lower corners, per axis) of a grid of `grid` samples
/// with `params` reads, clipped to the grid. The halo may start at any index: the sweep takes
/// parity classes from global indices.
///
/// In every mode but adaptive, one sample before the block and two past its far corners: a
/// cube's triangles depend on the Step 4 decisions of its grey edges, which read the cases of the
/// four cubes around each edge and the pinch test's neighbours one sample out; and the cube that
/// owns a merged pair emits its partner's ear too, so the partner one cube further along x or y
/// counts as well. Normals' central differences stay within that reach.
///
/// In adaptive mode, the halo grows with [`Params::max_box`] `M`: `2M + 2` cubes before the
/// block and `3M + 2` past it, rounded out to multiples of `M` (the box lattice), for the 2:1
/// balancing of boxes reaches that far (docs/adaptive.md §8).
///
/// ```
/// use sc_runtime::{Mode, Params, block_samples};
///
/// let params = Params::new(0.5);
/// assert_eq!(block_samples([100, 100, 100], [10..20, 0..99, 97..99], &params).unwrap(), [9..23, 0..100, 96..100]);
/// let adaptive = Params { mode: Mode::Adaptive, max_box: Some(4), ..params };
/// assert_eq!(block_samples([100, 100, 100], [20..40, 0..99, 97..99], &adaptive).unwrap(), [8..57, 0..100, 84..100]);
/// ```
pub fn block_samples(
    grid: [usize; 3],
    cubes: [Range<usize>; 3],
    params: &Params,
) -> Result<[Range<usize>; 3], Error> {
    check_cubes(grid, &cubes)?;
    check_mode(grid, params)?;
    if params.mode == Mode::Adaptive {
        return Ok(adaptive::blocks::block_samples(grid, &cubes, params));
    }
    Ok(core::array::from_fn(|d| {
        let lo = cubes[d].start.saturating_sub(1);
        lo..(cubes[d].end + 3).min(grid[d])
    }))
}

/// Refuses adaptive mode's options where they do not hold for the grid, or outside it.
fn check_mode(grid: [usize; 3], params: &Params) -> Result<(), Error> {
    if params.mode == Mode::Adaptive {
        adaptive::check(params, grid)
    } else {
        super::not_adaptive(params, "")
    }
}

pub(crate) fn check_cubes(grid: [usize; 3], cubes: &[Range<usize>; 3]) -> Result<(), Error> {
    for (d, r) in cubes.iter().enumerate() {
        if r.start > r.end || r.end > grid[d].saturating_sub(1) {
            return Err(Error::BlockOutsideGrid {
                axis: d,
                cubes: r.clone(),
                grid: grid[d],
            });
        }
    }
    Ok(())
}

/// The global name of a grid edge: its lower end and axis packed into one number, ordered the way
/// a sweep numbers vertices (by plane, x- then y-edges row by row, then the plane's z-edges), so
/// that sorting vertices by key gives [`crate::extract`]'s vertex order.
///
/// ```
/// use sc_runtime::edge_key;
///
/// let grid = [4, 3, 2];
/// // Plane 0: row 0's x-edges, row 0's y-edges, row 1's x-edges, …; then plane 0's z-edges.
/// assert!(edge_key(grid, [3, 0, 0], 0) < edge_key(grid, [0, 0, 0], 1));
/// assert!(edge_key(grid, [3, 0, 0], 1) < edge_key(grid, [0, 1, 0], 0));
/// assert!(edge_key(grid, [3, 2, 0], 0) < edge_key(grid, [0, 0, 0], 2));
/// assert!(edge_key(grid, [3, 2, 0], 2) < edge_key(grid, [0, 0, 1], 0));
/// ```
pub fn edge_key(grid: [usize; 3], lower: [usize; 3], axis: usize) -> u64 {
    let [nx, ny, _] = grid.map(|n| n as u64);
    let [x, y, z] = lower.map(|c| c as u64);
    let (group, row_part) = match axis {
        0 => (0, 0),
        1 => (0, 1),
        _ => (1, 0),
    };
    (((z * 2 + group) * ny + y) * 2 + row_part) * nx + x
}

/// The global name of a cube (by its lower corner), in the order a sweep visits cubes.
pub(crate) fn cube_key(grid: [usize; 3], [i, j, k]: [usize; 3]) -> u64 {
    let [nx, ny, _] = grid.map(|n| n as u64);
    ((k as u64) * ny + j as u64) * nx + i as u64
}

/// One block's share of the mesh: the triangles its cubes own, over the vertices they use, named
/// by global edge keys. Join shares with [`BlockMesh::merge`] (in any order or tree) and finish
/// with [`BlockMesh::into_mesh`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BlockMesh {
    /// Samples of the whole grid along x, y, z.
    pub grid: [usize; 3],
    /// Global edge keys ([`edge_key`]) of the vertices, strictly increasing.
    pub keys: Vec<u64>,
    /// Vertex positions in world units, one per key.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals, one per key, or empty when normals were not asked for.
    pub normals: Vec<[f32; 3]>,
    /// Triangles as indices into `keys`, wound as [`Mesh::triangles`].
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, the key of the cube that owns it; non-decreasing.
    pub cubes: Vec<u64>,
    /// The counts of the owned cubes and edges; they add up across blocks, but for `vertices`
    /// and `triangles`, which [`BlockMesh::into_mesh`] counts in the join (an adaptive box's
    /// vertex may be used by a block that does not own its edge).
    pub stats: Stats,
    /// Cubes owned, so that [`BlockMesh::into_mesh`] can tell a whole grid from a partial one.
    pub covered: u64,
}

/// Collects a block sweep's output with global names; the sweep numbers vertices in key order.
struct Collect {
    grid: [usize; 3],
    keys: Vec<u64>,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    cubes: Vec<u64>,
    /// The normals are scaled a layer at a time ([`Sink::settle_normals`]).
    unsettled: Unsettled,
}

impl Sink for Collect {
    fn vertex(&mut self, _: [f32; 3], _: Option<[f32; 3]>) {
        unreachable!("the sweep names every vertex through edge_vertex")
    }

    fn triangle(&mut self, _: [u32; 3]) {
        unreachable!("the sweep places every triangle through cube_triangle")
    }

    fn edge_vertex(
        &mut self,
        lower: [usize; 3],
        axis: usize,
        position: [f32; 3],
        normal: Option<[f32; 3]>,
    ) {
        self.keys.push(edge_key(self.grid, lower, axis));
        self.positions.push(position);
        if let Some(n) = normal {
            self.unsettled.push_unit(&mut self.normals, n);
        }
    }

    fn edge_vertex_toward(
        &mut self,
        lower: [usize; 3],
        axis: usize,
        position: [f32; 3],
        toward: [f32; 3],
    ) {
        self.keys.push(edge_key(self.grid, lower, axis));
        self.positions.push(position);
        self.normals.push(toward);
    }

    fn settle_normals(&mut self) {
        self.unsettled.settle(&mut self.normals);
    }

    fn cube_triangle(&mut self, cube: [usize; 3], triangle: [u32; 3]) {
        self.cubes.push(cube_key(self.grid, cube));
        self.triangles.push(triangle);
    }
}

/// Meshes the cubes `cubes` (lower corners, per axis, in global indices) of a grid of `grid`
/// samples. `samples` holds the samples of a box starting at global index `at`, which must cover
/// [`block_samples`]; a box that is too small is refused rather than meshed wrongly.
///
/// ```
/// use sc_runtime::{BlockMesh, Params, Volume, block_samples, demo, extract, extract_block};
///
/// let v = demo::torus(24);
/// let params = Params::new(v.iso);
/// let [nx, ny, nz] = v.dims;
/// let mut joined = BlockMesh::default();
/// for z in [0..11, 11..nz - 1] {
///     let cubes = [0..nx - 1, 0..ny - 1, z];
///     let need = block_samples(v.dims, cubes.clone(), &params).unwrap();
///     let box_ = &v.data[need[2].start * nx * ny..need[2].end * nx * ny];
///     let dims = [nx, ny, need[2].len()];
///     let part = extract_block(&Volume::new(box_, dims).unwrap(), [0, 0, need[2].start], v.dims, cubes, &params).unwrap();
///     joined = joined.merge(part).unwrap();
/// }
/// let whole = extract(&Volume::new(&v.data, v.dims).unwrap(), &params).unwrap();
/// assert_eq!(joined.into_mesh().unwrap(), whole);
/// ```
pub fn extract_block<T: Scalar>(
    samples: &Volume<'_, T>,
    at: [usize; 3],
    grid: [usize; 3],
    cubes: [Range<usize>; 3],
    params: &Params,
) -> Result<BlockMesh, Error> {
    let need = block_samples(grid, cubes.clone(), params)?;
    check_halo(samples.dims(), at, grid, &need)?;
    let share = BlockMesh {
        grid,
        covered: cubes.iter().map(|r| r.len() as u64).product(),
        ..BlockMesh::default()
    };
    if share.covered == 0 {
        return Ok(share);
    }
    if params.mode == Mode::Adaptive {
        return adaptive::blocks::extract_block(samples, at, need, cubes, params, share);
    }
    sweep_block(&Binary::new(params), samples, at, cubes, params, share)
}

/// [`extract_block`] with any engine, once the samples are known to cover the halo and `out`
/// (the share, empty) to own some cube.
pub(crate) fn sweep_block<T: Scalar>(
    engine: &impl Engine<T>,
    samples: &Volume<'_, T>,
    at: [usize; 3],
    cubes: [Range<usize>; 3],
    params: &Params,
    mut out: BlockMesh,
) -> Result<BlockMesh, Error> {
    let (dims, grid) = (samples.dims(), out.grid);
    let mut collect = Collect {
        grid,
        keys: Vec::new(),
        positions: Vec::new(),
        normals: Vec::new(),
        triangles: Vec::new(),
        cubes: Vec::new(),
        unsettled: Unsettled::default(),
    };
    let mut scratch = OwnedScratch::new(dims)?;
    let mut sweep = engine.sweep(dims, params, scratch.lend());
    sweep.restrict(
        at,
        core::array::from_fn(|d| (cubes[d].start - at[d], cubes[d].end - at[d])),
    );
    let src = InMemory::new(samples);
    sweep.start(0, &src, &mut collect, true)?;
    for k in 0..dims[2] - 1 {
        sweep.layer(k, &src, &mut collect)?;
    }
    out.stats = sweep.stats();
    // Keep the vertices the owned triangles use; the halo's others belong to other blocks.
    out.triangles = collect.triangles;
    let kept = keep_used(collect.keys.len(), &mut out.triangles);
    out.keys = kept.iter().map(|&v| collect.keys[v]).collect();
    out.positions = kept.iter().map(|&v| collect.positions[v]).collect();
    if !collect.normals.is_empty() {
        out.normals = kept.iter().map(|&v| collect.normals[v]).collect();
    }
    out.cubes = collect.cubes;
    Ok(out)
}

/// [`BlockMesh::check`] on a share's parts: its keys, the lengths of its positions and normals
/// (if any), its triangles and their owning cubes.
pub(crate) fn check_share(
    keys: &[u64],
    positions: usize,
    normals: Option<usize>,
    triangles: &[[u32; 3]],
    cubes: &[u64],
) -> Result<(), Error> {
    let n = keys.len();
    let broken = |what| Err(Error::BlockMalformed { what });
    if positions != n || normals.is_some_and(|m| m != n) {
        return broken("the vertex arrays differ in length");
    }
    if cubes.len() != triangles.len() {
        return broken("the triangle and owning-cube arrays differ in length");
    }
    if !keys.windows(2).all(|w| w[0] < w[1]) {
        return broken("the vertex keys are not strictly increasing");
    }
    if !cubes.windows(2).all(|w| w[0] <= w[1]) {
        return broken("the owning cubes are not in order");
    }
    if !triangles.iter().flatten().all(|&v| (v as usize) < n) {
        return broken("a triangle refers to a vertex that is not there");
    }
    Ok(())
}

/// Refuses samples of `dims` from grid index `at` that do not cover `need` or leave the grid.
pub(crate) fn check_halo(
    dims: [usize; 3],
    at: [usize; 3],
    grid: [usize; 3],
    need: &[Range<usize>; 3],
) -> Result<(), Error> {
    for d in 0..3 {
        let have = at[d]..at[d].saturating_add(dims[d]);
        if have.start > need[d].start || have.end < need[d].end || have.end > grid[d] {
            return Err(Error::HaloTooSmall {
                axis: d,
                have,
                need: need[d].clone(),
            });
        }
    }
    Ok(())
}

impl BlockMesh {
    /// Checks the rules [`BlockMesh::merge`] relies on, for a share that crossed a process or a
    /// file and may have been damaged on the way: one position (and normal, if any) per key, keys
    /// strictly increasing, one owning cube per triangle in non-decreasing order, and every
    /// triangle's indices inside the vertex list. A share from [`extract_block`] always passes.
    pub fn check(&self) -> Result<(), Error> {
        let normals = (!self.normals.is_empty()).then_some(self.normals.len());
        check_share(
            &self.keys,
            self.positions.len(),
            normals,
            &self.triangles,
            &self.cubes,
        )
    }

    /// Joins two shares of the same grid into one: the union of their vertices (in key order)
    /// and of their triangles (in cube order). Associative and commutative, so shares can be
    /// joined in any order or as a tree. Shares that own the same cube are refused.
    pub fn merge(self, other: BlockMesh) -> Result<BlockMesh, Error> {
        Self::merge_all([self, other])
    }

    /// Joins any number of shares at once, as [`BlockMesh::merge`] joins two: each vertex and
    /// triangle is copied once, where folding `merge` over `k` shares copies the growing result
    /// `k − 1` times.
    ///
    /// ```
    /// use sc_runtime::{BlockMesh, Params, Volume, demo, extract, extract_block};
    ///
    /// let v = demo::torus(24);
    /// let (volume, params) = (Volume::new(&v.data, v.dims).unwrap(), Params::new(v.iso));
    /// // Three slabs of cubes, each meshed from the whole volume (a block may be given more
    /// // samples than its halo needs).
    /// let shares = [0..7, 7..15, 15..23].map(|z| {
    ///     extract_block(&volume, [0, 0, 0], v.dims, [0..23, 0..23, z], &params).unwrap()
    /// });
    /// let whole = BlockMesh::merge_all(shares).unwrap().into_mesh().unwrap();
    /// assert_eq!(whole, extract(&volume, &params).unwrap());
    /// ```
    pub fn merge_all(shares: impl IntoIterator<Item = BlockMesh>) -> Result<BlockMesh, Error> {
        Self::merge_traced(shares.into_iter().collect(), |_, _| {})
    }

    /// [`BlockMesh::merge_all`], calling `origin(share, triangle)` for each triangle of the
    /// result, in order: where it came from, for data kept beside the shares (a label's pair).
    pub(crate) fn merge_traced(
        shares: Vec<BlockMesh>,
        mut origin: impl FnMut(usize, usize),
    ) -> Result<BlockMesh, Error> {
        // Empty shares (the default one a fold starts from) join anything.
        let live = || {
            shares
                .iter()
                .filter(|s| s.covered != 0 || !s.keys.is_empty())
        };
        let Some(first) = live().next() else {
            return Ok(BlockMesh::default());
        };
        let with_vertices = || shares.iter().filter(|s| !s.keys.is_empty());
        let normals = with_vertices()
            .next()
            .is_some_and(|s| !s.normals.is_empty());
        if live().any(|s| s.grid != first.grid)
            || with_vertices().any(|s| s.normals.is_empty() == normals)
        {
            return Err(Error::BlocksDiffer);
        }
        let total = |f: fn(&BlockMesh) -> usize| shares.iter().map(f).sum::<usize>();
        let mut out = BlockMesh {
            grid: first.grid,
            stats: shares.iter().fold(Stats::default(), |s, b| s + b.stats),
            covered: shares.iter().map(|s| s.covered).sum(),
            keys: Vec::with_capacity(total(|s| s.keys.len())),
            positions: Vec::with_capacity(total(|s| s.keys.len())),
            normals: Vec::with_capacity(total(|s| s.normals.len())),
            triangles: Vec::with_capacity(total(|s| s.triangles.len())),
            cubes: Vec::with_capacity(total(|s| s.cubes.len())),
        };
        // Vertices: the union of the sorted keys, with each share's old index → new index. A key
        // in several shares (a vertex on a block's face) is one vertex, at one position.
        let mut maps: Vec<Vec<u32>> = shares
            .iter()
            .map(|s| Vec::with_capacity(s.keys.len()))
            .collect();
        let mut differ = false;
        merge_sorted(shares.iter().map(|s| &s.keys[..]), |s, at, again| {
            let share = &shares[s];
            if again {
                differ |= out.positions.last() != Some(&share.positions[at]);
            } else {
                out.keys.push(share.keys[at]);
                out.positions.push(share.positions[at]);
                out.normals.extend(share.normals.get(at));
            }
            maps[s].push(out.keys.len() as u32 - 1);
        });
        if differ {
            return Err(Error::BlocksDiffer);
        }
        // Triangles by owning cube; a cube's triangles all come from one share, in their order.
        let mut overlap = None;
        merge_sorted(shares.iter().map(|s| &s.cubes[..]), |s, at, again| {
            let share = &shares[s];
            if again {
                overlap.get_or_insert(share.cubes[at]);
            } else {
                out.cubes.push(share.cubes[at]);
                out.triangles
                    .push(share.triangles[at].map(|v| maps[s][v as usize]));
                origin(s, at);
            }
        });
        match overlap {
            Some(cube) => Err(Error::BlocksOverlap { cube }),
            None => Ok(out),
        }
    }

    /// The whole mesh, once the shares joined cover every cube of the grid: exactly what
    /// [`crate::extract`] gives for the whole grid.
    pub fn into_mesh(self) -> Result<Mesh, Error> {
        let need: u64 = self
            .grid
            .iter()
            .map(|&n| n.saturating_sub(1) as u64)
            .product();
        if self.covered != need {
            return Err(Error::BlocksMissing {
                covered: self.covered,
                cubes: need,
            });
        }
        if u32::try_from(self.keys.len()).is_err() {
            return Err(Error::TooManyVertices);
        }
        Ok(Mesh {
            stats: Stats {
                vertices: self.keys.len() as u64,
                triangles: self.triangles.len() as u64,
                ..self.stats
            },
            positions: self.positions,
            normals: self.normals,
            triangles: self.triangles,
            ..Mesh::default()
        })
    }
}

/// Visits the elements of non-decreasing `lists` in order, as `visit(list, index, again)`:
/// `again` is true for an element equal to one just visited from another list (ties within one
/// list are plain visits, after the other lists' repeats). A run of one list that sorts before every other list's next element
/// is visited without touching the heap: a block's keys come in runs of a row.
fn merge_sorted<'a>(
    lists: impl Iterator<Item = &'a [u64]>,
    mut visit: impl FnMut(usize, usize, bool),
) {
    let lists: Vec<&[u64]> = lists.collect();
    let mut next = alloc::vec![0usize; lists.len()];
    let mut heads: BinaryHeap<Reverse<(u64, usize)>> = lists
        .iter()
        .enumerate()
        .filter_map(|(l, list)| Some(Reverse((*list.first()?, l))))
        .collect();
    while let Some(Reverse((v, l))) = heads.pop() {
        let list = lists[l];
        // This list's head, ...
        visit(l, next[l], false);
        let mut at = next[l] + 1;
        // ... the other lists' elements equal to it (repeats), ...
        while let Some(&Reverse((w, m))) = heads.peek()
            && w == v
        {
            heads.pop();
            let other = lists[m];
            let mut i = next[m];
            while i < other.len() && other[i] == v {
                visit(m, i, true);
                i += 1;
            }
            next[m] = i;
            if let Some(&u) = other.get(i) {
                heads.push(Reverse((u, m)));
            }
        }
        // ... then the rest of this list's run (its own ties included), up to the next list's
        // head, which the repeats left above `v`.
        let bound = heads.peek().map_or(u64::MAX, |r| r.0.0);
        while at < list.len() && list[at] < bound {
            visit(l, at, false);
            at += 1;
        }
        next[l] = at;
        if let Some(&u) = list.get(at) {
            heads.push(Reverse((u, l)));
        }
    }
}
