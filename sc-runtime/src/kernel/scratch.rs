use crate::Error;

/// Caller-provided working memory for one sweep: O(nx·ny), independent of nz.
///
/// Without `alloc`, size two buffers with [`Scratch::len`] and lend them; with `alloc`, the
/// meshing functions allocate them. Contents need no initialisation: the sweep writes every cell
/// before it reads it.
pub struct Scratch<'a> {
    pub(crate) bytes: &'a mut [u8],
    pub(crate) words: &'a mut [u32],
}

/// Sizes of the two scratch buffers for some dimensions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScratchLen {
    /// Length of the `u8` buffer.
    pub bytes: usize,
    /// Length of the `u32` buffer.
    pub words: usize,
}

/// Four classified slices, three layers of cube cases and a plane of merge marks, a byte per cell.
pub(crate) const BYTE_PLANES: usize = 8;
/// Bytes after the classified slices and after the cube cases: a row's last scan block (64
/// bytes, `sweep::SCAN`) is read whole and masked to the row, so that no row needs a
/// byte-by-byte tail loop.
pub(crate) const PAD: usize = 64;
/// Two planes of x- and y-edge vertex ids plus one layer of z-edge ids.
pub(crate) const WORD_PLANES: usize = 5;
/// Span pairs per row: four classified slices and three case layers.
pub(crate) const SPAN_ROWS: usize = 7;

impl<'a> Scratch<'a> {
    /// The buffer sizes a sweep over `dims` needs.
    pub fn len(dims: [usize; 3]) -> Result<ScratchLen, Error> {
        // Row spans are stored in 31 bits.
        if dims[0] >= 1 << 31 {
            return Err(Error::DimsOverflow(dims));
        }
        let nxy = dims[0]
            .checked_mul(dims[1])
            .ok_or(Error::DimsOverflow(dims))?;
        let bytes = nxy
            .checked_mul(BYTE_PLANES)
            .and_then(|b| b.checked_add(2 * PAD))
            .ok_or(Error::DimsOverflow(dims))?;
        let words = nxy
            .checked_mul(WORD_PLANES)
            .and_then(|w| w.checked_add(dims[1].checked_mul(2 * SPAN_ROWS)?))
            .ok_or(Error::DimsOverflow(dims))?;
        Ok(ScratchLen { bytes, words })
    }

    /// Lends buffers of at least [`Scratch::len`] cells to a sweep over `dims`.
    pub fn new(bytes: &'a mut [u8], words: &'a mut [u32], dims: [usize; 3]) -> Result<Self, Error> {
        let need = Self::len(dims)?;
        if bytes.len() < need.bytes || words.len() < need.words {
            return Err(Error::ScratchTooSmall);
        }
        Ok(Scratch { bytes, words })
    }
}
