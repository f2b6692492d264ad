//! scikit-image's layout of a mesh, made in Rust: `marching_cubes` returns vertices and normals
//! in the array's axis order, faces wound its way, and a value per vertex. Done in NumPy these
//! were five temporary arrays and half the extraction's time again on small scans. The sweep
//! emits the coordinates in the array's order ([`Axes::Zyx`] for a C-ordered array), so the one
//! pass left here is the winding, turned for one of the two gradient directions.

use numpy::{PyArray1, PyUntypedArray};
use pyo3::prelude::*;
use sc_runtime::{Axes, Mesh, Mode, Params};

use crate::arguments;
use crate::convert::{self, with_element};
use crate::extract::run;

/// Extracts the surface (embedded mode, with normals and values) and returns
/// `(verts, faces, normals, values)`: with `reverse_axes`, coordinates as `(z, y, x)`; with
/// `flip_winding`, each face's vertex order reversed; faces as `uint32`; `values` the larger
/// sample at the two ends of each vertex's grid edge, which the sweep records as it places the
/// vertex.
#[pyfunction]
#[pyo3(signature = (volume, level, spacing, threads, reverse_axes, flip_winding))]
#[allow(clippy::type_complexity)]
pub fn skimage_mesh<'py>(
    py: Python<'py>,
    volume: &Bound<'py, PyUntypedArray>,
    level: f64,
    spacing: [f64; 3],
    threads: &Bound<'py, PyAny>,
    reverse_axes: bool,
    flip_winding: bool,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    let threads = arguments::threads(threads)?;
    let params = Params {
        mode: Mode::Embedded,
        normals: true,
        values: true,
        spacing: arguments::triple("spacing", spacing)?,
        axes: if reverse_axes { Axes::Zyx } else { Axes::Xyz },
        ..Params::new(level)
    };
    let dims = convert::dims(volume, "volume")?;
    let mesh =
        with_element!(py, volume, "volume", T => run::<T>(py, volume, dims, &params, threads))?;
    let Mesh {
        positions,
        normals,
        values,
        mut triangles,
        ..
    } = mesh;
    if flip_winding {
        py.detach(|| triangles.iter_mut().for_each(|t| t.swap(0, 2)));
    }
    // The faces go out as `uint32`; the caller views them as `int32` (no copy), which holds
    // every index: the runtime numbers vertices in `u32`, and a mesh of 2^31 vertices would
    // not fit in memory as `f32` triples.
    (
        convert::rows(py, positions)?,
        convert::rows(py, triangles)?,
        convert::rows(py, normals)?,
        PyArray1::from_vec(py, values),
    )
        .into_pyobject(py)
}
