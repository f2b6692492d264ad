//! Adaptive mode's driver: the volume in memory, its boxes decided and triangulated on one
//! thread or several ([`Spread`]; docs/adaptive.md).
//!
//! 1. The Steps 1–3 mesh is swept as [`Mode::Steps123`](crate::Mode::Steps123) makes it, each
//!    vertex named by its grid edge and each triangle by its cube ([`record`]).
//! 2. Boxes of side 2, 4, … up to `max_box`, on the lattice of multiples of their side, are
//!    decided smallest first on their own samples and Steps 1–3 triangles: empty, refused, or
//!    accepted because their eight children may be boxes and they pass (S), (F), (P) and (E) in
//!    every variant their neighbours could give them ([`crate::kernel::adaptive`]).
//! 3. The largest accepted box over each pair of cubes is kept, and boxes are split until no
//!    face neighbour is less than half their side.
//! 4. The unit cubes outside boxes keep their Steps 1–3 triangles; each box emits its
//!    triangles in the variant its neighbours do give it, and the vertices no triangle uses any
//!    more are dropped.
//! 5. Triangles are ordered by the cube that owns them, so that blocks ([`blocks`]) join into
//!    exactly this mesh.

use alloc::vec;
use alloc::vec::Vec;
use core::ops::Range;

use crate::drivers::blocks::edge_key;
use crate::drivers::borrowed::sweep_at;
use crate::drivers::{has_cubes, keep_used};
use crate::kernel::Binary;
use crate::kernel::adaptive::checks::{Memo, bounds, scaled};
use crate::kernel::adaptive::outline::Shape;
use crate::kernel::adaptive::{
    BoxSource, Crossing, Patch, Tolerance, Vertex, accept, outline, triangulate,
};
use crate::kernel::vertex::sample_crossing;
use crate::mesh::OwnedScratch;
use crate::{Error, ErrorBound, Mesh, Mode, Params, Scalar, Sink, Stats, Volume};

pub(crate) mod blocks;
mod merged;
mod record;

use merged::Removed;
use record::{Kept, Recorded};

/// The bound adaptive mode holds when none is given: half the smallest spacing, in world units
/// (half a voxel where the spacing is even).
fn default_bound(params: &Params) -> ErrorBound {
    let least = params.spacing.iter().copied().fold(f64::INFINITY, f64::min);
    ErrorBound::World(0.5 * least)
}

/// The largest box adaptive mode makes, in cubes, and its default.
pub(crate) const LARGEST_BOX: u32 = 16;

/// Checks adaptive mode's options: the bound finite and at least zero, the box a power of two no
/// larger than the volume's longest cube count and no larger than the boxes this version makes.
pub(crate) fn check(params: &Params, dims: [usize; 3]) -> Result<(), Error> {
    if let Some(b) = params.max_error
        && !(b.value().is_finite() && b.value() >= 0.0)
    {
        return Err(Error::MaxError);
    }
    if let Some(given) = params.max_box {
        let cubes = dims.iter().map(|&d| d.saturating_sub(1)).max().unwrap_or(0);
        let volume = u32::try_from(cubes).unwrap_or(u32::MAX);
        let largest = LARGEST_BOX.min(if volume == 0 { 1 } else { 1 << volume.ilog2() });
        if given == 0 || !given.is_power_of_two() || given > largest {
            return Err(Error::MaxBox { given, largest });
        }
    }
    Ok(())
}

/// The storage behind a box's [`Patch`], reused from box to box.
#[derive(Default)]
struct PatchBuf {
    tris: Vec<[[f64; 3]; 3]>,
    boxes: Vec<[[f64; 3]; 2]>,
    starts: Vec<u32>,
}

/// How the boxes of one size are shared out: in order on this thread ([`InOrder`]), or over a
/// thread pool (`extract_par`). A box's decision reads its own samples, its Steps 1–3 triangles
/// and the decisions on its children, and a box's triangles its own box and its neighbours'
/// balanced sizes, so the mesh is the same however the boxes are shared out.
pub(crate) trait Spread: Sync {
    /// `f` on consecutive ranges that cover `0..n`, the results in the ranges' order.
    fn ranges<R: Send>(&self, n: usize, f: impl Fn(Range<usize>) -> R + Sync) -> Vec<R>;
}

/// Every box on the calling thread.
pub(crate) struct InOrder;

impl Spread for InOrder {
    fn ranges<R: Send>(&self, n: usize, f: impl Fn(Range<usize>) -> R + Sync) -> Vec<R> {
        vec![f(0..n)]
    }
}

/// Extracts the adaptive mesh of `volume` (see the module's steps), its boxes shared out by
/// `spread`.
pub(crate) fn extract<T: Scalar>(
    volume: &Volume<'_, T>,
    params: &Params,
    spread: &impl Spread,
) -> Result<Mesh, Error> {
    let dims = volume.dims();
    check(params, dims)?;
    let mut run = run(volume, [0; 3], dims, params, spread)?;
    let kept = keep_used(run.rec.edges.len(), &mut run.triangles);
    let mut mesh = vertices(volume, [0; 3], params, &kept)?;
    mesh.triangles = run.triangles;
    mesh.stats = Stats {
        v13: run.rec.edges.len() as u64,
        t13: run.rec.cubes.len() as u64,
        merged: run.merges.len() as u64,
        vertices: mesh.positions.len() as u64,
        triangles: mesh.triangles.len() as u64,
        ..Stats::default()
    };
    Ok(mesh)
}

/// A triangle (Steps 1–3 vertex ids) with the key of the cube that owns it
/// ([`Recorded::point_key`]), and its place in the list it is sorted in.
#[derive(Clone, Copy)]
pub(super) struct Owned {
    owner: u64,
    triangle: [u32; 3],
    seq: u32,
}

impl Owned {
    pub(super) fn new(owner: u64, triangle: [u32; 3]) -> Self {
        Owned {
            owner,
            triangle,
            seq: 0,
        }
    }
}

/// What [`run`] makes: the Steps 1–3 sweep (global edge and cube keys), the triangles over its
/// vertices with the cube that owns each, and the owner of each merge kept.
struct Run {
    rec: Recorded,
    /// The triangles, ordered by owner and, within one, as the steps make them.
    triangles: Vec<[u32; 3]>,
    /// Per triangle, the key of its owner ([`Recorded::point_key`]): a unit cube's triangles
    /// are its own, a merge's belong to the least of its four cubes and a box's to its lower
    /// corner cube.
    owners: Vec<u64>,
    /// Per merge kept, its owner.
    merges: Vec<u64>,
}

/// The adaptive mesh of samples lying at global index `at` (a multiple of the largest box) of
/// a grid of `grid` samples, meshed as if they were the whole grid, but on the whole grid's box
/// lattice and with its names. Where the samples reach far enough around a cube
/// (`blocks::block_samples`), its triangles are those the whole grid gives it.
fn run<T: Scalar>(
    volume: &Volume<'_, T>,
    at: [usize; 3],
    grid: [usize; 3],
    params: &Params,
    spread: &impl Spread,
) -> Result<Run, Error> {
    let dims = volume.dims();
    // Edges and triangles only: positions, normals and values wait for the vertices the mesh
    // keeps ([`vertices`]).
    let steps123 = Params {
        normals: false,
        values: false,
        ..steps123(params)
    };
    let mut rec = record(volume, at, &steps123, Recorded::new(grid))?;
    let largest = params.max_box.unwrap_or(LARGEST_BOX);
    let levels = largest.ilog2() as usize;
    if !has_cubes(dims) || levels == 0 {
        // Unit cubes only: the Steps 1–3 mesh, each triangle its cube's.
        return Ok(Run {
            triangles: rec.triangles.clone(),
            owners: rec.cubes.clone(),
            merges: Vec::new(),
            rec,
        });
    }
    let bound = params.max_error.unwrap_or_else(|| default_bound(params));
    let tolerance = Tolerance {
        scale: match bound {
            ErrorBound::World(_) => params.spacing,
            ErrorBound::Voxels(_) => [1.0; 3],
        },
        limit: bound.value(),
        allow_wrong_side: params.allow_wrong_side,
    };
    // Embedded mode's merges under the same bound, for the unit cubes no box covers.
    let embedded = Params {
        mode: Mode::Embedded,
        max_error: Some(bound),
        max_box: None,
        allow_wrong_side: false,
        normals: false,
        values: false,
        ..*params
    };
    let removed = {
        let mut removed = Removed::new(&rec);
        sweep(volume, at, &embedded, &mut removed)?;
        removed.finish()
    };
    let grid = Grid::new(volume, at, grid, params.iso, &rec);
    let lattice = grid.decide(levels, &tolerance, spread);
    let units = match lattice.first() {
        Some((pairs, _)) => {
            let mut level = final_levels(&lattice);
            balance(&mut level, *pairs, dims);
            grid.emit(&lattice, &level, &tolerance, &removed, spread)
        }
        None => {
            let mut triangles = Vec::new();
            let merges = grid.emit_units(&removed, |_| false, &tolerance, &mut triangles);
            (triangles, merges)
        }
    };
    drop(removed);
    // What is read from here on is the edges and the cubes: the Steps 1–3 triangles go first.
    rec.triangles = Vec::new();
    let (mut triangles, merges) = units;
    // Within an owner, the order the steps made them in, which no cut changes. A stable sort
    // would take a buffer as large as the list; the place in the list, kept in the padding,
    // makes an unstable one give the same order in place.
    match u32::try_from(triangles.len()) {
        Ok(_) => {
            for (seq, t) in triangles.iter_mut().enumerate() {
                t.seq = seq as u32;
            }
            triangles.sort_unstable_by_key(|t| (t.owner, t.seq));
        }
        Err(_) => triangles.sort_by_key(|t| t.owner),
    }
    let owners = triangles.iter().map(|t| t.owner).collect();
    let triangles = triangles.into_iter().map(|t| t.triangle).collect();
    Ok(Run {
        rec,
        triangles,
        owners,
        merges,
    })
}

/// The sweep of `volume` (at global index `at`) under `params` into `rec`, its spare room given
/// back.
fn record<T: Scalar>(
    volume: &Volume<'_, T>,
    at: [usize; 3],
    params: &Params,
    mut rec: Recorded,
) -> Result<Recorded, Error> {
    sweep(volume, at, params, &mut rec)?;
    rec.settle();
    Ok(rec)
}

/// `params` for the Steps 1–3 sweep adaptive mode starts from.
fn steps123(params: &Params) -> Params {
    Params {
        mode: Mode::Steps123,
        max_error: None,
        max_box: None,
        ..*params
    }
}

/// The positions (and normals and values, as `params` asks) of the Steps 1–3 vertices `kept`
/// (ids, ascending) of `volume` at global index `at`, from a second Steps 1–3 sweep. Sweeping
/// again costs a few milliseconds; holding every vertex's position and normal while the boxes
/// are decided would cost a fifth of adaptive mode's peak memory.
fn vertices<T: Scalar>(
    volume: &Volume<'_, T>,
    at: [usize; 3],
    params: &Params,
    kept: &[usize],
) -> Result<Mesh, Error> {
    let mut sink = Kept::new(kept);
    sweep(volume, at, &steps123(params), &mut sink)?;
    Ok(sink.finish())
}

/// The sweep of `volume` (at global index `at`) under `params` into `sink`.
fn sweep<T: Scalar>(
    volume: &Volume<'_, T>,
    at: [usize; 3],
    params: &Params,
    sink: &mut impl Sink,
) -> Result<(), Error> {
    let mut scratch = OwnedScratch::new(volume.dims())?;
    sweep_at(
        &Binary::new(params),
        volume,
        at,
        params,
        scratch.lend(),
        sink,
    )?;
    Ok(())
}

/// A box on the lattice of its size: whether it may replace its cubes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Cell {
    /// It may not: its cubes, or its children, stay.
    Cubes,
    /// No occupied edge in it: a box that emits nothing.
    Empty,
    /// A box that may emit its own triangles, in any variant.
    Box,
}

/// Per box size `2^ℓ`, from `ℓ = 1`: the boxes along each axis, and each one's decision.
type Lattice = Vec<([usize; 3], Vec<Cell>)>;

/// The volume, its Steps 1–3 mesh and the lookups the boxes need. Points, keys and boxes are
/// named in the whole grid's indices; the samples at hand start at `at`.
struct Grid<'a, T: Scalar> {
    data: &'a [T],
    /// Samples of the whole grid.
    dims: [usize; 3],
    /// Where the samples at hand start, a multiple of every box side, so that the boxes within
    /// them lie on the whole grid's lattice.
    at: [usize; 3],
    /// Samples at hand.
    local: [usize; 3],
    iso: f64,
    threshold: T::Threshold,
    /// The Steps 1–3 triangles, and each one's cube and each vertex's edge.
    triangles: &'a [[u32; 3]],
    rec: &'a Recorded,
}

impl<'a, T: Scalar> Grid<'a, T> {
    fn new(
        volume: &Volume<'a, T>,
        at: [usize; 3],
        grid: [usize; 3],
        iso: f64,
        rec: &'a Recorded,
    ) -> Self {
        // The sweep makes each cube's triangles in turn, cubes in key order, and sends the
        // vertices in the order blocks name them by (`edge_key`): a cube's triangles are a run
        // of `rec.cubes`, and a vertex is found, by bisection over `rec.edges`, with no sorted
        // copy of either.
        debug_assert!(rec.cubes.is_sorted(), "Steps 1–3 triangles in cube order");
        debug_assert!(
            rec.edges.is_sorted_by_key(|&k| sweep_order(k, grid)),
            "Steps 1–3 vertices in the order of their edge_key"
        );
        Grid {
            data: volume.data(),
            dims: grid,
            at,
            local: volume.dims(),
            iso,
            threshold: T::threshold(iso),
            triangles: &rec.triangles,
            rec,
        }
    }

    fn key(&self, p: [usize; 3]) -> u64 {
        (p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])) as u64
    }

    fn sample(&self, p: [usize; 3]) -> T {
        let [x, y, z]: [usize; 3] = core::array::from_fn(|d| p[d] - self.at[d]);
        self.data[x + self.local[0] * (y + self.local[1] * z)]
    }

    /// The global lower corner of the box of `side` with local lattice index `cell`.
    fn corner(&self, cell: [usize; 3], side: usize) -> [usize; 3] {
        core::array::from_fn(|d| cell[d] * side + self.at[d])
    }

    fn vertex_id(&self, lower: [usize; 3], axis: usize) -> Option<u32> {
        let want = edge_key(self.dims, lower, axis);
        let edges = &self.rec.edges;
        let i = edges.partition_point(|&k| sweep_order(k, self.dims) < want);
        let found = edges.get(i).map(|&k| sweep_order(k, self.dims));
        (found == Some(want)).then_some(i as u32)
    }

    /// A vertex's place in grid steps, from its edge key.
    fn place(&self, key: u64) -> [f64; 3] {
        let axis = (key % 3) as usize;
        let lower = unkey((key / 3) as usize, self.dims);
        let mut upper = lower;
        upper[axis] += 1;
        let t = sample_crossing(self.sample(lower), self.sample(upper), self.iso);
        core::array::from_fn(|d| lower[d] as f64 + if d == axis { t } else { 0.0 })
    }

    /// The ids of the triangles of the cube with key `cube`, in the order the sweep made them.
    fn cube_range(&self, cube: u64) -> core::ops::Range<usize> {
        let cubes = &self.rec.cubes;
        cubes.partition_point(|&k| k < cube)..cubes.partition_point(|&k| k <= cube)
    }

    /// The Steps 1–3 triangles of the box of `side` at `corner`, in the tolerance's units, cube by
    /// cube into `buf`.
    fn patch<'b>(
        &self,
        corner: [usize; 3],
        side: usize,
        tolerance: &Tolerance,
        buf: &'b mut PatchBuf,
    ) -> Patch<'b> {
        buf.tris.clear();
        buf.starts.clear();
        for dz in 0..side {
            for dy in 0..side {
                for dx in 0..side {
                    buf.starts.push(buf.tris.len() as u32);
                    let cube = [corner[0] + dx, corner[1] + dy, corner[2] + dz];
                    self.cube_triangles(cube, &mut |t| {
                        buf.tris.push(t.map(|p| scaled(p, tolerance)))
                    });
                }
            }
        }
        buf.starts.push(buf.tris.len() as u32);
        buf.boxes.clear();
        buf.boxes.extend(buf.tris.iter().map(bounds));
        Patch {
            tris: &buf.tris,
            boxes: &buf.boxes,
            starts: &buf.starts,
            corner,
            side,
            scale: tolerance.scale,
        }
    }

    /// Decides the boxes of every size up to `2^levels`, smallest first: a box is tested only if
    /// its eight children may all be boxes.
    fn decide(&self, levels: usize, tolerance: &Tolerance, spread: &impl Spread) -> Lattice {
        let mut lattice: Lattice = Vec::new();
        for level in 1..=levels {
            let side = 1 << level;
            let cells = self.local.map(|d| (d - 1) / side);
            if cells.contains(&0) {
                break;
            }
            let below = lattice.last();
            let states = spread
                .ranges(cells.iter().product(), |range| {
                    let mut buf = PatchBuf::default();
                    range
                        .map(|i| self.decide_box(unkey(i, cells), side, below, tolerance, &mut buf))
                        .collect::<Vec<Cell>>()
                })
                .concat();
            lattice.push((cells, states));
        }
        lattice
    }

    /// The decision on the box of `side` with local lattice index `cell`, given the decisions
    /// on the boxes of half its side (`below`; none for the smallest).
    fn decide_box(
        &self,
        cell: [usize; 3],
        side: usize,
        below: Option<&([usize; 3], Vec<Cell>)>,
        tolerance: &Tolerance,
        buf: &mut PatchBuf,
    ) -> Cell {
        if let Some((below, children)) = below {
            let whole = (0..8).all(|k| {
                let child: [usize; 3] = core::array::from_fn(|d| 2 * cell[d] + (k >> d & 1));
                children[cell_index(child, *below)] != Cell::Cubes
            });
            if !whole {
                return Cell::Cubes;
            }
        }
        // Whether a face has a box across is the whole grid's question: a box decides alike
        // wherever its samples are at hand.
        let grid_cells = self.dims.map(|d| (d - 1) / side);
        let corner = self.corner(cell, side);
        let global = corner.map(|c| c / side);
        match outline(self, corner, side) {
            Shape::Empty => Cell::Empty,
            Shape::Complex => Cell::Cubes,
            Shape::Simple(o) => {
                let may_chord = (0..o.n).fold(0u8, |m, i| {
                    match neighbour(global, usize::from(o.arc_face[i]), grid_cells) {
                        Some(_) => m | 1 << i,
                        None => m,
                    }
                });
                let patch = self.patch(corner, side, tolerance, buf);
                if accept(self, &o, may_chord, &patch, tolerance) {
                    Cell::Box
                } else {
                    Cell::Cubes
                }
            }
        }
    }

    /// The triangles with their owners: each box's, size by size, in the variant its
    /// neighbours give it, then those of the unit cubes outside boxes. `level` is the balanced size of the
    /// box holding each pair of cubes (`final_levels`).
    fn emit(
        &self,
        lattice: &Lattice,
        level: &[u8],
        tolerance: &Tolerance,
        removed: &[u32],
        spread: &impl Spread,
    ) -> (Vec<Owned>, Vec<u64>) {
        let pairs = lattice[0].0;
        let in_box = |cube_key: u64| -> bool {
            let cube = unkey(cube_key as usize, self.dims);
            let pair: [usize; 3] = core::array::from_fn(|d| (cube[d] - self.at[d]) / 2);
            (0..3).all(|d| pair[d] < pairs[d]) && level[cell_index(pair, pairs)] > 0
        };
        let mut parts = Vec::new();
        for (l, (cells, states)) in lattice.iter().enumerate() {
            parts.extend(spread.ranges(states.len(), |range| {
                let (mut buf, mut triangles) = (PatchBuf::default(), Vec::new());
                for i in range.filter(|&i| states[i] == Cell::Box) {
                    let at = (unkey(i, *cells), l as u8 + 1);
                    self.emit_box(at, level, pairs, tolerance, &mut buf, &mut triangles);
                }
                triangles
            }));
        }
        // The boxes' triangles are the largest list adaptive mode holds: the first part becomes
        // the output, so that it is not copied whole, and the units' triangles are added to it.
        let mut parts = parts.into_iter();
        let mut out = parts.next().unwrap_or_default();
        out.reserve_exact(parts.as_slice().iter().map(Vec::len).sum());
        for part in parts {
            out.extend(part);
        }
        let merges = self.emit_units(removed, in_box, tolerance, &mut out);
        (out, merges)
    }

    /// Pushes the triangles of the accepted box with lattice index `cell` at level `l` (side
    /// `2^l`), with their owner, if it is kept whole after balancing.
    fn emit_box(
        &self,
        (cell, l): ([usize; 3], u8),
        level: &[u8],
        pairs: [usize; 3],
        tolerance: &Tolerance,
        buf: &mut PatchBuf,
        out: &mut Vec<Owned>,
    ) {
        let side = 1usize << l;
        let first = cell.map(|c| c * (side / 2));
        if level[cell_index(first, pairs)] != l {
            return;
        }
        let corner = self.corner(cell, side);
        let Shape::Simple(o) = outline(self, corner, side) else {
            return;
        };
        // A face keeps its midline vertices unless a box at least as large is across.
        let refined = (0..o.n).fold(0u8, |m, i| {
            let face = usize::from(o.arc_face[i]);
            match across(first, side / 2, face, pairs) {
                Some(j) if level[j] >= l => m,
                _ => m | 1 << i,
            }
        });
        let patch = self.patch(corner, side, tolerance, buf);
        // Accepted boxes triangulate in every variant (`accept`), and the choice depends on the
        // box and its variant alone.
        let Some(t) = triangulate(self, &o, refined, &patch, tolerance, &mut Memo::new()) else {
            debug_assert!(false, "an accepted box failed its variant");
            return;
        };
        let owner = self.key(corner);
        for tri in t.triangles() {
            let ids = tri.map(|v: Vertex| self.vertex_id(v.lower, v.axis));
            if let [Some(a), Some(b), Some(c)] = ids {
                out.push(Owned::new(owner, [a, b, c]));
            }
        }
    }

    /// Pushes the triangles of the unit cubes outside boxes onto `out`, with embedded mode's
    /// merges where no box is near, and returns the merges' owners
    /// ([`merged::unit_triangles`]).
    fn emit_units(
        &self,
        removed: &[u32],
        in_box: impl Fn(u64) -> bool,
        tolerance: &Tolerance,
        out: &mut Vec<Owned>,
    ) -> Vec<u64> {
        let place = |key: u64| self.place(key);
        merged::unit_triangles(
            self.triangles,
            self.rec,
            removed,
            place,
            in_box,
            tolerance,
            out,
        )
    }
}

/// Per pair of cubes (the boxes of side 2), the level of the largest box holding it that may be
/// one (0: none, its cubes stay).
fn final_levels(lattice: &Lattice) -> Vec<u8> {
    let pairs = lattice[0].0;
    let mut level = vec![0u8; pairs.iter().product()];
    for (l, (cells, states)) in lattice.iter().enumerate() {
        let span = 1usize << l;
        for (i, &state) in states.iter().enumerate() {
            if state == Cell::Cubes {
                continue;
            }
            let cell = unkey(i, *cells);
            for k in 0..span * span * span {
                let pair: [usize; 3] =
                    core::array::from_fn(|d| cell[d] * span + k / span.pow(d as u32) % span);
                level[cell_index(pair, pairs)] = l as u8 + 1;
            }
        }
    }
    level
}

/// Splits boxes until no box has a face neighbour less than half its side (the unique minimal
/// 2:1 refinement). Every child of a box was accepted before it, in every variant, so a split
/// never leaves an untested box. Cubes past the last pair of a volume with an odd number of
/// cubes along an axis are unit cubes.
fn balance(level: &mut [u8], pairs: [usize; 3], dims: [usize; 3]) {
    loop {
        let mut changed = false;
        for i in 0..level.len() {
            let l = level[i];
            let first = unkey(i, pairs);
            let span = 1usize << l.saturating_sub(1);
            if l < 2 || first.iter().any(|&c| c % span != 0) {
                continue;
            }
            let too_small = (0..6).any(|face| {
                let (axis, high) = (face / 2, face % 2 == 1);
                let at = if high {
                    first[axis] + span
                } else if first[axis] == 0 {
                    return false;
                } else {
                    first[axis] - 1
                };
                if at >= pairs[axis] {
                    // Unit cubes past the last pair, if the grid has any.
                    return 2 * pairs[axis] < dims[axis] - 1;
                }
                let [a, b] = [(axis + 1) % 3, (axis + 2) % 3];
                (0..span * span).any(|k| {
                    let mut p = first;
                    p[axis] = at;
                    p[a] += k % span;
                    p[b] += k / span;
                    level[cell_index(p, pairs)] + 1 < l
                })
            });
            if too_small {
                for k in 0..span * span * span {
                    let pair: [usize; 3] =
                        core::array::from_fn(|d| first[d] + k / span.pow(d as u32) % span);
                    level[cell_index(pair, pairs)] = l - 1;
                }
                changed = true;
            }
        }
        if !changed {
            return;
        }
    }
}

/// The pair of cubes across face `face` (`2 · axis + side`) of the box whose first pair is
/// `first` and which spans `span` pairs, if that pair exists.
fn across(first: [usize; 3], span: usize, face: usize, pairs: [usize; 3]) -> Option<usize> {
    let (axis, high) = (face / 2, face % 2 == 1);
    let mut p = first;
    if high {
        p[axis] += span;
        if p[axis] >= pairs[axis] {
            return None;
        }
    } else {
        p[axis] = p[axis].checked_sub(1)?;
    }
    Some(cell_index(p, pairs))
}

/// A record's edge key ([`Recorded::point_key`] based) as the sweep orders its vertices.
fn sweep_order(key: u64, dims: [usize; 3]) -> u64 {
    edge_key(dims, unkey((key / 3) as usize, dims), (key % 3) as usize)
}

/// The point of a grid of `dims` with index `i`, x fastest.
fn unkey(i: usize, dims: [usize; 3]) -> [usize; 3] {
    [i % dims[0], i / dims[0] % dims[1], i / (dims[0] * dims[1])]
}

impl<T: Scalar> BoxSource for Grid<'_, T> {
    fn filled(&self, p: [usize; 3]) -> bool {
        self.sample(p).filled(self.threshold)
    }

    fn crossing(&self, lower: [usize; 3], axis: usize) -> Option<Crossing> {
        let mut upper = lower;
        upper[axis] += 1;
        let (a, b) = (self.sample(lower), self.sample(upper));
        let (fa, fb) = (a.filled(self.threshold), b.filled(self.threshold));
        (fa != fb).then(|| Crossing {
            t: sample_crossing(a, b, self.iso),
        })
    }

    fn cube_triangles(&self, cube: [usize; 3], f: &mut dyn FnMut([[f64; 3]; 3])) {
        for i in self.cube_range(self.key(cube)) {
            let t = self.triangles[i];
            f(t.map(|v| self.place(self.rec.edges[v as usize])));
        }
    }
}

fn cell_index(cell: [usize; 3], cells: [usize; 3]) -> usize {
    cell[0] + cells[0] * (cell[1] + cells[1] * cell[2])
}

/// The lattice box across face `face` (`2 · axis + side`) of `cell`, if there is one.
fn neighbour(cell: [usize; 3], face: usize, cells: [usize; 3]) -> Option<usize> {
    let (axis, side) = (face / 2, face % 2);
    let mut n = cell;
    if side == 0 {
        n[axis] = n[axis].checked_sub(1)?;
    } else {
        n[axis] += 1;
        if n[axis] >= cells[axis] {
            return None;
        }
    }
    Some(cell_index(n, cells))
}
