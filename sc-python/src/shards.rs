//! Shard files for the Dask driver: each task writes its block's share through the same writer
//! as `skelclimb extract --shards` and returns a small record, so that no worker holds the mesh;
//! one definition of the format (`sc_io::shard`) serves the command line and Python.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use pyo3::types::PyTuple;
use sc_io::shard::{self, MANIFEST_NAME, Manifest, Settings, ShardEntry, ShardSettings};

use crate::blocks::from_python;
use crate::convert;
use crate::errors;
use crate::extract::params;

/// A manifest's record of one shard: `(file, cubes, vertices, triangles)`, what a task returns
/// instead of its share (of either kind).
pub type Record = (String, [(usize, usize); 3], u64, u64);

/// The settings of every block of one mesh, as `skelclimb.dask` passes them: `(level, spacing,
/// origin, mode, normals, max_error)`, the arguments of `extract_block` in its order.
type SettingsArgs = (f64, [f64; 3], [f64; 3], String, bool, Option<(f64, String)>);

fn settings(
    (level, spacing, origin, mode, normals, max_error): SettingsArgs,
) -> PyResult<sc_runtime::Params> {
    params(level, spacing, origin, &mode, normals, max_error)
}

/// Writes `share` (a tuple from `extract_block`) owning `cubes` into `directory`, with the
/// settings it was made with; returns the record the manifest lists it by.
#[pyfunction]
pub fn write_shard(
    py: Python<'_>,
    share: Bound<'_, PyAny>,
    directory: PathBuf,
    cubes: [(usize, usize); 3],
    made_with: SettingsArgs,
) -> PyResult<Record> {
    let settings = Settings::from(&settings(made_with)?);
    let block = from_python(&share)?;
    let cubes = cubes.map(|(a, b)| a..b);
    let file = ShardEntry::file_name(&cubes);
    let entry = ShardEntry::new(file, cubes, &block);
    py.detach(|| shard::write_shard(&directory.join(&entry.file), &block, &settings))
        .map_err(errors::io)?;
    Ok(record(entry))
}

pub fn record(e: ShardEntry) -> Record {
    (
        e.file,
        e.cubes.map(|r| (r.start, r.end)),
        e.vertices,
        e.triangles,
    )
}

/// Writes `directory/manifest.json` for the shards `records` of a grid of `grid` samples, after
/// checking that they cover the grid once; returns its path.
#[pyfunction]
pub fn write_manifest(
    directory: PathBuf,
    grid: [usize; 3],
    records: Vec<Record>,
    made_with: SettingsArgs,
) -> PyResult<PathBuf> {
    write_listing(
        &directory,
        Manifest::new(grid, &settings(made_with)?),
        records,
    )
}

/// Writes `manifest`, listing the shards `records`, into `directory` (of any kind of shards);
/// returns its path.
pub fn write_listing<S: ShardSettings>(
    directory: &Path,
    mut manifest: Manifest<S>,
    records: Vec<Record>,
) -> PyResult<PathBuf> {
    manifest.shards = records
        .into_iter()
        .map(|(file, cubes, vertices, triangles)| ShardEntry {
            file,
            cubes: cubes.map(|(a, b)| a..b),
            vertices,
            triangles,
        })
        .collect();
    let path = directory.join(MANIFEST_NAME);
    manifest.write(&path).map_err(errors::io)?;
    // Read back: the same checks `merge` makes, now rather than on another machine later.
    Manifest::<S>::read(&path).map_err(errors::io)?;
    Ok(path)
}

/// The kind of shards the manifest at `manifest` lists: `"surface"` or `"labels"`.
#[pyfunction]
pub fn shard_kind(manifest: PathBuf) -> PyResult<String> {
    shard::kind(&manifest).map_err(errors::io)
}

/// Joins the shards a manifest lists: `(vertices, faces, normals or None, stats)`.
#[pyfunction]
pub fn merge_shards<'py>(py: Python<'py>, manifest: PathBuf) -> PyResult<Bound<'py, PyTuple>> {
    let (manifest, mesh) = py.detach(|| shard::merge(&manifest)).map_err(errors::io)?;
    let s = &manifest.settings;
    let stats = crate::extract::stats(
        py,
        &mesh.stats,
        s.mode.name(),
        s.iso,
        manifest.grid,
        manifest.world.space,
    )?;
    let normals = match s.normals {
        true => Some(convert::rows(py, mesh.normals)?),
        false => None,
    };
    (
        convert::rows(py, mesh.positions)?,
        convert::rows(py, mesh.triangles)?,
        normals,
        stats,
    )
        .into_pyobject(py)
}
