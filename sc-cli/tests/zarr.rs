//! Zarr input: v3 (zstd-compressed chunks) and v2 arrays and an OME-Zarr multiscale image give
//! exactly the mesh of the same samples as a raw file, placed by OME-Zarr's scale and
//! translation; levels are chosen with --zarr-level; bad stores fail cleanly.

mod common;
use common::{entries, fixture};

use std::path::Path;
use std::sync::Arc;

use assert_cmd::Command;
use predicates::str::contains;
use zarrs::array::codec::ZstdCodec;
use zarrs::array::{ArrayBuilder, DataType};
use zarrs::array_subset::ArraySubset;
use zarrs::filesystem::FilesystemStore;
use zarrs::group::GroupBuilder;

fn skelclimb() -> Command {
    Command::cargo_bin("skelclimb").unwrap()
}

/// The stent crop: 40 × 40 × 30 i16, x fastest (z, y, x in C order).
fn stent() -> Vec<i16> {
    std::fs::read(fixture("stent-crop-40x40x30.i16.raw"))
        .unwrap()
        .chunks_exact(2)
        .map(|c| i16::from_le_bytes([c[0], c[1]]))
        .collect()
}

/// Writes a zstd-compressed Zarr v3 array of shape `[z, y, x]` at `path` inside `store`.
fn v3_array(store: &Arc<FilesystemStore>, path: &str, shape: [u64; 3], data: &[i16]) {
    let array = ArrayBuilder::new(shape.to_vec(), vec![8, 16, 16], DataType::Int16, 0i16)
        .bytes_to_bytes_codecs(vec![Arc::new(ZstdCodec::new(3, false))])
        .build(store.clone(), path)
        .unwrap();
    array.store_metadata().unwrap();
    let all = ArraySubset::new_with_ranges(&shape.map(|n| 0..n));
    array.store_array_subset_elements(&all, data).unwrap();
}

/// The mesh bytes and the counts of `extract` with `args`.
fn mesh(dir: &Path, args: &[&str]) -> (Vec<u8>, serde_json::Value) {
    skelclimb()
        .current_dir(dir)
        .args(["extract", "-q", "-o", "m.ply", "--stats-json", "m.json"])
        .args(args)
        .assert()
        .success();
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("m.json")).unwrap()).unwrap();
    assert!(json["result"]["triangles"].as_u64().unwrap() > 1000);
    for volatile in ["seconds", "input", "format", "dtype"] {
        json[volatile] = serde_json::Value::Null;
    }
    (std::fs::read(dir.join("m.ply")).unwrap(), json)
}

#[test]
fn zarr_arrays_mesh_as_their_samples_do() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let data = stent();
    std::fs::copy(fixture("stent-crop-40x40x30.i16.raw"), d.join("s.raw")).unwrap();
    let raw = mesh(
        d,
        &[
            "s.raw", "--dims", "40,40,30", "--dtype", "i16", "--iso", "281",
        ],
    );

    // Zarr v3, zstd, chunks that do not divide the shape.
    let store = Arc::new(FilesystemStore::new(d.join("v3.zarr")).unwrap());
    v3_array(&store, "/", [30, 40, 40], &data);
    assert!(mesh(d, &["v3.zarr", "--iso", "281"]) == raw, "v3");
    assert!(
        mesh(d, &["v3.zarr", "--iso", "281", "--stream"]) == raw,
        "v3 --stream"
    );

    // Zarr v2, uncompressed, written by hand: chunks of 16 slices, the last one padded.
    let v2 = d.join("v2");
    std::fs::create_dir(&v2).unwrap();
    std::fs::write(
        v2.join(".zarray"),
        r#"{"zarr_format": 2, "shape": [30, 40, 40], "chunks": [16, 40, 40], "dtype": "<i2",
            "compressor": null, "fill_value": 0, "order": "C", "filters": null}"#,
    )
    .unwrap();
    for (i, chunk) in data.chunks(16 * 1600).enumerate() {
        let mut bytes: Vec<u8> = chunk.iter().flat_map(|v| v.to_le_bytes()).collect();
        bytes.resize(16 * 1600 * 2, 0);
        std::fs::write(v2.join(format!("{i}.0.0")), bytes).unwrap();
    }
    assert!(mesh(d, &["v2", "--iso", "281"]) == raw, "v2");
}

#[test]
fn ome_zarr_levels_are_placed_by_their_transforms() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let data = stent();
    // Level 1: every second sample along each axis.
    let half: Vec<i16> = (0..15)
        .flat_map(|z| (0..20).flat_map(move |y| (0..20).map(move |x| (x, y, z))))
        .map(|(x, y, z)| data[2 * x + 40 * (2 * y + 40 * 2 * z)])
        .collect();
    let store = Arc::new(FilesystemStore::new(d.join("img.zarr")).unwrap());
    let level = |path: &str, scale: f64| {
        serde_json::json!({ "path": path, "coordinateTransformations": [
            { "type": "scale", "scale": [1.0, 1.5 * scale, scale, scale] },
            { "type": "translation", "translation": [0.0, 10.0, 20.0, 30.0] } ] })
    };
    let attrs = serde_json::json!({ "ome": { "version": "0.5", "multiscales": [{
        "axes": [{"name": "c", "type": "channel"}, {"name": "z", "type": "space"},
                 {"name": "y", "type": "space"}, {"name": "x", "type": "space"}],
        "datasets": [level("0", 2.0), level("1", 4.0)] }] } });
    GroupBuilder::new()
        .attributes(attrs.as_object().unwrap().clone())
        .build(store.clone(), "/")
        .unwrap()
        .store_metadata()
        .unwrap();
    for (path, shape, samples) in [
        ("/0", [1, 30, 40, 40], &data),
        ("/1", [1, 15, 20, 20], &half),
    ] {
        let array = ArrayBuilder::new(shape.to_vec(), vec![1, 8, 16, 16], DataType::Int16, 0i16)
            .build(store.clone(), path)
            .unwrap();
        array.store_metadata().unwrap();
        let all = ArraySubset::new_with_ranges(&shape.map(|n| 0..n));
        array.store_array_subset_elements(&all, samples).unwrap();
    }
    let to_raw = |name: &str, v: &[i16]| {
        std::fs::write(
            d.join(name),
            v.iter().flat_map(|s| s.to_le_bytes()).collect::<Vec<u8>>(),
        )
        .unwrap()
    };
    to_raw("full.raw", &data);
    to_raw("half.raw", &half);
    let full = mesh(
        d,
        &[
            "full.raw",
            "--dims",
            "40,40,30",
            "--dtype",
            "i16",
            "--iso",
            "281",
            "--spacing",
            "2,2,3",
            "--origin",
            "30,20,10",
        ],
    );
    assert!(mesh(d, &["img.zarr", "--iso", "281"]) == full, "level 0");
    let coarse = mesh(
        d,
        &[
            "half.raw",
            "--dims",
            "20,20,15",
            "--dtype",
            "i16",
            "--iso",
            "281",
            "--spacing",
            "4,4,6",
            "--origin",
            "30,20,10",
        ],
    );
    assert!(
        mesh(d, &["img.zarr", "--iso", "281", "--zarr-level", "1"]) == coarse,
        "level 1"
    );
    skelclimb()
        .current_dir(d)
        .args(["info", "img.zarr"])
        .assert()
        .success()
        .stdout(contains("OME-Zarr"))
        .stdout(contains("40 × 40 × 30"));
    let before = entries(d);
    skelclimb()
        .current_dir(d)
        .args([
            "extract",
            "img.zarr",
            "--iso",
            "281",
            "--zarr-level",
            "2",
            "-o",
            "x.ply",
        ])
        .assert()
        .code(2)
        .stderr(contains("levels 0 to 1"));
    assert_eq!(entries(d), before);
}

#[test]
fn bad_stores_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A corrupt zstd chunk.
    let store = Arc::new(FilesystemStore::new(d.join("bad.zarr")).unwrap());
    v3_array(&store, "/", [30, 40, 40], &stent());
    let chunk = d.join("bad.zarr/c/1/0/0");
    let bytes = std::fs::read(&chunk).unwrap();
    std::fs::write(&chunk, &bytes[..bytes.len() / 2]).unwrap();
    // A 4-D array with two channels, and a group without multiscales.
    let four = Arc::new(FilesystemStore::new(d.join("four.zarr")).unwrap());
    ArrayBuilder::new(vec![2, 4, 4, 4], vec![1, 4, 4, 4], DataType::UInt8, 0u8)
        .build(four, "/")
        .unwrap()
        .store_metadata()
        .unwrap();
    let group = Arc::new(FilesystemStore::new(d.join("group.zarr")).unwrap());
    GroupBuilder::new()
        .build(group, "/")
        .unwrap()
        .store_metadata()
        .unwrap();
    for (input, message) in [
        ("bad.zarr", "bad.zarr"),
        ("four.zarr", "only 3-D volumes"),
        ("group.zarr", "multiscales"),
    ] {
        let before = entries(d);
        skelclimb()
            .current_dir(d)
            .args(["extract", input, "--iso", "281", "-o", "m.ply"])
            .assert()
            .code(1)
            .stderr(contains(message));
        assert_eq!(entries(d), before, "{input}");
    }
}
