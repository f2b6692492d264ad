//! `skelclimb`: Skeleton Climbing isosurfaces from volume files, as a command and as a library
//! of readers and writers that the command is a thin layer over.

pub mod atomic;
pub mod builtin;
pub mod check;
pub mod cli;
pub mod cmd;
pub mod error;
pub mod histogram;
pub mod progress;
pub mod read;
pub mod summary;
pub mod surface;
pub mod volume;
pub mod write;

pub use error::{Error, Result};

/// Runs a parsed command line.
pub fn run(cli: &cli::Cli) -> Result<()> {
    match &cli.command {
        cli::Command::Extract(args) => cmd::extract::run(args, cli.quiet),
        cli::Command::Info(args) => cmd::info::run(args, cli.quiet),
        cli::Command::Table1(args) => cmd::table1::run(args, cli.quiet),
    }
}
