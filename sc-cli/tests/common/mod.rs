//! Helpers the CLI test files share: fixtures, directory listings and NIfTI bytes to mutate.
// Each test file uses a different subset of these helpers.
#![allow(dead_code)]

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

/// A file or folder in `tests/data`.
pub fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data")
        .join(name)
}

/// Names in `dir`, sorted, to check that failures leave nothing (not even a temporary file).
pub fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The itk-t1 fixture as an uncompressed `.nii`, for tests that patch its header.
pub fn nifti() -> Vec<u8> {
    let gz = std::fs::read(fixture("itk-t1-mri.nii.gz")).unwrap();
    let mut nii = Vec::new();
    flate2::read::GzDecoder::new(&gz[..])
        .read_to_end(&mut nii)
        .unwrap();
    nii
}

/// `bytes` gzip-compressed.
pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// `skelclimb` with `args` in `dir` under a 6 GB address-space limit: an allocation a header
/// implies fails there rather than swapping, and an abort would show as exit 134.
pub fn limited(dir: &Path, args: &str) -> assert_cmd::Command {
    let mut cmd = assert_cmd::Command::new("bash");
    cmd.current_dir(dir)
        .arg("-c")
        .arg(format!(
            "ulimit -v 6000000; exec {} {args}",
            assert_cmd::cargo::cargo_bin("skelclimb").display()
        ))
        .timeout(std::time::Duration::from_secs(20));
    cmd
}
