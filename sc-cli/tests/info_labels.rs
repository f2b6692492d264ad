//! `skelclimb info` on label volumes: the AAL crop in `tests/data/labels` (see its README), with
//! its tables beside it, without them, with a table given, and with a broken one; scans keep
//! their report.

mod common;

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use common::fixture;
use predicates::prelude::*;
use predicates::str::contains;

fn info(args: &[&str], volume: &Path) -> String {
    let out = Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("info")
        .arg(volume)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The raw volume `fixture` (`.raw` and its `.json` sidecar) copied into `dir` as `name`, without
/// the tables beside it; its sidecar's path.
fn copy(dir: &tempfile::TempDir, fixture_stem: &str, name: &str) -> PathBuf {
    for ext in ["json", "raw"] {
        std::fs::copy(
            fixture(&format!("{fixture_stem}.{ext}")),
            dir.path().join(format!("{name}.{ext}")),
        )
        .unwrap();
    }
    dir.path().join(format!("{name}.json"))
}

/// The crop's sample counts, counted from the AAL volume independently of this program (and
/// summing to the crop's 24 × 24 × 16 = 9,216 samples).
const COUNTS: [(u64, u64); 9] = [
    (21, 4),
    (27, 39),
    (29, 70),
    (37, 16),
    (41, 145),
    (71, 1021),
    (73, 3362),
    (75, 1644),
    (77, 89),
];

/// The id and count of each listed label, in the order listed down the columns.
fn listed(report: &str) -> Vec<(u64, u64)> {
    let rows: Vec<Vec<&str>> = report
        .lines()
        .skip_while(|l| !l.starts_with("  samples per label"))
        .skip(1)
        .take_while(|l| l.starts_with("    "))
        .map(|l| l.split_whitespace().collect())
        .collect();
    let per_cell = if report.contains("(id name samples)") {
        3
    } else {
        2
    };
    let columns = rows[0].len() / per_cell;
    let mut cells = Vec::new();
    for c in 0..columns {
        for row in &rows {
            if let Some(cell) = row.get(c * per_cell..(c + 1) * per_cell) {
                let count = cell[per_cell - 1].replace(',', "").parse().unwrap();
                cells.push((cell[0].parse().unwrap(), count));
            }
        }
    }
    cells
}

#[test]
fn labels_named_from_the_tables_beside() {
    let report = info(&[], &fixture("labels/aal-crop-24x24x16.u8.json"));
    assert!(
        report.contains("  labels    9 (and background 0: 2,826 samples)\n"),
        "{report}"
    );
    assert!(
        report.contains("  table     aal-crop-24x24x16.u8.txt, aal-crop-24x24x16.u8.lut\n"),
        "{report}"
    );
    assert_eq!(listed(&report), COUNTS);
    for name in ["21 Olfactory_L", "73 Putamen_L", "77 Thalamus_L"] {
        assert!(report.contains(name), "{name}: {report}");
    }
    // No histogram or iso values for labels.
    assert!(
        !report.contains("histogram") && !report.contains("iso"),
        "{report}"
    );
}

/// Without a table, the volume is still told for labels (it is piecewise constant), and listed
/// by id; a table given names what it has, `?` for the rest; a broken table beside the volume
/// is reported and skipped.
#[test]
fn labels_without_a_table_with_one_given_and_with_a_broken_one() {
    let dir = tempfile::tempdir().unwrap();
    let seg = copy(&dir, "labels/aal-crop-24x24x16.u8", "seg");
    let report = info(&[], &seg);
    assert!(
        report.contains("  table     none (give one with --label-table)\n"),
        "{report}"
    );
    let why = report
        .lines()
        .find(|l| l.starts_with("  why       "))
        .unwrap();
    let percent: f64 = why.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(why.ends_with("% of neighbouring non-zero samples are equal: taken for labels"));
    assert!((75.0..=100.0).contains(&percent), "{why}");
    assert!(report.contains("(id samples)"), "{report}");
    assert_eq!(listed(&report), COUNTS);

    let itk = fixture("labels/itksnap-labels.txt");
    let report = info(&["--label-table", itk.to_str().unwrap()], &seg);
    assert!(
        report.contains(&format!(
            "  table     {} (8 of the 9 labels not named in it)\n",
            itk.display()
        )),
        "{report}"
    );
    assert!(report.contains("71 Caudate_L"), "{report}");
    assert!(report.contains("73 ?"), "{report}");
    assert_eq!(listed(&report.replace(" ? ", " unnamed ")), COUNTS);

    std::fs::write(dir.path().join("seg.txt"), "1 a\n1 b\n").unwrap();
    let report = info(&[], &seg);
    assert!(
        report.contains("warning   not read as a label table: "),
        "{report}"
    );
    assert!(
        report.contains("seg.txt: line 2: label 1 again"),
        "{report}"
    );
    assert_eq!(listed(&report), COUNTS);
}

/// A scan's report is the histogram and iso values as ever, even with a table beside it that
/// does not name its values; a table given makes it a label volume (the user says so), unless
/// its samples cannot be labels (negative here), and then the table is reported unused. A
/// table that cannot be read fails the command, naming it.
#[test]
fn scans_are_not_labels() {
    let dir = tempfile::tempdir().unwrap();
    let scan = copy(&dir, "itk-t1-crop-40x40x30.i16", "scan");
    let report = info(&[], &scan);
    assert!(
        report.contains("histogram") && report.contains("Otsu"),
        "{report}"
    );
    assert!(!report.contains("labels"), "{report}");
    let itk = fixture("labels/itksnap-labels.txt");
    std::fs::copy(&itk, dir.path().join("scan.txt")).unwrap();
    assert_eq!(info(&[], &scan), report);

    let given = info(&["--label-table", itk.to_str().unwrap()], &scan);
    assert!(given.contains("labels    "), "{given}");
    assert!(given.contains(" labels not named in it"), "{given}");

    // The same samples, less 100: negative values, not labels.
    let raw = std::fs::read(dir.path().join("scan.raw")).unwrap();
    let shifted: Vec<u8> = raw
        .chunks(2)
        .flat_map(|b| (i16::from_le_bytes([b[0], b[1]]) - 100).to_le_bytes())
        .collect();
    std::fs::write(dir.path().join("scan.raw"), shifted).unwrap();
    let shifted = info(&["--label-table", itk.to_str().unwrap()], &scan);
    assert!(shifted.contains("histogram"), "{shifted}");
    assert!(shifted.contains("unused: not a label volume"), "{shifted}");

    Command::cargo_bin("skelclimb")
        .unwrap()
        .arg("info")
        .arg(&scan)
        .args(["--label-table", "no-such-table.txt"])
        .assert()
        .code(1)
        .stderr(contains("no-such-table.txt: no such file").and(contains("panicked").not()));
}
