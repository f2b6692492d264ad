//! scikit-image's layout of a mesh, made in Rust: `marching_cubes` returns vertices and normals
//! in the array's axis order, `int32` faces wound its way, and a value per vertex. Done in NumPy
//! these were five temporary arrays and half the extraction's time again on small scans.

use numpy::{Element, PyArray1, PyUntypedArray};
use pyo3::prelude::*;
use sc_runtime::{Mesh, Params, Scalar};

use crate::convert::{self, with_element};
use crate::extract::{mode, run};

/// Extracts the surface (embedded mode, with normals) and returns
/// `(verts, faces, normals, values)`: with `reverse_axes`, coordinates as `(z, y, x)`; with
/// `flip_winding`, each face's vertex order reversed; `values` the larger sample at the two ends
/// of each vertex's grid edge.
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
        spacing,
        ..Params::new(level)
    };
    let dims = convert::dims(volume, "volume")?;
    let (mesh, values) = with_element!(py, volume, "volume", T => {
        let mesh = run::<T>(py, volume, dims, &params, threads)?;
        let samples = convert::samples::<T>(volume, "volume")?;
        let data = samples.as_slice().map_err(|_| {
            pyo3::exceptions::PyValueError::new_err("volume: the array is not contiguous")
        })?;
        let values = py.detach(|| edge_values(data, dims, spacing, &mesh.positions));
        Ok::<_, PyErr>((mesh, values))
    })?;
    let Mesh {
        mut positions,
        mut normals,
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

/// Per vertex, the larger of the two samples at the ends of its grid edge, as `f32`. A vertex
/// lies on a grid edge at least 1/1024 of it from either end, so one coordinate (in grid steps)
/// is clearly fractional and the other two are whole up to rounding: the edge's lower end is
/// that coordinate's floor and the others' nearest integers.
fn edge_values<T: Scalar + Element>(
    data: &[T],
    dims: [usize; 3],
    spacing: [f64; 3],
    positions: &[[f32; 3]],
) -> Vec<f32> {
    let [nx, ny, _] = dims;
    let at = |p: [usize; 3]| data[p[0] + nx * (p[1] + ny * p[2])].to_f64();
    let inverse = spacing.map(|s| 1.0 / s);
    // Coordinates are at least 0 (the origin is 0), so truncation is floor and `+ 0.5` then
    // truncation rounds: one instruction each, where `floor` and `round` are library calls.
    let last = dims.map(|n| n - 1);
    positions
        .iter()
        .map(|pos| {
            let c: [f64; 3] = core::array::from_fn(|d| (f64::from(pos[d]) * inverse[d]).max(0.0));
            let near = c.map(|v| (v + 0.5) as usize);
            let off = core::array::from_fn::<f64, 3, _>(|d| (c[d] - near[d] as f64).abs());
            let axis = (0..3).fold(0, |a, d| if off[d] > off[a] { d } else { a });
            let mut lower = near;
            lower[axis] = c[axis] as usize;
            let lower = core::array::from_fn(|d| lower[d].min(last[d]));
            let mut upper = lower;
            upper[axis] = (upper[axis] + 1).min(last[axis]);
            let (a, b) = (at(lower), at(upper));
            // As NumPy's maximum: a NaN end gives NaN.
            if a.is_nan() || b.is_nan() {
                f32::NAN
            } else {
                a.max(b) as f32
            }
        })
        .collect()
}
