//! `skelclimb extract --labels`: every region of a label volume, one closed mesh each, read
//! whole, streamed or written as shards; and `skelclimb merge` of those shards.

use std::path::Path;
use std::time::Instant;

use serde_json::json;

use super::extract::{Volume, check_outputs};
use super::warn;
use crate::cli::{ExtractArgs, MergeArgs};
use crate::progress::Bar;
use crate::summary::{mode_name, thousands};
use sc_io::atomic::AtomicFile;
use sc_io::labels::{self, LabelMeshes, LabelRequest, LabelTable};
use sc_io::read::Format;
use sc_io::write::{LabelFiles, LabelMesh, MeshFormat, WriteOptions, write_atlas};
use sc_io::{Error, Result, report};
use sc_runtime::Mode;

/// Where the meshes go.
enum Target<'a> {
    /// One .glb file, a node per label.
    Atlas(&'a Path),
    /// A directory, a file per label.
    Files(&'a Path),
}

impl<'a> Target<'a> {
    /// Where `-o output` puts the meshes: a .glb atlas, or a directory of `format` files.
    fn new(output: &'a Path, format: MeshFormat, ascii: bool) -> Result<Target<'a>> {
        let target = match MeshFormat::from_path(output) {
            Ok(MeshFormat::Glb) => Target::Atlas(output),
            Ok(_) => {
                return Err(Error::Usage(format!(
                    "-o {}: with --labels, give a .glb file (a node per label) or a directory (a \
                     file per label, in --format)",
                    output.display()
                )));
            }
            Err(_) => Target::Files(output),
        };
        if ascii && (matches!(target, Target::Atlas(_)) || format != MeshFormat::Ply) {
            return Err(Error::Usage("--ascii applies to .ply output only".into()));
        }
        Ok(target)
    }

    /// Opens the atlas file (a directory's files are opened when written) and the report file,
    /// before the long work, so that a bad path fails first.
    fn create(self, format: MeshFormat, stats: Option<&Path>) -> Result<Outputs<'a>> {
        let stats = stats.map(AtomicFile::create).transpose()?;
        let atlas = match self {
            Target::Atlas(path) => Some(AtomicFile::create(path)?),
            Target::Files(_) => None,
        };
        Ok(Outputs {
            target: self,
            format,
            atlas,
            stats,
        })
    }
}

/// The files a run writes, opened.
struct Outputs<'a> {
    target: Target<'a>,
    /// The format of a directory's files.
    format: MeshFormat,
    atlas: Option<AtomicFile>,
    stats: Option<AtomicFile>,
}

impl Outputs<'_> {
    /// Writes the meshes of `result`, named and coloured by `table`, and the report `report`
    /// gives for the time the writing took: all files or none.
    fn write(
        self,
        result: &LabelMeshes,
        table: Option<&LabelTable>,
        options: &WriteOptions,
        report: impl FnOnce(std::time::Duration) -> serde_json::Value,
    ) -> Result<()> {
        let clock = Instant::now();
        let meshes: Vec<LabelMesh> = result
            .meshes
            .iter()
            .map(|(id, mesh)| LabelMesh {
                id: *id,
                label: table.and_then(|t| t.get(*id)),
                mesh: mesh.into(),
            })
            .collect();
        match (self.target, self.atlas) {
            (Target::Atlas(_), Some(file)) => {
                let filled = file.fill(|out| write_atlas(&meshes, options, out))?;
                let written = clock.elapsed();
                super::commit_with_report(filled, self.stats, || report(written))
            }
            (Target::Files(dir), _) => {
                let files = LabelFiles::fill(dir, &meshes, self.format, options)?;
                let written = clock.elapsed();
                let report_file = match self.stats {
                    Some(file) => Some(file.fill(|out| {
                        serde_json::to_writer_pretty(out, &report(written))
                            .map_err(std::io::Error::other)
                    })?),
                    None => None,
                };
                crate::interrupt::finish(|| {
                    files.commit()?;
                    report_file.map_or(Ok(()), |filled| filled.commit())
                })
            }
            (Target::Atlas(_), None) => unreachable!("the atlas file is created with its target"),
        }
    }
}

/// Reads the label volume, meshes the labels asked for and writes them: all files or none.
pub fn run(args: &ExtractArgs, quiet: bool) -> Result<()> {
    let options = args.read.read_options();
    let Some(input) = &args.input else {
        return Err(Error::Usage("--labels needs an input volume".into()));
    };
    let format = Format::detect(input, &options)?;
    if let Some(dir) = &args.shards {
        return shards(args, input, dir, quiet);
    }
    let Some(output) = &args.output else {
        return Err(Error::Usage(
            "give -o ATLAS.glb (a node per label) or -o DIR (a file per label)".into(),
        ));
    };
    let target = Target::new(output, args.format, args.ascii)?;
    check_outputs(Some(input), output, args.stats_json.as_deref())?;
    let table = table(args, input)?;
    let outputs = target.create(args.format, args.stats_json.as_deref())?;
    let progress = Bar::new(!quiet);

    let clock = Instant::now();
    let (mut volume, _, _) = super::extract::open(args, Some(format), &options, &progress)?;
    let read_time = clock.elapsed();
    args.placement.apply(volume.grid_mut());
    let clock = Instant::now();
    let request = request(args);
    let result = match &mut volume {
        Volume::Whole(grid) => labels::extract(grid, &request, &progress),
        Volume::Streamed(stream) => labels::extract_stream(stream, &request, &progress),
    }
    .map_err(|e| at_file(e, input))?;
    let extract_time = clock.elapsed();
    let grid = volume.grid();
    for warning in &grid.warnings {
        warn(warning);
    }

    let world = sc_io::space::World::new(grid.frame, grid.origin, args.space);
    let write_options = WriteOptions {
        ascii: args.ascii,
        space: world.space,
    };
    let summary = summary(args, input, grid, &result, [read_time, extract_time]);
    outputs.write(&result, table.as_ref(), &write_options, |written| {
        let mut json = summary.clone();
        json["seconds"]["write"] = json!(written.as_secs_f64());
        json
    })?;
    progress.finish();
    if !quiet {
        print(&summary, output);
    }
    Ok(())
}

/// A usage error found in the volume (a label no sample holds) as an error naming `file`.
fn at_file(e: Error, file: &Path) -> Error {
    match e {
        Error::Usage(message) => Error::file(file, message),
        e => e,
    }
}

/// The label table: `--label-table`, or those beside the volume (a table there that cannot be
/// read is a warning, not an error).
fn table(args: &ExtractArgs, input: &Path) -> Result<Option<LabelTable>> {
    Ok(match &args.label_table {
        Some(path) => Some(LabelTable::read(path)?),
        None => {
            let beside = LabelTable::beside(input);
            for error in &beside.unread {
                warn(format!("label table not used: {error}"));
            }
            beside.table
        }
    })
}

/// What the arguments ask of the label sweep.
fn request(args: &ExtractArgs) -> LabelRequest {
    LabelRequest {
        background: args.background,
        mode: args.mode,
        normals: !args.no_normals,
        threads: args.threads,
        coordinates: args.space,
        selection: args.labels.clone().unwrap_or(labels::Selection::All),
        smoothing: args.smoothing,
    }
}

/// `extract --labels --shards`: the volume read whole, a shard per block of its atlas and a
/// manifest that records the table and the selection for `merge`.
fn shards(args: &ExtractArgs, input: &Path, dir: &Path, quiet: bool) -> Result<()> {
    let table = table(args, input)?;
    let progress = Bar::new(!quiet);
    let (mut grid, _, _) = super::extract::load(args, &args.read.read_options(), &progress)?;
    for warning in &grid.warnings {
        warn(warning);
    }
    args.placement.apply(&mut grid);
    let block = args.block_cubes();
    let manifest =
        labels::extract_shards(&grid, &request(args), table.as_ref(), block, dir, &progress)
            .map_err(|e| at_file(e, input))?;
    progress.finish();
    if !quiet {
        super::extract::print_shards(
            &input.display().to_string(),
            manifest.shards.len(),
            block,
            dir,
        );
    }
    Ok(())
}

/// `merge` of label shards: the files `extract --labels -o` writes, all or none.
pub fn merge(args: &MergeArgs, quiet: bool) -> Result<()> {
    let format = args.format.unwrap_or(MeshFormat::Ply);
    let target = Target::new(&args.output, format, args.ascii)?;
    check_outputs(
        Some(&args.manifest),
        &args.output,
        args.stats_json.as_deref(),
    )?;
    let outputs = target.create(format, args.stats_json.as_deref())?;
    let clock = Instant::now();
    let (manifest, result) = labels::merge_shards(&args.manifest)?;
    let merge_time = clock.elapsed();
    let settings = &manifest.settings;
    let write_options = WriteOptions {
        ascii: args.ascii,
        space: manifest.world.space,
    };
    let mut summary = json!({
        "manifest": args.manifest.display().to_string(),
        "shards": manifest.shards.len(),
        "dims": manifest.grid,
        "dtype": settings.dtype.name(),
        "background": settings.background,
        "smoothing": settings.smoothing,
    });
    add_counts(&mut summary, settings.mode, &result);
    summary["seconds"] = json!({ "merge": merge_time.as_secs_f64() });
    outputs.write(
        &result,
        settings.table.as_ref(),
        &write_options,
        |written| {
            summary["seconds"]["write"] = json!(written.as_secs_f64());
            summary.clone()
        },
    )?;
    if !quiet {
        println!(
            "{}: {} labels, atlas {} triangles; per-label meshes {} triangles → {}",
            super::merge::described(args, manifest.shards.len(), manifest.grid, settings.mode),
            result.meshes.len(),
            thousands(result.stats.triangles),
            thousands(per_label_triangles(&result)),
            args.output.display(),
        );
    }
    Ok(())
}

/// Triangles of the meshes per label, together: each interface twice.
fn per_label_triangles(result: &LabelMeshes) -> u64 {
    result
        .meshes
        .iter()
        .map(|(_, m)| m.triangles.len() as u64)
        .sum()
}

/// Adds the labels meshed and the counts to a report.
fn add_counts(json: &mut serde_json::Value, mode: Mode, result: &LabelMeshes) {
    json["labels"] = json!(result.meshes.iter().map(|(id, _)| *id).collect::<Vec<_>>());
    json["atlas"] = serde_json::Value::Object(report::counts(mode, None, &result.stats));
    json["per_label_triangles"] = json!(per_label_triangles(result));
}

/// The run's report, as `--stats-json` writes it.
fn summary(
    args: &ExtractArgs,
    input: &Path,
    grid: &sc_io::volume::Grid,
    result: &LabelMeshes,
    [read, extract]: [std::time::Duration; 2],
) -> serde_json::Value {
    let mut json = json!({
        "input": input.display().to_string(),
        "format": grid.format,
        "dims": grid.dims,
        "dtype": grid.samples.dtype().name(),
        "background": args.background,
        "smoothing": args.smoothing,
    });
    add_counts(&mut json, args.mode, result);
    json["seconds"] = json!({ "read": read.as_secs_f64(), "extract": extract.as_secs_f64() });
    json
}

/// The report in words.
fn print(summary: &serde_json::Value, output: &Path) {
    let labels = summary["labels"].as_array().map_or(0, Vec::len);
    let atlas = &summary["atlas"];
    let count = |v: &serde_json::Value| thousands(v.as_u64().unwrap_or(0));
    let dims: Vec<String> = summary["dims"]
        .as_array()
        .map(|d| d.iter().map(|n| n.to_string()).collect())
        .unwrap_or_default();
    println!(
        "{} ({}, {} {}): {labels} labels, {}",
        summary["input"].as_str().unwrap_or_default(),
        summary["format"].as_str().unwrap_or_default(),
        dims.join("×"),
        summary["dtype"].as_str().unwrap_or_default(),
        mode_name(
            summary["atlas"]["mode"]
                .as_str()
                .and_then(|m| m.parse().ok())
                .unwrap_or_default()
        ),
    );
    println!(
        "  atlas, each interface once: {} triangles, {} vertices; per-label meshes: {} triangles",
        count(&atlas["result"]["triangles"]),
        count(&atlas["result"]["vertices"]),
        count(&summary["per_label_triangles"]),
    );
    println!(
        "  read {:.3} s, meshed {:.3} s → {}",
        summary["seconds"]["read"].as_f64().unwrap_or(0.0),
        summary["seconds"]["extract"].as_f64().unwrap_or(0.0),
        output.display()
    );
}
