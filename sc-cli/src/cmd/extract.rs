//! `skelclimb extract`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use sc_runtime::{Mesh, Mode};

use super::warn;
use crate::builtin;
use crate::check::EdgeReport;
use crate::cli::{Demo, ExtractArgs, Output};
use crate::progress::{Bar, Counted};
use crate::summary::Summary;
use sc_io::atomic::{AtomicFile, Filled};
use sc_io::progress::{Progress, Silent};
use sc_io::read::stream::{self, Stream};
use sc_io::read::{self, Format, ReadOptions};
use sc_io::surface::{self, Request};
use sc_io::volume::Grid;
use sc_io::write::{MeshFormat, WriteOptions};
use sc_io::{Error, Result};

/// Reads, extracts, writes and reports. Output files are opened first, so that a bad output
/// path fails before a long read, and written whole or not at all.
pub fn run(args: &ExtractArgs, quiet: bool) -> Result<()> {
    let options = args.read.read_options();
    if args.labels.is_some() {
        return super::labels::run(args, quiet);
    }
    let format = check_input(args, &options)?;
    let output = match (&args.output, &args.shards) {
        (_, Some(dir)) => return shards(args, dir, &options, quiet),
        (Some(path), None) => Output::new(path.clone()).map_err(Error::Usage)?,
        (None, None) => return Err(Error::Usage("give -o FILE or --shards DIR".into())),
    };
    let output = &output;
    check_output(args, output)?;
    let mesh_file = AtomicFile::create(&output.path)?;
    let stats_file = args
        .stats_json
        .as_deref()
        .map(AtomicFile::create)
        .transpose()?;
    let progress = Bar::new(!quiet);

    let clock = Instant::now();
    let (mut volume, iso, input) = open(args, format, &options, &progress)?;
    let read_time = clock.elapsed();
    let file_dims = volume.grid().dims;
    place(args, volume.grid_mut(), iso, &input)?;

    let clock = Instant::now();
    let request = request(args, iso);
    let world = surface::world(volume.grid(), &request);
    let measure = args.stats_json.is_some();
    let (mesh, measured) = match &mut volume {
        Volume::Whole(grid) => {
            let (mesh, measured) = surface::extract_measured(grid, &request, measure, &progress)?;
            if measured.is_some_and(|m| m.wrong_side_samples.is_none()) {
                warn(
                    "wrong_side_samples is not measured: samples on the volume's border are \
                     filled, so the surface is open there (--pad closes it)",
                );
            }
            (mesh, measured)
        }
        Volume::Streamed(stream) => {
            if measure && args.mode == Mode::Adaptive {
                warn(
                    "distance_to_steps123 is not measured on a streamed volume: it needs the \
                     whole volume's Steps 1–3 mesh",
                );
            }
            if measure {
                warn(
                    "wrong_side_samples is not measured on a streamed volume: it needs the \
                     whole volume",
                );
            }
            (surface::extract_stream(stream, &request, &progress)?, None)
        }
    };
    let extract_time = clock.elapsed() - measured.map(|m| m.time).unwrap_or_default();
    for warning in &volume.grid().warnings {
        warn(warning);
    }
    if mesh.triangles.is_empty() {
        warn(format!(
            "{input}: {}; writing an empty mesh",
            why_empty(&volume, iso)
        ));
    }
    let paper_knot = paper_knot(args, &volume, &request, &mesh)?;

    let clock = Instant::now();
    let write_options = WriteOptions {
        ascii: args.ascii,
        space: world.space,
    };
    let mesh_filled = write_mesh(mesh_file, &mesh, output.format, &write_options, &progress)?;
    progress.finish();
    let grid = volume.grid();
    let summary = Summary {
        input,
        format: grid.format,
        dims: file_dims,
        padded: args.pad,
        coordinates: world.describe(),
        dtype: grid.samples.dtype().name(),
        iso,
        mode: args.mode,
        max_error: args.error_bound(),
        stats: mesh.stats,
        read: read_time,
        extract: extract_time,
        write: clock.elapsed(),
        paper_knot,
        edges: args.check.then(|| EdgeReport::of(&mesh.triangles)),
        measured,
    };
    super::commit_with_report(mesh_filled, stats_file, || summary.to_json())?;
    if !quiet {
        println!("{summary}");
    }
    Ok(())
}

/// The input's format (none for `--demo`), once the arguments are known to fit it.
fn check_input(args: &ExtractArgs, options: &ReadOptions) -> Result<Option<Format>> {
    match &args.input {
        Some(input) => {
            let format = Format::detect(input, options)?;
            if args.iso.is_none() {
                return Err(Error::Usage(format!(
                    "--iso is required for {}; `skelclimb info {}` suggests values",
                    input.display(),
                    input.display()
                )));
            }
            Ok(Some(format))
        }
        None if *options != ReadOptions::default() => Err(Error::Usage(
            "--dims, --dtype, --endian, --header-bytes and --array describe input files, not --demo"
                .into(),
        )),
        None => Ok(None),
    }
}

/// Refuses options that do not fit a single output file (clap does not enforce `requires`
/// beside `-o`'s conflict with --shards), and outputs that would overwrite the input or each
/// other.
fn check_output(args: &ExtractArgs, output: &Output) -> Result<()> {
    if args.block.is_some() {
        return Err(Error::Usage("--block applies with --shards only".into()));
    }
    if args.max_box.is_some() && args.mode != Mode::Adaptive {
        return Err(Error::Usage(
            "--max-box applies with --mode adaptive only".into(),
        ));
    }
    if args.allow_wrong_side && args.mode != Mode::Adaptive {
        return Err(Error::Usage(
            "--allow-wrong-side applies with --mode adaptive only".into(),
        ));
    }
    if args.ascii && output.format != MeshFormat::Ply {
        return Err(Error::Usage("--ascii applies to .ply output only".into()));
    }
    check_outputs(
        args.input.as_deref(),
        &output.path,
        args.stats_json.as_deref(),
    )
}

/// The volume to mesh: in memory, or open to be read a slab at a time.
pub(super) enum Volume {
    Whole(Grid),
    /// The grid of a stream holds the placement and type, not the samples.
    Streamed(Stream),
}

impl Volume {
    pub(super) fn grid(&self) -> &Grid {
        match self {
            Volume::Whole(grid) => grid,
            Volume::Streamed(stream) => &stream.grid,
        }
    }

    pub(super) fn grid_mut(&mut self) -> &mut Grid {
        match self {
            Volume::Whole(grid) => grid,
            Volume::Streamed(stream) => &mut stream.grid,
        }
    }
}

/// The volume, its iso value and its name for messages: streamed when [`open_stream`] says so,
/// otherwise read whole (or built in).
pub(super) fn open(
    args: &ExtractArgs,
    format: Option<Format>,
    options: &ReadOptions,
    progress: &dyn Progress,
) -> Result<(Volume, f64, String)> {
    if let (Some(path), Some(format)) = (&args.input, format)
        && let Some(stream) = open_stream(args, path, format, options)?
    {
        let iso = args.iso.unwrap_or_default();
        return Ok((Volume::Streamed(stream), iso, path.display().to_string()));
    }
    let (grid, iso, input) = load(args, options, progress)?;
    Ok((Volume::Whole(grid), iso, input))
}

/// The input opened for reading slab by slab, if it is to be read so: with --stream (refused for
/// a format that is only read whole), and without --pad (which needs every sample at once) for
/// a Zarr store or for samples that would fill more than half the machine's memory.
fn open_stream(
    args: &ExtractArgs,
    path: &Path,
    format: Format,
    options: &ReadOptions,
) -> Result<Option<Stream>> {
    if args.stream {
        return match stream::open(path, options)? {
            Some(stream) => Ok(Some(stream)),
            None => Err(Error::Usage(format!(
                "{}: --stream reads raw files, NIfTI (.nii, .nii.gz) and Zarr slice by slice; \
                 this file is read whole",
                path.display()
            ))),
        };
    }
    if args.pad {
        Ok(None)
    } else if format == Format::Zarr {
        // Streamed without being asked only if it would fit whole: a header that claims more
        // is refused here, before the sweep allocates by it, unless --stream says to go on.
        let stream = stream::open(path, options)?;
        if let Some(stream) = &stream {
            stream.check_whole().map_err(|e| match e {
                Error::File { path, message } => Error::File {
                    path,
                    message: format!("{message}; --stream meshes it a few slices at a time"),
                },
                e => e,
            })?;
        }
        Ok(stream)
    } else {
        // A header that does not open here is the whole read's to report, in its words.
        Ok(stream::open(path, options).ok().flatten().filter(too_big))
    }
}

/// Whether the samples of `stream` would take more than half the machine's memory, so that
/// reading them slice by slice is the only sane way. Unknown memory (not Linux) says no.
fn too_big(stream: &Stream) -> bool {
    let grid = &stream.grid;
    let bytes = grid.dims.iter().product::<usize>() as u64 * grid.samples.dtype().size() as u64;
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
        let kib = m.lines().find(|l| l.starts_with("MemTotal:"))?;
        kib.split_whitespace().nth(1)?.parse::<u64>().ok()
    });
    total.is_some_and(|kib| bytes > kib * 1024 / 2)
}

/// Applies `--spacing`, `--origin` and `--pad` to `grid`.
fn place(args: &ExtractArgs, grid: &mut Grid, iso: f64, input: &str) -> Result<()> {
    args.placement.apply(grid);
    if args.pad {
        grid.pad(iso).map_err(|e| Error::file(input, e))?;
    }
    Ok(())
}

/// Why the mesh is empty, in words. The value range is only needed for this, so the pass over
/// every sample is made only then, and not at all over a volume that was streamed.
fn why_empty(volume: &Volume, iso: f64) -> String {
    match volume {
        Volume::Whole(grid) => surface::why_empty(&grid.range(), iso),
        Volume::Streamed(_) => None,
    }
    .unwrap_or_else(|| "no sample is on both sides of the iso value".into())
}

/// For the paper's knot at the paper's size and iso: the triangles of paper mode, printed beside
/// Table 1's figures (meshed again, in paper mode and without any --max-error, if the run was in
/// another mode).
fn paper_knot(
    args: &ExtractArgs,
    volume: &Volume,
    request: &Request,
    mesh: &Mesh,
) -> Result<Option<u64>> {
    let is_paper_knot = args.demo == Some(Demo::Knot)
        && args.size == 64
        && args.iso.is_none_or(|i| i == request.iso);
    match volume {
        _ if !is_paper_knot => Ok(None),
        _ if args.mode == Mode::Paper => Ok(Some(mesh.stats.triangles)),
        Volume::Whole(grid) => {
            // Paper mode, without adaptive mode's options, which it refuses.
            let request = Request {
                mode: Mode::Paper,
                normals: false,
                max_error: None,
                max_box: None,
                allow_wrong_side: false,
                ..*request
            };
            Ok(Some(
                surface::extract(grid, &request, &Silent)?.stats.triangles,
            ))
        }
        // A built-in volume is never streamed.
        Volume::Streamed(_) => Ok(None),
    }
}

/// Writes `mesh` into `file`, counting the bytes for the progress bar.
fn write_mesh(
    file: AtomicFile,
    mesh: &Mesh,
    format: MeshFormat,
    options: &WriteOptions,
    progress: &dyn Progress,
) -> Result<Filled> {
    progress.phase("writing", approx_bytes(mesh, format, options.ascii));
    file.fill(|out| {
        let mut counted = Counted::new(out, progress);
        format.write(mesh, options, &mut counted)?;
        counted.flush()
    })
}

/// The volume read whole (or built in), its iso value, and its name for messages.
pub(super) fn load(
    args: &ExtractArgs,
    options: &ReadOptions,
    progress: &dyn Progress,
) -> Result<(Grid, f64, String)> {
    match (&args.input, args.demo) {
        (Some(path), _) => Ok((
            read::read(path, options, progress)?,
            args.iso.unwrap_or_default(),
            path.display().to_string(),
        )),
        (None, Some(demo)) => {
            let (grid, iso) = builtin::grid(demo, args.size);
            Ok((
                grid,
                args.iso.unwrap_or(iso),
                format!("{} {}³", builtin::name(demo), args.size),
            ))
        }
        (None, None) => Err(Error::Usage("give an input volume or --demo".into())),
    }
}

/// What the arguments ask the extractor for.
fn request(args: &ExtractArgs, iso: f64) -> Request {
    Request {
        iso,
        mode: args.mode,
        normals: !args.no_normals,
        threads: args.threads,
        coordinates: args.space,
        max_error: args.error_bound(),
        max_box: args.max_box,
        allow_wrong_side: args.allow_wrong_side,
    }
}

/// `extract --shards`: one shard per block and a manifest instead of one mesh file.
fn shards(args: &ExtractArgs, dir: &Path, options: &ReadOptions, quiet: bool) -> Result<()> {
    let progress = Bar::new(!quiet);
    let (mut grid, iso, input) = load(args, options, &progress)?;
    for warning in &grid.warnings {
        warn(warning);
    }
    place(args, &mut grid, iso, &input)?;
    let block = args.block_cubes();
    let manifest = surface::extract_shards(&grid, &request(args, iso), block, dir, &progress)?;
    progress.finish();
    if !quiet {
        print_shards(&input, manifest.shards.len(), block, dir);
    }
    Ok(())
}

/// The summary of `extract --shards`: how many, where, and how to join them.
pub(super) fn print_shards(input: &str, shards: usize, block: usize, dir: &Path) {
    let manifest_path = dir.join(sc_io::shard::MANIFEST_NAME);
    println!(
        "{input}: {shards} shards of up to {block}³ cubes in {}; join them with `skelclimb merge {}`",
        dir.display(),
        manifest_path.display()
    );
}

/// About how many bytes `format` writes for `mesh`, for the progress bar: exact for binary PLY
/// and STL up to the header, a fair guess for the text formats.
pub(super) fn approx_bytes(mesh: &Mesh, format: MeshFormat, ascii: bool) -> u64 {
    let v = mesh.positions.len() as u64;
    let n = mesh.normals.len() as u64;
    let t = mesh.triangles.len() as u64;
    let binary = match format {
        MeshFormat::Ply => 12 * (v + n) + 13 * t,
        MeshFormat::Stl => 84 + 50 * t,
        MeshFormat::Glb => 12 * (v + n) + 12 * t,
        MeshFormat::Obj => 3 * (12 * (v + n) + 12 * t),
    };
    if ascii { 3 * binary } else { binary }
}

/// Refuses a run whose outputs would overwrite its input or each other.
pub(super) fn check_outputs(input: Option<&Path>, mesh: &Path, stats: Option<&Path>) -> Result<()> {
    let clash = |what: &str, a: &Path, b: &Path| -> Result<()> {
        if same_place(a, b) {
            return Err(Error::Usage(format!(
                "{what} {} is the same file as {}; choose another name",
                a.display(),
                b.display()
            )));
        }
        Ok(())
    };
    if let Some(input) = input {
        clash("-o", mesh, input)?;
    }
    if let Some(stats) = stats {
        clash("--stats-json", stats, mesh)?;
        if let Some(input) = input {
            clash("--stats-json", stats, input)?;
        }
    }
    Ok(())
}

/// Whether two paths name the same file, whether or not it exists yet: links are followed to
/// where an output would land (a dangling link too), the folder is resolved (links, `..`) and
/// the names compared.
fn same_place(a: &Path, b: &Path) -> bool {
    let resolve = |p: &Path| -> Option<PathBuf> {
        let p = &sc_io::atomic::destination(p).ok()?;
        if let Ok(full) = p.canonicalize() {
            return Some(full);
        }
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(dir.canonicalize().ok()?.join(p.file_name()?))
    };
    matches!((resolve(a), resolve(b)), (Some(x), Some(y)) if x == y)
}
