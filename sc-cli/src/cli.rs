//! The command line. Everything clap can check is checked here, so that usage errors exit with
//! status 2 before any file is read.

use std::path::PathBuf;
use std::str::FromStr;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand, ValueEnum};
use sc_runtime::{ErrorBound, ErrorUnits, Mode, UnknownName};

use sc_io::limits;
use sc_io::read::dicom::DicomOptions;
use sc_io::read::{RawLayout, ReadOptions};
use sc_io::space::Coordinates;
use sc_io::volume::{Dtype, Endian};
use sc_io::write::MeshFormat;

/// Skeleton Climbing isosurfaces from volume files.
///
/// Skeleton Climbing (Poston, Wong, Heng 1998) meshes the surface `f = iso` of a sampled volume
/// like Marching Cubes, then merges triangles around a fixed set of grid edges, giving a closed
/// surface with about a quarter fewer triangles.
#[derive(Debug, Parser)]
#[command(name = "skelclimb", version, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// No progress bar and no summary; warnings and errors still go to stderr.
    #[arg(short, long, global = true)]
    pub quiet: bool,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Mesh the surface `f = iso` of a volume (or a built-in one) into a .ply, .obj, .stl or .glb.
    Extract(ExtractArgs),
    /// Describe a volume: size, type, spacing, values, and iso values worth trying.
    ///
    /// Suggested iso values come from the histogram: Otsu's threshold (the split of all values
    /// into two classes that are as far apart as possible, good for one object against a
    /// background) and valleys (values rarer than the peaks on both sides, typical of the
    /// boundary between two tissues or materials).
    Info(InfoArgs),
    /// Rerun the paper's Table 1 comparison: triangles and time for Steps 1–3 and Steps 1–4
    /// (embedded and paper modes) on the built-in volumes and any volumes given.
    Table1(Table1Args),
    /// Draw a mesh (.ply, .obj, .stl) into a PNG picture, to look at a result without a display.
    ///
    /// Examples:
    ///   skelclimb render knot.ply -o knot.png --wireframe
    ///   skelclimb render embedded.ply --compare steps123.ply -o both.png --view front
    ///   skelclimb render bounded.ply --color-by-error steps123.ply -o error.png
    #[command(verbatim_doc_comment)]
    Render(RenderArgs),
    /// Join the shards `extract --shards` (or `skelclimb.dask.extract(..., shards=DIR)`) wrote
    /// into one mesh: exactly the mesh a single `extract` of the whole volume writes. Shards of
    /// a label volume (`extract --labels --shards`) join into the files `extract --labels`
    /// writes: an atlas .glb or a directory of a file per label.
    ///
    /// Examples:
    ///   skelclimb extract scan.nii.gz --iso 300 --shards parts --block 64
    ///   skelclimb merge parts/manifest.json -o bone.ply
    ///   skelclimb extract seg.nii.gz --labels all --shards seg-parts --block 64
    ///   skelclimb merge seg-parts/manifest.json -o regions/ --format obj
    #[command(verbatim_doc_comment)]
    Merge(MergeArgs),
}

/// Arguments of `merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The manifest (`manifest.json` in the shard directory); the shards are beside it.
    pub manifest: PathBuf,
    /// The mesh file; its extension (.ply, .obj, .stl, .glb) chooses the format. For label
    /// shards, a .glb file (a node per label) or a directory (a file per label).
    #[arg(short, long)]
    pub output: PathBuf,
    /// For label shards merged into a directory: the format of each label's file [default: ply].
    #[arg(long, value_parser = parse_format)]
    pub format: Option<MeshFormat>,
    /// Write text PLY instead of binary.
    #[arg(long)]
    pub ascii: bool,
    /// Also write the counts and times as JSON to this file.
    #[arg(long)]
    pub stats_json: Option<PathBuf>,
}

/// Arguments of `render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// The mesh: .ply (text or binary), .obj or .stl; or a directory of label meshes
    /// (`extract --labels -o DIR`), each label in a colour of its own.
    pub mesh: PathBuf,
    /// The picture to write (.png).
    #[arg(short, long)]
    pub output: PathBuf,
    /// A named view [default: iso]; z is up.
    #[arg(long, value_enum, conflicts_with_all = ["azimuth", "elevation"])]
    pub view: Option<View>,
    /// Degrees around the z axis (0 looks along +y).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_angle)]
    pub azimuth: Option<f64>,
    /// Degrees above the horizon (90 looks down).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_angle)]
    pub elevation: Option<f64>,
    /// Gouraud shading (normals averaged at vertices) instead of flat faces.
    #[arg(long)]
    pub smooth: bool,
    /// Draw the triangles' edges over the surface.
    #[arg(long)]
    pub wireframe: bool,
    /// Picture size per mesh, `WIDTHxHEIGHT`.
    #[arg(long, default_value = "800x600", value_parser = parse_size_wh)]
    pub size: [usize; 2],
    /// A second mesh, drawn beside the first with the same camera; each is labelled with its
    /// triangle count.
    #[arg(long, conflicts_with = "color_by_error")]
    pub compare: Option<PathBuf>,
    /// Colour each triangle by the distance from its centroid to this mesh (blue 0, red the
    /// largest); the largest and mean distances are printed.
    #[arg(long)]
    pub color_by_error: Option<PathBuf>,
}

/// `--view` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum View {
    /// Looking along +y.
    Front,
    /// Looking along −x.
    Side,
    /// Looking down.
    Top,
    /// From above, at an angle.
    Iso,
}

fn parse_size_wh(s: &str) -> Result<[usize; 2], String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?} is not WIDTHxHEIGHT"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<usize>()
            .ok()
            .filter(|n| (16..=8192).contains(n))
    };
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok([w, h]),
        _ => Err("width and height must be whole numbers from 16 to 8192".into()),
    }
}

/// How to read a volume file; options for raw files are refused for the other formats.
#[derive(Debug, Args)]
pub struct InputArgs {
    /// Raw input: samples along x, y, z, e.g. `256,256,128` (x varies fastest in the file).
    #[arg(long, value_parser = parse_dims, requires = "dtype", help_heading = "Raw input")]
    pub dims: Option<[usize; 3]>,
    /// Raw input: the sample type.
    #[arg(long, value_enum, requires = "dims", help_heading = "Raw input")]
    pub dtype: Option<Dtype>,
    /// Raw input: byte order [default: little].
    #[arg(long, value_enum, requires = "dims", help_heading = "Raw input")]
    pub endian: Option<Endian>,
    /// Raw input: bytes to skip before the samples [default: 0].
    #[arg(long, requires = "dims", help_heading = "Raw input")]
    pub header_bytes: Option<u64>,
    /// .npz input: the array to read (may be left out if there is only one).
    #[arg(long)]
    pub array: Option<String>,
    /// DICOM input: the series to read when the directory holds several, by SeriesInstanceUID
    /// or by its number in `skelclimb info`'s list.
    #[arg(long, help_heading = "DICOM input")]
    pub series: Option<String>,
    /// DICOM input: resample a series with missing slices onto even spacing (linear
    /// interpolation) instead of refusing it.
    #[arg(long, help_heading = "DICOM input")]
    pub resample_gaps: bool,
    /// OME-Zarr input: the multiscale level to read, 0 being the finest.
    #[arg(long, default_value_t = 0)]
    pub zarr_level: usize,
}

impl InputArgs {
    /// The reader options these arguments give.
    pub fn read_options(&self) -> ReadOptions {
        let raw = match (self.dims, self.dtype) {
            (Some(dims), Some(dtype)) => Some(RawLayout {
                dims,
                dtype,
                endian: self.endian.unwrap_or_default(),
                header_bytes: self.header_bytes.unwrap_or(0),
            }),
            _ => None,
        };
        ReadOptions {
            raw,
            array: self.array.clone(),
            dicom: DicomOptions {
                series: self.series.clone(),
                resample_gaps: self.resample_gaps,
            },
            zarr_level: self.zarr_level,
        }
    }
}

/// Arguments of `extract`.
#[derive(Debug, Args)]
pub struct ExtractArgs {
    /// The volume: a .nii/.nii.gz, .nrrd/.nhdr, .mha/.mhd, .npy/.npz file, a Zarr or OME-Zarr
    /// store, a DICOM directory, or a raw file with --dims and --dtype.
    #[arg(required_unless_present = "demo", conflicts_with = "demo")]
    pub input: Option<PathBuf>,
    /// Use a built-in volume instead of a file; `knot` is the paper's knotted torus.
    #[arg(long, value_enum)]
    pub demo: Option<Demo>,
    /// Samples per axis of the built-in volume (2 to 512: the volume is f64, 1 GiB at 512).
    #[arg(long, requires = "demo", default_value_t = 64, value_parser = parse_size)]
    pub size: usize,
    /// The surface value: samples `>= iso` are inside. Required for files (see `skelclimb info`).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_iso)]
    pub iso: Option<f64>,
    /// The mesh file; its extension (.ply, .obj, .stl, .glb) chooses the format. With
    /// --labels, a .glb file holds every label as a named, coloured node, and a directory
    /// (any other path) gets one file per label.
    #[arg(short, long, required_unless_present = "shards")]
    pub output: Option<PathBuf>,
    /// Mesh a label volume (a segmentation, an atlas): every region at once, each a closed
    /// mesh, neighbours sharing their interfaces exactly. `all` or a list such as `1,5,17-20`
    /// chooses which labels get a mesh. With --stream, the same meshes from a few slices at a
    /// time.
    #[arg(long, value_name = "all|LIST", value_parser = sc_io::labels::Selection::parse,
          conflicts_with_all = ["iso", "demo", "max_error", "max_box", "allow_wrong_side", "pad"])]
    pub labels: Option<sc_io::labels::Selection>,
    /// With --labels: the label of no region, not meshed, and what lies outside the volume.
    #[arg(long, requires = "labels", default_value_t = 0)]
    pub background: u64,
    /// With --labels: names and colours of the labels (ITK-SNAP, FreeSurfer or MRIcron
    /// table) [default: a table beside the volume, such as aal.nii.txt and aal.nii.lut].
    #[arg(long, requires = "labels", value_name = "FILE")]
    pub label_table: Option<PathBuf>,
    /// With --labels: slide each vertex along its grid edge to where the Gaussian-smoothed
    /// regions on either side balance, this wide in voxels (0.75 gives spheres their area
    /// within 1 %); every sample stays on its own side. 0 (the default) keeps midpoints.
    #[arg(long, requires = "labels", default_value_t = 0.0, value_parser = parse_smoothing)]
    pub smoothing: f64,
    /// With --labels and a directory: the format of each label's file (with --shards, `merge`
    /// chooses it).
    #[arg(long, requires = "labels", value_parser = parse_format, default_value = "ply")]
    pub format: MeshFormat,
    /// Instead of one mesh file, write one shard per block of cubes into this directory (made
    /// if missing), plus `manifest.json`; `skelclimb merge` joins them into exactly the mesh
    /// `-o` would have written. The volume is read whole and the blocks meshed one after
    /// another: this is for splitting work by hand and for tests; volumes larger than one
    /// machine are split by the Python package's Dask driver (`shards=`). With --labels, the
    /// shards hold the atlas's blocks, and the manifest the selection, background, smoothing
    /// and label table, so that `merge` writes exactly the files `-o` would have.
    #[arg(long, conflicts_with_all = ["output", "stream", "check", "ascii", "stats_json"])]
    pub shards: Option<PathBuf>,
    /// With --shards: cubes per block along each axis [default: 128].
    #[arg(long, requires = "shards", value_parser = clap::value_parser!(u32).range(1..))]
    pub block: Option<u32>,
    /// Which steps run: `embedded` merges only where the result stays a closed 2-manifold,
    /// `paper` merges every interior grey edge as the paper does, `steps123` does not merge.
    #[arg(
        long,
        value_parser = named::<Mode>(Mode::ALL.map(|m| (m.name(), mode_help(m)))),
        default_value_t = Mode::Embedded
    )]
    pub mode: Mode,
    /// Merge a grey edge only if the vertex it removes lies closer than this to the two
    /// triangles that replace its four, and their new diagonal closer than this to the four: a
    /// bound on how far Step 4 moves the surface, in the volume's world units (mm for most
    /// scans) or, with `--error-units voxels`, in grid steps.
    /// 0 merges nothing (Steps 1–3's triangles); no bound (the default) merges what the mode
    /// allows. In adaptive mode, the largest distance between its surface and Steps 1–3's, both
    /// ways (default: half the smallest spacing).
    #[arg(long, value_parser = parse_max_error)]
    pub max_error: Option<f64>,
    /// With --mode adaptive: the largest box, in cubes per side (1, 2, 4, 8 or 16; default 16).
    #[arg(long, value_parser = parse_max_box)]
    pub max_box: Option<u32>,
    /// With --mode adaptive: let boxes leave samples on the wrong side of the surface, as the
    /// 1998 paper does, for fewer triangles (by default every sample keeps its side).
    #[arg(long)]
    pub allow_wrong_side: bool,
    /// The units of `--max-error`.
    #[arg(
        long,
        value_parser = named::<ErrorUnits>(ErrorUnits::ALL.map(|u| (u.name(), units_help(u)))),
        default_value_t = ErrorUnits::World,
        requires = "max_error"
    )]
    pub error_units: ErrorUnits,
    /// Leave out per-vertex normals.
    #[arg(long)]
    pub no_normals: bool,
    /// Worker threads; 0 uses every core. The mesh is the same for any number.
    #[arg(long, default_value_t = 0, value_parser = parse_threads)]
    pub threads: usize,
    /// Surround the volume with one layer of empty samples, so that every surface is closed.
    #[arg(long, conflicts_with = "stream")]
    pub pad: bool,
    /// Read the volume a few slices at a time instead of whole, so that a volume larger than
    /// memory can be meshed (raw files, NIfTI and Zarr; one thread), surfaces and --labels
    /// alike, into the same mesh files. This happens by itself for Zarr stores, and when the
    /// samples would fill more than half the machine's memory.
    #[arg(long, conflicts_with = "demo")]
    pub stream: bool,
    /// Where the samples are.
    #[command(flatten)]
    pub placement: Placement,
    /// The mesh's coordinates: the scanner's world as the file states it (`native`: RAS for
    /// NIfTI, LPS for DICOM, MetaImage and NRRD in LPS space), converted to `ras` or `lps`, or
    /// `index` (index × spacing + origin, the file's rotation ignored). Files without a world
    /// frame (raw, NumPy) always give index × spacing + origin.
    #[arg(long, value_enum, default_value_t = Coordinates::Native)]
    pub space: Coordinates,
    /// Also write the summary as JSON to this file, with the samples left on the wrong side of
    /// the surface (and in adaptive mode its distance to Steps 1–3) measured.
    #[arg(long)]
    pub stats_json: Option<PathBuf>,
    /// Write text PLY instead of binary.
    #[arg(long)]
    pub ascii: bool,
    /// Report how the mesh's edges are shared: border, manifold (two triangles), non-manifold
    /// (more), and misoriented.
    #[arg(long)]
    pub check: bool,
    /// How to read the volume.
    #[command(flatten)]
    pub read: InputArgs,
}

/// Overrides of where the file says its samples are.
#[derive(Debug, Args)]
pub struct Placement {
    /// Distance between samples along x, y, z, overriding the file's.
    #[arg(long, value_parser = parse_spacing)]
    pub spacing: Option<[f64; 3]>,
    /// World position of the first sample, overriding the file's.
    #[arg(long, value_parser = parse_triple, allow_hyphen_values = true)]
    pub origin: Option<[f64; 3]>,
}

impl Placement {
    /// Applies the overrides to `grid`.
    pub fn apply(&self, grid: &mut sc_io::volume::Grid) {
        if let Some(spacing) = self.spacing {
            grid.spacing = spacing;
        }
        if let Some(origin) = self.origin {
            grid.origin = origin;
        }
    }
}

/// Arguments of `info`.
#[derive(Debug, Args)]
pub struct InfoArgs {
    /// The volume (any format `extract` reads).
    pub input: PathBuf,
    /// Where the samples are.
    #[command(flatten)]
    pub placement: Placement,
    /// Histogram bins to print.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u16).range(1..=256))]
    pub bins: u16,
    /// The label table naming the labels of a label volume (ITK-SNAP, FreeSurfer, MRIcron .txt
    /// or .lut); by default the tables beside the volume (aal.nii.gz: aal.nii.txt, aal.nii.lut).
    #[arg(long, value_name = "FILE")]
    pub label_table: Option<PathBuf>,
    /// How to read the volume.
    #[command(flatten)]
    pub read: InputArgs,
}

/// Arguments of `table1`.
#[derive(Debug, Args)]
pub struct Table1Args {
    /// More volumes, each `FILE@ISO`, or just `FILE` to use its Otsu threshold.
    #[arg(value_parser = parse_volume)]
    pub volumes: Vec<String>,
    /// Samples per axis of the built-in sphere, torus and noisy sphere (the knot is always 64,
    /// as in the paper; 2 to 512).
    #[arg(long, default_value_t = 128, value_parser = parse_size)]
    pub size: usize,
    /// Worker threads; 0 uses every core.
    #[arg(long, default_value_t = 0, value_parser = parse_threads)]
    pub threads: usize,
    /// How to read the volumes.
    #[command(flatten)]
    pub read: InputArgs,
}

/// The built-in volumes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Demo {
    /// The paper's knotted torus (Table 1), iso 0.9.
    Knot,
    /// A ball.
    Sphere,
    /// A ring torus.
    Torus,
    /// A ball with noise: many small features, like real scans.
    SphereNoise,
}

/// A parser for names from one of the runtime's tables ([`Mode::NAMES`], [`ErrorUnits::NAMES`]),
/// each shown in `--help` with its line of help, so that the command line spells them as every
/// other front end does.
fn named<T>(
    values: impl IntoIterator<Item = (&'static str, &'static str)>,
) -> impl TypedValueParser<Value = T>
where
    T: FromStr<Err = UnknownName> + Clone + Send + Sync + 'static,
{
    let values = values
        .into_iter()
        .map(|(name, help)| PossibleValue::new(name).help(help));
    PossibleValuesParser::new(values).try_map(|name| name.parse::<T>())
}

/// `--mode`'s help for each value.
fn mode_help(mode: Mode) -> &'static str {
    match mode {
        Mode::Embedded => "Steps 1–4, merging where the surface stays a closed 2-manifold",
        Mode::Paper => "Steps 1–4, merging every interior grey edge, as the paper does",
        Mode::Steps123 => "Steps 1–3 only: no merging",
        Mode::Adaptive => {
            "Steps 1–3 with boxes of up to 16³ cubes meshed as one within --max-error (0.5 voxel by default), every sample kept on its side; on threads, in blocks with --shards, or streamed"
        }
    }
}

/// `--error-units`' help for each value.
fn units_help(units: ErrorUnits) -> &'static str {
    match units {
        ErrorUnits::World => "The volume's world units: spacing × index, usually mm",
        ErrorUnits::Voxels => "Grid steps, whatever the spacing",
    }
}

impl ExtractArgs {
    /// Cubes per block along each axis with --shards.
    pub fn block_cubes(&self) -> usize {
        self.block.unwrap_or(128) as usize
    }

    /// The bound `--max-error` and `--error-units` ask for.
    pub fn error_bound(&self) -> Option<ErrorBound> {
        self.max_error.map(|d| ErrorBound::new(d, self.error_units))
    }
}

/// An output path whose extension names a known mesh format.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Output {
    /// Where to write.
    pub path: PathBuf,
    /// What to write.
    pub format: MeshFormat,
}

impl Output {
    /// A mesh file, its format told by its extension.
    pub fn new(path: PathBuf) -> Result<Output, String> {
        let format = MeshFormat::from_path(&path)?;
        Ok(Output { path, format })
    }
}

fn parse_max_box(s: &str) -> Result<u32, String> {
    s.parse::<u32>()
        .ok()
        .filter(|b| b.is_power_of_two() && *b <= 16)
        .ok_or_else(|| format!("{s:?}: give a box side in cubes: 1, 2, 4, 8 or 16"))
}

fn parse_smoothing(s: &str) -> Result<f64, String> {
    let max = sc_runtime::labels::MAX_SMOOTHING;
    s.parse::<f64>()
        .ok()
        .filter(|w| (0.0..=max).contains(w))
        .ok_or_else(|| format!("{s:?}: give a width in voxels from 0 to {max}"))
}

fn parse_format(s: &str) -> Result<MeshFormat, String> {
    MeshFormat::from_path(std::path::Path::new(&format!("x.{s}")))
        .map_err(|_| format!("{s:?} is not a mesh format: use ply, obj, stl or glb"))
}

fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| format!("{x:?} is not a number"))
        })
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        &[x, y, z] => limits::triple([x, y, z]),
        _ => Err(limits::THREE_COORDINATES.into()),
    }
}

fn parse_threads(s: &str) -> Result<usize, String> {
    let n: u64 = s
        .parse()
        .map_err(|_| format!("{s:?} is not a whole number"))?;
    limits::threads(n)
}

fn parse_size(s: &str) -> Result<usize, String> {
    let n: usize = s
        .parse()
        .map_err(|_| format!("{s:?} is not a whole number"))?;
    if !(2..=512).contains(&n) {
        return Err("the built-in volumes have 2 to 512 samples per axis".into());
    }
    Ok(n)
}

fn parse_max_error(s: &str) -> Result<f64, String> {
    let v = finite(s, "the bound")?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("the bound must be 0 or more, not {s}"))
    }
}

fn parse_iso(s: &str) -> Result<f64, String> {
    finite(s, "the iso value")
}

/// A camera angle: NaN or infinity would put every point nowhere and draw a blank picture.
fn parse_angle(s: &str) -> Result<f64, String> {
    finite(s, "an angle")
}

fn finite(s: &str, what: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{what} must be a finite number, not {s}"))
    }
}

/// A `table1` volume, `FILE@ISO` or `FILE`, whose iso value (if any) is finite.
fn parse_volume(s: &str) -> Result<String, String> {
    match split_iso(s) {
        (_, Some(iso)) if !iso.is_finite() => Err(format!(
            "the iso value after @ must be a finite number, not {iso}"
        )),
        _ => Ok(s.to_owned()),
    }
}

fn parse_spacing(s: &str) -> Result<[f64; 3], String> {
    let v = parse_triple(s)?;
    if v.iter().all(|&c| c > 0.0) {
        Ok(v)
    } else {
        Err("spacings must be positive".into())
    }
}

fn parse_dims(s: &str) -> Result<[usize; 3], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<usize>()
                .map_err(|_| format!("{x:?} is not a whole number"))
        })
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|&d| d > 0) => Ok([*x, *y, *z]),
        _ => Err("expected three positive sizes X,Y,Z".into()),
    }
}

/// `FILE@ISO` or `FILE`, as `table1` takes them; an `@` not followed by a number is part of
/// the file name.
pub fn split_iso(spec: &str) -> (PathBuf, Option<f64>) {
    match spec
        .rsplit_once('@')
        .map(|(path, iso)| (path, iso.parse::<f64>()))
    {
        Some((path, Ok(iso))) => (PathBuf::from(path), Some(iso)),
        _ => (PathBuf::from(spec), None),
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    use super::*;

    #[test]
    fn definitions_are_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn parses_lists() {
        assert_eq!(parse_dims("3, 4,5"), Ok([3, 4, 5]));
        assert!(parse_dims("3,0,5").is_err());
        assert!(parse_dims("3,4").is_err());
        assert_eq!(parse_triple("-1.5,0,2e3"), Ok([-1.5, 0.0, 2000.0]));
        assert!(parse_spacing("1,0,1").is_err());
        assert!(parse_triple("1,1e38,1").is_err());
        assert!(parse_iso("nan").is_err() && parse_iso("inf").is_err());
        assert_eq!(parse_iso("-2.5"), Ok(-2.5));
        for bad in ["nan", "NaN", "inf", "-inf", "infinity"] {
            assert!(parse_angle(bad).is_err(), "{bad}");
            assert!(parse_volume(&format!("a.nii@{bad}")).is_err(), "{bad}");
        }
        assert_eq!(parse_angle("-400"), Ok(-400.0));
        assert_eq!(parse_volume("a.nii@20"), Ok("a.nii@20".into()));
        assert!(parse_threads("100000").is_err());
        assert_eq!(parse_threads("8"), Ok(8));
        assert!(parse_size("2000").is_err() && parse_size("1").is_err());
        assert!(Output::new("a.vtk".into()).is_err());
        assert_eq!(
            Output::new("A.GLB".into()).map(|o| o.format),
            Ok(MeshFormat::Glb)
        );
        assert_eq!(
            split_iso("a@b.nii@20"),
            (PathBuf::from("a@b.nii"), Some(20.0))
        );
        assert_eq!(split_iso("a@b.nii"), (PathBuf::from("a@b.nii"), None));
    }
}
