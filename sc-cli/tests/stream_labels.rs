//! `extract --labels --stream`: a label volume read a few slices at a time (raw with a sidecar,
//! NIfTI plain and gzip, Zarr in chunks of 1 to 48 slices) writes byte for byte the files of a
//! whole read, a directory of meshes or an atlas .glb, with selections, a background inside the
//! volume and smoothing; the whole read's refusals hold for the stream and leave no file.

mod common;
use common::{LABEL_DIMS, aal_labels, entries, gzip, label_nifti, limited, written};

use std::path::Path;

use assert_cmd::Command;
use predicates::str::contains;

fn skelclimb() -> Command {
    Command::cargo_bin("skelclimb").unwrap()
}

/// A Zarr v2 array of the samples, uncompressed, in chunks of `chunk` whole slices.
fn zarr(dir: &Path, samples: &[u8], chunk: usize) {
    std::fs::create_dir(dir).unwrap();
    let [nx, ny, nz] = LABEL_DIMS;
    std::fs::write(
        dir.join(".zarray"),
        format!(
            r#"{{"zarr_format": 2, "shape": [{nz}, {ny}, {nx}], "chunks": [{chunk}, {ny}, {nx}],
                "dtype": "|u1", "compressor": null, "fill_value": 0, "order": "C",
                "filters": null}}"#
        ),
    )
    .unwrap();
    for (i, part) in samples.chunks(chunk * nx * ny).enumerate() {
        let mut bytes = part.to_vec();
        bytes.resize(chunk * nx * ny, 0);
        std::fs::write(dir.join(format!("{i}.0.0")), bytes).unwrap();
    }
}

/// The fixtures in `dir`: `seg.raw` with its sidecar, `seg.nii`, `seg.nii.gz`, and Zarr stores
/// `z<k>.zarr` in chunks of `k` slices.
fn fixtures(dir: &Path, chunks: &[usize]) {
    let samples = aal_labels();
    std::fs::write(dir.join("seg.raw"), &samples).unwrap();
    std::fs::write(
        dir.join("seg.json"),
        r#"{"dims": [24, 24, 48], "dtype": "u8"}"#,
    )
    .unwrap();
    std::fs::write(dir.join("seg.nii"), label_nifti(&samples, 0.0, None)).unwrap();
    std::fs::write(
        dir.join("seg.nii.gz"),
        gzip(&label_nifti(&samples, 0.0, None)),
    )
    .unwrap();
    for &k in chunks {
        zarr(&dir.join(format!("z{k}.zarr")), &samples, k);
    }
}

/// Files and counts of a run: per file written, its name (none for a single file) and bytes;
/// the atlas's counts and labels.
type Written = (Vec<(String, Vec<u8>)>, String);

/// Runs `extract input -o out` with `args` in `dir`: the files written (for a directory, every
/// file in it) and the atlas's counts and labels from `--stats-json`.
fn extract(dir: &Path, input: &str, out: &str, args: &[&str]) -> Written {
    let stats = format!("{out}.stats.json");
    skelclimb()
        .current_dir(dir)
        .args(["extract", input, "-q", "-o", out, "--stats-json", &stats])
        .args(args)
        .assert()
        .success();
    let files = written(&dir.join(out));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join(stats)).unwrap()).unwrap();
    let counts = format!(
        "{} {} {}",
        json["atlas"], json["labels"], json["per_label_triangles"]
    );
    (files, counts)
}

/// Every streamed read gives the whole read's files and counts, for each set of options: a
/// file per label (PLY, OBJ), an atlas .glb, a selection, a background that is one of the
/// regions, smoothing (whose halo is wider). Zarr stores stream without being asked, in blocks
/// that end where their chunks do; raw and NIfTI files are read in one slab here.
#[test]
fn streamed_label_volumes_write_the_whole_reads_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let chunks = [1, 5, 7];
    fixtures(d, &chunks);
    let runs: [(&str, &[&str]); 5] = [
        ("all", &["--labels", "all"]),
        ("atlas.glb", &["--labels", "all"]),
        ("some", &["--labels", "21,37-41", "--format", "obj"]),
        ("bg.glb", &["--labels", "all", "--background", "29"]),
        ("smooth", &["--labels", "21-29,73", "--smoothing", "1.2"]),
    ];
    for (out, args) in runs {
        let raw = extract(d, "seg.raw", &format!("whole-raw-{out}"), args);
        // The NIfTI file is placed by its header: its meshes are compared with its own.
        let nii = extract(d, "seg.nii", &format!("whole-nii-{out}"), args);
        assert!(raw.0.len() >= 2 || out.ends_with(".glb"), "{out}");
        assert!(raw.0.iter().all(|(_, bytes)| bytes.len() > 1000), "{out}");
        let mut streamed: Vec<(String, &[&str], &Written)> = vec![
            ("seg.raw".into(), &["--stream"], &raw),
            ("seg.nii".into(), &["--stream"], &nii),
            ("seg.nii.gz".into(), &["--stream"], &nii),
        ];
        for k in chunks {
            streamed.push((format!("z{k}.zarr"), &[], &raw));
        }
        for (input, stream, want) in streamed {
            let args: Vec<&str> = args.iter().chain(stream).copied().collect();
            let got = extract(d, &input, &format!("{input}-{out}"), &args);
            assert_eq!(got.1, want.1, "{input} {out}: counts");
            let names = |w: &Written| w.0.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
            assert_eq!(names(&got), names(want), "{input} {out}");
            for ((name, a), (_, b)) in got.0.iter().zip(&want.0) {
                assert!(a == b, "{input} {out}: {name} differs");
            }
        }
    }
}

/// What the whole read refuses, the stream refuses in the same words, naming the file or the
/// argument, and leaves no file behind: floating-point samples, a rescaled NIfTI (a scan), a
/// background the sample type cannot hold, a label no sample holds, a gzip stream cut short;
/// a format read only whole says so.
#[test]
fn the_stream_refuses_what_the_whole_read_refuses() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fixtures(d, &[]);
    let samples = aal_labels();
    let floats: Vec<u8> = samples
        .iter()
        .flat_map(|&l| f32::from(l).to_le_bytes())
        .collect();
    std::fs::write(d.join("float.raw"), floats).unwrap();
    std::fs::write(d.join("scaled.nii"), label_nifti(&samples, 2.0, None)).unwrap();
    let gz = gzip(&label_nifti(&samples, 0.0, None));
    std::fs::write(d.join("cut.nii.gz"), &gz[..gz.len() * 3 / 5]).unwrap();
    let float_args = ["--labels", "all", "--dims", "24,24,48", "--dtype", "f32"];
    let all = ["--labels", "all"];
    let cases: [(&str, &[&str], &str); 5] = [
        (
            "float.raw",
            &float_args,
            "float.raw: --labels: the volume holds f32 samples",
        ),
        (
            "scaled.nii",
            &all,
            "scaled.nii: --labels: the volume rescales its samples",
        ),
        (
            "seg.raw",
            &["--labels", "all", "--background", "300"],
            "seg.raw: --background 300 does not fit",
        ),
        (
            "seg.raw",
            &["--labels", "5"],
            "seg.raw: --labels: no sample holds 5",
        ),
        ("cut.nii.gz", &all, "cut.nii.gz: "),
    ];
    for (input, args, message) in cases {
        for out in ["out", "atlas.glb"] {
            let mut said = Vec::new();
            for stream in [false, true] {
                let before = entries(d);
                let run = skelclimb()
                    .current_dir(d)
                    .args(["extract", input, "-o", out])
                    .args(["--stats-json", "stats.json"])
                    .args(args)
                    .args(stream.then_some("--stream"))
                    .assert()
                    .code(1)
                    .stderr(contains(message));
                said.push(run.get_output().stderr.clone());
                assert_eq!(
                    entries(d),
                    before,
                    "{input} {args:?} -o {out}: a file was left"
                );
            }
            assert_eq!(said[0], said[1], "{input} {args:?}");
        }
    }
    let mut nrrd =
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 24 24 48\nencoding: raw\n\n".to_vec();
    nrrd.extend_from_slice(&samples);
    std::fs::write(d.join("seg.nrrd"), nrrd).unwrap();
    let before = entries(d);
    skelclimb()
        .current_dir(d)
        .args([
            "extract", "seg.nrrd", "--labels", "all", "--stream", "-o", "out",
        ])
        .assert()
        .code(2)
        .stderr(contains(
            "seg.nrrd: --stream reads raw files, NIfTI (.nii, .nii.gz) and Zarr",
        ));
    assert_eq!(entries(d), before);
}

/// A label volume too large for memory is refused before it is read whole, with the hint that
/// --stream would mesh it (a Zarr header claiming 10¹² slices, under a 6 GB address-space limit).
#[test]
fn a_volume_too_large_for_memory_says_stream_would_mesh_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let store = d.join("tall.zarr");
    std::fs::create_dir(&store).unwrap();
    std::fs::write(
        store.join(".zarray"),
        r#"{"zarr_format": 2, "shape": [1000000000000, 4, 4], "chunks": [4, 4, 4],
            "dtype": "|u1", "compressor": null, "fill_value": 0, "order": "C", "filters": null}"#,
    )
    .unwrap();
    let before = entries(d);
    limited(d, "extract tall.zarr --labels all -o out")
        .assert()
        .code(1)
        .stderr(contains("tall.zarr"))
        .stderr(contains("4 × 4 × 1000000000000 samples"))
        .stderr(contains("--stream meshes it a few slices at a time"));
    assert_eq!(entries(d), before);
}
