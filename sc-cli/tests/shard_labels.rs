//! `extract --labels --shards` and `merge`: a label volume's shards, for several block sizes and
//! option sets, join into byte for byte the files `extract --labels` writes (a directory of
//! meshes or an atlas .glb, with selections, a background inside the volume, smoothing, a label
//! table, other modes, placement overrides and a rotated frame); a missing shard, shards of a
//! scan mixed with label ones, or shards made with other options are refused naming the file,
//! with exit status 1 and no file left behind.

mod common;
use common::{LABEL_DIMS, aal_labels, entries, label_nifti, written};

use std::path::Path;

use assert_cmd::Command;
use predicates::str::contains;

fn skelclimb(dir: &Path) -> Command {
    let mut cmd = Command::cargo_bin("skelclimb").unwrap();
    cmd.current_dir(dir).arg("-q");
    cmd
}

/// `seg.raw` with its sidecar, `seg.nii` placed by its header with a rotation, and an ITK-SNAP
/// table naming and colouring a few of the labels.
fn fixtures(dir: &Path) {
    let samples = aal_labels();
    std::fs::write(dir.join("seg.raw"), &samples).unwrap();
    let [nx, ny, nz] = LABEL_DIMS;
    std::fs::write(
        dir.join("seg.json"),
        format!(r#"{{"dims": [{nx}, {ny}, {nz}], "dtype": "u8"}}"#),
    )
    .unwrap();
    // A quarter turn about z, anisotropic voxels, shifted.
    let rotated = [
        [0.0, -1.5, 0.0, 10.0],
        [0.8, 0.0, 0.0, -20.0],
        [0.0, 0.0, 2.0, 5.0],
    ];
    std::fs::write(
        dir.join("seg.nii"),
        label_nifti(&samples, 0.0, Some(rotated)),
    )
    .unwrap();
    std::fs::write(
        dir.join("names.txt"),
        "21 250 10 10 1 1 1 \"Olfactory L\"\n37 10 250 10 1 1 1 \"Hippocampus L\"\n\
         73 10 10 250 1 1 1 \"Putamen L\"\n",
    )
    .unwrap();
}

/// The atlas's counts and the labels meshed, from a `--stats-json` report.
fn counts(path: &Path) -> String {
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    format!(
        "{} {} {}",
        json["atlas"], json["labels"], json["per_label_triangles"]
    )
}

/// Every option set, through shards of several block sizes (one block included), gives the
/// whole extraction's files and counts.
#[test]
fn label_shards_merge_into_the_whole_extracts_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fixtures(d);
    // (input, -o, options of extract, options of merge)
    let runs: [(&str, &str, &[&str], &[&str]); 8] = [
        ("seg.raw", "all", &["--labels", "all"], &[]),
        ("seg.raw", "atlas.glb", &["--labels", "all"], &[]),
        (
            "seg.raw",
            "some",
            &["--labels", "21,37-41", "--format", "obj"],
            &["--format", "obj"],
        ),
        (
            "seg.raw",
            "bg.glb",
            &["--labels", "all", "--background", "29"],
            &[],
        ),
        (
            "seg.raw",
            "smooth",
            &["--labels", "21-29,73", "--smoothing", "1.2"],
            &[],
        ),
        (
            "seg.raw",
            "named.glb",
            &[
                "--labels",
                "all",
                "--label-table",
                "names.txt",
                "--mode",
                "paper",
            ],
            &[],
        ),
        (
            "seg.raw",
            "placed",
            &[
                "--labels",
                "21-41",
                "--label-table",
                "names.txt",
                "--spacing",
                "0.5,1,2",
                "--origin",
                "-3,4,7.5",
                "--no-normals",
                "--mode",
                "steps123",
            ],
            &["--ascii"],
        ),
        (
            "seg.nii",
            "rotated.glb",
            &["--labels", "all", "--space", "lps"],
            &[],
        ),
    ];
    for (input, out, args, merge_args) in runs {
        let whole = format!("whole-{out}");
        let ascii = merge_args.contains(&"--ascii");
        skelclimb(d)
            .args(["extract", input, "-o", &whole, "--stats-json", "whole.json"])
            .args(args)
            .args(ascii.then_some("--ascii"))
            .assert()
            .success();
        let want = written(&d.join(&whole));
        assert!(want.len() >= 2 || out.ends_with(".glb"), "{out}");
        assert!(want.iter().all(|(_, b)| b.len() > 1000), "{out}");
        for block in ["7", "16", "64"] {
            let parts = format!("parts-{out}-{block}");
            skelclimb(d)
                .args(["extract", input, "--shards", &parts, "--block", block])
                .args(args)
                .assert()
                .success();
            let joined = format!("joined-{block}-{out}");
            skelclimb(d)
                .args(["merge", &format!("{parts}/manifest.json"), "-o", &joined])
                .args(["--stats-json", "joined.json"])
                .args(merge_args)
                .assert()
                .success();
            let got = written(&d.join(&joined));
            let names =
                |f: &[(String, Vec<u8>)]| f.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
            assert_eq!(names(&got), names(&want), "{out} block {block}");
            for ((name, a), (_, b)) in got.iter().zip(&want) {
                assert!(a == b, "{out} block {block}: {name} differs");
            }
            assert_eq!(
                counts(&d.join("joined.json")),
                counts(&d.join("whole.json")),
                "{out} block {block}"
            );
        }
    }
    // The table's names reach the file names (and its colours the files, compared above).
    assert!(entries(&d.join("whole-placed")).contains(&"37-Hippocampus_L.ply".to_string()));
}

/// Runs `merge` of `manifest` into `out` and checks that it fails with status `code` saying
/// `message`, leaving `dir` as it was.
fn refused(dir: &Path, manifest: &str, out: &str, extra: &[&str], code: i32, message: &str) {
    let before = entries(dir);
    skelclimb(dir)
        .args(["merge", manifest, "-o", out, "--stats-json", "stats.json"])
        .args(extra)
        .assert()
        .code(code)
        .stderr(contains(message));
    assert_eq!(
        entries(dir),
        before,
        "merge {manifest} -o {out}: a file was left"
    );
}

/// A missing shard, a scan's shard where a label shard is listed (and the reverse), a shard made
/// with other options, a damaged shard, and outputs that do not fit the shards are refused,
/// naming the file or the argument, and leave no file.
#[test]
fn merge_refuses_missing_foreign_and_mismatched_shards() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fixtures(d);
    let shards = |parts: &str, extra: &[&str]| {
        skelclimb(d)
            .args([
                "extract", "seg.raw", "--labels", "all", "--shards", parts, "--block", "16",
            ])
            .args(extra)
            .assert()
            .success();
    };
    shards("a", &[]);
    shards("b", &[]);
    shards("smooth", &["--smoothing", "1"]);
    // The scan's grid has 24 × 24 × 48 samples too, so that only the kind tells them apart.
    skelclimb(d)
        .args([
            "extract", "seg.raw", "--iso", "30", "--shards", "scan", "--block", "16",
        ])
        .assert()
        .success();
    let first = "block-0-0-0.npz";
    assert!(d.join("a").join(first).is_file() && d.join("scan").join(first).is_file());

    for out in ["out", "atlas.glb"] {
        // A shard from the same run's twin is fine: the merge reads it as its own.
        std::fs::copy(d.join("b").join(first), d.join("a").join(first)).unwrap();
        skelclimb(d)
            .args(["merge", "a/manifest.json", "-o", &format!("ok-{out}")])
            .assert()
            .success();

        std::fs::rename(d.join("b").join(first), d.join("b/kept.npz")).unwrap();
        refused(d, "b/manifest.json", out, &[], 1, &format!("b/{first}"));
        std::fs::rename(d.join("b/kept.npz"), d.join("b").join(first)).unwrap();

        std::fs::copy(d.join("scan").join(first), d.join("a").join(first)).unwrap();
        refused(
            d,
            "a/manifest.json",
            out,
            &[],
            1,
            &format!("a/{first}: a shard of surface"),
        );

        std::fs::copy(d.join("smooth").join(first), d.join("a").join(first)).unwrap();
        refused(
            d,
            "a/manifest.json",
            out,
            &[],
            1,
            "made with other settings",
        );
        refused(d, "a/manifest.json", out, &[], 1, &format!("a/{first}"));
        std::fs::copy(d.join("b").join(first), d.join("a").join(first)).unwrap();
    }
    // A flipped bit in a label shard: the zip's CRC-32 catches it.
    let path = d.join("b").join(first);
    let good = std::fs::read(&path).unwrap();
    let mut bad = good.clone();
    let middle = bad.len() / 2;
    bad[middle] ^= 0x40;
    std::fs::write(&path, &bad).unwrap();
    let message = format!("b/{first}: not a readable shard");
    refused(d, "b/manifest.json", "atlas.glb", &[], 1, &message);
    std::fs::write(&path, &good).unwrap();
    // A label shard where a scan's manifest lists one.
    std::fs::copy(d.join("b").join(first), d.join("scan").join(first)).unwrap();
    refused(
        d,
        "scan/manifest.json",
        "m.ply",
        &[],
        1,
        &format!("scan/{first}: a shard of labels"),
    );
    // Outputs that do not fit the kind of shards, refused before any is read.
    refused(d, "b/manifest.json", "m.ply", &[], 2, "give a .glb file");
    refused(d, "scan/manifest.json", "out", &[], 2, "-o out:");
    refused(
        d,
        "scan/manifest.json",
        "m.ply",
        &["--format", "obj"],
        2,
        "--format applies",
    );
    refused(
        d,
        "b/manifest.json",
        "m.glb",
        &["--ascii"],
        2,
        "--ascii applies",
    );
}

/// A manifest that names no kind, as those written before label shards, is a scan's, and still
/// merges; an unknown kind is refused by name.
#[test]
fn manifests_without_a_kind_are_a_scans() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let knot = ["extract", "--demo", "knot", "--size", "20"];
    skelclimb(d)
        .args(knot)
        .args(["-o", "whole.ply"])
        .assert()
        .success();
    skelclimb(d)
        .args(knot)
        .args(["--shards", "parts", "--block", "8"])
        .assert()
        .success();
    let path = d.join("parts/manifest.json");
    let mut manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(manifest["kind"], "surface");
    manifest.as_object_mut().unwrap().remove("kind");
    std::fs::write(&path, serde_json::to_vec(&manifest).unwrap()).unwrap();
    skelclimb(d)
        .args(["merge", "parts/manifest.json", "-o", "joined.ply"])
        .assert()
        .success();
    assert!(
        std::fs::read(d.join("whole.ply")).unwrap() == std::fs::read(d.join("joined.ply")).unwrap()
    );
    manifest["kind"] = "volumes".into();
    std::fs::write(&path, serde_json::to_vec(&manifest).unwrap()).unwrap();
    refused(
        d,
        "parts/manifest.json",
        "m.ply",
        &[],
        1,
        "a manifest of volumes shards",
    );
}

/// What the whole extraction refuses, the shards' refuse in the same words before any shard is
/// written: a label no sample holds, a background the sample type cannot hold, floating-point
/// samples; and --labels --shards takes no -o.
#[test]
fn extract_refuses_before_writing_any_shard() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fixtures(d);
    let floats: Vec<u8> = aal_labels()
        .iter()
        .flat_map(|&l| f32::from(l).to_le_bytes())
        .collect();
    std::fs::write(d.join("float.raw"), floats).unwrap();
    let float = ["--labels", "all", "--dims", "24,24,48", "--dtype", "f32"];
    let cases: [(&str, &[&str], &str); 3] = [
        (
            "seg.raw",
            &["--labels", "5,21"],
            "seg.raw: --labels: no sample holds 5 (present: ",
        ),
        (
            "seg.raw",
            &["--labels", "all", "--background", "300"],
            "seg.raw: --background 300 does not fit",
        ),
        (
            "float.raw",
            &float,
            "float.raw: --labels: the volume holds f32 samples",
        ),
    ];
    for (input, args, message) in cases {
        let before = entries(d);
        let whole = skelclimb(d)
            .args(["extract", input, "-o", "out"])
            .args(args)
            .assert()
            .code(1)
            .stderr(contains(message));
        let sharded = skelclimb(d)
            .args(["extract", input, "--shards", "parts"])
            .args(args)
            .assert()
            .code(1)
            .stderr(contains(message));
        assert_eq!(
            whole.get_output().stderr,
            sharded.get_output().stderr,
            "{input} {args:?}"
        );
        assert_eq!(entries(d), before, "{input} {args:?}: a file was left");
    }
    skelclimb(d)
        .args([
            "extract", "seg.raw", "--labels", "all", "--shards", "p", "-o", "x.glb",
        ])
        .assert()
        .code(2)
        .stderr(contains("cannot be used with"));
}
