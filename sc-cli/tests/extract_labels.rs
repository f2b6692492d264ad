//! `skelclimb extract --labels` on the AAL crop in `tests/data/labels` (nine labels, its
//! MRIcron tables beside it): an atlas `.glb`, a file per label, selections, threads, and
//! refusals that leave no file behind.

mod common;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use assert_cmd::Command;
use common::{entries, fixture};

/// The crop's labels (every sample holds one; the background is only the padding).
const LABELS: [u64; 9] = [21, 27, 29, 37, 41, 71, 73, 75, 77];

fn crop() -> PathBuf {
    fixture("labels/aal-crop-24x24x16.u8.json")
}

fn run(args: &[&str]) -> std::process::Output {
    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("extract")
        .args(args)
        .output()
        .unwrap()
}

fn ok(args: &[&str]) -> String {
    let out = run(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Every edge of the mesh in `path` used by exactly two triangles, once in each direction.
fn closed(path: &Path) -> usize {
    let mesh = sc_io::mesh_in::read(path).unwrap();
    let mut directed: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &mesh.triangles {
        for i in 0..3 {
            *directed.entry((t[i], t[(i + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(
            (n, directed.get(&(b, a)).copied()),
            (1, Some(1)),
            "{}: edge {a}-{b}",
            path.display()
        );
    }
    mesh.triangles.len()
}

#[test]
fn a_file_per_label_each_closed_and_named_from_the_table_beside() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("meshes");
    let stats = dir.path().join("stats.json");
    let crop = crop();
    ok(&[
        crop.to_str().unwrap(),
        "--labels",
        "all",
        "-o",
        out.to_str().unwrap(),
        "--stats-json",
        stats.to_str().unwrap(),
    ]);
    let files = entries(&out);
    assert_eq!(files.len(), LABELS.len(), "{files:?}");
    let mut total = 0;
    for id in LABELS {
        let name = files
            .iter()
            .find(|f| f.starts_with(&format!("{id}-")))
            .unwrap_or_else(|| panic!("{id}: {files:?}"));
        assert!(
            name.ends_with(".ply") && name.len() > format!("{id}-.ply").len(),
            "{name}"
        );
        total += closed(&out.join(name));
    }
    // The directory renders, each label in a colour of its own.
    let png = dir.path().join("atlas.png");
    let render = Command::cargo_bin("skelclimb")
        .unwrap()
        .args([
            "render",
            out.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
            "-q",
        ])
        .output()
        .unwrap();
    assert!(
        render.status.success(),
        "{}",
        String::from_utf8_lossy(&render.stderr)
    );
    assert_eq!(&std::fs::read(&png).unwrap()[1..4], b"PNG");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    assert_eq!(report["per_label_triangles"], total as u64);
    assert_eq!(report["labels"], serde_json::json!(LABELS));
    // Each interface is once in the atlas and twice among the files, the background's once.
    let atlas = report["atlas"]["result"]["triangles"].as_u64().unwrap() as usize;
    assert!(atlas < total && total < 2 * atlas, "{atlas} {total}");
}

#[test]
fn a_selection_meshes_those_labels_only() {
    let dir = tempfile::tempdir().unwrap();
    let crop = crop();
    ok(&[
        crop.to_str().unwrap(),
        "--labels",
        "71,73-75",
        "--format",
        "stl",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    let files = entries(dir.path());
    let ids: Vec<&str> = files.iter().map(|f| f.split('-').next().unwrap()).collect();
    assert_eq!(ids, ["71", "73", "75"], "{files:?}");
    assert!(files.iter().all(|f| f.ends_with(".stl")));
    for f in &files {
        closed(&dir.path().join(f));
    }
}

#[test]
fn the_atlas_glb_is_the_same_on_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let crop = crop();
    let glb = |threads: &str| {
        let path = dir.path().join(format!("atlas-{threads}.glb"));
        ok(&[
            crop.to_str().unwrap(),
            "--labels",
            "all",
            "--threads",
            threads,
            "-o",
            path.to_str().unwrap(),
            "-q",
        ]);
        std::fs::read(path).unwrap()
    };
    let one = glb("1");
    assert_eq!(&one[..4], b"glTF");
    let text = String::from_utf8_lossy(&one);
    assert!(
        text.contains("Hippocampus_L") && text.contains("Thalamus_L"),
        "names from the table beside"
    );
    assert_eq!(glb("2"), one);
}

#[test]
fn refusals_name_the_argument_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let crop = crop();
    let crop = crop.to_str().unwrap();
    let out = dir.path().join("out.glb");
    let out = out.to_str().unwrap();
    let broken = dir.path().join("broken.txt");
    std::fs::write(&broken, "1 Left\n1 Right\n").unwrap();
    let float = dir.path().join("float.json");
    std::fs::write(dir.path().join("float.raw"), vec![0u8; 4 * 8]).unwrap();
    std::fs::write(&float, r#"{"dims": [2, 2, 2], "dtype": "f32"}"#).unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![crop, "--labels", "300", "-o", out], "300"),
        (vec![crop, "--labels", "", "-o", out], "--labels"),
        (vec![crop, "--labels", "9-3", "-o", out], "backwards"),
        (
            vec![crop, "--labels", "all", "--iso", "3", "-o", out],
            "--iso",
        ),
        (
            vec![crop, "--labels", "all", "--background", "300", "-o", out],
            "--background",
        ),
        (
            vec![
                crop,
                "--labels",
                "all",
                "--label-table",
                broken.to_str().unwrap(),
                "-o",
                out,
            ],
            "broken.txt",
        ),
        (vec![crop, "--labels", "all", "-o", "x.ply"], ".glb"),
        (
            vec![crop, "--labels", "all", "--smoothing", "5", "-o", out],
            "--smoothing",
        ),
        (
            vec![crop, "--labels", "all", "--smoothing", "nan", "-o", out],
            "--smoothing",
        ),
        (
            vec![float.to_str().unwrap(), "--labels", "all", "-o", out],
            "f32",
        ),
    ];
    let before = entries(dir.path());
    for (args, says) in cases {
        let result = run(&args);
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert!(!result.status.success(), "{args:?}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert_eq!(entries(dir.path()), before, "{args:?} left a file");
    }
}

#[test]
fn smoothing_moves_vertices_and_keeps_every_mesh_closed() {
    let dir = tempfile::tempdir().unwrap();
    let crop = crop();
    let run_to = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![
            crop.to_str().unwrap(),
            "--labels",
            "71",
            "-o",
            out.to_str().unwrap(),
            "-q",
        ];
        args.extend_from_slice(extra);
        ok(&args);
        let file = out.join(&entries(&out)[0]);
        closed(&file);
        sc_io::mesh_in::read(&file).unwrap()
    };
    let (plain, smooth) = (
        run_to("plain", &[]),
        run_to("smooth", &["--smoothing", "0.75"]),
    );
    assert_eq!(plain.triangles, smooth.triangles);
    assert_ne!(plain.positions, smooth.positions);
}
