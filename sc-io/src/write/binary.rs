//! Numbers written as bytes, in batches: what the binary formats (PLY, STL, glTF) share.

use std::io::{self, Write};

/// Encodes records `0..count` of `record` bytes each with `encode` and writes them in batches:
/// writing each field with a call of its own cost as much as a quarter of the whole extraction
/// through a `BufWriter`, and far more through a writer that counts progress.
pub(crate) fn in_chunks(
    count: usize,
    record: usize,
    out: &mut impl Write,
    encode: impl Fn(usize, &mut [u8]),
) -> io::Result<()> {
    // At least 64 KiB per batch, so that batches bypass the output's `BufWriter`.
    const BATCH: usize = 8192;
    let mut buf = vec![0u8; BATCH.min(count) * record];
    for start in (0..count).step_by(BATCH) {
        let n = BATCH.min(count - start);
        for (k, rec) in buf[..n * record].chunks_exact_mut(record).enumerate() {
            encode(start + k, rec);
        }
        out.write_all(&buf[..n * record])?;
    }
    Ok(())
}

/// Writes `values` as consecutive little-endian numbers: as they lie in memory on little-endian
/// machines, encoded in batches elsewhere.
pub(crate) fn le_words<T: bytemuck::Pod, const N: usize>(
    values: &[[T; N]],
    out: &mut impl Write,
    to_le: impl Fn(T) -> [u8; 4],
) -> io::Result<()> {
    if cfg!(target_endian = "little") {
        out.write_all(bytemuck::cast_slice(values))
    } else {
        le_encoded(values, out, to_le)
    }
}

/// [`le_words`] on a big-endian machine: each number encoded.
fn le_encoded<T: Copy, const N: usize>(
    values: &[[T; N]],
    out: &mut impl Write,
    to_le: impl Fn(T) -> [u8; 4],
) -> io::Result<()> {
    in_chunks(values.len(), 4 * N, out, |i, rec| {
        for (field, &v) in rec.chunks_exact_mut(4).zip(&values[i]) {
            field.copy_from_slice(&to_le(v));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both ways of writing numbers give the file's bytes, across several batches and a partial
    /// one: the encoded way is what big-endian machines run, and is checked here against the
    /// little-endian bytes it must reproduce.
    #[test]
    fn numbers_encoded_and_cast_agree() {
        let values: Vec<[u32; 3]> = (0..20_000u32)
            .map(|i| [i, i.wrapping_mul(2_654_435_761), u32::MAX - i])
            .collect();
        let want: Vec<u8> = values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let mut encoded = Vec::new();
        le_encoded(&values, &mut encoded, u32::to_le_bytes).unwrap();
        assert!(encoded == want);
        let mut written = Vec::new();
        le_words(&values, &mut written, u32::to_le_bytes).unwrap();
        assert!(written == want);
    }
}
