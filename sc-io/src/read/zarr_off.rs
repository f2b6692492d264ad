//! Zarr without the `zarr` feature: a store is recognised, and refused with a message that says
//! why, so a build without `zarrs` (and the C libraries of its codecs) still names the format.
//! The fuzzer's crate builds sc-io so, and checks the refusal (`fuzz/src/zarr_off.rs`).

use std::path::Path;

use crate::error::{Error, Result};
use crate::volume::{Grid, Sample};

/// No Zarr array opens in this build, so there is no source.
pub enum Source {}

/// Refuses the store at `path`.
pub fn open(path: &Path, _level: usize) -> Result<(Grid, Source)> {
    Err(Error::file(
        path,
        "a Zarr store, which this build reads none of (sc-io's `zarr` feature is off)",
    ))
}

impl Source {
    pub fn chunk_z(&self) -> usize {
        match *self {}
    }

    pub fn read<T: Sample>(&mut self, _: &Path, _: usize, _: usize) -> Result<Vec<T>> {
        match *self {}
    }

    pub fn missing_chunks(&self) -> Result<Option<String>> {
        match *self {}
    }
}
