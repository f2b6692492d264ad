//! Raw volumes with a JSON sidecar: `skelclimb` reads the layout and placement from it, the same
//! mesh as spelling them out with `--dims`, `--dtype` and `--spacing`.

mod common;
use common::fixture;

use std::path::Path;

use assert_cmd::Command;
use predicates::str::contains;

fn extract(input: &Path, extra: &[&str], out: &Path) {
    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("extract")
        .arg(input)
        .args(["--iso", "20", "-q", "-o"])
        .arg(out)
        .args(extra)
        .assert()
        .success();
}

#[test]
fn sidecar_gives_the_same_mesh_as_explicit_options() {
    let dir = tempfile::tempdir().unwrap();
    let raw = fixture("itk-t1-crop-40x40x30.i16.raw");
    let explicit = dir.path().join("explicit.ply");
    extract(
        &raw,
        &["--dims", "40,40,30", "--dtype", "i16", "--spacing", "2,2,3"],
        &explicit,
    );
    let expected = std::fs::read(&explicit).unwrap();
    for input in [raw.clone(), fixture("itk-t1-crop-40x40x30.i16.json")] {
        let out = dir.path().join("sidecar.ply");
        extract(&input, &[], &out);
        assert_eq!(
            std::fs::read(&out).unwrap(),
            expected,
            "{}",
            input.display()
        );
    }
    // The sidecar's spacing is used: without it the mesh differs.
    let unit = dir.path().join("unit.ply");
    extract(&raw, &["--dims", "40,40,30", "--dtype", "i16"], &unit);
    assert_ne!(std::fs::read(&unit).unwrap(), expected);
}

#[test]
fn info_reads_the_sidecar_and_shows_its_suggestions() {
    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("info")
        .arg(fixture("itk-t1-crop-40x40x30.i16.json"))
        .assert()
        .success()
        .stdout(contains("raw + JSON sidecar"))
        .stdout(contains("spacing   2 × 2 × 3"))
        .stdout(contains("suggests iso values: skin 20"));
}

#[test]
fn a_bad_sidecar_names_the_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("v.json");
    std::fs::write(&json, r#"{"dims": [2, 2, 2], "dtype": "complex64"}"#).unwrap();
    std::fs::write(dir.path().join("v.raw"), [0u8; 8]).unwrap();
    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("info")
        .arg(&json)
        .assert()
        .code(1)
        .stderr(contains("v.json: `dtype` must be one of"));
    std::fs::write(&json, r#"{"dims": [2, 2, 3], "dtype": "u8"}"#).unwrap();
    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("info")
        .arg(&json)
        .assert()
        .code(1)
        .stderr(contains(
            "v.raw: the file has 8 bytes, but dims 2,2,3 of u8",
        ));
}

#[test]
fn info_takes_spacing_and_origin_overrides() {
    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("info")
        .arg(fixture("itk-t1-crop-40x40x30.i16.json"))
        .args(["--spacing", "0.5,0.5,1.25", "--origin", "-3,0,7"])
        .assert()
        .success()
        .stdout(contains("spacing   0.5 × 0.5 × 1.25"))
        .stdout(contains("origin    -3, 0, 7"));
}
