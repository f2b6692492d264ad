//! One error type for the whole tool, so that `main` can pick the exit code in one place.

use std::fmt::Display;
use std::io;
use std::path::{Path, PathBuf};

/// Why a command failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The command line is inconsistent in a way clap cannot see (e.g. `--dims` on a NIfTI file).
    /// Exit code 2, like clap's own usage errors.
    #[error("{0}")]
    Usage(String),
    /// A file could not be read, understood or written. Exit code 1.
    #[error("{}: {message}", path.display())]
    File {
        /// The file the user has to look at.
        path: PathBuf,
        /// What is wrong with it, in words.
        message: String,
    },
    /// The extractor refused the volume (e.g. more than `u32::MAX` vertices). Exit code 1.
    #[error("extraction failed: {0}")]
    Extract(#[from] sc_runtime::Error),
}

impl Error {
    /// A problem with `path`.
    pub fn file(path: impl AsRef<Path>, message: impl Display) -> Self {
        Error::File {
            path: path.as_ref().to_path_buf(),
            message: message.to_string(),
        }
    }

    /// An I/O failure on `path`, in words a user can act on rather than an errno name.
    pub fn io(path: impl AsRef<Path>, err: io::Error) -> Self {
        let message = match err.kind() {
            io::ErrorKind::NotFound => "no such file or directory".to_string(),
            io::ErrorKind::PermissionDenied => "permission denied".to_string(),
            io::ErrorKind::UnexpectedEof if err.get_ref().is_none() => {
                "the file ends early (truncated?)".to_string()
            }
            _ => err.to_string(),
        };
        Error::file(path, message)
    }

    /// The process exit code: 2 for usage errors (as clap uses), 1 for everything else.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Usage(_) => 2,
            _ => 1,
        }
    }
}

/// Results of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// `e` and its causes, `: `-separated: dicom-rs in particular puts the useful part (which tag,
/// which byte) in the causes.
pub fn with_causes(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}
