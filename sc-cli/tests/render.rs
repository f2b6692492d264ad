//! `skelclimb render`: pictures with properties that can be checked — a sphere from above covers
//! the disc the framing predicts, the same mesh in PLY, OBJ and STL gives the same picture, the
//! wireframe darkens pixels, `--compare` draws two panels, a mesh against itself has no error,
//! and bad input fails without leaving a file.

mod common;
use common::entries;

use std::path::Path;

use assert_cmd::Command;
use predicates::str::contains;

fn skelclimb() -> Command {
    Command::cargo_bin("skelclimb").unwrap()
}

fn run(dir: &Path, args: &[&str]) {
    skelclimb().current_dir(dir).args(args).assert().success();
}

/// Width, height and RGB bytes of a PNG.
fn decode(path: &Path) -> (usize, usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, buf)
}

fn covered(rgb: &[u8]) -> usize {
    rgb.chunks_exact(3)
        .filter(|p| p != &[255, 255, 255])
        .count()
}

fn dark(rgb: &[u8]) -> usize {
    rgb.chunks_exact(3)
        .filter(|p| p.iter().all(|&c| c < 80))
        .count()
}

#[test]
fn pictures_show_what_the_mesh_is() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for out in ["s.ply", "s.obj", "s.stl"] {
        run(
            d,
            &[
                "extract", "--demo", "sphere", "--size", "32", "-q", "-o", out,
            ],
        );
    }
    run(
        d,
        &[
            "render", "s.ply", "-o", "top.png", "--view", "top", "--size", "200x200",
        ],
    );
    let (w, h, rgb) = decode(&d.join("top.png"));
    assert_eq!((w, h), (200, 200));
    // The framing scales the mesh's extent to 92 % of the picture: a disc 184 pixels across.
    let disc = std::f64::consts::PI * 92.0 * 92.0;
    let got = covered(&rgb) as f64;
    assert!(
        (got / disc - 1.0).abs() < 0.03,
        "covered {got} pixels, a disc has {disc}"
    );
    // Deterministic, and the same for the same mesh in every format.
    let png = |name: &str| std::fs::read(d.join(name)).unwrap();
    run(
        d,
        &[
            "render",
            "s.ply",
            "-o",
            "again.png",
            "--view",
            "top",
            "--size",
            "200x200",
        ],
    );
    assert!(png("top.png") == png("again.png"));
    for mesh in ["s.obj", "s.stl"] {
        let out = format!("{mesh}.png");
        run(
            d,
            &[
                "render", mesh, "-o", &out, "--view", "top", "--size", "200x200",
            ],
        );
        assert!(png("top.png") == png(&out), "{mesh}");
    }
    // Edges darken the picture; smooth shading changes it but covers the same pixels.
    run(
        d,
        &[
            "render",
            "s.ply",
            "-o",
            "wire.png",
            "--wireframe",
            "--size",
            "200x200",
        ],
    );
    run(
        d,
        &["render", "s.ply", "-o", "iso.png", "--size", "200x200"],
    );
    run(
        d,
        &[
            "render",
            "s.ply",
            "-o",
            "smooth.png",
            "--smooth",
            "--size",
            "200x200",
        ],
    );
    let (iso, wire, smooth) = (
        decode(&d.join("iso.png")).2,
        decode(&d.join("wire.png")).2,
        decode(&d.join("smooth.png")).2,
    );
    assert!(
        dark(&wire) > dark(&iso) + 500,
        "{} vs {}",
        dark(&wire),
        dark(&iso)
    );
    assert_eq!(covered(&smooth), covered(&iso));
    assert!(smooth != iso);
}

#[test]
fn two_meshes_side_by_side_and_errors_in_colour() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run(d, &["extract", "--demo", "knot", "-q", "-o", "k.ply"]);
    run(
        d,
        &[
            "extract", "--demo", "knot", "--mode", "steps123", "-q", "-o", "k13.ply",
        ],
    );
    run(
        d,
        &[
            "render",
            "k.ply",
            "--compare",
            "k13.ply",
            "-o",
            "c.png",
            "--size",
            "300x200",
        ],
    );
    let (w, h, rgb) = decode(&d.join("c.png"));
    assert_eq!((w, h), (600, 200));
    let half = |left: bool| -> Vec<u8> {
        rgb.chunks_exact(3 * w)
            .flat_map(|row| {
                if left {
                    &row[..3 * 300]
                } else {
                    &row[3 * 300..]
                }
                .to_vec()
            })
            .collect()
    };
    assert!(covered(&half(true)) > 5000 && covered(&half(false)) > 5000);
    skelclimb()
        .current_dir(d)
        .args("render k.ply --color-by-error k.ply -o self.png".split(' '))
        .assert()
        .success()
        .stderr(contains("max 0.0000, mean 0.0000"));
    skelclimb()
        .current_dir(d)
        .args("render k.ply --color-by-error k13.ply -o e.png".split(' '))
        .assert()
        .success()
        .stderr(contains("max 0.0"));
}

#[test]
fn bad_input_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("bad.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n2\n",
    )
    .unwrap();
    std::fs::write(d.join("empty.obj"), "v 0 0 0\n").unwrap();
    for (args, code, message) in [
        (&["render", "bad.ply", "-o", "p.png"][..], 1, "bad.ply"),
        (&["render", "empty.obj", "-o", "p.png"], 1, "no triangles"),
        (&["render", "missing.ply", "-o", "p.png"], 1, "missing.ply"),
        (&["render", "bad.ply", "-o", "p.jpg"], 2, ".png"),
        (
            &["render", "bad.ply", "-o", "p.png", "--size", "10x10"],
            2,
            "16 to 8192",
        ),
    ] {
        let before = entries(d);
        skelclimb()
            .current_dir(d)
            .args(args)
            .assert()
            .code(code)
            .stderr(contains(message));
        assert_eq!(entries(d), before, "{args:?}");
    }
}
