//! What a writer records besides the mesh.

use crate::space::Space;

/// How to write, and what to record in the file besides the mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    /// Text PLY instead of binary (the other formats have one encoding here).
    pub ascii: bool,
    /// The world convention of the vertices (millimetres), or `None` for index coordinates.
    pub space: Option<Space>,
}

impl WriteOptions {
    /// The coordinate system in words, for file comments.
    pub fn coordinates(&self) -> String {
        match self.space {
            Some(space) => format!("{} world coordinates, millimetres", space.name()),
            None => "index × spacing + origin".into(),
        }
    }
}
