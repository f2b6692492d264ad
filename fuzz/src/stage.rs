//! What each fuzz target does with its input bytes, shared by the AFL targets (`fuzz/src/bin`)
//! and the corpus replay test (`sc-io/tests/fuzz_corpus.rs`, which includes this file), so that a
//! corpus file means the same thing in both.
//!
//! Readers take paths, so the bytes are written as a file with the target's extension in a
//! scratch folder, then read with the options the command line would give. Only std, sc-io and
//! flate2 are used here: the test suite builds this file without AFL.

use std::io::Write;
use std::path::{Path, PathBuf};

use sc_io::progress::Silent;
use sc_io::read::{ReadOptions, read};

/// One fuzz target: a reader, and how its input bytes become files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// `v.nii`, the bytes as they are.
    Nifti,
    /// `v.nii.gz`: an odd first byte writes the rest as it is (fuzzing the gzip layer), an even
    /// one gzips the rest (fuzzing the header and sizes behind a valid stream).
    NiftiGz,
    /// `v.nrrd`, header and attached data.
    Nrrd,
    /// `v.mha`, header and attached data.
    MetaImage,
    /// `v.npy`.
    Npy,
    /// `v.npz`, the zip archive as it is.
    Npz,
    /// `dicom/s.dcm`, read as a one-slice series.
    Dicom,
    /// `v.json` and `v.raw`: the bytes before the first NUL are the sidecar, the rest the samples.
    Sidecar,
    /// `m.ply`, through the mesh reader of `skelclimb render`.
    Ply,
    /// `m.obj`.
    Obj,
    /// `m.stl`.
    Stl,
    /// `v.zarr`, a Zarr store: the bytes, split at NUL bytes, are the files of
    /// [`ZARR_FILES`] in turn (an empty part writes no file), so that one input holds v2 or v3
    /// metadata, OME-Zarr attributes, a level's array and chunks. Read by the build with
    /// sc-io's `zarr` feature (`read_zarr`).
    Zarr,
}

/// The files a Zarr input is cut into, in order: a store's metadata at its root (v3, v2 array, v2
/// group and attributes), an OME-Zarr level `0` (v3, v2), and the first chunk of each array under
/// v2's and v3's default names.
pub const ZARR_FILES: [&str; 10] = [
    "zarr.json",
    ".zarray",
    ".zgroup",
    ".zattrs",
    "0/zarr.json",
    "0/.zarray",
    "0.0.0",
    "c/0/0/0",
    "0/0.0.0",
    "0/c/0/0/0",
];

/// Samples a Zarr input may claim and still be read whole: reading costs time in proportion to
/// the samples (and chunks) its header claims, whatever the store holds, and a slow read of a
/// large claim is not a finding; the checks of the claim, on opening, are fuzzed at any size.
const ZARR_READ_SAMPLES: usize = 1 << 16;

impl Target {
    /// Every target, in the order `fuzz/run.sh` runs them.
    pub const ALL: [Target; 12] = [
        Target::Nifti,
        Target::NiftiGz,
        Target::Nrrd,
        Target::MetaImage,
        Target::Npy,
        Target::Npz,
        Target::Dicom,
        Target::Sidecar,
        Target::Ply,
        Target::Obj,
        Target::Stl,
        Target::Zarr,
    ];

    /// The name of its binary and of its folders under `fuzz/corpus` and `fuzz/regressions`.
    pub fn name(self) -> &'static str {
        match self {
            Target::Nifti => "nifti",
            Target::NiftiGz => "nifti_gz",
            Target::Nrrd => "nrrd",
            Target::MetaImage => "metaimage",
            Target::Npy => "npy",
            Target::Npz => "npz",
            Target::Dicom => "dicom",
            Target::Sidecar => "sidecar",
            Target::Ply => "ply",
            Target::Obj => "obj",
            Target::Stl => "stl",
            Target::Zarr => "zarr",
        }
    }

    /// Writes `data` into `dir` as this target's input and returns the path to read.
    pub fn stage(self, dir: &Path, data: &[u8]) -> std::io::Result<PathBuf> {
        let file = |name: &str, bytes: &[u8]| {
            let path = dir.join(name);
            std::fs::write(&path, bytes).map(|()| path)
        };
        match self {
            Target::Nifti => file("v.nii", data),
            Target::NiftiGz => match data.split_first() {
                Some((mode, rest)) if mode % 2 == 0 => {
                    let mut gz =
                        flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
                    gz.write_all(rest)?;
                    file("v.nii.gz", &gz.finish()?)
                }
                Some((_, rest)) => file("v.nii.gz", rest),
                None => file("v.nii.gz", data),
            },
            Target::Nrrd => file("v.nrrd", data),
            Target::MetaImage => file("v.mha", data),
            Target::Npy => file("v.npy", data),
            Target::Npz => file("v.npz", data),
            Target::Dicom => {
                let series = dir.join("dicom");
                std::fs::create_dir_all(&series)?;
                std::fs::write(series.join("s.dcm"), data)?;
                Ok(series)
            }
            Target::Sidecar => {
                let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
                file("v.json", &data[..split])?;
                file("v.raw", data.get(split + 1..).unwrap_or_default())
            }
            Target::Ply => file("m.ply", data),
            Target::Obj => file("m.obj", data),
            Target::Stl => file("m.stl", data),
            Target::Zarr => {
                let store = dir.join("v.zarr");
                // AFL's persistent mode stages each input over the last: start afresh.
                if store.exists() {
                    std::fs::remove_dir_all(&store)?;
                }
                for (name, part) in ZARR_FILES.iter().zip(data.split(|&b| b == 0)) {
                    if !part.is_empty() {
                        let path = store.join(name);
                        std::fs::create_dir_all(path.parent().unwrap_or(&store))?;
                        std::fs::write(path, part)?;
                    }
                }
                std::fs::create_dir_all(&store)?;
                Ok(store)
            }
        }
    }

    /// Reads what [`Target::stage`] wrote: `Ok` for a volume or mesh that keeps its promises,
    /// the error's text for a refused file. A panic, an abort or a hang is the finding a fuzzer
    /// looks for, and so is an error that does not name the file (`Err` with a reason, from
    /// [`Target::run`]).
    fn read(self, path: &Path) -> Result<(), String> {
        match self {
            Target::Ply | Target::Obj | Target::Stl => {
                let mesh = sc_io::mesh_in::read(path).map_err(|e| e.to_string())?;
                let n = mesh.positions.len();
                assert!(
                    mesh.triangles.iter().flatten().all(|&i| (i as usize) < n),
                    "a triangle indexes past the {n} vertices"
                );
            }
            Target::Zarr => {
                let options = ReadOptions::default();
                let stream = sc_io::read::stream::open(path, &options)
                    .map_err(|e| e.to_string())?
                    .expect("a Zarr store streams");
                let samples = (stream.grid.dims.iter()).try_fold(1usize, |n, &d| n.checked_mul(d));
                if samples.is_some_and(|n| n <= ZARR_READ_SAMPLES) {
                    let grid = read(path, &options, &Silent).map_err(|e| e.to_string())?;
                    assert!(grid.dims.iter().product::<usize>() == grid.len());
                }
            }
            _ => {
                let grid =
                    read(path, &ReadOptions::default(), &Silent).map_err(|e| e.to_string())?;
                assert!(grid.dims.iter().product::<usize>() == grid.len());
            }
        }
        Ok(())
    }

    /// Stages `data` in `dir` and reads it. Returns whether the file was accepted, or why the
    /// outcome breaks the readers' promise (an error that does not name the file).
    pub fn run(self, dir: &Path, data: &[u8]) -> Result<bool, String> {
        let path = self
            .stage(dir, data)
            .map_err(|e| format!("staging failed: {e}"))?;
        match self.read(&path) {
            Ok(()) => Ok(true),
            Err(text) if text.contains(&*dir.to_string_lossy()) => Ok(false),
            Err(text) => Err(format!("the error does not name the file: {text}")),
        }
    }
}
