//! The layer sweep: Steps 1–4 over one z range with O(nx·ny) memory (SPEC §1–5).
//!
//! Layer `k` (cubes from `z = k` to `k + 1`) is finished before layer `k + 1` starts. Its output
//! needs slices `k − 1 ..= k + 2`: the merge decision for a grey edge in plane `k + 1` looks at the
//! cubes of layer `k + 1`, and normals take central differences. Vertices are numbered in a fixed
//! order, plane 0, z-edges of layer 0, plane 1, z-edges of layer 1, …, and within each group row by
//! row, so a sweep that starts at any layer numbers the vertices the way a full sweep does, offset
//! by a constant. That is what makes the parallel mesh identical to the sequential one.

use crate::scratch::{BYTE_PLANES, SPAN_ROWS, Scratch, WORD_PLANES};
use crate::tables::{Entry, NO_EAR, grey_edge};
use crate::vertex::{Field, crossing};
use crate::{Error, Mode, Params, Scalar, Sink, Stats};

/// Vertex id of a grey edge merged away by Step 4.
const MERGED: u32 = u32::MAX;

/// Gives the sweep the slices it asks for; `z` is always within what the step needs.
pub(crate) trait Slices<T> {
    fn slice(&self, z: usize) -> &[T];
}

/// What Step 4 does with an occupied grey edge.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Decision {
    /// Not mergeable in this mode, or on the grid boundary.
    Keep,
    /// Merged: its vertex disappears and its four ears become two triangles.
    Merge,
    /// Interior, but embedded mode's rules (a) or (b) forbid the merge.
    Blocked,
}

/// A row's classified samples are constant on `0..=lo` and on `hi..nx` (`lo = nx − 1`, `hi = 0` for
/// a uniform row). For a case row, the non-trivial cubes lie in `lo..hi`.
#[derive(Clone, Copy)]
struct Span {
    lo: usize,
    hi: usize,
}

pub(crate) struct Sweep<'s, T: Scalar> {
    dims: [usize; 3],
    params: Params,
    threshold: T::Threshold,
    entries: &'static [Entry; 2048],
    filled: &'s mut [u8],
    cases: &'s mut [u8],
    ids: &'s mut [u32],
    spans: &'s mut [u32],
    next_id: u32,
    emit: bool,
    pub stats: Stats,
}

impl<'s, T: Scalar> Sweep<'s, T> {
    pub fn new(dims: [usize; 3], params: &Params, scratch: Scratch<'s>) -> Self {
        let nxy = dims[0] * dims[1];
        let (filled, rest) = scratch.bytes.split_at_mut(4 * nxy);
        let (ids, spans) = scratch.words.split_at_mut(WORD_PLANES * nxy);
        debug_assert!(
            rest.len() >= (BYTE_PLANES - 4) * nxy && spans.len() >= 2 * SPAN_ROWS * dims[1]
        );
        Sweep {
            dims,
            params: *params,
            threshold: T::threshold(params.iso),
            entries: params.tables.for_mode(params.mode),
            filled,
            cases: &mut rest[..3 * nxy],
            ids,
            spans,
            next_id: 0,
            emit: true,
            stats: Stats::default(),
        }
    }

    /// Number of vertex ids handed out, including those of a first plane not emitted.
    #[cfg(feature = "std")]
    pub fn ids_used(&self) -> u32 {
        self.next_id
    }

    /// Prepares layer `z0`: classifies slices `z0 − 1 ..= z0 + 1`, computes cases of layers
    /// `z0 − 1` and `z0`, and numbers plane `z0`'s vertices. With `emit_plane` false (a parallel
    /// chunk after the first), those vertices are numbered but belong to the previous chunk.
    pub fn start(
        &mut self,
        z0: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
        emit_plane: bool,
    ) -> Result<(), Error> {
        for z in z0.saturating_sub(1)..=z0 + 1 {
            self.classify(z, src.slice(z));
        }
        if z0 >= 1 {
            self.compute_cases(z0 - 1);
        }
        self.compute_cases(z0);
        self.emit = emit_plane;
        let r = self.plane_vertices(z0, src, sink);
        self.emit = true;
        r
    }

    /// Runs layer `k`; slices `k − 1 ..= k + 2` (those that exist) must be readable.
    pub fn layer(
        &mut self,
        k: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
    ) -> Result<(), Error> {
        let nz = self.dims[2];
        if k + 2 < nz {
            self.classify(k + 2, src.slice(k + 2));
            self.compute_cases(k + 1);
        }
        self.z_vertices(k, src, sink)?;
        self.plane_vertices(k + 1, src, sink)?;
        self.triangles(k, sink);
        Ok(())
    }

    // ---- Step 1: classification and row spans -------------------------------------------------

    fn classify(&mut self, z: usize, slice: &[T]) {
        let [nx, ny, _] = self.dims;
        let slot = z % 4;
        let out = &mut self.filled[slot * nx * ny..(slot + 1) * nx * ny];
        for (o, v) in out.iter_mut().zip(slice) {
            *o = u8::from(v.filled(self.threshold));
        }
        for y in 0..ny {
            let row = &self.filled[slot * nx * ny + y * nx..][..nx];
            let lo = row.windows(2).position(|w| w[0] != w[1]).unwrap_or(nx - 1);
            let hi = row
                .windows(2)
                .rposition(|w| w[0] != w[1])
                .map_or(0, |i| i + 1);
            self.set_span(slot * ny + y, Span { lo, hi });
        }
    }

    fn span(&self, row: usize) -> Span {
        Span {
            lo: self.spans[2 * row] as usize,
            hi: self.spans[2 * row + 1] as usize,
        }
    }

    fn set_span(&mut self, row: usize, s: Span) {
        self.spans[2 * row] = s.lo as u32;
        self.spans[2 * row + 1] = s.hi as u32;
    }

    fn filled_row(&self, z: usize, y: usize) -> &[u8] {
        let [nx, ny, _] = self.dims;
        let start = (z % 4) * nx * ny + y * nx;
        &self.filled[start..start + nx]
    }

    /// The points where some of the rows `(y, z)` differ from one another or vary along x, as an
    /// inclusive range `start..=end` (empty when `start > end`).
    fn union_span(&self, rows: &[(usize, usize)]) -> (usize, usize) {
        let nx = self.dims[0];
        let ny = self.dims[1];
        let first = self.filled_row(rows[0].1, rows[0].0);
        let (f0, f1) = (first[0], first[nx - 1]);
        let (mut lo, mut hi) = (nx - 1, 0);
        let (mut same0, mut same1) = (true, true);
        for &(y, z) in rows {
            let s = self.span((z % 4) * ny + y);
            lo = lo.min(s.lo);
            hi = hi.max(s.hi);
            let r = self.filled_row(z, y);
            same0 &= r[0] == f0;
            same1 &= r[nx - 1] == f1;
        }
        (if same0 { lo } else { 0 }, if same1 { hi } else { nx - 1 })
    }

    fn compute_cases(&mut self, k: usize) {
        let [nx, ny, _] = self.dims;
        let slot = k % 3;
        for j in 0..ny - 1 {
            let (start, end) = self.union_span(&[(j, k), (j + 1, k), (j, k + 1), (j + 1, k + 1)]);
            // Cubes `start..end` can be non-trivial: cube `end` lies wholly in the constant tail.
            let (lo, hi) = (start, end.min(nx - 1));
            self.set_span(4 * ny + slot * ny + j, Span { lo, hi: hi.max(lo) });
            if lo >= hi {
                continue;
            }
            let rows = [(j, k), (j + 1, k), (j, k + 1), (j + 1, k + 1)]
                .map(|(y, z)| (z % 4) * nx * ny + y * nx);
            let out_start = slot * nx * ny + j * nx;
            let (filled, cases) = (&*self.filled, &mut *self.cases);
            for i in lo..hi {
                let mut case = 0u8;
                for (r, &row) in rows.iter().enumerate() {
                    case |= filled[row + i] << (2 * r) | filled[row + i + 1] << (2 * r + 1);
                }
                cases[out_start + i] = case;
            }
        }
    }

    fn case_at(&self, i: usize, j: usize, k: usize) -> u8 {
        let [nx, ny, _] = self.dims;
        self.cases[(k % 3) * nx * ny + j * nx + i]
    }

    fn is_filled(&self, x: usize, y: usize, z: usize) -> bool {
        self.filled_row(z, y)[x] == 1
    }

    // ---- Step 4's decision: which occupied grey edges merge -----------------------------------

    /// Step 4's decision for the occupied grey edge from `p` along `axis` (SPEC §5).
    fn decide(&self, p: [usize; 3], axis: usize) -> Decision {
        if self.params.mode == Mode::Steps123 {
            return Decision::Keep;
        }
        let [l, m, n] = p;
        let [nx, ny, nz] = self.dims;
        // The four cubes around the edge, as (i, j, k); the edge must be interior.
        let cubes = match axis {
            0 if (1..ny - 1).contains(&m) && (1..nz - 1).contains(&n) => {
                [(l, m - 1, n - 1), (l, m, n - 1), (l, m - 1, n), (l, m, n)]
            }
            1 if (1..nx - 1).contains(&l) && (1..nz - 1).contains(&n) => {
                [(l - 1, m, n - 1), (l, m, n - 1), (l - 1, m, n), (l, m, n)]
            }
            2 if (1..nx - 1).contains(&l) && (1..ny - 1).contains(&m) => {
                [(l - 1, m - 1, n), (l, m - 1, n), (l - 1, m, n), (l, m, n)]
            }
            _ => return Decision::Keep,
        };
        if self.params.mode == Mode::Paper {
            return Decision::Merge;
        }
        let entries = self.entries;
        let mergeable = cubes.iter().all(|&(i, j, k)| {
            let class = (i & 1) | (j & 1) << 1 | (k & 1) << 2;
            entries[class * 256 + usize::from(self.case_at(i, j, k))].mergeable >> axis & 1 == 1
        });
        if mergeable && !self.pinch(p, axis) {
            Decision::Merge
        } else {
            Decision::Blocked
        }
    }

    /// SPEC §5 (b): the lower end `p` is cut off in every face of the relevant fan around it.
    fn pinch(&self, p: [usize; 3], axis: usize) -> bool {
        let [nx, ny, nz] = self.dims;
        let [l, m, n] = p;
        let f = |x: usize, y: usize, z: usize| self.is_filled(x, y, z);
        let centre = f(l, m, n);
        // The two in-plane directions of the faces to test, and for z-greys the vertical one.
        let dirs: &[[usize; 2]] = if axis == 2 {
            &[[0, 2], [1, 2]]
        } else {
            &[[0, 1]]
        };
        let lim = [nx, ny, nz];
        for &[u, v] in dirs {
            // Both neighbours along u and v must exist, and differ from the centre.
            for d in [u, v] {
                if p[d] == 0 || p[d] + 1 >= lim[d] {
                    return false;
                }
                for s in [p[d] - 1, p[d] + 1] {
                    let mut q = p;
                    q[d] = s;
                    if f(q[0], q[1], q[2]) == centre {
                        return false;
                    }
                }
            }
            if !centre {
                for su in [p[u] - 1, p[u] + 1] {
                    for sv in [p[v] - 1, p[v] + 1] {
                        let mut q = p;
                        q[u] = su;
                        q[v] = sv;
                        if !f(q[0], q[1], q[2]) {
                            return false;
                        }
                    }
                }
            }
        }
        true
    }

    // ---- Step 1: vertices ---------------------------------------------------------------------

    fn new_vertex(
        &mut self,
        p: [usize; 3],
        axis: usize,
        field: &Field<'_, T>,
        sink: &mut impl Sink,
    ) -> Result<u32, Error> {
        let id = self.next_id;
        if id == MERGED {
            return Err(Error::TooManyVertices);
        }
        self.next_id += 1;
        if self.emit {
            self.stats.vertices += 1;
            let mut q = p;
            q[axis] += 1;
            let (a, b) = (field.value(p[0], p[1], p[2]), field.value(q[0], q[1], q[2]));
            let t = if a.is_nan() || b.is_nan() {
                0.5
            } else {
                crossing(a, b, self.params.iso)
            };
            let pos: [f32; 3] = core::array::from_fn(|d| {
                let c = p[d] as f64 + if d == axis { t } else { 0.0 };
                (self.params.origin[d] + c * self.params.spacing[d]) as f32
            });
            let a_filled = self.is_filled(p[0], p[1], p[2]);
            let normal = self
                .params
                .normals
                .then(|| field.normal(p, axis, t, a_filled));
            sink.vertex(pos, normal);
        }
        Ok(id)
    }

    fn field<'v>(
        &self,
        src: &'v impl Slices<T>,
        zs: core::ops::RangeInclusive<usize>,
    ) -> Field<'v, T> {
        let nz = self.dims[2];
        let first = zs.start().saturating_sub(1);
        let mut slices = [None; 4];
        for (i, z) in (first..=(zs.end() + 1).min(nz - 1)).enumerate() {
            slices[i] = Some(src.slice(z));
        }
        Field {
            dims: self.dims,
            spacing: self.params.spacing,
            slices,
            first,
        }
    }

    /// Occupied edge bookkeeping shared by all three edge kinds: count, decide, number.
    fn edge_vertex(
        &mut self,
        p: [usize; 3],
        axis: usize,
        grey: bool,
        field: &Field<'_, T>,
        sink: &mut impl Sink,
    ) -> Result<u32, Error> {
        let decision = if grey {
            self.decide(p, axis)
        } else {
            Decision::Keep
        };
        if self.emit {
            self.stats.v13 += 1;
            self.stats.merged += u64::from(decision == Decision::Merge);
            self.stats.blocked += u64::from(decision == Decision::Blocked);
        }
        if decision == Decision::Merge {
            return Ok(MERGED);
        }
        self.new_vertex(p, axis, field, sink)
    }

    /// Vertices on the x- and y-edges of plane `n`, row by row.
    fn plane_vertices(
        &mut self,
        n: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
    ) -> Result<(), Error> {
        let [nx, ny, _] = self.dims;
        let field = self.field(src, n..=n);
        let (xbase, ybase) = ((n % 2) * 2 * nx * ny, (n % 2) * 2 * nx * ny + nx * ny);
        for y in 0..ny {
            let s = self.span((n % 4) * ny + y);
            let x_grey = y % 2 == 1 && n % 2 == 1;
            for x in s.lo..s.hi {
                let row = self.filled_row(n, y);
                if row[x] != row[x + 1] {
                    let id = self.edge_vertex([x, y, n], 0, x_grey, &field, sink)?;
                    self.ids[xbase + y * nx + x] = id;
                }
            }
            if y + 1 < ny {
                let (start, end) = self.union_span(&[(y, n), (y + 1, n)]);
                for x in start..=end.min(nx - 1) {
                    if self.is_filled(x, y, n) != self.is_filled(x, y + 1, n) {
                        let grey = x % 2 == 1 && n % 2 == 0;
                        let id = self.edge_vertex([x, y, n], 1, grey, &field, sink)?;
                        self.ids[ybase + y * nx + x] = id;
                    }
                }
            }
        }
        Ok(())
    }

    /// Vertices on the z-edges of layer `k`, row by row.
    fn z_vertices(
        &mut self,
        k: usize,
        src: &impl Slices<T>,
        sink: &mut impl Sink,
    ) -> Result<(), Error> {
        let [nx, ny, _] = self.dims;
        let field = self.field(src, k..=k + 1);
        let zbase = 4 * nx * ny;
        for y in 0..ny {
            let (start, end) = self.union_span(&[(y, k), (y, k + 1)]);
            for x in start..=end.min(nx - 1) {
                if self.is_filled(x, y, k) != self.is_filled(x, y, k + 1) {
                    let grey = x % 2 == 0 && y % 2 == 0;
                    let id = self.edge_vertex([x, y, k], 2, grey, &field, sink)?;
                    self.ids[zbase + y * nx + x] = id;
                }
            }
        }
        Ok(())
    }

    // ---- Steps 3 and 4: triangles -------------------------------------------------------------

    fn triangles(&mut self, k: usize, sink: &mut impl Sink) {
        let [nx, ny, _] = self.dims;
        let nxy = nx * ny;
        let (lo, hi) = (k % 2, (k + 1) % 2);
        // Where each cube-local edge's vertex id lives, relative to the cube's `i + nx * j`.
        let edge_at: [usize; 12] = core::array::from_fn(|e| {
            let r = e % 4;
            let (a, b) = (r & 1, r >> 1);
            match e / 4 {
                0 => [lo, hi][b] * 2 * nxy + a * nx,
                1 => [lo, hi][b] * 2 * nxy + nxy + a,
                _ => 4 * nxy + a + b * nx,
            }
        });
        let merging = self.params.mode != Mode::Steps123;
        for j in 0..ny - 1 {
            let s = self.span(4 * ny + (k % 3) * ny + j);
            for i in s.lo..s.hi {
                let case = self.case_at(i, j, k);
                if case == 0 || case == 255 {
                    continue;
                }
                let class = (i & 1) | (j & 1) << 1 | (k & 1) << 2;
                let entries = self.entries;
                let entry = &entries[class * 256 + usize::from(case)];
                self.stats.t13 += u64::from(entry.count);
                let at = i + nx * j;
                let id = |e: u8| self.ids[edge_at[usize::from(e)] + at];
                // Per triangle: emit as is, skip (a merged ear), or replace by the merged pair's
                // triangle (the ear of the pair's owner).
                let mut replace: [Option<Option<[u32; 3]>>; 5] = [None; 5];
                if merging {
                    for axis in 0..3 {
                        let ear = entry.ears[axis];
                        if ear == NO_EAR || id(grey_edge(class as u8, axis)) != MERGED {
                            continue;
                        }
                        replace[usize::from(ear)] =
                            Some(self.merged_triangle(i, j, k, axis, entry, &edge_at));
                    }
                }
                for (t, r) in entry.tris[..usize::from(entry.count)].iter().zip(replace) {
                    let tri = match r {
                        None => Some(t.map(id)),
                        Some(merged) => merged,
                    };
                    if let Some(tri) = tri {
                        self.stats.triangles += 1;
                        sink.triangle(tri);
                    }
                }
            }
        }
    }

    /// For a merged grey edge: the triangle that replaces this cube's ear and its partner's, if
    /// this cube is the pair's owner (the partner then emits nothing for its ear).
    fn merged_triangle(
        &self,
        i: usize,
        j: usize,
        k: usize,
        axis: usize,
        entry: &Entry,
        edge_at: &[usize; 12],
    ) -> Option<[u32; 3]> {
        let (a, b) = (i & 1, j & 1);
        // x-greys pair with the y-neighbour; y-greys with the x-neighbour; z-greys alternate by
        // layer so the quads above and below a sample choose different diagonals.
        let along_y = match axis {
            0 => true,
            1 => false,
            _ => k % 2 == 0,
        };
        let owner = match axis {
            0 => b == 0,
            1 => a == 0,
            _ if along_y => b == 1,
            _ => a == 1,
        };
        if !owner {
            return None;
        }
        let (pi, pj) = if along_y { (i, j + 1) } else { (i + 1, j) };
        let nx = self.dims[0];
        let pclass = (pi & 1) | (pj & 1) << 1 | (k & 1) << 2;
        let pentry = &self.entries[pclass * 256 + usize::from(self.case_at(pi, pj, k))];
        let ear = |e: &Entry, at: usize| {
            e.tris[usize::from(e.ears[axis])].map(|x| self.ids[edge_at[usize::from(x)] + at])
        };
        let [ba, _, fa] = ear(entry, i + nx * j);
        let [bb, _, fb] = ear(pentry, pi + nx * pj);
        debug_assert!(
            ba == fb || bb == fa,
            "ears around a merged grey edge share a face side"
        );
        Some(if ba == fb { [fa, ba, bb] } else { [fb, fa, ba] })
    }
}
