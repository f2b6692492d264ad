//! What adaptive mode keeps of its Steps 1–3 sweeps: first the grid edge of each vertex and the
//! triangles with the cube of each, which its boxes read ([`Recorded`]); at the end, the
//! positions of the vertices its mesh uses ([`Kept`]).

use alloc::vec::Vec;

use crate::mesh::grow;
use crate::{Mesh, Sink};

/// The Steps 1–3 mesh being swept, without positions: each vertex's edge key and each
/// triangle's cube key (`x + nx · (y + ny · z)`; an edge's key is `3 ·` its lower end's key `+`
/// its axis).
pub(super) struct Recorded {
    pub triangles: Vec<[u32; 3]>,
    pub edges: Vec<u64>,
    pub cubes: Vec<u64>,
    pub dims: [usize; 3],
}

impl Recorded {
    pub fn new(dims: [usize; 3]) -> Recorded {
        Recorded {
            triangles: Vec::new(),
            edges: Vec::new(),
            cubes: Vec::new(),
            dims,
        }
    }

    /// Gives back the room the sweep's growing lists left spare: the record is held while every
    /// box is decided, the peak of adaptive mode's memory.
    pub fn settle(&mut self) {
        self.triangles.shrink_to_fit();
        self.edges.shrink_to_fit();
        self.cubes.shrink_to_fit();
    }

    pub fn point_key(&self, p: [usize; 3]) -> u64 {
        (p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])) as u64
    }
}

impl Sink for Recorded {
    fn vertex(&mut self, _: [f32; 3], _: Option<[f32; 3]>) {
        // Every vertex of the sweep comes with its edge; one without would have no key.
        self.edges.push(u64::MAX);
    }

    fn edge_vertex(&mut self, lower: [usize; 3], axis: usize, _: [f32; 3], _: Option<[f32; 3]>) {
        self.edges.push(3 * self.point_key(lower) + axis as u64);
    }

    fn triangle(&mut self, triangle: [u32; 3]) {
        self.cubes.push(u64::MAX);
        self.triangles.push(triangle);
    }

    fn expect(&mut self, vertices: usize, triangles: usize) {
        grow(&mut self.edges, vertices);
        grow(&mut self.triangles, triangles);
        grow(&mut self.cubes, triangles);
    }

    fn cube_triangle(&mut self, cube: [usize; 3], triangle: [u32; 3]) {
        self.cubes.push(self.point_key(cube));
        self.triangles.push(triangle);
    }
}

/// A Steps 1–3 sweep again, keeping the position (normal, value) of each vertex in `kept` (ids
/// in sweep order, ascending): the sweep sends its vertices in the same order every time.
pub(super) struct Kept<'a> {
    kept: &'a [usize],
    /// Vertices sent so far.
    sent: usize,
    /// Whether the last one sent is kept, for its value.
    last: bool,
    mesh: Mesh,
}

impl<'a> Kept<'a> {
    pub fn new(kept: &'a [usize]) -> Self {
        Kept {
            kept,
            sent: 0,
            last: false,
            mesh: Mesh::default(),
        }
    }

    /// The kept vertices, in the order of `kept`, and no triangle.
    pub fn finish(self) -> Mesh {
        debug_assert_eq!(self.mesh.positions.len(), self.kept.len());
        self.mesh
    }
}

impl Sink for Kept<'_> {
    fn vertex(&mut self, position: [f32; 3], normal: Option<[f32; 3]>) {
        let at = self.mesh.positions.len();
        self.last = self.kept.get(at) == Some(&self.sent);
        self.sent += 1;
        if self.last {
            if at == 0 {
                let n = self.kept.len();
                self.mesh.positions.reserve_exact(n);
                self.mesh
                    .normals
                    .reserve_exact(if normal.is_some() { n } else { 0 });
            }
            self.mesh.vertex(position, normal);
        }
    }

    fn vertex_value(&mut self, value: f32) {
        if self.last {
            self.mesh.vertex_value(value);
        }
    }

    fn triangle(&mut self, _: [u32; 3]) {}
}
