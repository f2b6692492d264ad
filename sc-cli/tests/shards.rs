//! `extract --shards` and `merge`: shards of any block split join into byte for byte the mesh
//! one `extract` writes, in every mode and format; a missing, damaged, foreign, duplicated or
//! absent shard is an error naming the file, with no output left behind.

mod common;
use common::{entries, fixture};

use std::ops::Range;
use std::path::Path;

use assert_cmd::Command;
use predicates::str::contains;
use sc_io::shard::{MANIFEST_NAME, Manifest, ShardEntry, write_shard};
use sc_runtime::{Mode, Params, Volume, block_samples, extract_block};

fn skelclimb(dir: &Path) -> Command {
    let mut cmd = Command::cargo_bin("skelclimb").unwrap();
    cmd.current_dir(dir).arg("-q");
    cmd
}

fn read(dir: &Path, name: &str) -> Vec<u8> {
    std::fs::read(dir.join(name)).unwrap()
}

/// The knot's mesh, whole and through shards of `block`³ cubes, in every mode, with and without
/// normals and with a bound: the same bytes and the same counts.
#[test]
fn knot_shards_merge_into_the_whole_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: [(&str, &[&str], &str); 7] = [
        ("embedded", &[], "7"),
        ("paper", &[], "13"),
        ("steps123", &[], "5"),
        ("embedded", &["--no-normals"], "3"),
        ("embedded", &["--max-error", "0.1"], "16"),
        ("adaptive", &["--max-box", "4"], "13"),
        ("adaptive", &["--allow-wrong-side", "--pad"], "20"),
    ];
    for (mode, extra, block) in cases {
        let knot = ["extract", "--demo", "knot", "--size", "34", "--mode", mode];
        skelclimb(d)
            .args(knot)
            .args(extra)
            .args(["-o", "whole.ply", "--stats-json", "whole.json"])
            .assert()
            .success();
        let _ = std::fs::remove_dir_all(d.join("parts"));
        skelclimb(d)
            .args(knot)
            .args(extra)
            .args(["--shards", "parts", "--block", block])
            .assert()
            .success();
        skelclimb(d)
            .args(["merge", "parts/manifest.json", "-o", "joined.ply"])
            .args(["--stats-json", "joined.json"])
            .assert()
            .success();
        let whole = read(d, "whole.ply");
        assert!(whole.len() > 10_000, "{mode} {extra:?}");
        assert!(
            whole == read(d, "joined.ply"),
            "{mode} {extra:?} block {block}: the mesh bytes differ"
        );
        let json = |name| -> serde_json::Value { serde_json::from_slice(&read(d, name)).unwrap() };
        let (w, j) = (json("whole.json"), json("joined.json"));
        for key in [
            "mode",
            "steps123",
            "result",
            "merged",
            "blocked",
            "bounded",
            "max_error",
        ] {
            assert_eq!(w[key], j[key], "{mode} {extra:?}: {key}");
        }
    }
}

/// Every mesh format `merge` writes is the one `extract` writes.
#[test]
fn every_format_merges_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let knot = ["extract", "--demo", "knot", "--size", "24"];
    skelclimb(d)
        .args(knot)
        .args(["--shards", "parts", "--block", "6"])
        .assert()
        .success();
    for out in ["m.obj", "m.stl", "m.glb", "m.ply"] {
        skelclimb(d).args(knot).args(["-o", out]).assert().success();
        let whole = read(d, out);
        skelclimb(d)
            .args(["merge", "parts/manifest.json", "-o", out])
            .assert()
            .success();
        assert!(whole == read(d, out), "{out}");
    }
    skelclimb(d)
        .args(knot)
        .args(["-o", "a.ply", "--ascii"])
        .assert()
        .success();
    skelclimb(d)
        .args(["merge", "parts/manifest.json", "-o", "b.ply", "--ascii"])
        .assert()
        .success();
    assert!(read(d, "a.ply") == read(d, "b.ply"), "text PLY");
}

/// A scan with a rotated frame: the manifest records the placement and `merge` applies it.
#[test]
fn a_rotated_scan_is_placed_as_extract_places_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = fixture("itk-t1-mri.nii.gz");
    let input = input.to_str().unwrap();
    let args = ["extract", input, "--iso", "47.5"];
    skelclimb(d)
        .args(args)
        .args(["-o", "whole.ply"])
        .assert()
        .success();
    skelclimb(d)
        .args(args)
        .args(["--shards", "parts", "--block", "50"])
        .assert()
        .success();
    skelclimb(d)
        .args(["merge", "parts/manifest.json", "-o", "joined.ply"])
        .assert()
        .success();
    let whole = read(d, "whole.ply");
    assert!(whole.len() > 10_000);
    assert!(whole == read(d, "joined.ply"));
}

/// A small deterministic generator, for reproducible random splits.
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 33) % n as u64) as usize
    }
}

/// Cuts `0..cubes` into pieces of 1 to 12 cubes, so that blocks one, two and three cubes wide
/// (and cuts through merged pairs) come up.
fn cuts(rng: &mut Lcg, cubes: usize) -> Vec<Range<usize>> {
    let mut out = vec![];
    let mut at = 0;
    while at < cubes {
        let width = match rng.below(3) {
            0 => 1 + rng.below(3),
            _ => 1 + rng.below(12),
        };
        out.push(at..(at + width).min(cubes));
        at += width;
    }
    out
}

/// Writes shards of a random 3-D split of `samples` (u8, `dims`) through the library, as another
/// driver would; returns the manifest's path.
fn random_shards(dir: &Path, samples: &[u8], dims: [usize; 3], params: &Params, seed: u64) {
    let mut rng = Lcg(seed);
    let mut manifest = Manifest::new(dims, params);
    let [xs, ys, zs] = [0, 1, 2].map(|d| cuts(&mut rng, dims[d] - 1));
    for z in &zs {
        for y in &ys {
            for x in &xs {
                let cubes = [x.clone(), y.clone(), z.clone()];
                let need = block_samples(dims, cubes.clone(), params).unwrap();
                let mut part = vec![];
                for k in need[2].clone() {
                    for j in need[1].clone() {
                        let row = (k * dims[1] + j) * dims[0];
                        part.extend_from_slice(&samples[row + need[0].start..row + need[0].end]);
                    }
                }
                let volume = Volume::new(&part, need.clone().map(|r| r.len())).unwrap();
                let block =
                    extract_block(&volume, need.map(|r| r.start), dims, cubes.clone(), params)
                        .unwrap();
                let file = ShardEntry::file_name(&cubes);
                write_shard(&dir.join(&file), &block, &manifest.settings).unwrap();
                manifest.shards.push(ShardEntry::new(file, cubes, &block));
            }
        }
    }
    // Arrival order does not matter: list the shards shuffled.
    for i in (1..manifest.shards.len()).rev() {
        manifest.shards.swap(i, rng.below(i + 1));
    }
    manifest.write(&dir.join(MANIFEST_NAME)).unwrap();
}

/// A real crop cut into random blocks by a driver other than `extract --shards`: `merge` gives
/// `extract`'s bytes in every mode.
#[test]
fn random_splits_of_a_real_crop_merge_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let raw = fixture("brainsmall-crop-40x40x30.u8.raw");
    let samples = std::fs::read(&raw).unwrap();
    let dims = [40, 40, 30];
    for (seed, (mode, name)) in [
        (Mode::Embedded, "embedded"),
        (Mode::Paper, "paper"),
        (Mode::Steps123, "steps123"),
    ]
    .into_iter()
    .enumerate()
    {
        let params = Params {
            mode,
            ..Params::new(20.0)
        };
        let parts = d.join(format!("parts-{name}"));
        std::fs::create_dir(&parts).unwrap();
        random_shards(&parts, &samples, dims, &params, seed as u64 + 1);
        skelclimb(d)
            .args([
                "extract",
                raw.to_str().unwrap(),
                "--dims",
                "40,40,30",
                "--dtype",
                "u8",
            ])
            .args(["--iso", "20", "--mode", name, "-o", "whole.ply"])
            .assert()
            .success();
        skelclimb(d)
            .args([
                "merge",
                &format!("parts-{name}/manifest.json"),
                "-o",
                "joined.ply",
            ])
            .assert()
            .success();
        let whole = read(d, "whole.ply");
        assert!(whole.len() > 10_000, "{name}");
        assert!(
            whole == read(d, "joined.ply"),
            "{name}: the mesh bytes differ"
        );
    }
}

/// Shards of the 20³ sphere in blocks of 8 (27 shards) in `d/name`.
fn sphere_shards(d: &Path, name: &str, extra: &[&str]) {
    skelclimb(d)
        .args([
            "extract", "--demo", "sphere", "--size", "20", "--block", "8",
        ])
        .args(["--shards", name])
        .args(extra)
        .assert()
        .success();
}

/// `merge` fails with `needle` in its message and leaves no output.
fn merge_fails(d: &Path, manifest: &str, needle: &str) {
    std::fs::create_dir_all(d.join("out")).unwrap();
    skelclimb(d)
        .args(["merge", manifest, "-o", "out/m.ply"])
        .assert()
        .code(1)
        .stderr(contains(needle));
    assert!(entries(&d.join("out")).is_empty(), "{needle}");
}

/// Edits the manifest at `path` as JSON.
fn edit_whole_manifest(path: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
    let mut m: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    edit(&mut m);
    std::fs::write(path, serde_json::to_vec(&m).unwrap()).unwrap();
}

/// Edits the list of shards of the manifest at `path`.
fn edit_manifest(path: &Path, edit: impl FnOnce(&mut Vec<serde_json::Value>)) {
    edit_whole_manifest(path, |m| edit(m["shards"].as_array_mut().unwrap()));
}

#[test]
fn a_missing_shard_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sphere_shards(d, "p", &[]);
    std::fs::remove_file(d.join("p/block-8-0-8.npz")).unwrap();
    merge_fails(d, "p/manifest.json", "block-8-0-8.npz: no such file");
}

/// Where `needle` first occurs in `hay` at or after `from`.
fn find(hay: &[u8], needle: &[u8], from: usize) -> usize {
    from + hay[from..]
        .windows(needle.len())
        .position(|w| w == needle)
        .unwrap()
}

#[test]
fn a_damaged_shard_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sphere_shards(d, "p", &[]);
    let shard = d.join("p/block-8-8-8.npz");
    let bytes = std::fs::read(&shard).unwrap();
    // Cut short, and the keys' order broken: both are refused, naming the file.
    std::fs::write(&shard, &bytes[..bytes.len() / 2]).unwrap();
    merge_fails(
        d,
        "p/manifest.json",
        "block-8-8-8.npz: not a readable shard",
    );
    // One bit of one vertex coordinate flipped: the entry's CRC-32 catches it.
    let name = find(&bytes, b"positions.npy", 0);
    let end = find(&bytes, b"PK\x03\x04", name);
    let mut flipped = bytes.clone();
    flipped[end - 1] ^= 1;
    std::fs::write(&shard, &flipped).unwrap();
    merge_fails(
        d,
        "p/manifest.json",
        "block-8-8-8.npz: not a readable shard",
    );
    let (mut block, settings) = {
        std::fs::write(&shard, &bytes).unwrap();
        sc_io::shard::read_shard(&shard).unwrap()
    };
    block.keys.reverse();
    write_shard(&shard, &block, &settings).unwrap();
    merge_fails(d, "p/manifest.json", "keys are not strictly increasing");
}

#[test]
fn a_shard_of_another_mesh_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sphere_shards(d, "p", &[]);
    sphere_shards(d, "paper", &["--mode", "paper"]);
    std::fs::copy(d.join("paper/block-0-8-0.npz"), d.join("p/block-0-8-0.npz")).unwrap();
    merge_fails(
        d,
        "p/manifest.json",
        "block-0-8-0.npz: made with other settings",
    );
    skelclimb(d)
        .args([
            "extract", "--demo", "sphere", "--size", "21", "--block", "8",
        ])
        .args(["--shards", "big"])
        .assert()
        .success();
    std::fs::copy(d.join("big/block-0-8-0.npz"), d.join("p/block-0-8-0.npz")).unwrap();
    merge_fails(
        d,
        "p/manifest.json",
        "block-0-8-0.npz: a shard of a [21, 21, 21] grid",
    );
    // The right mesh, but another block's file under this block's name.
    std::fs::copy(d.join("p/block-8-8-8.npz"), d.join("p/block-0-8-0.npz")).unwrap();
    merge_fails(
        d,
        "p/manifest.json",
        "block-0-8-0.npz: not the block of cubes",
    );
}

#[test]
fn overlapping_and_missing_blocks_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sphere_shards(d, "p", &[]);
    let manifest = d.join("p/manifest.json");
    let original = std::fs::read(&manifest).unwrap();
    type Edit = fn(&mut Vec<serde_json::Value>);
    let cases: [(Edit, &str); 6] = [
        (|s| drop(s.pop()), "cover 6832 of the grid's 6859 cubes"),
        (
            |s| s.push(s[0].clone()),
            "shard block-0-0-0.npz is listed twice",
        ),
        // Two files whose boxes overlap by one layer of cubes: both named, with the cubes
        // they share.
        (
            |s| s[0]["cubes"][0][1] = 9.into(),
            "shards block-0-0-0.npz and block-8-0-0.npz both own the cubes [8..9, 0..8, 0..8]",
        ),
        (
            |s| s[0]["cubes"][1] = serde_json::json!([8, 2]),
            "its cubes along y run backwards, 8..2",
        ),
        (
            |s| s[26]["cubes"][2][1] = 20.into(),
            "cubes 16..20 along z leave the grid, which has cubes 0..19 there",
        ),
        (
            |s| s[1]["file"] = "../p/block-0-0-0.npz".into(),
            "not a shard manifest: a bad shard entry",
        ),
    ];
    for (edit, needle) in cases {
        std::fs::write(&manifest, &original).unwrap();
        edit_manifest(&manifest, edit);
        merge_fails(d, "p/manifest.json", needle);
    }
    std::fs::write(&manifest, b"{\"format\": \"something else\"}").unwrap();
    merge_fails(d, "p/manifest.json", "manifest.json: not a shard manifest");
}

#[test]
fn shard_options_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for bad in [
        &["--shards", "p", "-o", "m.ply"][..],
        &["--shards", "p", "--block", "0"],
        &["--block", "8", "-o", "m.ply"],
    ] {
        skelclimb(d)
            .args(["extract", "--demo", "sphere", "--size", "20"])
            .args(bad)
            .assert()
            .code(2);
    }
    skelclimb(d)
        .args(["merge", "nothing.json", "-o", "m.ply"])
        .assert()
        .code(1)
        .stderr(contains("nothing.json: no such file"));
    assert!(entries(d).is_empty());
}

/// Names in a manifest are checked against the runtime's tables, and its numbers against the
/// limits every front end shares: each refusal says what is wrong, not "no settings".
#[test]
fn a_manifest_s_names_and_numbers_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sphere_shards(d, "p", &[]);
    let manifest = d.join("p/manifest.json");
    let original = std::fs::read(&manifest).unwrap();
    let cases: [(&str, serde_json::Value, &str); 6] = [
        (
            "/settings/mode",
            "fast".into(),
            "mode \"fast\": expected 'embedded', 'paper', 'steps123' or 'adaptive'",
        ),
        (
            "/settings/iso",
            "0.5".into(),
            "iso \"0.5\" is not a finite number",
        ),
        (
            "/settings/spacing/1",
            1e308.into(),
            "settings: spacing [0.1,1e+308,0.1]",
        ),
        (
            "/world/linear/0/0",
            1e308.into(),
            "world: linear row [1e+308,",
        ),
        ("/world/offset/2", 1e30.into(), "below 1e30"),
        ("/world/space", "XYZ".into(), "space \"XYZ\" is neither"),
    ];
    for (at, value, needle) in cases {
        std::fs::write(&manifest, &original).unwrap();
        edit_whole_manifest(&manifest, |m| *m.pointer_mut(at).unwrap() = value);
        merge_fails(d, "p/manifest.json", needle);
    }
}

/// A placement whose numbers pass the limits but whose product with the vertices passes f32's
/// range is refused, not written as infinities; a NaN or infinity inside a shard is refused
/// naming the shard.
#[test]
fn no_infinity_or_nan_reaches_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sphere_shards(d, "p", &["--spacing", "1e20,1e20,1e20"]);
    let manifest = d.join("p/manifest.json");
    let original = std::fs::read(&manifest).unwrap();
    edit_whole_manifest(&manifest, |m| m["world"]["linear"][0][0] = 1e29.into());
    merge_fails(d, "p/manifest.json", "beyond what 32-bit floats hold");
    std::fs::write(&manifest, &original).unwrap();
    let shard = d.join("p/block-8-8-8.npz");
    let (block, settings) = sc_io::shard::read_shard(&shard).unwrap();
    for (row, bad) in [(0, f32::NAN), (3, f32::INFINITY)] {
        let mut b = block.clone();
        b.positions[row][1] = bad;
        write_shard(&shard, &b, &settings).unwrap();
        merge_fails(
            d,
            "p/manifest.json",
            &format!("block-8-8-8.npz: not a readable shard: positions row {row}"),
        );
        let mut b = block.clone();
        b.normals[row][2] = bad;
        write_shard(&shard, &b, &settings).unwrap();
        merge_fails(d, "p/manifest.json", &format!("normals row {row}"));
    }
}

/// A shard or a manifest that is a FIFO is refused at once (opening it would wait for a writer
/// forever), naming it.
#[cfg(unix)]
#[test]
fn a_fifo_is_refused_not_waited_on() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    sphere_shards(d, "p", &[]);
    let fifo = |path: &Path| {
        let _ = std::fs::remove_file(path);
        let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo reads a NUL-terminated path that lives for the call.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    };
    fifo(&d.join("p/block-0-8-8.npz"));
    merge_fails(
        d,
        "p/manifest.json",
        "block-0-8-8.npz: is not a regular file",
    );
    fifo(&d.join("p/manifest.json"));
    merge_fails(d, "p/manifest.json", "manifest.json: is not a regular file");
}
