//! `skelclimb extract --labels`: every region of a label volume, one closed mesh each.

use std::path::Path;
use std::time::Instant;

use serde_json::json;

use super::extract::{Volume, check_outputs};
use super::warn;
use crate::cli::ExtractArgs;
use crate::progress::Bar;
use crate::summary::{mode_name, thousands};
use sc_io::atomic::AtomicFile;
use sc_io::labels::{self, LabelMeshes, LabelRequest, LabelTable};
use sc_io::read::Format;
use sc_io::write::{LabelFiles, LabelMesh, MeshFormat, WriteOptions, write_atlas};
use sc_io::{Error, Result, report};

/// Where the meshes go.
enum Target<'a> {
    /// One .glb file, a node per label.
    Atlas(&'a Path),
    /// A directory, a file per label.
    Files(&'a Path),
}

/// Reads the label volume, meshes the labels asked for and writes them: all files or none.
pub fn run(args: &ExtractArgs, quiet: bool) -> Result<()> {
    let options = args.read.read_options();
    let Some(input) = &args.input else {
        return Err(Error::Usage("--labels needs an input volume".into()));
    };
    let format = Format::detect(input, &options)?;
    let Some(output) = &args.output else {
        return Err(Error::Usage(
            "give -o ATLAS.glb (a node per label) or -o DIR (a file per label)".into(),
        ));
    };
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
    if args.ascii && (matches!(target, Target::Atlas(_)) || args.format != MeshFormat::Ply) {
        return Err(Error::Usage("--ascii applies to .ply output only".into()));
    }
    check_outputs(Some(input), output, args.stats_json.as_deref())?;
    let table = match &args.label_table {
        Some(path) => Some(LabelTable::read(path)?),
        None => {
            let beside = LabelTable::beside(input);
            for error in &beside.unread {
                warn(format!("label table not used: {error}"));
            }
            beside.table
        }
    };
    let stats_file = args
        .stats_json
        .as_deref()
        .map(AtomicFile::create)
        .transpose()?;
    let atlas_file = match target {
        Target::Atlas(path) => Some(AtomicFile::create(path)?),
        Target::Files(_) => None,
    };
    let progress = Bar::new(!quiet);

    let clock = Instant::now();
    let (mut volume, _, _) = super::extract::open(args, Some(format), &options, &progress)?;
    let read_time = clock.elapsed();
    args.placement.apply(volume.grid_mut());
    let clock = Instant::now();
    let request = LabelRequest {
        background: args.background,
        mode: args.mode,
        normals: !args.no_normals,
        threads: args.threads,
        coordinates: args.space,
        selection: args.labels.clone().unwrap_or(labels::Selection::All),
        smoothing: args.smoothing,
    };
    let result = match &mut volume {
        Volume::Whole(grid) => labels::extract(grid, &request, &progress),
        Volume::Streamed(stream) => labels::extract_stream(stream, &request, &progress),
    }
    .map_err(|e| match e {
        Error::Usage(message) => Error::file(input, message),
        e => e,
    })?;
    let extract_time = clock.elapsed();
    let grid = volume.grid();
    for warning in &grid.warnings {
        warn(warning);
    }

    let clock = Instant::now();
    let world = sc_io::space::World::new(grid.frame, grid.origin, args.space);
    let write_options = WriteOptions {
        ascii: args.ascii,
        space: world.space,
    };
    let meshes: Vec<LabelMesh> = result
        .meshes
        .iter()
        .map(|(id, mesh)| LabelMesh {
            id: *id,
            label: table.as_ref().and_then(|t| t.get(*id)),
            mesh: mesh.into(),
        })
        .collect();
    let summary = summary(args, input, grid, &result, [read_time, extract_time]);
    let report = |written: std::time::Duration| {
        let mut json = summary.clone();
        json["seconds"]["write"] = json!(written.as_secs_f64());
        json
    };
    match (target, atlas_file) {
        (Target::Atlas(_), Some(file)) => {
            let filled = file.fill(|out| write_atlas(&meshes, &write_options, out))?;
            let written = clock.elapsed();
            super::commit_with_report(filled, stats_file, || report(written))?;
        }
        (Target::Files(dir), _) => {
            let files = LabelFiles::fill(dir, &meshes, args.format, &write_options)?;
            let written = clock.elapsed();
            let report_file = match stats_file {
                Some(file) => Some(file.fill(|out| {
                    serde_json::to_writer_pretty(out, &report(written))
                        .map_err(std::io::Error::other)
                })?),
                None => None,
            };
            crate::interrupt::finish(|| {
                files.commit()?;
                report_file.map_or(Ok(()), |filled| filled.commit())
            })?;
        }
        (Target::Atlas(_), None) => unreachable!("the atlas file is created with its target"),
    }
    progress.finish();
    if !quiet {
        print(&summary, output);
    }
    Ok(())
}

/// The run's report, as `--stats-json` writes it.
fn summary(
    args: &ExtractArgs,
    input: &Path,
    grid: &sc_io::volume::Grid,
    result: &LabelMeshes,
    [read, extract]: [std::time::Duration; 2],
) -> serde_json::Value {
    let per_label: u64 = result
        .meshes
        .iter()
        .map(|(_, m)| m.triangles.len() as u64)
        .sum();
    json!({
        "input": input.display().to_string(),
        "format": grid.format,
        "dims": grid.dims,
        "dtype": grid.samples.dtype().name(),
        "background": args.background,
        "smoothing": args.smoothing,
        "labels": result.meshes.iter().map(|(id, _)| *id).collect::<Vec<_>>(),
        "atlas": report::counts(args.mode, None, &result.stats),
        "per_label_triangles": per_label,
        "seconds": { "read": read.as_secs_f64(), "extract": extract.as_secs_f64() },
    })
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
