//! MetaImage (`.mha` with the data after the header, `.mhd` with a separate data file), raw or
//! zlib-compressed. Like NRRD it is a short text header, so it shares [`super::header`].

use std::io::BufReader;
use std::path::Path;

use super::block::{Block, Start, read_block};
use super::header::{Syntax, TextHeader};
use super::payload::{self, Encoding, Layout};
use crate::error::Result;
use crate::progress::Progress;
use crate::space::{Frame, Space};
use crate::volume::{Dtype, Endian, Grid};

const SYNTAX: Syntax = Syntax {
    separator: "=",
    last_key: Some("ElementDataFile"),
    format: "MetaImage",
};

/// Reads a 3-D scalar MetaImage.
pub fn read(path: &Path, progress: &dyn Progress) -> Result<Grid> {
    let mut reader = BufReader::new(crate::input::open(path)?);
    let h = TextHeader::read(path, &mut reader, 0, &SYNTAX)?;
    drop(reader);

    let ndims = h.require("NDims")?;
    if ndims != "3" {
        return Err(h.error(format!("NDims is {ndims}; only 3-D volumes can be meshed")));
    }
    if h.get("ElementNumberOfChannels").is_some_and(|c| c != "1") {
        return Err(h.error("images with several channels per sample are not supported"));
    }
    let sizes = h.numbers::<usize>("DimSize", h.require("DimSize")?, 3)?;
    let dims = [sizes[0], sizes[1], sizes[2]];
    let dtype = dtype(&h)?;
    let endian = match h.get_any(&["BinaryDataByteOrderMSB", "ElementByteOrderMSB"]) {
        Some(b) if b.eq_ignore_ascii_case("true") => Endian::Big,
        _ => Endian::Little,
    };
    let compressed = h
        .get("CompressedData")
        .is_some_and(|c| c.eq_ignore_ascii_case("true"));
    let encoding = if compressed {
        Encoding::Zlib
    } else {
        Encoding::Raw
    };

    let data_file = h.require("ElementDataFile")?;
    if data_file.starts_with("LIST") || data_file.contains(' ') {
        return Err(
            h.error("multi-file data (ElementDataFile = LIST or a pattern) is not supported")
        );
    }
    let local = data_file.eq_ignore_ascii_case("LOCAL");
    let data_path = (!local).then(|| h.sibling(data_file)).transpose()?;
    let start = match h.get("HeaderSize") {
        Some("-1") if !compressed => Start::End,
        Some(n) => {
            let skip: u64 = n
                .parse()
                .map_err(|_| h.error(format!("bad HeaderSize {n:?}")))?;
            let base = if local { h.data_offset } else { 0 };
            Start::At(
                base.checked_add(skip)
                    .ok_or_else(|| h.error(format!("HeaderSize {n} is past any file")))?,
            )
        }
        None => Start::At(if local { h.data_offset } else { 0 }),
    };
    let block = Block {
        path: data_path.as_deref().unwrap_or(path),
        start,
        skip_lines: 0,
        encoding,
        skip_decoded: 0,
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
    let mut grid = Grid::new(read_block(&block, progress)?, dims, "MetaImage");
    if let Some(s) = h.get_any(&["ElementSpacing", "ElementSize"]) {
        let s = h.numbers::<f64>("ElementSpacing", s, 3)?;
        grid.spacing = [s[0], s[1], s[2]];
    }
    if let Some(o) = h.get_any(&["Offset", "Origin", "Position"]) {
        let o = h.numbers::<f64>("Offset", o, 3)?;
        grid.origin = [o[0], o[1], o[2]];
    }
    // MetaImage is ITK's format: LPS world space, TransformMatrix listing each axis's direction
    // in turn (three numbers per axis).
    let columns = match h.get_any(&["TransformMatrix", "Rotation", "Orientation"]) {
        Some(m) => {
            let m = h.numbers::<f64>("TransformMatrix", m, 9)?;
            [0, 1, 2].map(|a| [m[3 * a], m[3 * a + 1], m[3 * a + 2]])
        }
        None => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };
    let (frame, _) = Frame::from_columns(columns, Space::Lps)
        .ok_or_else(|| h.error("TransformMatrix is degenerate".to_string()))?;
    grid.frame = Some(frame);
    Ok(grid)
}

fn dtype(h: &TextHeader) -> Result<Dtype> {
    let name = h.require("ElementType")?;
    let (kind, bytes) = match name {
        "MET_UCHAR" => ('u', 1),
        "MET_CHAR" => ('i', 1),
        "MET_USHORT" => ('u', 2),
        "MET_SHORT" => ('i', 2),
        "MET_UINT" => ('u', 4),
        "MET_INT" => ('i', 4),
        "MET_FLOAT" => ('f', 4),
        "MET_DOUBLE" => ('f', 8),
        _ => ('?', 0),
    };
    Dtype::from_kind(kind, bytes)
        .ok_or_else(|| h.error(format!("ElementType {name} is not supported")))
}
