//! `skelclimb extract`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use sc_runtime::{Mesh, Mode};

use super::warn;
use crate::builtin;
use crate::check::EdgeReport;
use crate::cli::{Demo, ExtractArgs};
use crate::progress::{Bar, Counted};
use crate::summary::Summary;
use sc_io::atomic::AtomicFile;
use sc_io::progress::Progress;
use sc_io::read::{self, Format, ReadOptions, stream};
use sc_io::surface::{self, Request};
use sc_io::volume::Grid;
use sc_io::write::{MeshFormat, WriteOptions};
use sc_io::{Error, Result};

/// Whether the samples of `path` would take more than half the machine's memory, so that reading
/// them slice by slice is the only sane way. Unknown sizes and memory (not Linux) say no.
fn too_big(path: &Path, options: &ReadOptions) -> bool {
    let Ok(Some(s)) = stream::open(path, options) else {
        return false;
    };
    let bytes = s.grid.dims.iter().product::<usize>() as u64 * s.grid.samples.dtype().size() as u64;
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
        let kib = m.lines().find(|l| l.starts_with("MemTotal:"))?;
        kib.split_whitespace().nth(1)?.parse::<u64>().ok()
    });
    total.is_some_and(|kib| bytes > kib * 1024 / 2)
}

/// Reads, extracts, writes and reports. Output files are opened first, so that a bad output
/// path fails before a long read, and written whole or not at all.
pub fn run(args: &ExtractArgs, quiet: bool) -> Result<()> {
    let options = args.read.read_options();
    match (&args.input, args.demo) {
        (Some(input), _) => {
            Format::detect(input, &options)?;
            if args.iso.is_none() {
                return Err(Error::Usage(format!(
                    "--iso is required for {}; `skelclimb info {}` suggests values",
                    input.display(),
                    input.display()
                )));
            }
        }
        (None, _) if options != read::ReadOptions::default() => {
            return Err(Error::Usage("--dims, --dtype, --endian, --header-bytes and --array describe input files, not --demo".into()));
        }
        _ => {}
    }
    let output = match (&args.output, &args.shards) {
        (_, Some(dir)) => return shards(args, dir, &options, quiet),
        (Some(output), None) => output,
        (None, None) => return Err(Error::Usage("give -o FILE or --shards DIR".into())),
    };
    // clap does not enforce `requires` beside `-o`'s conflict with --shards.
    if args.block.is_some() {
        return Err(Error::Usage("--block applies with --shards only".into()));
    }
    if args.ascii && output.format != MeshFormat::Ply {
        return Err(Error::Usage("--ascii applies to .ply output only".into()));
    }
    check_outputs(
        args.input.as_deref(),
        &output.path,
        args.stats_json.as_deref(),
    )?;
    let mesh_file = AtomicFile::create(&output.path)?;
    let stats_file = args
        .stats_json
        .as_deref()
        .map(AtomicFile::create)
        .transpose()?;
    let progress = Bar::new(!quiet);

    let clock = Instant::now();
    let mut stream = match &args.input {
        Some(path)
            if args.stream
                || (!args.pad
                    && (Format::detect(path, &options)? == Format::Zarr
                        || too_big(path, &options))) =>
        {
            stream::open(path, &options)?
        }
        _ => None,
    };
    if let (true, None, Some(path)) = (args.stream, &stream, &args.input) {
        return Err(Error::Usage(format!(
            "{}: --stream reads raw files, NIfTI (.nii, .nii.gz) and Zarr slice by slice; this \
             file is read whole",
            path.display()
        )));
    }
    let (mut grid, iso, input) = match (&stream, &args.input) {
        (Some(s), Some(path)) => (
            s.grid.clone(),
            args.iso.unwrap_or_default(),
            path.display().to_string(),
        ),
        _ => load(args, &options, &progress)?,
    };
    let read_time = clock.elapsed();
    let file_dims = grid.dims;
    args.placement.apply(&mut grid);
    if args.pad {
        grid.pad(iso).map_err(|e| Error::file(&input, e))?;
    }

    let clock = Instant::now();
    let request = request(args, iso);
    let world = surface::world(&grid, &request);
    let mesh = match &mut stream {
        Some(s) => {
            s.grid.spacing = grid.spacing;
            s.grid.origin = grid.origin;
            surface::extract_stream(s, &request, &progress)?
        }
        None => surface::extract(&grid, &request, &progress)?,
    };
    let extract_time = clock.elapsed();
    // The value range is only needed to explain an empty mesh, so the pass over every sample
    // is made only then (and not at all over a volume that was streamed).
    if mesh.triangles.is_empty() {
        let why = (stream.is_none())
            .then(|| surface::why_empty(&grid.range(), iso))
            .flatten()
            .unwrap_or_else(|| "no sample is on both sides of the iso value".into());
        warn(format!("{input}: {why}; writing an empty mesh"));
    }
    let is_paper_knot =
        args.demo == Some(Demo::Knot) && args.size == 64 && args.iso.is_none_or(|i| i == iso);
    let paper_knot = match args.mode {
        _ if !is_paper_knot => None,
        Mode::Paper => Some(mesh.stats.triangles),
        _ => {
            // Table 1's figure, without any --max-error.
            let request = Request {
                mode: Mode::Paper,
                normals: false,
                max_error: None,
                ..request
            };
            Some(
                surface::extract(&grid, &request, &sc_io::progress::Silent)?
                    .stats
                    .triangles,
            )
        }
    };

    let clock = Instant::now();
    progress.phase("writing", approx_bytes(&mesh, output.format, args.ascii));
    let mesh_filled = mesh_file.fill(|out| {
        let mut counted = Counted::new(out, &progress);
        let options = WriteOptions {
            ascii: args.ascii,
            space: world.space,
        };
        output.format.write(&mesh, &options, &mut counted)?;
        counted.flush()
    })?;
    progress.finish();
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
    };
    super::commit_with_report(mesh_filled, stats_file, || summary.to_json())?;
    if !quiet {
        println!("{summary}");
    }
    Ok(())
}

/// The volume read whole (or built in), its iso value, and its name for messages.
fn load(
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
    }
}

/// `extract --shards`: one shard per block and a manifest instead of one mesh file.
fn shards(args: &ExtractArgs, dir: &Path, options: &ReadOptions, quiet: bool) -> Result<()> {
    let progress = Bar::new(!quiet);
    let (mut grid, iso, input) = load(args, options, &progress)?;
    args.placement.apply(&mut grid);
    if args.pad {
        grid.pad(iso).map_err(|e| Error::file(&input, e))?;
    }
    let block = args.block.unwrap_or(128) as usize;
    let manifest = surface::extract_shards(&grid, &request(args, iso), block, dir, &progress)?;
    progress.finish();
    if !quiet {
        let manifest_path = dir.join(sc_io::shard::MANIFEST_NAME);
        println!(
            "{input}: {} shards of up to {block}³ cubes in {}; join them with `skelclimb merge {}`",
            manifest.shards.len(),
            dir.display(),
            manifest_path.display()
        );
    }
    Ok(())
}

/// About how many bytes `format` writes for `mesh`, for the progress bar: exact for binary PLY
/// and STL up to the header, a fair guess for the text formats.
fn approx_bytes(mesh: &Mesh, format: MeshFormat, ascii: bool) -> u64 {
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
fn check_outputs(input: Option<&Path>, mesh: &Path, stats: Option<&Path>) -> Result<()> {
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

/// Whether two paths name the same file, whether or not it exists yet: the folder is resolved
/// (links, `..`) and the names compared.
fn same_place(a: &Path, b: &Path) -> bool {
    let resolve = |p: &Path| -> Option<PathBuf> {
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
