//! `--stream`: raw files (with options or a sidecar) and NIfTI (plain and gzip) read a few
//! slices at a time (a block of them in adaptive mode) give byte for byte the mesh and counts
//! of a whole read, in every mode; a truncated file fails cleanly; formats that cannot stream
//! say so.

mod common;
use common::{entries, fixture, gzip, nifti};

use std::path::Path;

use assert_cmd::Command;
use predicates::str::contains;

fn skelclimb() -> Command {
    Command::cargo_bin("skelclimb").unwrap()
}

/// The three modes a slice at a time.
const MODES: &[&[&str]] = &[
    &["--mode", "embedded"],
    &["--mode", "paper"],
    &["--mode", "steps123"],
];

/// Adaptive mode, a block of slices at a time: one block with boxes of 16 on these volumes,
/// several with boxes of 2.
const ADAPTIVE: &[&[&str]] = &[
    &["--mode", "adaptive"],
    &["--mode", "adaptive", "--max-box", "2", "--max-error", "1"],
];

/// Runs `extract` on `input` with `args` in each of `modes`, with and without `--stream`, and
/// checks that the mesh bytes and the counts agree.
fn same_either_way(dir: &Path, input: &str, args: &[&str], modes: &[&[&str]]) {
    for (m, mode) in modes.iter().enumerate() {
        let mut outputs = vec![];
        for stream in [false, true] {
            let out = format!("{m}-{stream}.ply");
            let stats = format!("{m}-{stream}.json");
            let mut cmd = skelclimb();
            cmd.current_dir(dir)
                .args(["extract", input, "-q", "-o", &out])
                .args(*mode)
                .args(["--stats-json", &stats])
                .args(args);
            if stream {
                cmd.arg("--stream");
            }
            let run = cmd.assert().success();
            let stderr = String::from_utf8_lossy(&run.get_output().stderr).into_owned();
            let mut json: serde_json::Value =
                serde_json::from_slice(&std::fs::read(dir.join(&stats)).unwrap()).unwrap();
            json["seconds"] = serde_json::Value::Null;
            // Measured on the whole volume only, as the streamed run warns.
            let measured = json.as_object_mut().unwrap().remove("distance_to_steps123");
            let adaptive = mode.contains(&"adaptive");
            assert_eq!(measured.is_some(), adaptive && !stream, "{input} {mode:?}");
            if adaptive && stream {
                assert!(stderr.contains("distance_to_steps123 is not measured"));
            }
            // The whole volume's is measured where its border is empty, as a whole run warns.
            let wrong = json.as_object_mut().unwrap().remove("wrong_side_samples");
            let why = if stream {
                "wrong_side_samples is not measured on a streamed volume"
            } else {
                "wrong_side_samples is not measured: samples on the volume's border are filled"
            };
            assert_eq!(wrong.is_none(), stderr.contains(why), "{input} {mode:?}");
            assert!(!stream || wrong.is_none(), "{input} {mode:?}");
            outputs.push((std::fs::read(dir.join(&out)).unwrap(), json));
        }
        assert!(
            outputs[0].1["result"]["triangles"].as_u64().unwrap() > 1000,
            "{input}"
        );
        assert_eq!(outputs[0].1, outputs[1].1, "{input} {mode:?}: counts");
        assert!(
            outputs[0].0 == outputs[1].0,
            "{input} {mode:?}: mesh bytes differ"
        );
    }
}

#[test]
fn streamed_volumes_mesh_exactly_as_whole_ones() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::copy(fixture("brainsmall-crop-40x40x30.u8.raw"), d.join("b.raw")).unwrap();
    let args = ["--dims", "40,40,30", "--dtype", "u8", "--iso", "20"];
    same_either_way(d, "b.raw", &args, MODES);
    same_either_way(d, "b.raw", &args, ADAPTIVE);
    // i16 big-endian behind a 100-byte header, with spacing and origin.
    let stent = std::fs::read(fixture("stent-crop-40x40x30.i16.raw")).unwrap();
    let mut be = vec![7u8; 100];
    be.extend(stent.chunks_exact(2).flat_map(|c| [c[1], c[0]]));
    std::fs::write(d.join("s.raw"), &be).unwrap();
    same_either_way(
        d,
        "s.raw",
        &[
            "--dims",
            "40,40,30",
            "--dtype",
            "i16",
            "--endian",
            "big",
            "--header-bytes",
            "100",
            "--iso",
            "281",
            "--spacing",
            "0.7,0.7,1.25",
            "--origin",
            "-5,3,10",
        ],
        MODES,
    );
    // f32 through a JSON sidecar.
    let f32s: Vec<u8> = stent
        .chunks_exact(2)
        .flat_map(|c| (f32::from(i16::from_le_bytes([c[0], c[1]])) * 0.5).to_le_bytes())
        .collect();
    std::fs::write(d.join("f.raw"), &f32s).unwrap();
    std::fs::write(
        d.join("f.json"),
        r#"{"dims": [40, 40, 30], "dtype": "f32", "spacing": [1, 1, 2]}"#,
    )
    .unwrap();
    same_either_way(d, "f.raw", &["--iso", "140.25"], MODES);
    // NIfTI: gzip and plain, placed in RAS by its header.
    std::fs::copy(fixture("itk-t1-mri.nii.gz"), d.join("t1.nii.gz")).unwrap();
    same_either_way(d, "t1.nii.gz", &["--iso", "20.5"], MODES);
    std::fs::write(d.join("t1.nii"), nifti()).unwrap();
    let args = ["--iso", "20.5", "--space", "lps"];
    same_either_way(d, "t1.nii", &args, MODES);
    same_either_way(d, "t1.nii", &args, &ADAPTIVE[1..]);
}

#[test]
fn streaming_failures_are_clean() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A NIfTI cut short inside its samples, and a gzip one with a corrupt tail.
    let nii = nifti();
    std::fs::write(d.join("short.nii"), &nii[..nii.len() - 5000]).unwrap();
    let mut gz = gzip(&nii);
    let n = gz.len();
    gz[n - 6] ^= 0xFF; // the CRC
    std::fs::write(d.join("crc.nii.gz"), &gz).unwrap();
    for (input, message) in [("short.nii", "short.nii"), ("crc.nii.gz", "crc.nii.gz")] {
        let before = entries(d);
        skelclimb()
            .current_dir(d)
            .args(["extract", input, "--iso", "20.5", "--stream", "-o", "m.ply"])
            .assert()
            .code(1)
            .stderr(contains(message));
        assert_eq!(entries(d), before, "{input} left files behind");
    }
    // Formats read whole say so; --pad needs the whole volume.
    std::fs::copy(fixture("stent-ct.npz"), d.join("s.npz")).unwrap();
    skelclimb()
        .current_dir(d)
        .args([
            "extract", "s.npz", "--iso", "281", "--stream", "-o", "m.ply",
        ])
        .assert()
        .code(2)
        .stderr(contains("read whole"));
    skelclimb()
        .current_dir(d)
        .args([
            "extract", "s.npz", "--iso", "281", "--stream", "--pad", "-o", "m.ply",
        ])
        .assert()
        .code(2);
    assert!(!d.join("m.ply").exists());
}
