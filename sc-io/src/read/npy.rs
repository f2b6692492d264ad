//! NumPy `.npy` and `.npz`. The `npyz` crate parses the header (and the zip archive); the samples
//! are read by [`payload::read_samples`] straight into their typed vector.
//!
//! Axes: a C-order array of shape `(a, b, c)`, the NumPy default, is indexed `[z, y, x]` with x
//! varying fastest, so the volume is `nx = c, ny = b, nz = a` and the bytes are used as they are.
//! A Fortran-order array of shape `(a, b, c)` is `nx = a, ny = b, nz = c`. Either way no sample is
//! moved; only the shape is read in the right direction.

use std::io::{self, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use npyz::npz::NpzArchive;
use npyz::{DType, NpyHeader, Order, TypeChar};
use py_literal::Value;

use super::block::MAX_TRAILING;
use super::payload::{self, Layout};
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::volume::{Dtype, Endian, Grid};

/// Reads an `.npy` file, or the array `array` of an `.npz` archive (which may be left out when
/// the archive holds one array).
pub fn read(path: &Path, array: Option<&str>, progress: &dyn Progress) -> Result<Grid> {
    let is_npz = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npz"));
    if !is_npz {
        let mut file = BufReader::new(crate::input::open(path)?);
        check_header(&mut file).map_err(|m| not_readable(path, m))?;
        file.seek(SeekFrom::Start(0))
            .map_err(|e| Error::io(path, e))?;
        let header =
            NpyHeader::from_reader(&mut file).map_err(|e| not_readable(path, e.to_string()))?;
        return read_array(path, &header, file, progress);
    }
    let mut archive = NpzArchive::new(BufReader::new(crate::input::open(path)?))
        .map_err(|e| Error::file(path, format!("not a readable .npz archive: {e}")))?;
    let names: Vec<String> = archive.array_names().map(str::to_owned).collect();
    let name = match (array, names.as_slice()) {
        (Some(name), _) => name.to_owned(),
        (None, [only]) => only.clone(),
        (None, _) => {
            return Err(Error::file(
                path,
                format!(
                    "the archive holds arrays {}: choose one with --array",
                    listing(&names)
                ),
            ));
        }
    };
    // npyz parses a member's header as it opens it: check the header first, as for `.npy`.
    let member = npyz::npz::file_name_from_array_name(&name);
    if let Ok(mut raw) = archive.zip_archive().by_name(&member) {
        check_header(&mut raw).map_err(|m| not_readable(path, m))?;
    }
    match archive.by_name(&name) {
        Ok(Some(npy)) => {
            let header = npy.header().clone();
            let mut member = npy.into_inner();
            let grid = read_array(path, &header, &mut member, progress)?;
            // The zip reader compares a member's CRC-32 only when it is read to its end: without
            // this, a flipped byte in the payload would mesh as an altered sample. What follows
            // the samples is bounded, not trusted.
            io::copy(&mut (&mut member).take(MAX_TRAILING), &mut io::sink())
                .map_err(|e| Error::file(path, format!("array {name:?} is corrupt: {e}")))?;
            Ok(grid)
        }
        Ok(None) => Err(Error::file(
            path,
            format!(
                "no array named {name:?}; the archive holds {}",
                listing(&names)
            ),
        )),
        Err(e) => Err(Error::file(path, format!("array {name:?}: {e}"))),
    }
}

fn not_readable(path: &Path, message: String) -> Error {
    Error::file(path, format!("not a readable .npy header: {message}"))
}

/// Array names for a message: the first ten, and how many more.
fn listing(names: &[String]) -> String {
    let shown = names
        .iter()
        .take(10)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    match names.len() {
        n if n > 10 => format!("{shown} and {} more", n - 10),
        _ => shown,
    }
}

/// The longest `.npy` header we read. A plain numeric array's header is about 120 bytes; only
/// structured dtypes, which cannot be meshed anyway, make long ones. npyz's parser backtracks,
/// so its time grows with the length as well as the nesting (fuzzing found headers of 64 KiB
/// nested 7 deep that took seconds).
const MAX_HEADER: usize = 1 << 12;

/// Deepest bracket nesting accepted in a header: npyz's parser takes time exponential in it
/// (about ×3 a level: 11 unclosed braces took 5 s, 15 more than 20 s; found by fuzzing), and
/// a plain array's header nests 2 deep (the dict, the shape tuple).
const MAX_NESTING: usize = 6;

/// Checks the header's declared length, nesting and shape before npyz sees it, so that a hostile
/// header can make it neither allocate gigabytes, run for minutes nor overflow: npyz multiplies
/// the dimensions unchecked, which panics in a debug build and wraps in a release one (fuzzing
/// found `(8888888888888888888+88888888888, 8)`, which its Python-literal parser sums).
///
/// The header is parsed here with the same parser npyz uses, so what passes is what npyz reads.
pub(crate) fn check_header(file: &mut impl Read) -> std::result::Result<(), String> {
    let mut start = [0u8; 12];
    file.read_exact(&mut start[..10])
        .map_err(|_| "the file is shorter than a header".to_string())?;
    if &start[..6] != b"\x93NUMPY" {
        return Err("the file does not start with the .npy magic".into());
    }
    let len = match start[6] {
        1 => usize::from(u16::from_le_bytes([start[8], start[9]])),
        2 | 3 => {
            file.read_exact(&mut start[10..12])
                .map_err(|_| "the file is shorter than a header".to_string())?;
            u32::from_le_bytes([start[8], start[9], start[10], start[11]]) as usize
        }
        v => return Err(format!("format version {v} is unknown")),
    };
    if len > MAX_HEADER {
        return Err(format!("a header length of {len} bytes is implausible"));
    }
    let mut text = vec![0u8; len];
    file.read_exact(&mut text)
        .map_err(|_| format!("the file ends inside its {len}-byte header"))?;
    let mut depth = 0usize;
    for &c in &text {
        match c {
            b'[' | b'(' | b'{' => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Err(format!("brackets nest more than {MAX_NESTING} deep"));
                }
            }
            b']' | b')' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    let text = text.strip_suffix(b"\n").unwrap_or(&text);
    let value: Value = std::str::from_utf8(text)
        .map_err(|_| "the header is not UTF-8 text".to_string())?
        .parse()
        .map_err(|e| format!("the header is not a Python literal: {e}"))?;
    let Value::Dict(entries) = value else {
        return Err("the header is not a Python dict".into());
    };
    let shape = entries
        .iter()
        .find(|(key, _)| key.as_string().is_some_and(|k| k == "shape"))
        .map(|(_, shape)| shape);
    if let Some(Value::Tuple(dims) | Value::List(dims)) = shape {
        let fits = dims.iter().try_fold(1u64, |n, d| {
            let d = u64::try_from(d.as_integer()?).ok()?;
            n.checked_mul(d)
        });
        if fits.is_none() {
            return Err(format!(
                "shape {} is not a list of sizes whose product fits in 64 bits",
                Value::List(dims.clone())
            ));
        }
    }
    Ok(())
}

fn read_array(
    path: &Path,
    header: &NpyHeader,
    reader: impl Read,
    progress: &dyn Progress,
) -> Result<Grid> {
    let bad = |message: String| Error::file(path, message);
    let DType::Plain(ty) = header.dtype() else {
        return Err(bad(format!(
            "dtype {} is structured; a plain numeric array is needed",
            header.dtype().descr()
        )));
    };
    let kind = match ty.type_char() {
        TypeChar::Int => 'i',
        TypeChar::Uint | TypeChar::Bool => 'u',
        TypeChar::Float => 'f',
        _ => '?',
    };
    let bytes = usize::try_from(ty.size_field()).unwrap_or(0);
    let dtype = Dtype::from_kind(kind, bytes).ok_or_else(|| {
        bad(format!(
            "dtype {ty} is not supported: 8- to 32-bit integers and floats are"
        ))
    })?;
    let shape = header.shape();
    let dims: [usize; 3] = match (shape, header.order()) {
        ([a, b, c], Order::C) => [*c, *b, *a],
        ([a, b, c], Order::Fortran) => [*a, *b, *c],
        _ => {
            return Err(bad(format!(
                "the array has shape {shape:?}; a 3-D array is needed"
            )));
        }
    }
    .map(|d| usize::try_from(d).unwrap_or(usize::MAX));
    let endian = match ty.endianness() {
        npyz::Endianness::Big => Endian::Big,
        _ => Endian::Little,
    };
    let count = dims
        .iter()
        .try_fold(1usize, |n, &d| n.checked_mul(d))
        .ok_or_else(|| bad("the array is too large".into()))?;
    let layout = Layout {
        dtype,
        endian,
        count,
    };
    let samples =
        payload::read_samples(reader, layout, false, progress).map_err(|e| Error::io(path, e))?;
    Ok(Grid::new(samples, dims, "NumPy"))
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// An `.npz` that is a FIFO is refused before it is opened, as an `.npy` one is: the zip
    /// reader would otherwise wait for a writer forever.
    #[test]
    fn a_fifo_npz_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("v.npz");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo reads a NUL-terminated path that lives for the call.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = read(&fifo, None, &crate::progress::Silent).unwrap_err();
        assert!(
            e.to_string().contains("v.npz: is not a regular file"),
            "{e}"
        );
    }
}
