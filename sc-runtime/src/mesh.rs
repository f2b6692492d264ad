use alloc::vec::Vec;

use crate::{Error, Params, Scalar, Stats, Volume};

/// An indexed triangle mesh: one vertex per surviving occupied grid edge, none unreferenced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions in world units.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals, one per position, or empty when normals were not asked for.
    pub normals: Vec<[f32; 3]>,
    /// Triangles wound so that `(b - a) × (c - a)` points from filled to empty.
    pub triangles: Vec<[u32; 3]>,
    /// Counts before and after merging.
    pub stats: Stats,
}

/// Extracts the surface on one thread.
pub fn extract<T: Scalar>(volume: &Volume<'_, T>, params: &Params) -> Result<Mesh, Error> {
    let _ = (volume, params);
    todo!("runtime in progress")
}
