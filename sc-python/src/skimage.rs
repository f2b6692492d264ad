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
///
/// This pass was a sixth of `marching_cubes`' time on the stent CT, mostly waiting for the
/// volume to come back into cache: it converts through `i64` (one instruction; `usize` takes
/// several) and picks the axis without a loop. Now 8 % of the MNI white matter's time.
fn edge_values<T: Scalar + Element>(
    data: &[T],
    dims: [usize; 3],
    spacing: [f64; 3],
    positions: &[[f32; 3]],
) -> Vec<f32> {
    let [nx, ny, _] = dims;
    let strides = [1, nx as i64, (nx * ny) as i64];
    let inverse = spacing.map(|s| 1.0 / s);
    let sample = |i: i64| {
        usize::try_from(i)
            .ok()
            .and_then(|i| data.get(i))
            .map_or(f64::NAN, |v| v.to_f64())
    };
    // Indices first, loads after, a batch at a time: the volume is no longer in cache, and
    // a loop of loads only keeps many misses in flight at once.
    const BATCH: usize = 256;
    let mut values = Vec::with_capacity(positions.len());
    let mut ends = [(0i64, 0i64); BATCH];
    for batch in positions.chunks(BATCH) {
        for (pos, end) in batch.iter().zip(&mut ends) {
            // Coordinates are at least 0 (the origin is 0), so truncation is floor and
            // `+ 0.5` then truncation rounds.
            let c: [f64; 3] = core::array::from_fn(|d| f64::from(pos[d]) * inverse[d]);
            let near = c.map(|v| (v + 0.5) as i64);
            let off: [f64; 3] = core::array::from_fn(|d| (c[d] - near[d] as f64).abs());
            let axis = if off[0] >= off[1] && off[0] >= off[2] {
                0
            } else if off[1] >= off[2] {
                1
            } else {
                2
            };
            let at = near[0] + near[1] * strides[1] + near[2] * strides[2];
            *end = (
                at - (near[axis] - c[axis] as i64) * strides[axis],
                strides[axis],
            );
        }
        values.extend(ends[..batch.len()].iter().map(|&(lower, step)| {
            let (a, b) = (sample(lower), sample(lower + step));
            // As NumPy's maximum: a NaN end gives NaN.
            (if a > b || a.is_nan() { a } else { b }) as f32
        }));
    }
    values
}
