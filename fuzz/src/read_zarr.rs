//! The fuzz target of `src/main.rs` in a build of sc-io with its `zarr` feature, for Zarr stores
//! (`SC_FUZZ_TARGET=zarr`); the other readers' build stays without zarrs. `fuzz/run.sh` builds it
//! after the others.

#[path = "main.rs"]
mod target;

fn main() {
    target::main();
}
