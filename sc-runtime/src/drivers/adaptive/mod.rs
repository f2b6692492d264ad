//! Adaptive mode's driver: one thread, the volume in memory (docs/adaptive.md).
//!
//! 1. The Steps 1–3 mesh is swept as [`Mode::Steps123`](crate::Mode::Steps123) makes it, each
//!    vertex named by its grid edge and each triangle by its cube ([`record`]).
//! 2. Every box of 2×2×2 cubes on the lattice of even samples is decided on its own samples and
//!    Steps 1–3 triangles: empty, refused (it stays eight unit cubes), or accepted because it
//!    passes (S), (F), (P) and (E) in every variant its neighbours could give it
//!    ([`crate::kernel::adaptive`]).
//! 3. The unit cubes outside accepted boxes keep their Steps 1–3 triangles; each accepted box
//!    emits its triangles in the variant its neighbours do give it, and the vertices no
//!    triangle uses any more are dropped.

use alloc::vec;
use alloc::vec::Vec;

use crate::drivers::borrowed::sweep_into;
use crate::drivers::has_cubes;
use crate::kernel::Binary;
use crate::kernel::adaptive::checks::Patch;
use crate::kernel::adaptive::outline::Shape;
use crate::kernel::adaptive::{
    BoxSource, Crossing, Metric, SIDE, Vertex, accept, outline, triangulate,
};
use crate::kernel::vertex::sample_crossing;
use crate::mesh::OwnedScratch;
use crate::{Error, ErrorBound, Mesh, Mode, Params, Scalar, Stats, Volume};

mod record;

use record::Recorded;

/// The bound adaptive mode holds when none is given: half the smallest spacing, in world units
/// (half a voxel where the spacing is even).
fn default_bound(params: &Params) -> ErrorBound {
    let least = params.spacing.iter().copied().fold(f64::INFINITY, f64::min);
    ErrorBound::World(0.5 * least)
}

/// The largest box adaptive mode makes, in cubes.
pub(crate) const LARGEST_BOX: u32 = SIDE as u32;

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

/// Extracts the adaptive mesh of `volume` (see the module's steps).
pub(crate) fn extract<T: Scalar>(volume: &Volume<'_, T>, params: &Params) -> Result<Mesh, Error> {
    let dims = volume.dims();
    check(params, dims)?;
    let steps123 = Params {
        mode: Mode::Steps123,
        max_error: None,
        max_box: None,
        ..*params
    };
    let mut rec = Recorded::new(dims);
    let mut scratch = OwnedScratch::new(dims)?;
    let stats = sweep_into(
        &Binary::new(&steps123),
        volume,
        &steps123,
        scratch.lend(),
        &mut rec,
    )?;
    drop(scratch);
    let mut mesh = core::mem::take(&mut rec.mesh);
    mesh.stats = Stats {
        v13: stats.v13,
        t13: stats.t13,
        ..Stats::default()
    };
    let side = params.max_box.unwrap_or(LARGEST_BOX) as usize;
    if !has_cubes(dims) || side < SIDE {
        mesh.stats.vertices = mesh.positions.len() as u64;
        mesh.stats.triangles = mesh.triangles.len() as u64;
        return Ok(mesh);
    }
    let bound = params.max_error.unwrap_or_else(|| default_bound(params));
    let metric = Metric {
        scale: match bound {
            ErrorBound::World(_) => params.spacing,
            ErrorBound::Voxels(_) => [1.0; 3],
        },
        limit: bound.value(),
    };
    let grid = Grid::new(volume, params.iso, &rec, &mesh.triangles);
    let cells = dims.map(|d| (d - 1) / SIDE);
    let boxes = grid.decide(cells, &metric);
    let triangles = grid.emit(cells, &boxes, &metric);
    drop(grid);
    mesh.triangles = triangles;
    compact(&mut mesh);
    mesh.stats.vertices = mesh.positions.len() as u64;
    mesh.stats.triangles = mesh.triangles.len() as u64;
    Ok(mesh)
}

/// A box on the lattice: whether it replaces its unit cubes.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Cell {
    /// Its unit cubes keep their Steps 1–3 triangles.
    Cubes,
    /// No occupied edge: a box that emits nothing.
    Empty,
    /// A box that emits its own triangles.
    Box,
}

/// The volume, its Steps 1–3 mesh and the lookups the boxes need.
struct Grid<'a, T: Scalar> {
    data: &'a [T],
    dims: [usize; 3],
    iso: f64,
    threshold: T::Threshold,
    /// Vertex edge keys with their ids, sorted by key.
    vertex_of: Vec<(u64, u32)>,
    /// Triangle ids sorted by their cube's key, with those keys.
    by_cube: Vec<(u64, u32)>,
    triangles: &'a [[u32; 3]],
    edges: &'a [u64],
    cubes: &'a [u64],
}

impl<'a, T: Scalar> Grid<'a, T> {
    fn new(volume: &Volume<'a, T>, iso: f64, rec: &'a Recorded, triangles: &'a [[u32; 3]]) -> Self {
        let mut vertex_of: Vec<(u64, u32)> = rec
            .edges
            .iter()
            .enumerate()
            .map(|(i, &k)| (k, i as u32))
            .collect();
        vertex_of.sort_unstable();
        let mut by_cube: Vec<(u64, u32)> = rec
            .cubes
            .iter()
            .enumerate()
            .map(|(i, &k)| (k, i as u32))
            .collect();
        by_cube.sort_unstable();
        Grid {
            data: volume.data(),
            dims: volume.dims(),
            iso,
            threshold: T::threshold(iso),
            vertex_of,
            by_cube,
            triangles,
            edges: &rec.edges,
            cubes: &rec.cubes,
        }
    }

    fn key(&self, p: [usize; 3]) -> u64 {
        (p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])) as u64
    }

    fn sample(&self, p: [usize; 3]) -> T {
        self.data[p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])]
    }

    fn vertex_id(&self, lower: [usize; 3], axis: usize) -> Option<u32> {
        let key = 3 * self.key(lower) + axis as u64;
        let i = self.vertex_of.partition_point(|&(k, _)| k < key);
        self.vertex_of
            .get(i)
            .filter(|&&(k, _)| k == key)
            .map(|&(_, id)| id)
    }

    /// A vertex's place in grid steps, from its edge key.
    fn place(&self, key: u64) -> [f64; 3] {
        let axis = (key % 3) as usize;
        let point = (key / 3) as usize;
        let lower = [
            point % self.dims[0],
            point / self.dims[0] % self.dims[1],
            point / (self.dims[0] * self.dims[1]),
        ];
        let mut upper = lower;
        upper[axis] += 1;
        let t = sample_crossing(self.sample(lower), self.sample(upper), self.iso);
        core::array::from_fn(|d| lower[d] as f64 + if d == axis { t } else { 0.0 })
    }

    /// The triangles of the cube with key `cube`.
    fn cube_range(&self, cube: u64) -> &[(u64, u32)] {
        let lo = self.by_cube.partition_point(|&(k, _)| k < cube);
        let hi = self.by_cube.partition_point(|&(k, _)| k <= cube);
        &self.by_cube[lo..hi]
    }

    /// Decides every box of the lattice, `cells` boxes along each axis.
    fn decide(&self, cells: [usize; 3], metric: &Metric) -> Vec<Cell> {
        let mut boxes = vec![Cell::Cubes; cells.iter().product()];
        for cz in 0..cells[2] {
            for cy in 0..cells[1] {
                for cx in 0..cells[0] {
                    let cell = [cx, cy, cz];
                    let corner = cell.map(|c| c * SIDE);
                    boxes[cell_index(cell, cells)] = match outline(self, corner) {
                        Shape::Empty => Cell::Empty,
                        Shape::Complex => Cell::Cubes,
                        Shape::Simple(o) => {
                            let may_chord = (0..o.n).fold(0u8, |m, i| {
                                let face = usize::from(o.arc_face[i]);
                                match neighbour(cell, face, cells) {
                                    Some(_) => m | 1 << i,
                                    None => m,
                                }
                            });
                            let patch = Patch::new(self, corner, metric);
                            if accept(self, &o, may_chord, &patch, metric) {
                                Cell::Box
                            } else {
                                Cell::Cubes
                            }
                        }
                    };
                }
            }
        }
        boxes
    }

    /// The triangles: those of unit cubes outside boxes, in sweep order, then each box's in the
    /// variant its neighbours give it.
    fn emit(&self, cells: [usize; 3], boxes: &[Cell], metric: &Metric) -> Vec<[u32; 3]> {
        let cell_of = |cube_key: u64| -> Option<usize> {
            let k = cube_key as usize;
            let cube = [
                k % self.dims[0],
                k / self.dims[0] % self.dims[1],
                k / (self.dims[0] * self.dims[1]),
            ];
            let cell = cube.map(|c| c / SIDE);
            (0..3)
                .all(|d| cell[d] < cells[d])
                .then(|| cell_index(cell, cells))
        };
        let mut out: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .zip(self.cubes)
            .filter(|&(_, &c)| c == u64::MAX || cell_of(c).is_none_or(|i| boxes[i] != Cell::Box))
            .map(|(&t, _)| t)
            .collect();
        for cz in 0..cells[2] {
            for cy in 0..cells[1] {
                for cx in 0..cells[0] {
                    let cell = [cx, cy, cz];
                    if boxes[cell_index(cell, cells)] != Cell::Box {
                        continue;
                    }
                    let corner = cell.map(|c| c * SIDE);
                    let Shape::Simple(o) = outline(self, corner) else {
                        continue;
                    };
                    let refined = (0..o.n).fold(0u8, |m, i| {
                        let face = usize::from(o.arc_face[i]);
                        match neighbour(cell, face, cells) {
                            Some(j) if boxes[j] != Cell::Cubes => m,
                            _ => m | 1 << i,
                        }
                    });
                    let patch = Patch::new(self, corner, metric);
                    // Accepted boxes triangulate in every variant (`accept`), and the choice
                    // depends on the box and its variant alone.
                    let Some(t) = triangulate(self, &o, refined, &patch, metric) else {
                        debug_assert!(false, "an accepted box failed its variant");
                        continue;
                    };
                    for tri in t.triangles() {
                        let ids = tri.map(|v: Vertex| self.vertex_id(v.lower, v.axis));
                        if let [Some(a), Some(b), Some(c)] = ids {
                            out.push([a, b, c]);
                        }
                    }
                }
            }
        }
        out
    }
}

impl<T: Scalar> BoxSource for Grid<'_, T> {
    fn crossing(&self, lower: [usize; 3], axis: usize) -> Option<Crossing> {
        let mut upper = lower;
        upper[axis] += 1;
        let (a, b) = (self.sample(lower), self.sample(upper));
        let (fa, fb) = (a.filled(self.threshold), b.filled(self.threshold));
        (fa != fb).then(|| Crossing {
            t: sample_crossing(a, b, self.iso),
            lower_filled: fa,
        })
    }

    fn cube_triangles(&self, cube: [usize; 3], f: &mut dyn FnMut([[f64; 3]; 3])) {
        for &(_, i) in self.cube_range(self.key(cube)) {
            let t = self.triangles[i as usize];
            f(t.map(|v| self.place(self.edges[v as usize])));
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

/// Drops the vertices no triangle uses, keeping the others' order.
fn compact(mesh: &mut Mesh) {
    let n = mesh.positions.len();
    let mut new_id = vec![u32::MAX; n];
    for t in &mesh.triangles {
        for &v in t {
            new_id[v as usize] = 0;
        }
    }
    let mut next = 0u32;
    for id in new_id.iter_mut() {
        if *id == 0 {
            *id = next;
            next += 1;
        }
    }
    keep_column(&mut mesh.positions, &new_id);
    keep_column(&mut mesh.normals, &new_id);
    keep_column(&mut mesh.values, &new_id);
    for t in &mut mesh.triangles {
        *t = t.map(|v| new_id[v as usize]);
    }
}

/// Keeps the entries of a per-vertex column (empty when not asked for) whose vertex stays.
fn keep_column<C>(column: &mut Vec<C>, new_id: &[u32]) {
    if column.is_empty() {
        return;
    }
    let mut i = 0;
    column.retain(|_| {
        i += 1;
        new_id[i - 1] != u32::MAX
    });
}
