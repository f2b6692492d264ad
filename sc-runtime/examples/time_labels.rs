//! Times one label volume's extraction for profiling the label sweep, on one thread (or on
//! `THREADS` from the environment, 0 for all): the best of `RUNS` runs of `extract_labels`
//! (embedded, padded) and, apart, of cutting the atlas into one mesh per label. Prints a
//! checksum of the atlas (positions, triangles, pairs), so that a change to the sweep can be
//! checked to leave the atlas bit-identical.
//! Under `valgrind --tool=callgrind` pass `RUNS` = 1.
//!
//! ```sh
//! cargo run --release -p sc-runtime --example time_labels -- \
//!     /work/shared/data/labels/aal-atlas/aal-atlas.raw 181,217,181 u8 5
//! ```
//! The volume is raw little-endian, x fastest; dtype is u8, u16 or u32. The background is 0
//! unless given.

use std::time::{Duration, Instant};

use sc_runtime::labels::{Atlas, Label, LabelParams, extract_labels};
use sc_runtime::{Mesh, Volume};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, path, dims, dtype, runs, rest @ ..] = args.as_slice() else {
        return Err("usage: time_labels VOLUME.raw NX,NY,NZ DTYPE RUNS [BACKGROUND]".into());
    };
    let background: u64 = rest.first().map_or(Ok(0), |b| b.parse())?;
    let dims: Vec<usize> = dims.split(',').map(str::parse).collect::<Result<_, _>>()?;
    let dims: [usize; 3] = dims.try_into().map_err(|_| "three dims")?;
    let runs: usize = runs.parse()?;
    let raw = std::fs::read(path)?;
    match dtype.as_str() {
        "u8" => time(&raw, dims, runs, background),
        "u16" => time(&cast(&raw, u16::from_le_bytes), dims, runs, background),
        "u32" => time(&cast(&raw, u32::from_le_bytes), dims, runs, background),
        other => Err(format!("unknown dtype {other}").into()),
    }
}

fn cast<T, const N: usize>(raw: &[u8], from: fn([u8; N]) -> T) -> Vec<T> {
    raw.chunks_exact(N)
        .map(|c| from(c.try_into().unwrap()))
        .collect()
}

fn time<L: Label + Into<u64> + TryFrom<u64>>(
    data: &[L],
    dims: [usize; 3],
    runs: usize,
    background: u64,
) -> Result<(), Box<dyn std::error::Error>> {
    let volume = Volume::new(data, dims)?;
    let params = LabelParams {
        background: L::try_from(background).map_err(|_| "background out of range")?,
        threads: std::env::var("THREADS").map_or(Ok(1), |t| t.parse())?,
        ..LabelParams::default()
    };
    let (mut sweep, mut cut) = (Duration::MAX, Duration::MAX);
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t0 = Instant::now();
        let atlas = extract_labels(volume, &params)?;
        let t1 = Instant::now();
        let labels = atlas.labels(params.background, params.threads);
        let meshes = atlas.meshes(&labels, false, params.threads);
        let t2 = Instant::now();
        sweep = sweep.min(t1 - t0);
        cut = cut.min(t2 - t1);
        last = Some((atlas, meshes));
    }
    let (atlas, meshes) = last.expect("one run");
    println!(
        "extract_labels {:.4} s, meshes {:.4} s (best of {runs}); {} vertices, {} triangles, \
         {} meshes, {} merged; checksums: atlas {:016x}, meshes {:016x}",
        sweep.as_secs_f64(),
        cut.as_secs_f64(),
        atlas.positions.len(),
        atlas.triangles.len(),
        meshes.len(),
        atlas.stats.merged,
        checksum(&atlas),
        meshes_checksum(&meshes),
    );
    Ok(())
}

/// FNV-1a over each mesh's label, positions (bits) and triangles.
fn meshes_checksum<L: Label + Into<u64>>(meshes: &[(L, Mesh)]) -> u64 {
    let mut h = Fnv::default();
    for (label, mesh) in meshes {
        h.eat((*label).into());
        mesh.positions
            .iter()
            .for_each(|p| p.iter().for_each(|c| h.eat(u64::from(c.to_bits()))));
        mesh.triangles
            .iter()
            .for_each(|t| t.iter().for_each(|&v| h.eat(u64::from(v))));
    }
    h.0
}

struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    fn eat(&mut self, x: u64) {
        self.0 ^= x;
        self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
    }
}

/// FNV-1a over the atlas's positions (bits), triangles and pairs.
fn checksum<L: Label + Into<u64>>(atlas: &Atlas<L>) -> u64 {
    let mut h = Fnv::default();
    for p in &atlas.positions {
        p.iter().for_each(|c| h.eat(u64::from(c.to_bits())));
    }
    for t in &atlas.triangles {
        t.iter().for_each(|&v| h.eat(u64::from(v)));
    }
    for pair in &atlas.pairs {
        pair.iter().for_each(|&l| h.eat(l.into()));
    }
    h.0
}
