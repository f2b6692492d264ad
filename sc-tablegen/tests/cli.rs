//! The `sc-tablegen` binary: verify's diff, dump's selections and formats, and clear errors with
//! a non-zero exit (never a panic) for bad input.

use std::path::PathBuf;

use assert_cmd::Command;

fn committed() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tables/skeleton-climbing.ron")
}

fn tablegen() -> Command {
    Command::cargo_bin("sc-tablegen").unwrap()
}

fn stdout(args: &[&str]) -> String {
    let out = tablegen()
        .args(args)
        .arg("--tables")
        .arg(committed())
        .assert()
        .success();
    String::from_utf8(out.get_output().stdout.clone()).unwrap()
}

/// Exit code and stderr of a failing run; stderr must not be a panic.
fn failure(args: &[&str]) -> (i32, String) {
    let out = tablegen().args(args).assert().failure();
    let o = out.get_output();
    let err = String::from_utf8(o.stderr.clone()).unwrap();
    assert!(!err.contains("panicked"), "{err}");
    (o.status.code().unwrap(), err)
}

#[test]
fn verify_passes_on_the_committed_file_and_reports_drift() {
    tablegen()
        .arg("verify")
        .arg("--tables")
        .arg(committed())
        .assert()
        .success();
    let text = std::fs::read_to_string(committed()).unwrap();
    let mut set = sc_tablegen::TableSet::from_ron(&text).unwrap();
    set.classes[0].cases[1].triangles[0].reverse();
    let dir = tempfile::tempdir().unwrap();
    let drifted = dir.path().join("drifted.ron");
    std::fs::write(&drifted, set.to_ron()).unwrap();
    let (code, err) = failure(&["verify", "--tables", drifted.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(
        err.contains("1 entries differ") && err.contains("class 0 case 1"),
        "{err}"
    );
}

#[test]
fn dump_selects_by_decimal_hex_and_binary_case() {
    for case in ["103", "0x67", "0b01100111"] {
        let out = stdout(&["dump", "--class", "0", "--case", case]);
        assert!(
            out.starts_with("class 0 case 103 (0x67, 0b01100111)  rule: demoted"),
            "{out}"
        );
        assert!(
            out.contains("NOT mergeable (forced fold)") && out.contains("●0"),
            "{out}"
        );
    }
}

#[test]
fn dump_json_follows_the_documented_schema() {
    let out = stdout(&["dump", "--class", "0", "--case", "1", "--format", "json"]);
    let j: serde_json::Value = serde_json::from_str(&out).unwrap();
    let entry = &j["classes"][0]["cases"][0];
    assert_eq!(j["classes"][0]["class"], 0);
    assert_eq!(entry["case"], 1);
    assert_eq!(entry["triangles"], serde_json::json!([[4, 8, 0]]));
    assert_eq!(
        entry["grey"],
        serde_json::json!([{"edge": 8, "ear": 0, "mergeable": true}])
    );
    assert_eq!(entry["rule"], "base");
    let ron = stdout(&["dump", "--class", "0", "--case", "1", "--format", "ron"]);
    assert!(ron.contains("(case: 1, triangles: [(4, 8, 0)], grey: [(edge: 8, ear: Some(0), mergeable: true)], rule: base)"), "{ron}");
}

#[test]
fn dump_stats_and_svg() {
    let out = stdout(&["dump", "--stats"]);
    assert!(out.contains("demoted    96"), "{out}");
    assert_eq!(out.matches(": 12  cases").count(), 8, "{out}");
    let dir = tempfile::tempdir().unwrap();
    stdout(&[
        "dump",
        "--class",
        "3",
        "--case",
        "0x69",
        "--svg",
        dir.path().to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(dir.path().join("class3-case105.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("<polygon"), "{svg}");
}

#[test]
fn bad_input_is_a_clear_error() {
    let tables = committed();
    let t = tables.to_str().unwrap();
    let (code, err) = failure(&["dump", "--tables", t, "--class", "9"]);
    assert_eq!(code, 2);
    assert!(err.contains("--class") && err.contains("9"), "{err}");
    let (code, err) = failure(&["dump", "--tables", t, "--case", "256"]);
    assert_eq!(code, 2);
    assert!(err.contains("case 256 is out of range"), "{err}");
    let (code, err) = failure(&["dump", "--tables", t, "--case", "0xzz"]);
    assert_eq!(code, 2);
    assert!(err.contains("not a number"), "{err}");
    let (code, err) = failure(&["dump", "--tables", "/nonexistent/tables.ron"]);
    assert_eq!(code, 1);
    assert!(err.contains("cannot read /nonexistent/tables.ron"), "{err}");
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.ron");
    std::fs::write(&bad, "(order: [1, 2").unwrap();
    let (code, err) = failure(&["verify", "--tables", bad.to_str().unwrap()]);
    assert_eq!(code, 1);
    assert!(err.contains("bad.ron: malformed tables"), "{err}");
    let (code, err) = failure(&[
        "generate",
        "--order",
        "0,1,2,3,4,5,6,7,8",
        "--out",
        "/tmp/never.ron",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("not a permutation"), "{err}");
}

/// Without `--tables`, the commands find the checkout's file from any subdirectory, `dump` uses
/// the built-in copy outside a checkout, `verify` there says what to do, and `generate` creates
/// its output folder.
#[test]
fn works_from_any_directory() {
    let inside = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/bin");
    let out = tablegen()
        .current_dir(&inside)
        .arg("verify")
        .assert()
        .success();
    let text = String::from_utf8(out.get_output().stdout.clone()).unwrap();
    assert!(
        text.contains("tables/skeleton-climbing.ron matches fresh generation"),
        "{text}"
    );

    let outside = tempfile::tempdir().unwrap();
    let out = tablegen()
        .current_dir(outside.path())
        .args(["dump", "--class", "0", "--case", "103"])
        .assert()
        .success();
    let text = String::from_utf8(out.get_output().stdout.clone()).unwrap();
    assert!(text.starts_with("class 0 case 103"), "{text}");
    let out = tablegen()
        .current_dir(outside.path())
        .arg("verify")
        .assert()
        .failure();
    let err = String::from_utf8(out.get_output().stderr.clone()).unwrap();
    assert!(err.contains("give --tables PATH"), "{err}");

    let target = outside.path().join("new/dir/t.ron");
    tablegen()
        .args(["generate", "--out", target.to_str().unwrap()])
        .assert()
        .success();
    let written = std::fs::read_to_string(&target).unwrap();
    assert_eq!(written, std::fs::read_to_string(committed()).unwrap());
    tablegen()
        .current_dir(outside.path())
        .arg("generate")
        .assert()
        .success();
    assert!(
        outside
            .path()
            .join("tables/skeleton-climbing.ron")
            .is_file()
    );
}

/// `sc-tablegen dump | head`: the reader stops early, and the command ends without a panic.
#[test]
fn a_closed_pipe_ends_dump_quietly() {
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("sc-tablegen"))
        .arg("dump")
        .arg("--tables")
        .arg(committed())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 16];
    std::io::Read::read_exact(child.stdout.as_mut().unwrap(), &mut first).unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !stderr.contains("panicked") && !stderr.contains("Broken pipe"),
        "{stderr}"
    );
}
