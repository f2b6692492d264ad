//! Zarr v2 and v3 arrays and OME-Zarr multiscale images, through the `zarrs` crate. Read a row of
//! chunks at a time (see [`crate::read::stream`]), so a store larger than memory is meshed with
//! the memory of one row of chunks plus the mesh.

use std::path::Path;
use std::sync::Arc;

use serde_json::Value;
use zarrs::array::{Array, DataType};
use zarrs::array_subset::ArraySubset;
use zarrs::filesystem::FilesystemStore;
use zarrs::group::Group;

use crate::error::{Error, Result};
use crate::volume::{Dtype, Grid, Sample, Samples};

/// An open Zarr array, read a slab of z-slices at a time.
pub struct Source {
    array: Array<FilesystemStore>,
    /// Leading axes of length 1 (OME-Zarr's `t` and `c`) before `z, y, x`.
    lead: usize,
    /// z-slices per chunk: slabs of whole chunk rows decode each chunk once.
    chunk_z: usize,
    /// The array's sample type.
    dtype: Dtype,
}

/// Opens the array at `path` (or multiscale level `level` of an OME-Zarr image there): the grid
/// without its samples, and the source of its samples.
pub fn open(path: &Path, level: usize) -> Result<(Grid, Source)> {
    let bad = |m: String| Error::file(path, m);
    let store = Arc::new(
        FilesystemStore::new(path).map_err(|e| bad(format!("not a readable Zarr store: {e}")))?,
    );
    let mut note = None;
    let (array, scale, translation) = match Array::open(store.clone(), "/") {
        Ok(array) => {
            if level != 0 {
                return Err(Error::Usage(format!(
                    "{}: --zarr-level picks a level of an OME-Zarr multiscale image; this store is one array",
                    path.display()
                )));
            }
            (array, None, None)
        }
        Err(array_error) => {
            let group = Group::open(store.clone(), "/").map_err(|_| {
                bad(format!(
                    "neither a Zarr array nor a Zarr group: {array_error}"
                ))
            })?;
            let attrs = group.attributes();
            let multiscales = attrs
                .get("multiscales")
                .or_else(|| attrs.get("ome").and_then(|o| o.get("multiscales")))
                .and_then(|m| m.get(0))
                .ok_or_else(|| bad("a Zarr group without OME-Zarr `multiscales`: give the path of an array in it".into()))?;
            let datasets = multiscales
                .get("datasets")
                .and_then(Value::as_array)
                .ok_or_else(|| bad("OME-Zarr `multiscales` without `datasets`".into()))?;
            let dataset = datasets.get(level).ok_or_else(|| {
                Error::Usage(format!(
                    "{}: --zarr-level {level}, but the image has levels 0 to {}",
                    path.display(),
                    datasets.len().saturating_sub(1)
                ))
            })?;
            let sub = dataset
                .get("path")
                .and_then(Value::as_str)
                .ok_or_else(|| bad(format!("OME-Zarr dataset {level} has no `path`")))?;
            let array = Array::open(store.clone(), &format!("/{}", sub.trim_matches('/')))
                .map_err(|e| bad(format!("OME-Zarr level {level} ({sub}): {e}")))?;
            let transform = |kind: &str| -> Option<Vec<f64>> {
                dataset
                    .get("coordinateTransformations")?
                    .as_array()?
                    .iter()
                    .find(|t| t.get("type").and_then(Value::as_str) == Some(kind))?
                    .get(kind)?
                    .as_array()?
                    .iter()
                    .map(Value::as_f64)
                    .collect()
            };
            note = Some(format!(
                "OME-Zarr image: level {level} ({sub}) of levels 0 to {}",
                datasets.len() - 1
            ));
            (array, transform("scale"), transform("translation"))
        }
    };
    let shape = array.shape().to_vec();
    let n = shape.len();
    if n < 3 || shape[..n - 3].iter().any(|&s| s != 1) {
        return Err(bad(format!(
            "the array has shape {shape:?}; only 3-D volumes (z, y, x, with any further leading axes of length 1) can be meshed"
        )));
    }
    let dims = [shape[n - 1], shape[n - 2], shape[n - 3]].map(|s| s as usize);
    let dtype = match array.data_type() {
        DataType::UInt8 => Dtype::U8,
        DataType::Int8 => Dtype::I8,
        DataType::UInt16 => Dtype::U16,
        DataType::Int16 => Dtype::I16,
        DataType::UInt32 => Dtype::U32,
        DataType::Int32 => Dtype::I32,
        DataType::Float32 => Dtype::F32,
        DataType::Float64 => Dtype::F64,
        other => {
            return Err(bad(format!(
                "samples of type {other} cannot be meshed; use u8, i8, u16, i16, u32, i32, f32 or f64"
            )));
        }
    };
    let mut grid = Grid::new(Samples::empty(dtype), dims, "Zarr");
    // OME-Zarr lists transforms per axis, slowest first: the last three are z, y, x.
    let xyz = |v: &Option<Vec<f64>>| {
        v.as_ref()
            .filter(|v| v.len() == n)
            .map(|v| [v[n - 1], v[n - 2], v[n - 3]])
    };
    if let Some(s) = xyz(&scale) {
        grid.spacing = s;
    }
    grid.notes.extend(note);
    if let Some(t) = xyz(&translation) {
        grid.origin = t;
    }
    let chunk_z = array
        .chunk_shape(&vec![0; n])
        .map(|c| c[n - 3].get() as usize)
        .unwrap_or(1);
    Ok((
        grid,
        Source {
            array,
            lead: n - 3,
            chunk_z,
            dtype,
        },
    ))
}

impl Source {
    /// z-slices per chunk: slabs of whole chunk rows decode each chunk once.
    pub fn chunk_z(&self) -> usize {
        self.chunk_z
    }

    /// z-slices `z0..z1`, x fastest, of the array's sample type `T`. `zarrs` decodes to this
    /// machine's byte order, so its bytes are the samples; they are copied, since a byte buffer
    /// need not be aligned for `T`. (Read as bytes, a sample type needs no `zarrs` trait, and
    /// [`Sample`] does not depend on this reader.)
    pub fn read<T: Sample>(&self, path: &Path, z0: usize, z1: usize) -> Result<Vec<T>> {
        let error =
            |e: &dyn std::fmt::Display| Error::file(path, format!("reading z {z0}..{z1}: {e}"));
        if T::DTYPE != self.dtype {
            return Err(error(&format_args!(
                "the array holds {}, not {}",
                self.dtype.name(),
                T::DTYPE.name()
            )));
        }
        let shape = self.array.shape();
        let n = shape.len();
        let mut ranges = vec![0..1; self.lead];
        ranges.extend([z0 as u64..z1 as u64, 0..shape[n - 2], 0..shape[n - 1]]);
        let bytes = self
            .array
            .retrieve_array_subset(&ArraySubset::new_with_ranges(&ranges))
            .map_err(|e| error(&e))?
            .into_fixed()
            .map_err(|e| error(&e))?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}
