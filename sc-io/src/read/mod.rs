//! Volume readers. Each format parses its own header (with a crate where a good one exists) and
//! hands the sample block to [`read_block`], so that byte order, compression, truncation and
//! progress are handled once.

pub mod dicom;
mod dicom_lengths;
pub mod header;
pub mod metaimage;
pub mod nifti;
pub mod npy;
pub mod nrrd;
pub mod payload;
pub mod raw;
pub mod sidecar;
pub mod stream;
#[cfg(feature = "zarr")]
pub mod zarr;
#[cfg(not(feature = "zarr"))]
#[path = "zarr_off.rs"]
pub mod zarr;

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::volume::{Buffer, Dtype, Endian, Grid, Sample, Samples};
use payload::{Encoding, Layout};

/// How to read a headerless file, from the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawLayout {
    /// `[nx, ny, nz]`, x fastest.
    pub dims: [usize; 3],
    /// Sample type.
    pub dtype: Dtype,
    /// Byte order.
    pub endian: Endian,
    /// Bytes to skip before the samples.
    pub header_bytes: u64,
}

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
    /// Raw samples described by a JSON sidecar (see [`sidecar`]).
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

/// Reads the volume at `path` in whatever format it is.
pub fn read(path: &Path, options: &ReadOptions, progress: &dyn Progress) -> Result<Grid> {
    let format = Format::detect(path, options)?;
    if !path.exists() {
        return Err(Error::file(path, "no such file or directory"));
    }
    let mut grid = match format {
        Format::Raw(layout) => raw::read(path, &layout, progress),
        Format::Nifti => nifti::read(path, progress),
        Format::Nrrd => nrrd::read(path, progress),
        Format::MetaImage => metaimage::read(path, progress),
        Format::Npy | Format::Npz => npy::read(path, options.array.as_deref(), progress),
        Format::Dicom => dicom::read(path, &options.dicom, progress),
        Format::Sidecar => read_with_sidecar(path, progress),
        Format::Zarr => match stream::open(path, options)? {
            Some(s) => s.read_all(progress),
            None => unreachable!("a Zarr store always streams"),
        },
    }?;
    grid.format = format.name();
    check_placement(path, &grid)?;
    Ok(grid)
}

/// Refuses what would mesh into garbage: an empty volume, and spacing or origin that are not
/// finite, not positive, or beyond what `f32` vertices can hold (NaN or infinite vertices make
/// invalid glTF; zero spacing collapses the mesh to a plane).
pub(crate) fn check_placement(path: &Path, grid: &Grid) -> Result<()> {
    let [nx, ny, nz] = grid.dims;
    if grid.dims.contains(&0) {
        return Err(Error::file(
            path,
            format!("the volume has no samples: its dims are {nx} × {ny} × {nz}"),
        ));
    }
    let usable = |v: f64| v.is_finite() && v.abs() < 1e30;
    if !grid.spacing.iter().all(|&s| usable(s) && s > 0.0) {
        return Err(Error::file(
            path,
            format!(
                "the file's sample spacing {:?} is unusable: every spacing must be a positive \
                 finite number (NIfTI pixdim or sform, NRRD spacings or space directions, \
                 MetaImage ElementSpacing, DICOM PixelSpacing or slice positions)",
                grid.spacing
            ),
        ));
    }
    if !grid.origin.iter().all(|&o| usable(o)) {
        return Err(Error::file(
            path,
            format!(
                "the file's origin {:?} is unusable: it must be finite (NIfTI sform or qform \
                 offset, NRRD space origin, MetaImage Offset, DICOM ImagePositionPatient)",
                grid.origin
            ),
        ));
    }
    Ok(())
}

fn read_with_sidecar(path: &Path, progress: &dyn Progress) -> Result<Grid> {
    let json = sidecar::find(path).ok_or_else(|| Error::file(path, "no JSON sidecar beside it"))?;
    let side = sidecar::Sidecar::read(&json)?;
    let mut grid = raw::read(&side.data, &side.layout, progress)?;
    grid.spacing = side.spacing.unwrap_or(grid.spacing);
    grid.origin = side.origin.unwrap_or(grid.origin);
    if !side.iso_suggestions.is_empty() {
        let named: Vec<String> = side
            .iso_suggestions
            .iter()
            .map(|(name, iso)| format!("{name} {iso}"))
            .collect();
        grid.notes.push(format!(
            "{} suggests iso values: {}",
            json.display(),
            named.join(", ")
        ));
    }
    Ok(grid)
}

/// Where a sample block starts in its file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Start {
    /// At this byte offset.
    At(u64),
    /// At the end minus the block's size: NRRD `byte skip: -1`, MetaImage `HeaderSize = -1`.
    End,
}

/// A sample block inside a file.
pub struct Block<'a> {
    /// The file holding the samples.
    pub path: &'a Path,
    /// Where the (possibly compressed) data starts.
    pub start: Start,
    /// Text lines to skip at `start` (NRRD `line skip`).
    pub skip_lines: usize,
    /// How the data is stored.
    pub encoding: Encoding,
    /// Decoded bytes to skip before the samples (NRRD `byte skip` of compressed data, and the
    /// NIfTI header inside a `.nii.gz`).
    pub skip_decoded: u64,
    /// The samples.
    pub layout: Layout,
}

/// Decoded bytes read after the samples of a compressed block (or a zip member) to reach its
/// checksum.
pub(crate) const MAX_TRAILING: u64 = 1 << 20;

/// Reads a sample block, with errors that name the data file and say what is missing.
pub fn read_block(block: &Block<'_>, progress: &dyn Progress) -> Result<Samples> {
    if let Some(samples) = map_block(block)? {
        let bytes = (samples.len() * block.layout.dtype.size()) as u64;
        progress.phase("reading", bytes);
        progress.inc(bytes);
        return Ok(samples);
    }
    let mut decoded = open_block(block)?;
    let verified = block.encoding == Encoding::Raw && block.skip_lines == 0;
    let result =
        payload::read_samples(&mut decoded, block.layout, verified, progress).and_then(|samples| {
            if block.encoding != Encoding::Raw {
                // Reading on to the end of the stream is what makes the decoder check the
                // gzip CRC and length (zlib: Adler-32): a flipped byte is an error, not a
                // silently altered sample. What follows the samples is bounded, not trusted.
                io::copy(&mut (&mut decoded).take(MAX_TRAILING), &mut io::sink())?;
            }
            Ok(samples)
        });
    result.map_err(|e| block_error(block, e))
}

/// The samples of an uncompressed block in this machine's byte order, mapped in place (see
/// [`Buffer`]); `None` for any other block, and for one the file is too short for, which the
/// reading path refuses with its message.
fn map_block(block: &Block<'_>) -> Result<Option<Samples>> {
    let layout = block.layout;
    let native = layout.endian == Endian::native() || layout.dtype.size() == 1;
    if block.encoding != Encoding::Raw
        || block.skip_lines != 0
        || block.skip_decoded != 0
        || !native
        || layout.count == 0
    {
        return Ok(None);
    }
    let Some(need) = layout.bytes() else {
        return Ok(None);
    };
    let path = block.path;
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let start = match block.start {
        Start::At(offset) => offset,
        Start::End => len.saturating_sub(need as u64),
    };
    if len < start.saturating_add(need as u64) {
        return Ok(None);
    }
    Ok(
        crate::with_dtype!(layout.dtype, T => Buffer::<T>::map(&file, start, layout.count).map(T::wrap)),
    )
}

/// The decoded bytes of a block, positioned at its first sample; a raw file too short for the
/// block is refused before anything is read.
pub(crate) fn open_block(block: &Block<'_>) -> Result<Box<dyn Read>> {
    let path = block.path;
    let need = block
        .layout
        .bytes()
        .ok_or_else(|| Error::file(path, "the volume is too large"))? as u64;
    let mut file = File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let start = match block.start {
        Start::At(offset) => offset,
        Start::End => len.saturating_sub(need),
    };
    // Saturating: a header's offset near 2^64 must not wrap the end back into the file.
    let end = start.saturating_add(need);
    if block.encoding == Encoding::Raw && block.skip_lines == 0 && len < end {
        return Err(Error::file(
            path,
            format!(
                "the file has {len} bytes, but {} samples of {} starting at byte {start} need {} \
                 (truncated file, or dimensions larger than the data?)",
                block.layout.count,
                block.layout.dtype.name(),
                end
            ),
        ));
    }
    file.seek(SeekFrom::Start(start))
        .map_err(|e| Error::io(path, e))?;
    let mut reader = BufReader::with_capacity(1 << 20, file);
    for skipped in 0..block.skip_lines {
        if reader.skip_until(b'\n').map_err(|e| Error::io(path, e))? == 0 {
            return Err(Error::file(
                path,
                format!(
                    "the file ends after {skipped} of the {} lines the header says to skip",
                    block.skip_lines
                ),
            ));
        }
    }
    let mut decoded = payload::decode(reader, block.encoding);
    let skipped = io::copy(
        &mut (&mut decoded).take(block.skip_decoded),
        &mut io::sink(),
    )
    .map_err(|e| block_error(block, e))?;
    if skipped < block.skip_decoded {
        return Err(block_error(
            block,
            io::Error::new(
                io::ErrorKind::UnexpectedEof,
                "the data ends before the samples start",
            ),
        ));
    }
    Ok(decoded)
}

/// A block's read error in words: which file, and whether it is short or corrupt.
pub(crate) fn block_error(block: &Block<'_>, e: io::Error) -> Error {
    let path = block.path;
    match (block.encoding, e.kind()) {
        (Encoding::Raw, _) | (_, io::ErrorKind::UnexpectedEof) => Error::io(path, e),
        (Encoding::Gzip, _) => Error::file(path, format!("corrupt gzip data: {e}")),
        (Encoding::Zlib, _) => Error::file(path, format!("corrupt zlib data: {e}")),
    }
}
