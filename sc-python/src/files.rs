//! Volume files in and mesh files out through `sc-io`, the readers and writers the `skelclimb`
//! command uses, so Python and the CLI read a scan the same way and write the same bytes.

use std::path::PathBuf;

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use sc_io::atomic::AtomicFile;
use sc_io::progress::Silent;
use sc_io::read::dicom::DicomOptions;
use sc_io::read::{RawLayout, ReadOptions};
use sc_io::volume::{Dtype, Endian, Grid, Linear, Sample, Samples};
use sc_io::with_samples;
use sc_io::write::{MeshFormat, MeshSlices, WriteOptions};

use crate::{convert, errors, world};

/// Writes a mesh straight from its NumPy arrays (C-contiguous `(n, 3)` rows, borrowed, not
/// copied); the format follows the extension (`.ply`, `.obj`, `.stl`, `.glb`) and `space`
/// (`"RAS"`, `"LPS"` or `None`) is recorded where the format has room. The file appears whole or
/// not at all.
#[pyfunction]
#[pyo3(signature = (path, vertices, faces, normals=None, ascii=false, space=None))]
pub fn save(
    py: Python<'_>,
    path: PathBuf,
    vertices: PyReadonlyArray2<'_, f32>,
    faces: PyReadonlyArray2<'_, u32>,
    normals: Option<PyReadonlyArray2<'_, f32>>,
    ascii: bool,
    space: Option<&str>,
) -> PyResult<()> {
    let format = MeshFormat::from_path(&path).map_err(PyValueError::new_err)?;
    if ascii && format != MeshFormat::Ply {
        return Err(PyValueError::new_err("ascii: applies to .ply files only"));
    }
    let options = WriteOptions {
        ascii,
        space: world::space(space)?,
    };
    let positions = convert::borrow_rows(&vertices, "vertices")?;
    let triangles = convert::borrow_rows(&faces, "faces")?;
    let normals = match &normals {
        Some(n) => convert::borrow_rows(n, "normals")?,
        None => &[],
    };
    if !normals.is_empty() && normals.len() != positions.len() {
        return Err(PyValueError::new_err(format!(
            "normals: {} rows for {} vertices",
            normals.len(),
            positions.len()
        )));
    }
    let count = positions.len();
    if let Some(bad) = triangles.iter().flatten().find(|&&i| i as usize >= count) {
        return Err(PyValueError::new_err(format!(
            "faces: vertex index {bad} is out of range for {count} vertices"
        )));
    }
    let mesh = MeshSlices {
        positions,
        normals,
        triangles,
    };
    py.detach(|| AtomicFile::create(&path)?.write_with(|out| format.write(mesh, &options, out)))
        .map_err(errors::io)
}

/// Reads a volume file (NIfTI, NRRD, MetaImage, NumPy, a DICOM directory, raw with `dims` and
/// `dtype`, or raw with a JSON sidecar). Returns `(volume, affine, space)`: a C-ordered array of
/// shape `(nz, ny, nx)`, the 4×4 map from `(x, y, z, 1)` index to world coordinates, and the
/// world's convention (`"RAS"`, `"LPS"`, or `None` for a file without a world frame). A rescale
/// slope/intercept in the file is applied (to float32 for 8- and 16-bit samples, float64
/// otherwise). Zarr chunks that have no file read as the fill value, with a `UserWarning` that
/// says how many there were.
#[pyfunction]
#[pyo3(signature = (path, *, dims=None, dtype=None, endian="little", header_bytes=0, array=None, series=None, resample_gaps=false, zarr_level=0))]
#[allow(clippy::too_many_arguments)]
pub fn load<'py>(
    py: Python<'py>,
    path: PathBuf,
    dims: Option<[usize; 3]>,
    dtype: Option<&str>,
    endian: &str,
    header_bytes: u64,
    array: Option<String>,
    series: Option<String>,
    resample_gaps: bool,
    zarr_level: usize,
) -> PyResult<Bound<'py, PyTuple>> {
    let raw = match (dims, dtype) {
        (Some(dims), Some(dtype)) => Some(RawLayout {
            dims,
            dtype: parse_dtype(dtype)?,
            endian: match endian {
                "little" => Endian::Little,
                "big" => Endian::Big,
                _ => {
                    return Err(PyValueError::new_err(format!(
                        "endian: expected 'little' or 'big', got {endian:?}"
                    )));
                }
            },
            header_bytes,
        }),
        (None, None) => None,
        _ => {
            return Err(PyValueError::new_err(
                "dims and dtype: give both for a raw file, or neither",
            ));
        }
    };
    let options = ReadOptions {
        raw,
        array,
        dicom: DicomOptions {
            series,
            resample_gaps,
        },
        zarr_level,
    };
    let grid = py
        .detach(|| sc_io::read::read(&path, &options, &Silent))
        .map_err(errors::io)?;
    for warning in &grid.warnings {
        let text = std::ffi::CString::new(warning.replace('\0', " "))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        PyErr::warn(
            py,
            &py.get_type::<pyo3::exceptions::PyUserWarning>(),
            &text,
            1,
        )?;
    }
    let (affine, space) = world::affine(py, &grid)?;
    let Grid {
        samples,
        dims: [nx, ny, nz],
        scale,
        ..
    } = grid;
    let samples = if scale.is_identity() {
        samples
    } else {
        with_samples!(&samples, v => rescaled(v, scale))
    };
    let volume = with_samples!(samples, v => PyArray1::from_vec(py, v.into_vec()).reshape([nz, ny, nx])?.into_any());
    (volume, affine, space).into_pyobject(py)
}

fn rescaled<T: Sample>(v: &[T], map: Linear) -> Samples {
    if T::DTYPE.size() <= 2 {
        Samples::F32(v.iter().map(|x| map.apply(x.to_f64()) as f32).collect())
    } else {
        Samples::F64(v.iter().map(|x| map.apply(x.to_f64())).collect())
    }
}

fn parse_dtype(name: &str) -> PyResult<Dtype> {
    Dtype::from_name(name).ok_or_else(|| {
        PyValueError::new_err(format!(
            "dtype: unsupported {name:?}; use {}",
            crate::convert::TYPES
        ))
    })
}
