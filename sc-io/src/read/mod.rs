//! Volume readers: [`read`] reads a file in whatever format it is, and [`stream`] reads raw,
//! NIfTI and Zarr volumes a few slices at a time. Each format parses its own header (with a crate
//! where a good one exists) and hands its sample block to one reader of blocks, so that byte
//! order, compression, truncation and progress are handled once.

mod block;
pub mod dicom;
mod dicom_lengths;
mod format;
mod header;
mod metaimage;
mod nifti;
pub(crate) mod npy;
mod nrrd;
mod payload;
mod placement;
mod raw;
mod sidecar;
pub mod stream;
#[cfg(feature = "zarr")]
mod zarr;
#[cfg(not(feature = "zarr"))]
#[path = "zarr_off.rs"]
mod zarr;

use std::path::Path;

pub use format::{Format, ReadOptions};
pub use raw::RawLayout;

use crate::error::{Error, Result};
use crate::progress::Progress;
use crate::volume::Grid;
use placement::check_placement;

/// Reads the volume at `path` in whatever format it is.
pub fn read(path: &Path, options: &ReadOptions, progress: &dyn Progress) -> Result<Grid> {
    let format = Format::detect(path, options)?;
    if !path.exists() {
        return Err(Error::file(path, "no such file or directory"));
    }
    let mut grid = match format {
        Format::Raw(layout) => raw::read(path, &layout, progress),
        Format::Nifti => nifti::read(path, progress),
        Format::Nrrd => nrrd::read(path, progress),
        Format::MetaImage => metaimage::read(path, progress),
        Format::Npy | Format::Npz => npy::read(path, options.array.as_deref(), progress),
        Format::Dicom => dicom::read(path, &options.dicom, progress),
        Format::Sidecar => read_with_sidecar(path, progress),
        Format::Zarr => match stream::open(path, options)? {
            Some(s) => s.read_all(progress),
            None => unreachable!("a Zarr store always streams"),
        },
    }?;
    grid.format = format.name();
    check_placement(path, &grid)?;
    Ok(grid)
}

fn read_with_sidecar(path: &Path, progress: &dyn Progress) -> Result<Grid> {
    let json = sidecar::find(path).ok_or_else(|| Error::file(path, "no JSON sidecar beside it"))?;
    let side = sidecar::Sidecar::read(&json)?;
    let mut grid = raw::read(&side.data, &side.layout, progress)?;
    grid.spacing = side.spacing.unwrap_or(grid.spacing);
    grid.origin = side.origin.unwrap_or(grid.origin);
    if !side.iso_suggestions.is_empty() {
        let named: Vec<String> = side
            .iso_suggestions
            .iter()
            .map(|(name, iso)| format!("{name} {iso}"))
            .collect();
        grid.notes.push(format!(
            "{} suggests iso values: {}",
            json.display(),
            named.join(", ")
        ));
    }
    Ok(grid)
}
