//! How much two cores give on this machine: one single-thread extraction alone, then two
//! independent ones at the same time, then `extract_par` on two threads.
//!
//! ```sh
//! cargo run --release -p sc-runtime --example two_at_once -- \
//!     tests/data/brainsmall-crop-40x40x30.u8.raw 40,40,30 20
//! ```
//! The volume is raw u8, x fastest.

use std::time::Instant;

use sc_runtime::{Mode, Params, Volume, extract, extract_par};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, path, dims, iso] = args.as_slice() else {
        return Err("usage: two_at_once VOLUME.u8.raw NX,NY,NZ ISO".into());
    };
    let dims: Vec<usize> = dims.split(',').map(str::parse).collect::<Result<_, _>>()?;
    let data = std::fs::read(path)?;
    let vol = Volume::new(&data, dims.try_into().map_err(|_| "three dims")?)?;
    let params = Params {
        mode: Mode::Embedded,
        normals: false,
        ..Params::new(iso.parse()?)
    };
    let runs = 40;
    let time = |f: &dyn Fn()| {
        let t = Instant::now();
        for _ in 0..runs {
            f();
        }
        t.elapsed().as_secs_f64() * 1e3 / runs as f64
    };
    let one = || drop(extract(&vol, &params).expect("extraction succeeds"));
    let alone = time(&one);
    let (a, b) = std::thread::scope(|s| {
        let other = s.spawn(|| time(&one));
        (time(&one), other.join().expect("no panic"))
    });
    let par = time(&|| drop(extract_par(&vol, &params, 2, &|_| {}).expect("extraction succeeds")));
    println!(
        "alone {alone:.2} ms; two at once {a:.2} and {b:.2} ms each; extract_par on 2 threads {par:.2} ms"
    );
    Ok(())
}
