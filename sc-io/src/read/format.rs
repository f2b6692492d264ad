//! What a volume file is: its format, told from its name, and the options that only some formats
//! accept.

use std::path::Path;

use super::raw::RawLayout;
use super::{dicom, sidecar};
use crate::error::{Error, Result};

/// Reader options from the command line that only some formats accept.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Layout of a raw file; required for raw input, refused for any other.
    pub raw: Option<RawLayout>,
    /// Array name inside an `.npz` archive.
    pub array: Option<String>,
    /// Series choice and gap handling for a DICOM directory.
    pub dicom: dicom::DicomOptions,
    /// The level of an OME-Zarr multiscale image (0, the finest, by default).
    pub zarr_level: usize,
}

/// The input formats, told apart by extension (a directory is a DICOM series).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Headerless samples described by `--dims`/`--dtype`.
    Raw(RawLayout),
    /// NIfTI-1, `.nii` or `.nii.gz`.
    Nifti,
    /// NRRD, `.nrrd` or `.nhdr`.
    Nrrd,
    /// MetaImage, `.mha` or `.mhd`.
    MetaImage,
    /// NumPy `.npy`.
    Npy,
    /// NumPy `.npz`.
    Npz,
    /// A directory of DICOM slices.
    Dicom,
    /// Raw samples described by a JSON sidecar (`scan.json` next to `scan.raw`).
    Sidecar,
    /// A Zarr v2 or v3 array, or an OME-Zarr image (a directory).
    Zarr,
}

impl Format {
    /// The format of `path`, or a usage error if options and format do not fit together.
    pub fn detect(path: &Path, options: &ReadOptions) -> Result<Format> {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        let ends = |suffixes: &[&str]| suffixes.iter().any(|s| name.ends_with(s));
        let format = if is_zarr_store(path) {
            Format::Zarr
        } else if path.is_dir() {
            Format::Dicom
        } else if ends(&[".nii", ".nii.gz"]) {
            Format::Nifti
        } else if ends(&[".nrrd", ".nhdr"]) {
            Format::Nrrd
        } else if ends(&[".mha", ".mhd"]) {
            Format::MetaImage
        } else if ends(&[".npy"]) {
            Format::Npy
        } else if ends(&[".npz"]) {
            Format::Npz
        } else if let Some(layout) = options.raw {
            Format::Raw(layout)
        } else if sidecar::find(path).is_some() {
            Format::Sidecar
        } else if ends(&[".dcm"]) {
            return Err(Error::Usage(format!(
                "{}: give the directory that holds the DICOM series, not one slice",
                path.display()
            )));
        } else {
            return Err(Error::Usage(format!(
                "{}: unknown volume format; expected .nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd, \
                 .npy, .npz, a DICOM directory, raw samples with --dims and --dtype, or raw samples \
                 with a .json sidecar",
                path.display()
            )));
        };
        if options.raw.is_some() && !matches!(format, Format::Raw(_)) {
            return Err(Error::Usage(format!(
                "--dims/--dtype/--endian/--header-bytes describe raw files; {} has its own header",
                path.display()
            )));
        }
        if options.dicom != dicom::DicomOptions::default() && format != Format::Dicom {
            return Err(Error::Usage(
                "--series and --resample-gaps apply to DICOM directories".into(),
            ));
        }
        if options.zarr_level != 0 && format != Format::Zarr {
            return Err(Error::Usage(
                "--zarr-level picks a level of an OME-Zarr image".into(),
            ));
        }
        if options.array.is_some() && format != Format::Npz {
            return Err(Error::Usage(
                "--array selects an array in an .npz file".into(),
            ));
        }
        Ok(format)
    }

    /// The name shown in summaries.
    pub fn name(self) -> &'static str {
        match self {
            Format::Raw(_) => "raw",
            Format::Nifti => "NIfTI-1",
            Format::Nrrd => "NRRD",
            Format::MetaImage => "MetaImage",
            Format::Npy => "NumPy .npy",
            Format::Npz => "NumPy .npz",
            Format::Dicom => "DICOM series",
            Format::Zarr => "Zarr",
            Format::Sidecar => "raw + JSON sidecar",
        }
    }
}

/// Whether `path` is a Zarr store: a folder with Zarr metadata, or named `*.zarr`. Recognised
/// with the `zarr` feature or without it, which then names the format in its refusal.
fn is_zarr_store(path: &Path) -> bool {
    path.is_dir()
        && (["zarr.json", ".zarray", ".zgroup"]
            .iter()
            .any(|m| path.join(m).is_file())
            || path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("zarr")))
}
