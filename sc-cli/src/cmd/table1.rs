//! `skelclimb table1`: the paper's Table 1 comparison, rerun.

use std::time::{Duration, Instant};

use sc_runtime::Mode;

use crate::builtin;
use crate::cli::{Demo, Table1Args, split_iso};
use crate::histogram::Histogram;
use crate::progress::Bar;
use crate::summary::{PAPER_KNOT, thousands};
use sc_io::read;
use sc_io::surface::{self, Request};
use sc_io::volume::Grid;
use sc_io::{Error, Result};

const MODES: [Mode; 3] = [Mode::Steps123, Mode::Embedded, Mode::Paper];

/// Runs each volume in the three modes and prints one row per volume.
pub fn run(args: &Table1Args, quiet: bool) -> Result<()> {
    let options = args.read.read_options();
    let files: Vec<_> = args.volumes.iter().map(|v| split_iso(v)).collect();
    for (path, _) in &files {
        read::Format::detect(path, &options)?;
    }
    let progress = Bar::new(!quiet);
    println!(
        "{:<40}{:>22}{:>22}{:>22}",
        "triangles (time)", "Steps 1–3", "Steps 1–4 embedded", "Steps 1–4 paper"
    );
    for demo in [Demo::Knot, Demo::Sphere, Demo::Torus, Demo::SphereNoise] {
        let n = if demo == Demo::Knot { 64 } else { args.size };
        let (grid, iso) = builtin::grid(demo, n);
        row(
            &format!("{} {n}³ (iso {iso})", builtin::name(demo)),
            &grid,
            iso,
            args.threads,
            &progress,
        )?;
        if demo == Demo::Knot {
            let [mc, t13, t14] = PAPER_KNOT.map(thousands);
            println!(
                "{:<40}{:>22}{:>22}{:>22}",
                format!("  the paper (Marching Cubes {mc})"),
                t13,
                "",
                t14
            );
        }
    }
    for (path, iso) in files {
        let grid = read::read(&path, &options, &progress)?;
        let iso = match iso {
            Some(iso) => iso,
            None => Histogram::of(&grid, &grid.range(), 128)
                .otsu()
                .ok_or_else(|| {
                    Error::file(&path, "no Otsu threshold (constant volume?): give FILE@ISO")
                })?,
        };
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        row(
            &format!("{} (iso {iso})", shorten(&name, 30)),
            &grid,
            iso,
            args.threads,
            &progress,
        )?;
    }
    progress.finish();
    Ok(())
}

fn row(label: &str, grid: &Grid, iso: f64, threads: usize, progress: &Bar) -> Result<()> {
    let mut cells = Vec::new();
    for mode in MODES {
        let request = Request {
            mode,
            normals: false,
            threads,
            ..Request::new(iso)
        };
        // The best of three runs: the first also pays for page faults and thread start-up.
        let mut best = Duration::MAX;
        let mut triangles = 0;
        for _ in 0..3 {
            let clock = Instant::now();
            triangles = surface::extract(grid, &request, progress)?.stats.triangles;
            best = best.min(clock.elapsed());
        }
        cells.push(format!("{} ({})", thousands(triangles), millis(best)));
    }
    println!(
        "{label:<40}{:>22}{:>22}{:>22}",
        cells[0], cells[1], cells[2]
    );
    Ok(())
}

/// At most `max` characters, with an ellipsis in the middle when cut.
fn shorten(name: &str, max: usize) -> String {
    let chars: Vec<char> = name.chars().collect();
    if chars.len() <= max {
        return name.to_string();
    }
    let half = (max - 1) / 2;
    let head: String = chars[..half].iter().collect();
    let tail: String = chars[chars.len() - (max - 1 - half)..].iter().collect();
    format!("{head}…{tail}")
}

fn millis(d: Duration) -> String {
    format!("{:.1} ms", d.as_secs_f64() * 1e3)
}
