//! Extraction speed: built-in 256³ volumes and the real volumes of `SC_DATA_DIR`, in each mode,
//! on one thread and on all threads.
//!
//! `SC_DATA_DIR` points at a folder of `<name>/<name>.raw` + `<name>.json` volumes (dims, dtype,
//! suggested iso values), such as the project's shared data. Without it those benchmarks are
//! skipped with a notice. `bench/compare.py` runs these and VTK's FlyingEdges in one go.

use std::path::Path;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use sc_runtime::{Mode, Params, Scalar, Volume, demo, extract_par};

const MODES: [(Mode, &str); 3] = [
    (Mode::Steps123, "steps123"),
    (Mode::Embedded, "embedded"),
    (Mode::Paper, "paper"),
];

fn bench_volume<T: Scalar>(c: &mut Criterion, name: &str, data: &[T], dims: [usize; 3], iso: f64) {
    let vol = Volume::new(data, dims).expect("bench volumes are consistent");
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    for (mode, mode_name) in MODES {
        let params = Params {
            mode,
            normals: false,
            ..Params::new(iso)
        };
        for threads in [1, all] {
            group.bench_with_input(
                BenchmarkId::new(mode_name, format!("{threads}t")),
                &threads,
                |b, &t| {
                    b.iter(|| extract_par(&vol, &params, t, &|_| {}).expect("extraction succeeds"))
                },
            );
        }
    }
    group.finish();
}

fn synthetic(c: &mut Criterion) {
    let to_f32 = |v: demo::DemoVolume| {
        (
            v.data.iter().map(|&x| x as f32).collect::<Vec<f32>>(),
            v.dims,
            v.iso,
        )
    };
    for (name, v) in [
        ("sphere-256", demo::sphere(256)),
        ("knot-256", demo::knot(256)),
        ("noise-256", demo::sphere_noise(256)),
    ] {
        let (data, dims, iso) = to_f32(v);
        bench_volume(c, name, &data, dims, iso);
    }
}

fn real(c: &mut Criterion) {
    let Some(dir) = std::env::var_os("SC_DATA_DIR") else {
        eprintln!("SC_DATA_DIR is not set: skipping the real-volume benchmarks");
        return;
    };
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .collect();
    names.sort();
    for d in names.iter().filter(|p| p.is_dir()) {
        let stem = d
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let json = d.join(format!("{stem}.json"));
        match load(&json) {
            Ok((meta, raw)) => {
                let dims = meta.dims;
                let name = format!("{stem}@{}", meta.iso);
                match meta.dtype.as_str() {
                    "u8" => bench_volume(c, &name, &raw, dims, meta.iso),
                    "i16" => {
                        bench_volume(c, &name, &cast(&raw, i16::from_le_bytes), dims, meta.iso)
                    }
                    "u16" => {
                        bench_volume(c, &name, &cast(&raw, u16::from_le_bytes), dims, meta.iso)
                    }
                    other => eprintln!("{}: dtype {other} not benchmarked", json.display()),
                }
            }
            Err(e) => eprintln!("skipping {}: {e}", json.display()),
        }
    }
}

struct Meta {
    dims: [usize; 3],
    dtype: String,
    iso: f64,
}

/// Reads a volume's description (its first suggested iso value) and raw samples.
fn load(json: &Path) -> Result<(Meta, Vec<u8>), String> {
    let text = std::fs::read_to_string(json).map_err(|e| e.to_string())?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    let dims: Vec<usize> = v["dims"]
        .as_array()
        .ok_or("no dims")?
        .iter()
        .filter_map(|d| d.as_u64())
        .map(|d| d as usize)
        .collect();
    let iso = v["iso_suggestions"]
        .as_object()
        .and_then(|o| o.values().find_map(|x| x.as_f64()))
        .ok_or("no iso")?;
    let dtype = v["dtype"].as_str().ok_or("no dtype")?.to_string();
    let raw = std::fs::read(json.with_extension("raw")).map_err(|e| e.to_string())?;
    Ok((
        Meta {
            dims: dims.try_into().map_err(|_| "dims need 3 values")?,
            dtype,
            iso,
        },
        raw,
    ))
}

fn cast<T, const N: usize>(raw: &[u8], f: fn([u8; N]) -> T) -> Vec<T> {
    raw.chunks_exact(N)
        .map(|b| f(b.try_into().expect("chunks of N")))
        .collect()
}

criterion_group!(benches, synthetic, real);
criterion_main!(benches);
