//! Binary glTF 2.0 (`.glb`): one file that browsers and three.js viewers open directly.
//!
//! Layout: one buffer holding positions, normals (if any) and `u32` indices, one accessor each.
//! The position accessor carries `min`/`max`, which glTF requires and viewers use to frame the
//! model. An empty mesh becomes a scene with no nodes, since glTF forbids zero-count accessors.
//!
//! An atlas (a mesh per label) is one node per label, each with its mesh and a coloured
//! material; meshes that lend the same vertex arrays share their accessors.

use std::io::{self, Write};

use super::binary::le_words;
use super::labels::LabelMesh;
use super::options::WriteOptions;
use super::slices::MeshSlices;
use crate::labels;
use crate::space::Space;
use serde_json::{Value, json};

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const TRIANGLES: u32 = 4;

/// Writes one mesh: the GLB header, the JSON chunk and the binary chunk.
pub fn write<'a>(
    mesh: impl Into<MeshSlices<'a>>,
    options: &WriteOptions,
    out: &mut impl Write,
) -> io::Result<()> {
    let mesh = mesh.into();
    let mut bin = Binary::default();
    let doc = if mesh.triangles.is_empty() {
        json!({ "asset": asset(options), "scene": 0, "scenes": [{ "nodes": [] }] })
    } else {
        let primitive = bin.primitive(mesh);
        json!({
            "asset": asset(options),
            "scene": 0,
            "scenes": [{ "nodes": [0] }],
            "nodes": [node(Some(0), "isosurface", options)],
            "meshes": [{ "primitives": [primitive] }],
            "buffers": [{ "byteLength": bin.len }],
            "bufferViews": bin.views,
            "accessors": bin.accessors,
        })
    };
    container(&doc, &bin.parts, out)
}

/// Writes an atlas: a node per label, named after it (`label-<id>` if unnamed), with the label
/// id in the node's `extras`, its mesh, and a material of its colour (from the table, else
/// [`labels::default_rgb`]). A label without triangles keeps its node, without a mesh.
pub fn write_atlas(
    meshes: &[LabelMesh<'_>],
    options: &WriteOptions,
    out: &mut impl Write,
) -> io::Result<()> {
    let mut bin = Binary::default();
    let mut nodes = Vec::with_capacity(meshes.len());
    let mut gltf_meshes = Vec::new();
    let mut materials = Vec::new();
    for m in meshes {
        let name = match m.label {
            Some(label) if !label.name.is_empty() => label.name.clone(),
            _ => format!("label-{}", m.id),
        };
        let mesh_index = (!m.mesh.triangles.is_empty()).then(|| {
            let mut primitive = bin.primitive(m.mesh);
            primitive["material"] = json!(materials.len());
            let rgb = m.label.and_then(|l| l.rgb).unwrap_or(labels::default_rgb(m.id));
            let [r, g, b] = rgb.map(srgb_to_linear);
            materials.push(json!({
                "name": name,
                "pbrMetallicRoughness": {
                    "baseColorFactor": [r, g, b, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.7,
                },
            }));
            gltf_meshes.push(json!({ "name": name, "primitives": [primitive] }));
            gltf_meshes.len() - 1
        });
        let mut node = node(mesh_index, &name, options);
        node["extras"] = json!({ "label": m.id });
        nodes.push(node);
    }
    let mut doc = json!({
        "asset": asset(options),
        "scene": 0,
        "scenes": [{ "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
    });
    if !gltf_meshes.is_empty() {
        doc["meshes"] = json!(gltf_meshes);
        doc["materials"] = json!(materials);
        doc["buffers"] = json!([{ "byteLength": bin.len }]);
        doc["bufferViews"] = json!(bin.views);
        doc["accessors"] = json!(bin.accessors);
    }
    container(&doc, &bin.parts, out)
}

/// A palette colour (sRGB, 0 to 255) as glTF's linear colour factor.
fn srgb_to_linear(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    let linear = if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    };
    // Four decimals: finer than 8-bit colour resolves, and a shorter file.
    (linear * 1e4).round() / 1e4
}

/// The binary chunk being laid out: its parts in order, and the views and accessors over them.
#[derive(Default)]
struct Binary<'a> {
    parts: Vec<Part<'a>>,
    views: Vec<Value>,
    accessors: Vec<Value>,
    /// Bytes so far, a multiple of 4 (every part is).
    len: usize,
    /// Vertex arrays already laid out, by address and length, with their accessor: meshes that
    /// lend the same array (an atlas's labels over one vertex array) share it.
    laid_out: Vec<((usize, usize), usize)>,
}

/// A part of the binary chunk.
enum Part<'a> {
    Vectors(&'a [[f32; 3]]),
    Triangles(&'a [[u32; 3]]),
}

impl<'a> Binary<'a> {
    /// A view over the next `length` bytes.
    fn view(&mut self, length: usize, target: u32, part: Part<'a>) -> usize {
        self.views.push(
            json!({ "buffer": 0, "byteOffset": self.len, "byteLength": length, "target": target }),
        );
        self.len += length;
        self.parts.push(part);
        self.views.len() - 1
    }

    /// The accessor of a vertex array (`VEC3` floats), laid out unless already.
    fn vectors(&mut self, data: &'a [[f32; 3]], bounds: bool) -> usize {
        let key = (data.as_ptr() as usize, data.len());
        if let Some(&(_, accessor)) = self.laid_out.iter().find(|(k, _)| *k == key) {
            return accessor;
        }
        let view = self.view(12 * data.len(), ARRAY_BUFFER, Part::Vectors(data));
        let mut accessor = json!({ "bufferView": view, "componentType": FLOAT, "count": data.len(), "type": "VEC3" });
        if bounds {
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for p in data {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        self.accessors.push(accessor);
        self.laid_out.push((key, self.accessors.len() - 1));
        self.accessors.len() - 1
    }

    /// A triangle primitive of `mesh` (which has triangles), its arrays laid out.
    fn primitive(&mut self, mesh: MeshSlices<'a>) -> Value {
        let mut attributes = json!({ "POSITION": self.vectors(mesh.positions, true) });
        if !mesh.normals.is_empty() {
            attributes["NORMAL"] = json!(self.vectors(mesh.normals, false));
        }
        let view = self.view(
            12 * mesh.triangles.len(),
            ELEMENT_ARRAY_BUFFER,
            Part::Triangles(mesh.triangles),
        );
        self.accessors.push(json!({
            "bufferView": view, "componentType": UNSIGNED_INT,
            "count": 3 * mesh.triangles.len(), "type": "SCALAR",
        }));
        json!({ "attributes": attributes, "indices": self.accessors.len() - 1, "mode": TRIANGLES })
    }
}

/// Writes the GLB container: header, JSON chunk (padded with spaces), binary chunk if any.
fn container(doc: &Value, parts: &[Part<'_>], out: &mut impl Write) -> io::Result<()> {
    let bin_len: usize = parts
        .iter()
        .map(|part| match part {
            Part::Vectors(v) => 12 * v.len(),
            Part::Triangles(t) => 12 * t.len(),
        })
        .sum();
    let too_big = || {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "the mesh is too large for one GLB file",
        )
    };
    let mut json = serde_json::to_vec(doc).map_err(io::Error::other)?;
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
        for part in parts {
            match part {
                Part::Vectors(v) => le_words(v, out, f32::to_le_bytes)?,
                Part::Triangles(t) => le_words(t, out, u32::to_le_bytes)?,
            }
        }
    }
    Ok(())
}

fn asset(options: &WriteOptions) -> Value {
    json!({
        "version": "2.0",
        "generator": "skelclimb (Skeleton Climbing)",
        "extras": { "coordinates": options.coordinates() },
    })
}

/// A node, with `mesh` if any. glTF is in metres with +Y up and viewers look down −Z; scanner
/// coordinates are millimetres with +Z superior. For those, the node scales by 1/1000 and turns
/// the patient upright, facing the viewer (anterior towards +Z), leaving the vertex data exact.
fn node(mesh: Option<usize>, name: &str, options: &WriteOptions) -> Value {
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
    let mut node = match mesh {
        Some(mesh) => json!({ "mesh": mesh, "name": name }),
        None => json!({ "name": name }),
    };
    if let Some(m) = matrix {
        node["matrix"] = json!(m);
    }
    node
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
