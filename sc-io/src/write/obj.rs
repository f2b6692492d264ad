//! Wavefront OBJ: text, 1-based indices, normals shared by index with positions.

use std::io::{self, Write};

use super::options::WriteOptions;
use super::slices::MeshSlices;
use super::text::Lines;

/// Writes `v`, `vn` (if the mesh has normals) and `f` lines.
pub fn write<'a>(
    mesh: impl Into<MeshSlices<'a>>,
    options: &WriteOptions,
    out: &mut impl Write,
) -> io::Result<()> {
    let mesh = mesh.into();
    writeln!(
        out,
        "# skelclimb (Skeleton Climbing): {} vertices, {} triangles\n# coordinates: {}",
        mesh.positions.len(),
        mesh.triangles.len(),
        options.coordinates()
    )?;
    let mut lines = Lines::new(out);
    for (tag, vectors) in [("v ", mesh.positions), ("vn ", mesh.normals)] {
        for &[x, y, z] in vectors {
            lines
                .text(tag)
                .float(x)
                .text(" ")
                .float(y)
                .text(" ")
                .float(z)
                .end()?;
        }
    }
    let with_normals = !mesh.normals.is_empty();
    for t in mesh.triangles {
        lines.text("f");
        for i in t.map(|i| u64::from(i) + 1) {
            lines.text(" ").int(i);
            if with_normals {
                lines.text("//").int(i);
            }
        }
        lines.end()?;
    }
    lines.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::write::test_mesh::tetrahedron;

    fn read_back(bytes: &[u8]) -> tobj::Mesh {
        let options = tobj::LoadOptions {
            single_index: true,
            ..Default::default()
        };
        let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &options, |_| {
            Err(tobj::LoadError::GenericFailure)
        })
        .unwrap();
        assert_eq!(models.len(), 1);
        models.into_iter().next().unwrap().mesh
    }

    #[test]
    fn round_trips_through_tobj() {
        let mesh = tetrahedron();
        let mut bytes = Vec::new();
        write(&mesh, &WriteOptions::default(), &mut bytes).unwrap();
        let back = read_back(&bytes);
        // tobj renumbers vertices in order of first use: compare what each corner points at.
        assert_eq!(back.positions.len(), 3 * mesh.positions.len());
        assert_eq!(back.indices.len(), 3 * mesh.triangles.len());
        let at = |v: &[f32], i: u32| [0, 1, 2].map(|a| v[3 * i as usize + a]);
        for (&i, &j) in back.indices.iter().zip(mesh.triangles.iter().flatten()) {
            assert_eq!(at(&back.positions, i), mesh.positions[j as usize]);
            assert_eq!(at(&back.normals, i), mesh.normals[j as usize]);
        }
    }

    #[test]
    fn without_normals() {
        let mut mesh = tetrahedron();
        mesh.normals.clear();
        let mut bytes = Vec::new();
        write(&mesh, &WriteOptions::default(), &mut bytes).unwrap();
        let back = read_back(&bytes);
        assert!(back.normals.is_empty());
        assert_eq!(back.indices.len(), 12);
    }
}
