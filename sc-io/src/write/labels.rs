//! Meshes of a label volume, one per label: a file each in a directory, or one atlas `.glb`
//! ([`write_atlas`](super::write_atlas)).

use std::path::{Path, PathBuf};

use super::{MeshFormat, MeshSlices, WriteOptions};
use crate::atomic::{AtomicFile, Filled};
use crate::error::{Error, Result};
use crate::labels::{Label, file_stem};

/// One label's mesh, borrowed, with what the table says of the label.
#[derive(Clone, Copy, Debug)]
pub struct LabelMesh<'a> {
    /// The label's value in the volume.
    pub id: u64,
    /// Its name and colour, if a table has it.
    pub label: Option<&'a Label>,
    /// Its triangles.
    pub mesh: MeshSlices<'a>,
}

/// A file per label, written and waiting to be renamed into their directory together.
///
/// Each file is named [`file_stem`]`(id, name)` with the format's extension:
/// `17-Left-Hippocampus.ply`, `label-17.ply` for a label without a name. Every file is written
/// to a temporary file in the directory first ([`AtomicFile::fill`]); only when all are complete
/// does [`commit`](Self::commit) rename them, so an error while writing (a full disk) or an
/// interruption leaves none of the set's files (a directory made for the set is removed again
/// after an error; the signal handler's [`remove_pending`](crate::atomic::remove_pending) removes
/// the temporary files, not the directory). Files of the directory that the set does not name
/// (those of an earlier run with other labels) are left alone. The ids must differ.
///
/// Staging in a temporary directory renamed over the target would make the set appear in one
/// step, but cannot replace a directory that already holds files, which is the usual case on a
/// second run; renaming file by file in the same directory fails only if the directory is
/// changed meanwhile, and then [`commit`](Self::commit) removes the files it had put in place.
pub struct LabelFiles {
    files: Vec<(PathBuf, Filled)>,
    /// The directory, if this run made it (removed again if nothing lands in it).
    made: Option<PathBuf>,
}

impl LabelFiles {
    /// Writes a file per label in `format` into `dir`, creating `dir` (not its parents) if it
    /// does not exist. Nothing is renamed into place yet: see [`commit`](Self::commit).
    pub fn fill(
        dir: &Path,
        meshes: &[LabelMesh<'_>],
        format: MeshFormat,
        options: &WriteOptions,
    ) -> Result<LabelFiles> {
        let made = make_dir(dir)?;
        let mut set = LabelFiles {
            files: Vec::with_capacity(meshes.len()),
            made,
        };
        let ext = match format {
            MeshFormat::Ply => "ply",
            MeshFormat::Obj => "obj",
            MeshFormat::Stl => "stl",
            MeshFormat::Glb => "glb",
        };
        for m in meshes {
            let name = m.label.map_or("", |l| l.name.as_str());
            let path = dir.join(format!("{}.{ext}", file_stem(m.id, name)));
            let filled =
                AtomicFile::create(&path)?.fill(|out| format.write(m.mesh, options, out))?;
            set.files.push((path, filled));
        }
        Ok(set)
    }

    /// The files, as they will be named.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.files.iter().map(|(path, _)| path.as_path())
    }

    /// Renames every file into place. If one cannot be, those already renamed are removed (an
    /// older file of the same name is then gone too), and the error names the file.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        let mut done: Vec<PathBuf> = Vec::with_capacity(self.files.len());
        let mut paths = Vec::with_capacity(self.files.len());
        for (path, filled) in std::mem::take(&mut self.files) {
            let dest = filled.destination().to_path_buf();
            if let Err(e) = filled.commit() {
                for placed in &done {
                    let _ = std::fs::remove_file(placed);
                }
                return Err(e);
            }
            done.push(dest);
            paths.push(path);
        }
        // Kept: the directory now holds the set.
        if !paths.is_empty() {
            self.made = None;
        }
        Ok(paths)
    }
}

impl Drop for LabelFiles {
    /// A directory made for a set that never landed is removed (if still empty).
    fn drop(&mut self) {
        self.files.clear();
        if let Some(dir) = &self.made {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// Makes `dir` if it does not exist, returning it if made; refuses a path that is not a
/// directory, and a missing parent.
fn make_dir(dir: &Path) -> Result<Option<PathBuf>> {
    match std::fs::metadata(dir) {
        Ok(meta) if meta.is_dir() => Ok(None),
        Ok(_) => Err(Error::file(
            dir,
            "is not a directory: a file per label needs a directory",
        )),
        Err(_) => std::fs::create_dir(dir)
            .map(|()| Some(dir.to_path_buf()))
            .map_err(|e| Error::file(dir, format!("cannot create the directory: {}", reason(e)))),
    }
}

fn reason(e: std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "its parent does not exist".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => e.to_string(),
    }
}
