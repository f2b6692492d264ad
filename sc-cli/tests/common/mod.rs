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

/// The files at `path`: every file of a directory, by name, or a single file, unnamed.
pub fn written(path: &Path) -> Vec<(String, Vec<u8>)> {
    if path.is_dir() {
        entries(path)
            .into_iter()
            .map(|name| {
                let bytes = std::fs::read(path.join(&name)).unwrap();
                (name, bytes)
            })
            .collect()
    } else {
        vec![(String::new(), std::fs::read(path).unwrap())]
    }
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

/// Samples along x, y, z of [`aal_labels`].
pub const LABEL_DIMS: [usize; 3] = [24, 24, 48];

/// The AAL crop three times along z, the middle copy mirrored: 24 × 24 × 48 u8, x fastest,
/// so that regions run across the copies' seams and a stream or a set of shards has several
/// blocks.
pub fn aal_labels() -> Vec<u8> {
    let crop = std::fs::read(fixture("labels/aal-crop-24x24x16.u8.raw")).unwrap();
    let slices: Vec<&[u8]> = crop.chunks_exact(24 * 24).collect();
    let mut all = Vec::with_capacity(crop.len() * 3);
    for slice in slices.iter().chain(slices.iter().rev()).chain(&slices) {
        all.extend_from_slice(slice);
    }
    all
}

/// A NIfTI-1 file of u8 `samples` of [`LABEL_DIMS`], unit voxels, scaled by `slope` (0: none),
/// placed by the affine rows `sform` if given (else no rotation).
pub fn label_nifti(samples: &[u8], slope: f32, sform: Option<[[f32; 4]; 3]>) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let [nx, ny, nz] = LABEL_DIMS;
    let dim = [3, nx, ny, nz, 1, 1, 1, 1].map(|d| d as i16);
    for (i, d) in dim.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&2i16.to_le_bytes()); // DT_UINT8
    h[72..74].copy_from_slice(&8i16.to_le_bytes());
    for i in 0..8 {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[112..116].copy_from_slice(&slope.to_le_bytes());
    if let Some(rows) = sform {
        h[254..256].copy_from_slice(&1i16.to_le_bytes()); // sform_code: scanner
        for (i, x) in rows.as_flattened().iter().enumerate() {
            h[280 + 4 * i..284 + 4 * i].copy_from_slice(&x.to_le_bytes());
        }
    }
    h[344..348].copy_from_slice(b"n+1\0");
    h.extend_from_slice(samples);
    h
}
