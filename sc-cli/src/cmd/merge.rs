//! `skelclimb merge`: shards in, one mesh out (or, for a label volume's shards, its meshes).

use std::time::Instant;

use serde_json::json;

use sc_runtime::Mode;

use crate::cli::{MergeArgs, Output};
use crate::summary::{self, mode_name, thousands};
use sc_io::atomic::AtomicFile;
use sc_io::labels::LabelSettings;
use sc_io::shard::{self, ShardSettings};
use sc_io::write::{MeshFormat, WriteOptions};
use sc_io::{Error, Result};

/// Joins the shards the manifest lists and writes the mesh (and the counts), whole or not at all.
/// The manifest's kind is read first, to know what `-o` must name.
pub fn run(args: &MergeArgs, quiet: bool) -> Result<()> {
    if shard::kind(&args.manifest)? == LabelSettings::KIND {
        return super::labels::merge(args, quiet);
    }
    let output = Output::new(args.output.clone())
        .map_err(|e| Error::Usage(format!("-o {}: {e}", args.output.display())))?;
    if args.format.is_some() {
        return Err(Error::Usage(
            "--format applies to label shards merged into a directory; -o's extension chooses \
             the mesh format"
                .into(),
        ));
    }
    if args.ascii && output.format != MeshFormat::Ply {
        return Err(Error::Usage("--ascii applies to .ply output only".into()));
    }
    let mesh_file = AtomicFile::create(&output.path)?;
    let stats_file = args
        .stats_json
        .as_deref()
        .map(AtomicFile::create)
        .transpose()?;
    let clock = Instant::now();
    let (manifest, mesh) = shard::merge(&args.manifest)?;
    let merge_time = clock.elapsed();
    let clock = Instant::now();
    let options = WriteOptions {
        ascii: args.ascii,
        space: manifest.world.space,
    };
    let mesh_filled = mesh_file.fill(|out| output.format.write(&mesh, &options, out))?;
    let write_time = clock.elapsed();
    let settings = &manifest.settings;
    super::commit_with_report(mesh_filled, stats_file, || {
        let mut j = json!({
            "manifest": args.manifest.display().to_string(),
            "shards": manifest.shards.len(),
            "dims": manifest.grid,
            "iso": settings.iso,
            "seconds": { "merge": merge_time.as_secs_f64(), "write": write_time.as_secs_f64() },
        });
        summary::add_counts(&mut j, settings.mode, settings.max_error, &mesh.stats);
        j
    })?;
    if !quiet {
        println!(
            "{}: {} vertices, {} triangles\n  time: merge {:.3} s, write {:.3} s",
            described(args, manifest.shards.len(), manifest.grid, settings.mode),
            thousands(mesh.stats.vertices),
            thousands(mesh.stats.triangles),
            merge_time.as_secs_f64(),
            write_time.as_secs_f64(),
        );
    }
    Ok(())
}

/// The start of `merge`'s report in words: the manifest, its shards, grid and mode.
pub(super) fn described(args: &MergeArgs, shards: usize, grid: [usize; 3], mode: Mode) -> String {
    format!(
        "{}: {shards} shards of a {} × {} × {} grid, {}",
        args.manifest.display(),
        grid[0],
        grid[1],
        grid[2],
        mode_name(mode)
    )
}
