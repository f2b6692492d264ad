//! Binary STL: one record per triangle with its face normal, as 3-D printing tools expect.

use std::io::{self, Write};

use super::binary::in_chunks;
use super::slices::MeshSlices;

/// Writes the 80-byte header, the triangle count and one 50-byte record per triangle.
pub fn write<'a>(mesh: impl Into<MeshSlices<'a>>, out: &mut impl Write) -> io::Result<()> {
    let mesh = mesh.into();
    let mut header = [b' '; 80];
    let title = b"skelclimb (Skeleton Climbing) binary STL";
    header[..title.len()].copy_from_slice(title);
    out.write_all(&header)?;
    let count = u32::try_from(mesh.triangles.len())
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "too many triangles for STL"))?;
    out.write_all(&count.to_le_bytes())?;
    in_chunks(mesh.triangles.len(), 50, out, |i, rec| {
        let [a, b, c] = mesh.triangles[i].map(|v| mesh.positions[v as usize]);
        let values = face_normal(a, b, c).into_iter().chain(a).chain(b).chain(c);
        for (field, v) in rec.chunks_exact_mut(4).zip(values) {
            field.copy_from_slice(&v.to_le_bytes());
        }
        // The attribute byte count, which no reader uses.
        rec[48..].fill(0);
    })
}

/// The unit normal of triangle `abc` by the right-hand rule, or zero for a degenerate one (STL
/// readers then compute their own).
fn face_normal(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [f32; 3] {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let len = n.iter().map(|x| x * x).sum::<f32>().sqrt();
    if len > 0.0 {
        n.map(|x| x / len)
    } else {
        [0.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::write::test_mesh::tetrahedron;

    #[test]
    fn round_trips_through_stl_io() {
        let mesh = tetrahedron();
        let mut bytes = Vec::new();
        write(&mesh, &mut bytes).unwrap();
        assert_eq!(bytes.len(), 84 + 50 * mesh.triangles.len());
        let back = stl_io::read_stl(&mut std::io::Cursor::new(bytes)).unwrap();
        assert_eq!(back.faces.len(), mesh.triangles.len());
        for (face, t) in back.faces.iter().zip(&mesh.triangles) {
            for (k, &i) in face.vertices.iter().enumerate() {
                let v = back.vertices[i];
                assert_eq!([v[0], v[1], v[2]], mesh.positions[t[k] as usize]);
            }
            let expected = t.map(|i| mesh.positions[i as usize]);
            let n = face_normal(expected[0], expected[1], expected[2]);
            assert_eq!([face.normal[0], face.normal[1], face.normal[2]], n);
        }
    }

    #[test]
    fn outward_normal_of_a_ccw_triangle() {
        assert_eq!(
            face_normal([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            [0.0, 0.0, 1.0]
        );
        assert_eq!(
            face_normal([0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]),
            [0.0; 3]
        );
    }
}
