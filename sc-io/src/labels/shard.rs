//! Shards of a label volume: each block's share of the atlas (`sc_runtime::labels::AtlasBlock`)
//! in a file of its own, plus a manifest, in the envelope of [`crate::shard`] with `kind`
//! `labels`; [`merge_shards`] joins them into exactly the meshes [`extract`](super::extract)
//! makes of the whole volume.
//!
//! A label shard holds `header`, `keys`, `positions`, `triangles` and `cubes` as a surface shard
//! does, and instead of `normals` (an atlas has none: each label's mesh gets its own when it is
//! cut out), `pairs`: `(T, 2)` in the label type the sweep ran on, each triangle's two labels.
//! The manifest's settings hold the sweep's parameters, which every shard repeats and is checked
//! by, and what only the merge uses: the selection, whether meshes get normals, and the label
//! table (names and colours), which the shards leave out.

use std::ops::Range;
use std::path::Path;

use sc_runtime::labels::{Atlas, AtlasBlock, Label as Sample, LabelParams, extract_block};
use sc_runtime::{Mode, Volume};
use serde_json::{Value, json};

use super::mesh::{self, LabelMeshes, LabelRequest, Selection};
use super::{Label, LabelTable};
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::shard::{
    self, Header, MANIFEST_NAME, Manifest, ShardEntry, ShardFile, ShardSettings, put, rows,
};
use crate::slabs::Joiner;
use crate::space::World;
use crate::volume::{Dtype, Grid, Samples, cut};

/// How a label volume's shards were made, and what its manifest asks of the merge.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelSettings {
    /// The label type the sweep ran on (8-bit signed volumes run as `i16`); the shards' pairs
    /// are stored in it.
    pub dtype: Dtype,
    /// The label of no region ([`LabelRequest::background`]).
    pub background: u64,
    /// Which steps run.
    pub mode: Mode,
    /// Whether the volume is meshed padded.
    pub pad: bool,
    /// World distance between samples along x, y, z.
    pub spacing: [f64; 3],
    /// World position of sample (0, 0, 0) as the sweep applied it.
    pub origin: [f64; 3],
    /// Gaussian width of the smoothing along edges, 0 for midpoints.
    pub smoothing: f64,
    /// The merge's: whether the meshes get normals.
    pub normals: bool,
    /// The merge's: which labels get a mesh.
    pub selection: Selection,
    /// The merge's: the labels' names and colours, if a table was given or found.
    pub table: Option<LabelTable>,
}

/// The label types a sweep runs on, by name.
const DTYPES: [Dtype; 5] = [Dtype::U8, Dtype::I16, Dtype::U16, Dtype::U32, Dtype::I32];

impl LabelSettings {
    /// The settings of shards swept with `params` on labels of type `dtype`, for `request`.
    fn new<L: Sample + TryInto<i64>>(
        dtype: Dtype,
        params: &LabelParams<L>,
        request: &LabelRequest,
        table: Option<&LabelTable>,
    ) -> LabelSettings {
        LabelSettings {
            dtype,
            background: request.background,
            mode: params.mode,
            pad: params.pad,
            spacing: params.spacing,
            origin: params.origin,
            smoothing: params.smoothing,
            normals: request.normals,
            selection: request.selection.clone(),
            table: table.cloned(),
        }
    }

    /// The background as a label of type `L`, the label type of the manifest at `path`; a
    /// background that does not fit it is a bad manifest.
    pub fn background_label<L: TryFrom<u64>>(&self, path: &Path) -> Result<L> {
        L::try_from(self.background).map_err(|_| {
            Error::file(
                path,
                format!(
                    "not a shard manifest: background {} does not fit its {} labels",
                    self.background,
                    self.dtype.name()
                ),
            )
        })
    }

    /// The request the merge cuts the meshes by.
    fn request(&self) -> LabelRequest {
        LabelRequest {
            background: self.background,
            mode: self.mode,
            normals: self.normals,
            threads: 1,
            coordinates: crate::space::Coordinates::Index,
            selection: self.selection.clone(),
            smoothing: self.smoothing,
        }
    }
}

impl ShardSettings for LabelSettings {
    const KIND: &'static str = "labels";

    fn to_json(&self) -> Value {
        let table = self.table.as_ref().map(|t| {
            t.iter()
                .map(|(id, l)| json!({ "id": id, "name": l.name, "rgb": l.rgb }))
                .collect::<Vec<_>>()
        });
        json!({
            "labels": self.dtype.name(),
            "background": self.background,
            "mode": self.mode.name(),
            "pad": self.pad,
            "spacing": self.spacing,
            "origin": self.origin,
            "smoothing": self.smoothing,
            "normals": self.normals,
            "selection": self.selection.to_string(),
            "table": table,
        })
    }

    fn from_json(v: &Value) -> std::result::Result<Self, String> {
        let dtype = v["labels"]
            .as_str()
            .and_then(Dtype::from_name)
            .filter(|d| DTYPES.contains(d))
            .ok_or_else(|| {
                format!(
                    "settings: labels {} is not a label type ({})",
                    v["labels"],
                    DTYPES.map(Dtype::name).join(", ")
                )
            })?;
        let mode = v["mode"]
            .as_str()
            .ok_or("settings: no mode")?
            .parse::<Mode>()
            .map_err(|e| format!("settings: mode {}: {e}", v["mode"]))?;
        let flag = |name: &str| {
            v[name]
                .as_bool()
                .ok_or_else(|| format!("settings: {name} {} is not true or false", v[name]))
        };
        let smoothing = v["smoothing"]
            .as_f64()
            .filter(|w| (0.0..=sc_runtime::labels::MAX_SMOOTHING).contains(w))
            .ok_or_else(|| format!("settings: smoothing {} is not a width", v["smoothing"]))?;
        let selection = v["selection"]
            .as_str()
            .ok_or("settings: no selection")
            .map(Selection::parse)?
            .map_err(|e| format!("settings: selection: {e}"))?;
        let table = match &v["table"] {
            Value::Null => None,
            t => Some(table_from_json(t).ok_or_else(|| format!("settings: a bad table {t}"))?),
        };
        Ok(LabelSettings {
            dtype,
            background: v["background"].as_u64().ok_or_else(|| {
                format!("settings: background {} is not a label", v["background"])
            })?,
            mode,
            pad: flag("pad")?,
            spacing: shard::coordinates(&v["spacing"], "settings: spacing")?,
            origin: shard::coordinates(&v["origin"], "settings: origin")?,
            smoothing,
            normals: flag("normals")?,
            selection,
            table,
        })
    }

    /// The table is the manifest's alone: a shard does not need it, and it can be long.
    fn in_shards(&self) -> Self {
        LabelSettings {
            table: None,
            ..self.clone()
        }
    }

    /// Saturating: a manifest's grid may be any number, and one this large is refused by the
    /// cover check, not wrapped.
    fn key_grid(&self, grid: [usize; 3]) -> [usize; 3] {
        grid.map(|n| n.saturating_add(2 * usize::from(self.pad)))
    }
}

fn table_from_json(v: &Value) -> Option<LabelTable> {
    v.as_array()?
        .iter()
        .map(|l| {
            let rgb = match &l["rgb"] {
                Value::Null => None,
                c => Some(match c.as_array()?.as_slice() {
                    [r, g, b] => [r, g, b].map(|x| x.as_u64().and_then(|n| u8::try_from(n).ok())),
                    _ => return None,
                })
                .map(|[r, g, b]| Some([r?, g?, b?]))?,
            };
            let label = Label {
                name: l["name"].as_str()?.to_owned(),
                rgb,
            };
            Some((l["id"].as_u64()?, label))
        })
        .collect()
}

/// Meshes the label volume `grid` in blocks of up to `block` cubes per axis and writes each
/// block's share of the atlas to its own shard in `dir` (made if missing), then the manifest;
/// [`merge_shards`] joins them into exactly [`extract`](super::extract)'s meshes. The blocks are
/// meshed one after another; `table` travels in the manifest.
pub fn extract_shards(
    grid: &Grid,
    request: &LabelRequest,
    table: Option<&LabelTable>,
    block: usize,
    dir: &Path,
    progress: &dyn Progress,
) -> Result<Manifest<LabelSettings>> {
    mesh::check_scale(grid)?;
    let world = World::new(grid.frame, grid.origin, request.coordinates);
    let job = Job {
        grid,
        request,
        table,
        world,
        block,
        dir,
        progress,
    };
    match &grid.samples {
        Samples::U8(v) => job.run(Dtype::U8, v),
        Samples::I8(v) => {
            let wide: Vec<i16> = v.iter().map(|&l| i16::from(l)).collect();
            job.run(Dtype::I16, &wide)
        }
        Samples::U16(v) => job.run(Dtype::U16, v),
        Samples::I16(v) => job.run(Dtype::I16, v),
        Samples::U32(v) => job.run(Dtype::U32, v),
        Samples::I32(v) => job.run(Dtype::I32, v),
        Samples::F32(_) | Samples::F64(_) => Err(mesh::not_integers(grid)),
    }
}

/// [`extract_shards`]'s arguments.
struct Job<'a> {
    grid: &'a Grid,
    request: &'a LabelRequest,
    table: Option<&'a LabelTable>,
    world: World,
    block: usize,
    dir: &'a Path,
    progress: &'a dyn Progress,
}

/// A label type shards store (their `pairs`): one NumPy has.
pub trait Stored:
    Sample + TryFrom<u64> + TryInto<i64> + npyz::AutoSerialize + npyz::Deserialize
{
}
impl<L: Sample + TryFrom<u64> + TryInto<i64> + npyz::AutoSerialize + npyz::Deserialize> Stored
    for L
{
}

impl Job<'_> {
    fn run<L: Stored>(self, dtype: Dtype, data: &[L]) -> Result<Manifest<LabelSettings>> {
        let dims = self.grid.dims;
        let params = mesh::params::<L>(self.grid, self.request, &self.world)?;
        // The merge's refusals of the selection, before any shard is written: padded, every
        // label a sample holds has a surface, so the samples tell which the atlas will hold.
        // Runs of one label are skipped, which leaves the set little to do.
        let mut present = std::collections::BTreeSet::new();
        for run in data.chunk_by(|a, b| a == b) {
            present.insert(run[0]);
        }
        present.remove(&params.background);
        let present: Vec<L> = present.into_iter().collect();
        mesh::chosen(&present, self.request)?;
        let manifest = Manifest {
            grid: dims,
            settings: LabelSettings::new(dtype, &params, self.request, self.table),
            world: self.world,
            shards: Vec::new(),
        };
        write_blocks(data, &params, manifest, self.block, self.dir, self.progress)
    }
}

/// Meshes the volume `data` of `manifest.grid` samples swept with `params` in blocks of up to
/// `block` cubes per axis, writes their shards into `dir`, lists them in `manifest` and writes
/// it.
fn write_blocks<L: Stored>(
    data: &[L],
    params: &LabelParams<L>,
    mut manifest: Manifest<LabelSettings>,
    block: usize,
    dir: &Path,
    progress: &dyn Progress,
) -> Result<Manifest<LabelSettings>> {
    let dims = manifest.grid;
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let cubes = manifest.settings.key_grid(dims).map(|n| n - 1);
    progress.phase("meshing labels", shard::blocks(cubes, block).count() as u64);
    for cubes in shard::blocks(cubes, block) {
        let need = sc_runtime::labels::block_samples(dims, cubes.clone(), params)?;
        let samples = cut(data, dims, &need);
        let at = need.clone().map(|r| r.start);
        let volume = Volume::new(&samples, need.map(|r| r.len()))?;
        let share = extract_block(volume, at, dims, cubes.clone(), params)?;
        let entry = write_block(dir, cubes, &share, &manifest.settings)?;
        manifest.shards.push(entry);
        progress.inc(1);
    }
    manifest.write(&dir.join(MANIFEST_NAME))?;
    Ok(manifest)
}

/// Writes `share`, owning `cubes` and swept with `settings` (of its label type), to its shard
/// file in `dir`, whole or not at all, and returns the manifest's entry for it: the one writer of
/// label shards, for the command line and Python's Dask driver.
pub fn write_block<L: Stored>(
    dir: &Path,
    cubes: [Range<usize>; 3],
    share: &AtlasBlock<L>,
    settings: &LabelSettings,
) -> Result<ShardEntry> {
    let entry = ShardEntry {
        file: ShardEntry::file_name(&cubes),
        cubes,
        vertices: share.keys.len() as u64,
        triangles: share.triangles.len() as u64,
    };
    write_shard(&dir.join(&entry.file), share, settings)?;
    Ok(entry)
}

/// Writes `share`, swept with `settings`, to the shard file `path`, whole or not at all.
fn write_shard<L: Stored>(
    path: &Path,
    share: &AtlasBlock<L>,
    settings: &LabelSettings,
) -> Result<()> {
    let header = Header {
        grid: share.grid,
        settings: settings.clone(),
        stats: share.stats,
        covered: share.covered,
    };
    shard::write_file(path, &header, |npz| {
        put(npz, "keys", &[share.keys.len()], &share.keys)?;
        put(
            npz,
            "positions",
            &[share.positions.len(), 3],
            share.positions.as_flattened(),
        )?;
        put(
            npz,
            "triangles",
            &[share.triangles.len(), 3],
            share.triangles.as_flattened(),
        )?;
        put(
            npz,
            "pairs",
            &[share.pairs.len(), 2],
            share.pairs.as_flattened(),
        )?;
        put(npz, "cubes", &[share.cubes.len()], &share.cubes)
    })
}

/// Reads the shard `entry` of `manifest` names, and checks that it is that block of that atlas.
fn read_checked<L: Stored>(
    path: &Path,
    entry: &ShardEntry,
    manifest: &Manifest<LabelSettings>,
) -> Result<AtlasBlock<L>> {
    let (mut file, header) = ShardFile::open::<LabelSettings>(path)?;
    // The settings first: the pairs are read in the label type they name.
    shard::check_entry(
        path,
        entry,
        manifest,
        &header,
        [entry.vertices, entry.triangles],
        &[],
    )?;
    let pairs: Vec<L> = file.array("pairs", 2)?;
    let share = AtlasBlock {
        grid: header.grid,
        pad: header.settings.pad,
        keys: file.array("keys", 1)?,
        positions: rows(file.array("positions", 3)?),
        triangles: rows(file.array("triangles", 3)?),
        pairs: pairs.chunks_exact(2).map(|p| [p[0], p[1]]).collect(),
        cubes: file.array("cubes", 1)?,
        stats: header.stats,
        covered: header.covered,
    };
    share.check().map_err(|e| file.bad(&e.to_string()))?;
    file.check_finite("positions", &share.positions)?;
    let counts = [share.keys.len(), share.triangles.len()].map(|n| n as u64);
    shard::check_entry(path, entry, manifest, &header, counts, &share.cubes)?;
    Ok(share)
}

/// Joins the label shards the manifest at `manifest_path` lists and cuts the meshes it asks
/// for: exactly what [`extract`](super::extract) gives for the whole volume, placed as the
/// manifest says. Holds about the atlas plus one shard at a time.
pub fn merge_shards(manifest_path: &Path) -> Result<(Manifest<LabelSettings>, LabelMeshes)> {
    let manifest = Manifest::<LabelSettings>::read(manifest_path)?;
    let out = match manifest.settings.dtype {
        Dtype::U8 => merge_typed::<u8>(manifest_path, &manifest),
        Dtype::U16 => merge_typed::<u16>(manifest_path, &manifest),
        Dtype::I16 => merge_typed::<i16>(manifest_path, &manifest),
        Dtype::U32 => merge_typed::<u32>(manifest_path, &manifest),
        Dtype::I32 => merge_typed::<i32>(manifest_path, &manifest),
        other => unreachable!("{other:?} is refused when the manifest is read"),
    }?;
    let out = mesh::placed(out, &manifest.world);
    Ok((manifest, out))
}

fn merge_typed<L: Stored>(path: &Path, manifest: &Manifest<LabelSettings>) -> Result<LabelMeshes> {
    let settings = &manifest.settings;
    let background = settings.background_label::<L>(path)?;
    let atlas = join_shards::<L>(path, manifest)?;
    mesh::select(atlas, background, &settings.request()).map_err(|e| match e {
        Error::Usage(message) => Error::file(path, message),
        e => e,
    })
}

/// Joins the label shards `manifest` (read from `path`) lists into the atlas of the whole
/// volume, before any placement or selection: for a front end that cuts the meshes itself.
/// `L` is the manifest's label type ([`LabelSettings::dtype`]), which the caller dispatches on
/// (pairs of another type do not read). Holds about the atlas plus one shard at a time.
pub fn join_shards<L: Stored>(path: &Path, manifest: &Manifest<LabelSettings>) -> Result<Atlas<L>> {
    let at_manifest = |e: sc_runtime::Error| Error::file(path, e.to_string());
    let mut shares = Joiner::default();
    for entry in &manifest.shards {
        let share = read_checked::<L>(&shard::shard_path(path, entry), entry, manifest)?;
        shares.push(share).map_err(at_manifest)?;
    }
    let mut joined = shares.finish().map_err(at_manifest)?;
    if joined.grid == [0; 3] {
        (joined.grid, joined.pad) = (manifest.grid, manifest.settings.pad);
    }
    joined.into_atlas().map_err(at_manifest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::labels::stream::tests::{params, volume};
    use crate::progress::Silent;
    use crate::space::Coordinates;
    use sc_runtime::labels::extract_labels;

    /// Shards of every block size join into the meshes and counts of the whole volume, padded
    /// or not (the command line always pads), smoothed or not, with a background inside the
    /// volume; the manifest, table and selection included, reads back as written.
    #[test]
    fn shards_padded_or_not_merge_into_the_whole_meshes() {
        let dims = [9, 7, 23];
        let labels = volume(dims, 5);
        let table: LabelTable = [(3, "three", Some([1, 2, 3])), (5, "", None)]
            .into_iter()
            .map(|(id, name, rgb)| {
                let label = Label {
                    name: name.into(),
                    rgb,
                };
                (id, label)
            })
            .collect();
        for (pad, smoothing, background, selection) in [
            (true, 0.0, 0, Selection::All),
            (false, 0.0, 0, Selection::parse("1-3,5").unwrap()),
            (false, 1.5, 2, Selection::All),
            (true, 0.75, 3, Selection::parse("0,4-6").unwrap()),
        ] {
            let params = params(pad, Mode::Embedded, smoothing, background);
            let request = LabelRequest {
                background: u64::from(background),
                mode: params.mode,
                normals: true,
                threads: 1,
                coordinates: Coordinates::Index,
                selection,
                smoothing,
            };
            let whole = extract_labels(Volume::new(&labels, dims).unwrap(), &params).unwrap();
            let whole = mesh::select(whole, background, &request).unwrap();
            assert!(whole.meshes.len() >= 3 && whole.stats.merged > 0);
            for block in [3, 8, 40] {
                let dir = tempfile::tempdir().unwrap();
                let manifest = Manifest {
                    grid: dims,
                    settings: LabelSettings::new(Dtype::U16, &params, &request, Some(&table)),
                    world: World::new(None, params.origin, Coordinates::Index),
                    shards: Vec::new(),
                };
                let written =
                    write_blocks(&labels, &params, manifest, block, dir.path(), &Silent).unwrap();
                let (read, merged) = merge_shards(&dir.path().join(MANIFEST_NAME)).unwrap();
                assert_eq!(read, written);
                assert!(
                    merged.meshes == whole.meshes && merged.stats == whole.stats,
                    "pad {pad}, smoothing {smoothing}, background {background}, blocks of {block}"
                );
            }
        }
    }
}
