//! NRRD (`.nrrd` with attached data, `.nhdr` with a detached data file), encodings raw and gzip.
//! No maintained crate reads NRRD, and the part needed here is a short text header.

use std::io::{BufRead, BufReader};
use std::path::Path;

use super::block::{Block, Start, read_block};
use super::header::{Syntax, TextHeader};
use super::payload::{self, Encoding, Layout};
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::space::{Frame, Space};
use crate::volume::{Dtype, Endian, Grid};

const SYNTAX: Syntax = Syntax {
    separator: ":",
    last_key: None,
    format: "NRRD",
};

/// Reads a 3-D scalar NRRD.
pub fn read(path: &Path, progress: &dyn Progress) -> Result<Grid> {
    let mut reader = BufReader::new(crate::input::open(path)?);
    let mut magic = Vec::new();
    reader
        .read_until(b'\n', &mut magic)
        .map_err(|e| Error::io(path, e))?;
    if !magic.starts_with(b"NRRD000") {
        return Err(Error::file(
            path,
            "not a NRRD file: it does not start with NRRD000x",
        ));
    }
    let h = TextHeader::read(path, &mut reader, magic.len() as u64, &SYNTAX)?;
    drop(reader);

    let dtype = dtype(&h)?;
    let dimension = h.require("dimension")?;
    if dimension != "3" {
        return Err(h.error(format!(
            "dimension is {dimension}; only 3-D volumes can be meshed"
        )));
    }
    let sizes = h.numbers::<usize>("sizes", h.require("sizes")?, 3)?;
    let endian = match h.get("endian") {
        Some("little") => Endian::Little,
        Some("big") => Endian::Big,
        None if dtype.size() == 1 => Endian::Little,
        None => return Err(h.error("the required field \"endian\" is missing")),
        Some(other) => return Err(h.error(format!("unknown endian {other:?}"))),
    };
    let encoding = match h.require("encoding")? {
        "raw" => Encoding::Raw,
        "gzip" | "gz" => Encoding::Gzip,
        other => {
            return Err(h.error(format!(
                "encoding {other:?} is not supported (raw and gzip are)"
            )));
        }
    };
    let byte_skip: i64 = parse_or(&h, "byte skip", 0)?;
    let skip_lines: usize = parse_or(&h, "line skip", 0)?;
    let detached = h.get_any(&["data file", "datafile"]);
    if detached.is_some_and(|d| d.starts_with("LIST") || d.contains(' ')) {
        return Err(h.error("multi-file data (\"data file: LIST\" or a pattern) is not supported"));
    }
    let data_path = detached.map(|name| h.sibling(name)).transpose()?;
    let attached_at = if detached.is_some() { 0 } else { h.data_offset };
    // The NRRD spec applies the byte skip to the file for raw data and to the decoded stream for
    // compressed data; -1 (raw only) means "the samples are the last bytes".
    let (start, skip_decoded) = match (encoding, byte_skip) {
        (Encoding::Raw, -1) => (Start::End, 0),
        (_, n) if n < 0 => return Err(h.error(format!("byte skip {n} is invalid here"))),
        (Encoding::Raw, n) => (Start::At(attached_at + n as u64), 0),
        (_, n) => (Start::At(attached_at), n as u64),
    };

    let dims = [sizes[0], sizes[1], sizes[2]];
    let block = Block {
        path: data_path.as_deref().unwrap_or(path),
        start,
        skip_lines,
        encoding,
        skip_decoded,
        layout: Layout {
            dtype,
            endian,
            count: payload::sample_count(dims).ok_or_else(|| {
                h.error(format!(
                    "sizes {dims:?} hold more samples than memory can address"
                ))
            })?,
        },
    };
    let mut grid = Grid::new(read_block(&block, progress)?, dims, "NRRD");
    place(&h, &mut grid)?;
    Ok(grid)
}

fn parse_or<T: std::str::FromStr>(h: &TextHeader, key: &str, default: T) -> Result<T> {
    h.get(key).map_or(Ok(default), |v| {
        v.parse().map_err(|_| h.error(format!("bad {key} {v:?}")))
    })
}

fn dtype(h: &TextHeader) -> Result<Dtype> {
    let name = h.require("type")?;
    let (kind, bytes) = match name.to_ascii_lowercase().as_str() {
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => ('u', 1),
        "signed char" | "int8" | "int8_t" => ('i', 1),
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => ('u', 2),
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            ('i', 2)
        }
        "uint" | "unsigned int" | "uint32" | "uint32_t" => ('u', 4),
        "int" | "signed int" | "int32" | "int32_t" => ('i', 4),
        "float" => ('f', 4),
        "double" => ('f', 8),
        _ => ('?', 0),
    };
    Dtype::from_kind(kind, bytes)
        .ok_or_else(|| h.error(format!("sample type {name:?} is not supported")))
}

/// Spacing from `space directions` (the vectors' lengths) or `spacings`, origin from
/// `space origin`; with a `space` of LPS or RAS the directions place the volume in that world.
fn place(h: &TextHeader, grid: &mut Grid) -> Result<()> {
    let space = match h.get("space") {
        Some("left-posterior-superior" | "LPS") => Some(Space::Lps),
        Some("right-anterior-superior" | "RAS") => Some(Space::Ras),
        Some(other) => {
            grid.notes.push(format!(
                "space {other}: not RAS or LPS, so the mesh is in index × spacing + origin"
            ));
            None
        }
        None => None,
    };
    match h.get("space directions") {
        Some(dirs) if dirs != "none" => {
            let v = h.numbers::<f64>("space directions", dirs, 9)?;
            let columns = [0, 1, 2].map(|a| [v[3 * a], v[3 * a + 1], v[3 * a + 2]]);
            let (frame, spacing) = Frame::from_columns(columns, space.unwrap_or(Space::Lps))
                .ok_or_else(|| {
                    h.error(format!(
                        "space directions {dirs} do not span three dimensions"
                    ))
                })?;
            grid.spacing = spacing;
            grid.frame = space.map(|_| frame);
        }
        _ => {
            if let Some(s) = h.get("spacings") {
                let s = h.numbers::<f64>("spacings", s, 3)?;
                grid.spacing = [s[0], s[1], s[2]];
            }
            grid.frame = space.map(Frame::aligned);
        }
    }
    if let Some(o) = h.get("space origin") {
        let o = h.numbers::<f64>("space origin", o, 3)?;
        grid.origin = [o[0], o[1], o[2]];
    }
    Ok(())
}
