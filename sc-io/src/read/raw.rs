//! Headerless sample files, laid out by the command line.

use std::path::Path;

use super::block::{Block, Start, read_block};
use super::payload::{Encoding, Layout};
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::volume::{Dtype, Endian, Grid};

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

/// Reads `path` as `layout` says. The file size must match exactly: a raw file has nothing else
/// to catch wrong `--dims` or `--dtype`, and a size mismatch is almost always one.
pub fn read(path: &Path, layout: &RawLayout, progress: &dyn Progress) -> Result<Grid> {
    let block = block(path, layout)?;
    Ok(Grid::new(read_block(&block, progress)?, layout.dims, "raw"))
}

/// The sample block of `path` laid out as `layout` says, checked against the file's size.
pub fn block<'a>(path: &'a Path, layout: &RawLayout) -> Result<Block<'a>> {
    let [nx, ny, nz] = layout.dims;
    let count = nx
        .checked_mul(ny)
        .and_then(|n| n.checked_mul(nz))
        .ok_or_else(|| Error::file(path, "the dims overflow"))?;
    let block_layout = Layout {
        dtype: layout.dtype,
        endian: layout.endian,
        count,
    };
    let need = block_layout.bytes().map(|b| b as u64 + layout.header_bytes);
    // A FIFO's size is 0: name what it is, not a size mismatch.
    crate::input::regular(path)?;
    let len = std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .len();
    if need != Some(len) {
        return Err(Error::file(
            path,
            format!(
                "the file has {len} bytes, but dims {nx},{ny},{nz} of {} with {} header bytes \
                 need {}",
                layout.dtype.name(),
                layout.header_bytes,
                need.map_or("more than fits in memory".into(), |n| n.to_string())
            ),
        ));
    }
    Ok(Block {
        path,
        start: Start::At(layout.header_bytes),
        skip_lines: 0,
        encoding: Encoding::Raw,
        skip_decoded: 0,
        layout: block_layout,
    })
}
