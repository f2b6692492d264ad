//! scikit-image's layout of a mesh, made in Rust: `marching_cubes` returns vertices and normals
//! in the array's axis order, `int32` faces wound its way, and a value per vertex. Done in NumPy
//! these were five temporary arrays and half the extraction's time again on small scans.

use numpy::{PyArray1, PyUntypedArray};
use pyo3::prelude::*;
use sc_runtime::{Mesh, Params};

use crate::convert::{self, with_element};
use crate::extract::{mode, run};

/// Extracts the surface (embedded mode, with normals and values) and returns
/// `(verts, faces, normals, values)`: with `reverse_axes`, coordinates as `(z, y, x)`; with
/// `flip_winding`, each face's vertex order reversed; `values` the larger sample at the two ends
/// of each vertex's grid edge, which the sweep records as it places the vertex.
#[pyfunction]
#[pyo3(signature = (volume, level, spacing, threads, reverse_axes, flip_winding))]
#[allow(clippy::type_complexity)]
pub fn skimage_mesh<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyUntypedArray>,
    level: f64,
    spacing: [f64; 3],
    threads: usize,
    reverse_axes: bool,
    flip_winding: bool,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    let params = Params {
        mode: mode("embedded")?,
        normals: true,
        values: true,
        spacing,
        ..Params::new(level)
    };
    let dims = convert::dims(volume, "volume")?;
    let mesh =
        with_element!(py, volume, "volume", T => run::<T>(py, volume, dims, &params, threads))?;
    let Mesh {
        mut positions,
        mut normals,
        values,
        triangles,
        ..
    } = mesh;
    let faces: Vec<[i32; 3]> = py.detach(|| {
        if reverse_axes {
            positions.iter_mut().for_each(|p| p.reverse());
            normals.iter_mut().for_each(|n| n.reverse());
        }
        // Fewer than 2^31 vertices: the runtime numbers them in u32, and a mesh that large
        // would not fit in memory as f32 triples anyway.
        // Same size and alignment: the standard library collects this in place.
        let face = |t: [u32; 3]| t.map(|i| i as i32);
        if flip_winding {
            triangles
                .into_iter()
                .map(|[a, b, c]| face([c, b, a]))
                .collect()
        } else {
            triangles.into_iter().map(face).collect()
        }
    });
    (
        convert::rows(py, positions)?,
        convert::rows(py, faces)?,
        convert::rows(py, normals)?,
        PyArray1::from_vec(py, values),
    )
        .into_pyobject(py)
}
