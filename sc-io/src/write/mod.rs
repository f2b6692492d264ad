//! Mesh writers, chosen by the output file's extension. Each writes to any `Write`; the caller
//! puts a temporary file behind it (see [`crate::atomic`]).

mod glb;
mod obj;
mod ply;
mod stl;
mod text;

use std::io::{self, Write};
use std::path::Path;

use sc_runtime::Mesh;

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

    /// Writes `mesh`, recording its coordinate system where the format has room for it.
    pub fn write(
        self,
        mesh: &Mesh,
        options: &WriteOptions,
        out: &mut impl Write,
    ) -> io::Result<()> {
        match self {
            MeshFormat::Ply if options.ascii => ply::write_ascii(mesh, options, out),
            MeshFormat::Ply => ply::write_binary(mesh, options, out),
            MeshFormat::Obj => obj::write(mesh, options, out),
            MeshFormat::Stl => stl::write(mesh, out),
            MeshFormat::Glb => glb::write(mesh, options, out),
        }
    }
}

/// Encodes records `0..count` of `record` bytes each with `encode` and writes them in batches:
/// writing each field with a call of its own cost as much as a quarter of the whole extraction
/// through a `BufWriter`, and far more through a writer that counts progress.
pub(crate) fn in_chunks(
    count: usize,
    record: usize,
    out: &mut impl Write,
    encode: impl Fn(usize, &mut [u8]),
) -> io::Result<()> {
    // At least 64 KiB per batch, so that batches bypass the output's `BufWriter`.
    const BATCH: usize = 8192;
    let mut buf = vec![0u8; BATCH.min(count) * record];
    for start in (0..count).step_by(BATCH) {
        let n = BATCH.min(count - start);
        for (k, rec) in buf[..n * record].chunks_exact_mut(record).enumerate() {
            encode(start + k, rec);
        }
        out.write_all(&buf[..n * record])?;
    }
    Ok(())
}

/// Writes `values` as consecutive little-endian numbers: as they lie in memory on little-endian
/// machines, encoded in batches elsewhere.
pub(crate) fn le_words<T: bytemuck::Pod, const N: usize>(
    values: &[[T; N]],
    out: &mut impl Write,
    to_le: impl Fn(T) -> [u8; 4],
) -> io::Result<()> {
    if cfg!(target_endian = "little") {
        out.write_all(bytemuck::cast_slice(values))
    } else {
        le_encoded(values, out, to_le)
    }
}

/// [`le_words`] on a big-endian machine: each number encoded.
fn le_encoded<T: Copy, const N: usize>(
    values: &[[T; N]],
    out: &mut impl Write,
    to_le: impl Fn(T) -> [u8; 4],
) -> io::Result<()> {
    in_chunks(values.len(), 4 * N, out, |i, rec| {
        for (field, &v) in rec.chunks_exact_mut(4).zip(&values[i]) {
            field.copy_from_slice(&to_le(v));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both ways of writing numbers give the file's bytes, across several batches and a partial
    /// one: the encoded way is what big-endian machines run, and is checked here against the
    /// little-endian bytes it must reproduce.
    #[test]
    fn numbers_encoded_and_cast_agree() {
        let values: Vec<[u32; 3]> = (0..20_000u32)
            .map(|i| [i, i.wrapping_mul(2_654_435_761), u32::MAX - i])
            .collect();
        let want: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let mut encoded = Vec::new();
        le_encoded(&values, &mut encoded, u32::to_le_bytes).unwrap();
        assert!(encoded == want);
        let mut written = Vec::new();
        le_words(&values, &mut written, u32::to_le_bytes).unwrap();
        assert!(written == want);
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
