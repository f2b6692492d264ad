//! Steps 1–3 over a label volume: each cube's construction, with vertices numbered as they are
//! first used, layer by layer, so that memory beyond the output is a few planes of vertex ids.

use alloc::vec;
use alloc::vec::Vec;

use super::{Atlas, Label, LabelParams};
use core::ops::Range;
use hashbrown::HashMap;

use crate::kernel::labels::{Junction, Kind, Local, classify, edge_corners, few_labels, junction};
use crate::tables::{Entry, NO_EAR};
use crate::{Error, Mode, Volume};

const NONE: u32 = u32::MAX;

/// A binary cube's ear on a grey edge: what Step 4 needs to merge the four around the edge.
#[derive(Clone, Copy)]
pub(super) struct Ear<L> {
    pub vertex: u32,
    pub triangle: u32,
    /// The label the cube's binary case calls empty.
    pub background: L,
    /// The cube's table marks the grey edge mergeable (SPEC §5 (a)).
    pub mergeable: bool,
    /// Bit 0: the ear's back vertex lies in the plane of the merged pair's diagonal (SPEC §5);
    /// bit 1: its forward vertex does.
    pub diagonal: u8,
    /// The grey edge's lower end in the padded grid, and its axis.
    pub lower: [usize; 3],
    pub axis: usize,
}

/// The volume as the sweep sees it: with a border of background when padded. It may hold a
/// window of the volume only (a block and its halo); indices are always the whole padded grid's.
pub(super) struct Padded<'a, L> {
    data: &'a [L],
    /// The samples `data` holds along each axis, and the volume index of its first.
    dims: [usize; 3],
    at: [usize; 3],
    /// The whole volume's samples along each axis.
    volume: [usize; 3],
    pad: usize,
    pub background: L,
    /// Samples along each axis, the border included.
    pub n: [usize; 3],
}

impl<'a, L: Label> Padded<'a, L> {
    pub fn new(volume: Volume<'a, L>, params: &LabelParams<L>) -> Self {
        Self::window(volume, [0; 3], volume.dims(), params)
    }

    /// The part `samples` of a volume of `volume` samples, starting at volume index `at`: read
    /// only where the caller checked it holds what is read.
    pub fn window(
        samples: Volume<'a, L>,
        at: [usize; 3],
        volume: [usize; 3],
        params: &LabelParams<L>,
    ) -> Self {
        let pad = usize::from(params.pad);
        Padded {
            data: samples.data(),
            dims: samples.dims(),
            at,
            volume,
            pad,
            background: params.background,
            n: volume.map(|d| d + 2 * pad),
        }
    }

    /// The label at `p` of the padded grid.
    #[inline]
    pub fn at(&self, p: [usize; 3]) -> L {
        let mut q = [0; 3];
        for a in 0..3 {
            if p[a] < self.pad || p[a] >= self.volume[a] + self.pad {
                return self.background;
            }
            q[a] = p[a] - self.pad - self.at[a];
        }
        self.data[q[0] + self.dims[0] * (q[1] + self.dims[1] * q[2])]
    }

    /// The labels at `p` plus each of `offsets` (each within one sample of `p`), `None` where
    /// that leaves the padded grid: read straight from the samples where all of them lie in
    /// the data, as they do but near the volume's border.
    #[inline]
    pub fn around<const N: usize>(
        &self,
        p: [usize; 3],
        offsets: &[[isize; 3]; N],
    ) -> [Option<L>; N] {
        let start = |a: usize| self.pad + self.at[a];
        if (0..3).all(|a| p[a] > start(a) && p[a] + 1 < start(a) + self.dims[a]) {
            let [dx, dy, _] = self.dims;
            let q: [usize; 3] = core::array::from_fn(|a| p[a] - start(a));
            let base = q[0] + dx * (q[1] + dy * q[2]);
            let stride = [1, dx as isize, (dx * dy) as isize];
            return offsets.map(|d| {
                let step = d[0] * stride[0] + d[1] * stride[1] + d[2] * stride[2];
                Some(self.data[base.wrapping_add_signed(step)])
            });
        }
        offsets.map(|d| {
            let q: [usize; 3] = core::array::from_fn(|a| p[a].wrapping_add_signed(d[a]));
            (q.iter().zip(&self.n).all(|(&c, &m)| c < m)).then(|| self.at(q))
        })
    }

    /// Copies the samples `xs × ys` of plane `z` of the padded grid into `out`, row by row.
    pub fn plane(&self, z: usize, xs: Range<usize>, ys: Range<usize>, out: &mut [L]) {
        let w = xs.len();
        let [dx, dy, _] = self.dims;
        // The columns inside the volume, as indices into a row of `out`.
        let x0 = xs.start.max(self.pad).min(xs.end);
        let x1 = xs.end.min(self.volume[0] + self.pad).max(x0);
        if z < self.pad || z >= self.volume[2] + self.pad {
            out.fill(self.background);
            return;
        }
        let slice = &self.data[(z - self.pad - self.at[2]) * dx * dy..][..dx * dy];
        for (r, y) in ys.enumerate() {
            let row = &mut out[r * w..][..w];
            if y < self.pad || y >= self.volume[1] + self.pad {
                row.fill(self.background);
                continue;
            }
            let src = &slice[(y - self.pad - self.at[1]) * dx..][..dx];
            let from = |x: usize| x - self.pad - self.at[0];
            row[..x0 - xs.start].fill(self.background);
            row[x0 - xs.start..x1 - xs.start].copy_from_slice(&src[from(x0)..from(x1)]);
            row[x1 - xs.start..].fill(self.background);
        }
    }

    /// About how much surface layer `z` of the padded grid holds: how often the label changes
    /// from a sample of plane `z` to the next along each axis, counted on every fourth row,
    /// which is plenty to share the work out by.
    pub fn changes(&self, z: usize) -> usize {
        let start = self.pad + self.at[2];
        if z < start || z >= start + self.dims[2] {
            return 0;
        }
        let [dx, dy, dz] = self.dims;
        let row = |y: usize, z: usize| &self.data[dx * (y + dy * z)..][..dx];
        // Exact slices of one length and a flag sum: vector compares.
        let differ = |a: &[L], b: &[L]| -> usize {
            let n = a.len().min(b.len());
            let (a, b) = (&a[..n], &b[..n]);
            (0..n).fold(0u32, |c, i| c + u32::from(a[i] != b[i])) as usize
        };
        let z = z - start;
        (0..dy)
            .step_by(4)
            .map(|y| {
                let here = row(y, z);
                let along_x = differ(here, &here[1..]);
                let along_y = if y + 1 < dy {
                    differ(here, row(y + 1, z))
                } else {
                    0
                };
                let along_z = if z + 1 < dz {
                    differ(here, row(y, z + 1))
                } else {
                    0
                };
                along_x + along_y + along_z
            })
            .sum()
    }

    /// `kind`, [`few_labels`] of the labels themselves, as it is of their keys: the keys order
    /// two labels unlike the labels only when the larger is the background, which then plays
    /// empty. (Comparing labels is cheaper than comparing keys, and one or two labels is most
    /// cubes with a surface.)
    #[inline]
    pub fn by_key(&self, labels: &[L; 8], kind: Kind) -> Kind {
        match kind {
            Kind::Binary { background, case } => {
                let other = case.trailing_zeros() as usize;
                if self.key(labels[other]) < self.key(labels[usize::from(background)]) {
                    Kind::Binary {
                        background: other as u8,
                        case: !case,
                    }
                } else {
                    kind
                }
            }
            kind => kind,
        }
    }

    /// The order of labels for the face rule: the background first, then ascending.
    #[inline]
    pub fn key(&self, l: L) -> (bool, L) {
        (l != self.background, l)
    }
}

/// Offset of corner `c` from its cube's lower corner.
const fn offset(c: u8) -> [usize; 3] {
    [
        (c & 1) as usize,
        ((c >> 1) & 1) as usize,
        ((c >> 2) & 1) as usize,
    ]
}

/// The axis of cube edge `e`.
const fn edge_axis(e: u8) -> usize {
    (e / 4) as usize
}

/// Vertex ids of the nodes shared between cubes, for the planes and layer in reach: x- and
/// y-edges and z-facing face centres of planes `k` and `k + 1` (by `z % 2`), z-edges and x- and
/// y-facing face centres of layer `k`. A slot holds its id plus one, and counts only if that id
/// was made since its plane or layer came into reach: ids grow as the sweep goes, so moving on
/// is a few numbers, not a fill of six planes per layer.
struct Ids {
    nx: usize,
    /// Nine planes of `nx · ny` slots, in the order of [`Ids::X`] and the rest.
    slots: Vec<u32>,
    /// Per plane, the first id made since it came into reach.
    since: [u32; 9],
    /// Per cube edge, in the current layer: its offset from the cube's slot, and the first id
    /// its plane may hold (a copy of `since`, fixed for the layer). Sixteen, so that an edge
    /// masked to four bits needs no bound check.
    edges: [(usize, u32); 16],
}

impl Ids {
    const X: usize = 0;
    const Y: usize = 2;
    const Z: usize = 4;
    const FX: usize = 5;
    const FY: usize = 6;
    const FZ: usize = 7;

    fn new(nx: usize, ny: usize) -> Ids {
        Ids {
            nx,
            slots: vec![0; 9 * nx * ny],
            since: [0; 9],
            edges: [(0, 0); 16],
        }
    }

    fn plane_len(&self) -> usize {
        self.slots.len() / 9
    }

    /// Brings layer `k` and plane `k + 1` into reach (the latter in plane `k − 1`'s slots, if
    /// `k` is not the first layer); `next` is the next id to be made.
    fn start_layer(&mut self, k: usize, next: u32, first: bool) {
        let s = (k + 1) % 2;
        if !first {
            for plane in [Self::X + s, Self::Y + s, Self::FZ + s] {
                self.since[plane] = next;
            }
            for plane in [Self::Z, Self::FX, Self::FY] {
                self.since[plane] = next;
            }
        }
        let n = self.plane_len();
        for (e, slot) in self.edges[..12].iter_mut().enumerate() {
            let [dx, dy, dz] = EDGE_LOWER[e];
            let plane = match edge_axis(e as u8) {
                0 => Self::X + (k + dz) % 2,
                1 => Self::Y + (k + dz) % 2,
                _ => Self::Z,
            };
            *slot = (plane * n + dx + self.nx * dy, self.since[plane]);
        }
    }

    /// Plane `z`'s slots (x-edges, y-edges, face centres), with those not made since it came
    /// into reach cleared.
    fn plane(&self, z: usize) -> [Vec<u32>; 3] {
        let n = self.plane_len();
        let s = z % 2;
        [Self::X + s, Self::Y + s, Self::FZ + s].map(|plane| {
            let since = self.since[plane];
            self.slots[plane * n..][..n]
                .iter()
                .map(|&v| if v > since { v } else { 0 })
                .collect()
        })
    }

    /// The slot of the vertex on cube edge `e` of the cube at `at` (`i + nx · j`) in this
    /// layer, and the first id it may hold.
    #[inline]
    fn edge(&mut self, at: usize, e: u8) -> (&mut u32, u32) {
        let (offset, since) = self.edges[usize::from(e & 15)];
        (&mut self.slots[offset + at], since)
    }

    /// [`Ids::edge`] for the centre of face `f` of the cube `[i, j, k]` (`i`, `j` from the
    /// box's corner).
    fn face(&mut self, cube: [usize; 3], f: u8) -> (&mut u32, u32) {
        let side = usize::from(f % 2);
        let [i, j, k] = cube;
        let (plane, at) = match f / 2 {
            0 => (Self::FX, i + side + self.nx * j),
            1 => (Self::FY, i + self.nx * (j + side)),
            _ => (Self::FZ + (k + side) % 2, i + self.nx * j),
        };
        let n = self.plane_len();
        (&mut self.slots[plane * n + at], self.since[plane])
    }
}

/// The vertex in `slot` (see [`Ids`]), made by `make` if it has none yet.
// Always inlined: a cube's few vertex lookups are most of a surface cube's work, and the call
// around one costs as much as the lookup.
#[inline(always)]
fn shared(
    (slot, since): (&mut u32, u32),
    make: impl FnOnce() -> Result<u32, Error>,
) -> Result<u32, Error> {
    if *slot <= since {
        *slot = make()? + 1;
    }
    Ok(*slot - 1)
}

/// The sweep's output so far.
struct Out<'p, L> {
    atlas: &'p mut Atlas<L>,
    /// Per axis, the world coordinate of each quarter of a cube side over the box's cubes,
    /// from its first cube's lower corner: a vertex's position is three loads.
    coordinates: [Vec<f32>; 3],
    /// The box's first cube.
    start: [usize; 3],
    /// With smoothing, per vertex: the grid edge it lies on (lower end, axis), or
    /// [`NOT_ON_AN_EDGE`].
    edges: Option<Vec<Edge>>,
    /// With smoothing, the vertices of hub cubes, which stay where they are made.
    pinned: Vec<u32>,
}

/// A grid edge: its lower end in the padded grid, and its axis.
pub(super) type Edge = [u32; 4];

/// [`Edge`] for a vertex that is not an edge's (a face's or cube's centre, a hub's).
pub(super) const NOT_ON_AN_EDGE: Edge = [u32::MAX; 4];

impl<L> Out<'_, L> {
    /// A new vertex at `quarters` (quarters of a cube side) from `cube`'s lower corner.
    fn vertex(&mut self, cube: [usize; 3], quarters: [i32; 3]) -> Result<u32, Error> {
        let id = self.atlas.positions.len();
        // Ids are u32, and stored plus one (see `Ids`).
        if id >= (NONE - 1) as usize {
            return Err(Error::TooManyVertices);
        }
        let p: [f32; 3] = core::array::from_fn(|a| {
            self.coordinates[a][4 * (cube[a] - self.start[a]) + quarters[a] as usize]
        });
        self.atlas.positions.push(p);
        if let Some(edges) = &mut self.edges {
            edges.push(NOT_ON_AN_EDGE);
        }
        Ok(id as u32)
    }

    /// A new vertex at the midpoint of cube edge `e` of `cube`.
    fn edge_vertex(&mut self, cube: [usize; 3], e: u8) -> Result<u32, Error> {
        let id = self.vertex(cube, EDGE_QUARTERS[usize::from(e)])?;
        if let Some(edges) = &mut self.edges {
            let [x, y, z] = edge_lower(cube, e);
            // The padded grid's sizes fit in u32 (its vertex ids do).
            edges[id as usize] = [x as u32, y as u32, z as u32, edge_axis(e) as u32];
        }
        Ok(id)
    }
}

/// The output of a run of layers, to be joined with its neighbours'.
pub(super) struct Piece<L> {
    pub atlas: Atlas<L>,
    pub ears: Vec<Ear<L>>,
    /// The vertex slots (ids plus one, 0 for none) of the first plane's x-edges, y-edges and
    /// face centres, and of the plane after the last layer: the vertices two pieces share.
    pub bottom: [Vec<u32>; 3],
    pub top: [Vec<u32>; 3],
    /// With smoothing: per vertex its grid edge, and the vertices that stay (see `Out`).
    pub edges: Vec<Edge>,
    pub pinned: Vec<u32>,
    /// When asked for, each cube with triangles, in sweep order (see [`Emitter`]).
    pub emitters: Vec<Emitter>,
}

/// A cube that made triangles, and where its output starts: its triangles run to the next
/// emitter's first, and so do the vertices it was the first to use. What a block needs to name
/// vertices and triangles by the cube that made them.
#[derive(Clone, Copy, Debug)]
pub(super) struct Emitter {
    pub cube: [usize; 3],
    pub triangle: u32,
    pub vertex: u32,
}

/// Steps 1–3 over the box `cubes` (lower corners, per axis) of the padded grid; with `record`,
/// the piece lists its [`Emitter`]s. Vertices are numbered as the piece first uses them, from 0,
/// so a piece depends only on its cubes, not on where the sweep started.
pub(super) fn sweep<L: Label>(
    grid: &Padded<'_, L>,
    params: &LabelParams<L>,
    cubes: [Range<usize>; 3],
    record: bool,
) -> Result<Piece<L>, Error> {
    // The box's samples along x and y; indices into its planes are relative to its corner.
    let [xs, ys] = [0, 1].map(|a| cubes[a].start..cubes[a].end + 1);
    let (nx, ny) = (xs.len(), ys.len());
    let layers = cubes[2].clone();
    let mut atlas = Atlas::default();
    let mut ears = Vec::new();
    let mut emitters = Vec::new();
    let mut ids = Ids::new(nx, ny);
    let pad = f64::from(u8::from(params.pad));
    let mut out = Out {
        atlas: &mut atlas,
        coordinates: core::array::from_fn(|a| {
            // The world position of padded sample 0 along the axis.
            let origin = params.origin[a] - pad * params.spacing[a];
            (4 * cubes[a].start..=4 * cubes[a].end)
                .map(|q| {
                    let (cube, quarter) = (q / 4, q % 4);
                    (origin + (cube as f64 + quarter as f64 / 4.0) * params.spacing[a]) as f32
                })
                .collect()
        }),
        start: cubes.clone().map(|r| r.start),
        edges: (params.smoothing > 0.0).then(Vec::new),
        pinned: Vec::new(),
    };
    let mut binaries = Binaries::new(params);
    let mut patterns = Patterns::default();
    let mut planes = [
        vec![grid.background; nx * ny],
        vec![grid.background; nx * ny],
    ];
    // Padded for `changed`; `differs` writes the first `nx − 1`.
    let mut mask = vec![0u8; (nx - 1).next_multiple_of(8)];
    let mut bottom = [Vec::new(), Vec::new(), Vec::new()];
    let first = layers.start;
    grid.plane(first, xs.clone(), ys.clone(), &mut planes[first % 2]);
    for k in layers.clone() {
        if k == first + 1 {
            bottom = ids.plane(first);
        }
        ids.start_layer(k, out.atlas.positions.len() as u32, k == first);
        grid.plane(k + 1, xs.clone(), ys.clone(), &mut planes[(k + 1) % 2]);
        let (lower, upper) = (&planes[k % 2], &planes[(k + 1) % 2]);
        for j in 0..ny - 1 {
            let rows = [
                &lower[j * nx..][..nx],
                &lower[(j + 1) * nx..][..nx],
                &upper[j * nx..][..nx],
                &upper[(j + 1) * nx..][..nx],
            ];
            differs(rows, &mut mask[..nx - 1]);
            for i in changed(&mask) {
                let labels = [
                    rows[0][i],
                    rows[0][i + 1],
                    rows[1][i],
                    rows[1][i + 1],
                    rows[2][i],
                    rows[2][i + 1],
                    rows[3][i],
                    rows[3][i + 1],
                ];
                let cube = [xs.start + i, ys.start + j, k];
                let here = i + nx * j;
                if record {
                    emitters.push(Emitter {
                        cube,
                        triangle: out.atlas.triangles.len() as u32,
                        vertex: out.atlas.positions.len() as u32,
                    });
                }
                let (kind, nodes, built) = match few_labels(&labels) {
                    Some(kind) => (grid.by_key(&labels, kind), &[][..], &[][..]),
                    None => patterns.get(grid, &labels),
                };
                match kind {
                    Kind::Uniform => {}
                    Kind::Binary { background, case } => {
                        let class = (cube[0] & 1) | (cube[1] & 1) << 1 | (k & 1) << 2;
                        let entry = binaries.get(class * 256 + usize::from(case));
                        let w = labels[usize::from(background & 7)];
                        // Sixteen slots, indexed by four bits: no bound checks.
                        let mut v = [0; 16];
                        for (v, &e) in v.iter_mut().zip(&entry.edges[..usize::from(entry.used)]) {
                            *v = edge_vertex(&mut ids, &mut out, cube, here, e)?;
                        }
                        let first = out.atlas.triangles.len() as u32;
                        // Extended from slices rather than pushed: one capacity check each.
                        let count = usize::from(entry.count);
                        out.atlas.triangles.extend(
                            entry.tris[..count]
                                .iter()
                                .map(|tri| tri.map(|s| v[usize::from(s & 15)])),
                        );
                        out.atlas.pairs.extend(
                            entry.other[..count]
                                .iter()
                                .map(|&c| [labels[usize::from(c & 7)], w]),
                        );
                        for ear in &entry.ears[..usize::from(entry.n_ears)] {
                            let o = ear.lower;
                            ears.push(Ear {
                                vertex: v[usize::from(ear.slot & 15)],
                                triangle: first + u32::from(ear.triangle),
                                background: w,
                                mergeable: ear.mergeable,
                                diagonal: ear.diagonal,
                                lower: core::array::from_fn(|a| cube[a] + usize::from(o[a])),
                                axis: usize::from(ear.axis),
                            });
                        }
                    }
                    Kind::Junction => {
                        // Sixty-four slots, indexed by six bits: no bound checks. A junction uses
                        // at most 45 (12 edges, 6 faces, the centre, 18 inner nodes, 8 corners).
                        let mut v = [0; 64];
                        for (v, &node) in v.iter_mut().zip(nodes) {
                            *v = match node {
                                Local::Edge(e) => edge_vertex(&mut ids, &mut out, cube, here, e)?,
                                Local::Face(f) => shared(ids.face([i, j, k], f), || {
                                    out.vertex(cube, node.quarters())
                                })?,
                                // The centre and the inner vertices are the cube's own.
                                _ => out.vertex(cube, node.quarters())?,
                            };
                        }
                        let corners = |b: &Built| b.nodes.map(|s| v[usize::from(s & 63)]);
                        // Extended, as a binary cube's are: one capacity check each.
                        out.atlas.triangles.extend(built.iter().map(corners));
                        out.atlas
                            .pairs
                            .extend(built.iter().map(|b| b.pair).map(|[x, y]| {
                                [labels[usize::from(x & 7)], labels[usize::from(y & 7)]]
                            }));
                        if out.edges.is_some() {
                            let pinned = built.iter().filter(|b| b.pinned);
                            out.pinned.extend(pinned.flat_map(corners));
                        }
                    }
                }
            }
        }
    }
    if layers.len() == 1 {
        bottom = ids.plane(first);
    }
    let top = ids.plane(layers.end);
    let Out { edges, pinned, .. } = out;
    Ok(Piece {
        edges: edges.unwrap_or_default(),
        pinned,
        atlas,
        ears,
        bottom,
        top,
        emitters,
    })
}

/// A binary table entry as the sweep reads it, derived from the entry when first met.
#[derive(Clone, Copy, Default)]
struct Binary {
    /// The entry's edges in order of first use: their vertices, looked up in that order, are
    /// made in the order the triangles would make them, and each is looked up once.
    edges: [u8; 12],
    used: u8,
    /// Triangles as indices into `edges`.
    tris: [[u8; 3]; 5],
    /// Per triangle, the corner of its first edge that is not the background's: its label is
    /// the one the triangle faces away from.
    other: [u8; 5],
    count: u8,
    /// The ears Step 4 may merge; none in Steps 1–3.
    ears: [BinaryEar; 3],
    n_ears: u8,
    ready: bool,
}

/// What [`Ear`] takes from a binary entry.
#[derive(Clone, Copy, Default)]
struct BinaryEar {
    /// The ear's triangle in the entry, its grey edge's index in [`Binary::edges`] and lower
    /// end (from the cube's lower corner).
    triangle: u8,
    slot: u8,
    lower: [u8; 3],
    axis: u8,
    mergeable: bool,
    diagonal: u8,
}

/// The entries of a mode's table as [`Binary`], each derived when first met.
struct Binaries {
    table: &'static [Entry; 2048],
    mergeable: &'static [u8; 2048],
    ears: bool,
    derived: Vec<Binary>,
}

impl Binaries {
    fn new<L>(params: &LabelParams<L>) -> Self {
        Binaries {
            table: params.tables.for_mode(params.mode),
            mergeable: params.tables.mergeable(),
            ears: params.mode != Mode::Steps123,
            derived: vec![Binary::default(); 2048],
        }
    }

    /// Entry `case_at` (`class * 256 + case`).
    #[inline]
    fn get(&mut self, case_at: usize) -> &Binary {
        if !self.derived[case_at].ready {
            self.derived[case_at] = self.derive(case_at);
        }
        &self.derived[case_at]
    }

    fn derive(&self, case_at: usize) -> Binary {
        let entry = &self.table[case_at];
        let case = case_at as u8;
        let mut b = Binary {
            count: entry.count,
            ready: true,
            ..Binary::default()
        };
        let slot = |b: &mut Binary, e: u8| match b.edges[..usize::from(b.used)]
            .iter()
            .position(|&f| f == e)
        {
            Some(s) => s as u8,
            None => {
                b.edges[usize::from(b.used)] = e;
                b.used += 1;
                b.used - 1
            }
        };
        for (n, tri) in entry.tris[..usize::from(entry.count)].iter().enumerate() {
            b.tris[n] = tri.map(|e| slot(&mut b, e));
            let (c0, c1) = edge_corners(tri[0]);
            b.other[n] = if case >> c0 & 1 == 1 { c0 } else { c1 };
        }
        if self.ears {
            // The class's parity bits stand for the cube's: diagonals depend on nothing else.
            let class = case_at / 256;
            let cube = [class & 1, class >> 1 & 1, class >> 2 & 1];
            for axis in 0..3 {
                let ear = entry.ears[axis];
                if ear == NO_EAR {
                    continue;
                }
                let [back, grey, forward] = entry.tris[usize::from(ear)];
                b.ears[usize::from(b.n_ears)] = BinaryEar {
                    triangle: ear,
                    slot: slot(&mut b, grey),
                    lower: EDGE_LOWER[usize::from(grey)].map(|o| o as u8),
                    axis: axis as u8,
                    mergeable: self.mergeable[case_at] >> axis & 1 == 1,
                    diagonal: u8::from(in_diagonal_plane(cube, grey, back))
                        | u8::from(in_diagonal_plane(cube, grey, forward)) << 1,
                };
                b.n_ears += 1;
            }
        }
        b
    }
}

/// A junction cube's triangle: its vertices as indices into its pattern's nodes, a corner on
/// the side it faces away from and one on the side it faces toward, and whether smoothing
/// leaves its vertices where they are made (a hub's walls and floors are radial from the
/// cube's centre only with their nodes at midpoints).
#[derive(Clone, Copy)]
struct Built {
    nodes: [u8; 3],
    pair: [u8; 2],
    pinned: bool,
}

/// A pattern's construction: its kind, and for a junction the ranges of its nodes (in
/// `Patterns::nodes`) and triangles (in `Patterns::triangles`).
#[derive(Clone, Copy)]
struct Construction {
    kind: Kind,
    nodes: (usize, usize),
    triangles: (usize, usize),
}

/// The constructions of cubes with three or more labels met so far, by the order pattern of
/// their corners' labels: a segmentation has few patterns, and building one takes thousands of
/// instructions, while a cube reads every label only through comparisons, so cubes of one
/// pattern are built alike.
#[derive(Default)]
struct Patterns {
    index: HashMap<u32, Construction>,
    /// Per junction pattern, the vertices its triangles use, in order of first use: a cube
    /// makes or finds each once, in the order its triangles would.
    nodes: Vec<Local>,
    triangles: Vec<Built>,
    built: Junction,
}

impl Patterns {
    /// The construction of a cube of `labels` on `grid`.
    fn get<L: Label>(
        &mut self,
        grid: &Padded<'_, L>,
        labels: &[L; 8],
    ) -> (Kind, &[Local], &[Built]) {
        let pattern = pattern(labels, grid.background);
        let found = match self.index.get(&pattern) {
            Some(&found) => found,
            None => {
                let keys = &labels.map(|l| grid.key(l));
                let kind = classify(keys);
                let (nodes, triangles) = (self.nodes.len(), self.triangles.len());
                if kind == Kind::Junction {
                    junction(keys, &mut self.built);
                    let b = &self.built;
                    for n in 0..b.len {
                        let triangle = b.triangles[n].map(|local| {
                            let mine = &mut self.nodes;
                            let s = match mine[nodes..].iter().position(|&l| l == local) {
                                Some(s) => s,
                                None => {
                                    mine.push(local);
                                    mine.len() - 1 - nodes
                                }
                            };
                            s as u8
                        });
                        self.triangles.push(Built {
                            nodes: triangle,
                            pair: b.pairs[n],
                            pinned: b.triangles[n]
                                .iter()
                                .any(|l| matches!(l, Local::InnerNode(_) | Local::InnerCorner(_))),
                        });
                    }
                }
                let found = Construction {
                    kind,
                    nodes: (nodes, self.nodes.len()),
                    triangles: (triangles, self.triangles.len()),
                };
                self.index.insert(pattern, found);
                found
            }
        };
        (
            found.kind,
            &self.nodes[found.nodes.0..found.nodes.1],
            &self.triangles[found.triangles.0..found.triangles.1],
        )
    }
}

/// The order pattern of a cube's keys ([`Padded::key`]): three bits per corner, its key's rank
/// among the distinct keys. From the 28 comparisons of pairs of labels, without a sort: a
/// corner's rank counts the smaller keys' first corners. Keys order labels as the labels do,
/// but for the background, which comes first: comparing labels is cheaper than comparing keys.
#[inline]
fn pattern<L: Ord + Copy>(labels: &[L; 8], background: L) -> u32 {
    let mut smaller = [0u32; 8];
    let mut firsts = 0xFFu32;
    let mut backgrounds = 0u32;
    for c in 0..8 {
        backgrounds |= u32::from(labels[c] == background) << c;
        for d in c + 1..8 {
            match labels[d].cmp(&labels[c]) {
                core::cmp::Ordering::Less => smaller[c] |= 1 << d,
                core::cmp::Ordering::Greater => smaller[d] |= 1 << c,
                core::cmp::Ordering::Equal => firsts &= !(1 << d),
            }
        }
    }
    (0..8).fold(0, |p, c| {
        let below = if backgrounds >> c & 1 == 1 {
            0
        } else {
            smaller[c] & !backgrounds | backgrounds
        };
        p | (below & firsts).count_ones() << (3 * c)
    })
}

/// The cubes a row's mask marks: most cubes hold one label, and are skipped eight at a time.
/// The mask is padded with zeros to a multiple of eight, so each word is one load.
fn changed(mask: &[u8]) -> Changed<'_> {
    Changed {
        mask,
        next: 0,
        word: 0,
    }
}

/// The iterator of [`changed`]: a word of the mask and where the next starts, which is less
/// state for the sweep's loop to keep than a chain of adapters.
struct Changed<'a> {
    mask: &'a [u8],
    next: usize,
    word: u64,
}

impl Iterator for Changed<'_> {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        while self.word == 0 {
            let bytes = self.mask.get(self.next..self.next + 8)?;
            self.word = u64::from_le_bytes(bytes.try_into().unwrap_or_default());
            self.next += 8;
        }
        let k = self.word.trailing_zeros() as usize / 8;
        // Each byte is 0 or 1: clearing the lowest bit set clears its byte.
        self.word &= self.word - 1;
        Some(self.next - 8 + k)
    }
}

/// Per cube of a row, 1 if its eight corners (`rows`: y and y + 1 at z, then at z + 1) do not
/// all hold one label. Written without branches, so that it vectorises.
fn differs<L: Label>(rows: [&[L]; 4], mask: &mut [u8]) {
    let n = mask.len();
    let [a, b, c, d] = rows.map(|r| &r[..n + 1]);
    for i in 0..n {
        let v = a[i];
        let any = (a[i + 1] != v)
            | (b[i] != v)
            | (b[i + 1] != v)
            | (c[i] != v)
            | (c[i + 1] != v)
            | (d[i] != v)
            | (d[i + 1] != v);
        mask[i] = u8::from(any);
    }
}

/// The lower end of cube edge `e` of `cube`, in the grid.
#[inline]
fn edge_lower(cube: [usize; 3], e: u8) -> [usize; 3] {
    let o = EDGE_LOWER[usize::from(e)];
    [cube[0] + o[0], cube[1] + o[1], cube[2] + o[2]]
}

/// Each cube edge's midpoint, in quarters of a side from the cube's lower corner.
const EDGE_QUARTERS: [[i32; 3]; 12] = {
    let mut out = [[0; 3]; 12];
    let mut e = 0;
    while e < 12 {
        out[e] = Local::Edge(e as u8).quarters();
        e += 1;
    }
    out
};

/// Each cube edge's lower end, from the cube's lower corner.
const EDGE_LOWER: [[usize; 3]; 12] = {
    let mut out = [[0; 3]; 12];
    let mut e = 0;
    while e < 12 {
        out[e] = offset(edge_corners(e as u8).0);
        e += 1;
    }
    out
};

/// The vertex on cube edge `e`, made at its midpoint when first used.
// Always inlined, as `shared` is: out of line, the call costs more than the lookup.
#[inline(always)]
fn edge_vertex<L>(
    ids: &mut Ids,
    out: &mut Out<'_, L>,
    cube: [usize; 3],
    at: usize,
    e: u8,
) -> Result<u32, Error> {
    shared(ids.edge(at, e), || out.edge_vertex(cube, e))
}

/// Whether the vertex on cube edge `e` is a corner of the merged pair's diagonal for grey edge
/// `grey` (SPEC §5): in the grey edge's plane `z = n` for x- and y-greys; for z-greys, in the
/// plane `x = l` in even layers and `y = m` in odd ones.
fn in_diagonal_plane(cube: [usize; 3], grey: u8, e: u8) -> bool {
    let g = edge_lower(cube, grey);
    let p = edge_lower(cube, e);
    let axis = edge_axis(e);
    match edge_axis(grey) {
        2 if g[2].is_multiple_of(2) => axis != 0 && p[0] == g[0],
        2 => axis != 1 && p[1] == g[1],
        _ => axis != 2 && p[2] == g[2],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`pattern`] is each corner's rank among the distinct keys, as sorting the keys gives it,
    /// for every labelling of a cube with four labels, the background each of them in turn.
    #[test]
    fn pattern_ranks_keys() {
        for background in 0u8..4 {
            for n in 0..4u32.pow(8) {
                let labels: [u8; 8] = core::array::from_fn(|c| (n >> (2 * c) & 3) as u8);
                let keys = labels.map(|l| (l != background, l));
                let mut distinct = keys.to_vec();
                distinct.sort_unstable();
                distinct.dedup();
                let sorted = (0..8).fold(0, |p, c| {
                    let rank = distinct.iter().position(|k| *k == keys[c]).unwrap();
                    p | (rank as u32) << (3 * c)
                });
                assert_eq!(
                    pattern(&labels, background),
                    sorted,
                    "{labels:?}, {background}"
                );
            }
        }
    }
}
