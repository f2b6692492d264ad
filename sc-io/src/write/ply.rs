//! Stanford PLY, binary little-endian (compact, what most viewers load fastest) or ASCII.

use std::io::{self, Write};

use super::binary::{in_chunks, le_words};
use super::options::WriteOptions;
use super::slices::MeshSlices;
use super::text::Lines;

fn header(
    mesh: MeshSlices<'_>,
    format: &str,
    options: &WriteOptions,
    out: &mut impl Write,
) -> io::Result<()> {
    writeln!(
        out,
        "ply\nformat {format} 1.0\ncomment skelclimb (Skeleton Climbing)\ncomment coordinates: {}",
        options.coordinates()
    )?;
    writeln!(out, "element vertex {}", mesh.positions.len())?;
    writeln!(out, "property float x\nproperty float y\nproperty float z")?;
    if !mesh.normals.is_empty() {
        writeln!(
            out,
            "property float nx\nproperty float ny\nproperty float nz"
        )?;
    }
    writeln!(out, "element face {}", mesh.triangles.len())?;
    writeln!(out, "property list uchar uint vertex_indices\nend_header")
}

/// Binary little-endian PLY. Records are encoded into a buffer a few thousand at a time and
/// written in one call each: writing them field by field through the `BufWriter` cost as much as
/// a quarter of the whole extraction.
pub fn write_binary<'a>(
    mesh: impl Into<MeshSlices<'a>>,
    options: &WriteOptions,
    out: &mut impl Write,
) -> io::Result<()> {
    let mesh = mesh.into();
    header(mesh, "binary_little_endian", options, out)?;
    let with_normals = !mesh.normals.is_empty();
    if !with_normals {
        // Positions alone are the file's records.
        le_words(mesh.positions, out, f32::to_le_bytes)?;
    } else {
        let vertex_bytes = if with_normals { 24 } else { 12 };
        in_chunks(mesh.positions.len(), vertex_bytes, out, |i, rec| {
            put_floats(&mut rec[..12], &mesh.positions[i]);
            if with_normals {
                put_floats(&mut rec[12..], &mesh.normals[i]);
            }
        })?;
    }
    in_chunks(mesh.triangles.len(), 13, out, |i, rec| {
        rec[0] = 3;
        for (field, v) in rec[1..].chunks_exact_mut(4).zip(mesh.triangles[i]) {
            field.copy_from_slice(&v.to_le_bytes());
        }
    })
}

fn put_floats(rec: &mut [u8], values: &[f32; 3]) {
    for (field, v) in rec.chunks_exact_mut(4).zip(values) {
        field.copy_from_slice(&v.to_le_bytes());
    }
}

/// ASCII PLY; floats are printed in their shortest exact form, so nothing is lost.
pub fn write_ascii<'a>(
    mesh: impl Into<MeshSlices<'a>>,
    options: &WriteOptions,
    out: &mut impl Write,
) -> io::Result<()> {
    let mesh = mesh.into();
    header(mesh, "ascii", options, out)?;
    let mut lines = Lines::new(out);
    for (i, [x, y, z]) in mesh.positions.iter().enumerate() {
        lines.float(*x).text(" ").float(*y).text(" ").float(*z);
        if let Some([a, b, c]) = mesh.normals.get(i) {
            lines
                .text(" ")
                .float(*a)
                .text(" ")
                .float(*b)
                .text(" ")
                .float(*c);
        }
        lines.end()?;
    }
    for [a, b, c] in mesh.triangles {
        lines
            .text("3 ")
            .int(u64::from(*a))
            .text(" ")
            .int(u64::from(*b));
        lines.text(" ").int(u64::from(*c)).end()?;
    }
    lines.finish()
}

#[cfg(test)]
mod tests {
    use ply_rs::parser::Parser;
    use ply_rs::ply::{DefaultElement, Property};

    use sc_runtime::Mesh;

    use super::*;
    use crate::write::test_mesh::tetrahedron;

    fn float(e: &DefaultElement, key: &str) -> f32 {
        match e.get(key) {
            Some(Property::Float(v)) => *v,
            other => panic!("{key}: {other:?}"),
        }
    }

    fn read_back(bytes: &[u8]) -> Mesh {
        let ply = Parser::<DefaultElement>::new()
            .read_ply(&mut &bytes[..])
            .unwrap();
        let vertices = &ply.payload["vertex"];
        let mut mesh = Mesh::default();
        for v in vertices {
            mesh.positions.push(["x", "y", "z"].map(|k| float(v, k)));
            if v.contains_key("nx") {
                mesh.normals.push(["nx", "ny", "nz"].map(|k| float(v, k)));
            }
        }
        for f in &ply.payload["face"] {
            match f.get("vertex_indices") {
                Some(Property::ListUInt(i)) => mesh.triangles.push([i[0], i[1], i[2]]),
                other => panic!("face: {other:?}"),
            }
        }
        mesh
    }

    /// With normals (records encoded field by field) and without (positions written as they
    /// lie in memory).
    #[test]
    fn binary_round_trips() {
        for normals in [true, false] {
            let mut mesh = tetrahedron();
            if !normals {
                mesh.normals.clear();
            }
            let mut bytes = Vec::new();
            write_binary(&mesh, &WriteOptions::default(), &mut bytes).unwrap();
            let back = read_back(&bytes);
            assert_eq!(
                (back.positions, back.normals, back.triangles),
                (mesh.positions, mesh.normals, mesh.triangles)
            );
        }
    }

    #[test]
    fn ascii_round_trips_without_normals() {
        let mut mesh = tetrahedron();
        mesh.normals.clear();
        let mut bytes = Vec::new();
        write_ascii(&mesh, &WriteOptions::default(), &mut bytes).unwrap();
        let back = read_back(&bytes);
        assert!(back.normals.is_empty());
        assert_eq!(
            (back.positions, back.triangles),
            (mesh.positions, mesh.triangles)
        );
    }

    #[test]
    fn empty_mesh_is_a_valid_file() {
        let mut bytes = Vec::new();
        write_binary(&Mesh::default(), &WriteOptions::default(), &mut bytes).unwrap();
        let back = read_back(&bytes);
        assert!(back.positions.is_empty() && back.triangles.is_empty());
    }
}
