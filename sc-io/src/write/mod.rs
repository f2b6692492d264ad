//! Mesh writers, chosen by the output file's extension. Each writes to any `Write`; the caller
//! puts a temporary file behind it (see [`crate::atomic`]). The meshes of a label volume go to
//! a directory, a file per label ([`LabelFiles`]), or to one `.glb` atlas ([`write_atlas`]).

mod binary;
mod glb;
mod labels;
mod obj;
mod options;
mod ply;
mod slices;
mod stl;
mod text;

use std::io::{self, Write};
use std::path::Path;

pub use glb::write_atlas;
pub use labels::{LabelFiles, LabelMesh};
pub use options::WriteOptions;
pub use slices::MeshSlices;

/// The mesh formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Stanford PLY.
    Ply,
    /// Wavefront OBJ.
    Obj,
    /// Binary STL.
    Stl,
    /// Binary glTF 2.0.
    Glb,
}

impl MeshFormat {
    /// The format for `path`'s extension, or an error message listing the ones known.
    pub fn from_path(path: &Path) -> Result<MeshFormat, String> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("ply") => Ok(MeshFormat::Ply),
            Some("obj") => Ok(MeshFormat::Obj),
            Some("stl") => Ok(MeshFormat::Stl),
            Some("glb") => Ok(MeshFormat::Glb),
            _ => Err(format!(
                "cannot tell the mesh format of {}: use the extension .ply, .obj, .stl or .glb",
                path.display()
            )),
        }
    }

    /// Writes `mesh` (a [`Mesh`](sc_runtime::Mesh) or [`MeshSlices`]), recording its coordinate system where the
    /// format has room for it.
    pub fn write<'a>(
        self,
        mesh: impl Into<MeshSlices<'a>>,
        options: &WriteOptions,
        out: &mut impl Write,
    ) -> io::Result<()> {
        let mesh = mesh.into();
        match self {
            MeshFormat::Ply if options.ascii => ply::write_ascii(mesh, options, out),
            MeshFormat::Ply => ply::write_binary(mesh, options, out),
            MeshFormat::Obj => obj::write(mesh, options, out),
            MeshFormat::Stl => stl::write(mesh, out),
            MeshFormat::Glb => glb::write(mesh, options, out),
        }
    }
}

#[cfg(test)]
pub(crate) mod test_mesh {
    use sc_runtime::{Mesh, Stats};

    /// A unit-ish tetrahedron, wound outward, with normals; positions are not round numbers so
    /// that round trips test full f32 precision.
    pub fn tetrahedron() -> Mesh {
        let positions = vec![
            [0.1, 0.2, 0.3],
            [1.123_456_7, 0.2, 0.3],
            [0.1, 1.987_654_3, 0.3],
            [0.1, 0.2, -1.000_001],
        ];
        let normals = vec![
            [-0.577_350_3, -0.577_350_3, 0.577_350_3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
        ];
        let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let stats = Stats {
            vertices: 4,
            triangles: 4,
            ..Stats::default()
        };
        Mesh {
            positions,
            normals,
            triangles,
            stats,
            ..Mesh::default()
        }
    }
}
