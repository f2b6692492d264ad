//! The Steps 1–3 mesh of a volume, with the grid edge of each vertex and the cube of each
//! triangle: what adaptive mode keeps of it, and what its boxes read.

use alloc::vec::Vec;

use crate::mesh::grow;
use crate::{Mesh, Sink};

/// Marks, in [`Recorded::cubes`], a triangle of a pair Step 4 merged: what adaptive mode keeps
/// of embedded mode's sweep.
pub const MERGED: u64 = 1 << 63;

/// A mesh being swept, and each vertex's edge key and each triangle's cube key
/// (`x + nx · (y + ny · z)`; an edge's key is `3 ·` its lower end's key `+` its axis).
pub(super) struct Recorded {
    pub mesh: Mesh,
    pub edges: Vec<u64>,
    pub cubes: Vec<u64>,
    pub dims: [usize; 3],
    /// Whether positions (and normals) are kept: embedded mode's sweep, read for its merges
    /// only, needs the edges and triangles alone.
    positions: bool,
}

impl Recorded {
    pub fn new(dims: [usize; 3]) -> Recorded {
        Recorded {
            mesh: Mesh::default(),
            edges: Vec::new(),
            cubes: Vec::new(),
            dims,
            positions: true,
        }
    }

    /// A record of the edges and triangles only.
    pub fn without_positions(dims: [usize; 3]) -> Recorded {
        Recorded {
            positions: false,
            ..Recorded::new(dims)
        }
    }

    /// Gives back the room the sweep's growing lists left spare: the records are held while
    /// every box is decided, the peak of adaptive mode's memory.
    pub fn settle(&mut self) {
        self.mesh.positions.shrink_to_fit();
        self.mesh.normals.shrink_to_fit();
        self.mesh.triangles.shrink_to_fit();
        self.edges.shrink_to_fit();
        self.cubes.shrink_to_fit();
    }

    pub fn point_key(&self, p: [usize; 3]) -> u64 {
        (p[0] + self.dims[0] * (p[1] + self.dims[1] * p[2])) as u64
    }
}

impl Sink for Recorded {
    fn vertex(&mut self, position: [f32; 3], normal: Option<[f32; 3]>) {
        // Every vertex of the sweep comes with its edge; one without would have no key.
        self.edges.push(u64::MAX);
        if self.positions {
            self.mesh.vertex(position, normal);
        }
    }

    fn edge_vertex(
        &mut self,
        lower: [usize; 3],
        axis: usize,
        position: [f32; 3],
        normal: Option<[f32; 3]>,
    ) {
        self.edges.push(3 * self.point_key(lower) + axis as u64);
        if self.positions {
            self.mesh.vertex(position, normal);
        }
    }

    fn vertex_value(&mut self, value: f32) {
        self.mesh.vertex_value(value);
    }

    fn triangle(&mut self, triangle: [u32; 3]) {
        self.cubes.push(u64::MAX);
        self.mesh.triangle(triangle);
    }

    fn expect(&mut self, vertices: usize, triangles: usize) {
        self.mesh
            .expect(if self.positions { vertices } else { 0 }, triangles);
        grow(&mut self.edges, vertices);
        grow(&mut self.cubes, triangles);
    }

    fn cube_triangle(&mut self, cube: [usize; 3], triangle: [u32; 3]) {
        self.cubes.push(self.point_key(cube));
        self.mesh.triangle(triangle);
    }

    /// Only merged pairs come this way (the sweep's other triangles come by
    /// [`Sink::cube_triangle`]), so they are marked [`MERGED`].
    fn cube_triangle_if(&mut self, cube: [usize; 3], triangle: [u32; 3], keep: bool) {
        if keep {
            self.cubes.push(self.point_key(cube) | MERGED);
            self.mesh.triangle(triangle);
        }
    }
}
