//! Stanford PLY, binary little-endian (compact, what most viewers load fastest) or ASCII.

use std::io::{self, Write};

use sc_runtime::Mesh;

use super::WriteOptions;

fn header(
    mesh: &Mesh,
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
pub fn write_binary(mesh: &Mesh, options: &WriteOptions, out: &mut impl Write) -> io::Result<()> {
    header(mesh, "binary_little_endian", options, out)?;
    let with_normals = !mesh.normals.is_empty();
    if !with_normals && cfg!(target_endian = "little") {
        // Positions alone are already the file's records, byte for byte.
        out.write_all(bytemuck::cast_slice(&mesh.positions))?;
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

/// Encodes records `0..count` of `record` bytes each with `encode` and writes them in batches.
fn in_chunks(
    count: usize,
    record: usize,
    out: &mut impl Write,
    encode: impl Fn(usize, &mut [u8]),
) -> io::Result<()> {
    // At least 64 KiB per batch, so that batches bypass the output's `BufWriter`.
    const BATCH: usize = 8192;
    let mut buf = vec![0u8; BATCH * record];
    for start in (0..count).step_by(BATCH) {
        let n = BATCH.min(count - start);
        for (k, rec) in buf[..n * record].chunks_exact_mut(record).enumerate() {
            encode(start + k, rec);
        }
        out.write_all(&buf[..n * record])?;
    }
    Ok(())
}

/// ASCII PLY; floats are printed in their shortest exact form, so nothing is lost.
pub fn write_ascii(mesh: &Mesh, options: &WriteOptions, out: &mut impl Write) -> io::Result<()> {
    header(mesh, "ascii", options, out)?;
    for (i, [x, y, z]) in mesh.positions.iter().enumerate() {
        match mesh.normals.get(i) {
            Some([a, b, c]) => writeln!(out, "{x} {y} {z} {a} {b} {c}")?,
            None => writeln!(out, "{x} {y} {z}")?,
        }
    }
    for [a, b, c] in &mesh.triangles {
        writeln!(out, "3 {a} {b} {c}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use ply_rs::parser::Parser;
    use ply_rs::ply::{DefaultElement, Property};

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
