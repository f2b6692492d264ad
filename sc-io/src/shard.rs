//! Shards: one block's share of a mesh in a file of its own, plus a manifest listing them, for
//! meshes too large for one machine. Workers write shards and keep nothing; [`merge`] joins them
//! on a machine that can hold the result, into exactly the mesh one process makes.
//!
//! A shard is a NumPy `.npz` archive (uncompressed, as `numpy.savez` writes), so NumPy and
//! anything that reads `.npy` can open it without this crate. It holds exactly a
//! [`BlockMesh`]:
//!
//! | array       | dtype   | shape    | content                                               |
//! |-------------|---------|----------|-------------------------------------------------------|
//! | `header`    | `uint8` | `(n,)`   | UTF-8 JSON: format, version, grid, settings, counts   |
//! | `keys`      | `<u8`   | `(V,)`   | global edge keys of the vertices, strictly increasing |
//! | `positions` | `<f4`   | `(V, 3)` | vertex positions                                      |
//! | `normals`   | `<f4`   | `(V, 3)` | unit normals, or `(0, 3)` without normals             |
//! | `triangles` | `<u4`   | `(T, 3)` | indices into `keys`                                   |
//! | `cubes`     | `<u8`   | `(T,)`   | each triangle's owning cube key, non-decreasing       |
//!
//! The header is JSON rather than more arrays so that a person (or `json.loads(bytes(h))`) can
//! read what a shard is without knowing the key packing. The manifest, `manifest.json` beside
//! the shards, names the format and version, the grid, the settings, where the mesh's
//! coordinates are, and each shard's file and cubes; [`merge`] checks every shard against it, so
//! a missing, damaged, foreign or duplicated shard is reported by file name instead of giving a
//! wrong mesh.
//!
//! Manifests and shards name their `kind`: `surface` for the iso surfaces above (the kind of
//! files that name none, written before label shards existed), `labels` for a label volume's
//! atlas ([`crate::labels::extract_shards`]; its shards hold `pairs` instead of `normals`). The envelope —
//! manifest, header, cover and entry checks — is this module's for both, through
//! [`ShardSettings`].

use std::io::{self, BufReader, Read, Seek, Write};
use std::ops::Range;
use std::path::{Path, PathBuf};

use npyz::WriterBuilder;
use npyz::npz::{NpzArchive, NpzWriter};
use sc_runtime::{BlockMesh, ErrorBound, Mesh, Mode, Params, Stats};
use serde_json::{Value, json};

use crate::atomic::AtomicFile;
use crate::error::{Error, Result};
use crate::limits;
use crate::report;
use crate::space::{Space, World};

/// The `format` field of a manifest.
const MANIFEST_FORMAT: &str = "skelclimb-shards";
/// The `format` field of a shard's header.
const SHARD_FORMAT: &str = "skelclimb-shard";
/// The version of both; a reader refuses others rather than guess.
const VERSION: u64 = 1;
/// The manifest's file name inside a shard directory.
pub const MANIFEST_NAME: &str = "manifest.json";
/// The kind of files written before kinds were named.
const SURFACE: &str = "surface";

/// What one kind of shards records of how they were made: every shard of a manifest must have
/// been made with its manifest's settings.
pub trait ShardSettings: Clone + PartialEq + std::fmt::Debug + Sized {
    /// The `kind` field of manifests and shard headers.
    const KIND: &'static str;
    /// The settings as JSON.
    fn to_json(&self) -> Value;
    /// The settings `v` holds, or what is wrong with them.
    fn from_json(v: &Value) -> std::result::Result<Self, String>;
    /// The part of the settings each shard records, which is what it is checked by (the
    /// manifest may record more, that only the merge uses).
    fn in_shards(&self) -> Self {
        self.clone()
    }
    /// Samples along x, y, z of the grid whose cubes the shards own and name by key (the
    /// volume's, unless the meshing pads it).
    fn key_grid(&self, grid: [usize; 3]) -> [usize; 3] {
        grid
    }
}

/// What every block of one mesh must share besides the grid: the extractor's parameters (the
/// case tables excepted, which a file cannot name). A type of its own rather than [`Params`]
/// because it must compare (a shard's against its manifest's) and round-trip through JSON,
/// which the `&'static` tables forbid; each field is the [`Params`] field of the same name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// The iso value in stored units ([`Params::iso`]).
    pub iso: f64,
    /// Which steps run.
    pub mode: Mode,
    /// Whether vertices carry normals.
    pub normals: bool,
    /// World distance between samples along x, y, z.
    pub spacing: [f64; 3],
    /// World position of sample (0, 0, 0) as the extractor applied it.
    pub origin: [f64; 3],
    /// Step 4's bound, if any.
    pub max_error: Option<ErrorBound>,
    /// Adaptive mode's largest box, if given: shares made with other boxes do not join.
    pub max_box: Option<u32>,
    /// Adaptive mode: whether boxes may leave samples on the wrong side.
    pub allow_wrong_side: bool,
}

impl From<&Params> for Settings {
    fn from(p: &Params) -> Settings {
        Settings {
            iso: p.iso,
            mode: p.mode,
            normals: p.normals,
            spacing: p.spacing,
            origin: p.origin,
            max_error: p.max_error,
            max_box: p.max_box,
            allow_wrong_side: p.allow_wrong_side,
        }
    }
}

impl Settings {
    /// The parameters these settings describe, with the default case tables.
    pub fn params(&self) -> Params {
        Params {
            mode: self.mode,
            normals: self.normals,
            spacing: self.spacing,
            origin: self.origin,
            max_error: self.max_error,
            max_box: self.max_box,
            allow_wrong_side: self.allow_wrong_side,
            ..Params::new(self.iso)
        }
    }
}

impl ShardSettings for Settings {
    const KIND: &'static str = SURFACE;

    fn to_json(&self) -> Value {
        json!({
            "iso": self.iso,
            "mode": self.mode.name(),
            "normals": self.normals,
            "spacing": self.spacing,
            "origin": self.origin,
            "max_error": self.max_error.map(report::bound),
            "max_box": self.max_box,
            "allow_wrong_side": self.allow_wrong_side,
        })
    }

    /// An unknown mode or units name lists the valid ones, and every number must be one the
    /// extractor can use ([`limits`]).
    fn from_json(v: &Value) -> std::result::Result<Settings, String> {
        let mode = v["mode"]
            .as_str()
            .ok_or("settings: no mode")?
            .parse::<Mode>()
            .map_err(|e| format!("settings: mode {}: {e}", v["mode"]))?;
        let max_error = match &v["max_error"] {
            Value::Null => None,
            b => {
                let value = b["value"]
                    .as_f64()
                    .filter(|x| x.is_finite() && *x >= 0.0)
                    .ok_or_else(|| format!("settings: max_error {b} has no finite value"))?;
                let units = b["units"]
                    .as_str()
                    .ok_or_else(|| format!("settings: max_error {b} has no units"))?
                    .parse()
                    .map_err(|e| format!("settings: max_error units {}: {e}", b["units"]))?;
                Some(ErrorBound::new(value, units))
            }
        };
        let iso = v["iso"]
            .as_f64()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("settings: iso {} is not a finite number", v["iso"]))?;
        let normals = v["normals"].as_bool().ok_or("settings: no normals flag")?;
        // Absent in shards written before adaptive mode ran in blocks: the defaults.
        let max_box = match &v["max_box"] {
            Value::Null => None,
            b => Some(
                b.as_u64()
                    .and_then(|n| u32::try_from(n).ok())
                    .filter(|n| n.is_power_of_two())
                    .ok_or_else(|| format!("settings: max_box {b} is not a power of two"))?,
            ),
        };
        let allow_wrong_side = match &v["allow_wrong_side"] {
            Value::Null => false,
            b => b
                .as_bool()
                .ok_or_else(|| format!("settings: allow_wrong_side {b} is not true or false"))?,
        };
        Ok(Settings {
            iso,
            mode,
            normals,
            spacing: coordinates(&v["spacing"], "settings: spacing")?,
            origin: coordinates(&v["origin"], "settings: origin")?,
            max_error,
            max_box,
            allow_wrong_side,
        })
    }
}

/// Three numbers at `v`, each a coordinate the extractor can use ([`limits::triple`]).
pub(crate) fn coordinates(v: &Value, what: &str) -> std::result::Result<[f64; 3], String> {
    triple(v)
        .ok_or_else(|| format!("{what} {v}: {}", limits::THREE_COORDINATES))
        .and_then(|t| limits::triple(t).map_err(|e| format!("{what} {v}: {e}")))
}

fn triple(v: &Value) -> Option<[f64; 3]> {
    match v.as_array()?.as_slice() {
        [a, b, c] => Some([a.as_f64()?, b.as_f64()?, c.as_f64()?]),
        _ => None,
    }
}

fn usizes(v: &Value) -> Option<[usize; 3]> {
    match v.as_array()?.as_slice() {
        [a, b, c] => Some([a, b, c].map(|x| x.as_u64().and_then(|n| usize::try_from(n).ok()))),
        _ => None,
    }
    .and_then(|[a, b, c]| Some([a?, b?, c?]))
}

/// One shard as the manifest lists it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShardEntry {
    /// The file's name, in the manifest's directory.
    pub file: String,
    /// The cubes the block owns (lower corners, per axis x, y, z).
    pub cubes: [Range<usize>; 3],
    /// Vertices in the shard, to tell a shard from another block's with the same name.
    pub vertices: u64,
    /// Triangles in the shard.
    pub triangles: u64,
}

impl ShardEntry {
    /// The entry for `block`, written to `file`, owning `cubes`.
    pub fn new(file: impl Into<String>, cubes: [Range<usize>; 3], block: &BlockMesh) -> Self {
        ShardEntry {
            file: file.into(),
            cubes,
            vertices: block.keys.len() as u64,
            triangles: block.triangles.len() as u64,
        }
    }

    /// A file name for the block owning `cubes`, unique among the blocks of a grid (blocks do
    /// not share a first cube).
    pub fn file_name(cubes: &[Range<usize>; 3]) -> String {
        format!(
            "block-{}-{}-{}.npz",
            cubes[0].start, cubes[1].start, cubes[2].start
        )
    }

    /// Cubes in the box; the manifest's reader has checked that the box is inside a grid
    /// whose cube count fits in 64 bits, elsewhere it saturates.
    fn count(&self) -> u64 {
        self.cubes
            .iter()
            .fold(1u64, |n, r| n.saturating_mul(r.len() as u64))
    }
}

/// A manifest: the grid, the settings, where the coordinates are, and the shards; of iso
/// surface shards unless `S` says otherwise.
#[derive(Clone, Debug, PartialEq)]
pub struct Manifest<S = Settings> {
    /// Samples of the whole grid along x, y, z.
    pub grid: [usize; 3],
    /// The extractor's settings, the same for every shard.
    pub settings: S,
    /// The map from the shards' positions to the mesh's coordinates; identity plus the origin
    /// unless the volume's file rotates it (then [`merge`] places the joined mesh).
    pub world: World,
    /// The shards, each owning a disjoint box of cubes.
    pub shards: Vec<ShardEntry>,
}

impl Manifest {
    /// A manifest for shards of `grid` extracted with `params`, in index × spacing + origin
    /// coordinates, listing no shard yet.
    pub fn new(grid: [usize; 3], params: &Params) -> Manifest {
        Manifest {
            grid,
            settings: Settings::from(params),
            world: World::new(None, params.origin, crate::space::Coordinates::Index),
            shards: Vec::new(),
        }
    }
}

/// The kind of shards the manifest at `path` lists (`surface` for one that names none), after
/// checking that it is a manifest this version reads; for a reader to choose how to merge.
pub fn kind(path: &Path) -> Result<String> {
    let v = load(path)?;
    kind_of(&v)
        .map(str::to_owned)
        .map_err(|m| Error::file(path, m))
}

/// The `kind` field of a manifest or shard header.
fn kind_of(v: &Value) -> std::result::Result<&str, String> {
    match &v["kind"] {
        Value::Null => Ok(SURFACE),
        k => k
            .as_str()
            .ok_or_else(|| format!("not a shard manifest: its kind {k} is not a name")),
    }
}

/// The manifest at `path` as JSON, if it is one of the version this crate reads.
fn load(path: &Path) -> Result<Value> {
    let mut bytes = Vec::new();
    crate::input::open(path)?
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    let bad = |m: &str| Error::file(path, format!("not a shard manifest: {m}"));
    let v: Value = serde_json::from_slice(&bytes).map_err(|e| bad(&e.to_string()))?;
    if v["format"] != MANIFEST_FORMAT {
        return Err(bad(&format!("its format is not {MANIFEST_FORMAT:?}")));
    }
    if v["version"] != VERSION {
        return Err(Error::file(
            path,
            format!(
                "manifest version {} is not the {VERSION} this skelclimb reads",
                v["version"]
            ),
        ));
    }
    Ok(v)
}

impl<S: ShardSettings> Manifest<S> {
    fn to_json(&self) -> Value {
        json!({
            "format": MANIFEST_FORMAT,
            "version": VERSION,
            "kind": S::KIND,
            "grid": self.grid,
            "settings": self.settings.to_json(),
            "world": {
                "linear": self.world.linear,
                "offset": self.world.offset,
                "space": self.world.space.map(Space::name),
            },
            "shards": self.shards.iter().map(|s| json!({
                "file": s.file,
                "cubes": s.cubes.iter().map(|r| [r.start, r.end]).collect::<Vec<_>>(),
                "vertices": s.vertices,
                "triangles": s.triangles,
            })).collect::<Vec<_>>(),
        })
    }

    /// Writes the manifest to `path`, whole or not at all.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_vec_pretty(&self.to_json()).map_err(io::Error::other);
        AtomicFile::create(path)?.write_with(|out| out.write_all(&text?))
    }

    /// Reads a manifest of shards of this kind and checks that its shards are distinct files
    /// owning disjoint boxes of cubes that together cover the grid.
    pub fn read(path: &Path) -> Result<Manifest<S>> {
        let v = load(path)?;
        let bad = |m: &str| Error::file(path, format!("not a shard manifest: {m}"));
        let kind = kind_of(&v).map_err(|m| Error::file(path, m))?;
        if kind != S::KIND {
            return Err(Error::file(
                path,
                format!(
                    "a manifest of {kind} shards, where {} shards are wanted",
                    S::KIND
                ),
            ));
        }
        let grid = usizes(&v["grid"]).ok_or_else(|| bad("no grid"))?;
        let settings = S::from_json(&v["settings"]).map_err(|m| bad(&m))?;
        let world = world_from_json(&v["world"]).map_err(|m| bad(&m))?;
        let shards = v["shards"]
            .as_array()
            .ok_or_else(|| bad("no list of shards"))?
            .iter()
            .map(|s| entry_from_json(s).ok_or_else(|| bad(&format!("a bad shard entry {s}"))))
            .collect::<Result<Vec<_>>>()?;
        let manifest = Manifest {
            grid,
            settings,
            world,
            shards,
        };
        manifest.check_cover(path)?;
        Ok(manifest)
    }

    /// Every cube of the grid in exactly one listed shard, found from the boxes alone so that
    /// the message can name the files.
    fn check_cover(&self, path: &Path) -> Result<()> {
        let refuse = |m: String| Err(Error::file(path, m));
        let cubes = self
            .settings
            .key_grid(self.grid)
            .map(|n| n.saturating_sub(1));
        let total = cubes.iter().try_fold(1u64, |n, &c| n.checked_mul(c as u64));
        let Some(total) = total else {
            return refuse(format!(
                "a {:?} grid has more cubes than a 64-bit count holds",
                self.grid
            ));
        };
        let mut files = std::collections::HashSet::new();
        for s in &self.shards {
            if !files.insert(s.file.as_str()) {
                return refuse(format!("shard {} is listed twice", s.file));
            }
            for (d, r) in s.cubes.iter().enumerate() {
                if r.start > r.end {
                    return refuse(format!(
                        "shard {}: its cubes along {} run backwards, {}..{}",
                        s.file, AXES[d], r.start, r.end
                    ));
                }
                if r.end > cubes[d] {
                    return refuse(format!(
                        "shard {}: its cubes {}..{} along {} leave the grid, which has cubes 0..{} there",
                        s.file, r.start, r.end, AXES[d], cubes[d]
                    ));
                }
            }
        }
        let boxes: Vec<&ShardEntry> = self.shards.iter().filter(|s| s.count() > 0).collect();
        // Sixteen cells a box: a grid of blocks has one.
        let cell_budget = (16 * boxes.len() as u64).max(1 << 20);
        match overlapping(&boxes, (cell_budget, PAIR_BUDGET)) {
            Ok(None) => {}
            Ok(Some((a, b))) => {
                let both: [Range<usize>; 3] = std::array::from_fn(|d| {
                    a.cubes[d].start.max(b.cubes[d].start)..a.cubes[d].end.min(b.cubes[d].end)
                });
                return refuse(format!(
                    "shards {} and {} both own the cubes {both:?} (x, y, z)",
                    a.file, b.file
                ));
            }
            Err(()) => {
                return refuse(format!(
                    "its {} shards' boxes are too irregular to check for overlaps: shards are \
                     blocks of a grid of blocks",
                    boxes.len()
                ));
            }
        }
        // Disjoint boxes inside the grid: their counts sum to at most `total`.
        let covered: u64 = self.shards.iter().map(ShardEntry::count).sum();
        if covered != total {
            return refuse(format!(
                "the shards cover {covered} of the grid's {total} cubes: blocks are missing"
            ));
        }
        Ok(())
    }
}

/// Axis names for messages.
const AXES: [&str; 3] = ["x", "y", "z"];

/// Pairs of boxes that [`overlapping`] may compare when it cannot mark cells.
const PAIR_BUDGET: u64 = 1 << 26;

/// Two boxes that share a cube, if any. The boxes' boundaries cut the grid into a coarse grid
/// whose cells each lie in one box or none: a grid of blocks has as many cells as blocks, and
/// marking each box's cells finds a shared one in time and memory proportional to the cells.
/// Boundaries that make more than `cell_budget` cells (irregular boxes, which no tool writes)
/// fall back to comparing the pairs whose z ranges meet, up to `pair_budget` pairs; beyond that,
/// `Err`, so that a hostile manifest cannot keep the merge busy for hours.
fn overlapping<'s>(
    boxes: &[&'s ShardEntry],
    (cell_budget, pair_budget): (u64, u64),
) -> std::result::Result<Option<(&'s ShardEntry, &'s ShardEntry)>, ()> {
    let cuts: [Vec<usize>; 3] = std::array::from_fn(|d| {
        let mut c: Vec<usize> = boxes
            .iter()
            .flat_map(|b| [b.cubes[d].start, b.cubes[d].end])
            .collect();
        c.sort_unstable();
        c.dedup();
        c
    });
    let cells = cuts
        .iter()
        .try_fold(1u64, |n, c| n.checked_mul(c.len().saturating_sub(1) as u64));
    if let Some(cells) = cells.filter(|&n| n <= cell_budget) {
        let [nx, ny] = [cuts[0].len() - 1, cuts[1].len() - 1];
        let mut owner = vec![u32::MAX; cells as usize];
        for (i, b) in boxes.iter().enumerate() {
            let span = |d: usize| {
                let at = |v: usize| cuts[d].partition_point(|&c| c < v);
                at(b.cubes[d].start)..at(b.cubes[d].end)
            };
            for z in span(2) {
                for y in span(1) {
                    for x in span(0) {
                        let cell = &mut owner[x + nx * (y + ny * z)];
                        if *cell != u32::MAX {
                            return Ok(Some((boxes[*cell as usize], b)));
                        }
                        *cell = i as u32;
                    }
                }
            }
        }
        return Ok(None);
    }
    let mut by_start = boxes.to_vec();
    by_start.sort_by_key(|s| s.cubes[2].start);
    let mut pairs = 0u64;
    for (i, a) in by_start.iter().enumerate() {
        for b in &by_start[i + 1..] {
            if b.cubes[2].start >= a.cubes[2].end {
                break;
            }
            pairs += 1;
            if pairs > pair_budget {
                return Err(());
            }
            if (0..3).all(|d| overlap(&a.cubes[d], &b.cubes[d])) {
                return Ok(Some((a, b)));
            }
        }
    }
    Ok(None)
}

fn overlap(a: &Range<usize>, b: &Range<usize>) -> bool {
    a.start < b.end && b.start < a.end
}

/// The placement `v` holds, every entry a coordinate the extractor can use ([`limits`]), so
/// that placing a finite mesh cannot overflow unless its own numbers are near `f32`'s end.
fn world_from_json(v: &Value) -> std::result::Result<World, String> {
    let rows = v["linear"]
        .as_array()
        .filter(|r| r.len() == 3)
        .ok_or_else(|| format!("world: linear {} is not three rows", v["linear"]))?;
    let linear = [0, 1, 2].map(|r| coordinates(&rows[r], "world: linear row"));
    let [a, b, c] = linear;
    let space = match &v["space"] {
        Value::Null => None,
        s => Some(match s.as_str() {
            Some("RAS") => Space::Ras,
            Some("LPS") => Space::Lps,
            _ => {
                return Err(format!(
                    "world: space {s} is neither \"RAS\", \"LPS\" nor null"
                ));
            }
        }),
    };
    Ok(World {
        linear: [a?, b?, c?],
        offset: coordinates(&v["offset"], "world: offset")?,
        space,
    })
}

fn entry_from_json(v: &Value) -> Option<ShardEntry> {
    let file = v["file"].as_str()?;
    // Shards live beside their manifest: a path could read any file on the machine.
    if file.is_empty() || file.contains(['/', '\\']) || file == "." || file == ".." {
        return None;
    }
    let cubes = v["cubes"].as_array()?;
    let range = |r: &Value| -> Option<Range<usize>> {
        let [a, b] = [&r[0], &r[1]].map(|x| x.as_u64().and_then(|n| usize::try_from(n).ok()));
        Some(a?..b?)
    };
    let cubes = match cubes.as_slice() {
        [x, y, z] => [range(x)?, range(y)?, range(z)?],
        _ => return None,
    };
    Some(ShardEntry {
        file: file.to_owned(),
        cubes,
        vertices: v["vertices"].as_u64()?,
        triangles: v["triangles"].as_u64()?,
    })
}

/// Writes `block`, meshed with `settings`, to the shard file `path`, whole or not at all.
pub fn write_shard(path: &Path, block: &BlockMesh, settings: &Settings) -> Result<()> {
    let header = Header {
        grid: block.grid,
        settings: *settings,
        stats: block.stats,
        covered: block.covered,
    };
    write_file(path, &header, |npz| {
        put(npz, "keys", &[block.keys.len()], &block.keys)?;
        put(
            npz,
            "positions",
            &[block.positions.len(), 3],
            block.positions.as_flattened(),
        )?;
        put(
            npz,
            "normals",
            &[block.normals.len(), 3],
            block.normals.as_flattened(),
        )?;
        put(
            npz,
            "triangles",
            &[block.triangles.len(), 3],
            block.triangles.as_flattened(),
        )?;
        put(npz, "cubes", &[block.cubes.len()], &block.cubes)
    })
}

/// A shard's header besides its format, version and kind: what every kind of share carries.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Header<S> {
    /// Samples of the whole grid.
    pub grid: [usize; 3],
    /// How the share was made ([`ShardSettings::in_shards`] of the manifest's).
    pub settings: S,
    /// The counts of the owned cubes.
    pub stats: Stats,
    /// Cubes owned.
    pub covered: u64,
}

/// The npz archive a shard is written into.
pub(crate) type ShardWriter<'a, 'b> = NpzWriter<&'a mut io::BufWriter<crate::atomic::Output<'b>>>;

/// Writes a shard of `header`'s kind to `path`, whole or not at all: the header, then the arrays
/// `arrays` [`put`]s.
pub(crate) fn write_file<S: ShardSettings>(
    path: &Path,
    header: &Header<S>,
    arrays: impl FnOnce(&mut ShardWriter<'_, '_>) -> io::Result<()>,
) -> Result<()> {
    let header = json!({
        "format": SHARD_FORMAT,
        "version": VERSION,
        "kind": S::KIND,
        "grid": header.grid,
        "settings": header.settings.in_shards().to_json(),
        "stats": stats_json(&header.stats),
        "covered": header.covered,
    });
    let header = serde_json::to_vec(&header).map_err(io::Error::other);
    AtomicFile::create(path)?.write_with(|out| {
        let header = header?;
        let mut npz = NpzWriter::new(out);
        put(&mut npz, "header", &[header.len()], &header)?;
        arrays(&mut npz)?;
        npz.zip_writer().finish().map_err(io::Error::other)?;
        Ok(())
    })
}

/// The seven counts by name ([`Stats::NAMES`]).
fn stats_json(s: &Stats) -> Value {
    Value::Object(
        Stats::NAMES
            .iter()
            .zip(s.to_array())
            .map(|(name, n)| (name.to_string(), n.into()))
            .collect(),
    )
}

fn stats_from_json(v: &Value) -> Option<Stats> {
    let mut counts = [0; 7];
    for (n, name) in counts.iter_mut().zip(Stats::NAMES) {
        *n = v[name].as_u64()?;
    }
    Some(Stats::from_array(counts))
}

pub(crate) fn put<T, W>(
    npz: &mut NpzWriter<W>,
    name: &str,
    shape: &[usize],
    data: &[T],
) -> io::Result<()>
where
    T: npyz::AutoSerialize + Copy,
    W: Write + Seek,
{
    let options = npyz::zip::write::FileOptions::default()
        .compression_method(npyz::zip::CompressionMethod::Stored)
        .large_file(std::mem::size_of_val(data) >= u32::MAX as usize);
    let shape: Vec<u64> = shape.iter().map(|&n| n as u64).collect();
    let mut w = npz
        .array::<T>(name, options)?
        .default_dtype()
        .shape(&shape)
        .begin_nd()?;
    w.extend(data.iter().copied())?;
    w.finish()
}

/// Reads a shard: its block mesh and the settings it was made with. A damaged file is an error
/// naming it, never a wrong mesh.
pub fn read_shard(path: &Path) -> Result<(BlockMesh, Settings)> {
    let (mut file, header) = ShardFile::open::<Settings>(path)?;
    let block = BlockMesh {
        grid: header.grid,
        stats: header.stats,
        covered: header.covered,
        keys: file.array("keys", 1)?,
        positions: rows(file.array("positions", 3)?),
        normals: rows(file.array("normals", 3)?),
        triangles: rows(file.array("triangles", 3)?),
        cubes: file.array("cubes", 1)?,
    };
    block.check().map_err(|e| file.bad(&e.to_string()))?;
    file.check_finite("positions", &block.positions)?;
    file.check_finite("normals", &block.normals)?;
    Ok((block, header.settings))
}

/// A shard opened for reading its arrays; errors name its file.
pub(crate) struct ShardFile<'p> {
    path: &'p Path,
    npz: NpzArchive<BufReader<std::fs::File>>,
    /// The file's length, which no stored entry can pass.
    limit: u64,
}

impl<'p> ShardFile<'p> {
    /// Opens the shard at `path` and reads its header, which must be of kind `S`.
    pub(crate) fn open<S: ShardSettings>(path: &'p Path) -> Result<(Self, Header<S>)> {
        let file = crate::input::open(path)?;
        let limit = file.metadata().map_err(|e| Error::io(path, e))?.len();
        let npz = NpzArchive::new(BufReader::new(file))
            .map_err(|e| Error::file(path, format!("not a readable shard: {e}")))?;
        let mut shard = ShardFile { path, npz, limit };
        let header: Vec<u8> = shard.array("header", 1)?;
        let header: Value =
            serde_json::from_slice(&header).map_err(|e| shard.bad(&format!("header: {e}")))?;
        if header["format"] != SHARD_FORMAT {
            return Err(shard.bad(&format!("its header's format is not {SHARD_FORMAT:?}")));
        }
        if header["version"] != VERSION {
            return Err(shard.bad(&format!(
                "shard version {} is not the {VERSION} this skelclimb reads",
                header["version"]
            )));
        }
        let kind = kind_of(&header).map_err(|m| shard.bad(&m))?;
        if kind != S::KIND {
            return Err(Error::file(
                path,
                format!(
                    "a shard of {kind}, where the manifest lists {} shards",
                    S::KIND
                ),
            ));
        }
        let header = Header {
            grid: usizes(&header["grid"]).ok_or_else(|| shard.bad("no grid"))?,
            settings: S::from_json(&header["settings"]).map_err(|m| shard.bad(&m))?,
            stats: stats_from_json(&header["stats"]).ok_or_else(|| shard.bad("no counts"))?,
            covered: header["covered"]
                .as_u64()
                .ok_or_else(|| shard.bad("no cube count"))?,
        };
        Ok((shard, header))
    }

    /// The error that the file is not a readable shard, for `why`.
    pub(crate) fn bad(&self, why: &str) -> Error {
        Error::file(self.path, format!("not a readable shard: {why}"))
    }

    /// The array `name` ([`array`]).
    pub(crate) fn array<T: npyz::Deserialize + Copy>(
        &mut self,
        name: &str,
        width: usize,
    ) -> Result<Vec<T>> {
        array(&mut self.npz, name, width, self.limit).map_err(|m| self.bad(&m))
    }

    /// Refuses rows that are not all finite numbers.
    pub(crate) fn check_finite(&self, name: &str, rows: &[[f32; 3]]) -> Result<()> {
        match rows.iter().position(|r| !r.iter().all(|c| c.is_finite())) {
            Some(i) => Err(self.bad(&format!(
                "{name} row {i} is {:?}: not finite numbers",
                rows[i]
            ))),
            None => Ok(()),
        }
    }
}

/// The array `name`, of shape `(n,)` for `width` 1 or `(n, width)` otherwise, flattened.
///
/// The entry is read whole first, so that the zip reader reaches its end and checks the CRC-32
/// the writer recorded: a flipped byte in a shard is then an error, not a wrong vertex. Shards
/// are stored uncompressed, so no entry can be longer than the file, `limit`.
///
/// An `(n, width)` array in Fortran order (NumPy's `fortran_order: True`, as `np.asfortranarray`
/// or a transposed view gives) is transposed into rows, so it means what it means to NumPy.
fn array<T: npyz::Deserialize + Copy, R: Read + Seek>(
    npz: &mut NpzArchive<R>,
    name: &str,
    width: usize,
    limit: u64,
) -> std::result::Result<Vec<T>, String> {
    let mut bytes = Vec::new();
    let file = npyz::npz::file_name_from_array_name(name);
    let entry = match npz.zip_archive().by_name(&file) {
        Ok(entry) => entry,
        Err(npyz::zip::result::ZipError::FileNotFound) => return Err(format!("no array {name}")),
        Err(e) => return Err(format!("array {name}: {e}")),
    };
    entry
        .take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("array {name}: {e}"))?;
    if bytes.len() as u64 > limit {
        return Err(format!("array {name} is longer than the file"));
    }
    crate::read::npy::check_header(&mut &bytes[..]).map_err(|e| format!("array {name}: {e}"))?;
    let npy = npyz::NpyFile::new(&bytes[..]).map_err(|e| format!("array {name}: {e}"))?;
    let shape = npy.shape().to_vec();
    let fits = match shape.as_slice() {
        [_] => width == 1,
        [_, w] => *w == width as u64 && width > 1,
        _ => false,
    };
    if !fits {
        return Err(format!("array {name} has shape {shape:?}"));
    }
    let order = npy.header().order();
    let flat = npy.into_vec().map_err(|e| format!("array {name}: {e}"))?;
    Ok(match order {
        npyz::Order::C => flat,
        // NumPy writes a Fortran-order (column-major) array column by column: the rows' first
        // elements, then their second ones, and so on.
        npyz::Order::Fortran => {
            let n = flat.len() / width;
            (0..n)
                .flat_map(|i| (0..width).map(move |j| j * n + i))
                .map(|k| flat[k])
                .collect()
        }
    })
}

pub(crate) fn rows<T: Copy>(flat: Vec<T>) -> Vec<[T; 3]> {
    flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

/// Joins the shards `manifest` lists into the whole mesh, exactly the one a single process makes,
/// holding about the result plus one shard at a time. Every shard is checked against the
/// manifest first: its grid, settings, cubes and counts.
pub fn merge(manifest_path: &Path) -> Result<(Manifest, Mesh)> {
    let manifest = Manifest::read(manifest_path)?;
    // A binary counter of joined shares (like a merge sort's stack): each vertex and triangle
    // is copied O(log n) times, not O(n) as a left fold would.
    let mut stack: Vec<(u32, BlockMesh)> = Vec::new();
    for entry in &manifest.shards {
        let block = read_checked(&shard_path(manifest_path, entry), entry, &manifest)?;
        let mut top = (0, block);
        while stack.last().is_some_and(|(level, _)| *level == top.0) {
            let (level, below) = stack.pop().expect("checked above");
            top = (level + 1, join(below, top.1, manifest_path)?);
        }
        stack.push(top);
    }
    let mut whole = BlockMesh::default();
    while let Some((_, b)) = stack.pop() {
        whole = join(b, whole, manifest_path)?;
    }
    if whole.grid == [0; 3] {
        whole.grid = manifest.grid;
    }
    let mut mesh = whole
        .into_mesh()
        .map_err(|e| Error::file(manifest_path, e))?;
    if !manifest.world.is_translation() {
        manifest.world.place(&mut mesh);
        // Every number of the placement is below 1e30 and every shard's position finite, but
        // their product can still pass f32's largest value: refuse rather than write infinities.
        if let Some(p) = mesh
            .positions
            .iter()
            .find(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(Error::file(
                manifest_path,
                format!(
                    "the world placement takes a vertex to {p:?}, beyond what 32-bit floats hold"
                ),
            ));
        }
    }
    Ok((manifest, mesh))
}

fn join(a: BlockMesh, b: BlockMesh, manifest: &Path) -> Result<BlockMesh> {
    a.merge(b).map_err(|e| Error::file(manifest, e))
}

/// Reads the shard `entry` names and checks that it is that block of that mesh.
fn read_checked(path: &Path, entry: &ShardEntry, manifest: &Manifest) -> Result<BlockMesh> {
    let (block, settings) = read_shard(path)?;
    let header = Header {
        grid: block.grid,
        settings,
        stats: block.stats,
        covered: block.covered,
    };
    let counts = [block.keys.len(), block.triangles.len()].map(|n| n as u64);
    check_entry(path, entry, manifest, &header, counts, &block.cubes)?;
    Ok(block)
}

/// Checks that the shard at `path`, with `header`, `counts` (vertices, triangles) and owning
/// cubes `cubes`, is the block `entry` of the manifest's mesh.
pub(crate) fn check_entry<S: ShardSettings>(
    path: &Path,
    entry: &ShardEntry,
    manifest: &Manifest<S>,
    header: &Header<S>,
    counts: [u64; 2],
    cubes: &[u64],
) -> Result<()> {
    let refuse = |m: String| Err(Error::file(path, m));
    if header.grid != manifest.grid {
        return refuse(format!(
            "a shard of a {:?} grid, but the manifest's grid is {:?}",
            header.grid, manifest.grid
        ));
    }
    let wanted = manifest.settings.in_shards();
    if header.settings != wanted {
        return refuse(format!(
            "made with other settings than the manifest's ({} rather than {})",
            header.settings.to_json(),
            wanted.to_json()
        ));
    }
    let [nx, ny, _] = manifest.settings.key_grid(manifest.grid).map(|n| n as u64);
    let inside = |key: u64| {
        let at = [key % nx, key / nx % ny, key / nx / ny];
        (0..3).all(|d| entry.cubes[d].contains(&(at[d] as usize)))
    };
    if header.covered != entry.count()
        || counts != [entry.vertices, entry.triangles]
        || !cubes.iter().all(|&c| inside(c))
    {
        return refuse(format!(
            "not the block of cubes {:?} the manifest lists under this name",
            entry.cubes
        ));
    }
    Ok(())
}

/// The blocks of up to `block` cubes per axis that tile a grid of `cubes` cubes per axis, x
/// fastest: the blocks `extract --shards` writes.
pub(crate) fn blocks(cubes: [usize; 3], block: usize) -> impl Iterator<Item = [Range<usize>; 3]> {
    let block = block.max(1);
    let starts = move |d: usize| (0..cubes[d]).step_by(block);
    let along = move |d: usize, s: usize| s..(s + block).min(cubes[d]);
    starts(2).flat_map(move |z| {
        starts(1).flat_map(move |y| starts(0).map(move |x| [along(0, x), along(1, y), along(2, z)]))
    })
}

/// Where the shard `entry` of the manifest at `manifest_path` is.
pub(crate) fn shard_path(manifest_path: &Path, entry: &ShardEntry) -> PathBuf {
    manifest_path
        .parent()
        .unwrap_or(Path::new(""))
        .join(&entry.file)
}

#[cfg(test)]
mod tests {
    use sc_runtime::{Volume, demo, extract_block};

    use super::*;

    /// A shard reads back as exactly the block written, counts and settings included, and
    /// NumPy's layout (shapes, dtypes) is what the table above says.
    #[test]
    fn a_shard_reads_back_exactly() {
        let v = demo::torus(20);
        let mut params = Params::new(v.iso);
        params.max_error = Some(ErrorBound::Voxels(0.25));
        params.spacing = [0.5, 1.0, 2.0];
        let volume = Volume::new(&v.data, v.dims).unwrap();
        let block = extract_block(&volume, [0; 3], v.dims, [3..9, 0..19, 4..12], &params).unwrap();
        assert!(block.triangles.len() > 20 && block.stats.bounded + block.stats.merged > 0);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.npz");
        write_shard(&path, &block, &Settings::from(&params)).unwrap();
        let (back, settings) = read_shard(&path).unwrap();
        assert_eq!(back, block);
        assert_eq!(settings, Settings::from(&params));
        let mut npz = NpzArchive::open(&path).unwrap();
        let positions = npz.by_name("positions").unwrap().unwrap();
        assert_eq!(positions.shape(), [block.keys.len() as u64, 3]);
        assert_eq!(positions.dtype().descr(), "'<f4'");

        // Adaptive mode's box settings travel with the shard, and tell its shares apart.
        let adaptive = Params {
            mode: Mode::Adaptive,
            max_box: Some(4),
            allow_wrong_side: true,
            ..params
        };
        let block =
            extract_block(&volume, [0; 3], v.dims, [0..19, 0..19, 0..19], &adaptive).unwrap();
        write_shard(&path, &block, &Settings::from(&adaptive)).unwrap();
        let (back, settings) = read_shard(&path).unwrap();
        assert_eq!((back, settings), (block, Settings::from(&adaptive)));
        assert_eq!(settings.params().max_box, Some(4));
        assert!(settings.params().allow_wrong_side);
        for other in [
            Params {
                max_box: Some(8),
                ..adaptive
            },
            Params {
                max_box: None,
                ..adaptive
            },
            Params {
                allow_wrong_side: false,
                ..adaptive
            },
        ] {
            assert_ne!(Settings::from(&other), settings);
        }
    }

    /// Settings written before the box settings existed read with their defaults; bad ones are
    /// refused by name.
    #[test]
    fn box_settings_default_and_are_checked() {
        let mut v = Settings::from(&Params::new(1.5)).to_json();
        v.as_object_mut().unwrap().remove("max_box");
        v.as_object_mut().unwrap().remove("allow_wrong_side");
        let s = Settings::from_json(&v).unwrap();
        assert_eq!((s.max_box, s.allow_wrong_side), (None, false));
        v["max_box"] = json!(3);
        assert!(Settings::from_json(&v).unwrap_err().contains("max_box 3"));
        v["max_box"] = json!(16);
        v["allow_wrong_side"] = json!("yes");
        assert!(
            Settings::from_json(&v)
                .unwrap_err()
                .contains("allow_wrong_side")
        );
    }

    /// `path` rewritten as NumPy writes `np.asfortranarray` arrays: every `(n, 3)` array in
    /// column-major order, marked `fortran_order: True`.
    fn to_fortran(path: &Path) {
        let (block, _) = read_shard(path).unwrap();
        let header: Vec<u8> = NpzArchive::open(path)
            .unwrap()
            .by_name("header")
            .unwrap()
            .unwrap()
            .into_vec()
            .unwrap();
        fn columns<T: npyz::AutoSerialize + Copy, W: Write + Seek>(
            npz: &mut NpzWriter<W>,
            name: &str,
            rows: &[[T; 3]],
        ) {
            let stored = npyz::zip::write::FileOptions::default()
                .compression_method(npyz::zip::CompressionMethod::Stored);
            let mut w = npz
                .array::<T>(name, stored)
                .unwrap()
                .default_dtype()
                .shape(&[rows.len() as u64, 3])
                .order(npyz::Order::Fortran)
                .begin_nd()
                .unwrap();
            w.extend((0..3).flat_map(|j| rows.iter().map(move |r| r[j])))
                .unwrap();
            w.finish().unwrap();
        }
        let mut npz = NpzWriter::create(path).unwrap();
        put(&mut npz, "header", &[header.len()], &header).unwrap();
        put(&mut npz, "keys", &[block.keys.len()], &block.keys).unwrap();
        columns(&mut npz, "positions", &block.positions);
        columns(&mut npz, "normals", &block.normals);
        columns(&mut npz, "triangles", &block.triangles);
        put(&mut npz, "cubes", &[block.cubes.len()], &block.cubes).unwrap();
        npz.zip_writer().finish().unwrap();
    }

    /// Shards whose `(n, 3)` arrays are stored in Fortran order read as the same blocks and
    /// merge into the same mesh as the C-order shards they were rewritten from.
    /// Every pair of boxes in a 3 × 3 × 3 grid of cubes, found overlapping by marking cells and by
    /// comparing pairs exactly when they share a cube; a grid of 200,000 one-cube blocks in one
    /// layer has none; and pairs beyond the budget are refused rather than compared.
    #[test]
    fn overlaps_are_found_by_both_paths_exactly() {
        let ranges: Vec<Range<usize>> = (0..3)
            .flat_map(|a| (a + 1..=3).map(move |b| a..b))
            .collect();
        let boxes: Vec<ShardEntry> = (0..ranges.len().pow(3))
            .map(|i| {
                let n = ranges.len();
                let cubes = [i % n, i / n % n, i / (n * n)].map(|k| ranges[k].clone());
                ShardEntry::new(format!("b{i}.npz"), cubes, &BlockMesh::default())
            })
            .collect();
        for a in &boxes {
            for b in &boxes {
                if std::ptr::eq(a, b) {
                    continue;
                }
                let shared = (0..3).all(|d| overlap(&a.cubes[d], &b.cubes[d]));
                for budgets in [(u64::MAX, u64::MAX), (0, u64::MAX)] {
                    let found = overlapping(&[a, b], budgets).unwrap();
                    assert_eq!(
                        found.is_some(),
                        shared,
                        "{:?} {:?} {budgets:?}",
                        a.cubes,
                        b.cubes
                    );
                }
            }
        }
        let blocks: Vec<ShardEntry> = (0..200_000)
            .map(|i| {
                let cubes = [i % 1000..i % 1000 + 1, i / 1000..i / 1000 + 1, 0..1];
                ShardEntry::new(format!("b{i}.npz"), cubes, &BlockMesh::default())
            })
            .collect();
        let refs: Vec<&ShardEntry> = blocks.iter().collect();
        assert!(overlapping(&refs, (16 * 200_000, 0)).unwrap().is_none());
        assert!(overlapping(&refs[..100], (0, 10)).is_err());
    }

    #[test]
    fn fortran_order_shards_merge_as_c_order_ones() {
        let v = demo::torus(16);
        let params = Params::new(v.iso);
        let volume = Volume::new(&v.data, v.dims).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let mut manifest = Manifest::new(v.dims, &params);
        for z in [0..7, 7..15] {
            let cubes = [0..15, 0..15, z];
            let block = extract_block(&volume, [0; 3], v.dims, cubes.clone(), &params).unwrap();
            let entry = ShardEntry::new(ShardEntry::file_name(&cubes), cubes, &block);
            write_shard(
                &dir.path().join(&entry.file),
                &block,
                &Settings::from(&params),
            )
            .unwrap();
            manifest.shards.push(entry);
        }
        let path = dir.path().join(MANIFEST_NAME);
        manifest.write(&path).unwrap();
        let (_, c_order) = merge(&path).unwrap();
        assert!(c_order.triangles.len() > 100);
        for entry in &manifest.shards {
            let shard = dir.path().join(&entry.file);
            let before = read_shard(&shard).unwrap();
            to_fortran(&shard);
            let raw = std::fs::read(&shard).unwrap();
            assert!(raw.windows(21).any(|w| w == b"'fortran_order': True"));
            assert_eq!(read_shard(&shard).unwrap(), before);
        }
        let (_, fortran) = merge(&path).unwrap();
        assert_eq!(fortran, c_order);
    }
}
