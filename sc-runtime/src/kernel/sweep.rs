//! The layer sweep: Steps 1–4 over one z range with O(nx·ny) memory (SPEC §1–5).
//!
//! Layer `k` (cubes from `z = k` to `k + 1`) is finished before layer `k + 1` starts. Its output
//! needs slices `k − 1 ..= k + 2`: the merge decision for a grey edge in plane `k + 1` looks at the
//! cubes of layer `k + 1`, and normals take central differences. Vertices are numbered in a fixed
//! order, plane 0, z-edges of layer 0, plane 1, z-edges of layer 1, …, and within each group row by
//! row, so a sweep that starts at any layer numbers the vertices the way a full sweep does, offset
//! by a constant. That is what makes the parallel mesh identical to the sequential one.
//!
//! Like Flying Edges, every pass skips the parts of a row where nothing changes: a classified row
//! records where its x-edges change, and a cube row only visits the span where its four sample
//! rows can disagree.

use core::num::NonZeroU8;

use wide::u8x16;

use crate::kernel::scratch::{PAD, Scratch, WORD_PLANES};
use crate::kernel::vertex::{Field, InteriorPlane, InteriorRow, Normal, Steps, wide_crossing};
use crate::tables::{BACK_SHARED, Entry};

mod ahead;
mod bound;
mod cube_ids;
mod edge_row;
mod greys;
use crate::kernel::engine::{Binary, Engine, Layers, Slices};
use crate::{Axes, Error, Mode, Params, Scalar, Sink, Stats};
use ahead::Ahead;
use cube_ids::{Cube, CubeIds};
use edge_row::EdgeRow;
use greys::{Around, Greys};

/// Calls a vertex pass in the copy for the output the parameters ask for: with or without
/// normals, and with `(x, y, z)` or `(z, y, x)` coordinates. Each is a copy of its own: in one
/// copy the normals' per-row state would take registers from the other's scan, and a test of
/// the axis order per vertex would cost instructions on every vertex.
macro_rules! with_output {
    ($sweep:ident, $pass:ident($($arg:expr),*)) => {
        match ($sweep.params.normals, $sweep.params.axes) {
            (false, Axes::Xyz) => $sweep.$pass::<false, false>($($arg),*),
            (true, Axes::Xyz) => $sweep.$pass::<true, false>($($arg),*),
            (false, Axes::Zyx) => $sweep.$pass::<false, true>($($arg),*),
            (true, Axes::Zyx) => $sweep.$pass::<true, true>($($arg),*),
        }
    };
}

/// The top bit of a classified row's span words: its first and last bytes (see `Grid::ends`).
const END_BIT: u32 = 1 << 31;

/// Vertex id of a grey edge merged away by Step 4.
const MERGED: u32 = u32::MAX;

/// What Step 4 does with an occupied grey edge.
#[derive(Clone, Copy)]
enum Decision {
    /// Not mergeable in this mode, or on the grid boundary.
    Keep,
    /// Merged: its vertex disappears and its four ears become two triangles.
    Merge(Around),
    /// Interior, but embedded mode's rules (a) or (b) forbid the merge.
    Blocked,
}

/// What the vertex and triangle passes read: classified slices, cube cases and row spans. Kept
/// apart from [`Out`] so a pass can read rows while it writes vertex ids.
struct Grid<'s> {
    dims: [usize; 3],
    mode: Mode,
    entries: &'static [Entry; 2048],
    /// Per entry, bit `axis` set iff that grey edge may merge (embedded table).
    mergeable: &'static [u8; 2048],
    /// Four slices of 0/1 bytes, slice `z` at `z % 4`, then [`PAD`] bytes.
    filled: &'s mut [u8],
    /// Three layers of cube cases, layer `k` at `k % 3`, row stride `nx`, then [`PAD`] bytes.
    cases: &'s mut [u8],
    /// Per classified row (slice `z` at `z % 4`, `ny` rows each), the x-edge changes lie in
    /// `lo..hi` (`lo = nx − 1`, `hi = 0` for a uniform row), with the row's first and last bytes
    /// in the top bits (see [`union_span`]).
    row_spans: &'s mut [Span],
    /// Per cube row (layer `k` at `k % 3`), the non-trivial cubes lie in `lo..hi`.
    case_spans: &'s mut [Span],
    /// Where these samples sit in the whole grid: a block's vertices and triangles are reported
    /// in global indices, and the parity classes follow global indices.
    offset: [usize; 3],
    /// Per axis, the cubes whose triangles this sweep emits and the edge lower ends it counts
    /// (local indices); everything, except for a block, whose halo is only read.
    own_cubes: [(usize, usize); 3],
    own_edges: [(usize, usize); 3],
    /// Whether `own_edges` leaves any edge out (a block's sweep): otherwise the per-vertex
    /// ownership test is skipped.
    restricted: bool,
}

/// Vertex numbering and counts.
struct Out<'s> {
    /// Merge marks of two layers of cubes in one byte per cube: bit `3 · (k % 2) + axis` set iff
    /// that grey edge of the cube in layer `k` merged. The triangle pass reads one byte per cube
    /// instead of three vertex ids.
    merged: &'s mut [u8],
    next_id: u32,
    /// False while numbering a first plane that the previous parallel chunk emits.
    emit: bool,
    stats: Stats,
}

pub(crate) struct Sweep<'s, T: Scalar> {
    grid: Grid<'s>,
    out: Out<'s>,
    /// Two planes of x- then y-edge ids (plane `n` at `n % 2`), then one layer of z-edge ids:
    /// apart from [`Out`], so that a vertex pass can hold a row of them while it numbers.
    ids: &'s mut [u32],
    params: Params,
    threshold: T::Threshold,
    /// The layer `start` prepared: where this sweep's output began.
    first_layer: usize,
    /// The gradient's reciprocal steps, computed once.
    steps: Steps,
}

impl<T: Scalar> Engine<T> for Binary<T> {
    type Sweep<'s> = Sweep<'s, T>;

    fn sweep<'s>(&self, dims: [usize; 3], params: &Params, scratch: Scratch<'s>) -> Sweep<'s, T> {
        Sweep::new(dims, params, self.threshold, scratch)
    }

    #[cfg(feature = "alloc")]
    fn classify_row(&self, row: &[T], out: &mut [u8]) {
        T::classify_row(row, self.threshold, out);
    }
}

impl<'s, T: Scalar> Sweep<'s, T> {
    fn new(
        dims: [usize; 3],
        params: &Params,
        threshold: T::Threshold,
        scratch: Scratch<'s>,
    ) -> Self {
        let nxy = dims[0] * dims[1];
        let (filled, rest) = scratch.bytes.split_at_mut(4 * nxy + PAD);
        let (cases, merged) = rest.split_at_mut(3 * nxy + PAD);
        let (ids, spans) = scratch.words.split_at_mut(WORD_PLANES * nxy);
        let (row_spans, case_spans) = spans.as_chunks_mut().0.split_at_mut(4 * dims[1]);
        Sweep {
            grid: Grid {
                dims,
                mode: params.mode,
                entries: params.tables.for_mode(params.mode),
                mergeable: params.tables.mergeable(),
                filled,
                cases,
                row_spans,
                case_spans,
                offset: [0; 3],
                own_cubes: dims.map(|n| (0, n.saturating_sub(1))),
                own_edges: dims.map(|n| (0, n)),
                restricted: false,
            },
            out: Out {
                merged: &mut merged[..nxy],
                next_id: 0,
                emit: true,
                stats: Stats::default(),
            },
            ids,
            params: *params,
            threshold,
            first_layer: 0,
            steps: Steps::new(params.spacing),
        }
    }
}

impl<T: Scalar> Layers<T> for Sweep<'_, T> {
    /// Makes this a block's sweep: its samples start at `offset` in the whole grid, and it emits
    /// the triangles of the local cubes `own` only, counting the edges whose lower ends those
    /// cubes hold (and, on the grid's far side, the last sample's edges too).
    #[cfg(feature = "alloc")]
    fn restrict(&mut self, offset: [usize; 3], own: [(usize, usize); 3]) {
        let dims = self.grid.dims;
        self.grid.offset = offset;
        self.grid.own_cubes = own;
        self.grid.restricted = true;
        self.grid.own_edges = core::array::from_fn(|d| {
            (
                own[d].0,
                if own[d].1 + 1 == dims[d] {
                    dims[d]
                } else {
                    own[d].1
                },
            )
        });
    }

    fn stats(&self) -> Stats {
        self.out.stats
    }

    /// Number of vertex ids handed out, including those of a first plane not emitted.
    #[cfg(feature = "std")]
    fn ids_used(&self) -> u32 {
        self.out.next_id
    }

    /// Prepares layer `z0`: classifies slices `z0 − 1 ..= z0 + 1`, computes cases of layers
    /// `z0 − 1` and `z0`, and numbers plane `z0`'s vertices. With `emit_plane` false (a parallel
    /// chunk after the first), those vertices are numbered but belong to the previous chunk.
    fn start(
        &mut self,
        z0: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
        emit_plane: bool,
    ) -> Result<(), Error> {
        for z in z0.saturating_sub(1)..=z0 + 1 {
            self.grid.classify::<T>(z, src.slice(z), self.threshold);
        }
        if z0 >= 1 {
            self.grid.compute_cases(z0 - 1);
        }
        // Plane z0's merges mark the cubes of layers z0 − 1 and z0.
        self.out.merged.fill(0);
        self.grid.compute_cases(z0);
        self.first_layer = z0;
        self.out.emit = emit_plane;
        let r = with_output!(self, plane_vertices(z0, src, sink));
        sink.settle_normals();
        self.out.emit = true;
        r
    }

    /// Runs layer `k`; slices `k − 1 ..= k + 2` (those that exist) must be readable.
    fn layer(&mut self, k: usize, src: &impl Slices<T>, sink: &mut impl Sink) -> Result<(), Error> {
        if k + 2 < self.grid.dims[2] {
            self.grid
                .classify::<T>(k + 2, src.slice(k + 2), self.threshold);
            self.grid.compute_cases(k + 1);
        }
        // Plane k + 1's merges start marking layer k + 1, whose bits layer k − 1 used: they lie
        // on cubes around merged grey edges, crossed cubes, so within layer k − 1's case spans.
        // Clearing the whole plane cost 1 % of brainsmall's instructions.
        if k >= 1 {
            let stale = !(7u8 << (3 * ((k + 1) % 2)));
            let [nx, ny, _] = self.grid.dims;
            let spans = &self.grid.case_spans[((k - 1) % 3) * ny..][..ny - 1];
            for (row, &span) in self.out.merged.chunks_exact_mut(nx).zip(spans) {
                let (lo, hi) = lo_hi(span);
                if lo < hi {
                    row[lo..hi].iter_mut().for_each(|m| *m &= stale);
                }
            }
        }
        with_output!(self, vertex_passes(k, src, sink))?;
        sink.settle_normals();
        let (own_lo, own_hi) = self.grid.own_cubes[2];
        if (own_lo..own_hi).contains(&k) {
            // Slice `k + 3`, which layer `k + 1` classifies first.
            let (y_lo, y_hi) = self.grid.own_cubes[1];
            let ahead = Ahead::new(src.ahead(k + 3), y_hi.saturating_sub(y_lo));
            if self.grid.mode == Mode::Steps123 {
                self.triangles::<false, 0>(k, sink, &ahead);
            } else if k.is_multiple_of(2) {
                self.triangles::<true, 0>(k, sink, &ahead);
            } else {
                self.triangles::<true, 3>(k, sink, &ahead);
            }
        }
        if self.out.emit {
            // Layers done since this sweep started, and the ones left, extrapolate the output.
            let done = (k + 1 - self.first_layer) as u64;
            let left = (self.grid.dims[2] - 1).saturating_sub(k + 1) as u64;
            let per = |n: u64| usize::try_from(n.saturating_mul(left) / done).unwrap_or(usize::MAX);
            sink.expect(per(self.out.stats.vertices), per(self.out.stats.triangles));
        }
        Ok(())
    }
}

impl<T: Scalar> Sweep<'_, T> {
    fn field<'v>(&self, src: &'v impl Slices<T>, z_lo: usize, z_hi: usize) -> Field<'v, T> {
        let nz = self.grid.dims[2];
        let first = z_lo.saturating_sub(1);
        // Slices past the grid stay empty: reading one fails like an index past the data.
        let mut slices: [&[T]; 4] = [&[]; 4];
        for (i, z) in (first..=(z_hi + 1).min(nz - 1)).enumerate() {
            slices[i] = src.slice(z);
        }
        Field {
            dims: self.grid.dims,
            steps: self.steps,
            slices,
            first,
        }
    }

    /// Layer `k`'s vertex passes: its z-edges, then plane `k + 1`'s x- and y-edges.
    #[inline(always)]
    fn vertex_passes<const NORMALS: bool, const ZYX: bool>(
        &mut self,
        k: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
    ) -> Result<(), Error> {
        self.z_vertices::<NORMALS, ZYX>(k, src, sink)?;
        self.plane_vertices::<NORMALS, ZYX>(k + 1, src, sink)
    }

    /// Vertices on the x- and y-edges of plane `n`, row by row.
    // Not inlined: each pass runs once per layer, and apart it shows in a profile.
    #[inline(never)]
    fn plane_vertices<const NORMALS: bool, const ZYX: bool>(
        &mut self,
        n: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
    ) -> Result<(), Error> {
        let [nx, ny, _] = self.grid.dims;
        let field = self.field(src, n, n);
        let samples = src.slice(n);
        let (grid, out, params, ids) = (&self.grid, &mut self.out, &self.params, &mut *self.ids);
        let (x_greys, y_greys) = (Greys::<0>::new(grid, n), Greys::<1>::new(grid, n));
        let (x_plane, y_plane) = (
            field.interior_plane::<0>(n, NORMALS),
            field.interior_plane::<1>(n, NORMALS),
        );
        let xbase = (n % 2) * 2 * nx * ny;
        let ybase = xbase + nx * ny;
        let spans = grid.plane_spans(n);
        for y in 0..ny {
            let (lo, hi) = lo_hi(spans[y]);
            let (start, end) = if y + 1 < ny {
                union_span([spans[y], spans[y + 1]], nx)
            } else {
                (0, 0)
            };
            // Rows wholly inside or outside the surface, with their neighbour, are skipped before
            // anything is sliced: slicing the rows cost more than scanning them.
            if lo >= hi && start >= end {
                continue;
            }
            let row = grid.padded_row(n, y);
            let values = &samples[y * nx..][..nx];
            let greys = x_greys.as_ref().and_then(|greys| greys.in_row(y));
            let at = RowContext::new(grid, params, &field, x_plane.as_ref(), greys, y, n);
            EdgeRow::new(values, &values[1..], &mut ids[xbase + y * nx..][..nx]).scan(
                (row, &row[1..]),
                lo,
                hi,
                |x, ends| out.edge_vertex::<T, 0, NORMALS, ZYX>(&at, [x, y, n], ends, sink),
            )?;
            if y + 1 < ny {
                let next = grid.padded_row(n, y + 1);
                let next_values = &samples[(y + 1) * nx..][..nx];
                let at = RowContext::new(
                    grid,
                    params,
                    &field,
                    y_plane.as_ref(),
                    y_greys.as_ref(),
                    y,
                    n,
                );
                let mut edges = EdgeRow::new(values, next_values, &mut ids[ybase + y * nx..][..nx]);
                edges.scan((row, next), start, end, |x, ends| {
                    out.edge_vertex::<T, 1, NORMALS, ZYX>(&at, [x, y, n], ends, sink)
                })?;
            }
        }
        Ok(())
    }

    /// Vertices on the z-edges of layer `k`, row by row.
    // Not inlined: each pass runs once per layer, and apart it shows in a profile.
    #[inline(never)]
    fn z_vertices<const NORMALS: bool, const ZYX: bool>(
        &mut self,
        k: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
    ) -> Result<(), Error> {
        let [nx, ny, _] = self.grid.dims;
        let field = self.field(src, k, k + 1);
        let (lower, upper) = (src.slice(k), src.slice(k + 1));
        let (grid, out, params, ids) = (&self.grid, &mut self.out, &self.params, &mut *self.ids);
        let greys = Greys::<2>::new(grid, k);
        let plane = field.interior_plane::<2>(k, NORMALS);
        let zbase = 4 * nx * ny;
        let (below, above) = (grid.plane_spans(k), grid.plane_spans(k + 1));
        for y in 0..ny {
            let (start, end) = union_span([below[y], above[y]], nx);
            // As in `plane_vertices`: nothing is sliced for a row with nothing to scan.
            if start >= end {
                continue;
            }
            let (below, above) = (grid.padded_row(k, y), grid.padded_row(k + 1, y));
            let (lower, upper) = (&lower[y * nx..][..nx], &upper[y * nx..][..nx]);
            let row_greys = greys.as_ref().and_then(|greys| greys.in_row(y));
            let at = RowContext::new(grid, params, &field, plane.as_ref(), row_greys, y, k);
            let mut edges = EdgeRow::new(lower, upper, &mut ids[zbase + y * nx..][..nx]);
            edges.scan((below, above), start, end, |x, ends| {
                out.edge_vertex::<T, 2, NORMALS, ZYX>(&at, [x, y, k], ends, sink)
            })?;
        }
        Ok(())
    }

    /// Steps 3 and 4: each cube's table triangles, with the ears of merged grey edges replaced
    /// (`MERGING`, a constant so that Steps 1–3 get a copy without the merge marks). `SHIFT` is
    /// where layer `k`'s marks lie in their bytes, `3 · (k % 2)` (see [`Out::merged`]): a
    /// constant, one copy per layer parity, as a shift by a variable cost the merging pass two
    /// instructions per crossed cube. Each cube row also fetches its share of the slice `ahead`.
    // Not inlined: each pass runs once per layer, and apart it shows in a profile.
    #[inline(never)]
    fn triangles<const MERGING: bool, const SHIFT: u8>(
        &mut self,
        k: usize,
        sink: &mut impl Sink,
        ahead: &Ahead,
    ) {
        let [nx, ny, _] = self.grid.dims;
        let nxy = nx * ny;
        let grid = &self.grid;
        let ids = CubeIds::new(self.ids, self.out.merged, grid.dims, k);
        // Counted in locals, added to the stats once: stores to the stats on every cube could
        // not be moved past the loop's bounds checks.
        let (mut t13, mut triangles) = (0u64, 0u64);
        let entries = grid.entries;
        let [ox, oy, oz] = grid.offset;
        let [(x_lo, x_hi), (y_lo, y_hi), _] = grid.own_cubes;
        let spans = (k % 3) * ny;
        let pairs = grid.partners(k);
        for j in y_lo..y_hi {
            ahead.fetch(j - y_lo);
            let (start, end) = lo_hi(grid.case_spans[spans + j]);
            let cases = &grid.cases[(k % 3) * nxy + j * nx..];
            let class_jk = ((j + oy) & 1) << 1 | ((k + oz) & 1) << 2;
            let (start, end) = (start.max(x_lo), end.min(x_hi));
            if start >= end {
                continue;
            }
            for_each_crossed(cases, start, end, |i, case| {
                let class = ((i + ox) & 1) | class_jk;
                let entry = &entries[class * 256 + usize::from(case)];
                t13 += u64::from(entry.count);
                let at = i + nx * j;
                // Every cube the scan visits is one: the test is what lets the ids be read
                // unchecked.
                let Some(cube) = ids.cube(at) else {
                    return;
                };
                // A merged grey edge's ear is dropped; the pair's owner emits the merged
                // triangle in its place (its partner emits nothing). Table lookups rather than
                // branches: which greys merged is data, and data-dependent branches mispredict.
                let mut kept = entry.kept[0];
                if MERGING {
                    let marks = usize::from(cube.marks() >> SHIFT & 7);
                    kept = entry.kept[marks];
                    // Most crossed cubes own no merged pair, many own one, a few more: the
                    // first pair's triangle is made whether or not there is one, and kept if
                    // there is. A loop over the owned pairs mispredicted on two cubes in five
                    // (callgrind's branch simulation, the ITK MRI); without it, one thread takes
                    // 0.96–1.0 times the time.
                    let owned = marks as u8 & entry.owned_ears;
                    let any = owned != 0;
                    // Axis 0 for none, with its partner the cube itself: every read stays within
                    // the cube's own data.
                    let axis = (owned.trailing_zeros() & 3) as usize;
                    let pair = core::hint::select_unpredictable(any, pairs[axis], (0, 0));
                    let owner = (cube, &cases[i..], class);
                    let mut merge = |axis: usize, pair, keep: bool| {
                        let t = grid.merged_triangle(owner, axis, pair, entry);
                        debug_assert!(
                            !keep || grid.ears_share_a_side(owner, axis, pair, entry, t),
                            "ears around a merged grey edge share a face side"
                        );
                        sink.cube_triangle_if([i + ox, j + oy, k + oz], t, keep);
                        triangles += u64::from(keep);
                    };
                    merge(axis, pair, any);
                    let mut more = owned & owned.wrapping_sub(1);
                    while more != 0 {
                        let axis = more.trailing_zeros() as usize;
                        more &= more - 1;
                        merge(axis, pairs[axis], true);
                    }
                }
                // Five triangles at most: the mask says so to the compiler, which then drops
                // the bounds check on `tris` (and the zero test of `trailing_zeros`).
                kept &= (1 << entry.tris.len()) - 1;
                while let Some(set) = NonZeroU8::new(kept) {
                    let n = set.trailing_zeros() as usize;
                    kept &= kept - 1;
                    triangles += 1;
                    let [a, b, c] = entry.tris[n];
                    let t = [cube.id(a), cube.id(b), cube.id(c)];
                    sink.cube_triangle([i + ox, j + oy, k + oz], t);
                }
            });
        }
        self.out.stats.t13 += t13;
        self.out.stats.triangles += triangles;
    }
}

/// What a vertex pass hands [`Out::edge_vertex`] for every edge along `AXIS` of a row.
struct RowContext<'a, 'v, T, const AXIS: usize> {
    grid: &'a Grid<'a>,
    params: &'a Params,
    /// The samples, for the bound on Step 4 and for normals.
    field: &'a Field<'v, T>,
    /// For normals, the row's unchecked view of the field.
    normals: Option<InteriorRow<'a, 'v, T, AXIS>>,
    /// For Step 4, the plane's grey edges if the row has any.
    greys: Option<&'a Greys<'a, AXIS>>,
    /// The row's y and z in world units, in lanes 1 and 2 (lane 0 is unused): the coordinates its
    /// vertices share except along their edge's axis, computed once per row as [`send`] would
    /// per vertex.
    fixed: [f32; 3],
}

impl<'a, 'v, T: Scalar, const AXIS: usize> RowContext<'a, 'v, T, AXIS> {
    /// The context of row `y` of plane `z`, whose rows for normals are `plane`'s.
    #[inline(always)]
    fn new(
        grid: &'a Grid<'a>,
        params: &'a Params,
        field: &'a Field<'v, T>,
        plane: Option<&'a InteriorPlane<'v, T, AXIS>>,
        greys: Option<&'a Greys<'a, AXIS>>,
        y: usize,
        z: usize,
    ) -> Self {
        let world = |d: usize, c: usize| world(params, d, (c + grid.offset[d]) as i64 as f64);
        RowContext {
            grid,
            params,
            field,
            normals: plane.and_then(|plane| plane.row(y)),
            greys,
            fixed: [0.0, world(1, y), world(2, z)],
        }
    }
}

/// Grid coordinate `c` along axis `d` in world units.
#[inline(always)]
fn world(params: &Params, d: usize, c: f64) -> f32 {
    (params.origin[d] + c * params.spacing[d]) as f32
}

impl Out<'_> {
    /// Marks the four cubes around a merged grey edge along `AXIS` (see [`Out::merged`]). An x-
    /// or y-edge's cubes lie in two layers, one of each parity, so two bytes each take both
    /// layers' bits.
    #[inline(always)]
    fn mark_merged<const AXIS: usize>(&mut self, nx: usize, around: Around) {
        let (at, m) = (around.plane(), &mut *self.merged);
        // Unchecked: with a bounds test per cube (or one for all four, which panics) the vertex
        // passes kept more values live around it, 1–2 % of the sweep's instructions.
        let mut mark = |c: usize, bits: u8| {
            debug_assert!(c < m.len());
            // SAFETY: `c <= at + nx + 1`, below `nx · ny` for the cubes around an interior edge
            // (`Around::plane`), and the marks are a plane of cubes, `nx · ny` long
            // (`Sweep::new`).
            unsafe { *m.get_unchecked_mut(c) |= bits };
        };
        match AXIS {
            0 => {
                mark(at, 0b1001);
                mark(at + nx, 0b1001);
            }
            1 => {
                mark(at, 0b1001 << 1);
                mark(at + 1, 0b1001 << 1);
            }
            _ => {
                let bit = 1 << (3 * (around.k() % 2) + 2);
                for c in [at, at + 1, at + nx, at + nx + 1] {
                    mark(c, bit);
                }
            }
        }
    }

    /// Occupied edge bookkeeping shared by all three edge kinds: count, decide, number. The
    /// axis is a constant so each pass gets its own copy with the axis tests folded away; the
    /// caller reads the edge's two samples straight from its rows.
    #[inline(always)]
    fn edge_vertex<T: Scalar, const AXIS: usize, const NORMALS: bool, const ZYX: bool>(
        &mut self,
        row: &RowContext<'_, '_, T, AXIS>,
        p: [usize; 3],
        (a, b): (T, T),
        sink: &mut impl Sink,
    ) -> Result<u32, Error> {
        let RowContext {
            grid,
            params,
            field,
            ..
        } = *row;
        let counted = self.emit && grid.owns_edge(p);
        self.stats.v13 += u64::from(counted);
        // Only a grey edge has a decision to count: three in four occupied edges skip it. Where
        // the row has no `greys`, each would be kept.
        if let Some(greys) = row.greys
            && greys.is_grey(p[0])
        {
            let mut decision = greys.decide(p[0], p[1]);
            let mut bounded = false;
            if let Decision::Merge(_) = decision
                && let Some(bound) = params.max_error
                && !grid.within_bound(p, AXIS, bound, field, params)
            {
                decision = Decision::Blocked;
                bounded = true;
            }
            if counted {
                self.stats.merged += u64::from(matches!(decision, Decision::Merge(_)));
                self.stats.blocked += u64::from(matches!(decision, Decision::Blocked));
                self.stats.bounded += u64::from(bounded);
            }
            if let Decision::Merge(around) = decision {
                self.mark_merged::<AXIS>(grid.dims[0], around);
                return Ok(MERGED);
            }
        }
        let id = self.next_id;
        if id == MERGED {
            return Err(Error::TooManyVertices);
        }
        self.next_id += 1;
        if self.emit {
            self.stats.vertices += u64::from(counted);
            let ends = (a.to_f64(), b.to_f64());
            let t = wide_crossing(ends.0, ends.1, params.iso);
            // An `if`, not `bool::then` with a closure: in the Python extension's build the
            // closure was left out of line, three calls per vertex and 40 % more normals time.
            let normal = if NORMALS {
                Some(field.normal::<AXIS>(row.normals, p, ends, params.iso))
            } else {
                None
            };
            send::<T, AXIS, ZYX>(row, p, t, normal, ends, sink);
        }
        Ok(id)
    }
}

/// Sends the vertex `t` along the edge from `p` along `AXIS`, whose samples are `(a, b)`, with
/// its value when [`Params::values`] asks for one.
#[inline(always)]
fn send<T, const AXIS: usize, const ZYX: bool>(
    row: &RowContext<'_, '_, T, AXIS>,
    p: [usize; 3],
    t: f64,
    normal: Option<Normal>,
    (a, b): (f64, f64),
    sink: &mut impl Sink,
) {
    let RowContext { grid, params, .. } = *row;
    let global: [usize; 3] = core::array::from_fn(|d| p[d] + grid.offset[d]);
    let pos: [f32; 3] = core::array::from_fn(|d| {
        // Through i64: one instruction, where usize to f64 takes several; exact below 2^53.
        let c = global[d] as i64 as f64;
        match d {
            _ if d == AXIS => world(params, d, c + t),
            0 => world(params, d, c),
            _ => row.fixed[d],
        }
    });
    let (pos, normal) = if ZYX {
        (reversed(pos), normal.map(Normal::reversed))
    } else {
        (pos, normal)
    };
    match normal {
        Some(Normal::Toward(toward)) => sink.edge_vertex_toward(global, AXIS, pos, toward),
        Some(Normal::Unit(normal)) => sink.edge_vertex(global, AXIS, pos, Some(normal)),
        None => sink.edge_vertex(global, AXIS, pos, None),
    }
    if params.values {
        // As NumPy's `maximum`: a NaN end gives NaN.
        sink.vertex_value((if a > b || a.is_nan() { a } else { b }) as f32);
    }
}

/// `[z, y, x]` from `[x, y, z]`, for [`Axes::Zyx`].
#[inline(always)]
fn reversed([x, y, z]: [f32; 3]) -> [f32; 3] {
    [z, y, x]
}

impl Grid<'_> {
    #[inline(always)]
    fn row(&self, z: usize, y: usize) -> &[u8] {
        &self.padded_row(z, y)[..self.dims[0]]
    }

    /// A classified row and whatever follows it, at least [`PAD`] bytes: what
    /// [`for_each_differing`] reads.
    #[inline(always)]
    fn padded_row(&self, z: usize, y: usize) -> &[u8] {
        let [nx, ny, _] = self.dims;
        &self.filled[(z % 4) * nx * ny + y * nx..]
    }

    /// Whether this sweep counts the edge with lower end `p` (see [`Sweep::restrict`]).
    #[inline(always)]
    fn owns_edge(&self, p: [usize; 3]) -> bool {
        let [x, y, z] = self.own_edges;
        !self.restricted
            || p[0] >= x.0 && p[0] < x.1 && p[1] >= y.0 && p[1] < y.1 && p[2] >= z.0 && p[2] < z.1
    }

    #[inline(always)]
    fn is_filled(&self, p: [usize; 3]) -> bool {
        self.row(p[2], p[1])[p[0]] == 1
    }

    /// The spans of slice `z`'s classified rows.
    #[inline(always)]
    fn plane_spans(&self, z: usize) -> &[Span] {
        let ny = self.dims[1];
        &self.row_spans[(z % 4) * ny..][..ny]
    }

    /// Step 1's classification of slice `z`, and each row's span of x-edge changes.
    // Not inlined: each pass runs once per layer, and apart it shows in a profile.
    #[inline(never)]
    fn classify<T: Scalar>(&mut self, z: usize, slice: &[T], threshold: T::Threshold) {
        let [nx, ny, _] = self.dims;
        let slot = (z % 4) * nx * ny;
        for y in 0..ny {
            let row = &mut self.filled[slot + y * nx..][..nx];
            T::classify_row(&slice[y * nx..][..nx], threshold, row);
            let span = match first_differing(row, row[0]) {
                None => (nx - 1, 0),
                Some(first) => (
                    first - 1,
                    last_differing(row, row[nx - 1]).map_or(0, |l| l + 1),
                ),
            };
            let (first, last) = (u32::from(row[0]) << 31, u32::from(row[nx - 1]) << 31);
            self.row_spans[(z % 4) * ny + y] = [span.0 as u32 | first, span.1 as u32 | last];
        }
    }

    /// Cube cases of layer `k`, over each cube row's span of non-trivial cubes.
    // Not inlined: each pass runs once per layer, and apart it shows in a profile.
    #[inline(never)]
    fn compute_cases(&mut self, k: usize) {
        let [nx, ny, _] = self.dims;
        let plane_spans = |z: usize| &self.row_spans[(z % 4) * ny..][..ny];
        let (below, above) = (plane_spans(k), plane_spans(k + 1));
        let spans = &mut self.case_spans[(k % 3) * ny..][..ny];
        let plane = |z: usize| &self.filled[(z % 4) * nx * ny..];
        let (lower, upper) = (plane(k), plane(k + 1));
        let cases = &mut self.cases[(k % 3) * nx * ny..];
        for j in 0..ny - 1 {
            let four = [below[j], below[j + 1], above[j], above[j + 1]];
            // Points `start..end` may vary, so cubes `start..end - 1` may be non-trivial.
            let (start, end) = union_span(four, nx);
            let (lo, hi) = (start, (end.max(1) - 1).max(start));
            spans[j] = [lo as u32, hi as u32];
            if lo >= hi {
                continue;
            }
            // The rows run past `hi` into the next row or the padding (see `cube_cases`).
            let blocks = (hi - lo).div_ceil(LANES);
            let (at, len) = (j * nx + lo, LANES * blocks + 1);
            let out = &mut cases[at..][..LANES * blocks];
            let rows = [
                &lower[at..][..len],
                &lower[at + nx..][..len],
                &upper[at..][..len],
                &upper[at + nx..][..len],
            ];
            cube_cases(rows, out, hi - lo);
        }
    }

    #[inline(always)]
    fn case_at(&self, i: usize, j: usize, k: usize) -> u8 {
        let [nx, ny, _] = self.dims;
        self.cases[(k % 3) * nx * ny + j * nx + i]
    }

    /// The four cubes around the edge from `p` along `axis`, as `(i, j, k)`, if it is interior:
    /// the lower two then the upper two along the third axis, each pair ordered along the
    /// remaining one.
    #[inline(always)]
    fn cubes_around(&self, p: [usize; 3], axis: usize) -> Option<[(usize, usize, usize); 4]> {
        let [l, m, n] = p;
        let [nx, ny, nz] = self.dims;
        Some(match axis {
            0 if (1..ny - 1).contains(&m) && (1..nz - 1).contains(&n) => {
                [(l, m - 1, n - 1), (l, m, n - 1), (l, m - 1, n), (l, m, n)]
            }
            1 if (1..nx - 1).contains(&l) && (1..nz - 1).contains(&n) => {
                [(l - 1, m, n - 1), (l, m, n - 1), (l - 1, m, n), (l, m, n)]
            }
            2 if (1..nx - 1).contains(&l) && (1..ny - 1).contains(&m) => {
                [(l - 1, m - 1, n), (l, m - 1, n), (l - 1, m, n), (l, m, n)]
            }
            _ => return None,
        })
    }

    /// The parity class of a cube of these samples, which follows its global indices.
    #[inline(always)]
    fn class_of(&self, (i, j, k): (usize, usize, usize)) -> usize {
        let [ox, oy, oz] = self.offset;
        ((i + ox) & 1) | ((j + oy) & 1) << 1 | ((k + oz) & 1) << 2
    }

    /// SPEC §5 (b): the lower end `p` is cut off in every face of its fan: all four faces of the
    /// horizontal plane for x- and y-greys, all eight vertical faces for z-greys. A corner is cut
    /// off when both its face neighbours differ from it and it or the diagonal corner is filled;
    /// a missing face (grid border) is not cut off.
    ///
    /// For z-greys we go further than the SPEC: `p` is a pinch as soon as its six neighbours all
    /// differ from it, whatever the diagonal corners. An empty `p` with filled neighbours but an
    /// empty diagonal passes the SPEC's test, yet the z-greys above and below it then both merge,
    /// and their quads lie (wholly or in part) in the plane `z = n` with different diagonals:
    /// coplanar triangles overlap. Found by the self-intersection tests on real MRI data; the
    /// stricter test costs a few triangles (the knot: 10,520 instead of 10,516).
    #[inline(always)]
    fn pinch(&self, p: [usize; 3], axis: usize) -> bool {
        let centre = self.is_filled(p);
        // Face planes as pairs of axes spanning them.
        let planes: &[[usize; 2]] = if axis == 2 {
            &[[0, 2], [1, 2]]
        } else {
            &[[0, 1]]
        };
        let at = |q: [usize; 3]| self.is_filled(q);
        for &[u, v] in planes {
            for d in [u, v] {
                if p[d] == 0 || p[d] + 1 >= self.dims[d] {
                    return false;
                }
                for s in [p[d] - 1, p[d] + 1] {
                    let mut q = p;
                    q[d] = s;
                    if at(q) == centre {
                        return false;
                    }
                }
            }
            if !centre && axis != 2 {
                for su in [p[u] - 1, p[u] + 1] {
                    for sv in [p[v] - 1, p[v] + 1] {
                        let mut q = p;
                        q[u] = su;
                        q[v] = sv;
                        if !at(q) {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }

    /// Per grey-edge axis, where a merged pair's partner is from its owner in layer `k` (see
    /// [`Entry::owned_ears`]): its distance in a plane of cubes, and the parity bit that differs.
    fn partners(&self, k: usize) -> [(usize, usize); 3] {
        let (along_x, along_y) = ((1, 1), (self.dims[0], 2));
        let z = if (k + self.offset[2]).is_multiple_of(2) {
            along_y
        } else {
            along_x
        };
        [along_y, along_x, z]
    }

    /// For a merged grey edge owned by this cube (see [`Entry::owned_ears`]): the triangle that
    /// replaces its ear and its partner's. The cube's case is `cases[0]`; its partner is `step`
    /// further on in the cases and the ids, with its class `flip`ped ([`Grid::partners`]).
    #[inline(always)]
    fn merged_triangle(
        &self,
        (cube, cases, class): (Cube<'_, '_>, &[u8], usize),
        axis: usize,
        (step, flip): (usize, usize),
        entry: &Entry,
    ) -> [u32; 3] {
        let pentry = self.partner(cases, class, (step, flip));
        // The partner adds the outer vertex of its ear that is off the face the two share; the
        // entries say which (`Entry::merge`), so the partner's ear itself is not read.
        let far = cube.next_id(step, pentry.merge[axis]);
        // An ear is stored `[back, grey, forward]`: only its two outer vertices matter. Clamped,
        // since a cube that owns no pair makes a triangle too, from an axis that may have no ear
        // (see `Sweep::triangles`); an ear's index is at most 4.
        let [b, _, f] = entry.tris[usize::from(entry.ears[axis]).min(4)];
        let (b, f) = (cube.id(b), cube.id(f));
        // Which of this ear's vertices is shared is data: conditional moves, not a branch. One
        // per vertex: a select between two arrays went through the stack, and loading the
        // chosen array as one word waited for its separate stores (a fifth of the merged
        // triangles' time).
        let back_shared = entry.merge[axis] & BACK_SHARED != 0;
        let pick = |a: u32, b: u32| core::hint::select_unpredictable(back_shared, a, b);
        [pick(f, far), pick(b, f), pick(far, b)]
    }

    /// The entry of the merge partner `step` further on, its class `flip`ped.
    #[inline(always)]
    fn partner(&self, cases: &[u8], class: usize, (step, flip): (usize, usize)) -> &'static Entry {
        &self.entries[(class ^ flip) * 256 + usize::from(cases[step])]
    }

    /// Whether the triangle `merged_triangle` made for an owned pair replaces two ears that share
    /// a face side: the partner's ear runs between the triangle's far vertex and the shared one.
    fn ears_share_a_side(
        &self,
        (cube, cases, class): (Cube<'_, '_>, &[u8], usize),
        axis: usize,
        pair: (usize, usize),
        entry: &Entry,
        [first, middle, last]: [u32; 3],
    ) -> bool {
        let pentry = self.partner(cases, class, pair);
        let step = pair.0;
        let [pb, _, pf] = pentry.tris[usize::from(pentry.ears[axis])];
        // The triangle is `[f, b, far]` when the back vertex `b` is shared, else `[far, f, b]`.
        let (far, shared) = if entry.merge[axis] & BACK_SHARED != 0 {
            (last, middle)
        } else {
            (first, middle)
        };
        let ear = [cube.next_id(step, pb), cube.next_id(step, pf)];
        ear == [far, shared] || ear == [shared, far]
    }
}

/// A row's span as stored: `[lo, hi]`, and for a classified row its first and last bytes in the
/// top bits ([`END_BIT`]), so that [`union_span`] reads only the compact spans, not two cache
/// lines of each row.
type Span = [u32; 2];

/// A span's `lo..hi`, without the end bits.
#[inline(always)]
fn lo_hi([lo, hi]: Span) -> (usize, usize) {
    ((lo & !END_BIT) as usize, (hi & !END_BIT) as usize)
}

/// The x range `start..end` outside which the classified rows of these spans agree with each
/// other and are constant along x.
#[inline(always)]
fn union_span<const N: usize>(spans: [Span; N], nx: usize) -> (usize, usize) {
    let (mut lo, mut hi) = (nx - 1, 0);
    let (mut same0, mut same1) = (true, true);
    for span in spans {
        let (l, h) = lo_hi(span);
        lo = lo.min(l);
        hi = hi.max(h);
        same0 &= (span[0] ^ spans[0][0]) & END_BIT == 0;
        same1 &= (span[1] ^ spans[0][1]) & END_BIT == 0;
    }
    let start = if same0 { lo } else { 0 };
    let end = if same1 { hi + 1 } else { nx };
    (start, end.max(start))
}

/// Calls `f(x, case)` for each `x` in `start..end`, in order, whose cube the surface crosses (its
/// case is neither 0 nor 255). Tests a block of cases at a time: most of a row's span lies wholly
/// inside or outside the surface (seven in eight cubes of brainsmall's spans), and the crossed
/// cubes of a block are then taken from its mask, each case from the block itself, so that a
/// crossed cube costs no second load. `cases` runs at least `SCAN − 1` bytes past `end` (see
/// [`in_span`]).
#[inline(always)]
fn for_each_crossed(cases: &[u8], start: usize, end: usize, mut f: impl FnMut(usize, u8)) {
    let mut x = start;
    while x < end {
        let block: &[u8; SCAN] = cases[x..x + SCAN].try_into().expect("a scan block");
        let trivial = mask(|r| {
            let v = load(&block[LANES * r..]);
            v.simd_eq(u8x16::splat(0)) | v.simd_eq(u8x16::splat(255))
        });
        let mut crossed = !trivial & in_span(end - x);
        while crossed != 0 {
            let n = crossed.trailing_zeros() as usize;
            f(x + n, block[n % SCAN]);
            crossed &= crossed - 1;
        }
        x += SCAN;
    }
}

/// Bytes per register: one SSE2 or NEON compare gives a bit mask of sixteen bytes
/// (`to_bitmask`), so that a scan walks the mask's bits straight to the bytes it wants, where
/// eight-byte words need a shift and a mask per byte found.
const LANES: usize = 16;

/// Bytes per block of the row scans: four registers' masks in one word. The loop over a block's
/// bits mispredicts its exit about once per block with something in it, and a surface's
/// crossings in a row cluster where it enters and leaves: wider blocks, fewer exits.
const SCAN: usize = 4 * LANES;
const _: () = assert!(
    SCAN <= PAD,
    "a scan block past a row's end stays in the scratch"
);

/// The bit mask of a block's first `left` bytes (all of them from `SCAN` up). Rows are read a
/// whole block at a time, past their end into padding or the next row, and the mask keeps what
/// lies within, rather than a byte-by-byte loop over the last few bytes of each row.
#[inline(always)]
fn in_span(left: usize) -> u64 {
    u64::MAX >> (64 - SCAN.min(left))
}

/// A scan block's bit mask from its registers' compares: `test(r)` for bytes `16 · r ..`.
#[inline(always)]
fn mask(test: impl Fn(usize) -> u8x16) -> u64 {
    (0..SCAN / LANES).fold(0, |m, r| m | u64::from(test(r).to_bitmask()) << (LANES * r))
}

/// Sixteen bytes from the start of `bytes`.
#[inline(always)]
fn load(bytes: &[u8]) -> u8x16 {
    u8x16::new(bytes[..LANES].try_into().expect("sixteen bytes"))
}

/// The cases of cubes `0..len` into `out` (`16 · ⌈len / 16⌉` bytes; those from `len` on are left
/// as they were), from their four sample rows — `y` and `y + 1` at `z`, then at `z + 1` — each at
/// least one byte longer than `out`.
///
/// A block of cubes at a time, from each row's blocks at `x` and `x + 1`: zips over each row
/// vectorise too, but every row then pays a scalar tail and a mispredicted loop exit.
#[inline(always)]
fn cube_cases(rows: [&[u8]; 4], out: &mut [u8], len: usize) {
    let blocks = out.len() / LANES;
    for (c, cell) in out.chunks_exact_mut(LANES).enumerate() {
        // Bit `2n` of a case is row `n` at `x`, bit `2n + 1` the same row at `x + 1`: built
        // from the last bit down by doubling, which needs no masks (samples are 0 or 1).
        let case = rows.iter().rev().fold(u8x16::splat(0), |case, row| {
            let at = |o: usize| load(&row[LANES * c + o..]);
            let case = case + case + at(1);
            case + case + at(0)
        });
        if c + 1 == blocks {
            // Past the span: leave the next cubes' cases as they are.
            let keep = !(u128::MAX >> (8 * (LANES - (len - LANES * c))));
            let old = u128::from_le_bytes(cell.try_into().expect("sixteen bytes"));
            let case = u128::from_le_bytes(case.to_array()) & !keep | old & keep;
            cell.copy_from_slice(&case.to_le_bytes());
        } else {
            cell.copy_from_slice(&case.to_array());
        }
    }
}

/// Calls `f(x)` for each `x` in `start..end`, in order, where `a[x] != b[x]`, comparing a block
/// of bytes at a time: most of a row's span is unchanged, and a vertex is the rare event. Both
/// slices run at least `SCAN − 1` bytes past `end`: the last block is read whole and masked, so that
/// `f` has one call site and is inlined (called out of line, once per vertex, it cost a fifth of
/// the vertex passes).
#[inline]
fn for_each_differing(
    a: &[u8],
    b: &[u8],
    start: usize,
    end: usize,
    mut f: impl FnMut(usize) -> Result<(), Error>,
) -> Result<(), Error> {
    // Whole blocks from slices cut to whole blocks once: no bounds check per block.
    let blocks = (end.max(start) - start).div_ceil(SCAN);
    let (a, b) = (&a[start..][..SCAN * blocks], &b[start..][..SCAN * blocks]);
    let mut scan = a
        .as_chunks::<SCAN>()
        .0
        .iter()
        .zip(b.as_chunks::<SCAN>().0)
        .enumerate();
    // Blocks without a difference are passed over in a loop of their own, whose few registers
    // `f` does not take: in one loop with `f`, every block reloaded the scan's state from the
    // stack.
    let differing = |(w, (a, b)): (usize, (&[u8; SCAN], &[u8; SCAN]))| {
        let same = mask(|r| load(&a[LANES * r..]).simd_eq(load(&b[LANES * r..])));
        let diff = !same & in_span(end - start - SCAN * w);
        (diff != 0).then_some((start + SCAN * w, diff))
    };
    while let Some((x, mut diff)) = scan.find_map(differing) {
        while diff != 0 {
            f(x + diff.trailing_zeros() as usize)?;
            diff &= diff - 1;
        }
    }
    Ok(())
}

/// The first index whose byte differs from `v`, comparing a block of bytes at a time.
fn first_differing(row: &[u8], v: u8) -> Option<usize> {
    let chunks = row.chunks_exact(LANES);
    let tail = chunks.remainder();
    for (c, chunk) in chunks.enumerate() {
        let d = differing(chunk, v);
        if d != 0 {
            return Some(c * LANES + d.trailing_zeros() as usize);
        }
    }
    tail.iter()
        .position(|&b| b != v)
        .map(|i| row.len() - tail.len() + i)
}

/// The last index whose byte differs from `v`, comparing a block of bytes at a time.
fn last_differing(row: &[u8], v: u8) -> Option<usize> {
    let chunks = row.rchunks_exact(LANES);
    let head = chunks.remainder();
    for (c, chunk) in chunks.enumerate() {
        let d = differing(chunk, v);
        if d != 0 {
            let start = row.len() - (c + 1) * LANES;
            return Some(start + 31 - d.leading_zeros() as usize);
        }
    }
    head.iter().rposition(|&b| b != v)
}

/// The bit mask of the bytes of a block that differ from `v`.
#[inline(always)]
fn differing(block: &[u8], v: u8) -> u32 {
    !load(block).simd_eq(u8x16::splat(v)).to_bitmask() & 0xFFFF
}

#[cfg(test)]
mod tests {
    use super::{LANES, SCAN, cube_cases, for_each_crossed, for_each_differing};
    use alloc::vec;
    use alloc::vec::Vec;

    /// Rows mixing runs of 0 and 255 with crossed cases at every position of a block, each
    /// followed by `SCAN − 1` crossed bytes that the scans must not report.
    fn rows() -> impl Iterator<Item = (Vec<u8>, usize)> {
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        (0..40).map(move |_| {
            let mut row: Vec<u8> = (0..2 * SCAN + 11)
                .map(|_| {
                    state = state
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    match (state >> 60) % 4 {
                        0 => 0,
                        1 => 255,
                        2 => (state >> 32) as u8,
                        _ => [1, 254, 128, 127][(state >> 40) as usize % 4],
                    }
                })
                .collect();
            let len = row.len();
            row.extend([7; SCAN - 1]);
            (row, len)
        })
    }

    /// `for_each_crossed` finds exactly the cases a byte-by-byte filter finds, for every sub-range.
    #[test]
    fn crossed_matches_a_plain_filter() {
        for (row, len) in rows() {
            for start in 0..len {
                for end in start..=len {
                    let plain: Vec<(usize, u8)> = (start..end)
                        .map(|x| (x, row[x]))
                        .filter(|&(_, c)| c != 0 && c != 255)
                        .collect();
                    let mut seen = Vec::new();
                    for_each_crossed(&row, start, end, |x, case| seen.push((x, case)));
                    assert_eq!(seen, plain);
                }
            }
        }
    }

    /// `cube_cases` gives every cube of `0..len` the case a cube-by-cube formula gives, for
    /// every `len` up to 37 cubes, and leaves the bytes past `len` alone.
    #[test]
    fn cube_cases_match_a_plain_formula() {
        let mut state = 0x853C_49E6_748F_EA9Bu64;
        for _ in 0..50 {
            let rows: Vec<Vec<u8>> = (0..4)
                .map(|_| {
                    (0..49)
                        .map(|_| {
                            state ^= state << 13;
                            state ^= state >> 7;
                            state ^= state << 17;
                            (state >> 33) as u8 & 1
                        })
                        .collect()
                })
                .collect();
            for len in 1usize..=37 {
                let blocks = LANES * len.div_ceil(LANES);
                let mut out = vec![0xAA; blocks];
                let cut = |n: usize| &rows[n][..blocks + 1];
                cube_cases([cut(0), cut(1), cut(2), cut(3)], &mut out, len);
                for (x, &case) in out.iter().enumerate() {
                    let plain =
                        (0..4).fold(0, |c, n| c | (rows[n][x] | rows[n][x + 1] << 1) << (2 * n));
                    let want = if x < len { plain } else { 0xAA };
                    assert_eq!(case, want, "cube {x} of {len}");
                }
            }
        }
    }

    /// `for_each_differing` visits exactly the positions where two rows differ, in order, for
    /// every sub-range; past `end` the rows differ everywhere, and must not be visited.
    #[test]
    fn for_each_differing_matches_a_plain_filter() {
        let all: Vec<(Vec<u8>, usize)> = rows().collect();
        for pair in all.windows(2) {
            let ((a, len), (b, _)) = (&pair[0], &pair[1]);
            let b: Vec<u8> = b[..*len].iter().chain(&[8; SCAN - 1]).copied().collect();
            for start in 0..*len {
                for end in start..=*len {
                    let plain: Vec<usize> = (start..end).filter(|&x| a[x] != b[x]).collect();
                    let mut seen = Vec::new();
                    for_each_differing(a, &b, start, end, |x| {
                        seen.push(x);
                        Ok(())
                    })
                    .unwrap();
                    assert_eq!(seen, plain);
                }
            }
        }
    }
}
