//! Hostile and careless input: each case is a clear error naming the file or option, with exit
//! 1 (data) or 2 (usage), no panic, no allocation abort and no file left behind.

mod common;
use common::{entries, fixture, gzip, nifti};

use std::path::Path;
use std::process::Stdio;

use assert_cmd::Command;
use predicates::str::contains;

/// Runs `args` in `dir`, expecting exit `code`, `message` on stderr, no panic and no new file.
fn refused(dir: &Path, args: &[&str], code: i32, message: &str) {
    let before = entries(dir);
    let out = Command::cargo_bin("skelclimb")
        .unwrap()
        .current_dir(dir)
        .args(args)
        .assert()
        .code(code)
        .stderr(contains(message));
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(entries(dir), before, "{args:?} left files behind");
}

#[test]
fn options_out_of_range_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    refused(
        d,
        &[
            "extract",
            "--demo",
            "sphere",
            "--threads",
            "100000",
            "-o",
            "m.ply",
        ],
        2,
        "threads",
    );
    refused(
        d,
        &[
            "extract", "--demo", "sphere", "--size", "2000", "-o", "m.ply",
        ],
        2,
        "512",
    );
    refused(
        d,
        &["extract", "--demo", "sphere", "--iso", "nan", "-o", "m.ply"],
        2,
        "finite",
    );
    refused(
        d,
        &["extract", "--demo", "sphere", "--iso", "inf", "-o", "m.ply"],
        2,
        "finite",
    );
    refused(
        d,
        &[
            "extract",
            "--demo",
            "sphere",
            "--spacing",
            "1,1e38,1",
            "-o",
            "m.ply",
        ],
        2,
        "1e30",
    );
    refused(
        d,
        &[
            "extract", "--demo", "sphere", "--origin", "nan,0,0", "-o", "m.ply",
        ],
        2,
        "finite",
    );
}

#[test]
fn outputs_never_overwrite_the_input_or_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A raw volume that happens to be called .ply.
    std::fs::copy(
        fixture("brainsmall-crop-40x40x30.u8.raw"),
        d.join("vol.ply"),
    )
    .unwrap();
    let raw = ["--dims", "40,40,30", "--dtype", "u8", "--iso", "20"];
    let mut args = vec!["extract", "vol.ply", "-o", "./vol.ply"];
    args.extend(raw);
    refused(d, &args, 2, "same file");
    let mut args = vec!["extract", "vol.ply", "-o", "m.ply", "--stats-json", "m.ply"];
    args.extend(raw);
    refused(d, &args, 2, "same file");
    assert_eq!(
        std::fs::read(d.join("vol.ply")).unwrap(),
        std::fs::read(fixture("brainsmall-crop-40x40x30.u8.raw")).unwrap()
    );
}

#[test]
fn a_long_legal_output_name_works() {
    let dir = tempfile::tempdir().unwrap();
    let name = format!("{}.ply", "m".repeat(246));
    Command::cargo_bin("skelclimb")
        .unwrap()
        .current_dir(dir.path())
        .args([
            "extract", "--demo", "sphere", "--size", "16", "-q", "-o", &name,
        ])
        .assert()
        .success();
    assert_eq!(entries(dir.path()), [name]);
}

#[test]
fn unusable_placements_in_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = nifti();
    let f32_at = |bytes: &mut Vec<u8>, at: usize, v: f32| {
        bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
    };
    let i16_at = |bytes: &mut Vec<u8>, at: usize, v: i16| {
        bytes[at..at + 2].copy_from_slice(&v.to_le_bytes());
    };
    // sform with NaN; pixdim NaN and zero under the qform; a NaN qform offset.
    let mut nan_sform = base.clone();
    f32_at(&mut nan_sform, 280, f32::NAN);
    let mut nan_pixdim = base.clone();
    i16_at(&mut nan_pixdim, 254, 0);
    f32_at(&mut nan_pixdim, 80, f32::NAN);
    let mut zero_pixdim = nan_pixdim.clone();
    f32_at(&mut zero_pixdim, 80, 0.0);
    let mut nan_offset = base.clone();
    i16_at(&mut nan_offset, 254, 0);
    f32_at(&mut nan_offset, 268, f32::INFINITY);
    for (name, bytes, message) in [
        ("nan-sform.nii", nan_sform, "sform"),
        ("nan-pixdim.nii", nan_pixdim, "spacing"),
        ("zero-pixdim.nii", zero_pixdim, "spacing"),
        ("inf-offset.nii", nan_offset, "origin"),
    ] {
        std::fs::write(d.join(name), bytes).unwrap();
        refused(
            d,
            &["extract", name, "--iso", "47.5", "-o", "m.ply"],
            1,
            message,
        );
        std::fs::remove_file(d.join(name)).unwrap();
    }
    // A NRRD with negative spacing and one with a zero-size axis.
    std::fs::write(d.join("v.raw"), [0u8; 64]).unwrap();
    for (header, message) in [
        ("sizes: 4 4 4\nspacings: 1 -1 1\n", "spacing"),
        ("sizes: 0 4 4\n", "no samples"),
    ] {
        let text = format!(
            "NRRD0004\ntype: uchar\ndimension: 3\n{header}encoding: raw\ndata file: v.raw\n"
        );
        std::fs::write(d.join("v.nhdr"), text).unwrap();
        refused(
            d,
            &["extract", "v.nhdr", "--iso", "1", "-o", "m.ply"],
            1,
            message,
        );
    }
}

#[test]
fn compressed_payloads_are_checked_and_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // One flipped byte inside the gzip stream's data: the CRC catches it.
    let nii = nifti();
    let mut gz = gzip(&nii);
    let mid = gz.len() / 2;
    gz[mid] ^= 0x01;
    std::fs::write(d.join("flipped.nii.gz"), &gz).unwrap();
    let out = Command::cargo_bin("skelclimb")
        .unwrap()
        .current_dir(d)
        .args(["info", "flipped.nii.gz"])
        .assert()
        .code(1);
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        stderr.contains("flipped.nii.gz") && !stderr.contains("panicked"),
        "{stderr}"
    );
    // A header claiming 2000³ samples over the same small payload: an error at the end of the
    // data, not an allocation of 16 GB.
    let mut big = nii.clone();
    for (at, v) in [(42, 2000i16), (44, 2000), (46, 2000)] {
        big[at..at + 2].copy_from_slice(&v.to_le_bytes());
    }
    std::fs::write(d.join("big.nii.gz"), gzip(&big)).unwrap();
    refused(
        d,
        &["extract", "big.nii.gz", "--iso", "47.5", "-o", "m.ply"],
        1,
        "ends after",
    );
}

#[test]
fn a_closed_pipe_ends_the_command_quietly() {
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("skelclimb"))
        .args(["info", "--bins", "256"])
        .arg(fixture("itk-t1-mri.nii.gz"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !stderr.contains("panicked") && !stderr.contains("Broken pipe"),
        "{stderr}"
    );
}

#[test]
fn headers_cannot_point_anywhere_or_loop() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("v.raw"), [0u8; 64]).unwrap();
    let nrrd = |extra: &str| {
        format!("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n{extra}")
    };
    for (extra, message) in [
        ("data file: /dev/zero\n", "outside the header's folder"),
        ("data file: ../v.raw\n", "outside the header's folder"),
        ("data file: \n", "data file name is empty"),
        (
            "line skip: 18446744073709551615\ndata file: v.raw\n",
            "lines the header says",
        ),
        (
            "line skip: 1000000000\ndata file: v.raw\n",
            "lines the header says",
        ),
    ] {
        std::fs::write(d.join("v.nhdr"), nrrd(extra)).unwrap();
        refused(
            d,
            &["extract", "v.nhdr", "--iso", "1", "-o", "m.ply"],
            1,
            message,
        );
    }
    std::fs::remove_file(d.join("v.nhdr")).unwrap();
    std::fs::write(
        d.join("v.mhd"),
        "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n\
         HeaderSize = 18446744073709551615\nElementDataFile = LOCAL\n",
    )
    .unwrap();
    refused(
        d,
        &["extract", "v.mhd", "--iso", "1", "-o", "m.ply"],
        1,
        "HeaderSize",
    );
}

#[test]
fn numpy_headers_are_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut v2 = b"\x93NUMPY\x02\x00".to_vec();
    v2.extend(u32::MAX.to_le_bytes());
    v2.extend(b"{'descr': '<f4'}");
    std::fs::write(d.join("long.npy"), v2).unwrap();
    refused(d, &["info", "long.npy"], 1, "implausible");
    let descr = format!(
        "{{'descr': {}'<f4'{}, 'fortran_order': False, 'shape': (2, 2, 2), }}",
        "[(".repeat(40),
        ")]".repeat(40)
    );
    let mut nested = b"\x93NUMPY\x01\x00".to_vec();
    nested.extend((descr.len() as u16).to_le_bytes());
    nested.extend(descr.as_bytes());
    std::fs::write(d.join("nested.npy"), nested).unwrap();
    refused(d, &["info", "nested.npy"], 1, "nest");
}

#[test]
fn a_truncated_nifti_header_is_described_in_words() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("cut.nii.gz"), gzip(&nifti()[..200])).unwrap();
    let out = Command::cargo_bin("skelclimb")
        .unwrap()
        .current_dir(d)
        .args(["info", "cut.nii.gz"])
        .assert()
        .code(1)
        .stderr(contains("cut.nii.gz"));
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        !stderr.contains("Custom {") && !stderr.contains("kind:"),
        "{stderr}"
    );
}

#[test]
fn a_flipped_byte_in_an_npz_member_fails_its_crc() {
    use std::io::Read;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let npz = std::fs::read(fixture("stent-ct.npz")).unwrap();
    // The one member's deflate data starts after its local header (30 bytes, name, extra field).
    let field = |at: usize| usize::from(u16::from_le_bytes([npz[at], npz[at + 1]]));
    let data = 30 + field(26) + field(28);
    let inflate = |bytes: &[u8]| {
        let mut out = Vec::new();
        flate2::read::DeflateDecoder::new(bytes)
            .read_to_end(&mut out)
            .map(|_| out)
    };
    let original = inflate(&npz[data..]).unwrap();
    // A flip that leaves the deflate stream valid, so only the CRC-32 can tell: the samples
    // change but their number does not.
    let flipped = (npz.len() / 2..npz.len() - 100)
        .step_by(101)
        .map(|at| {
            let mut bytes = npz.clone();
            bytes[at] ^= 0x10;
            bytes
        })
        .find(|bytes| {
            inflate(&bytes[data..]).is_ok_and(|out| out.len() == original.len() && out != original)
        })
        .expect("no flip keeps the deflate stream valid");
    std::fs::write(d.join("flipped.npz"), flipped).unwrap();
    refused(d, &["info", "flipped.npz"], 1, "flipped.npz");
    refused(
        d,
        &["extract", "flipped.npz", "--iso", "250", "-o", "m.ply"],
        1,
        "checksum",
    );
}

#[test]
fn sigterm_during_extract_leaves_no_temporary_file() {
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("skelclimb"))
        .current_dir(d)
        .args([
            "extract",
            "--demo",
            "sphere-noise",
            "--size",
            "400",
            "--threads",
            "1",
        ])
        .args(["-q", "-o", "m.ply"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The temporary mesh file is created before the volume is built; a moment later the command
    // is building or meshing it (a 400³ volume on one thread takes seconds).
    let start = Instant::now();
    while entries(d).is_empty() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no temporary file"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(entries(d)[0].ends_with(".tmp"), "{:?}", entries(d));
    std::thread::sleep(Duration::from_millis(800));
    assert!(
        child.try_wait().unwrap().is_none(),
        "extract ended before the signal"
    );
    // SAFETY: kill(2) on our own child, which has not been waited for, so its pid is still ours.
    assert_eq!(
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) },
        0
    );
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    assert_eq!(entries(d), Vec::<String>::new(), "files left behind");
}
