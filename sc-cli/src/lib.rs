//! `skelclimb`: Skeleton Climbing isosurfaces from volume files. The readers and writers live in
//! `sc-io`, shared with the Python package; this crate is the commands.

pub mod builtin;
pub mod check;
pub mod cli;
pub mod cmd;
pub mod histogram;
pub mod interrupt;
pub mod progress;
pub mod render;
pub mod summary;

pub use sc_io::{Error, Result};

/// Runs a parsed command line.
pub fn run(cli: &cli::Cli) -> Result<()> {
    match &cli.command {
        cli::Command::Extract(args) => cmd::extract::run(args, cli.quiet),
        cli::Command::Info(args) => cmd::info::run(args, cli.quiet),
        cli::Command::Table1(args) => cmd::table1::run(args, cli.quiet),
        cli::Command::Render(args) => render::run(args, cli.quiet),
        cli::Command::Merge(args) => cmd::merge::run(args, cli.quiet),
    }
}
