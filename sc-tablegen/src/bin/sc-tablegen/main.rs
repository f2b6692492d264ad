//! `sc-tablegen`: generate, verify, inspect and tune the Skeleton Climbing tables.

mod dump;
mod locate;
mod measure;
mod svg;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use locate::Source;
use sc_tablegen::{ORDER0, TableSet};

#[derive(Parser)]
#[command(
    version,
    about = "Generate, verify and inspect the Skeleton Climbing case tables"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Generate and validate all 2048 entries, then write them as RON.
    Generate {
        /// Where to write the tables; its folder is created if missing [default: the checkout's
        /// tables/skeleton-climbing.ron, or ./tables/skeleton-climbing.ron outside a checkout].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Class 0's order of the nine non-grey edges, comma-separated (default: the chosen one).
        #[arg(long, value_parser = parse_order)]
        order: Option<[u8; 9]>,
    },
    /// Fail (exit 1) with a diff summary when the tables file differs from fresh generation.
    Verify {
        /// The committed tables file [default: tables/skeleton-climbing.ron in the checkout that
        /// holds the current directory].
        #[arg(long)]
        tables: Option<PathBuf>,
    },
    /// Show entries, statistics or pictures of a tables file.
    Dump {
        /// The tables file to read [default: the checkout's, or the copy built into this binary
        /// outside a checkout].
        #[arg(long)]
        tables: Option<PathBuf>,
        /// Parity class 0..=7 (default: all classes).
        #[arg(long, value_parser = clap::value_parser!(u8).range(0..8))]
        class: Option<u8>,
        /// Case: decimal, 0x67 or 0b01100111 (default: all cases).
        #[arg(long, value_parser = parse_case)]
        case: Option<u8>,
        /// Output format.
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
        /// Print the summary: entries per rule, forced folds per class, triangles per entry.
        #[arg(long)]
        stats: bool,
        /// Write one SVG picture per selected case into this directory.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Measure total interior side length (L1) on real volumes for candidate non-grey orders.
    OptimizeOrder {
        /// A volume's JSON description (`dims`, `dtype`, `iso_suggestions`) next to its `.raw`.
        #[arg(long, required = true)]
        volume: Vec<PathBuf>,
        /// Random candidate orders to try besides the current one.
        #[arg(long, default_value_t = 200)]
        candidates: usize,
        /// Seed for the candidate orders.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Text,
    Ron,
    Json,
}

fn main() -> ExitCode {
    // `sc-tablegen dump | head`: end quietly when the reader stops, as Unix tools do, rather
    // than panic in `println!` (Rust ignores SIGPIPE by default).
    #[cfg(unix)]
    // SAFETY: SIG_DFL at start-up, before any thread exists, installs no handler code.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    match run(Cli::parse().command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("sc-tablegen: {msg}");
            ExitCode::FAILURE
        }
    }
}

fn run(command: Command) -> Result<(), String> {
    match command {
        Command::Generate { out, order } => {
            let set = generate(&order.unwrap_or(ORDER0))?;
            let out = out.unwrap_or_else(locate::default_output);
            write_atomic(&out, &set.to_ron())?;
            println!(
                "wrote {} ({} entries, all valid)",
                out.display(),
                set.classes.len() * 256
            );
            Ok(())
        }
        Command::Verify { tables } => {
            let source = Source::find(tables, false)?;
            let committed = load(&source)?;
            let tables = source.describe();
            let fresh = generate(&ORDER0)?;
            if committed.to_ron() == fresh.to_ron() {
                println!("{tables} matches fresh generation (2048 entries)");
                return Ok(());
            }
            let diffs = dump::diff(&committed, &fresh);
            let mut msg = format!("{tables} differs from fresh generation: ");
            if committed.order != fresh.order {
                msg.push_str(&format!(
                    "order {:?} vs built-in {:?}; ",
                    committed.order, fresh.order
                ));
            }
            msg.push_str(&format!(
                "{} entries differ; run `sc-tablegen generate` and commit tables/",
                diffs.len()
            ));
            for d in diffs.iter().take(20) {
                msg.push_str("\n  ");
                msg.push_str(d);
            }
            Err(msg)
        }
        Command::Dump {
            tables,
            class,
            case,
            format,
            stats,
            svg,
        } => {
            let set = load(&Source::find(tables, true)?)?;
            if stats {
                print!("{}", dump::stats(&set));
                return Ok(());
            }
            let classes: Vec<u8> = class.map_or((0..8).collect(), |c| vec![c]);
            let cases: Vec<u8> = case.map_or((0..=255).collect(), |c| vec![c]);
            if let Some(dir) = svg {
                return svg::write_all(&set, &classes, &cases, &dir);
            }
            match format {
                Format::Text => {
                    for &p in &classes {
                        for &c in &cases {
                            println!("{}", dump::text(&set, p, c));
                        }
                    }
                }
                Format::Ron | Format::Json => {
                    let sel = dump::select(&set, &classes, &cases);
                    let text = if matches!(format, Format::Json) {
                        serde_json::to_string_pretty(&sel).map_err(|e| e.to_string())?
                    } else {
                        sel.to_ron()
                    };
                    println!("{}", text.trim_end());
                }
            }
            Ok(())
        }
        Command::OptimizeOrder {
            volume,
            candidates,
            seed,
        } => measure::optimize(&volume, candidates, seed),
    }
}

fn generate(order: &[u8; 9]) -> Result<TableSet, String> {
    sc_tablegen::generate(order).map_err(|errors| {
        let mut msg = format!("{} invalid entries:", errors.len());
        for e in errors.iter().take(20) {
            msg.push_str(&format!("\n  {e}"));
        }
        msg
    })
}

fn load(source: &Source) -> Result<TableSet, String> {
    let text = match source {
        Source::File(path) => std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read {}: {e}", path.display()))?,
        Source::Embedded => locate::EMBEDDED.to_string(),
    };
    TableSet::from_ron(&text).map_err(|e| format!("{}: malformed tables: {e}", source.describe()))
}

/// Writes through a temporary file in the same directory, so a failure never leaves half a table.
fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    }
    let tmp = path.with_extension("ron.tmp");
    std::fs::write(&tmp, text)
        .and_then(|()| std::fs::rename(&tmp, path))
        .map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            format!("cannot write {}: {e}", path.display())
        })
}

fn parse_case(s: &str) -> Result<u8, String> {
    let parsed = if let Some(hex) = s.strip_prefix("0x").or_else(|| s.strip_prefix("0X")) {
        u32::from_str_radix(hex, 16)
    } else if let Some(bin) = s.strip_prefix("0b").or_else(|| s.strip_prefix("0B")) {
        u32::from_str_radix(bin, 2)
    } else {
        s.parse::<u32>()
    };
    let n = parsed.map_err(|_| format!("`{s}` is not a number (use 103, 0x67 or 0b01100111)"))?;
    u8::try_from(n).map_err(|_| format!("case {n} is out of range 0..=255"))
}

fn parse_order(s: &str) -> Result<[u8; 9], String> {
    let edges: Vec<u8> = s
        .split(',')
        .map(|e| {
            e.trim()
                .parse::<u8>()
                .map_err(|_| format!("`{e}` is not an edge id"))
        })
        .collect::<Result<_, _>>()?;
    let nine: [u8; 9] = edges
        .try_into()
        .map_err(|_| "an order lists exactly nine edges".to_string())?;
    if sc_tablegen::order::is_valid_nine(&nine) {
        Ok(nine)
    } else {
        Err(format!(
            "{nine:?} is not a permutation of class 0's non-grey edges 0,1,2,4,6,7,9,10,11"
        ))
    }
}
