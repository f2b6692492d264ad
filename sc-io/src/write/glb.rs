//! Binary glTF 2.0 (`.glb`): one file that browsers and three.js viewers open directly.
//!
//! Layout: one buffer holding positions, normals (if any) and `u32` indices, one accessor each.
//! The position accessor carries `min`/`max`, which glTF requires and viewers use to frame the
//! model. An empty mesh becomes a scene with no nodes, since glTF forbids zero-count accessors.

use std::io::{self, Write};

use super::binary::le_words;
use super::options::WriteOptions;
use super::slices::MeshSlices;
use crate::space::Space;
use serde_json::{Value, json};

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const TRIANGLES: u32 = 4;

/// Writes the GLB header, the JSON chunk and the binary chunk.
pub fn write<'a>(
    mesh: impl Into<MeshSlices<'a>>,
    options: &WriteOptions,
    out: &mut impl Write,
) -> io::Result<()> {
    let mesh = mesh.into();
    let too_big = || {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "the mesh is too large for one GLB file",
        )
    };
    let (json, bin_len) = document(mesh, options);
    let mut json = serde_json::to_vec(&json).map_err(io::Error::other)?;
    json.resize(json.len().next_multiple_of(4), b' ');
    let total = 12 + 8 + json.len() + if bin_len > 0 { 8 + bin_len } else { 0 };
    let total = u32::try_from(total).map_err(|_| too_big())?;

    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    out.write_all(&(json.len() as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(&json)?;
    if bin_len > 0 {
        out.write_all(&(bin_len as u32).to_le_bytes())?;
        out.write_all(b"BIN\0")?;
        le_words(mesh.positions, out, f32::to_le_bytes)?;
        le_words(mesh.normals, out, f32::to_le_bytes)?;
        le_words(mesh.triangles, out, u32::to_le_bytes)?;
    }
    Ok(())
}

/// The JSON document and the binary chunk's length (a multiple of 4, as every part is).
fn document(mesh: MeshSlices<'_>, options: &WriteOptions) -> (Value, usize) {
    let asset = json!({
        "version": "2.0",
        "generator": "skelclimb (Skeleton Climbing)",
        "extras": { "coordinates": options.coordinates() },
    });
    if mesh.triangles.is_empty() {
        return (
            json!({ "asset": asset, "scene": 0, "scenes": [{ "nodes": [] }] }),
            0,
        );
    }
    let vertices = mesh.positions.len();
    let vec3_bytes = 12 * vertices;
    let index_bytes = 12 * mesh.triangles.len();
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in mesh.positions {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let view = |offset: usize, length: usize, target: u32| json!({ "buffer": 0, "byteOffset": offset, "byteLength": length, "target": target });
    let mut views = vec![view(0, vec3_bytes, ARRAY_BUFFER)];
    let mut accessors = vec![json!({
        "bufferView": 0, "componentType": FLOAT, "count": vertices, "type": "VEC3",
        "min": lo, "max": hi,
    })];
    let mut attributes = json!({ "POSITION": 0 });
    if !mesh.normals.is_empty() {
        views.push(view(vec3_bytes, vec3_bytes, ARRAY_BUFFER));
        accessors.push(
            json!({ "bufferView": 1, "componentType": FLOAT, "count": vertices, "type": "VEC3" }),
        );
        attributes["NORMAL"] = json!(1);
    }
    let index_offset = vec3_bytes * views.len();
    views.push(view(index_offset, index_bytes, ELEMENT_ARRAY_BUFFER));
    accessors.push(json!({
        "bufferView": views.len() - 1, "componentType": UNSIGNED_INT,
        "count": 3 * mesh.triangles.len(), "type": "SCALAR",
    }));
    let bin_len = index_offset + index_bytes;
    let doc = json!({
        "asset": asset,
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [node(options)],
        "meshes": [{ "primitives": [{
            "attributes": attributes, "indices": accessors.len() - 1, "mode": TRIANGLES,
        }] }],
        "buffers": [{ "byteLength": bin_len }],
        "bufferViews": views,
        "accessors": accessors,
    });
    (doc, bin_len)
}

/// The mesh's node. glTF is in metres with +Y up and viewers look down −Z; scanner coordinates
/// are millimetres with +Z superior. For those, the node scales by 1/1000 and turns the patient
/// upright, facing the viewer (anterior towards +Z), leaving the vertex data exact.
fn node(options: &WriteOptions) -> Value {
    // Column-major 4×4 matrices: glTF (x, y, z) = (−x, z, y) from RAS, (x, z, −y) from LPS.
    let matrix: Option<[f64; 16]> = match options.space {
        Some(Space::Ras) => Some([
            -0.001, 0.0, 0.0, 0.0, 0.0, 0.0, 0.001, 0.0, 0.0, 0.001, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ]),
        Some(Space::Lps) => Some([
            0.001, 0.0, 0.0, 0.0, 0.0, 0.0, -0.001, 0.0, 0.0, 0.001, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ]),
        None => None,
    };
    match matrix {
        Some(m) => json!({ "mesh": 0, "name": "isosurface", "matrix": m }),
        None => json!({ "mesh": 0, "name": "isosurface" }),
    }
}

#[cfg(test)]
mod tests {
    use sc_runtime::Mesh;

    use super::*;
    use crate::write::test_mesh::tetrahedron;

    fn glb(mesh: &Mesh) -> Vec<u8> {
        let mut bytes = Vec::new();
        write(mesh, &WriteOptions::default(), &mut bytes).unwrap();
        assert_eq!(bytes.len() % 4, 0);
        assert_eq!(
            u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
            bytes.len()
        );
        bytes
    }

    #[test]
    fn round_trips_through_the_gltf_crate() {
        let mesh = tetrahedron();
        let bytes = glb(&mesh);
        let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
        let blob = gltf.blob.clone().unwrap();
        let primitive = gltf.meshes().next().unwrap().primitives().next().unwrap();
        let reader = primitive.reader(|_| Some(&blob));
        assert_eq!(
            reader.read_positions().unwrap().collect::<Vec<_>>(),
            mesh.positions
        );
        assert_eq!(
            reader.read_normals().unwrap().collect::<Vec<_>>(),
            mesh.normals
        );
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(
            indices,
            mesh.triangles.iter().flatten().copied().collect::<Vec<_>>()
        );
        let bounds = primitive.bounding_box();
        assert_eq!(
            (bounds.min, bounds.max),
            ([0.1, 0.2, -1.000_001], [1.123_456_7, 1.987_654_3, 0.3])
        );
    }

    #[test]
    fn without_normals_and_empty() {
        let mut mesh = tetrahedron();
        mesh.normals.clear();
        let gltf = gltf::Gltf::from_slice(&glb(&mesh)).unwrap();
        let primitive = gltf.meshes().next().unwrap().primitives().next().unwrap();
        assert!(primitive.get(&gltf::Semantic::Normals).is_none());

        let empty = gltf::Gltf::from_slice(&glb(&Mesh::default())).unwrap();
        assert_eq!(empty.meshes().count(), 0);
        assert!(empty.blob.is_none());
    }
}
