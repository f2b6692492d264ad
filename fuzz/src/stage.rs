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
    /// `manifest.json` and its shards `s0.npz`, `s1.npz`, …, of a scan or of a label volume,
    /// joined as `skelclimb merge` joins them ([`sc_io::shard::merge`] or
    /// [`sc_io::labels::merge_shards`], by the manifest's kind): see [`shards`] for how the bytes
    /// are cut.
    Shards,
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
    pub const ALL: [Target; 13] = [
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
        Target::Shards,
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
            Target::Shards => "shards",
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
            Target::Shards => shards(dir, data),
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
            Target::Shards => {
                use sc_io::shard::{self, ShardSettings};
                let text = |e: sc_io::Error| e.to_string();
                let meshes =
                    if shard::kind(path).map_err(text)? == sc_io::labels::LabelSettings::KIND {
                        let (_, labels) = sc_io::labels::merge_shards(path).map_err(text)?;
                        labels.meshes.into_iter().map(|(_, mesh)| mesh).collect()
                    } else {
                        vec![shard::merge(path).map_err(text)?.1]
                    };
                for mesh in meshes {
                    let n = mesh.positions.len();
                    assert!(
                        mesh.triangles.iter().flatten().all(|&i| (i as usize) < n),
                        "a triangle indexes past the {n} vertices"
                    );
                    assert!(
                        mesh.positions
                            .iter()
                            .chain(&mesh.normals)
                            .flatten()
                            .all(|c| c.is_finite()),
                        "a vertex or normal is not finite"
                    );
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

/// Stages a shard set: the bytes before the first NUL are `manifest.json`; the rest are shards,
/// each a 32-bit little-endian length and that many bytes (fewer at the end), written as `s0.npz`,
/// `s1.npz`, …. A shard whose first byte is odd is the rest as it is (fuzzing the zip layer);
/// an even one is its six `.npy` members, each length-prefixed the same way, zipped here with
/// their CRC-32s right, so that mutations reach the arrays behind the zip's checks: a scan's
/// members for a first byte of 0 modulo 4, a label shard's (`pairs` for `normals`) for 2.
fn shards(dir: &Path, data: &[u8]) -> std::io::Result<PathBuf> {
    const MEMBERS: [[&str; 6]; 2] = [
        [
            "header",
            "keys",
            "positions",
            "normals",
            "triangles",
            "cubes",
        ],
        ["header", "keys", "positions", "pairs", "triangles", "cubes"],
    ];
    fn pieces(mut data: &[u8]) -> impl Iterator<Item = &[u8]> {
        std::iter::from_fn(move || {
            let (len, rest) = data.split_first_chunk::<4>()?;
            let len = (u32::from_le_bytes(*len) as usize).min(rest.len());
            let piece;
            (piece, data) = rest.split_at(len);
            Some(piece)
        })
    }
    // A folder of its own, emptied for each input: a shard left by an earlier input would
    // otherwise stand in for one this input lacks.
    let dir = dir.join("shards");
    match std::fs::remove_dir_all(&dir) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
        _ => std::fs::create_dir(&dir)?,
    }
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let manifest = dir.join("manifest.json");
    std::fs::write(&manifest, &data[..split])?;
    for (i, shard) in pieces(data.get(split + 1..).unwrap_or_default()).enumerate() {
        let bytes = match shard.split_first() {
            Some((mode, rest)) if mode % 2 == 0 => {
                let members = MEMBERS[usize::from(mode % 4 / 2)];
                stored_zip(members.iter().map(|m| format!("{m}.npy")).zip(pieces(rest)))
            }
            Some((_, rest)) => rest.to_vec(),
            None => Vec::new(),
        };
        std::fs::write(dir.join(format!("s{i}.npz")), bytes)?;
    }
    Ok(manifest)
}

/// A zip archive of `members`, stored (uncompressed), as `numpy.savez` writes one.
fn stored_zip(members: impl Iterator<Item = (String, impl AsRef<[u8]>)>) -> Vec<u8> {
    let (mut out, mut directory, mut count) = (Vec::new(), Vec::new(), 0u16);
    for (name, data) in members {
        let data = data.as_ref();
        let mut crc = flate2::Crc::new();
        crc.update(data);
        // Version 2.0, no flags, stored, no time: the fields a local and a central header share.
        let mut common = vec![20, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        common.extend(crc.sum().to_le_bytes());
        common.extend((data.len() as u32).to_le_bytes());
        common.extend((data.len() as u32).to_le_bytes());
        common.extend((name.len() as u16).to_le_bytes());
        common.extend([0, 0]);
        directory.extend(b"PK\x01\x02\x14\x00");
        directory.extend(&common);
        directory.extend([0; 10]);
        directory.extend((out.len() as u32).to_le_bytes());
        directory.extend(name.as_bytes());
        out.extend(b"PK\x03\x04");
        out.extend(&common);
        out.extend(name.as_bytes());
        out.extend(data);
        count += 1;
    }
    let at = out.len() as u32;
    out.extend(&directory);
    out.extend(b"PK\x05\x06\x00\x00\x00\x00");
    out.extend(count.to_le_bytes());
    out.extend(count.to_le_bytes());
    out.extend((directory.len() as u32).to_le_bytes());
    out.extend(at.to_le_bytes());
    out.extend([0, 0]);
    out
}
