//! Stanford PLY, binary little-endian (compact, what most viewers load fastest) or ASCII.

use std::io::{self, Write};

use sc_runtime::Mesh;

fn header(mesh: &Mesh, format: &str, out: &mut impl Write) -> io::Result<()> {
    writeln!(
        out,
        "ply\nformat {format} 1.0\ncomment skelclimb (Skeleton Climbing)"
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

/// Binary little-endian PLY.
pub fn write_binary(mesh: &Mesh, out: &mut impl Write) -> io::Result<()> {
    header(mesh, "binary_little_endian", out)?;
    for (i, p) in mesh.positions.iter().enumerate() {
        let n = mesh.normals.get(i);
        for c in p.iter().chain(n.into_iter().flatten()) {
            out.write_all(&c.to_le_bytes())?;
        }
    }
    for t in &mesh.triangles {
        out.write_all(&[3])?;
        for i in t {
            out.write_all(&i.to_le_bytes())?;
        }
    }
    Ok(())
}

/// ASCII PLY; floats are printed in their shortest exact form, so nothing is lost.
pub fn write_ascii(mesh: &Mesh, out: &mut impl Write) -> io::Result<()> {
    header(mesh, "ascii", out)?;
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

    #[test]
    fn binary_round_trips() {
        let mesh = tetrahedron();
        let mut bytes = Vec::new();
        write_binary(&mesh, &mut bytes).unwrap();
        let back = read_back(&bytes);
        assert_eq!(
            (back.positions, back.normals, back.triangles),
            (mesh.positions, mesh.normals, mesh.triangles)
        );
    }

    #[test]
    fn ascii_round_trips_without_normals() {
        let mut mesh = tetrahedron();
        mesh.normals.clear();
        let mut bytes = Vec::new();
        write_ascii(&mesh, &mut bytes).unwrap();
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
        write_binary(&Mesh::default(), &mut bytes).unwrap();
        let back = read_back(&bytes);
        assert!(back.positions.is_empty() && back.triangles.is_empty());
    }
}
