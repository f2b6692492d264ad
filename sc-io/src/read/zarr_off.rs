//! Zarr without the `zarr` feature: a store is recognised, and refused with a message that says
//! why, so a build without `zarrs` (and the C libraries of its codecs) still names the format.

use std::path::Path;

use crate::error::{Error, Result};
use crate::volume::{Grid, Sample};

/// Every sample type: nothing is read from Zarr.
pub trait Element {}

impl<T> Element for T {}

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

    pub fn read<T: Sample>(&self, _: &Path, _: usize, _: usize) -> Result<Vec<T>> {
        match *self {}
    }
}

#[cfg(test)]
mod tests {
    use crate::progress::Silent;
    use crate::read::{ReadOptions, read};

    /// A Zarr store is recognised and refused, the message naming the store and the feature.
    #[test]
    fn a_zarr_store_is_refused_naming_the_feature() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        let store = dir.path().join("volume.zarr");
        std::fs::create_dir(&store).expect("the store's folder");
        std::fs::write(store.join("zarr.json"), "{}").expect("its metadata");
        let error = read(&store, &ReadOptions::default(), &Silent)
            .err()
            .expect("no Zarr store is read without the feature")
            .to_string();
        assert!(error.contains("volume.zarr"), "{error}");
        assert!(error.contains("`zarr` feature"), "{error}");
    }
}
