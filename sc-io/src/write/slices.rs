//! The borrowed view of a mesh that every writer reads.

use sc_runtime::Mesh;

/// A mesh's arrays, borrowed: all the writers read. A [`Mesh`] lends its own; a front end that
/// holds the arrays elsewhere (NumPy's, in Python) lends those, so that writing copies nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeshSlices<'a> {
    /// Vertex positions.
    pub positions: &'a [[f32; 3]],
    /// Unit normals, one per position, or empty.
    pub normals: &'a [[f32; 3]],
    /// Triangles as indices into `positions`, each below `positions.len()`.
    pub triangles: &'a [[u32; 3]],
}

impl<'a> From<&'a Mesh> for MeshSlices<'a> {
    fn from(mesh: &'a Mesh) -> Self {
        MeshSlices {
            positions: &mesh.positions,
            normals: &mesh.normals,
            triangles: &mesh.triangles,
        }
    }
}
