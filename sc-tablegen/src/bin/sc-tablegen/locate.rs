//! Where the tables file is when `--tables` is not given, so that the command works from any
//! directory: inside a checkout it finds the committed file by walking up from the current
//! directory; elsewhere (an installed binary) `dump` falls back to the copy built into it.

use std::path::{Path, PathBuf};

/// The committed tables, relative to the workspace root.
pub const RELATIVE: &str = "tables/skeleton-climbing.ron";

/// The tables this binary was built with, for `dump` outside a checkout.
pub const EMBEDDED: &str = include_str!("../../../tables/skeleton-climbing.ron");

/// Where tables come from.
pub enum Source {
    /// A file on disk.
    File(PathBuf),
    /// The copy built into the binary.
    Embedded,
}

impl Source {
    /// The tables file for reading: `--tables` if given, else the checkout's; `embedded_ok` lets
    /// the built-in copy stand in when there is no checkout.
    pub fn find(given: Option<PathBuf>, embedded_ok: bool) -> Result<Source, String> {
        if let Some(path) = given {
            return Ok(Source::File(path));
        }
        match workspace_file() {
            Some(path) => Ok(Source::File(path)),
            None if embedded_ok => Ok(Source::Embedded),
            None => Err(format!(
                "no {RELATIVE} found in this directory or any parent; run inside the \
                 skeleton-climbing checkout or give --tables PATH"
            )),
        }
    }

    /// The name used in messages.
    pub fn describe(&self) -> String {
        match self {
            Source::File(path) => path.display().to_string(),
            Source::Embedded => "the built-in tables".into(),
        }
    }
}

/// Where `generate` writes without `--out`: the checkout's tables file, or `tables/` under the
/// current directory outside a checkout.
pub fn default_output() -> PathBuf {
    workspace_file().unwrap_or_else(|| PathBuf::from(RELATIVE))
}

/// `tables/skeleton-climbing.ron` in the nearest ancestor of the current directory that is a
/// Cargo workspace holding one.
fn workspace_file() -> Option<PathBuf> {
    let cwd = std::env::current_dir().ok()?;
    cwd.ancestors().find_map(tables_in)
}

fn tables_in(dir: &Path) -> Option<PathBuf> {
    let path = dir.join(RELATIVE);
    (dir.join("Cargo.toml").is_file() && path.is_file()).then_some(path)
}
