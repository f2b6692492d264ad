//! Sample blocks: where in a file the samples are and how they are stored. Every format that
//! keeps its samples in one block hands it to [`read_block`], so that byte order, compression,
//! truncation and progress are handled once.

use std::io::{self, BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use super::payload::{self, Encoding, Layout};
use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::volume::{Buffer, Endian, Sample, Samples};

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
    let file = crate::input::open(path)?;
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
    let mut file = crate::input::open(path)?;
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
