//! Zarr input: v3 (zstd-compressed chunks) and v2 arrays and an OME-Zarr multiscale image give
//! exactly the mesh of the same samples as a raw file, placed by OME-Zarr's scale and
//! translation; levels are chosen with --zarr-level; bad stores fail cleanly.

mod common;
use common::{entries, fixture, limited};

use std::path::Path;
use std::sync::Arc;

use assert_cmd::Command;
use predicates::prelude::{PredicateBooleanExt, PredicateBoxExt};
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

/// Writes the stent as a Zarr v2 array at `dir`, uncompressed, written by hand: chunks of 16
/// slices, the last one padded; only the first `files` chunks get a file.
fn stent_v2(dir: &Path, files: usize) {
    std::fs::create_dir(dir).unwrap();
    std::fs::write(
        dir.join(".zarray"),
        r#"{"zarr_format": 2, "shape": [30, 40, 40], "chunks": [16, 40, 40], "dtype": "<i2",
            "compressor": null, "fill_value": 0, "order": "C", "filters": null}"#,
    )
    .unwrap();
    for (i, chunk) in stent().chunks(16 * 1600).enumerate().take(files) {
        let mut bytes: Vec<u8> = chunk.iter().flat_map(|v| v.to_le_bytes()).collect();
        bytes.resize(16 * 1600 * 2, 0);
        std::fs::write(dir.join(format!("{i}.0.0")), bytes).unwrap();
    }
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

    stent_v2(&d.join("v2"), 2);
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

/// Writes a v2 store at `dir` with `.zarray` metadata of `shape` and `chunks` (u8 samples, no
/// compressor, fill value 0, `extra` more fields) and one chunk file `0.0.0` of `chunk_bytes`.
fn v2_store(dir: &Path, shape: &str, chunks: &str, extra: &str, chunk_bytes: usize) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join(".zarray"),
        format!(
            r#"{{"zarr_format": 2, "shape": {shape}, "chunks": {chunks}, "dtype": "|u1",
                "compressor": null, "fill_value": 0, "order": "C", "filters": null{extra}}}"#
        ),
    )
    .unwrap();
    std::fs::write(dir.join("0.0.0"), vec![200u8; chunk_bytes]).unwrap();
}

/// Headers that claim far more samples than the store holds (10⁶ on each axis, 10¹² or 2⁶³
/// slices, 2⁶³ samples a row, a chunk of 10⁶ cubed) are refused before anything is allocated by
/// them, by `extract` (streamed by default, or with --stream), `info` and a whole read: exit 1,
/// a message naming the store and the size, and no file left beside the output.
#[test]
fn lying_headers_are_refused_before_any_allocation() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let c = "[4, 4, 4]";
    v2_store(
        &d.join("cube.zarr"),
        "[1000000, 1000000, 1000000]",
        c,
        "",
        64,
    );
    v2_store(&d.join("tall.zarr"), "[1000000000000, 4, 4]", c, "", 64);
    v2_store(
        &d.join("deep.zarr"),
        "[9223372036854775808, 4, 4]",
        c,
        "",
        64,
    );
    v2_store(
        &d.join("wide.zarr"),
        "[4, 4, 9223372036854775807]",
        c,
        "",
        64,
    );
    v2_store(
        &d.join("chunk.zarr"),
        "[4, 4, 4]",
        "[1000000, 1000000, 1000000]",
        "",
        64,
    );
    let v3 = d.join("v3.zarr");
    std::fs::create_dir(&v3).unwrap();
    std::fs::write(
        v3.join("zarr.json"),
        r#"{"zarr_format": 3, "node_type": "array", "shape": [1000000, 1000000, 1000000],
            "data_type": "uint8", "chunk_grid": {"name": "regular", "configuration":
            {"chunk_shape": [4, 4, 4]}}, "chunk_key_encoding": {"name": "default"},
            "fill_value": 0, "codecs": [{"name": "bytes"}]}"#,
    )
    .unwrap();
    // The store, a flag, the size named, and whether the slabs would fit (then, without
    // --stream, the message says that --stream would mesh it).
    let cases = [
        ("cube.zarr", "", "1000000 × 1000000 samples", false),
        ("cube.zarr", "--stream", "1000000 × 1000000 samples", false),
        ("v3.zarr", "", "1000000 × 1000000 samples", false),
        (
            "tall.zarr",
            "",
            "4 × 4 × 1000000000000 samples would need 16.0 TB",
            true,
        ),
        ("deep.zarr", "", "4 × 4 × 9223372036854775808 samples", true),
        ("wide.zarr", "", "9223372036854775807 × 4 samples", false),
        (
            "wide.zarr",
            "--stream",
            "9223372036854775807 × 4 samples",
            false,
        ),
        (
            "chunk.zarr",
            "",
            "a chunk of shape [1000000, 1000000, 1000000]",
            false,
        ),
    ];
    for (store, flag, size, slabs_fit) in cases {
        let before = entries(d);
        let hint = contains("--stream meshes it a few slices at a time");
        limited(d, &format!("extract {store} --iso 100 -o m.ply {flag}"))
            .assert()
            .code(1)
            .stderr(contains(store))
            .stderr(contains(size))
            .stderr(contains("more than the"))
            .stderr(if slabs_fit {
                hint.boxed()
            } else {
                hint.not().boxed()
            });
        assert_eq!(entries(d), before, "{store} {flag}: a file was left behind");
        limited(d, &format!("info {store}"))
            .assert()
            .code(1)
            .stderr(contains(store))
            .stderr(contains(size));
    }
}

/// Makes a FIFO at `path` (opening it for reading would wait for a writer forever).
fn fifo(path: &Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap();
    assert!(status.success());
}

/// A chunk file or a metadata file that is a FIFO is refused, naming it, instead of hanging
/// `extract` and `info`.
#[test]
fn special_files_in_a_store_are_refused_not_opened() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let chunk = d.join("chunk.zarr");
    v2_store(&chunk, "[8, 4, 4]", "[4, 4, 4]", "", 64);
    fifo(&chunk.join("1.0.0"));
    let meta = d.join("meta.zarr");
    std::fs::create_dir(&meta).unwrap();
    fifo(&meta.join(".zarray"));
    for (store, file) in [("chunk.zarr", "1.0.0"), ("meta.zarr", ".zarray")] {
        for args in [
            format!("extract {store} --iso 100 -o m.ply"),
            format!("info {store}"),
        ] {
            let before = entries(d);
            limited(d, &args)
                .assert()
                .code(1)
                .stderr(contains(format!("{store}/{file}")))
                .stderr(contains("not a regular file"));
            assert_eq!(entries(d), before, "{args}");
        }
    }
}

/// Missing chunks read as the fill value, and the user is told how many: the mesh is exactly
/// that of the samples with the missing chunk's slices set to the fill value, with a warning on
/// stderr, and `info` says so too.
#[test]
fn missing_chunks_are_counted_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut data = stent();
    // Only the first chunk (slices 0 to 15) has a file.
    let v2 = d.join("half.zarr");
    stent_v2(&v2, 1);
    data[16 * 1600..].fill(0);
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(d.join("s.raw"), bytes).unwrap();
    let raw = mesh(
        d,
        &[
            "s.raw", "--dims", "40,40,30", "--dtype", "i16", "--iso", "281",
        ],
    );
    let warning = "1 of its 2 chunks have no file (such as 1.0.0) and were read as the fill value";
    for flag in [None, Some("--stream"), Some("--pad")] {
        skelclimb()
            .current_dir(d)
            .args(["extract", "half.zarr", "--iso", "281", "-o", "m.ply"])
            .args(["--stats-json", "m.json"])
            .args(flag)
            .assert()
            .success()
            .stderr(contains(format!(
                "skelclimb: warning: half.zarr: {warning}"
            )));
        if flag.is_none() {
            let mut json: serde_json::Value =
                serde_json::from_slice(&std::fs::read(d.join("m.json")).unwrap()).unwrap();
            for volatile in ["seconds", "input", "format", "dtype"] {
                json[volatile] = serde_json::Value::Null;
            }
            assert!((std::fs::read(d.join("m.ply")).unwrap(), json) == raw);
        }
    }
    skelclimb()
        .current_dir(d)
        .args(["extract", "half.zarr", "--iso", "281", "--shards", "parts"])
        .assert()
        .success()
        .stderr(contains(format!(
            "skelclimb: warning: half.zarr: {warning}"
        )));
    skelclimb()
        .current_dir(d)
        .args(["info", "half.zarr"])
        .assert()
        .success()
        .stdout(contains(format!("  warning   half.zarr: {warning}")));
    // A store with every chunk present says nothing.
    std::fs::write(v2.join("1.0.0"), vec![0u8; 16 * 1600 * 2]).unwrap();
    skelclimb()
        .current_dir(d)
        .args(["extract", "half.zarr", "--iso", "281", "-o", "m.ply"])
        .assert()
        .success()
        .stderr(contains("warning").not());
}

/// A store whose chunk files separate their indices otherwise than its metadata says reads as
/// nothing but fill value: it is refused, naming both separators, for v2 (`dimension_separator`)
/// and v3 (`chunk_key_encoding`) alike, rather than meshed as empty.
#[test]
fn a_store_with_the_wrong_separator_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dotted = d.join("dotted.zarr");
    v2_store(
        &dotted,
        "[8, 4, 4]",
        "[4, 4, 4]",
        r#", "dimension_separator": "/""#,
        64,
    );
    let nested = d.join("nested.zarr");
    v2_store(&nested, "[8, 4, 4]", "[4, 4, 4]", "", 64);
    std::fs::remove_file(nested.join("0.0.0")).unwrap();
    std::fs::create_dir_all(nested.join("0/0")).unwrap();
    std::fs::write(nested.join("0/0/0"), [200u8; 64]).unwrap();
    // v3 with "." as its separator, and its chunk written under "/".
    let v3 = d.join("v3.zarr");
    std::fs::create_dir_all(v3.join("c/0/0")).unwrap();
    std::fs::write(
        v3.join("zarr.json"),
        r#"{"zarr_format": 3, "node_type": "array", "shape": [4, 4, 4], "data_type": "uint8",
            "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [4, 4, 4]}},
            "chunk_key_encoding": {"name": "default", "configuration": {"separator": "."}},
            "fill_value": 0, "codecs": [{"name": "bytes"}]}"#,
    )
    .unwrap();
    std::fs::write(v3.join("c/0/0/0"), [200u8; 64]).unwrap();
    for (store, message) in [
        (
            "dotted.zarr",
            r#"0.0.0 exists: the chunk files separate their indices with ".", not the "/""#,
        ),
        (
            "nested.zarr",
            r#"0/0/0 exists: the chunk files separate their indices with "/", not the ".""#,
        ),
        (
            "v3.zarr",
            r#"c/0/0/0 exists: the chunk files separate their indices with "/", not the ".""#,
        ),
    ] {
        for args in [
            vec!["extract", store, "--iso", "100", "-o", "m.ply"],
            vec!["info", store],
        ] {
            let before = entries(d);
            skelclimb()
                .current_dir(d)
                .args(&args)
                .assert()
                .code(1)
                .stderr(contains(store))
                .stderr(contains(message));
            assert_eq!(entries(d), before, "{args:?}");
        }
    }
    // With the separator put right, the same files mesh.
    std::fs::write(
        dotted.join(".zarray"),
        std::fs::read_to_string(dotted.join(".zarray"))
            .unwrap()
            .replace(r#", "dimension_separator": "/""#, ""),
    )
    .unwrap();
    skelclimb()
        .current_dir(d)
        .args(["extract", "dotted.zarr", "--iso", "100", "-o", "m.ply"])
        .assert()
        .success()
        .stderr(contains("1 of its 2 chunks have no file"));
}

/// An OME-Zarr transformation that is not one number per axis is refused, naming the field,
/// rather than ignored (which placed the mesh at unit spacing without a word).
#[test]
fn ome_transforms_must_be_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for (name, scale, message) in [
        (
            "word.zarr",
            serde_json::json!(["a", 1.0, 1.0]),
            r#"its `scale` transformation is ["a",1.0,1.0], not a list of 3 numbers"#,
        ),
        (
            "short.zarr",
            serde_json::json!([1.0, 1.0]),
            "its `scale` transformation is [1.0,1.0], not a list of 3 numbers",
        ),
        (
            "none.zarr",
            serde_json::json!("x"),
            r#"its `scale` transformation is "x""#,
        ),
    ] {
        let store = Arc::new(FilesystemStore::new(d.join(name)).unwrap());
        let attrs = serde_json::json!({ "multiscales": [{ "datasets": [{ "path": "0",
            "coordinateTransformations": [{ "type": "scale", "scale": scale }] }] }] });
        GroupBuilder::new()
            .attributes(attrs.as_object().unwrap().clone())
            .build(store.clone(), "/")
            .unwrap()
            .store_metadata()
            .unwrap();
        v3_array(&store, "/0", [30, 40, 40], &stent());
        skelclimb()
            .current_dir(d)
            .args(["info", name])
            .assert()
            .code(1)
            .stderr(contains(name))
            .stderr(contains("OME-Zarr dataset 0 (0)"))
            .stderr(contains(message));
    }
}
