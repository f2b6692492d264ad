//! Output files appear whole or not at all: content goes to a temporary file in the target's
//! directory (so the final rename cannot cross file systems) and is renamed over the target only
//! once complete. An error drops the temporary file; a signal handler can remove it with
//! [`remove_pending`].
//!
//! A target that is a symbolic link is written through: the file the link points to is replaced
//! (atomically, its temporary file made beside it) and the link is kept, as `>` in a shell or an
//! editor's save would leave it. A target that is, or links to, a FIFO, a device or a socket is
//! refused before anything is created: a rename would replace the special file with a regular
//! one, and writing into it would not be atomic (a FIFO would wait for a reader).

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use tempfile::{NamedTempFile, TempPath};

use crate::error::{Error, Result};

/// Temporary files not yet renamed, for [`remove_pending`].
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Removes every temporary file not yet renamed. A signal handler calls it before exiting: the
/// targets are safe without it (the rename never happens), but stray `.tmp` files would remain.
pub fn remove_pending() {
    if let Ok(pending) = PENDING.lock() {
        for path in pending.iter() {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// A file being written to a temporary name beside `target`.
pub struct AtomicFile {
    temp: NamedTempFile,
    /// The path as given, for messages.
    target: PathBuf,
    /// Where the file goes: `target`, or the file its symbolic links lead to.
    dest: PathBuf,
    _pending: Pending,
}

/// Keeps a temporary file's path in [`PENDING`] while it exists.
struct Pending(PathBuf);

impl Pending {
    fn new(path: &Path) -> Self {
        if let Ok(mut pending) = PENDING.lock() {
            pending.push(path.to_path_buf());
        }
        Pending(path.to_path_buf())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if let Ok(mut pending) = PENDING.lock() {
            pending.retain(|p| *p != self.0);
        }
    }
}

/// Symbolic links followed before giving up, as Linux's `ELOOP` limit.
const MAX_LINKS: usize = 40;

/// The path an output written to `target` lands on: `target` itself, or the end of its chain of
/// symbolic links (which need not exist yet: a dangling link creates its target). Relative links
/// are resolved against the folder holding the link.
pub fn destination(target: &Path) -> Result<PathBuf> {
    let mut path = target.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&path) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = std::fs::read_link(&path).map_err(|e| Error::io(&path, e))?;
                path = match path.parent() {
                    Some(dir) => dir.join(link),
                    None => link,
                };
            }
            _ => return Ok(path),
        }
    }
    Err(Error::file(
        target,
        format!("more than {MAX_LINKS} symbolic links lead from it"),
    ))
}

/// What a special file is, in words, or `None` for a regular file (or nothing yet).
#[cfg(unix)]
fn special(meta: &std::fs::Metadata) -> Option<&'static str> {
    use std::os::unix::fs::FileTypeExt;
    let kind = meta.file_type();
    if kind.is_file() {
        None
    } else if kind.is_fifo() {
        Some("a FIFO")
    } else if kind.is_socket() {
        Some("a socket")
    } else if kind.is_char_device() || kind.is_block_device() {
        Some("a device")
    } else {
        Some("not a regular file")
    }
}

#[cfg(not(unix))]
fn special(meta: &std::fs::Metadata) -> Option<&'static str> {
    (!meta.is_file()).then_some("not a regular file")
}

impl AtomicFile {
    /// Creates the temporary file now, so that a missing or unwritable directory is reported
    /// before any slow work. A symbolic link is written through; a target that is (or links to)
    /// a folder, a FIFO, a device or a socket is refused (see the module's documentation).
    pub fn create(target: &Path) -> Result<Self> {
        let dest = destination(target)?;
        let through = if dest == target {
            String::new()
        } else {
            format!(" (a link to {})", dest.display())
        };
        if let Ok(meta) = std::fs::metadata(&dest) {
            if meta.is_dir() {
                return Err(Error::file(target, format!("is a directory{through}")));
            }
            if let Some(kind) = special(&meta) {
                return Err(Error::file(
                    target,
                    format!("is {kind}{through}: outputs are written to regular files only"),
                ));
            }
        }
        let dir = match dest.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        if !dir.is_dir() {
            return Err(Error::file(
                target,
                format!("the directory {} does not exist", dir.display()),
            ));
        }
        let name = dest
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        // The temporary name adds a dot, six random characters and `.tmp` to the target's: keep
        // it short enough that a legal 255-byte target name still has a legal temporary name.
        let cut = (0..=name.len().min(100))
            .rev()
            .find(|&i| name.is_char_boundary(i))
            .unwrap_or(0);
        let short = &name[..cut];
        let prefix = format!(".{short}.");
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".tmp");
        // A temporary file is private (0600) by default, and the rename would keep that: ask for
        // 0666 so the umask gives the output the mode any newly created file gets.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let temp = builder.tempfile_in(dir).map_err(|e| {
            Error::file(
                target,
                format!(
                    "cannot create a file in {}: {}",
                    dir.display(),
                    io_reason(&e)
                ),
            )
        })?;
        let pending = Pending::new(temp.path());
        Ok(AtomicFile {
            temp,
            target: target.to_path_buf(),
            dest,
            _pending: pending,
        })
    }

    /// Writes the content with `fill` through a buffer, then renames the file over the target.
    pub fn write_with(
        self,
        fill: impl FnOnce(&mut BufWriter<Output<'_>>) -> io::Result<()>,
    ) -> Result<()> {
        self.fill(fill)?.commit()
    }

    /// Writes the content to the temporary file and syncs it, without renaming yet: a run with
    /// several outputs fills them all first and renames them only when every one is complete,
    /// so a full disk leaves none of them half-updated.
    pub fn fill(
        self,
        fill: impl FnOnce(&mut BufWriter<Output<'_>>) -> io::Result<()>,
    ) -> Result<Filled> {
        let fail =
            |e: io::Error| Error::file(&self.target, format!("cannot write: {}", io_reason(&e)));
        // 64 KiB: enough to batch the text formats' small writes. The binary writers hand over
        // larger batches, which pass straight through; a larger buffer only adds pages to fault
        // in.
        let mut out = BufWriter::with_capacity(1 << 16, Output::new(self.temp.as_file()));
        fill(&mut out).map_err(fail)?;
        out.flush().map_err(fail)?;
        drop(out);
        self.temp.as_file().sync_all().map_err(fail)?;
        // The file is closed here, keeping only its name: a run with hundreds of outputs (a file
        // per label) would otherwise hold a descriptor for each until the renames, past the usual
        // limit of 256 (macOS) or 1024 (Linux).
        let AtomicFile {
            temp,
            target,
            dest,
            _pending,
        } = self;
        Ok(Filled {
            temp: temp.into_temp_path(),
            target,
            dest,
            _pending,
        })
    }
}

/// The temporary file as [`AtomicFile::fill`] writes it. On Linux, each mebibyte written is handed
/// to the disk at once (`sync_file_range`), so that the `fsync` before the rename waits only for
/// the last of it, rather than for the whole file, which is most of a small run's fixed cost.
pub struct Output<'a> {
    file: &'a File,
    /// Where the next write lands.
    at: u64,
    /// The end of the data written so far, and how far of it has been handed to the disk.
    end: u64,
    started: u64,
}

/// Bytes written between two starts of writeback.
#[cfg(target_os = "linux")]
const WRITEBACK_EVERY: u64 = 1 << 20;

impl<'a> Output<'a> {
    fn new(file: &'a File) -> Self {
        Output {
            file,
            at: 0,
            end: 0,
            started: 0,
        }
    }

    /// Starts writing to disk what was written since the last start, without waiting for it.
    #[cfg(target_os = "linux")]
    fn start_writeback(&mut self) {
        use std::os::fd::AsRawFd;
        if self.end - self.started >= WRITEBACK_EVERY {
            let (from, len) = (self.started, self.end - self.started);
            // SAFETY: sync_file_range only reads the file descriptor, which `file` keeps open.
            // Its result is a hint's: where it fails, the fsync does all the work, as before.
            unsafe {
                libc::sync_file_range(
                    self.file.as_raw_fd(),
                    from as libc::off64_t,
                    len as libc::off64_t,
                    libc::SYNC_FILE_RANGE_WRITE,
                )
            };
            self.started = self.end;
        }
    }

    #[cfg(not(target_os = "linux"))]
    fn start_writeback(&mut self) {}
}

impl Write for Output<'_> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.file.write(buf)?;
        self.at += n as u64;
        self.end = self.end.max(self.at);
        self.start_writeback();
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

/// The NumPy `.npz` writer goes back to fill in sizes.
impl Seek for Output<'_> {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.at = self.file.seek(pos)?;
        Ok(self.at)
    }
}

/// A complete temporary file, closed, waiting to be renamed over its target.
pub struct Filled {
    temp: TempPath,
    target: PathBuf,
    dest: PathBuf,
    _pending: Pending,
}

impl Filled {
    /// Renames the file over its target.
    pub fn commit(self) -> Result<()> {
        let Filled {
            temp, target, dest, ..
        } = self;
        temp.persist(&dest)
            .map_err(|e| Error::file(&target, format!("cannot write: {}", io_reason(&e.error))))
    }

    /// The path the file is renamed to: the target, or the file its symbolic links lead to.
    pub fn destination(&self) -> &Path {
        &self.dest
    }
}

fn io_reason(e: &io::Error) -> String {
    match e.kind() {
        io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The output gets the permissions of any new file (the umask's), not a temporary file's 0600.
    #[cfg(unix)]
    #[test]
    fn output_has_ordinary_file_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("mesh.ply");
        AtomicFile::create(&target)
            .unwrap()
            .write_with(|out| out.write_all(b"ply"))
            .unwrap();
        let plain = dir.path().join("plain");
        File::create(&plain).unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&target), mode(&plain));
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn success_leaves_only_the_target() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("a.ply");
        AtomicFile::create(&target)
            .unwrap()
            .write_with(|w| w.write_all(b"hello"))
            .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"hello");
        assert_eq!(entries(dir.path()), ["a.ply"]);
    }

    #[test]
    fn failure_leaves_nothing_and_keeps_an_old_target() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("a.ply");
        std::fs::write(&target, b"old").unwrap();
        let err = AtomicFile::create(&target)
            .unwrap()
            .write_with(|w| {
                w.write_all(b"partial")?;
                Err(io::Error::other("disk full"))
            })
            .unwrap_err();
        assert!(err.to_string().contains("disk full"), "{err}");
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(entries(dir.path()), ["a.ply"]);
    }

    /// Several mebibytes in uneven pieces, past the points where writeback starts, then a seek
    /// back to patch the start (as the `.npz` writer does): the file holds exactly what was
    /// written, and the writeback started for every whole mebibyte but the last.
    #[test]
    fn writeback_and_seeks_keep_the_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("big.bin");
        let want: Vec<u8> = (0..(3 << 20) + 12_345u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
            .collect();
        let mut started = 0;
        AtomicFile::create(&target)
            .unwrap()
            .write_with(|w| {
                w.write_all(&[0; 8])?;
                for piece in want[8..].chunks(70_001) {
                    w.write_all(piece)?;
                }
                w.seek(SeekFrom::Start(0))?;
                w.write_all(&want[..8])?;
                w.flush()?;
                started = w.get_ref().started;
                Ok(())
            })
            .unwrap();
        assert!(std::fs::read(&target).unwrap() == want);
        #[cfg(target_os = "linux")]
        assert!(
            started >= 2 << 20 && started <= want.len() as u64,
            "{started}"
        );
    }

    /// A link is written through: the file it leads to (through a chain of relative and
    /// absolute links, in another folder) gets the content, the links stay links, and neither
    /// folder keeps a temporary file. A dangling link creates the file it names.
    #[cfg(unix)]
    #[test]
    fn links_are_written_through() {
        use std::os::unix::fs::symlink;
        let here = tempfile::tempdir().unwrap();
        let there = tempfile::tempdir().unwrap();
        let real = there.path().join("real.ply");
        std::fs::write(&real, b"old").unwrap();
        symlink(&real, here.path().join("hop")).unwrap();
        let link = here.path().join("mesh.ply");
        symlink("hop", &link).unwrap();
        assert_eq!(destination(&link).unwrap(), real);
        AtomicFile::create(&link)
            .unwrap()
            .write_with(|w| w.write_all(b"new"))
            .unwrap();
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        assert!(link.symlink_metadata().unwrap().file_type().is_symlink());
        assert_eq!(entries(here.path()), ["hop", "mesh.ply"]);
        assert_eq!(entries(there.path()), ["real.ply"]);

        let dangling = here.path().join("new.ply");
        symlink(there.path().join("made.ply"), &dangling).unwrap();
        AtomicFile::create(&dangling)
            .unwrap()
            .write_with(|w| w.write_all(b"made"))
            .unwrap();
        assert_eq!(
            std::fs::read(there.path().join("made.ply")).unwrap(),
            b"made"
        );
        assert!(
            dangling
                .symlink_metadata()
                .unwrap()
                .file_type()
                .is_symlink()
        );

        let looped = here.path().join("loop.ply");
        symlink("loop.ply", &looped).unwrap();
        let Err(err) = AtomicFile::create(&looped) else {
            panic!()
        };
        assert!(err.to_string().contains("symbolic links"), "{err}");
    }

    /// A FIFO, or a link to a device, is refused by name before anything is created; the FIFO
    /// and the link stay what they were.
    #[cfg(unix)]
    #[test]
    fn special_files_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.ply");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo reads a NUL-terminated path that lives for the call.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let Err(err) = AtomicFile::create(&fifo) else {
            panic!()
        };
        let err = err.to_string();
        assert!(
            err.contains("pipe.ply") && err.contains("is a FIFO"),
            "{err}"
        );
        let null = dir.path().join("null.ply");
        std::os::unix::fs::symlink("/dev/null", &null).unwrap();
        let Err(err) = AtomicFile::create(&null) else {
            panic!()
        };
        let err = err.to_string();
        assert!(err.contains("is a device (a link to /dev/null)"), "{err}");
        assert_eq!(entries(dir.path()), ["null.ply", "pipe.ply"]);
        use std::os::unix::fs::FileTypeExt;
        assert!(fifo.symlink_metadata().unwrap().file_type().is_fifo());
        assert!(null.symlink_metadata().unwrap().file_type().is_symlink());
    }

    #[test]
    fn dropped_before_writing_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        drop(AtomicFile::create(&dir.path().join("a.ply")).unwrap());
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn missing_directory_is_reported_up_front() {
        let dir = tempfile::tempdir().unwrap();
        let Err(err) = AtomicFile::create(&dir.path().join("no/such/dir/a.ply")) else {
            panic!()
        };
        assert!(err.to_string().contains("does not exist"), "{err}");
    }
}
