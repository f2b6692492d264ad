//! Samples held in memory or mapped from their file.
//!
//! An uncompressed volume in this machine's byte order is already laid out as the extractor reads
//! it, so it is mapped rather than copied: reading it into fresh memory costs zeroing and
//! faulting in the pages and then the kernel's copy, several times what mapping it and reading
//! it through costs, and the page cache's copy is then the only one in memory. nibabel maps NIfTI
//! files the same way by default.

use std::fmt;
use std::fs::File;
use std::ops::Deref;
use std::sync::Arc;

use bytemuck::Pod;
use memmap2::Mmap;

/// Samples of type `T`, x fastest, owned or mapped read-only from a file. Dereferences to
/// `[T]`.
pub struct Buffer<T> {
    storage: Storage<T>,
}

enum Storage<T> {
    Owned(Vec<T>),
    /// `len` samples from byte `offset` of `map`, which is aligned for `T` there.
    Mapped {
        map: Arc<Mmap>,
        offset: usize,
        len: usize,
    },
}

impl<T: Pod> Buffer<T> {
    /// Maps `len` samples from byte `offset` of `file`, or returns `None` where the bytes cannot
    /// be read in place (misaligned for `T`, past the file's end, or a mapping refused): the
    /// caller then reads them. Byte order is the caller's to check.
    pub(crate) fn map(file: &File, offset: u64, len: usize) -> Option<Self> {
        let size = std::mem::size_of::<T>();
        let offset = usize::try_from(offset).ok()?;
        let end = len.checked_mul(size)?.checked_add(offset)?;
        // SAFETY: the mapping is read-only and private. It is undefined behaviour only if the
        // file is changed while mapped: truncated, reading past the new end raises SIGBUS;
        // rewritten, the samples change under the extraction. Volume files are not rewritten
        // while they are read, and nibabel and NumPy's `mmap_mode` map them on the same terms.
        let map = unsafe { Mmap::map(file) }.ok()?;
        let bytes = map.get(offset..end)?;
        // The map starts on a page, so alignment depends on the offset alone; checked anyway.
        bytemuck::try_cast_slice::<u8, T>(bytes).ok()?;
        Some(Buffer {
            storage: Storage::Mapped {
                map: Arc::new(map),
                offset,
                len,
            },
        })
    }

    /// The samples as an owned vector: moved when owned, copied when mapped.
    pub fn into_vec(self) -> Vec<T> {
        match self.storage {
            Storage::Owned(v) => v,
            Storage::Mapped { .. } => self.deref().to_vec(),
        }
    }
}

impl<T: Pod> Deref for Buffer<T> {
    type Target = [T];

    fn deref(&self) -> &[T] {
        match &self.storage {
            Storage::Owned(v) => v,
            Storage::Mapped { map, offset, len } => {
                bytemuck::cast_slice(&map[*offset..*offset + len * std::mem::size_of::<T>()])
            }
        }
    }
}

impl<T> From<Vec<T>> for Buffer<T> {
    fn from(v: Vec<T>) -> Self {
        Buffer {
            storage: Storage::Owned(v),
        }
    }
}

impl<T> FromIterator<T> for Buffer<T> {
    fn from_iter<I: IntoIterator<Item = T>>(iter: I) -> Self {
        Vec::from_iter(iter).into()
    }
}

impl<T: Pod> Clone for Buffer<T> {
    fn clone(&self) -> Self {
        let storage = match &self.storage {
            Storage::Owned(v) => Storage::Owned(v.clone()),
            Storage::Mapped { map, offset, len } => Storage::Mapped {
                map: Arc::clone(map),
                offset: *offset,
                len: *len,
            },
        };
        Buffer { storage }
    }
}

impl<T: Pod + PartialEq> PartialEq for Buffer<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl<T: Pod + fmt::Debug> fmt::Debug for Buffer<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&**self, f)
    }
}

#[cfg(test)]
mod tests {
    use std::io::Write;

    use super::Buffer;

    /// A mapped buffer reads the same samples as the file holds, from any aligned offset; a
    /// misaligned offset or a range past the end is left to the reader.
    #[test]
    fn maps_what_the_file_holds_where_it_can() {
        let values: Vec<i16> = (0..1000).map(|i| (i * 37 % 2001 - 1000) as i16).collect();
        let mut file = tempfile::tempfile().unwrap();
        file.write_all(&[9; 6]).unwrap();
        file.write_all(bytemuck::cast_slice(&values)).unwrap();
        let mapped = Buffer::<i16>::map(&file, 6, 1000).unwrap();
        assert_eq!(*mapped, values[..]);
        assert_eq!(mapped.clone().into_vec(), values);
        assert_eq!(mapped, Buffer::from(values.clone()));
        assert!(Buffer::<i16>::map(&file, 5, 10).is_none(), "misaligned");
        assert!(Buffer::<i16>::map(&file, 6, 1001).is_none(), "past the end");
        assert!(
            Buffer::<i16>::map(&file, u64::MAX, 1).is_none(),
            "offset overflows"
        );
    }
}
