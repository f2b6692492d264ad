//! Times one volume's extraction, for profiling and for comparing variants of the sweep:
//! the median of `RUNS` single-threaded extractions (normals off unless `--normals`), in each
//! mode given. `--python` adds the values and the `(z, y, x)` coordinates that the Python
//! package's `marching_cubes` asks for: the sweep's copy for that output is compiled apart, and
//! a change can speed one copy and not the other (see `docs/speed-log.md`, after `b78d4f4`).
//! `--reuse` extracts through one [`Extractor`] (one thread), which keeps its mesh's memory
//! between runs: against the default, where each run's mesh is fresh memory while the last
//! run's is still held, it shows what first touching the output's pages costs.
//! Under `valgrind --tool=callgrind` pass `RUNS` = 1: instruction counts, unlike seconds, do not
//! move with the machine's load.
//!
//! ```sh
//! cargo run --release -p sc-runtime --example time_extract -- \
//!     tests/data/brainsmall-crop-40x40x30.u8.raw 40,40,30 u8 20 20 embedded,steps123
//! ```
//! The volume is raw little-endian, x fastest; dtype is u8, i16, u16 or f32.

use std::time::Instant;

use sc_runtime::{Axes, Extractor, Mode, Params, Scalar, Volume, extract_par};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, path, dims, dtype, iso, runs, modes, rest @ ..] = args.as_slice() else {
        return Err(
            "usage: time_extract VOLUME.raw NX,NY,NZ DTYPE ISO RUNS MODE[,MODE…] [--normals] [--python] [--threads N | --reuse]"
                .into(),
        );
    };
    let dims: Vec<usize> = dims.split(',').map(str::parse).collect::<Result<_, _>>()?;
    let dims: [usize; 3] = dims.try_into().map_err(|_| "three dims")?;
    let raw = std::fs::read(path)?;
    let options = Options {
        iso: iso.parse()?,
        runs: runs.parse()?,
        normals: rest.iter().any(|a| a == "--normals"),
        python: rest.iter().any(|a| a == "--python"),
        reuse: rest.iter().any(|a| a == "--reuse"),
        threads: rest
            .iter()
            .position(|a| a == "--threads")
            .and_then(|i| rest.get(i + 1))
            .map_or(Ok(1), |t| t.parse())?,
    };
    for mode in modes.split(',') {
        let mode: Mode = mode
            .parse()
            .map_err(|e| format!("unknown mode {mode}: {e}"))?;
        let Timing {
            median,
            fastest,
            triangles,
            checksum,
        } = match dtype.as_str() {
            "u8" => time(&raw, dims, mode, &options)?,
            "i16" => time(&cast(&raw, i16::from_le_bytes), dims, mode, &options)?,
            "u16" => time(&cast(&raw, u16::from_le_bytes), dims, mode, &options)?,
            "f32" => time(&cast(&raw, f32::from_le_bytes), dims, mode, &options)?,
            other => return Err(format!("unknown dtype {other}").into()),
        };
        println!(
            "{mode:?}: {median:.3} ms (median of {}; fastest {fastest:.3} ms), {triangles} triangles, mesh checksum {checksum:016x}",
            options.runs
        );
    }
    Ok(())
}

struct Timing {
    median: f64,
    fastest: f64,
    triangles: usize,
    checksum: u64,
}

struct Options {
    iso: f64,
    runs: usize,
    normals: bool,
    /// Values and `(z, y, x)` coordinates, as the Python package's `marching_cubes` asks.
    python: bool,
    threads: usize,
    /// Through one `Extractor`, whose mesh keeps its memory from run to run.
    reuse: bool,
}

fn time<T: Scalar>(
    data: &[T],
    dims: [usize; 3],
    mode: Mode,
    options: &Options,
) -> Result<Timing, Box<dyn std::error::Error>> {
    let vol = Volume::new(data, dims)?;
    let params = Params {
        mode,
        normals: options.normals,
        values: options.python,
        axes: if options.python { Axes::Zyx } else { Axes::Xyz },
        ..Params::new(options.iso)
    };
    let mut times = Vec::with_capacity(options.runs);
    let mut mesh = None;
    let mut extractor = Extractor::new();
    for _ in 0..options.runs.max(1) {
        let t = Instant::now();
        // The last run's mesh is dropped after the clock stops.
        let fresh = if options.reuse {
            extractor.extract(&vol, &params)?;
            None
        } else {
            Some(extract_par(&vol, &params, options.threads, &|_| {})?)
        };
        times.push(t.elapsed().as_secs_f64() * 1e3);
        mesh = fresh;
    }
    times.sort_by(f64::total_cmp);
    let mesh = mesh.unwrap_or_else(|| extractor.into_mesh());
    Ok(Timing {
        median: times[times.len() / 2],
        fastest: times[0],
        triangles: mesh.triangles.len(),
        checksum: checksum(&mesh),
    })
}

/// FNV-1a over the mesh's bytes: variants of the sweep must leave it unchanged.
fn checksum(mesh: &sc_runtime::Mesh) -> u64 {
    let words = (mesh
        .positions
        .iter()
        .chain(&mesh.normals)
        .flatten()
        .map(|c| c.to_bits()))
    .chain(mesh.triangles.iter().flatten().copied());
    words.fold(0xcbf2_9ce4_8422_2325, |h, w| {
        (h ^ u64::from(w)).wrapping_mul(0x0100_0000_01b3)
    })
}

fn cast<T, const N: usize>(raw: &[u8], f: fn([u8; N]) -> T) -> Vec<T> {
    raw.chunks_exact(N)
        .map(|b| f(b.try_into().expect("chunks of N")))
        .collect()
}
