//! A DICOM series: one directory, one slice per file (dicom-rs reads and decodes them).
//!
//! Slices are ordered by ImagePositionPatient projected on the slice normal (row × column
//! direction), not by file name or InstanceNumber, which scanners do not keep in spatial order.
//! The directory must hold one series of equally sized, equally oriented slices; anything else is
//! refused with the names of two files that disagree, since guessing which slices belong together
//! silently builds a wrong volume.

use std::io::Read;
use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;
use dicom_object::{DefaultDicomObject, OpenFileOptions};
use dicom_pixeldata::{ConvertOptions, ModalityLutOption, PixelDecoder};

use crate::error::{Error, Result, with_causes};
use crate::progress::Progress;
use crate::space::{Frame, Space};
use crate::volume::{Dtype, Grid, Sample, Samples};
use crate::{with_dtype, with_samples};

/// What pass one learns of a slice from its header, before any pixel is decoded.
struct Slice {
    path: PathBuf,
    series: String,
    description: String,
    size: [u32; 2],
    dtype: Dtype,
    orientation: [f64; 6],
    position: [f64; 3],
    pixel_spacing: [f64; 2],
    rescale: [f64; 2],
    /// Distance along the slice normal, filled in once the normal is known.
    depth: f64,
}

/// How to read a DICOM directory.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct DicomOptions {
    /// The series to read when the directory holds several: its SeriesInstanceUID, or its
    /// number (from 1) in [`list_series`]'s order.
    pub series: Option<String>,
    /// Resample a series with missing slices onto even spacing instead of refusing it.
    pub resample_gaps: bool,
}

/// One series found in a directory, for listings.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesInfo {
    /// SeriesInstanceUID.
    pub uid: String,
    /// SeriesDescription, possibly empty.
    pub description: String,
    /// Slices found.
    pub slices: usize,
    /// Columns × rows of its first slice.
    pub size: [u32; 2],
}

/// The series under `dir` (searched recursively), in the order of their first file's path.
pub fn list_series(dir: &Path) -> Result<Vec<SeriesInfo>> {
    Ok(group(headers(dir)?)
        .into_iter()
        .map(|slices| SeriesInfo {
            uid: slices[0].series.clone(),
            description: slices[0].description.clone(),
            slices: slices.len(),
            size: slices[0].size,
        })
        .collect())
}

fn headers(dir: &Path) -> Result<Vec<Slice>> {
    let mut slices = Vec::new();
    for path in dicom_files(dir)? {
        super::dicom_lengths::check(&path)?;
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
    Ok(slices)
}

/// Slices grouped by series, groups in the order of their first slice.
fn group(slices: Vec<Slice>) -> Vec<Vec<Slice>> {
    let mut groups: Vec<Vec<Slice>> = Vec::new();
    for s in slices {
        match groups.iter_mut().find(|g| g[0].series == s.series) {
            Some(g) => g.push(s),
            None => groups.push(vec![s]),
        }
    }
    groups
}

/// Picks the series `options` asks for, or the only one.
fn choose(dir: &Path, mut groups: Vec<Vec<Slice>>, wanted: Option<&str>) -> Result<Vec<Slice>> {
    let listing = |groups: &[Vec<Slice>]| {
        groups
            .iter()
            .enumerate()
            .map(|(i, g)| {
                format!(
                    "\n  {}. {} ({} slices{}{})",
                    i + 1,
                    g[0].series,
                    g.len(),
                    if g[0].description.is_empty() {
                        ""
                    } else {
                        ", "
                    },
                    g[0].description
                )
            })
            .collect::<String>()
    };
    let index = match wanted {
        None if groups.len() <= 1 => 0,
        None => {
            return Err(Error::file(
                dir,
                format!(
                    "the directory holds {} series; choose one with --series UID or its number:{}",
                    groups.len(),
                    listing(&groups)
                ),
            ));
        }
        Some(w) => match groups.iter().position(|g| g[0].series == w) {
            Some(i) => i,
            None => match w.parse::<usize>() {
                Ok(n) if (1..=groups.len()).contains(&n) => n - 1,
                _ => {
                    return Err(Error::file(
                        dir,
                        format!("no series {w:?} here; the series are:{}", listing(&groups)),
                    ));
                }
            },
        },
    };
    if groups.is_empty() {
        return Err(Error::file(
            dir,
            "no DICOM files in this directory or below it",
        ));
    }
    Ok(groups.swap_remove(index))
}

/// Reads the series in `dir` (or below it).
pub(crate) fn read(dir: &Path, choice: &DicomOptions, progress: &dyn Progress) -> Result<Grid> {
    let mut slices = choose(dir, group(headers(dir)?), choice.series.as_deref())?;
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
    let samples = with_dtype!(dtype, T => decode_all::<T>(&slices, &options, progress).map(|v| Sample::wrap(v.into())))?;

    let mut grid = Grid::new(samples, dims, "DICOM series");
    if same_rescale {
        grid.rescale(first.rescale[0], first.rescale[1]);
    }
    let depths: Vec<f64> = slices.iter().map(|s| s.depth).collect();
    let spacing = even_spacing(dir, &slices, choice.resample_gaps)?;
    if let Some((dz, true)) = spacing {
        let resampled = resample(&grid, &depths, dz);
        grid.notes.push(format!(
            "slices resampled onto even spacing {dz:.4} ({} slices → {})",
            depths.len(),
            resampled.dims[2]
        ));
        grid.samples = resampled.samples;
        grid.dims = resampled.dims;
        grid.scale = resampled.scale;
    }
    let dz = spacing.map_or(1.0, |(dz, _)| dz);
    let gaps = depths.windows(2).map(|p| p[1] - p[0]);
    let (lo, hi) = gaps.fold((f64::INFINITY, 0.0f64), |(lo, hi), g| {
        (lo.min(g), hi.max(g))
    });
    if matches!(spacing, Some((_, false))) && hi - lo > 0.01 * dz {
        grid.notes.push(format!(
            "slice gaps vary from {lo:.4} to {hi:.4}; the mesh uses their mean {dz:.4}"
        ));
    }
    grid.spacing = [first.pixel_spacing[1], first.pixel_spacing[0], dz];
    grid.origin = first.position;
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

/// Regular files that carry the DICOM preamble, in path order, in `dir` and the folders below it
/// (exports often nest `PATIENT/STUDY/SERIES/`; symbolic links to folders are not followed, so
/// a loop cannot trap the search). A DICOMDIR index and other files (notes, thumbnails) are passed
/// over: every slice is found by its own header.
fn dicom_files(dir: &Path) -> Result<Vec<PathBuf>> {
    const MAX_DEPTH: usize = 8;
    let mut files = Vec::new();
    let mut pending = vec![(dir.to_path_buf(), 0)];
    while let Some((folder, depth)) = pending.pop() {
        let entries = std::fs::read_dir(&folder).map_err(|e| Error::io(&folder, e))?;
        for entry in entries {
            let entry = entry.map_err(|e| Error::io(&folder, e))?;
            let path = entry.path();
            let file_name = entry.file_name();
            let hidden = file_name.to_string_lossy().starts_with('.');
            let kind = entry.file_type().map_err(|e| Error::io(&path, e))?;
            if hidden {
                continue;
            }
            if kind.is_dir() && depth < MAX_DEPTH {
                pending.push((path, depth + 1));
            } else if path.is_file()
                && !file_name.eq_ignore_ascii_case("DICOMDIR")
                && has_preamble(&path)?
            {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

fn has_preamble(path: &Path) -> Result<bool> {
    let mut head = [0u8; 132];
    let mut file = crate::input::open(path)?;
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
    let description = obj
        .get(tags::SERIES_DESCRIPTION)
        .and_then(|e| e.to_str().ok())
        .map(|s| s.trim_end_matches(['\0', ' ']).to_string())
        .unwrap_or_default();
    let size = [int(tags::COLUMNS, "Columns")?, int(tags::ROWS, "Rows")?];
    // Decoders allocate Rows × Columns samples before they look at the data: refuse sizes the
    // file cannot hold even at a generous compression ratio.
    let file_len = std::fs::metadata(&path)
        .map_err(|e| Error::io(&path, e))?
        .len();
    let pixel_bytes = u64::from(size[0]) * u64::from(size[1]) * u64::from(bits / 8);
    if pixel_bytes > (64 * file_len).max(1 << 24) {
        return Err(Error::file(
            &path,
            format!(
                "Rows {} × Columns {} of {bits}-bit samples ({pixel_bytes} bytes) cannot come from \
                 a {file_len}-byte file",
                size[1], size[0]
            ),
        ));
    }
    Ok(Slice {
        series,
        description,
        size,
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

/// Most gaps may differ from the median by this share before the series counts as uneven: real
/// scanners jitter by about 2 %, a missing slice doubles a gap.
const GAP_TOLERANCE: f64 = 0.2;

/// The slice spacing of `slices` (sorted by depth) and whether they must be resampled onto it,
/// or `None` for a single slice. Slices that are not evenly spaced (a missing slice, a gap
/// between two stacks) are refused with their positions, unless `resample` asks for resampling
/// onto the median spacing.
fn even_spacing(dir: &Path, slices: &[Slice], resample: bool) -> Result<Option<(f64, bool)>> {
    let gaps: Vec<f64> = slices.windows(2).map(|p| p[1].depth - p[0].depth).collect();
    if gaps.is_empty() {
        return Ok(None);
    }
    let mut sorted = gaps.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let uneven = gaps
        .iter()
        .position(|g| (g - median).abs() > GAP_TOLERANCE * median);
    match uneven {
        None => Ok(Some((gaps.iter().sum::<f64>() / gaps.len() as f64, false))),
        Some(_) if resample => Ok(Some((median, true))),
        Some(i) => Err(Error::file(
            dir,
            format!(
                "the slices are not evenly spaced: {} is at {:.4} and {} at {:.4} along the slice \
                 normal, {:.4} apart where the others are about {median:.4} (a missing slice?); \
                 --resample-gaps resamples the series onto even spacing",
                name(&slices[i].path),
                slices[i].depth,
                name(&slices[i + 1].path),
                slices[i + 1].depth,
                gaps[i]
            ),
        )),
    }
}

/// `grid`'s slices, which sit at `depths`, linearly interpolated onto slices `dz` apart from
/// the first. Values stay in stored units (the rescale map commutes with interpolation), as
/// `f32` for 8- and 16-bit samples, `f64` otherwise.
fn resample(grid: &Grid, depths: &[f64], dz: f64) -> Grid {
    let [nx, ny, _] = grid.dims;
    let nxy = nx * ny;
    let span = depths[depths.len() - 1] - depths[0];
    let nz = (span / dz).round() as usize + 1;
    let values: Vec<f64> = with_samples!(&grid.samples, v => v.iter().map(|&x| sc_runtime::Scalar::to_f64(x)).collect());
    let mut out = Vec::with_capacity(nxy * nz);
    let mut below = 0;
    for k in 0..nz {
        let d = depths[0] + k as f64 * dz;
        while below + 2 < depths.len() && depths[below + 1] <= d {
            below += 1;
        }
        let (d0, d1) = (depths[below], depths[below + 1]);
        let t = ((d - d0) / (d1 - d0)).clamp(0.0, 1.0);
        let (a, b) = (
            &values[below * nxy..][..nxy],
            &values[(below + 1) * nxy..][..nxy],
        );
        out.extend(a.iter().zip(b).map(|(a, b)| a + t * (b - a)));
    }
    let samples = if grid.samples.dtype().size() <= 2 {
        Samples::F32(out.iter().map(|&v| v as f32).collect())
    } else {
        Samples::F64(out.into())
    };
    let mut resampled = Grid::new(samples, [nx, ny, nz], grid.format);
    resampled.scale = grid.scale;
    resampled
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
            .from_reader(&bytes[..super::dicom_lengths::pixel_data_end(&bytes)])
            .map_err(|e| {
                Error::file(
                    path,
                    format!("cannot read the pixel data: {}", with_causes(&e)),
                )
            })?;
        // The pixel decoders (RLE, JPEG) panic on some corrupt fragments: a bad slice must
        // become an error naming it, not end the program.
        let decoded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let pixels = obj
                .decode_pixel_data()
                .map_err(|e| format!("cannot decode the pixel data: {}", with_causes(&e)))?;
            pixels
                .to_vec_frame_with_options::<T>(0, options)
                .map_err(|e| format!("cannot convert the pixel data: {}", with_causes(&e)))
        }));
        let values: Vec<T> = match decoded {
            Ok(result) => result.map_err(|message| Error::file(path, message))?,
            Err(_) => {
                return Err(Error::file(
                    path,
                    "the pixel data is corrupt (its decoder failed)",
                ));
            }
        };
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
