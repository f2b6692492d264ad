//! The sample block that every format ends in: `count` values of one type, in one byte order,
//! raw or compressed. Reading goes straight into the typed vector, so the volume is copied once,
//! from the file into its final place.

use std::io::{self, Read};

use flate2::read::{MultiGzDecoder, ZlibDecoder};

use crate::progress::Progress;
use crate::volume::{Dtype, Endian, Sample, Samples};
use crate::with_dtype;

/// How the sample bytes are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// As they are.
    Raw,
    /// A gzip stream (NRRD `encoding: gzip`, `.nii.gz`).
    Gzip,
    /// A zlib stream (MetaImage `CompressedData = True`).
    Zlib,
}

/// The layout of a sample block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Sample type.
    pub dtype: Dtype,
    /// Byte order.
    pub endian: Endian,
    /// Number of samples.
    pub count: usize,
}

impl Layout {
    /// Bytes of decoded samples, or `None` if that overflows.
    pub fn bytes(&self) -> Option<usize> {
        self.count.checked_mul(self.dtype.size())
    }
}

/// The number of samples of a `dims` volume, or `None` if it overflows: a header's sizes are
/// untrusted, and a wrapped product would describe a small volume that is not there (fuzzing
/// found NRRD and MetaImage sizes whose product overflowed).
pub fn sample_count(dims: [usize; 3]) -> Option<usize> {
    dims.iter().try_fold(1usize, |n, &d| n.checked_mul(d))
}

/// `reader` with `encoding` undone.
pub fn decode<'a>(reader: impl Read + 'a, encoding: Encoding) -> Box<dyn Read + 'a> {
    match encoding {
        Encoding::Raw => Box::new(reader),
        Encoding::Gzip => Box::new(MultiGzDecoder::new(reader)),
        Encoding::Zlib => Box::new(ZlibDecoder::new(reader)),
    }
}

/// Reads `layout.count` samples from decoded bytes.
///
/// A short read says how far the data got, which is what a user needs to tell a truncated
/// download from wrong dimensions.
///
/// `verified` says the payload was checked to hold `layout`'s bytes (an uncompressed file of the
/// right length): then the samples are allocated at once. Otherwise (compressed data, archive
/// members) they grow as bytes actually arrive, so a header that claims a huge volume over a
/// small payload fails at the end of the data instead of aborting on an allocation.
pub fn read_samples(
    reader: impl Read,
    layout: Layout,
    verified: bool,
    progress: &dyn Progress,
) -> io::Result<Samples> {
    with_dtype!(layout.dtype, T => read_typed::<T>(reader, layout, verified, progress).map(|v| Sample::wrap(v.into())))
}

/// Chunk size for progress updates: large enough that the bar costs nothing.
const CHUNK: usize = 1 << 22;

pub(crate) fn read_typed<T: Sample>(
    mut reader: impl Read,
    layout: Layout,
    verified: bool,
    progress: &dyn Progress,
) -> io::Result<Vec<T>> {
    let need = layout.bytes().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            "the volume does not fit in memory",
        )
    })?;
    progress.phase("reading", need as u64);
    let size = layout.dtype.size();
    let mut samples: Vec<T> = Vec::new();
    let no_memory = || {
        io::Error::new(
            io::ErrorKind::OutOfMemory,
            format!("not enough memory for {need} bytes of samples"),
        )
    };
    if verified {
        samples
            .try_reserve_exact(layout.count)
            .map_err(|_| no_memory())?;
    }
    let mut got = 0;
    while got < need {
        let end = need.min(got + CHUNK);
        let want = end.div_ceil(size);
        if samples.len() < want {
            samples
                .try_reserve(want - samples.len())
                .map_err(|_| no_memory())?;
            samples.resize(want, T::zeroed());
        }
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut samples);
        match reader.read(&mut bytes[got..end]) {
            Ok(0) => {
                return Err(io::Error::new(
                    io::ErrorKind::UnexpectedEof,
                    format!(
                        "the sample data ends after {got} of {need} bytes \
                         (truncated file, or dimensions larger than the data?)"
                    ),
                ));
            }
            Ok(n) => {
                got += n;
                progress.inc(n as u64);
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    if layout.endian != Endian::native() && size > 1 {
        bytemuck::cast_slice_mut::<T, u8>(&mut samples)
            .chunks_exact_mut(layout.dtype.size())
            .for_each(<[u8]>::reverse);
    }
    Ok(samples)
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use flate2::Compression;
    use flate2::write::GzEncoder;

    use super::*;

    fn read(
        bytes: &[u8],
        encoding: Encoding,
        dtype: Dtype,
        endian: Endian,
        count: usize,
    ) -> io::Result<Samples> {
        let layout = Layout {
            dtype,
            endian,
            count,
        };
        read_samples(
            decode(bytes, encoding),
            layout,
            false,
            &crate::progress::Silent,
        )
    }

    #[test]
    fn big_endian_is_swapped() {
        let bytes = [0x01, 0x02, 0xff, 0xfe];
        let s = read(&bytes, Encoding::Raw, Dtype::I16, Endian::Big, 2);
        assert_eq!(s.unwrap(), Samples::I16(vec![0x0102, -2].into()));
    }

    #[test]
    fn gzip_round_trips() {
        let data: Vec<u8> = (0..=255).collect();
        let mut gz = GzEncoder::new(Vec::new(), Compression::fast());
        gz.write_all(&data).unwrap();
        let gz = gz.finish().unwrap();
        let s = read(&gz, Encoding::Gzip, Dtype::U8, Endian::Little, 256);
        assert_eq!(s.unwrap(), Samples::U8(data.into()));
    }

    #[test]
    fn short_data_says_how_far_it_got() {
        let e = read(&[0u8; 5], Encoding::Raw, Dtype::F32, Endian::Little, 2).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::UnexpectedEof);
        assert!(e.to_string().contains("after 5 of 8 bytes"), "{e}");
    }

    #[test]
    fn truncated_gzip_is_an_error() {
        let mut gz = GzEncoder::new(Vec::new(), Compression::fast());
        gz.write_all(&[7u8; 1000]).unwrap();
        let gz = gz.finish().unwrap();
        let cut = &gz[..gz.len() / 2];
        assert!(read(cut, Encoding::Gzip, Dtype::U8, Endian::Little, 1000).is_err());
    }
}
