//! Steps 1–3 over a label volume: each cube's construction, with vertices numbered as they are
//! first used, layer by layer, so that memory beyond the output is a few planes of vertex ids.

use alloc::vec;
use alloc::vec::Vec;

use super::{Atlas, Label, LabelParams};
use crate::kernel::labels::{Junction, Kind, Local, classify, edge_corners, junction};
use crate::tables::NO_EAR;
use crate::{Error, Mode, Volume};

const NONE: u32 = u32::MAX;

/// A binary cube's ear on a grey edge: what Step 4 needs to merge the four around the edge.
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

/// The volume as the sweep sees it: with a border of background when padded.
pub(super) struct Padded<'a, L> {
    data: &'a [L],
    dims: [usize; 3],
    pad: usize,
    pub background: L,
    /// Samples along each axis, the border included.
    pub n: [usize; 3],
}

impl<'a, L: Label> Padded<'a, L> {
    pub fn new(volume: Volume<'a, L>, params: &LabelParams<L>) -> Self {
        let dims = volume.dims();
        let pad = usize::from(params.pad);
        Padded {
            data: volume.data(),
            dims,
            pad,
            background: params.background,
            n: dims.map(|d| d + 2 * pad),
        }
    }

    /// The label at `p` of the padded grid.
    #[inline]
    pub fn at(&self, p: [usize; 3]) -> L {
        let mut q = [0; 3];
        for a in 0..3 {
            if p[a] < self.pad || p[a] >= self.dims[a] + self.pad {
                return self.background;
            }
            q[a] = p[a] - self.pad;
        }
        self.data[q[0] + self.dims[0] * (q[1] + self.dims[1] * q[2])]
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
/// y-edges and z-facing face centres of planes `k` and `k + 1` (slot `z % 2`), z-edges and
/// x- and y-facing face centres of layer `k`.
struct Ids {
    nx: usize,
    x: [Vec<u32>; 2],
    y: [Vec<u32>; 2],
    fz: [Vec<u32>; 2],
    z: Vec<u32>,
    fx: Vec<u32>,
    fy: Vec<u32>,
}

impl Ids {
    fn new(nx: usize, ny: usize) -> Ids {
        let plane = || vec![NONE; nx * ny];
        Ids {
            nx,
            x: [plane(), plane()],
            y: [plane(), plane()],
            fz: [plane(), plane()],
            z: plane(),
            fx: plane(),
            fy: plane(),
        }
    }

    /// Forgets plane `k + 1`'s slot (plane `k − 1`'s until now) and layer `k − 1`.
    fn next_layer(&mut self, k: usize) {
        let s = (k + 1) % 2;
        for ids in [&mut self.x[s], &mut self.y[s], &mut self.fz[s]] {
            ids.fill(NONE);
        }
        for ids in [&mut self.z, &mut self.fx, &mut self.fy] {
            ids.fill(NONE);
        }
    }

    fn edge(&mut self, lower: [usize; 3], axis: usize) -> &mut u32 {
        let at = lower[0] + self.nx * lower[1];
        match axis {
            0 => &mut self.x[lower[2] % 2][at],
            1 => &mut self.y[lower[2] % 2][at],
            _ => &mut self.z[at],
        }
    }

    fn face(&mut self, cube: [usize; 3], f: u8) -> &mut u32 {
        let side = usize::from(f % 2);
        let [i, j, k] = cube;
        match f / 2 {
            0 => &mut self.fx[i + side + self.nx * j],
            1 => &mut self.fy[i + self.nx * (j + side)],
            _ => &mut self.fz[(k + side) % 2][i + self.nx * j],
        }
    }
}

/// The sweep's output so far.
struct Out<'p, L> {
    atlas: &'p mut Atlas<L>,
    spacing: [f64; 3],
    /// The world position of padded sample `(0, 0, 0)`.
    origin: [f64; 3],
}

impl<L> Out<'_, L> {
    /// A new vertex at `quarters` (quarters of a cube side) from `cube`'s lower corner.
    fn vertex(&mut self, cube: [usize; 3], quarters: [i32; 3]) -> Result<u32, Error> {
        let id = u32::try_from(self.atlas.positions.len()).map_err(|_| Error::TooManyVertices)?;
        if id == NONE {
            return Err(Error::TooManyVertices);
        }
        let p: [f32; 3] = core::array::from_fn(|a| {
            (self.origin[a] + (cube[a] as f64 + f64::from(quarters[a]) / 4.0) * self.spacing[a])
                as f32
        });
        self.atlas.positions.push(p);
        Ok(id)
    }

    fn triangle(&mut self, t: [u32; 3], pair: [L; 2]) -> u32 {
        self.atlas.triangles.push(t);
        self.atlas.pairs.push(pair);
        (self.atlas.triangles.len() - 1) as u32
    }
}

/// Steps 1–3 into `atlas`; returns the binary cubes' ears on grey edges, for Step 4.
pub(super) fn sweep<L: Label>(
    volume: Volume<'_, L>,
    params: &LabelParams<L>,
    atlas: &mut Atlas<L>,
) -> Result<Vec<Ear<L>>, Error> {
    let grid = Padded::new(volume, params);
    let [nx, ny, nz] = grid.n;
    let mut ears = Vec::new();
    if nx < 2 || ny < 2 || nz < 2 {
        return Ok(ears);
    }
    let mut ids = Ids::new(nx, ny);
    let pad = f64::from(u8::from(params.pad));
    let mut out = Out {
        atlas,
        spacing: params.spacing,
        origin: core::array::from_fn(|a| params.origin[a] - pad * params.spacing[a]),
    };
    let table = params.tables.for_mode(params.mode);
    let mergeable = params.tables.mergeable();
    let mut built = Junction::default();
    for k in 0..nz - 1 {
        if k > 0 {
            ids.next_layer(k);
        }
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let cube = [i, j, k];
                let labels: [L; 8] = core::array::from_fn(|c| {
                    let o = offset(c as u8);
                    grid.at([i + o[0], j + o[1], k + o[2]])
                });
                let keys = labels.map(|l| grid.key(l));
                match classify(&keys) {
                    Kind::Uniform => {}
                    Kind::Binary { background, case } => {
                        let class = (i & 1) | (j & 1) << 1 | (k & 1) << 2;
                        let at = class * 256 + usize::from(case);
                        let entry = &table[at];
                        let w = labels[usize::from(background)];
                        let mut first = 0;
                        for (n, tri) in entry.tris[..usize::from(entry.count)].iter().enumerate() {
                            let mut t = [0; 3];
                            for (v, &e) in t.iter_mut().zip(tri) {
                                *v = edge_vertex(&mut ids, &mut out, cube, e)?;
                            }
                            let (a, b) = edge_corners(tri[0]);
                            let x = if labels[usize::from(a)] == w {
                                labels[usize::from(b)]
                            } else {
                                labels[usize::from(a)]
                            };
                            let id = out.triangle(t, [x, w]);
                            if n == 0 {
                                first = id;
                            }
                        }
                        if params.mode == Mode::Steps123 {
                            continue;
                        }
                        for axis in 0..3 {
                            let ear = entry.ears[axis];
                            if ear == NO_EAR {
                                continue;
                            }
                            let [back, grey, forward] = entry.tris[usize::from(ear)];
                            let vertex = *ids.edge(edge_lower(cube, grey), axis);
                            ears.push(Ear {
                                vertex,
                                triangle: first + u32::from(ear),
                                background: w,
                                mergeable: mergeable[at] >> axis & 1 == 1,
                                diagonal: u8::from(in_diagonal_plane(cube, grey, back))
                                    | u8::from(in_diagonal_plane(cube, grey, forward)) << 1,
                                lower: edge_lower(cube, grey),
                                axis,
                            });
                        }
                    }
                    Kind::Junction => {
                        junction(&keys, &mut built);
                        let mut own = [NONE; 27];
                        for n in 0..built.len {
                            let mut t = [0; 3];
                            for (v, &local) in t.iter_mut().zip(&built.triangles[n]) {
                                *v = match local {
                                    Local::Edge(e) => edge_vertex(&mut ids, &mut out, cube, e)?,
                                    Local::Face(f) => {
                                        let slot = ids.face(cube, f);
                                        if *slot == NONE {
                                            *slot = out.vertex(cube, local.quarters())?;
                                        }
                                        *slot
                                    }
                                    Local::Centre | Local::InnerNode(_) | Local::InnerCorner(_) => {
                                        let s = match local {
                                            Local::Centre => 0,
                                            Local::InnerNode(n) => 1 + usize::from(n),
                                            Local::InnerCorner(c) => 19 + usize::from(c),
                                            _ => unreachable!(),
                                        };
                                        if own[s] == NONE {
                                            own[s] = out.vertex(cube, local.quarters())?;
                                        }
                                        own[s]
                                    }
                                };
                            }
                            let [a, b] = built.pairs[n];
                            out.triangle(t, [labels[usize::from(a)], labels[usize::from(b)]]);
                        }
                    }
                }
            }
        }
    }
    Ok(ears)
}

/// The lower end of cube edge `e` of `cube`, in the grid.
fn edge_lower(cube: [usize; 3], e: u8) -> [usize; 3] {
    let o = offset(edge_corners(e).0);
    [cube[0] + o[0], cube[1] + o[1], cube[2] + o[2]]
}

/// The vertex on cube edge `e`, made at its midpoint when first used.
fn edge_vertex<L>(
    ids: &mut Ids,
    out: &mut Out<'_, L>,
    cube: [usize; 3],
    e: u8,
) -> Result<u32, Error> {
    let slot = ids.edge(edge_lower(cube, e), edge_axis(e));
    if *slot == NONE {
        *slot = out.vertex(cube, Local::Edge(e).quarters())?;
    }
    Ok(*slot)
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
