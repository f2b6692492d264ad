//! Block extraction for the Dask driver: one block's share of a mesh, and joining shares. A share
//! crosses Python as a plain tuple of NumPy arrays and numbers, so Dask can pickle it between
//! processes and machines without knowing about this extension.

use numpy::{Element, PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArray};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use sc_runtime::{BlockMesh, Params, Scalar, Stats, Volume, extract_block as block};

use crate::convert::{self, with_element};
use crate::errors;
use crate::extract::params;

/// A share as Python sees it: `(grid, keys, positions, normals, faces, cubes, counts, covered)`,
/// with `normals` empty when not asked for and `counts` the seven `Stats` fields in order.
type Share<'py> = (
    [usize; 3],
    Bound<'py, PyArray1<u64>>,
    Bound<'py, numpy::PyArray2<f32>>,
    Bound<'py, numpy::PyArray2<f32>>,
    Bound<'py, numpy::PyArray2<u32>>,
    Bound<'py, PyArray1<u64>>,
    [u64; 7],
    u64,
);

/// `sc_runtime::block_samples`: the samples meshing the cubes `cubes` (`(start, end)` per axis,
/// x, y, z) of a grid of `grid` samples reads in `mode` (with boxes up to `max_box` cubes, in
/// adaptive mode), as `(start, end)` per axis.
#[pyfunction]
#[pyo3(signature = (grid, cubes, mode, max_box=None))]
pub fn block_samples(
    grid: [usize; 3],
    cubes: [(usize, usize); 3],
    mode: &str,
    max_box: Option<u32>,
) -> PyResult<[(usize, usize); 3]> {
    let params = Params {
        mode: crate::extract::mode(mode)?,
        max_box,
        ..Params::new(0.0)
    };
    let need = sc_runtime::block_samples(grid, cubes.map(|(a, b)| a..b), &params)
        .map_err(errors::runtime)?;
    Ok(need.map(|r| (r.start, r.end)))
}

/// Meshes the cubes `cubes` (`(start, end)` per axis, x, y, z) of a grid of `grid` samples from
/// `samples`, a 3-D array whose first sample sits at global index `at`.
#[pyfunction]
#[pyo3(signature = (samples, at, grid, cubes, level, spacing, origin, mode, normals, max_error=None, max_box=None, allow_wrong_side=false))]
#[allow(clippy::too_many_arguments)]
pub fn extract_block<'py>(
    py: Python<'py>,
    samples: &Bound<'py, PyUntypedArray>,
    at: [usize; 3],
    grid: [usize; 3],
    cubes: [(usize, usize); 3],
    level: f64,
    spacing: [f64; 3],
    origin: [f64; 3],
    mode: &str,
    normals: bool,
    max_error: Option<(f64, String)>,
    max_box: Option<u32>,
    allow_wrong_side: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    let params = Params {
        max_box,
        allow_wrong_side,
        ..params(level, spacing, origin, mode, normals, max_error)?
    };
    let dims = convert::dims(samples, "samples")?;
    let cubes = cubes.map(|(a, b)| a..b);
    let share = with_element!(py, samples, "samples", T => run::<T>(py, samples, dims, at, grid, cubes.clone(), &params))?;
    to_python(py, share)?.into_pyobject(py)
}

fn run<T: Scalar + Element>(
    py: Python<'_>,
    samples: &Bound<'_, PyUntypedArray>,
    dims: [usize; 3],
    at: [usize; 3],
    grid: [usize; 3],
    cubes: [core::ops::Range<usize>; 3],
    params: &Params,
) -> PyResult<BlockMesh> {
    let data = convert::samples::<T>(samples, "samples")?;
    let data = data
        .as_slice()
        .map_err(|_| PyValueError::new_err("samples: the array is not contiguous"))?;
    let volume = Volume::new(data, dims).map_err(errors::runtime)?;
    py.detach(|| block(&volume, at, grid, cubes, params))
        .map_err(errors::runtime)
}

/// Joins shares (any number, in any order) into one share.
#[pyfunction]
pub fn merge_blocks<'py>(
    py: Python<'py>,
    shares: Vec<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let shares = shares
        .iter()
        .map(from_python)
        .collect::<PyResult<Vec<_>>>()?;
    let joined = py.detach(|| BlockMesh::merge_all(shares));
    to_python(py, joined.map_err(errors::runtime)?)?.into_pyobject(py)
}

/// The whole mesh from a share that covers the grid: `(vertices, faces, normals, stats)`, with
/// the stats dict `extract` gives.
#[pyfunction]
pub fn finish_blocks<'py>(
    py: Python<'py>,
    share: Bound<'py, PyAny>,
    mode: &str,
    level: f64,
) -> PyResult<Bound<'py, PyTuple>> {
    let share = from_python(&share)?;
    let grid = share.grid;
    let mesh = share.into_mesh().map_err(errors::runtime)?;
    let stats = crate::extract::stats(py, &mesh.stats, mode, level, grid, None)?;
    (
        convert::rows(py, mesh.positions)?,
        convert::rows(py, mesh.triangles)?,
        convert::rows(py, mesh.normals)?,
        stats,
    )
        .into_pyobject(py)
}

fn to_python(py: Python<'_>, b: BlockMesh) -> PyResult<Share<'_>> {
    Ok((
        b.grid,
        PyArray1::from_vec(py, b.keys),
        convert::rows(py, b.positions)?,
        convert::rows(py, b.normals)?,
        convert::rows(py, b.triangles)?,
        PyArray1::from_vec(py, b.cubes),
        b.stats.to_array(),
        b.covered,
    ))
}

pub fn from_python(obj: &Bound<'_, PyAny>) -> PyResult<BlockMesh> {
    let bad = |what: &str| PyValueError::new_err(format!("block mesh: {what}"));
    #[allow(clippy::type_complexity)]
    let (grid, keys, positions, normals, triangles, cubes, c, covered): (
        [usize; 3],
        PyReadonlyArray1<'_, u64>,
        PyReadonlyArray2<'_, f32>,
        PyReadonlyArray2<'_, f32>,
        PyReadonlyArray2<'_, u32>,
        PyReadonlyArray1<'_, u64>,
        [u64; 7],
        u64,
    ) = obj
        .extract()
        .map_err(|e| bad(&format!("not a share from extract_block ({e})")))?;
    let vec1 = |a: &PyReadonlyArray1<'_, u64>| a.as_array().to_vec();
    let keys = vec1(&keys);
    let cubes = vec1(&cubes);
    let positions = rows(&positions).ok_or_else(|| bad("positions are not (V, 3)"))?;
    let normals = rows(&normals).ok_or_else(|| bad("normals are not (V, 3)"))?;
    let triangles = rows(&triangles).ok_or_else(|| bad("faces are not (T, 3)"))?;
    let share = BlockMesh {
        grid,
        keys,
        positions,
        normals,
        triangles,
        cubes,
        stats: Stats::from_array(c),
        covered,
    };
    share.check().map_err(|e| bad(&e.to_string()))?;
    Ok(share)
}

/// The rows of an `(n, N)` array, or `None` if it has another width.
pub fn rows<T: Element + Copy, const N: usize>(a: &PyReadonlyArray2<'_, T>) -> Option<Vec<[T; N]>> {
    let view = a.as_array();
    (view.ncols() == N || view.nrows() == 0).then(|| {
        view.rows()
            .into_iter()
            .map(|r| core::array::from_fn(|k| r[k]))
            .collect()
    })
}
