//! Label blocks for the Dask driver (`skelclimb.dask.labels`): one block's share of an atlas,
//! joining shares, and the result `labels` gives from the joined atlas. A share crosses Python
//! as a plain tuple of NumPy arrays and numbers, so Dask can pickle it between processes; its
//! pairs keep the label type, which every call reads back from them.

use std::fmt::Display;

use numpy::{Element, PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArray};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use sc_runtime::labels::{AtlasBlock, Label, LabelParams, block_samples, extract_block};
use sc_runtime::{Stats, Volume};

use crate::blocks::rows;
use crate::convert;
use crate::labels::{Reply, label, respond};
use crate::{errors, extract};

/// Calls `$body` with `$t` bound to the label type of `$array`'s dtype.
macro_rules! with_label {
    ($py:expr, $array:expr, $name:expr, $t:ident => $body:expr) => {
        $crate::convert::with_type!(
            $py, $array, $name, $crate::labels::TYPES, [u8, u16, u32, u64, i16, i32], $t => $body
        )
    };
}
pub(crate) use with_label;

/// Meshes the cubes `cubes` (`(start, end)` per axis, x, y, z, numbered as
/// `sc_runtime::labels::block_samples` says) of a volume of `grid` samples from `samples`, a
/// 3-D label array whose first sample sits at volume index `at`. Returns the share as
/// `(grid, pad, keys, positions, faces, pairs, cubes, counts, covered)`.
#[pyfunction]
#[pyo3(signature = (samples, at, grid, cubes, spacing, origin, background, mode, pad, smoothing, affine=None, space=None))]
#[allow(clippy::too_many_arguments)]
pub fn extract_label_block<'py>(
    py: Python<'py>,
    samples: &Bound<'py, PyUntypedArray>,
    at: [usize; 3],
    grid: [usize; 3],
    cubes: [(usize, usize); 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    background: Bound<'py, PyAny>,
    mode: &str,
    pad: bool,
    smoothing: f64,
    affine: Option<[[f64; 4]; 3]>,
    space: Option<&str>,
) -> PyResult<Bound<'py, PyTuple>> {
    let (spacing, origin, _) = extract::placement(spacing, origin, affine, space)?;
    let dims = convert::dims(samples, "samples")?;
    let cubes = cubes.map(|(a, b)| a..b);
    let mode = extract::mode(mode)?;
    with_label!(py, samples, "samples", L => {
        let params = LabelParams {
            background: label::<L>(&background)?,
            mode,
            pad,
            spacing,
            origin,
            smoothing,
            threads: 1,
            ..LabelParams::default()
        };
        let data = convert::samples::<L>(samples, "samples")?;
        let data = data
            .as_slice()
            .map_err(|_| PyValueError::new_err("samples: the array is not contiguous"))?;
        let volume = Volume::new(data, dims).map_err(errors::runtime)?;
        let share = py
            .detach(|| extract_block(volume, at, grid, cubes.clone(), &params))
            .map_err(errors::runtime)?;
        to_python(py, share)
    })
}

/// Joins shares (any number, in any order, all of one label type) into one share.
#[pyfunction]
pub fn merge_label_blocks<'py>(
    py: Python<'py>,
    shares: Vec<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let Some(first) = shares.first() else {
        return Err(PyValueError::new_err("label blocks: no shares to merge"));
    };
    let pairs = pairs_of(first)?;
    with_label!(py, &pairs, "label block pairs", L => {
        let shares = shares
            .iter()
            .map(from_python::<L>)
            .collect::<PyResult<Vec<_>>>()?;
        let joined = py.detach(|| AtlasBlock::merge_all(shares));
        to_python(py, joined.map_err(errors::runtime)?)
    })
}

/// What `_native.labels` returns, from a share covering the volume: the atlas is the one
/// `labels` makes of the whole volume, placed, cut and counted as it does.
#[pyfunction]
#[pyo3(signature = (share, background, mode, normals, selection=None, affine=None, space=None))]
#[allow(clippy::too_many_arguments)]
pub fn finish_label_blocks<'py>(
    py: Python<'py>,
    share: Bound<'py, PyAny>,
    background: Bound<'py, PyAny>,
    mode: &str,
    normals: bool,
    selection: Option<Vec<Bound<'py, PyAny>>>,
    affine: Option<[[f64; 4]; 3]>,
    space: Option<&str>,
) -> PyResult<Bound<'py, PyTuple>> {
    let (_, _, world) = extract::placement([1.0; 3], [0.0; 3], affine, space)?;
    let pairs = pairs_of(&share)?;
    with_label!(py, &pairs, "label block pairs", L => {
        let share = from_python::<L>(&share)?;
        let dims = share.grid;
        let atlas = share.into_atlas().map_err(errors::runtime)?;
        let reply = Reply {
            dims,
            world,
            background: label::<L>(&background)?,
            mode,
            normals,
            // As each block's task: one thread, the scheduler shares out the rest.
            threads: 1,
            selection,
        };
        respond(py, atlas, reply)
    })
}

/// The pairs array of a share, whose dtype is the share's label type.
pub fn pairs_of<'py>(share: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    share
        .get_item(5)
        .ok()
        .and_then(|p| p.cast_into::<PyUntypedArray>().ok())
        .ok_or_else(|| PyValueError::new_err("label block: not a share from extract_label_block"))
}

fn to_python<'py, L: Label + Element>(
    py: Python<'py>,
    b: AtlasBlock<L>,
) -> PyResult<Bound<'py, PyTuple>> {
    (
        b.grid,
        b.pad,
        PyArray1::from_vec(py, b.keys),
        convert::rows(py, b.positions)?,
        convert::rows(py, b.triangles)?,
        convert::rows(py, b.pairs)?,
        PyArray1::from_vec(py, b.cubes),
        b.stats.to_array(),
        b.covered,
    )
        .into_pyobject(py)
}

/// The share `obj`, a tuple as [`to_python`] makes, of label type `L`, checked.
pub fn from_python<'py, L>(obj: &Bound<'py, PyAny>) -> PyResult<AtlasBlock<L>>
where
    L: Label + Element + Display + FromPyObjectOwned<'py>,
{
    let bad = |what: &str| PyValueError::new_err(format!("label block: {what}"));
    #[allow(clippy::type_complexity)]
    let (grid, pad, keys, positions, triangles, pairs, cubes, c, covered): (
        [usize; 3],
        bool,
        PyReadonlyArray1<'_, u64>,
        PyReadonlyArray2<'_, f32>,
        PyReadonlyArray2<'_, u32>,
        PyReadonlyArray2<'_, L>,
        PyReadonlyArray1<'_, u64>,
        [u64; 7],
        u64,
    ) = obj
        .extract()
        .map_err(|e| bad(&format!("not a share from extract_label_block ({e})")))?;
    let share = AtlasBlock {
        grid,
        pad,
        keys: keys.as_array().to_vec(),
        positions: rows(&positions).ok_or_else(|| bad("positions are not (V, 3)"))?,
        triangles: rows(&triangles).ok_or_else(|| bad("faces are not (T, 3)"))?,
        pairs: rows(&pairs).ok_or_else(|| bad("pairs are not (T, 2)"))?,
        cubes: cubes.as_array().to_vec(),
        stats: Stats::from_array(c),
        covered,
    };
    share.check().map_err(|e| bad(&e.to_string()))?;
    Ok(share)
}

/// `sc_runtime::labels::block_samples`: the samples meshing the cubes `cubes` of a volume of
/// `grid` samples reads, as `(start, end)` per axis.
#[pyfunction]
pub fn label_block_samples(
    grid: [usize; 3],
    cubes: [(usize, usize); 3],
    pad: bool,
    smoothing: f64,
) -> PyResult<[(usize, usize); 3]> {
    let params = LabelParams::<u8> {
        pad,
        smoothing,
        ..LabelParams::default()
    };
    let need = block_samples(grid, cubes.map(|(a, b)| a..b), &params).map_err(errors::runtime)?;
    Ok(need.map(|r| (r.start, r.end)))
}
