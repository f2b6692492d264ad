//! Reading meshes back (PLY, OBJ, STL), for `skelclimb render`: positions and triangles only.
//! Each format goes through its crate (`ply-rs`, `tobj`, `stl_io`); polygons are fanned into
//! triangles, and STL's unshared corners are merged by position (`stl_io` indexes them).

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use ply_rs::parser::Parser;
use ply_rs::ply::{DefaultElement, Property};

use crate::error::{Error, Result};

/// An indexed triangle mesh as read from a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// Whether [`read`] reads `path`, by its extension.
pub fn readable(path: &Path) -> bool {
    matches!(extension(path).as_str(), "ply" | "obj" | "stl")
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Reads `path` by its extension: `.ply` (text or binary), `.obj` or `.stl` (text or binary).
pub fn read(path: &Path) -> Result<TriangleMesh> {
    let ext = extension(path);
    let open = || crate::input::open(path);
    let mesh = match ext.as_str() {
        "ply" => ply(path, open()?)?,
        "obj" => obj(path)?,
        "stl" => {
            let m = stl_io::read_stl(&mut BufReader::new(open()?))
                .map_err(|e| Error::file(path, format!("not a readable STL file: {e}")))?;
            TriangleMesh {
                positions: m.vertices.iter().map(|v| [v[0], v[1], v[2]]).collect(),
                triangles: m
                    .faces
                    .iter()
                    .map(|f| f.vertices.map(|i| i as u32))
                    .collect(),
            }
        }
        _ => {
            return Err(Error::Usage(format!(
                "{}: expected a .ply, .obj or .stl mesh",
                path.display()
            )));
        }
    };
    let n = mesh.positions.len();
    if let Some(t) = mesh
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(Error::file(
            path,
            format!(
                "a face refers to vertex {} of {n}",
                t.iter().max().unwrap_or(&0)
            ),
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(Error::file(path, "the mesh has no triangles"));
    }
    if !mesh.positions.iter().flatten().all(|c| c.is_finite()) {
        return Err(Error::file(
            path,
            "a vertex position is not a finite number",
        ));
    }
    Ok(mesh)
}

fn ply(path: &Path, file: File) -> Result<TriangleMesh> {
    let bad = |m: String| Error::file(path, format!("not a readable PLY file: {m}"));
    // ply-rs panics on some malformed headers and bodies (unchecked number parsing): a bad file
    // must become an error naming it, not end the program.
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        Parser::<DefaultElement>::new().read_ply(&mut BufReader::new(file))
    }))
    .map_err(|_| bad("malformed header or data".into()))?
    .map_err(|e| bad(e.to_string()))?;
    let number = |p: Option<&Property>| -> Option<f64> {
        Some(match p? {
            Property::Float(v) => f64::from(*v),
            Property::Double(v) => *v,
            Property::Char(v) => f64::from(*v),
            Property::UChar(v) => f64::from(*v),
            Property::Short(v) => f64::from(*v),
            Property::UShort(v) => f64::from(*v),
            Property::Int(v) => f64::from(*v),
            Property::UInt(v) => f64::from(*v),
            _ => return None,
        })
    };
    let vertices = parsed
        .payload
        .get("vertex")
        .ok_or_else(|| bad("no vertex element".into()))?;
    let positions = vertices
        .iter()
        .map(|v| {
            let c = |k: &str| number(v.get(k)).map(|x| x as f32);
            Some([c("x")?, c("y")?, c("z")?])
        })
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| bad("a vertex without numeric x, y, z".into()))?;
    let mut triangles = Vec::new();
    for face in parsed.payload.get("face").map_or(&[][..], Vec::as_slice) {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"));
        let ids: Vec<i64> = match list {
            Some(Property::ListUInt(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListInt(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListUShort(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListShort(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            Some(Property::ListUChar(v)) => v.iter().map(|&i| i64::from(i)).collect(),
            _ => return Err(bad("a face without a vertex_indices list".into())),
        };
        fan(&ids, &mut triangles).ok_or_else(|| bad(format!("a face with indices {ids:?}")))?;
    }
    Ok(TriangleMesh {
        positions,
        triangles,
    })
}

/// Splits a polygon into a fan of triangles; `None` for a negative or oversized index.
fn fan(ids: &[i64], out: &mut Vec<[u32; 3]>) -> Option<()> {
    let ids: Vec<u32> = ids
        .iter()
        .map(|&i| u32::try_from(i).ok())
        .collect::<Option<_>>()?;
    for w in 1..ids.len().saturating_sub(1) {
        out.push([ids[0], ids[w], ids[w + 1]]);
    }
    Some(())
}

fn obj(path: &Path) -> Result<TriangleMesh> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let bad = |m: String| Error::file(path, format!("not a readable OBJ file: {m}"));
    let mut reader = BufReader::new(crate::input::open(path)?);
    // tobj multiplies a face's resolved normal and texture indices unchecked: an out-of-range
    // relative index overflows (a panic where overflow checks are on; found by fuzzing). And
    // materials are never loaded: only the geometry is used, and a `mtllib` line may name any
    // file (`/dev/zero` would be read without end).
    let (models, _) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(&mut reader, &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
    }))
    .map_err(|_| bad("malformed face indices".into()))?
    .map_err(|e| bad(e.to_string()))?;
    let mut mesh = TriangleMesh::default();
    for m in models {
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(m.mesh.positions.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        mesh.triangles.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
        );
    }
    Ok(mesh)
}
