//! Opening input files: only regular files are read. Opening a FIFO for reading waits for a
//! writer, which may never come, and a device can be endless; refused before they are opened,
//! they cannot hang a command, a Python call or a merge.

use std::fs::File;
use std::path::Path;

use crate::error::{Error, Result};

/// Opens `path` for reading if it is a regular file (a symbolic link to one is followed).
pub(crate) fn open(path: &Path) -> Result<File> {
    regular(path)?;
    File::open(path).map_err(|e| Error::io(path, e))
}

/// Refuses `path` unless it is a regular file.
pub(crate) fn regular(path: &Path) -> Result<()> {
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if meta.is_file() {
        Ok(())
    } else if meta.is_dir() {
        Err(Error::file(path, "is a folder, where a file was expected"))
    } else {
        Err(Error::file(
            path,
            "is not a regular file (a FIFO, a socket or a device): only files are read",
        ))
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// A FIFO is refused without being opened (opening it would wait for a writer forever); a
    /// folder and a missing file are refused with their own words; a file opens.
    #[test]
    fn only_regular_files_open() {
        let dir = std::env::temp_dir().join(format!("sc-io-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo reads a NUL-terminated path that lives for the call.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = open(&fifo).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
        let e = open(&dir).unwrap_err().to_string();
        assert!(e.contains("is a folder"), "{e}");
        let e = open(&dir.join("missing")).unwrap_err().to_string();
        assert!(e.contains("no such file"), "{e}");
        let file = dir.join("file");
        std::fs::write(&file, b"x").unwrap();
        assert!(open(&file).is_ok());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
