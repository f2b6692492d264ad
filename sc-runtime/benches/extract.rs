//! Extraction speed: built-in 256³ volumes and the real volumes of `SC_DATA_DIR`, in each mode,
//! on one thread and on all threads.
//!
//! `SC_DATA_DIR` points at folders (separated by `:`) of `<name>/<name>.raw` + `<name>.json`
//! volumes (dims, dtype u8/i16/u16/f32, suggested iso values; each is benchmarked at every
//! suggested value), such as the project's shared data and what `bench/derive_volumes.py` makes
//! of it. Without it those benchmarks are skipped with a notice. `bench/compare.py` runs these
//! and VTK's FlyingEdges in one go.
//!
//! `SC_BENCH_ONLY=<group>` (say `stent-ct@281`) builds and loads that volume alone: criterion's
//! own filter skips the timing of the others but not the making of their volumes, which takes
//! seconds. `bench/compare.py` runs one group at a time, alternating with Flying Edges.

use std::path::Path;
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use sc_runtime::{Extractor, Mode, Params, Scalar, Volume, demo, extract_par};

const MODES: [Mode; 3] = [Mode::Steps123, Mode::Embedded, Mode::Paper];

fn bench_volume<T: Scalar>(c: &mut Criterion, name: &str, data: &[T], dims: [usize; 3], iso: f64) {
    let vol = Volume::new(data, dims).expect("bench volumes are consistent");
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_millis(1500));
    let threads = if all > 1 { vec![1, all] } else { vec![1] };
    let runs = MODES
        .iter()
        .flat_map(|&mode| threads.iter().map(move |&t| (mode, mode.name(), false, t)))
        // Normals' cost, on one thread, in the mode people use.
        .chain([(Mode::Embedded, "embedded-normals", true, 1)]);
    for (mode, mode_name, normals, threads) in runs {
        let params = Params {
            mode,
            normals,
            ..Params::new(iso)
        };
        group.bench_with_input(
            BenchmarkId::new(mode_name, format!("{threads}t")),
            &threads,
            |b, &t| b.iter(|| extract_par(&vol, &params, t, &|_| {}).expect("extraction succeeds")),
        );
    }
    // The same with normals through an `Extractor`, which keeps its buffers between calls: what
    // the allocator costs the line above (see "Repeated extractions and glibc" in
    // docs/speed-log.md).
    let params = Params {
        normals: true,
        ..Params::new(iso)
    };
    let mut extractor = Extractor::new();
    group.bench_function(BenchmarkId::new("embedded-normals-reused", "1t"), |b| {
        b.iter(|| {
            extractor
                .extract(&vol, &params)
                .expect("extraction succeeds")
                .triangles
                .len()
        })
    });
    group.finish();
}

/// Whether `SC_BENCH_ONLY` leaves the group `name` in.
fn wanted(name: &str) -> bool {
    std::env::var("SC_BENCH_ONLY").map_or(true, |only| only == name)
}

fn synthetic(c: &mut Criterion) {
    let to_f32 = |v: demo::DemoVolume| {
        (
            v.data.iter().map(|&x| x as f32).collect::<Vec<f32>>(),
            v.dims,
            v.iso,
        )
    };
    type Make = fn(usize) -> demo::DemoVolume;
    let volumes: [(&str, Make); 3] = [
        ("sphere-256", demo::sphere),
        ("knot-256", demo::knot),
        ("noise-256", demo::sphere_noise),
    ];
    for (name, make) in volumes.into_iter().filter(|(name, _)| wanted(name)) {
        let (data, dims, iso) = to_f32(make(256));
        bench_volume(c, name, &data, dims, iso);
    }
}

fn real(c: &mut Criterion) {
    let Some(dirs) = std::env::var_os("SC_DATA_DIR") else {
        eprintln!("SC_DATA_DIR is not set: skipping the real-volume benchmarks");
        return;
    };
    let mut names: Vec<_> = std::env::split_paths(&dirs)
        .flat_map(std::fs::read_dir)
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
        let meta = match load(&json) {
            Ok(meta) => meta,
            Err(e) => {
                eprintln!("skipping {}: {e}", json.display());
                continue;
            }
        };
        let groups: Vec<(String, f64)> = meta
            .isos
            .iter()
            .map(|&iso| (format!("{stem}@{iso}"), iso))
            .filter(|(name, _)| wanted(name))
            .collect();
        if groups.is_empty() {
            continue;
        }
        let raw = match std::fs::read(json.with_extension("raw")) {
            Ok(raw) => raw,
            Err(e) => {
                eprintln!("skipping {}: {e}", json.display());
                continue;
            }
        };
        for (name, iso) in groups {
            let dims = meta.dims;
            match meta.dtype.as_str() {
                "u8" => bench_volume(c, &name, &raw, dims, iso),
                "i16" => bench_volume(c, &name, &cast(&raw, i16::from_le_bytes), dims, iso),
                "u16" => bench_volume(c, &name, &cast(&raw, u16::from_le_bytes), dims, iso),
                "f32" => bench_volume(c, &name, &cast(&raw, f32::from_le_bytes), dims, iso),
                other => eprintln!("{}: dtype {other} not benchmarked", json.display()),
            }
        }
    }
}

struct Meta {
    dims: [usize; 3],
    dtype: String,
    isos: Vec<f64>,
}

/// Reads a volume's description: its dims, dtype and suggested iso values.
fn load(json: &Path) -> Result<Meta, String> {
    let text = std::fs::read_to_string(json).map_err(|e| e.to_string())?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    let dims: Vec<usize> = v["dims"]
        .as_array()
        .ok_or("no dims")?
        .iter()
        .filter_map(|d| d.as_u64())
        .map(|d| d as usize)
        .collect();
    let isos: Vec<f64> = v["iso_suggestions"]
        .as_object()
        .map(|o| o.values().filter_map(|x| x.as_f64()).collect())
        .unwrap_or_default();
    if isos.is_empty() {
        return Err("no iso".into());
    }
    let dtype = v["dtype"].as_str().ok_or("no dtype")?.to_string();
    Ok(Meta {
        dims: dims.try_into().map_err(|_| "dims need 3 values")?,
        dtype,
        isos,
    })
}

fn cast<T, const N: usize>(raw: &[u8], f: fn([u8; N]) -> T) -> Vec<T> {
    raw.chunks_exact(N)
        .map(|b| f(b.try_into().expect("chunks of N")))
        .collect()
}

criterion_group!(benches, synthetic, real);
criterion_main!(benches);
