//! Label shards for the Dask driver (`skelclimb.dask.labels(shards=)`): each task writes its
//! block's share of the atlas through the writer `skelclimb extract --labels --shards` uses
//! (`sc_io::labels::write_block`), and `merge_label_shards` joins any label manifest into what
//! `labels` returns for the whole volume.

use std::fmt::Display;
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

use numpy::{Element, PyUntypedArrayMethods};
use pyo3::BoundObject;
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use sc_io::labels::{LabelSettings, Selection, Stored, join_shards, write_block};
use sc_io::shard::{Manifest, ShardSettings};
use sc_io::space::World;
use sc_io::volume::Dtype;

use crate::label_blocks::{from_python, pairs_of, with_label};
use crate::labels::{Reply, respond};
use crate::shards::{Record, record, write_listing};
use crate::{errors, extract};

/// The settings of every block of one label volume, as `skelclimb.dask.labels` passes them:
/// `(background, mode, pad, spacing, origin, smoothing, affine, space, normals, selection)`,
/// checked there (labels and the background 0 or more, a selection without it).
type LabelArgs = (
    u64,
    String,
    bool,
    [f64; 3],
    [f64; 3],
    f64,
    Option<[[f64; 4]; 3]>,
    Option<String>,
    bool,
    Option<Vec<u64>>,
);

/// The shards' settings for labels of NumPy type `dtype`, and where their meshes go.
fn settings(dtype: &str, args: LabelArgs) -> PyResult<(LabelSettings, World)> {
    let (background, mode, pad, spacing, origin, smoothing, affine, space, normals, selection) =
        args;
    let (spacing, origin, world) = extract::placement(spacing, origin, affine, space.as_deref())?;
    let selection = match selection {
        None => Selection::All,
        Some(ids) => Selection::Only(ids.into_iter().map(|i| i..=i).collect()),
    };
    let dtype = Dtype::from_name(dtype)
        .ok_or_else(|| PyValueError::new_err(format!("shards: no label shards of {dtype}")))?;
    let settings = LabelSettings {
        dtype,
        background,
        mode: extract::mode(&mode)?,
        pad,
        spacing,
        origin,
        smoothing,
        normals,
        selection,
        table: None,
    };
    // Checked as the manifest's reader checks them: a manifest that would not read is not
    // written, nor any shard.
    LabelSettings::from_json(&settings.to_json())
        .map_err(|m| PyValueError::new_err(format!("shards: {m}")))?;
    Ok((settings, world))
}

/// Writes `share` (a tuple from `extract_label_block`) owning `cubes` into `directory`, with the
/// settings it was made with; returns the record the manifest lists it by.
#[pyfunction]
pub fn write_label_shard(
    py: Python<'_>,
    share: Bound<'_, PyAny>,
    directory: PathBuf,
    cubes: [(usize, usize); 3],
    made_with: LabelArgs,
) -> PyResult<Record> {
    let pairs = pairs_of(&share)?;
    let (settings, _) = settings(&pairs.dtype().to_string(), made_with)?;
    let cubes = cubes.map(|(a, b)| a..b);
    with_label!(py, &pairs, "label block pairs", L => {
        let share = from_python::<L>(&share)?;
        let entry = py
            .detach(|| write_block(&directory, cubes, &share, &settings))
            .map_err(errors::io)?;
        Ok(record(entry))
    })
}

/// Writes `directory/manifest.json` for the label shards `records` of a grid of `grid` samples
/// of NumPy type `dtype`, after checking that they cover the grid once; returns its path.
#[pyfunction]
pub fn write_label_manifest(
    directory: PathBuf,
    grid: [usize; 3],
    records: Vec<Record>,
    dtype: &str,
    made_with: LabelArgs,
) -> PyResult<PathBuf> {
    let (settings, world) = settings(dtype, made_with)?;
    let manifest = Manifest {
        grid,
        settings,
        world,
        shards: Vec::new(),
    };
    write_listing(&directory, manifest, records)
}

/// Joins the label shards a manifest lists: what `_native.labels` returns for the whole volume
/// with the manifest's settings.
#[pyfunction]
pub fn merge_label_shards<'py>(
    py: Python<'py>,
    manifest: PathBuf,
) -> PyResult<Bound<'py, PyTuple>> {
    let read = Manifest::<LabelSettings>::read(&manifest).map_err(errors::io)?;
    match read.settings.dtype {
        Dtype::U8 => merged::<u8>(py, &manifest, &read),
        Dtype::U16 => merged::<u16>(py, &manifest, &read),
        Dtype::I16 => merged::<i16>(py, &manifest, &read),
        Dtype::U32 => merged::<u32>(py, &manifest, &read),
        Dtype::I32 => merged::<i32>(py, &manifest, &read),
        // The manifest's reader refuses every other type.
        other => Err(PyValueError::new_err(format!(
            "{}: no label shards of {}",
            manifest.display(),
            other.name()
        ))),
    }
}

fn merged<'py, L>(
    py: Python<'py>,
    path: &Path,
    manifest: &Manifest<LabelSettings>,
) -> PyResult<Bound<'py, PyTuple>>
where
    L: Stored + Element + Display + FromPyObjectOwned<'py> + IntoPyObject<'py>,
{
    let s = &manifest.settings;
    let background = s.background_label::<L>(path).map_err(errors::io)?;
    let atlas = py
        .detach(|| join_shards::<L>(path, manifest))
        .map_err(errors::io)?;
    let selection = match &s.selection {
        Selection::All => None,
        Selection::Only(ranges) => {
            let present = atlas.labels(background, 0);
            let mut wanted = Vec::new();
            for range in ranges {
                let inside = within(range, &present);
                if inside.is_empty() {
                    // Then `respond` reports it missing, as `labels` reports a label the
                    // volume lacks.
                    wanted.push(range.start().into_pyobject(py)?.into_any());
                }
                for l in inside {
                    wanted.push(
                        l.into_pyobject(py)
                            .map_err(Into::into)?
                            .into_bound()
                            .into_any(),
                    );
                }
            }
            Some(wanted)
        }
    };
    let reply = Reply {
        dims: manifest.grid,
        world: manifest.world,
        background,
        mode: s.mode.name(),
        normals: s.normals,
        // A call in the user's process, as `labels` is: every core.
        threads: 0,
        selection,
    };
    respond(py, atlas, reply)
}

/// The labels of `present` in `range`.
fn within<L: Stored>(range: &RangeInclusive<u64>, present: &[L]) -> Vec<L> {
    let id = |l: L| l.try_into().ok().and_then(|v: i64| u64::try_from(v).ok());
    present
        .iter()
        .copied()
        .filter(|&l| id(l).is_some_and(|i| range.contains(&i)))
        .collect()
}
