//! sc-io as this crate builds it, without its `zarr` feature: a Zarr store is still recognised,
//! and refused with an error that names the store and the feature. `fuzz/run.sh` runs this once
//! after the build. It is a check here rather than a test in sc-io because this crate is the
//! build of sc-io without the feature that CI makes anyway; `cargo test -p sc-io
//! --no-default-features` rebuilt the readers' dependencies (and sc-io's dev-dependencies) with
//! other features for it, 100–245 s of CI on two cores.

use sc_io::progress::Silent;
use sc_io::read::{ReadOptions, read};

fn main() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let store = dir.path().join("volume.zarr");
    std::fs::create_dir(&store).expect("the store's folder");
    std::fs::write(store.join("zarr.json"), "{}").expect("its metadata");
    let error = match read(&store, &ReadOptions::default(), &Silent) {
        Ok(_) => fail("a Zarr store was read, though the `zarr` feature is off"),
        Err(e) => e.to_string(),
    };
    if !(error.contains("volume.zarr") && error.contains("`zarr` feature")) {
        fail(&format!(
            "the refusal does not name the store and the feature: {error}"
        ));
    }
    println!("without the zarr feature, a Zarr store is refused: {error}");
}

fn fail(why: &str) -> ! {
    eprintln!("zarr_off: {why}");
    std::process::exit(1)
}
