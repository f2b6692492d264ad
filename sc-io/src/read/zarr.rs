//! Zarr v2 and v3 arrays and OME-Zarr multiscale images, through the `zarrs` crate. Read a row of
//! chunks at a time (see [`crate::read::stream`]), so a store larger than memory is meshed with
//! the memory of one row of chunks plus the mesh.
//!
//! zarrs reads the store's files itself, not through [`crate::input`]: the metadata files and
//! each chunk file a read needs are checked here first, so that a FIFO among them is refused
//! instead of hanging the read. The same look counts the chunks that have no file: legal (they
//! read as the fill value), but the user is told how many there were, and a store none of whose
//! chunks is where its metadata says, but which has them under the other separator, is refused.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde_json::Value;
use zarrs::array::{Array, DataType};
use zarrs::array_subset::ArraySubset;
use zarrs::filesystem::FilesystemStore;
use zarrs::group::Group;

use crate::error::{Error, Result};
use crate::volume::{Dtype, Grid, Sample, Samples};

/// The metadata files zarrs may read in a folder of the store (v3, then v2).
const METADATA: [&str; 4] = ["zarr.json", ".zarray", ".zgroup", ".zattrs"];

/// An open Zarr array, read a slab of z-slices at a time.
pub struct Source {
    array: Array<FilesystemStore>,
    /// The store's folder: chunk keys are paths below it.
    root: PathBuf,
    /// Chunks a read has needed so far, and those of them that have no file.
    chunks: u64,
    missing: u64,
    /// The key of the first chunk that had no file.
    first_missing: Option<String>,
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
    regular_metadata(path)?;
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
            let sub = sub.trim_matches('/');
            regular_metadata(&path.join(sub))?;
            let array = Array::open(store.clone(), &format!("/{sub}"))
                .map_err(|e| bad(format!("OME-Zarr level {level} ({sub}): {e}")))?;
            let axes = array.shape().len();
            let transform = |kind: &str| {
                transform(dataset, kind, axes)
                    .map_err(|e| bad(format!("OME-Zarr dataset {level} ({sub}): {e}")))
            };
            note = Some(format!(
                "OME-Zarr image: level {level} ({sub}) of levels 0 to {}",
                datasets.len() - 1
            ));
            (array, transform("scale")?, transform("translation")?)
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
    let xyz = |v: &Option<Vec<f64>>| v.as_ref().map(|v| [v[n - 1], v[n - 2], v[n - 3]]);
    if let Some(s) = xyz(&scale) {
        grid.spacing = s;
    }
    grid.notes.extend(note);
    if let Some(t) = xyz(&translation) {
        grid.origin = t;
    }
    let chunk = array
        .chunk_shape(&vec![0; n])
        .map_err(|e| bad(format!("its chunk grid: {e}")))?;
    // zarrs decodes a whole chunk, whatever part of it a read needs.
    let chunk: Vec<u64> = chunk.iter().map(|c| c.get()).collect();
    let samples = chunk.iter().fold(1u128, |a, &c| a.saturating_mul(c.into()));
    crate::limits::bytes(
        samples,
        dtype.size(),
        &format!("a chunk of shape {chunk:?}"),
    )
    .map_err(bad)?;
    let chunk_z = usize::try_from(chunk[n - 3].min(shape[n - 3])).unwrap_or(usize::MAX);
    Ok((
        grid,
        Source {
            array,
            root: path.to_path_buf(),
            chunks: 0,
            missing: 0,
            first_missing: None,
            lead: n - 3,
            chunk_z,
            dtype,
        },
    ))
}

/// Refuses a metadata file in the folder `dir` that is there but is not a regular file.
fn regular_metadata(dir: &Path) -> Result<()> {
    for name in METADATA {
        let file = dir.join(name);
        if std::fs::symlink_metadata(&file).is_ok() {
            crate::input::regular(&file)?;
        }
    }
    Ok(())
}

/// The OME-Zarr coordinate transformation `kind` ("scale" or "translation") of `dataset`, one
/// number per axis of an array of `axes` axes; `None` if the dataset has none.
fn transform(
    dataset: &Value,
    kind: &str,
    axes: usize,
) -> std::result::Result<Option<Vec<f64>>, String> {
    let Some(found) = dataset
        .get("coordinateTransformations")
        .and_then(Value::as_array)
        .and_then(|t| {
            t.iter()
                .find(|t| t.get("type").and_then(Value::as_str) == Some(kind))
        })
    else {
        return Ok(None);
    };
    let value = found.get(kind);
    let numbers = value
        .and_then(Value::as_array)
        .and_then(|v| v.iter().map(Value::as_f64).collect::<Option<Vec<f64>>>())
        .filter(|v| v.len() == axes);
    match numbers {
        Some(v) => Ok(Some(v)),
        None => Err(format!(
            "its `{kind}` transformation is {}, not a list of {axes} numbers (one per axis)",
            value.map_or("missing".into(), Value::to_string)
        )),
    }
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
    pub fn read<T: Sample>(&mut self, path: &Path, z0: usize, z1: usize) -> Result<Vec<T>> {
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
        let subset = ArraySubset::new_with_ranges(&ranges);
        self.look_for_chunks(&subset).map_err(|e| match e {
            Error::File { .. } => e,
            e => error(&e),
        })?;
        let bytes = self
            .array
            .retrieve_array_subset(&subset)
            .map_err(|e| error(&e))?
            .into_fixed()
            .map_err(|e| error(&e))?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

impl Source {
    /// Checks the file of every chunk `subset` needs before zarrs opens it: a chunk file that is
    /// not a regular file is refused, and one that is not there is counted.
    fn look_for_chunks(&mut self, subset: &ArraySubset) -> Result<()> {
        let chunks = self
            .array
            .chunks_in_array_subset(subset)
            .ok()
            .flatten()
            .ok_or_else(|| Error::file(&self.root, "its chunk grid does not cover the array"))?;
        for indices in &chunks.indices() {
            let key = self.array.chunk_key(&indices);
            let file = self.root.join(key.as_str());
            self.chunks += 1;
            match std::fs::metadata(&file) {
                Ok(meta) if meta.is_file() => {}
                Ok(_) => crate::input::regular(&file)?,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                    self.missing += 1;
                    self.first_missing
                        .get_or_insert_with(|| key.as_str().to_owned());
                }
                Err(e) => return Err(Error::io(&file, e)),
            }
        }
        Ok(())
    }

    /// After the last read: a warning that names how many chunks had no file, if any did. A
    /// store none of whose chunks has a file where its metadata puts them, but whose first one
    /// has a file under the other separator (`0/0/0` for `0.0.0`, or the reverse), is refused:
    /// its metadata names the wrong separator, and reading it as all fill value would be wrong.
    pub fn missing_chunks(&self) -> Result<Option<String>> {
        let Some(key) = &self.first_missing else {
            return Ok(None);
        };
        if self.missing == self.chunks {
            // The key is the array's path, then the chunk's part: swap the separators there.
            let prefix = self.array.path().as_str().trim_start_matches('/');
            let prefix = if prefix.is_empty() {
                String::new()
            } else {
                format!("{prefix}/")
            };
            let chunk = key.strip_prefix(&prefix).unwrap_or(key);
            let other: String = chunk
                .chars()
                .map(|c| match c {
                    '.' => '/',
                    '/' => '.',
                    c => c,
                })
                .collect();
            let (said, found) = if chunk.contains('/') {
                ("/", ".")
            } else {
                (".", "/")
            };
            if self.root.join(format!("{prefix}{other}")).is_file() {
                return Err(Error::file(
                    &self.root,
                    format!(
                        "none of its {} chunks is where its metadata puts them (such as {key}), \
                         but {prefix}{other} exists: the chunk files separate their indices with \
                         \"{found}\", not the \"{said}\" the metadata names \
                         (`dimension_separator` in .zarray, `chunk_key_encoding` in zarr.json)",
                        self.chunks
                    ),
                ));
            }
        }
        Ok(Some(format!(
            "{}: {} of its {} chunks have no file (such as {key}) and were read as the fill value",
            self.root.display(),
            self.missing,
            self.chunks
        )))
    }
}
